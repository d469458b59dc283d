// The atmosphere (and ground) before the first and after the last cloud slice.
// There the shadow surface no longer changes (no cloud), so the slices that
// continue the slicing beyond the cloud box — which carry the shafts of light
// (000 §5, Fig. 6c) — are drawn in one pass: each pixel steps through
// `steps` samples of its ray inside the region and looks the shadow surface up at
// each, which is what drawing them one by one would compute, without a blend per
// slice. Before the cloud (pre) the sun is unshadowed; after it (post) the
// shadow surface holds the whole cloud. Output as for a slice: rgb = radiance
// toward the eye, a = 1, or 0 where the ground closes the ray in the region.
in vec2 texCoord;
uniform sampler2D intervalPhase;
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
  float tGround = GroundDistance(origin, direction);
  float tEnd = min(min(OpaqueDistance(texCoord, origin, direction), TopDistance(origin, direction)),
    tGround);
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
  float alpha = 1.0;
  if (t1 > t0 && atmosphereOn != 0)
  {
    // Quadratic spacing: dense near the region's start (the camera side when the
    // region starts at the eye), sparse toward the top of the atmosphere.
    float span = t1 - t0;
    for (int k = 0; k < steps; ++k)
    {
      float u = (float(k) + 0.5) / float(steps);
      float t = t0 + span * u * u;
      float dt = span * 2.0 * u / float(steps);
      vec3 p = origin + t * direction;
      float altitude = Altitude(p);
      vec3 air = AtmosphereRow(1, altitude) * intervalAndPhase.z +
        AtmosphereRow(2, altitude) * intervalAndPhase.w;
      if (useShadow != 0 && shaftsOn != 0)
      {
        air *= exp(-ShadowDepth(p));
      }
      color += air * AtmosphereViewTransmittance(origin, direction, t) * dt * lengthUnit;
    }
  }
  if (tGround < kInfinity && tGround <= tEnd)
  {
    float dGround = dot(origin + tGround * direction, sliceNormal);
    if (dGround >= regionStart && dGround < regionEnd)
    {
      vec3 g = origin + tGround * direction;
      color += GroundRadiance(g, useShadow != 0 ? ShadowDepth(g) : 0.0) *
        AtmosphereViewTransmittance(origin, direction, tGround);
      alpha = 0.0;
    }
  }
  gl_FragData[0] = vec4(color, alpha);
}
