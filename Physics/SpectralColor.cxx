#include "SpectralColor.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace nimbus
{

namespace
{
// Piecewise Gaussian of Wyman, Sloan & Shirley 2013: exp(-((x - mu)/sigma)^2 / 2)
// with sigma = sigma1 for x < mu and sigma2 otherwise (all in nm).
double PiecewiseGaussian(double x, double mu, double sigma1, double sigma2)
{
  const double t = (x - mu) / (x < mu ? sigma1 : sigma2);
  return std::exp(-0.5 * t * t);
}

// Simpson step used to integrate hat-function x CMF products [nm].  The CMF fit
// has a second-derivative jump at each lobe centre; with 0.05 nm steps the
// quadrature error is < 1e-9 relative.
constexpr double kSimpsonStepNm = 0.05;

// integral_a^b f by composite Simpson with about kSimpsonStepNm steps.
template <class F>
std::array<double, 3> Simpson3(const F& f, double a, double b)
{
  int m = static_cast<int>(std::ceil((b - a) / kSimpsonStepNm));
  m += m % 2;
  m = std::max(m, 2);
  const double h = (b - a) / m;
  std::array<double, 3> sum = { 0.0, 0.0, 0.0 };
  for (int k = 0; k <= m; ++k)
  {
    const double w = (k == 0 || k == m) ? 1.0 : (k % 2 == 1 ? 4.0 : 2.0);
    const std::array<double, 3> v = f(a + k * h);
    for (int c = 0; c < 3; ++c)
    {
      sum[c] += w * v[c];
    }
  }
  for (double& s : sum)
  {
    s *= h / 3.0;
  }
  return sum;
}
} // namespace

//------------------------------------------------------------------------------
// Wyman, Sloan & Shirley, JCGT 2(2) 2013, Eq. 4 (multi-lobe fit of CIE 1931 2 deg).
double CieXBar1931(double lambda)
{
  return 1.056 * PiecewiseGaussian(lambda, 599.8, 37.9, 31.0) +
    0.362 * PiecewiseGaussian(lambda, 442.0, 16.0, 26.7) -
    0.065 * PiecewiseGaussian(lambda, 501.1, 20.4, 26.2);
}

double CieYBar1931(double lambda)
{
  return 0.821 * PiecewiseGaussian(lambda, 568.8, 46.9, 40.5) +
    0.286 * PiecewiseGaussian(lambda, 530.9, 16.3, 31.1);
}

double CieZBar1931(double lambda)
{
  return 1.217 * PiecewiseGaussian(lambda, 437.0, 11.8, 36.0) +
    0.681 * PiecewiseGaussian(lambda, 459.0, 26.0, 13.8);
}

std::array<double, 3> CieXyzBar1931(double lambda)
{
  return { CieXBar1931(lambda), CieYBar1931(lambda), CieZBar1931(lambda) };
}

std::array<double, 3> XyzToLinearSrgb(const std::array<double, 3>& xyz)
{
  // IEC 61966-2-1:1999 XYZ -> linear RGB (D65).
  const double X = xyz[0], Y = xyz[1], Z = xyz[2];
  return { 3.2406 * X - 1.5372 * Y - 0.4986 * Z, -0.9689 * X + 1.8758 * Y + 0.0415 * Z,
    0.0557 * X - 0.2040 * Y + 1.0570 * Z };
}

double SrgbEncode(double linear)
{
  const double c = std::min(1.0, std::max(0.0, linear)); // also maps NaN -> 0
  return c <= 0.0031308 ? 12.92 * c : 1.055 * std::pow(c, 1.0 / 2.4) - 0.055;
}

double SrgbDecode(double encoded)
{
  const double c = std::min(1.0, std::max(0.0, encoded)); // also maps NaN -> 0
  return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}

std::array<double, 2> XyzToChromaticity(const std::array<double, 3>& xyz)
{
  const double sum = xyz[0] + xyz[1] + xyz[2];
  if (sum == 0.0)
  {
    return { 0.0, 0.0 };
  }
  return { xyz[0] / sum, xyz[1] / sum };
}

double PlanckSpectralRadiance(double lambdaNm, double T)
{
  constexpr double h = 6.62607015e-34;   // Planck constant [J s]
  constexpr double c = 299792458.0;      // speed of light [m/s]
  constexpr double kB = 1.380649e-23;    // Boltzmann constant [J/K]
  const double lambda = lambdaNm * 1e-9; // [m]
  const double l5 = std::pow(lambda, 5);
  // B = 2 h c^2 / lambda^5 / (exp(h c / (lambda kB T)) - 1)  [W m^-2 sr^-1 m^-1]
  const double B = 2.0 * h * c * c / l5 / std::expm1(h * c / (lambda * kB * T));
  return B * 1e-9; // per nm
}

//------------------------------------------------------------------------------
SpectralSamples::SpectralSamples(
  int n, SpectralReconstruction reconstruction, double lambdaMin, double lambdaMax)
  : Reconstruction(reconstruction)
{
  if (n < 2 || !(lambdaMin > 0.0) || !(lambdaMax > lambdaMin) || !std::isfinite(lambdaMax))
  {
    throw std::invalid_argument(
      "nimbus::SpectralSamples: need n >= 2 and 0 < lambdaMin < lambdaMax");
  }
  const double h = (lambdaMax - lambdaMin) / (n - 1); // sample spacing [nm]
  for (int i = 0; i < n; ++i)
  {
    this->Wavelengths.push_back(i == n - 1 ? lambdaMax : lambdaMin + i * h);
  }
  this->Weights.assign(n, { 0.0, 0.0, 0.0 });

  // Natural cubic spline: second derivatives M = K S (K is n x n; M_0 = M_{n-1} = 0),
  // from h/6 M_{i-1} + 2h/3 M_i + h/6 M_{i+1} = (S_{i+1} - 2 S_i + S_{i-1})/h.
  // Column j of K is the spline of the unit vector e_j (Thomas algorithm).
  std::vector<std::vector<double>> K(n, std::vector<double>(n, 0.0));
  if (reconstruction == SpectralReconstruction::NaturalCubicSpline && n > 2)
  {
    for (int j = 0; j < n; ++j)
    {
      std::vector<double> diag(n, 2.0 * h / 3.0), rhs(n, 0.0);
      for (int i = 1; i < n - 1; ++i)
      {
        rhs[i] = ((i + 1 == j) - 2.0 * (i == j) + (i - 1 == j)) / h;
      }
      const double off = h / 6.0;
      for (int i = 2; i < n - 1; ++i)
      {
        const double m = off / diag[i - 1];
        diag[i] -= m * off;
        rhs[i] -= m * rhs[i - 1];
      }
      for (int i = n - 2; i >= 1; --i)
      {
        K[i][j] = (rhs[i] - (i + 1 < n - 1 ? off * K[i + 1][j] : 0.0)) / diag[i];
      }
    }
  }

  // On [l_i, l_{i+1}] with A = (l_{i+1} - l)/h, B = 1 - A the interpolant is
  //   A S_i + B S_{i+1} + h^2/6 ((A^3 - A) M_i + (B^3 - B) M_{i+1})
  // (the linear hat functions alone for PiecewiseLinear); weights are the
  // integrals of these basis functions times the CMFs.
  double yIntegral = 0.0;
  for (int i = 0; i + 1 < n; ++i)
  {
    const double a = this->Wavelengths[i];
    const double b = this->Wavelengths[i + 1];
    const double len = b - a;
    const auto basisTimesCmf = [&](int which)
    {
      return [&, which](double l)
      {
        const std::array<double, 3> cmf = CieXyzBar1931(l);
        const double A = (b - l) / len;
        const double B = 1.0 - A;
        const double phi = which == 0 ? A : (which == 1 ? A * A * A - A : B * B * B - B);
        return std::array<double, 3>{ phi * cmf[0], phi * cmf[1], phi * cmf[2] };
      };
    };
    const std::array<double, 3> all = Simpson3(CieXyzBar1931, a, b);
    const std::array<double, 3> intA = Simpson3(basisTimesCmf(0), a, b);
    for (int c = 0; c < 3; ++c)
    {
      this->Weights[i][c] += intA[c];
      this->Weights[i + 1][c] += all[c] - intA[c]; // B = 1 - A
    }
    if (reconstruction == SpectralReconstruction::NaturalCubicSpline && n > 2)
    {
      const std::array<double, 3> intA3 = Simpson3(basisTimesCmf(1), a, b);
      const std::array<double, 3> intB3 = Simpson3(basisTimesCmf(2), a, b);
      for (int j = 0; j < n; ++j)
      {
        for (int c = 0; c < 3; ++c)
        {
          this->Weights[j][c] += len * len / 6.0 * (intA3[c] * K[i][j] + intB3[c] * K[i + 1][j]);
        }
      }
    }
    yIntegral += all[1];
  }
  for (auto& w : this->Weights)
  {
    for (double& v : w)
    {
      v /= yIntegral;
    }
  }
}

std::array<double, 3> SpectralSamples::ToXyz(const std::vector<double>& spectrum) const
{
  if (spectrum.size() != this->Wavelengths.size())
  {
    throw std::invalid_argument("nimbus::SpectralSamples::ToXyz: spectrum size mismatch");
  }
  std::array<double, 3> xyz = { 0.0, 0.0, 0.0 };
  for (std::size_t i = 0; i < spectrum.size(); ++i)
  {
    for (int c = 0; c < 3; ++c)
    {
      xyz[c] += spectrum[i] * this->Weights[i][c];
    }
  }
  return xyz;
}

std::array<double, 3> SpectralSamples::ToLinearSrgb(const std::vector<double>& spectrum) const
{
  return XyzToLinearSrgb(this->ToXyz(spectrum));
}

} // namespace nimbus
