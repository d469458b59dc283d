#include "BlackbodyEmission.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace nimbus
{

BlackbodyEmission::BlackbodyEmission(
  const SpectralSamples& samples, double referenceTemperatureKelvin)
  : Samples(samples)
  , ReferenceTemperature(referenceTemperatureKelvin)
{
  if (!(referenceTemperatureKelvin >= 500.0 && referenceTemperatureKelvin <= 50000.0))
  {
    std::ostringstream message;
    message << "the emission's reference temperature must be in [500, 50000] K (got "
            << referenceTemperatureKelvin << ")";
    throw std::invalid_argument(message.str());
  }
  this->ReferenceLuminance = samples.ToXyz(samples.Sample(
    [&](double lambda) { return PlanckSpectralRadiance(lambda, referenceTemperatureKelvin); }))[1];
  const std::size_t n = static_cast<std::size_t>(kTableMaxKelvin / kTableStepKelvin) + 1;
  this->RgbTable.resize(n);
  for (std::size_t i = 0; i < n; ++i)
  {
    this->RgbTable[i] = this->ExactRelativeRgb(static_cast<double>(i) * kTableStepKelvin);
  }
}

std::vector<double> BlackbodyEmission::RelativeSpectrum(double temperatureKelvin) const
{
  if (!(temperatureKelvin > 0.0) || !std::isfinite(temperatureKelvin))
  {
    return std::vector<double>(this->Samples.GetNumberOfSamples(), 0.0);
  }
  return this->Samples.Sample(
    [&](double lambda)
    {
      // Planck's law underflows to 0 (exp(hc / lambda k T) = inf) below ~20 K: no light.
      return PlanckSpectralRadiance(lambda, temperatureKelvin) / this->ReferenceLuminance;
    });
}

double BlackbodyEmission::RelativeLuminance(double temperatureKelvin) const
{
  return this->Samples.ToXyz(this->RelativeSpectrum(temperatureKelvin))[1];
}

std::array<double, 3> BlackbodyEmission::ExactRelativeRgb(double temperatureKelvin) const
{
  return this->Samples.ToLinearSrgb(this->RelativeSpectrum(temperatureKelvin));
}

std::array<double, 3> BlackbodyEmission::RelativeRgb(double temperatureKelvin) const
{
  if (!(temperatureKelvin > 0.0) || std::isnan(temperatureKelvin))
  {
    return { { 0.0, 0.0, 0.0 } };
  }
  if (temperatureKelvin >= kTableMaxKelvin)
  {
    return this->ExactRelativeRgb(std::isfinite(temperatureKelvin) ? temperatureKelvin : 1e9);
  }
  const double x = temperatureKelvin / kTableStepKelvin;
  const std::size_t i = static_cast<std::size_t>(x);
  const double f = x - static_cast<double>(i);
  const auto& a = this->RgbTable[i];
  const auto& b = this->RgbTable[i + 1];
  return { { a[0] + f * (b[0] - a[0]), a[1] + f * (b[1] - a[1]), a[2] + f * (b[2] - a[2]) } };
}

} // namespace nimbus
