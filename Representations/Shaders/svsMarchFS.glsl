// The atmosphere and the ground outside the cloud box, after the slices (which
// draw only inside the box). Each pixel marches its ray outside the box in one
// pass: `segment` 0, the part in front of the box (the whole ray where it misses
// the box), added as it is; `segment` 1, the part behind it, which the mapper's
// blend multiplies by the cloud transmittance the slices left in the alpha.
// Shadows: the shadow surface is complete now and holds, per sun line, the cloud's
// whole optical depth along it. A point outside the (convex) box lies either
// sunward of all of the box's part of its sun line or beyond all of it, so its
// cloud depth toward the sun is that whole value when the line toward the sun
// meets the box, else 0: exact, where drawing the slices on past the box (000 §5,
// Fig. 6c, the shafts) would give the same up to the slicing. The ground point
// inside the box (a box that reaches below the ground) takes the whole line too.
// Output: rgb = radiance toward the eye, a = 1, or 0 where the ground closes the
// ray (not over a sky, see overSky); second output: the same without the cloud's
// shadow (see svsSliceFS.glsl).
in vec2 texCoord;
uniform sampler2D intervalPhase;
uniform sampler2D rayEnds;  // (t_end, t_ground) per pixel, this frame
uniform int segment;        // 0: in front of the box (or the whole ray), 1: behind it
uniform int shaftsOn;
uniform int steps;          // samples per segment outside the cloud's shadow
uniform float sliceSpacing; // Delta d of the slices (world)
uniform int maxShadowSteps; // cap of the samples in the shadow (the number of slices)

const int kDenseAtStart = 0;
const int kDenseAtEnd = 1;
const int kUniform = 2;

vec3 color = vec3(0.0);
vec3 clearColor = vec3(0.0); // without the cloud's shadow

// Air of [t0, t1] by `count` samples, spaced uniformly or quadratically (dense
// at one end); viewTransmittance comes in at t0 and leaves at t1 (altitude over
// the spherical earth, accumulated step by step: the interval can reach the top
// of the atmosphere along rays near the horizon).
void MarchAir(vec3 origin, vec3 direction, vec2 phase, float t0, float t1, int spacing,
  int count, bool shadowed, inout vec3 viewTransmittance)
{
  float span = t1 - t0;
  if (span <= 0.0)
  {
    return;
  }
  for (int k = 0; k < count; ++k)
  {
    float u = (float(k) + 0.5) / float(count);
    float t = spacing == kUniform ? t0 + span * u
      : spacing == kDenseAtStart  ? t0 + span * u * u
                                  : t1 - span * (1.0 - u) * (1.0 - u);
    float density = spacing == kUniform ? 1.0 : 2.0 * (spacing == kDenseAtStart ? u : 1.0 - u);
    float dt = span * density / float(count) * metresPerUnit;
    vec3 p = origin + t * direction;
    float altitude = Altitude(p);
    vec3 clearAir = AirSource(altitude, phase);
    vec3 air = clearAir;
    if (shadowed) // (only inside ShadowInterval: elsewhere the cloud depth is 0)
    {
      air *= exp(-CloudDepthOutsideBox(p));
    }
    vec3 multiple = AirMultipleSource(altitude);
    air += multiple;
    clearAir += multiple;
    vec3 extinction = AirExtinction(altitude);
    vec3 stepTransmittance = exp(-extinction * dt);
    // Exact for constant coefficients over the step: (1 - T_step) / k_atm.
    vec3 weight = mix(vec3(dt), (1.0 - stepTransmittance) / max(extinction, vec3(1e-30)),
      step(vec3(1e-4), extinction * dt));
    color += air * viewTransmittance * weight;
    clearColor += clearAir * viewTransmittance * weight;
    viewTransmittance *= stepTransmittance;
  }
}

void main()
{
  vec3 origin, direction;
  ViewRay(texCoord, origin, direction);
  vec4 intervalAndPhase = texture(intervalPhase, texCoord);
  vec4 rayEnd = texture(rayEnds, texCoord);
  vec2 ends = rayEnd.rg;
  float tEnd = ends.x;
  float tGround = ends.y;
  float tEndMarch = min(tEnd, 1e9);
  float tIn, tOut;
  bool hitsBox = BoxInterval(origin, direction, tIn, tOut) && tOut > 0.0 && tIn < tEnd;
  tIn = max(tIn, 0.0);
  if (segment == 1 && !hitsBox)
  {
    discard;
  }
  // This segment's part of the ray.
  float t0 = 0.0, t1 = tEndMarch;
  if (hitsBox)
  {
    t0 = segment == 0 ? 0.0 : min(tOut, tEndMarch);
    t1 = segment == 0 ? min(tIn, tEndMarch) : tEndMarch;
  }
  // Behind the box: from the slices' transmittance at the box exit (BoxViewTransmittance).
  vec3 viewTransmittance = hitsBox && segment == 1
    ? BoxViewTransmittance(origin, direction, t0, rayEnd.ba)
    : AtmosphereViewTransmittance(origin, direction, t0);
  float a, b;
  if (atmosphereOn == 0 || t1 <= t0)
  {
  }
  else if (shaftsOn != 0 && ShadowInterval(origin, direction, t0, t1, a, b))
  {
    // In the shadow (the shafts): one sample per slice plane crossed, as drawing
    // the slices on would take (at least steps / 2, at most maxShadowSteps);
    // around it, steps / 2 each, dense toward it.
    int around = max(steps / 2, 1);
    float crossings = (b - a) * abs(dot(direction, sliceNormal)) / sliceSpacing;
    int inside = int(clamp(ceil(crossings), float(around), float(max(maxShadowSteps, 1))));
    vec2 phase = intervalAndPhase.zw;
    MarchAir(origin, direction, phase, t0, a, kDenseAtEnd, around, false, viewTransmittance);
    MarchAir(origin, direction, phase, a, b, kUniform, inside, true, viewTransmittance);
    MarchAir(origin, direction, phase, b, t1, kDenseAtStart, around, false, viewTransmittance);
  }
  else
  {
    // Smooth air: dense toward the box (in front: its end), else near the eye.
    MarchAir(origin, direction, intervalAndPhase.zw, t0, t1,
      hitsBox && segment == 0 ? kDenseAtEnd : kDenseAtStart, steps, false, viewTransmittance);
  }
  float alpha = 1.0;
  // The ground where the ray ends on it in this segment: in front of the box, or
  // behind (or inside) it.
  bool groundHere = tGround < kInfinity && tGround <= tEnd &&
    (segment == 0 ? (!hitsBox || tGround < tIn) : tGround >= tIn);
  if (groundHere)
  {
    vec3 g = origin + tGround * direction;
    // The march ended at the ground (t1 = t_end = t_ground), unless it is beyond 1e9.
    vec3 groundTransmittance = atmosphereOn != 0 && tGround < 1e9
      ? viewTransmittance : AtmosphereViewTransmittance(origin, direction, tGround);
    color += GroundRadiance(g, CloudDepthOutsideBox(g)) * groundTransmittance;
    clearColor += GroundRadiance(g, 0.0) * groundTransmittance;
    alpha = overSky != 0 ? 1.0 : 0.0;
  }
  gl_FragData[0] = vec4(color, alpha);
  gl_FragData[1] = vec4(clearColor, 1.0);
}
