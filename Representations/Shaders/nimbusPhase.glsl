// Phase functions, normalised to 1 over the sphere [1/sr]: the GLSL twins of
// Physics/PhaseFunctions.h (nimbus::Rayleigh, nimbus::HenyeyGreenstein,
// nimbus::CornetteShanks), the same names and the same steps, compared with them on
// a grid of arguments by the test TestShaderTwins. mu = cos(scattering angle) =
// dot(propagation direction of the incident light, scattered direction); g is the
// asymmetry parameter.
const float kPi = 3.14159265358979;

float ClampMu(float mu)
{
  return clamp(mu, -1.0, 1.0);
}

// |g| <= 1 - 1e-6 (kMaxAbsAsymmetry): g = +-1 is a delta distribution.
float ClampAsymmetry(float g)
{
  return clamp(g, -0.999999, 0.999999);
}

// 1 + g^2 - 2 g mu as a sum of non-negative terms: (1 - g)^2 + 2 g (1 - mu) for
// g >= 0, (1 + g)^2 - 2 g (1 + mu) for g < 0 (no cancellation at either peak).
float HgDenominator(float mu, float g)
{
  if (g >= 0.0)
  {
    float oneMinusG = 1.0 - g;
    return oneMinusG * oneMinusG + 2.0 * g * (1.0 - mu);
  }
  float onePlusG = 1.0 + g;
  return onePlusG * onePlusG - 2.0 * g * (1.0 + mu);
}

// (1 - g^2) / (1 + g^2 - 2 g mu)^{3/2}: the Henyey-Greenstein lobe normalised to 4 pi.
float HgLobe(float mu, float g)
{
  float d = HgDenominator(mu, g);
  return (1.0 - g) * (1.0 + g) / (d * sqrt(d));
}

float HenyeyGreenstein(float mu, float g)
{
  g = ClampAsymmetry(g);
  return HgLobe(ClampMu(mu), g) / (4.0 * kPi);
}

// 000 Eq. 3 / 004 Eq. 5, divided by 4 pi.
float CornetteShanks(float mu, float g)
{
  g = ClampAsymmetry(g);
  mu = ClampMu(mu);
  float k = 3.0 / (2.0 * (2.0 + g * g));
  return k * (1.0 + mu * mu) * HgLobe(mu, g) / (4.0 * kPi);
}

// 3 / (16 pi) (1 + mu^2).
float Rayleigh(float mu)
{
  mu = ClampMu(mu);
  return 3.0 / (16.0 * kPi) * (1.0 + mu * mu);
}
