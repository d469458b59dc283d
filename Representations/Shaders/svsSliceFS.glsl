// One shadow-view slice seen from the camera (000 Eqs. 5, 8, 9; §4.3 blending is
// the fixed-function blend set by the mapper). Output: rgb = C_i, the radiance the
// slab around slice i sends toward the eye (already multiplied by the atmosphere's
// view transmittance in front of it), a = alpha_i, the slab's cloud transmittance
// Delta g_view_cl. Only the slice's part inside the cloud box is drawn: the air
// and the ground outside it are the march passes' (svsMarchFS.glsl).
// Second output (only bound when the mapper draws over a Nimbus sky): the same
// slab's radiance without the cloud — unshadowed air — with alpha 1,
// which the same blend sums; the composite subtracts what the cloud hides and
// shadows of it from the sky (see svsCompositeFS.glsl).
in vec2 texCoord;
uniform sampler2D intervalPhase;  // (1/|v.n|, beta_cl + k_multi/4pi, beta_R, beta_M) per pixel (000 §4.4)
uniform sampler2D rayEnds;        // (t_end, t_ground) per pixel, this frame
uniform float sliceOffset;        // d_i: the slice plane is dot(x, n) = d_i
uniform float sliceSpacing;       // Delta d (world)
uniform float sunStepMetres;      // Delta s = Delta d / dot(n, -L) [m] (000 Eq. 10)
uniform int shaftsOn;             // atmosphere in cloud shadow
uniform int unlit;                // benchmark floor: composite the slices without lighting
uniform int boxAirOn;             // the air in the box (0: the bottom layer has it)
void main()
{
  vec3 origin, direction;
  ViewRay(texCoord, origin, direction);
  float vn = dot(direction, sliceNormal);
  float tEnd = texture(rayEnds, texCoord).r;
  // This pixel's plane of slice i (SliceJitter): stratified along the ray.
  float planeOffset = sliceOffset + SliceJitterFraction(gl_FragCoord.xy) * sliceSpacing;
  float t = abs(vn) > 1e-7 ? (planeOffset - dot(origin, sliceNormal)) / vn : -1.0;
  // Only the slice's part inside the box: the air and the ground outside it are
  // the march passes' (svsMarchFS.glsl), and so is the ground where a ray ends on
  // it (these slices stop at t_end).
  if (t < 0.0 || t >= tEnd)
  {
    discard;
  }
  vec3 p = origin + t * direction;
  if (!InsideBox(p))
  {
    discard;
  }
  // k_cl rho_cl [1/m] (p is inside the box)
  float sigma = extinctionPerDensity * max(texture(density, (worldToTexture * vec4(p, 1.0)).xyz).r, 0.0);
  if (sigma <= 0.0 && atmosphereOn == 0)
  {
    discard; // empty space without air: nothing to add, nothing to attenuate
  }
  vec4 intervalAndPhase = texture(intervalPhase, texCoord);
  float stepMetres = sliceSpacing * intervalAndPhase.x * metresPerUnit; // Delta t(p) [m]
  float alpha = exp(-sigma * stepMetres);                              // 000 Eq. 9 (cloud part)
  // Exact integral of a constant source over the slab: (1 - alpha) / sigma.
  float slabLength = sigma * stepMetres > 1e-4 ? (1.0 - alpha) / sigma : stepMetres;
  vec3 source;
  vec3 clearColor = vec3(0.0); // the slab without the cloud
  // Third output (bound for the lightning's delta-M view): the lightning's light
  // (CloudLightningDeltaM) with the slab's transmittance through the reduced extinction
  // as its own alpha, which the same blend accumulates; the composite adds it.
  float reducedSigma = LightningReducedExtinction() * sigma;
  float reducedAlpha = lightningDeltaM != 0 ? exp(-reducedSigma * stepMetres) : 1.0;
  float reducedLength =
    reducedSigma * stepMetres > 1e-4 ? (1.0 - reducedAlpha) / reducedSigma : stepMetres;
  vec3 lightning = vec3(0.0);
  if (unlit != 0)
  {
    source = vec3(sigma);
  }
  else
  {
    float altitude = Altitude(p);
    // Midpoint rule toward the sun: the slices before plus half of this one (000 Eq. 7).
    float sunDepth = CloudDepthInsideBox(p) + 0.5 * sigma * sunStepMetres;
    float sunTransmittance = exp(-sunDepth);
    source = vec3(0.0);
    if (sigma > 0.0) // (empty parts of the box: the air alone, and no cloud terms to pay)
    {
      // (One piece of a distributed cloud: its own piece's solve. Dimming it by the
      // other pieces' shade on p's sun line darkened the piece's face toward them;
      // left as it is, docs/parallel.md.)
      source = CloudSource(p, direction, sigma, sunDepth, intervalAndPhase.y, altitude);
      lightning = CloudLightningDeltaM(p, direction, sigma);
    }
    vec3 viewTransmittance =
      BoxViewTransmittance(origin, direction, t, texture(rayEnds, texCoord).ba);
    if (atmosphereOn != 0 && boxAirOn != 0)
    {
      vec3 air = AirSource(altitude, intervalAndPhase.zw);              // 000 Eq. 8, atmosphere
      vec3 multiple = AirMultipleSource(altitude);
      source += air * (shaftsOn != 0 ? sunTransmittance : 1.0) + multiple;
      clearColor = (air + multiple) * viewTransmittance * stepMetres;
    }
    source *= viewTransmittance;
    lightning *= viewTransmittance;
  }
  gl_FragData[0] = vec4(source * slabLength, alpha);
  gl_FragData[1] = vec4(clearColor, 1.0);
  gl_FragData[2] = vec4(lightning * reducedLength, reducedAlpha);
}
