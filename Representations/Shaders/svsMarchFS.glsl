// The atmosphere (and ground) before the first and after the last cloud slice.
// There the shadow surface no longer changes (no cloud), so the slices that
// continue the slicing beyond the cloud box — which carry the shafts of light
// (000 §5, Fig. 6c) — are drawn in one pass: each pixel steps through
// `steps` samples of its ray inside the region and looks the shadow surface up at
// each, which is what drawing them one by one would compute, without a blend per
// slice. Before the cloud (pre) the sun is unshadowed; after it (post) the
// shadow surface holds the whole cloud. Output as for a slice: rgb = radiance
// toward the eye, a = 1, or 0 where the ground closes the ray in the region
// (not over a sky, see overSky);
// second output: the same without the cloud's shadow (see svsSliceFS.glsl).
in vec2 texCoord;
uniform sampler2D intervalPhase;
uniform sampler2D rayEnds;  // (t_end, t_ground) per pixel, this frame
uniform float regionStart;  // d range of the region (dot(x, n)); +-1e30 for open ends
uniform float regionEnd;
uniform int useShadow;      // 1 after the cloud
uniform int shaftsOn;
uniform int steps;

void main()
{
  vec3 origin, direction;
  ViewRay(texCoord, origin, direction);
  vec4 intervalAndPhase = texture(intervalPhase, texCoord);
  vec2 ends = texture(rayEnds, texCoord).rg;
  float tEnd = ends.x;
  float tGround = ends.y;
  float tEndMarch = min(tEnd, 1e9);
  // The part of [0, tEnd] where regionStart <= dot(x, n) < regionEnd.
  float d0 = dot(origin, sliceNormal);
  float vn = dot(direction, sliceNormal);
  float t0 = 0.0, t1 = tEndMarch;
  if (abs(vn) > 1e-7)
  {
    float ta = (regionStart - d0) / vn, tb = (regionEnd - d0) / vn;
    t0 = max(t0, min(ta, tb));
    t1 = min(t1, max(ta, tb));
  }
  else if (d0 < regionStart || d0 >= regionEnd)
  {
    discard;
  }
  vec3 color = vec3(0.0);
  vec3 clearColor = vec3(0.0); // without the cloud's shadow
  float alpha = 1.0;
  // View transmittance: closed form (flat layers) up to the region's start, then
  // accumulated step by step with the altitude over the spherical earth, because
  // the region can reach the top of the atmosphere along rays near the horizon.
  vec3 viewTransmittance = AtmosphereViewTransmittance(origin, direction, t0);
  if (t1 > t0 && atmosphereOn != 0)
  {
    // Quadratic spacing: dense at the region's start, sparse toward its far end.
    float span = t1 - t0;
    for (int k = 0; k < steps; ++k)
    {
      float u = (float(k) + 0.5) / float(steps);
      float t = t0 + span * u * u;
      float dt = span * 2.0 * u / float(steps) * metresPerUnit;
      vec3 p = origin + t * direction;
      float altitude = Altitude(p);
      vec3 clearAir = AirSource(altitude, intervalAndPhase.zw);
      vec3 air = clearAir;
      if (useShadow != 0 && shaftsOn != 0)
      {
        air *= exp(-ShadowDepth(p));
      }
      vec3 multiple = AirMultipleSource(altitude);
      air += multiple;
      clearAir += multiple;
      vec3 stepTransmittance = exp(-AtmosphereRow(3, altitude) * dt);
      // Exact for constant coefficients over the step: (1 - T_step) / k_atm.
      vec3 extinction = AtmosphereRow(3, altitude);
      vec3 weight = mix(vec3(dt), (1.0 - stepTransmittance) / max(extinction, vec3(1e-30)),
        step(vec3(1e-4), extinction * dt));
      color += air * viewTransmittance * weight;
      clearColor += clearAir * viewTransmittance * weight;
      viewTransmittance *= stepTransmittance;
    }
  }
  if (tGround < kInfinity && tGround <= tEnd)
  {
    float dGround = dot(origin + tGround * direction, sliceNormal);
    if (dGround >= regionStart && dGround < regionEnd)
    {
      vec3 g = origin + tGround * direction;
      vec3 groundTransmittance = (t1 > t0 && atmosphereOn != 0)
        ? viewTransmittance : AtmosphereViewTransmittance(origin, direction, tGround);
      color += GroundRadiance(g, useShadow != 0 ? ShadowDepth(g) : 0.0) * groundTransmittance;
      clearColor += GroundRadiance(g, 0.0) * groundTransmittance;
      alpha = overSky != 0 ? 1.0 : 0.0;
    }
  }
  gl_FragData[0] = vec4(color, alpha);
  gl_FragData[1] = vec4(clearColor, 1.0);
}
