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
uniform int boxAirOn;             // the air in the box (0: the bottom layer has it; issue 18)
// Multiple scattering (issue 14; Physics/MultipleScattering.h).
uniform float cloudG;                 // Cornette-Shanks asymmetry of the cloud
uniform int scatteringTextureOn;      // the solver's in-scattered radiance J(x, w)
uniform sampler3D scatteringRed;      // SH c_00, c_1-1, c_10, c_11 of J, per channel
uniform sampler3D scatteringGreen;
uniform sampler3D scatteringBlue;
uniform mat4 worldToScattering;       // world -> these textures' coordinates
uniform float scatteringScale;        // the sun's illuminance now / at the solve (J is linear in it)
uniform float forwardPeakFraction;    // delta-M f of the discrete-direction solve
uniform int octaves;                  // Wrenninge et al. 2013: terms incl. the single one
uniform vec3 octaveScales;            // a (extinction), b (scattering), c (asymmetry)
// Lightning (issue 16; vtkNimbusLightningIllumination, 003 Eqs. 8-10): J of the strokes'
// light, all orders, in the same layout and units.
uniform int lightningTextureOn;
uniform sampler3D lightningRed;
uniform sampler3D lightningGreen;
uniform sampler3D lightningBlue;
uniform vec3 lightningTextureScale;   // density texture coordinates -> these textures'
// Temperature emission (issue 17; Physics/BlackbodyEmission.h): eta = E rho B(T) / Y[B(T_ref)]
// [Y/(sr m)]; the texture holds rho B(T) / Y[B(T_ref)] in linear sRGB, on the density's texels.
uniform int emissionOn;
uniform sampler3D emissionRgb;
uniform float emissionScale; // E [Y/(sr m) per unit density at T_ref]

// J(p, w) of the solver: the radiance the cloud's particles at p scatter toward w
// (w the direction of travel) per unit scattering coefficient, beyond the sun's
// single scattering (degree-1 spherical harmonics, clamped at 0).
vec3 InScattering(vec3 p, vec3 w)
{
  vec3 tc = (worldToScattering * vec4(p, 1.0)).xyz;
  vec4 y = vec4(0.2820948, 0.4886025 * w.y, 0.4886025 * w.z, 0.4886025 * w.x);
  return scatteringScale * max(vec3(dot(texture(scatteringRed, tc), y),
                                 dot(texture(scatteringGreen, tc), y),
                                 dot(texture(scatteringBlue, tc), y)), vec3(0.0));
}

// J(p, w) of the lightning (the same form as InScattering, without the sun's scale).
vec3 LightningInScattering(vec3 p, vec3 w)
{
  vec3 tc = (worldToTexture * vec4(p, 1.0)).xyz * lightningTextureScale;
  vec4 y = vec4(0.2820948, 0.4886025 * w.y, 0.4886025 * w.z, 0.4886025 * w.x);
  return max(vec3(dot(texture(lightningRed, tc), y), dot(texture(lightningGreen, tc), y),
               dot(texture(lightningBlue, tc), y)), vec3(0.0));
}

// The sun's light scattered more than once that the mapper evaluates per sample,
// as a multiple of sigma_s E_sun: the part of the forward peak the delta-M solve
// left on the sun's direction, (1 - f) p(mu) (exp(-(1 - f albedo) tau) - exp(-tau)), and
// the octaves sum_{i>=1} b^i p(mu; c^i g) exp(-a^i tau).
float SunMultipleScattering(float mu, float tau)
{
  float sum = 0.0;
  if (forwardPeakFraction > 0.0)
  {
    // delta-M: the beam's excess leaves it at sigma_s (1 - f) (the rest stays in the
    // peak), by the cloud's own phase function for the last scattering. Measured
    // against the path tracer (docs/multiple-scattering.md): with p alone the backlit
    // cloud is too bright (silver_lining RMSE 0.109); with the truncated HG(g') the
    // glow near the sun too dim (haze_shafts 0.108); this way 0.038 and 0.092.
    sum += (1.0 - forwardPeakFraction) * CornetteShanks(mu, cloudG) *
      (exp(-(1.0 - forwardPeakFraction * cloudAlbedo) * tau) - exp(-tau));
  }
  float a = 1.0, b = 1.0, c = 1.0;
  for (int i = 1; i < octaves; ++i)
  {
    a *= octaveScales.x;
    b *= octaveScales.y;
    c *= octaveScales.z;
    sum += b * CornetteShanks(mu, c * cloudG) * exp(-a * tau);
  }
  return sum;
}

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
      float mu = clamp(dot(direction, sunDirection), -1.0, 1.0);
      source = cloudAlbedo * sigma *
        (intervalAndPhase.y * sunTransmittance + SunMultipleScattering(mu, sunDepth)) *
        SunIrradiance(altitude);                                       // 000 Eq. 8, cloud
      if (scatteringTextureOn != 0)
      {
        // (One piece of a distributed cloud: its own piece's solve. Dimming it by the
        // other pieces' shade on p's sun line darkened the piece's face toward them;
        // left as it is, issue 18, docs/parallel.md.)
        source += cloudAlbedo * sigma * InScattering(p, -direction);
      }
      if (lightningTextureOn != 0)
      {
        source += cloudAlbedo * sigma * LightningInScattering(p, -direction);
      }
      if (emissionOn != 0)
      {
        // The source term of the RTE, eta ds: attenuated in the slab like the scattering.
        source += emissionScale * max(texture(emissionRgb, (worldToTexture * vec4(p, 1.0)).xyz).rgb, vec3(0.0));
      }
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
  }
  gl_FragData[0] = vec4(source * slabLength, alpha);
  gl_FragData[1] = vec4(clearColor, 1.0);
}
