// Preetham, Shirley & Smits 1999, Appendix A.2 (formulas and coefficients in PreethamSky.h).
#include "PreethamSky.h"

#include "Math.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace nimbus
{

namespace
{
// Perez et al. 1993's distribution F(theta, gamma), coefficients c = {A, B, C, D, E}.
double Perez(const double c[5], double viewZenith, double gamma)
{
  const double cosTheta = std::max(std::cos(viewZenith), 1e-4); // just above the horizon
  const double cosGamma = std::cos(gamma);
  return (1.0 + c[0] * std::exp(c[1] / cosTheta)) *
    (1.0 + c[2] * std::exp(c[3] * gamma) + c[4] * cosGamma * cosGamma);
}
} // namespace

double PreethamZenithLuminance(double turbidity, double sunZenith)
{
  const double chi = (4.0 / 9.0 - turbidity / 120.0) * (kPi - 2.0 * sunZenith);
  return (4.0453 * turbidity - 4.9710) * std::tan(chi) - 0.2155 * turbidity + 2.4192;
}

PreethamSky::PreethamSky(double turbidity, double sunZenith)
  : Turbidity(turbidity)
  , SunZenith(sunZenith)
{
  if (!(std::isfinite(turbidity) && turbidity >= 1.7 && turbidity <= 20.0))
  {
    throw std::invalid_argument(
      "nimbus::PreethamSky: turbidity must be in [1.7, 20] (fitted over [2, 10])");
  }
  if (!(std::isfinite(sunZenith) && sunZenith >= 0.0 && sunZenith <= 0.5 * kPi))
  {
    throw std::invalid_argument("nimbus::PreethamSky: sun zenith angle must be in [0, pi/2] rad");
  }
  const double T = turbidity;
  // Appendix A.2, distribution coefficients (A, B, C, D, E) linear in T.
  const double table[3][5][2] = {
    { { 0.1787, -1.4630 }, { -0.3554, 0.4275 }, { -0.0227, 5.3251 }, { 0.1206, -2.5771 },
      { -0.0670, 0.3703 } },
    { { -0.0193, -0.2592 }, { -0.0665, 0.0008 }, { -0.0004, 0.2125 }, { -0.0641, -0.8989 },
      { -0.0033, 0.0452 } },
    { { -0.0167, -0.2608 }, { -0.0950, 0.0092 }, { -0.0079, 0.2102 }, { -0.0441, -1.6537 },
      { -0.0109, 0.0529 } },
  };
  for (int k = 0; k < 3; ++k)
  {
    for (int i = 0; i < 5; ++i)
    {
      this->Coefficients[k][i] = table[k][i][0] * T + table[k][i][1];
    }
    this->Normalisation[k] = Perez(this->Coefficients[k], 0.0, sunZenith);
  }
  this->ZenithY = PreethamZenithLuminance(T, sunZenith);
  // Appendix A.2, zenith chromaticity: [T^2 T 1] M [theta^3 theta^2 theta 1]^T.
  const double Mx[3][4] = { { 0.00166, -0.00375, 0.00209, 0.0 },
    { -0.02903, 0.06377, -0.03202, 0.00394 }, { 0.11693, -0.21196, 0.06052, 0.25886 } };
  const double My[3][4] = { { 0.00275, -0.00610, 0.00317, 0.0 },
    { -0.04214, 0.08970, -0.04153, 0.00516 }, { 0.15346, -0.26756, 0.06670, 0.26688 } };
  const double t = sunZenith;
  const double theta[4] = { t * t * t, t * t, t, 1.0 };
  const double tv[3] = { T * T, T, 1.0 };
  this->ZenithX = 0.0;
  this->ZenithYc = 0.0;
  for (int i = 0; i < 3; ++i)
  {
    for (int j = 0; j < 4; ++j)
    {
      this->ZenithX += tv[i] * Mx[i][j] * theta[j];
      this->ZenithYc += tv[i] * My[i][j] * theta[j];
    }
  }
}

std::array<double, 3> PreethamSky::Distributions(double viewZenith, double gamma) const
{
  std::array<double, 3> f;
  for (int k = 0; k < 3; ++k)
  {
    f[k] = Perez(this->Coefficients[k], viewZenith, gamma) / this->Normalisation[k];
  }
  return f;
}

double PreethamSky::Luminance(double viewZenith, double gamma) const
{
  return this->ZenithY * this->Distributions(viewZenith, gamma)[0];
}

std::array<double, 2> PreethamSky::Chromaticity(double viewZenith, double gamma) const
{
  const std::array<double, 3> f = this->Distributions(viewZenith, gamma);
  return { { this->ZenithX * f[1], this->ZenithYc * f[2] } };
}

} // namespace nimbus
