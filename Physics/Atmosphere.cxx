#include "Atmosphere.h"
#include "Math.h"

#include "PhaseFunctions.h"

#include <algorithm>
#include <cmath>
#include <queue>
#include <stdexcept>
#include <string>
#include <vector>

namespace nimbus
{

namespace
{

// Relative tolerance of the adaptive quadrature.  The Kronrod estimate is far
// more accurate than the |K15 - G7| error bound, so the actual error is orders
// of magnitude below this (measured < 1e-12 in TestAtmosphere).
constexpr double kRelativeTolerance = 1e-12;
constexpr int kMaxIntervals = 4000;

//------------------------------------------------------------------------------
// Adaptive Gauss-Kronrod 7/15 quadrature (QUADPACK QK15 nodes and weights),
// globally adaptive: always bisects the interval with the largest |K15 - G7|.
struct GkInterval
{
  double a, b, value, error;
  bool operator<(const GkInterval& o) const { return this->error < o.error; }
};

constexpr double kXgk[8] = { 0.991455371120812639206854697526329,
  0.949107912342758524526189684047851, 0.864864423359769072789712788640926,
  0.741531185599394439863864773280788, 0.586087235467691130294144845693013,
  0.405845151377397166906606412076961, 0.207784955007898467600689403773245, 0.0 };
constexpr double kWgk[8] = { 0.022935322010529224963732008058970,
  0.063092092629978553290700663189204, 0.104790010322250183839876322541518,
  0.140653259715525918745189590510238, 0.169004726639267902826583426598550,
  0.190350578064785409913256402421014, 0.204432940075298892414161999234649,
  0.209482141084727828012999174891714 };
// 7-point Gauss weights for the odd Kronrod nodes kXgk[1], [3], [5], [7].
constexpr double kWg[4] = { 0.129484966168869693270611432679082,
  0.279705391489276667901467771423780, 0.381830050505118944950369775488975,
  0.417959183673469387755102040816327 };

template <class F>
GkInterval Gk15(const F& f, double a, double b)
{
  const double c = 0.5 * (a + b);
  const double h = 0.5 * (b - a);
  const double fc = f(c);
  double kronrod = kWgk[7] * fc;
  double gauss = kWg[3] * fc;
  for (int j = 0; j < 7; ++j)
  {
    const double sum = f(c - h * kXgk[j]) + f(c + h * kXgk[j]);
    kronrod += kWgk[j] * sum;
    if (j % 2 == 1)
    {
      gauss += kWg[j / 2] * sum;
    }
  }
  return { a, b, kronrod * h, std::abs((kronrod - gauss) * h) };
}

/// Integral of f over consecutive pieces [breaks[i], breaks[i+1]].
template <class F>
double IntegrateAdaptive(const F& f, const std::vector<double>& breaks)
{
  std::priority_queue<GkInterval> queue;
  double total = 0.0;
  double error = 0.0;
  for (std::size_t i = 0; i + 1 < breaks.size(); ++i)
  {
    if (breaks[i + 1] > breaks[i])
    {
      const GkInterval piece = Gk15(f, breaks[i], breaks[i + 1]);
      total += piece.value;
      error += piece.error;
      queue.push(piece);
    }
  }
  int count = static_cast<int>(queue.size());
  while (!queue.empty() && error > kRelativeTolerance * std::abs(total) && count < kMaxIntervals)
  {
    const GkInterval worst = queue.top();
    queue.pop();
    const double mid = 0.5 * (worst.a + worst.b);
    if (!(mid > worst.a && mid < worst.b))
    {
      break; // cannot bisect further in double precision
    }
    const GkInterval left = Gk15(f, worst.a, mid);
    const GkInterval right = Gk15(f, mid, worst.b);
    total += left.value + right.value - worst.value;
    error += left.error + right.error - worst.error;
    queue.push(left);
    queue.push(right);
    ++count;
  }
  // Re-sum to remove the drift of the running updates.
  double sum = 0.0;
  while (!queue.empty())
  {
    sum += queue.top().value;
    queue.pop();
  }
  return sum;
}

//------------------------------------------------------------------------------
// A ray o + s d (d unit) described by scalars, relative to the earth centre.
struct Ray
{
  Vector3 o;
  Vector3 d;
  double r0; // |o| [m]
  double b;  // dot(o, d) [m]; s* = -b is the point of closest approach
};

// (r0 - R)(r0 + R) = r0^2 - R^2 without cancellation near r0 = R.
double DiffOfSquares(double r0, double R)
{
  return (r0 - R) * (r0 + R);
}

// Altitude along the ray at parameter s, h = r(s) - R with
// r(s)^2 - R^2 = (r0^2 - R^2) + s (2b + s), evaluated as (r^2 - R^2)/(r + R)
// to keep relative accuracy (no subtraction of two ~6.4e6 m numbers).
double AltitudeAlongRay(const Ray& ray, double R, double s)
{
  const double r2MinusR2 = DiffOfSquares(ray.r0, R) + s * (2.0 * ray.b + s);
  const double r = std::sqrt(std::max(0.0, R * R + r2MinusR2));
  return r2MinusR2 / (r + R);
}

// Interval [sIn, sOut] of the full line inside the ball of radius Rb; false if the
// line misses it (or only touches it).
bool BallInterval(const Ray& ray, double Rb, double& sIn, double& sOut)
{
  const double c = DiffOfSquares(ray.r0, Rb);
  const double disc = ray.b * ray.b - c;
  if (!(disc > 0.0))
  {
    return false;
  }
  const double q = -(ray.b + std::copysign(std::sqrt(disc), ray.b)); // stable roots
  double s1 = q;
  double s2 = q != 0.0 ? c / q : 0.0;
  if (s1 > s2)
  {
    std::swap(s1, s2);
  }
  sIn = s1;
  sOut = s2;
  return true;
}

// integral_{s0}^{s1} density(h(s)) ds, split at the closest approach s* = -b and where
// the ray crosses the altitudes `kinks` [m] (where the profile's slope jumps, so the
// adaptive quadrature need not bisect down to them).
template <class Density>
double IntegrateProfile(const Ray& ray, double R, const Density& density, double s0, double s1,
  const std::vector<double>& kinks = {})
{
  if (!(s1 > s0))
  {
    return 0.0;
  }
  std::vector<double> breaks{ s0 };
  const double sStar = -ray.b;
  if (sStar > s0 && sStar < s1)
  {
    breaks.push_back(sStar);
  }
  for (double h : kinks)
  {
    double sIn = 0.0, sOut = 0.0;
    if (BallInterval(ray, R + h, sIn, sOut))
    {
      for (double sk : { sIn, sOut })
      {
        if (sk > s0 && sk < s1)
        {
          breaks.push_back(sk);
        }
      }
    }
  }
  std::sort(breaks.begin() + 1, breaks.end());
  breaks.push_back(s1);
  const auto rho = [&](double s) { return density(AltitudeAlongRay(ray, R, s)); };
  return IntegrateAdaptive(rho, breaks);
}

// integral_{s0}^{s1} exp(-max(h,0)/H) ds.
double IntegrateDensity(const Ray& ray, double R, double H, double s0, double s1)
{
  return IntegrateProfile(
    ray, R, [H](double h) { return std::exp(-std::max(0.0, h) / H); }, s0, s1);
}

// Bruneton 2017's ozone layer: a tent from 10 km to 40 km, 1 at 25 km [relative].
double OzoneTent(double h)
{
  return std::max(0.0, 1.0 - std::abs(h - 25000.0) / 15000.0);
}

// Serdyuchenko et al. 2014, 233 K, 10-nm bin means from 360 nm (bin [360, 370) at
// index 0) to 830 nm, in m^2 per molecule, as tabulated by Bruneton 2017.
constexpr double kOzoneCrossSectionTable[48] = { 1.18e-27, 2.182e-28, 2.818e-28, 6.636e-28,
  1.527e-27, 2.763e-27, 5.52e-27, 8.451e-27, 1.582e-26, 2.316e-26, 3.669e-26, 4.924e-26, 7.752e-26,
  9.016e-26, 1.48e-25, 1.602e-25, 2.139e-25, 2.755e-25, 3.091e-25, 3.5e-25, 4.266e-25, 4.672e-25,
  4.398e-25, 4.701e-25, 5.019e-25, 4.305e-25, 3.74e-25, 3.215e-25, 2.662e-25, 2.238e-25, 1.852e-25,
  1.473e-25, 1.209e-25, 9.423e-26, 7.455e-26, 6.566e-26, 5.105e-26, 4.15e-26, 4.228e-26, 3.237e-26,
  2.451e-26, 2.801e-26, 2.534e-26, 1.624e-26, 1.465e-26, 2.078e-26, 1.383e-26, 7.105e-27 };
constexpr double kDobsonUnitPerSquareMetre = 2.687e20;              // molecules per m^2 per DU
constexpr double kOzoneProfileColumnMetres = 15000.0;               // integral of OzoneTent dh
const std::vector<double> kOzoneKinks{ 10000.0, 25000.0, 40000.0 }; // OzoneTent's corners [m]

Ray MakeRay(const Vector3& o, const Vector3& direction)
{
  const double len = std::sqrt(Dot(direction, direction));
  if (!(len > 0.0) || !std::isfinite(len))
  {
    throw std::invalid_argument("nimbus::Atmosphere: direction is zero or not finite");
  }
  Ray ray;
  ray.o = o;
  ray.d = { direction[0] / len, direction[1] / len, direction[2] / len };
  ray.r0 = std::sqrt(Dot(o, o));
  ray.b = Dot(o, ray.d);
  return ray;
}

void CheckPoint(const Vector3& p)
{
  if (!IsFinite(p))
  {
    throw std::invalid_argument("nimbus::Atmosphere: position is not finite");
  }
}
} // namespace

//------------------------------------------------------------------------------
double AerosolOpticalDepthFromTurbidity(double turbidity)
{
  return kAerosolOpticalDepthPerTurbidity * (turbidity - 1.0);
}

double MieScatteringFromTurbidity(double turbidity, const AtmosphereParameters& a)
{
  if (!std::isfinite(turbidity) || turbidity < 1.0)
  {
    throw std::invalid_argument(
      "nimbus::MieScatteringFromTurbidity: turbidity must be finite and >= 1 (1 = no aerosol)");
  }
  // tau_A(550) = beta_M,ext(550) H_M;  beta_M,s = albedo beta_M,ext.
  return a.MieAlbedo * AerosolOpticalDepthFromTurbidity(turbidity) / a.MieScaleHeightMetres;
}

double TurbidityFromMieScattering(double mie, const AtmosphereParameters& a)
{
  if (!std::isfinite(mie) || mie < 0.0)
  {
    throw std::invalid_argument(
      "nimbus::TurbidityFromMieScattering: the scattering coefficient must be finite and >= 0");
  }
  const double opticalDepth = mie * a.MieScaleHeightMetres / a.MieAlbedo;
  return 1.0 + opticalDepth / kAerosolOpticalDepthPerTurbidity;
}

AtmosphereParameters ClearSkyAtmosphere(double turbidity)
{
  if (!(std::isfinite(turbidity) && turbidity >= kMinTurbidity && turbidity <= kMaxTurbidity))
  {
    throw std::invalid_argument("nimbus::ClearSkyAtmosphere: turbidity must be in [" +
      std::to_string(kMinTurbidity) + ", " + std::to_string(kMaxTurbidity) + "]");
  }
  AtmosphereParameters a;
  a.MieAngstromExponent = 1.3;
  // Cornette-Shanks g whose mean cosine is the measured 0.70 (bisection: the mean
  // cosine grows monotonically with g).
  double lo = 0.0, hi = 0.99;
  for (int i = 0; i < 60; ++i)
  {
    const double mid = 0.5 * (lo + hi);
    (CornetteShanksMeanCosine(mid) < 0.70 ? lo : hi) = mid;
  }
  a.MieG = 0.5 * (lo + hi);
  a.OzoneDobsonUnits = 300.0;
  a.MieScatteringPerMetre = MieScatteringFromTurbidity(turbidity, a);
  return a;
}

double OzoneCrossSection(double lambdaNm)
{
  // Bin i covers [360 + 10 i, 370 + 10 i) nm: its value sits at the centre 365 + 10 i.
  const double u = std::min(47.0, std::max(0.0, (lambdaNm - 365.0) / 10.0));
  const int i = std::min(46, static_cast<int>(u));
  const double f = u - i;
  return (1.0 - f) * kOzoneCrossSectionTable[i] + f * kOzoneCrossSectionTable[i + 1];
}

//------------------------------------------------------------------------------
Atmosphere::Atmosphere(const AtmosphereParameters& p)
  : Parameters(p)
{
  const bool ok = std::isfinite(p.EarthRadiusMetres) && std::isfinite(p.TopRadiusMetres) &&
    p.EarthRadiusMetres > 0.0 && p.TopRadiusMetres > p.EarthRadiusMetres &&
    std::isfinite(p.RayleighScaleHeightMetres) && p.RayleighScaleHeightMetres > 0.0 &&
    std::isfinite(p.MieScaleHeightMetres) && p.MieScaleHeightMetres > 0.0 &&
    std::isfinite(p.RayleighScatteringPerMetre) && p.RayleighScatteringPerMetre >= 0.0 &&
    std::isfinite(p.MieScatteringPerMetre) && p.MieScatteringPerMetre >= 0.0 && p.MieAlbedo > 0.0 &&
    p.MieAlbedo <= 1.0 && !std::isnan(p.MieG) && std::isfinite(p.MieAngstromExponent) &&
    std::abs(p.MieAngstromExponent) <= 4.0 && std::isfinite(p.OzoneDobsonUnits) &&
    p.OzoneDobsonUnits >= 0.0 && p.OzoneDobsonUnits <= 2000.0;
  if (!ok)
  {
    throw std::invalid_argument("nimbus::Atmosphere: invalid AtmosphereParameters (radii, "
                                "scale heights > 0, coefficients >= 0, albedo in (0, 1], "
                                "|MieAngstromExponent| <= 4, "
                                "OzoneDobsonUnits in [0, 2000])");
  }
}

double Atmosphere::Altitude(const Vector3& p) const
{
  return std::sqrt(Dot(p, p)) - this->Parameters.EarthRadiusMetres;
}

double Atmosphere::Density(double altitude, double scaleHeight) const
{
  const double thickness = this->Parameters.TopRadiusMetres - this->Parameters.EarthRadiusMetres;
  if (altitude > thickness)
  {
    return 0.0;
  }
  return std::exp(-std::max(0.0, altitude) / scaleHeight);
}

double Atmosphere::RayleighScattering(double lambdaNm) const
{
  const double x = 550.0 / lambdaNm;
  return this->Parameters.RayleighScatteringPerMetre * (x * x) * (x * x);
}

double Atmosphere::MieScattering(double lambdaNm) const
{
  const double alpha = this->Parameters.MieAngstromExponent;
  return alpha == 0.0 ? this->Parameters.MieScatteringPerMetre
                      : this->Parameters.MieScatteringPerMetre * std::pow(550.0 / lambdaNm, alpha);
}

double Atmosphere::MieExtinction(double lambdaNm) const
{
  return this->MieScattering(lambdaNm) / this->Parameters.MieAlbedo;
}

double Atmosphere::OzoneAbsorption(double lambdaNm) const
{
  return this->Parameters.OzoneDobsonUnits * kDobsonUnitPerSquareMetre / kOzoneProfileColumnMetres *
    OzoneCrossSection(lambdaNm);
}

double Atmosphere::OzoneDensity(double altitude) const
{
  return this->Parameters.OzoneDobsonUnits > 0.0 ? OzoneTent(altitude) : 0.0;
}

double Atmosphere::RayleighPhase(double mu) const
{
  return Rayleigh(mu);
}

double Atmosphere::MiePhase(double mu) const
{
  return CornetteShanks(mu, this->Parameters.MieG);
}

//------------------------------------------------------------------------------
double Atmosphere::OpticalLength(const Vector3& p0, const Vector3& p1, double H) const
{
  CheckPoint(p0);
  CheckPoint(p1);
  if (!(H > 0.0) || !std::isfinite(H))
  {
    throw std::invalid_argument("nimbus::Atmosphere::OpticalLength: scale height must be > 0");
  }
  const Vector3 delta = { p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2] };
  const double length = std::sqrt(Dot(delta, delta));
  if (!(length > 0.0))
  {
    return 0.0;
  }
  const Ray ray = MakeRay(p0, delta);
  double sIn = 0.0, sOut = 0.0;
  if (!BallInterval(ray, this->Parameters.TopRadiusMetres, sIn, sOut))
  {
    return 0.0;
  }
  // Clip the segment [0, length] to the atmosphere ball (density 0 above the top).
  return IntegrateDensity(
    ray, this->Parameters.EarthRadiusMetres, H, std::max(0.0, sIn), std::min(length, sOut));
}

double Atmosphere::OzoneOpticalLength(const Vector3& p0, const Vector3& p1) const
{
  CheckPoint(p0);
  CheckPoint(p1);
  if (!(this->Parameters.OzoneDobsonUnits > 0.0))
  {
    return 0.0;
  }
  const Vector3 delta = { p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2] };
  const double length = std::sqrt(Dot(delta, delta));
  if (!(length > 0.0))
  {
    return 0.0;
  }
  const Ray ray = MakeRay(p0, delta);
  double sIn = 0.0, sOut = 0.0;
  if (!BallInterval(ray, this->Parameters.TopRadiusMetres, sIn, sOut))
  {
    return 0.0;
  }
  return IntegrateProfile(ray, this->Parameters.EarthRadiusMetres, OzoneTent, std::max(0.0, sIn),
    std::min(length, sOut), kOzoneKinks);
}

OpticalLengths Atmosphere::OpticalLengthsToTop(const Vector3& p, const Vector3& d) const
{
  CheckPoint(p);
  const double R = this->Parameters.EarthRadiusMetres;
  Ray ray = MakeRay(p, d);
  if (ray.r0 < R)
  {
    // Below the ground: clamp radially onto the ground (the earth centre maps to
    // the ground point along d).
    const Vector3 up =
      ray.r0 > 0.0 ? Vector3{ p[0] / ray.r0, p[1] / ray.r0, p[2] / ray.r0 } : ray.d;
    ray.o = { R * up[0], R * up[1], R * up[2] };
    ray.r0 = R;
    ray.b = R * Dot(up, ray.d);
  }

  OpticalLengths result;
  double sIn = 0.0, sOut = 0.0;
  if (!BallInterval(ray, this->Parameters.TopRadiusMetres, sIn, sOut) || !(sOut > 0.0))
  {
    return result; // misses the atmosphere, or above it looking away
  }
  double sBegin = std::max(0.0, sIn);
  double sEnd = sOut;

  // Ground: hit iff the ray moves strictly inward (b < 0) and crosses the
  // sphere r = R (discriminant > 0; a tangent ray only grazes it).
  const double cGround = DiffOfSquares(ray.r0, R); // >= 0 after the clamp
  const double discGround = ray.b * ray.b - cGround;
  if (ray.b < 0.0 && discGround > 0.0)
  {
    // Nearest root without cancellation: s = c / (-b + sqrt(disc)).
    const double sGround = cGround / (-ray.b + std::sqrt(discGround));
    result.HitsGround = true;
    sEnd = std::min(sEnd, sGround);
  }
  sBegin = std::min(sBegin, sEnd);

  result.RayleighLengthMetres =
    IntegrateDensity(ray, R, this->Parameters.RayleighScaleHeightMetres, sBegin, sEnd);
  result.MieLengthMetres =
    IntegrateDensity(ray, R, this->Parameters.MieScaleHeightMetres, sBegin, sEnd);
  if (this->Parameters.OzoneDobsonUnits > 0.0)
  {
    result.OzoneLengthMetres = IntegrateProfile(ray, R, OzoneTent, sBegin, sEnd, kOzoneKinks);
  }
  return result;
}

double Atmosphere::OpticalDepth(const OpticalLengths& lengths, double lambdaNm) const
{
  return this->RayleighScattering(lambdaNm) * lengths.RayleighLengthMetres +
    this->MieExtinction(lambdaNm) * lengths.MieLengthMetres +
    (lengths.OzoneLengthMetres > 0.0 ? this->OzoneAbsorption(lambdaNm) * lengths.OzoneLengthMetres
                                     : 0.0);
}

double Atmosphere::Transmittance(const OpticalLengths& lengths, double lambdaNm) const
{
  if (lengths.HitsGround)
  {
    return 0.0;
  }
  return std::exp(-this->OpticalDepth(lengths, lambdaNm));
}

double Atmosphere::TransmittanceToTop(const Vector3& p, const Vector3& d, double lambdaNm) const
{
  return this->Transmittance(this->OpticalLengthsToTop(p, d), lambdaNm);
}

double Atmosphere::TransmittanceBetween(const Vector3& p0, const Vector3& p1, double lambdaNm) const
{
  OpticalLengths lengths;
  lengths.RayleighLengthMetres =
    this->OpticalLength(p0, p1, this->Parameters.RayleighScaleHeightMetres);
  lengths.MieLengthMetres = this->OpticalLength(p0, p1, this->Parameters.MieScaleHeightMetres);
  lengths.OzoneLengthMetres = this->OzoneOpticalLength(p0, p1);
  return this->Transmittance(lengths, lambdaNm);
}

double DistanceToTopOfAtmosphere(double r, double mu, double topRadius)
{
  const double b = r * mu;
  const double c = (r - topRadius) * (r + topRadius);
  const double disc = b * b - c;
  if (disc < 0.0)
  {
    return 0.0;
  }
  return std::max(-b + std::sqrt(disc), 0.0);
}

namespace
{
// integral_0^d exp(-(h + s c)/H) ds for h >= 0 (the exponential layer alone), in
// closed form, with the series for |x| < 1e-2.
double ExponentialLayerLength(double h, double c, double d, double H)
{
  const double x = d * c / H;
  const double factor = std::abs(x) < 1e-2 ? d * (1.0 - x / 2.0 + x * x / 6.0 - x * x * x / 24.0)
                                           : H * (1.0 - std::exp(-x)) / c;
  return std::exp(-h / H) * factor;
}
}

double FlatLayerOpticalLength(
  double altitudeMetres, double cosZenith, double distanceMetres, double scaleHeightMetres)
{
  // Below sea level the density is the sea level's (Atmosphere::Density): the path
  // splits where it crosses h = 0 into a part of density 1 and an exponential part.
  double below = 0.0;
  double start = altitudeMetres;
  double length = distanceMetres;
  if (altitudeMetres < 0.0)
  {
    if (!(cosZenith > 0.0))
    {
      return distanceMetres; // never rises above sea level
    }
    below = std::min(distanceMetres, -altitudeMetres / cosZenith);
    start = 0.0;
    length = distanceMetres - below;
  }
  else if (cosZenith < 0.0)
  {
    length = std::min(distanceMetres, altitudeMetres / -cosZenith);
    below = distanceMetres - length;
  }
  return below + ExponentialLayerLength(start, cosZenith, length, scaleHeightMetres);
}

} // namespace nimbus
