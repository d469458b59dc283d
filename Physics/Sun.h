// The sun as every Nimbus renderer sees it: where it is (two angles) and what it
// emits above the atmosphere (a blackbody spectrum of a given luminance). The scene
// format, the reference renderers, the GPU mapper, the sky and the sunlight helper
// all use these names and these two functions.
//
// Frame: x east, y north, z up. Radiometry is relative: the irradiance above the
// atmosphere has luminance Y = Illuminance (so a white Lambertian plane facing that
// sun has radiance Y = Illuminance / pi).
#ifndef nimbus_Sun_h
#define nimbus_Sun_h

#include "Math.h"
#include "NimbusPhysicsExport.h" // for export macro

#include <vector>

namespace nimbus
{
class SpectralSamples;

/// The sun. Names carry their units (Illuminance is relative, dimensionless).
struct NIMBUSPHYSICS_EXPORT SunParameters
{
  double AzimuthDegrees = 135.0;     // from north (+y) toward east (+x)
  double ElevationDegrees = 45.0;    // above the horizon, in [-90, 90]
  double Illuminance = 1.0;          // luminance Y of the irradiance above the atmosphere
  double TemperatureKelvin = 5778.0; // blackbody temperature of the solar spectrum
};

/// Unit vector from the scene toward the sun:
/// (cos e sin a, cos e cos a, sin e) for elevation e and azimuth a.
NIMBUSPHYSICS_EXPORT Vector3 SunDirection(double elevationDegrees, double azimuthDegrees);

/// Spectral irradiance above the atmosphere at the sample wavelengths: Planck's
/// law at temperatureKelvin (SpectralColor.h) scaled so that its luminance Y
/// (SpectralSamples::ToXyz) is `illuminance`.
NIMBUSPHYSICS_EXPORT std::vector<double> SunIrradianceSpectrum(
  const SpectralSamples& samples, double temperatureKelvin, double illuminance);

} // namespace nimbus

#endif
