#include "SunAndAir.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace nimbus
{

namespace
{
void Require(bool condition, const std::string& what)
{
  if (!condition)
  {
    throw std::invalid_argument(what);
  }
}
}

SunAndAir::SunAndAir(const SunParameters& sun, const SceneAtmosphere& air, int spectralSamples)
  : Sun(sun)
  , AirParameters(air)
{
  Require(spectralSamples >= 3 && spectralSamples <= 256, "spectral samples must be in [3, 256]");
  // Spline reconstruction overshoots below 8 samples (Physics/README.md): linear there.
  this->Spectrum = std::make_unique<SpectralSamples>(spectralSamples,
    spectralSamples >= 8 ? SpectralReconstruction::NaturalCubicSpline
                         : SpectralReconstruction::PiecewiseLinear);
  this->Wavelengths = this->Spectrum->GetWavelengths();

  Require(std::isfinite(sun.AzimuthDegrees), "sun AzimuthDegrees must be finite");
  Require(std::isfinite(sun.ElevationDegrees) && std::abs(sun.ElevationDegrees) <= 90.0,
    "sun ElevationDegrees must be in [-90, 90]");
  Require(std::isfinite(sun.Illuminance) && sun.Illuminance >= 0.0,
    "sun Illuminance must be finite and >= 0");
  Require(std::isfinite(sun.TemperatureKelvin) && sun.TemperatureKelvin >= 1000.0,
    "sun TemperatureKelvin must be >= 1000");
  this->ToSun = SunDirection(sun.ElevationDegrees, sun.AzimuthDegrees);
  this->SunIrradiance =
    SunIrradianceSpectrum(*this->Spectrum, sun.TemperatureKelvin, sun.Illuminance);

  if (air.Enabled)
  {
    Require(std::isfinite(air.SceneAltitudeMetres) && air.SceneAltitudeMetres >= 0.0,
      "atmosphere SceneAltitudeMetres must be finite and >= 0");
    try
    {
      this->Air = std::make_unique<Atmosphere>(air);
    }
    catch (const std::invalid_argument& error)
    {
      throw std::invalid_argument(std::string("atmosphere: ") + error.what());
    }
    for (double lambda : this->Wavelengths)
    {
      this->BetaRayleigh.push_back(this->Air->RayleighScattering(lambda));
    }
    // Mie is grey: its coefficients do not depend on the wavelength.
    this->BetaMieScattering = this->Air->MieScattering(550.0);
    this->BetaMieExtinction = this->Air->MieExtinction(550.0);
  }
}

SunAndAir::~SunAndAir() = default;

std::array<double, 3> SunAndAir::ToLinearSrgb(const std::vector<double>& spectrum) const
{
  return this->Spectrum->ToLinearSrgb(spectrum);
}

Vector3 SunAndAir::EarthCentred(const Vector3& p) const
{
  const double base =
    this->AirParameters.EarthRadiusMetres + this->AirParameters.SceneAltitudeMetres;
  return { { p[0], p[1], base + p[2] } };
}

void SunAndAir::AtmosphereCoefficients(const Vector3& p, std::vector<double>& rayleighScattering,
  double& mieScattering, double& mieExtinction) const
{
  rayleighScattering.assign(this->Wavelengths.size(), 0.0);
  mieScattering = mieExtinction = 0.0;
  if (!this->Air)
  {
    return;
  }
  const AtmosphereParameters& a = this->Air->GetParameters();
  const double altitude = this->Air->Altitude(this->EarthCentred(p));
  const double rhoR = this->Air->Density(altitude, a.RayleighScaleHeightMetres);
  const double rhoM = this->Air->Density(altitude, a.MieScaleHeightMetres);
  for (std::size_t i = 0; i < this->Wavelengths.size(); ++i)
  {
    rayleighScattering[i] = this->BetaRayleigh[i] * rhoR;
  }
  mieScattering = this->BetaMieScattering * rhoM;
  mieExtinction = this->BetaMieExtinction * rhoM;
}

void SunAndAir::SunAtmosphereTransmittance(
  const Vector3& p, std::vector<double>& transmittance) const
{
  transmittance.assign(this->Wavelengths.size(), 1.0);
  if (!this->Air)
  {
    return;
  }
  const OpticalLengths lengths = this->Air->OpticalLengthsToTop(this->EarthCentred(p), this->ToSun);
  for (std::size_t i = 0; i < this->Wavelengths.size(); ++i)
  {
    transmittance[i] = this->Air->Transmittance(lengths, this->Wavelengths[i]);
  }
}

void SunAndAir::AtmosphereTransmittanceBetween(
  const Vector3& p0, const Vector3& p1, std::vector<double>& transmittance) const
{
  transmittance.assign(this->Wavelengths.size(), 1.0);
  if (!this->Air)
  {
    return;
  }
  const Vector3 q0 = this->EarthCentred(p0), q1 = this->EarthCentred(p1);
  const AtmosphereParameters& a = this->Air->GetParameters();
  OpticalLengths lengths;
  lengths.RayleighLengthMetres = this->Air->OpticalLength(q0, q1, a.RayleighScaleHeightMetres);
  lengths.MieLengthMetres = this->Air->OpticalLength(q0, q1, a.MieScaleHeightMetres);
  lengths.OzoneLengthMetres = this->Air->OzoneOpticalLength(q0, q1);
  for (std::size_t i = 0; i < this->Wavelengths.size(); ++i)
  {
    transmittance[i] = this->Air->Transmittance(lengths, this->Wavelengths[i]);
  }
}

double SunAndAir::DistanceToTopOfAtmosphere(const Vector3& origin, const Vector3& direction) const
{
  if (!this->Air)
  {
    return std::numeric_limits<double>::infinity();
  }
  const Vector3 o = this->EarthCentred(origin);
  const double top = this->Air->GetParameters().TopRadiusMetres;
  const double b = Dot(o, direction);
  const double c = Dot(o, o) - top * top;
  const double disc = b * b - c;
  if (disc < 0.0)
  {
    return 0.0;
  }
  return std::max(0.0, -b + std::sqrt(disc));
}

} // namespace nimbus
