// Airlight of a point light (Sun, Ramamoorthi, Narasimhan & Nayar 2005, §3): see
// Airlight.h for the formulas, the derivation of the finite ray's limits and the extremes.
#include "Airlight.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>
#include <stdexcept>
#include <vector>

namespace nimbus
{
namespace
{
constexpr double kInfinity = std::numeric_limits<double>::infinity();
constexpr double kEpsilon = std::numeric_limits<double>::epsilon();

// Gauss-Kronrod (7, 15) on [-1, 1] (Piessens et al. 1983, QUADPACK's qk15): the
// Kronrod nodes x_k >= 0 (x_1, x_3, x_5, x_7 are the 7-point Gauss nodes) and weights.
constexpr double kKronrodNodes[8] = { 0.991455371120812639206854697526329,
  0.949107912342758524526189684047851, 0.864864423359769072789712788640926,
  0.741531185599394439863864773280788, 0.586087235467691130294144845693013,
  0.405845151377397166906606412076961, 0.207784955007898467600689403773245, 0.0 };
constexpr double kKronrodWeights[8] = { 0.022935322010529224963732008058970,
  0.063092092629978553290700663189204, 0.104790010322250183839876322541518,
  0.140653259715525918745189590510238, 0.169004726639267902826583426598550,
  0.190350578064785409913256402421014, 0.204432940075298892414161999234649,
  0.209482141084727828012999174891714 };
constexpr double kGaussWeights[4] = { 0.129484966168869693270611432679082,
  0.279705391489276667901467771423780, 0.381830050505118944950369775488975,
  0.417959183673469387755102040816327 };

struct Interval
{
  double A, B, Value, Error;
  bool operator<(const Interval& other) const { return this->Error < other.Error; }
};

template <class Function>
Interval Kronrod(const Function& f, double a, double b)
{
  const double center = 0.5 * (a + b), half = 0.5 * (b - a);
  const double fc = f(center);
  double kronrod = kKronrodWeights[7] * fc, gauss = kGaussWeights[3] * fc;
  double magnitude = kKronrodWeights[7] * std::abs(fc);
  for (int k = 0; k < 7; ++k)
  {
    const double f1 = f(center - half * kKronrodNodes[k]);
    const double f2 = f(center + half * kKronrodNodes[k]);
    kronrod += kKronrodWeights[k] * (f1 + f2);
    magnitude += kKronrodWeights[k] * (std::abs(f1) + std::abs(f2));
    if (k % 2 == 1)
    {
      gauss += kGaussWeights[k / 2] * (f1 + f2);
    }
  }
  const double h = std::abs(half);
  // |K - G| bounds the error of the 7-point rule, hence (very pessimistically) of the
  // 15-point one; below 50 eps of the integral of |f| it is rounding and is not chased.
  const double error = std::max(std::abs(kronrod - gauss) * h, 50.0 * kEpsilon * magnitude * h);
  return { a, b, kronrod * half, error };
}

// Globally adaptive Gauss-Kronrod (7, 15): splits the interval of largest estimated
// error until the total estimate is below relativeTolerance x |integral| (or the
// intervals can no longer be split in double precision, or 20000 of them).
template <class Function>
double Integrate(const Function& f, double a, double b, double relativeTolerance)
{
  if (!(b > a))
  {
    return 0.0;
  }
  std::priority_queue<Interval> queue;
  std::vector<Interval> done;
  Interval first = Kronrod(f, a, b);
  double value = first.Value, error = first.Error;
  queue.push(first);
  for (int splits = 0; splits < 20000 && !queue.empty(); ++splits)
  {
    if (error <= relativeTolerance * std::abs(value))
    {
      break;
    }
    const Interval worst = queue.top();
    queue.pop();
    const double middle = 0.5 * (worst.A + worst.B);
    if (!(middle > worst.A && middle < worst.B) ||
      worst.B - worst.A <= 4.0 * kEpsilon * std::max(std::abs(worst.A), std::abs(worst.B)))
    {
      done.push_back(worst); // as fine as double precision allows
      error -= worst.Error;
      continue;
    }
    const Interval left = Kronrod(f, worst.A, middle), right = Kronrod(f, middle, worst.B);
    value += left.Value + right.Value - worst.Value;
    error += left.Error + right.Error - worst.Error;
    queue.push(left);
    queue.push(right);
  }
  double sum = 0.0; // summed afresh: the running value carries the subtractions' rounding
  for (const Interval& interval : done)
  {
    sum += interval.Value;
  }
  while (!queue.empty())
  {
    sum += queue.top().Value;
    queue.pop();
  }
  return sum;
}

constexpr double kTolerance = 1e-13;

void CheckMedium(const AirlightMedium& medium, double intensity, double rayLength)
{
  if (!(medium.ScatteringPerMetre >= 0.0) || !std::isfinite(medium.ScatteringPerMetre) ||
    !(medium.ExtinctionPerMetre >= 0.0) || !std::isfinite(medium.ExtinctionPerMetre))
  {
    throw std::invalid_argument("airlight: the scattering and extinction coefficients must be "
                                "finite and non-negative (1/m)");
  }
  if (!std::isfinite(intensity))
  {
    throw std::invalid_argument("airlight: the light's intensity must be finite");
  }
  if (!(rayLength >= 0.0))
  {
    throw std::invalid_argument("airlight: the ray's length must be >= 0 (m; +inf: the whole ray)");
  }
}

// K = integral over x in [0, t] of exp(-sigma_t (d + x)) / d^2 dx [1/m], the light at
// distance `along` along the ray and `h` >= 0 from it (D^2 = along^2 + h^2): the
// airlight is sigma_s I / (4 pi) K. The closed form of Airlight.h.
double PathIntegral(double sigmaT, double along, double h, double distance, double t)
{
  if (t == 0.0)
  {
    return 0.0;
  }
  if (h == 0.0)
  {
    if (distance == 0.0 || (along > 0.0 && t >= distance))
    {
      return kInfinity; // the segment passes through the light: 1/d^2 is not integrable
    }
    if (along > 0.0)
    {
      // Ahead, beyond the segment's end: d + x = D all along.
      return std::exp(-sigmaT * distance) * t / (distance * (distance - t));
    }
    // Behind (gamma = pi): the limit h -> 0 of the integral in beta, beta = h eta.
    if (sigmaT == 0.0)
    {
      return std::isinf(t) ? 1.0 / distance : t / (distance * (distance + t));
    }
    const double eta0 = 0.5 / distance, eta1 = std::isinf(t) ? 0.0 : 0.5 / (distance + t);
    return 2.0 *
      Integrate([&](double eta) { return std::exp(-sigmaT * (1.0 / eta - distance)); }, eta1, eta0,
        kTolerance);
  }
  // beta(x) = atan2(h, x - D cos gamma) / 2, from beta0 (x = 0) down to beta1 (x = t).
  const double beta0 = 0.5 * std::atan2(h, -along);
  // beta0 - beta1 = atan2(h t, D^2 - t D cos gamma) / 2 (the angle between the two
  // ends seen from the light, halved) with D^2 = along^2 + h^2 and both arguments
  // divided by t: no subtraction but the exact along - t, no overflow for long rays.
  const double width =
    std::isinf(t) ? beta0 : 0.5 * std::atan2(h, along * ((along - t) / t) + h * (h / t));
  if (sigmaT == 0.0)
  {
    return 2.0 * width / h; // F(0, v) = v
  }
  // exp(-sigma_t D cos gamma) [F(A1, v1) - F(A1, v0)] as one integral, s = beta0 - beta.
  const double integral = Integrate([&](double s)
    { return std::exp(-sigmaT * (along + h / std::tan(std::max(beta0 - s, 0.0)))); },
    0.0, width, kTolerance);
  return 2.0 * integral / h;
}

double Airlight(const AirlightMedium& medium, double intensity, double along, double h,
  double distance, double rayLength)
{
  if (medium.ScatteringPerMetre == 0.0 || intensity == 0.0 || rayLength == 0.0)
  {
    return 0.0;
  }
  const double k = PathIntegral(medium.ExtinctionPerMetre, along, h, distance, rayLength);
  return medium.ScatteringPerMetre * intensity / (4.0 * kPi) * k;
}
} // namespace

double AirlightF(double u, double v)
{
  if (!(u >= 0.0) || !std::isfinite(u) || !(v >= 0.0) || !(v <= 0.5 * kPi))
  {
    throw std::invalid_argument("AirlightF(u, v): u must be finite and >= 0, v in [0, pi/2]");
  }
  if (u == 0.0)
  {
    return v;
  }
  return Integrate([u](double xi) { return std::exp(-u * std::tan(xi)); }, 0.0, v, kTolerance);
}

double PointLightAirlight(const AirlightMedium& medium, double intensity, double distanceToLight,
  double gamma, double rayLength)
{
  CheckMedium(medium, intensity, rayLength);
  if (!(distanceToLight >= 0.0) || !std::isfinite(distanceToLight))
  {
    throw std::invalid_argument("airlight: the distance to the light must be finite and >= 0 (m)");
  }
  if (!(gamma >= 0.0) || !(gamma <= kPi))
  {
    throw std::invalid_argument("airlight: the angle to the light must be in [0, pi] (rad)");
  }
  return Airlight(medium, intensity, distanceToLight * std::cos(gamma),
    distanceToLight * std::sin(gamma), distanceToLight, rayLength);
}

double PointLightAirlight(const AirlightMedium& medium, double intensity,
  const Vector3& lightFromViewer, const Vector3& rayDirection, double rayLength)
{
  CheckMedium(medium, intensity, rayLength);
  if (!IsFinite(lightFromViewer))
  {
    throw std::invalid_argument("airlight: the light's position must be finite (m)");
  }
  const Vector3 w = Normalized(rayDirection); // throws for a zero or non-finite direction
  return Airlight(medium, intensity, Dot(lightFromViewer, w), Length(Cross(lightFromViewer, w)),
    Length(lightFromViewer), rayLength);
}

double PointLightAirlightByQuadrature(const AirlightMedium& medium, double intensity,
  double distanceToLight, double gamma, double rayLength, double relativeTolerance)
{
  CheckMedium(medium, intensity, rayLength);
  if (!(distanceToLight >= 0.0) || !std::isfinite(distanceToLight) || !(gamma >= 0.0) ||
    !(gamma <= kPi) || !(relativeTolerance > 0.0))
  {
    throw std::invalid_argument("airlight quadrature: invalid distance, angle or tolerance");
  }
  if (medium.ScatteringPerMetre == 0.0 || intensity == 0.0 || rayLength == 0.0)
  {
    return 0.0;
  }
  const double sigmaT = medium.ExtinctionPerMetre;
  const double along = distanceToLight * std::cos(gamma);
  const double h = distanceToLight * std::sin(gamma);
  const double closest = std::clamp(along, 0.0, rayLength); // the closest approach on the segment
  if (h == 0.0 && along == closest)
  {
    return kInfinity;
  }
  // The integrand of the paper's integral over x, d computed from (x - D cos gamma, h).
  auto integrand = [&](double x)
  {
    const double d2 = (x - along) * (x - along) + h * h;
    return std::exp(-sigmaT * (std::sqrt(d2) + x)) / d2;
  };
  double k = Integrate(integrand, 0.0, closest, relativeTolerance);
  if (std::isfinite(rayLength))
  {
    k += Integrate(integrand, closest, rayLength, relativeTolerance);
  }
  else
  {
    // [closest, X] and the tail x = X + X s / (1 - s), s in [0, 1).
    const double x = closest + distanceToLight;
    k += Integrate(integrand, closest, x, relativeTolerance);
    k += Integrate(
      [&](double s)
      {
        const double r = 1.0 / (1.0 - s);
        return integrand(x + x * s * r) * x * r * r;
      },
      0.0, 1.0, relativeTolerance);
  }
  return medium.ScatteringPerMetre * intensity / (4.0 * kPi) * k;
}

} // namespace nimbus
