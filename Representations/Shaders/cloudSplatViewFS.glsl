// Billboard splatting, the view pass: the billboard texture gives the cumulative density
// C through the ball at this fragment (CloudSplats.h SplatColumnTexture), the attenuation
// ratio is a = exp(-kappa C), the ball's scattered light ballColor (1 - a) (the ball's
// single scattering with the sun's light at its centre: the integral of
// sigma exp(-tau to the exit) along the column). Blended (GL_ONE, GL_ONE_MINUS_SRC_ALPHA):
// the framebuffer is multiplied by a and the colour added (002 §3.3).
// With SUN_SAMPLES (SunLightSamples > 0, accumulation texture): the light along the
// fragment's own view ray through the ball, at SUN_SAMPLES midpoints x_j of its chord:
//   L = albedo p(mu) E_sun sum_j kappa f(x_j) dh T_sun(x_j) exp(-kappa P(u, h_j)),
// T_sun from the sun's accumulation texture at x_j (all balls, this one included),
// exp(-kappa P) this ball's own column between x_j and the eye (P: the partial-column
// table), u the ray's distance from the centre and h along it, both in units of R.
// With MULTIPLE_SCATTERING (MultipleScattering on) each point adds the light scattered
// more than once, as the cloud mapper's cloudLight.glsl: albedo kappa f(x_j) dh
// exp(-kappa P) times J(x_j, toward the eye) (the solver's in-scattered radiance, SH
// textures) plus the delta-M forward peak's part of the sun's light,
// (1 - f) p(mu) E_sun (exp(-(1 - f albedo) tau_sun) - exp(-tau_sun)).
// Over a sky: E_sun is the sun's colour above the air x the ball's tint (the air's
// reddening at its centre), and the air between the eye and the ball dims the colour and
// adds its own light where the ball covers: out = T_air C + (1 - a) L_air, coverage 1 - a
// (the sky behind, which already holds L_air, is multiplied by a).
//VTK::System::Dec
// (the mapper defines SUN_SAMPLES, the number of points, on the next line)
//SPLAT::SunSamples
//SPLAT::MultipleScattering
#ifdef SUN_SAMPLES
//NIMBUS::Library
#endif
in vec2 corner;
in float kappa;
in vec3 ballColor;
in vec3 billboardPoint;
flat in vec4 ballWorld;
flat in vec3 sunTint;
flat in vec3 airTransmittance;
flat in vec3 airRadiance;
uniform sampler2D billboard;
#ifdef SUN_SAMPLES
uniform sampler3D sunDepth;
uniform sampler2D partialColumn;
uniform vec3 eyeWorld;
uniform vec3 toSun;
uniform vec3 sunAxisX;
uniform vec3 sunAxisY;
uniform vec4 sunRect;
uniform vec2 sunDepthRange;
uniform vec3 sunColor;
uniform float albedo;
uniform float cloudG;
#ifdef MULTIPLE_SCATTERING
uniform sampler3D scatteringRed; // J's SH c_00, c_1-1, c_10, c_11 per colour
uniform sampler3D scatteringGreen;
uniform sampler3D scatteringBlue;
uniform vec3 scatteringScale; // texture coordinate = x scatteringScale + scatteringOffset
uniform vec3 scatteringOffset;
uniform vec3 lightScale;
uniform float forwardPeakFraction;

// J(x, w) toward w (direction of travel), per unit scattering coefficient.
vec3 SplatInScattering(vec3 x, vec3 w)
{
  vec3 tc = x * scatteringScale + scatteringOffset;
  vec4 y = vec4(0.2820948, 0.4886025 * w.y, 0.4886025 * w.z, 0.4886025 * w.x);
  return max(vec3(dot(texture(scatteringRed, tc), y), dot(texture(scatteringGreen, tc), y),
               dot(texture(scatteringBlue, tc), y)), vec3(0.0));
}
#endif

float SunOpticalDepth(vec3 x)
{
  vec3 size = vec3(textureSize(sunDepth, 0));
  vec3 s = vec3((vec2(dot(x, sunAxisX), dot(x, sunAxisY)) - sunRect.xy) * sunRect.zw,
    (-dot(x, toSun) - sunDepthRange.x) * sunDepthRange.y);
  s.z = (s.z * (size.z - 1.0) + 0.5) / size.z;
  return texture(sunDepth, s).r;
}

float PartialColumn(float u, float h)
{
  vec2 size = vec2(textureSize(partialColumn, 0));
  vec2 uv = (vec2(u, clamp(h, -1.0, 1.0) * 0.5 + 0.5) * (size - 1.0) + 0.5) / size;
  return texture(partialColumn, uv).r;
}
#endif
//VTK::Output::Dec

void main()
{
  if (dot(corner, corner) >= 1.0)
  {
    discard;
  }
  float column = texture(billboard, corner * 0.5 + 0.5).r;
  float opacity = 1.0 - exp(-kappa * column);
  vec3 color = ballColor * opacity;
#ifdef SUN_SAMPLES
  {
    vec3 d = normalize(billboardPoint - eyeWorld);
    float R = ballWorld.w;
    float tc = dot(ballWorld.xyz - eyeWorld, d);
    vec3 closest = eyeWorld + tc * d;
    float u = min(length(closest - ballWorld.xyz) / R, 1.0);
    float chord = sqrt(max(1.0 - u * u, 0.0));
    float dh = 2.0 * chord / float(SUN_SAMPLES);
    float sum = 0.0;
    float peakSum = 0.0;
    vec3 scatteredSum = vec3(0.0);
    for (int j = 0; j < SUN_SAMPLES; ++j)
    {
      float h = -chord + (float(j) + 0.5) * dh; // from the eye's side
      vec3 x = closest + h * R * d;
      float q = u * u + h * h;
      float f = 1.0 + q * (-22.0 / 9.0 + q * (17.0 / 9.0 - q * 4.0 / 9.0));
      float tau = SunOpticalDepth(x);
      float weight = kappa * f * dh * exp(-kappa * PartialColumn(u, h));
      sum += weight * exp(-tau);
#ifdef MULTIPLE_SCATTERING
      peakSum += weight * (exp(-(1.0 - forwardPeakFraction * albedo) * tau) - exp(-tau));
      scatteredSum += weight * SplatInScattering(x, -d);
#endif
    }
    // mu: the sunlight's direction (-toSun) against the way to the eye (-d).
    color = albedo * CornetteShanks(dot(toSun, d), cloudG) * sunColor * sunTint * sum;
#ifdef MULTIPLE_SCATTERING
    color += albedo * (CornetteShanks(dot(toSun, d), cloudG) * sunColor * sunTint *
                        (1.0 - forwardPeakFraction) * peakSum +
                      lightScale * scatteredSum);
#endif
  }
#endif
  gl_FragData[0] = vec4(airTransmittance * color + opacity * airRadiance, opacity);
}
