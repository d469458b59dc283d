#include "PhaseFunctions.h"
#include "Math.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace nimbus
{

namespace
{
constexpr double kInv4Pi = 1.0 / (4.0 * kPi);

double ClampMu(double mu)
{
  return std::min(1.0, std::max(-1.0, mu));
}

// 1 + g^2 - 2 g mu, written as (1 - g)^2 + 2 g (1 - mu) for g >= 0 and as
// (1 + g)^2 - 2 g (1 + mu) for g < 0: sums of non-negative terms, so it does not
// cancel at the forward peak (g -> 1, mu -> 1) or the backward one (g -> -1,
// mu -> -1); it is >= (1 - |g|)^2 > 0 after clamping.
double HgDenominator(double mu, double g)
{
  if (g >= 0.0)
  {
    const double oneMinusG = 1.0 - g;
    return oneMinusG * oneMinusG + 2.0 * g * (1.0 - mu);
  }
  const double onePlusG = 1.0 + g;
  return onePlusG * onePlusG - 2.0 * g * (1.0 + mu);
}

// (1 - g^2) / (1 + g^2 - 2 g mu)^{3/2}: the HG lobe normalised to 4 pi.
double HgLobe(double mu, double g)
{
  const double d = HgDenominator(mu, g);
  return (1.0 - g) * (1.0 + g) / (d * std::sqrt(d));
}

// Inverse HG CDF for g >= 0, written through 1 - mu to avoid cancellation:
// with D = 1 - g + 2 g u and t = (1 - g^2)/D,
//   1 - mu = (t^2 - (1-g)^2)/(2g) = (1 - g)(1 - u)(t + 1 - g)/D,
// which is also the isotropic limit 2(1 - u) at g = 0.
double SampleHgNonNegative(double g, double u)
{
  const double D = 1.0 - g + 2.0 * g * u;
  const double t = (1.0 - g) * (1.0 + g) / D;
  const double oneMinusMu = (1.0 - g) * (1.0 - u) * (t + 1.0 - g) / D;
  return ClampMu(1.0 - oneMinusMu);
}
} // namespace

double ClampAsymmetry(double g)
{
  if (std::isnan(g))
  {
    throw std::invalid_argument("nimbus phase function: asymmetry parameter g is NaN");
  }
  return std::min(kMaxAbsAsymmetry, std::max(-kMaxAbsAsymmetry, g));
}

//------------------------------------------------------------------------------
double HenyeyGreenstein(double mu, double g)
{
  g = ClampAsymmetry(g);
  return kInv4Pi * HgLobe(ClampMu(mu), g);
}

double SampleHenyeyGreenstein(double g, double u)
{
  g = ClampAsymmetry(g);
  u = std::min(1.0, std::max(0.0, u));
  // The distribution for -g is the mirror image: mu(-g, u) = -mu(g, 1 - u).
  return g >= 0.0 ? SampleHgNonNegative(g, u) : -SampleHgNonNegative(-g, 1.0 - u);
}

double HenyeyGreensteinMeanCosine(double g)
{
  return ClampAsymmetry(g);
}

//------------------------------------------------------------------------------
double CornetteShanks(double mu, double g)
{
  g = ClampAsymmetry(g);
  mu = ClampMu(mu);
  // 000 Eq. 3 / 004 Eq. 5, divided by 4 pi.
  const double k = 3.0 / (2.0 * (2.0 + g * g));
  return kInv4Pi * k * (1.0 + mu * mu) * HgLobe(mu, g);
}

double CornetteShanksMeanCosine(double g)
{
  g = ClampAsymmetry(g);
  // 3/(2(2+g^2)) * (<mu>_HG + <mu^3>_HG) with <mu^3>_HG = (2 g^3 + 3 g)/5.
  return 3.0 * g * (g * g + 4.0) / (5.0 * (g * g + 2.0));
}

double CornetteShanksAcceptance(double mu)
{
  return 0.5 * (1.0 + mu * mu);
}

//------------------------------------------------------------------------------
double Rayleigh(double mu)
{
  mu = ClampMu(mu);
  return 3.0 / (16.0 * kPi) * (1.0 + mu * mu);
}

double SampleRayleigh(double u)
{
  u = std::min(1.0, std::max(0.0, u));
  // CDF (mu^3 + 3 mu + 4)/8 = u  <=>  mu^3 + 3 mu - 2 z = 0 with z = 4u - 2.
  // Cardano: mu = A - 1/A, A = cbrt(z + sqrt(z^2 + 1)); for z < 0 use the odd
  // symmetry mu(-z) = -mu(z) so that z + sqrt(z^2+1) never cancels.
  const double z = 4.0 * u - 2.0;
  const double az = std::abs(z);
  const double A = std::cbrt(az + std::sqrt(az * az + 1.0));
  const double mu = A - 1.0 / A;
  return ClampMu(z >= 0.0 ? mu : -mu);
}

double RayleighMeanCosine()
{
  return 0.0;
}

//------------------------------------------------------------------------------
std::array<double, 3> DirectionFromCosine(
  const std::array<double, 3>& incident, double mu, double u2)
{
  const double len =
    std::sqrt(incident[0] * incident[0] + incident[1] * incident[1] + incident[2] * incident[2]);
  if (!(len > 0.0) || !std::isfinite(len))
  {
    throw std::invalid_argument(
      "nimbus DirectionFromCosine: incident direction is zero or not finite");
  }
  const double w[3] = { incident[0] / len, incident[1] / len, incident[2] / len };
  // Orthonormal basis (t, b, w): Duff et al., "Building an Orthonormal Basis,
  // Revisited", JCGT 6(1), 2017.
  const double sign = std::copysign(1.0, w[2]);
  const double a = -1.0 / (sign + w[2]);
  const double b = w[0] * w[1] * a;
  const double t[3] = { 1.0 + sign * w[0] * w[0] * a, sign * b, -sign * w[0] };
  const double s[3] = { b, sign + w[1] * w[1] * a, -w[1] };

  mu = ClampMu(mu);
  const double sinTheta = std::sqrt(std::max(0.0, (1.0 - mu) * (1.0 + mu)));
  const double phi = 2.0 * kPi * u2;
  const double ct = sinTheta * std::cos(phi);
  const double cs = sinTheta * std::sin(phi);
  return { mu * w[0] + ct * t[0] + cs * s[0], mu * w[1] + ct * t[1] + cs * s[1],
    mu * w[2] + ct * t[2] + cs * s[2] };
}

std::array<double, 3> SampleHenyeyGreensteinDirection(
  const std::array<double, 3>& incident, double g, double u1, double u2)
{
  return DirectionFromCosine(incident, SampleHenyeyGreenstein(g, u1), u2);
}

//------------------------------------------------------------------------------
double EvaluatePhaseFunction(PhaseFunctionKind kind, double mu, double g)
{
  switch (kind)
  {
    case PhaseFunctionKind::Isotropic:
      return kInv4Pi;
    case PhaseFunctionKind::Rayleigh:
      return Rayleigh(mu);
    case PhaseFunctionKind::HenyeyGreenstein:
      return HenyeyGreenstein(mu, g);
    case PhaseFunctionKind::CornetteShanks:
    default:
      return CornetteShanks(mu, g);
  }
}

double PhaseFunctionMeanCosine(PhaseFunctionKind kind, double g)
{
  switch (kind)
  {
    case PhaseFunctionKind::Isotropic:
      return 0.0;
    case PhaseFunctionKind::Rayleigh:
      return RayleighMeanCosine();
    case PhaseFunctionKind::HenyeyGreenstein:
      return HenyeyGreensteinMeanCosine(g);
    case PhaseFunctionKind::CornetteShanks:
    default:
      return CornetteShanksMeanCosine(g);
  }
}

//------------------------------------------------------------------------------
void PhaseFunctionMixture::AddComponent(double weight, PhaseFunctionKind kind, double g)
{
  if (!(weight >= 0.0) || !std::isfinite(weight))
  {
    throw std::invalid_argument("nimbus PhaseFunctionMixture: weight must be finite and >= 0");
  }
  g = ClampAsymmetry(g);
  this->RawWeights.push_back(weight);
  this->Components.push_back({ 0.0, kind, g });
  double sum = 0.0;
  for (double w : this->RawWeights)
  {
    sum += w;
  }
  for (std::size_t i = 0; i < this->Components.size(); ++i)
  {
    this->Components[i].weight = sum > 0.0 ? this->RawWeights[i] / sum : 0.0;
  }
}

double PhaseFunctionMixture::Evaluate(double mu) const
{
  double F = 0.0; // 004 Eq. 4
  for (const Component& c : this->Components)
  {
    F += c.weight * EvaluatePhaseFunction(c.kind, mu, c.g);
  }
  return F;
}

double PhaseFunctionMixture::MeanCosine() const
{
  double m = 0.0;
  for (const Component& c : this->Components)
  {
    m += c.weight * PhaseFunctionMeanCosine(c.kind, c.g);
  }
  return m;
}

std::size_t PhaseFunctionMixture::SelectComponent(double u) const
{
  double cumulative = 0.0;
  std::size_t last = this->Components.size();
  for (std::size_t i = 0; i < this->Components.size(); ++i)
  {
    if (this->Components[i].weight <= 0.0)
    {
      continue;
    }
    last = i;
    cumulative += this->Components[i].weight;
    if (u < cumulative)
    {
      return i;
    }
  }
  if (last == this->Components.size())
  {
    throw std::logic_error("nimbus PhaseFunctionMixture: no component with positive weight");
  }
  return last; // u rounding past the last cumulative sum
}

} // namespace nimbus
