// The cloud's light at a sample, shared by the shadow-view slices (svsSliceFS.glsl)
// and the ray march (cloudMarchFS.glsl): the sun's single scattering through the
// cloud's optical depth toward the sun, the multiple scattering of the solver's
// texture or of the octaves, lightning and temperature emission. Prepended after
// svsCommon.glsl to the passes that light the cloud.
// Multiple scattering (Physics/MultipleScattering.h).
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
// Lightning (vtkNimbusLightningIllumination, 003 Eqs. 8-10): J of the strokes'
// light, all orders, in the same layout and units.
uniform int lightningTextureOn;
uniform sampler3D lightningRed;
uniform sampler3D lightningGreen;
uniform sampler3D lightningBlue;
uniform vec3 lightningTextureScale;   // density texture coordinates -> these textures'
// Its first scattering on the density's grid (Physics/FirstScattering.h), when the filter
// computed it there (then the textures above hold the orders >= 2): the sources'
// unscattered irradiance E (alpha) and its net flux F (rgb), grey, times the colour.
uniform int lightningFirstOn;
uniform sampler3D lightningFirst;
uniform vec3 lightningFirstScale;     // density texture coordinates -> this texture's
uniform vec3 lightningColour;
uniform float lightningFirstK1;       // the cloud's phase function's mean cosine
// The delta-M view (the mapper's LightningDeltaMView; then lightningFirst is the beam
// through the reduced extinction alone, E' = I exp(-(1 - f albedo) tau) / r^2): the
// lightning's light (1 - f) albedo sigma (J' + J1') attenuated by the reduced extinction
// (1 - f albedo) sigma, J' the solver's J with its degree-1 part scaled by g'/k1, J1'
// with the truncated phase function's g' (Wiscombe 1977; docs/lightning.md).
uniform int lightningDeltaM;
uniform float lightningPeakFraction;  // f = k2
uniform float lightningTruncatedG;    // g' = (k1 - k2) / (1 - k2)
uniform float lightningDegreeOneScale; // g' / k1
uniform float lightningPeakLobeG;     // the truncated peak's own HG lobe (DeltaMPeakLobeG)
uniform sampler3D lightningBeamCosine; // the delta-M beam's mean cosine (E / E')^(1 - g_peak)
// Temperature emission (Physics/BlackbodyEmission.h): eta = E rho B(T) / Y[B(T_ref)]
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
// degreeOne scales the degree-1 part (1, or g'/k1 for the delta-M view).
vec3 LightningInScattering(vec3 p, vec3 w, float degreeOne)
{
  vec3 tc = (worldToTexture * vec4(p, 1.0)).xyz * lightningTextureScale;
  float y1 = 0.4886025 * degreeOne;
  vec4 y = vec4(0.2820948, y1 * w.y, y1 * w.z, y1 * w.x);
  return max(vec3(dot(texture(lightningRed, tc), y), dot(texture(lightningGreen, tc), y),
               dot(texture(lightningBlue, tc), y)), vec3(0.0));
}

// J1(p, w) of the lightning's first scattering in degree-1 spherical harmonics, as the
// solver's J: (E + 3 k_1 F . w) / (4 pi), k_1 the phase function's mean cosine. (A lobe
// p(w . F/|F|) around the net flux, exact for one point source, was measured darker than
// the path tracer next to a channel: a line's light arrives in a fan of directions, which
// the lobe folds into one: docs/lightning.md.)
// k1: the mean cosine of the phase function (the truncated one's g' for the delta-M view).
vec3 LightningFirstScattering(vec3 p, vec3 w, float k1)
{
  vec4 v = texture(lightningFirst, (worldToTexture * vec4(p, 1.0)).xyz * lightningFirstScale);
  return lightningColour * max((v.a + 3.0 * k1 * dot(v.rgb, w)) / (4.0 * kPi), 0.0);
}

// The delta-M view's lightning at p toward the eye per metre, before the view's reduced
// attenuation: (1 - f) albedo sigma (J'(p, -direction) + J1'(p, -direction)); 0 when off.
vec3 CloudLightningDeltaM(vec3 p, vec3 direction, float sigma)
{
  if (lightningDeltaM == 0)
  {
    return vec3(0.0);
  }
  vec3 j = LightningFirstScattering(p, -direction, lightningTruncatedG);
  if (lightningTextureOn != 0)
  {
    j += LightningInScattering(p, -direction, lightningDegreeOneScale);
  }
  return (1.0 - lightningPeakFraction) * cloudAlbedo * sigma * j;
}

// The light the delta-M view keeps on the sources' beams, seen by the eye: the beam E'
// (through the reduced extinction) loses f albedo sigma E' a metre to the truncated
// forward peak, and its last scattering toward the eye goes through the peak's own lobe
// and then the full extinction (CloudOtherSources). Along a pencil from a point source
// this sums to I (exp(-(1 - f albedo) tau) - exp(-tau)) / D^2, the light that scattered
// only inside the peak: the source's aureole through the cloud, which the reduced view
// alone draws nowhere (docs/lightning.md). The beam's directions at p are taken as an HG
// lobe about F'/|F'| with mean cosine |F'|/E' (the sources' geometry: 1 for one point
// source, less in a channel's fan) times the spread its own peak scatterings gave it
// (lightningBeamCosine, DeltaMBeamMeanCosine), so the peak's lobe folded with them is
// HG(g_peak times both) (HG lobes fold by multiplying their g). Per unit scattering
// coefficient, like J.
vec3 LightningForwardPeak(vec3 p, vec3 w)
{
  vec3 tc = (worldToTexture * vec4(p, 1.0)).xyz * lightningFirstScale;
  vec4 v = texture(lightningFirst, tc);
  float flux = length(v.rgb);
  if (v.a <= 0.0 || flux <= 0.0)
  {
    return vec3(0.0);
  }
  float meanCosine = min(flux / v.a, 1.0) * clamp(texture(lightningBeamCosine, tc).r, 0.0, 1.0);
  float mu = clamp(dot(v.rgb, w) / flux, -1.0, 1.0);
  return lightningColour * v.a * HenyeyGreenstein(mu, lightningPeakLobeG * meanCosine);
}

// The reduced extinction's share (1 - f albedo) of the delta-M view.
float LightningReducedExtinction()
{
  return 1.0 - lightningPeakFraction * cloudAlbedo;
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


// The cloud's light at p toward the eye per metre other than the sun's single and
// forward-peak scattering: the solver's multiple scattering, lightning, emission.
vec3 CloudOtherSources(vec3 p, vec3 direction, float sigma)
{
  vec3 source = vec3(0.0);
  if (scatteringTextureOn != 0)
  {
    source += cloudAlbedo * sigma * InScattering(p, -direction);
  }
  // (The delta-M view's lightning is CloudLightningDeltaM's, attenuated apart.)
  if (lightningTextureOn != 0 && lightningDeltaM == 0)
  {
    source += cloudAlbedo * sigma * LightningInScattering(p, -direction, 1.0);
  }
  if (lightningFirstOn != 0 && lightningDeltaM == 0)
  {
    source += cloudAlbedo * sigma * LightningFirstScattering(p, -direction, lightningFirstK1);
  }
  if (lightningFirstOn != 0 && lightningDeltaM != 0)
  {
    source += lightningPeakFraction * cloudAlbedo * sigma * LightningForwardPeak(p, -direction);
  }
  if (emissionOn != 0)
  {
    // The source term of the RTE, eta ds: attenuated in the slab like the scattering.
    source += emissionScale * max(texture(emissionRgb, (worldToTexture * vec4(p, 1.0)).xyz).rgb, vec3(0.0));
  }
  return source;
}

// The radiance the cloud sends toward the eye per metre at p [relative to the sun],
// before the view's attenuation: sigma = k rho [1/m], sunDepth = the cloud's optical
// depth toward the sun, cloudPhase = the pixel's phase value (beta_cl + k_multi / 4 pi,
// 000 Eq. 8), direction = the view ray's.
vec3 CloudSource(vec3 p, vec3 direction, float sigma, float sunDepth, float cloudPhase,
  float altitude)
{
  float mu = clamp(dot(direction, sunDirection), -1.0, 1.0);
  return cloudAlbedo * sigma *
    (cloudPhase * exp(-sunDepth) + SunMultipleScattering(mu, sunDepth)) *
    SunIrradiance(altitude) +                                      // 000 Eq. 8, cloud
    CloudOtherSources(p, direction, sigma);
}
