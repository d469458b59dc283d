#include "Sun.h"

#include "SpectralColor.h"

#include <cmath>

namespace nimbus
{

Vector3 SunDirection(double elevationDegrees, double azimuthDegrees)
{
  const double e = elevationDegrees * kDegree, a = azimuthDegrees * kDegree;
  return { { std::cos(e) * std::sin(a), std::cos(e) * std::cos(a), std::sin(e) } };
}

std::vector<double> SunIrradianceSpectrum(
  const SpectralSamples& samples, double temperatureKelvin, double illuminance)
{
  std::vector<double> irradiance = samples.Sample([temperatureKelvin](double lambda)
    { return PlanckSpectralRadiance(lambda, temperatureKelvin); });
  const double luminance = samples.ToXyz(irradiance)[1];
  for (double& e : irradiance)
  {
    e *= illuminance / luminance;
  }
  return irradiance;
}

} // namespace nimbus
