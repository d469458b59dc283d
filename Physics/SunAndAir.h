// The sun and the air between it and a scene, at the spectral sample wavelengths:
// what every renderer needs of them, computed once. The reference renderers
// (through RenderContext) and the GPU mapper's atmosphere table both read their
// sunlight, air coefficients and colour conversion from here, so they agree.
//
// Units: metres, 1/m, nm; radiometry relative to the sun (Sun.h). Scene points are
// in metres with z up; see SceneAtmosphere for the earth-centred frame of
// Atmosphere.h.
#ifndef nimbus_SunAndAir_h
#define nimbus_SunAndAir_h

#include "Atmosphere.h"
#include "Math.h"
#include "NimbusPhysicsExport.h" // for export macro
#include "SpectralColor.h"
#include "Sun.h"

#include <array>
#include <memory>
#include <vector>

namespace nimbus
{

class NIMBUSPHYSICS_EXPORT SunAndAir
{
public:
  /// spectralSamples wavelengths in [3, 256] (the spline reconstruction from 8 on,
  /// piecewise linear below: SpectralColor.h). Throws std::invalid_argument, naming
  /// the parameter, for a non-finite or out-of-range sun, an invalid atmosphere
  /// (when enabled) or a bad sample count.
  SunAndAir(const SunParameters& sun, const SceneAtmosphere& air, int spectralSamples);
  ~SunAndAir();
  SunAndAir(const SunAndAir&) = delete;
  SunAndAir& operator=(const SunAndAir&) = delete;

  const SunParameters& GetSun() const { return this->Sun; }
  const SceneAtmosphere& GetSceneAtmosphere() const { return this->AirParameters; }

  // --- spectrum
  const SpectralSamples& GetSpectrum() const { return *this->Spectrum; }
  const std::vector<double>& GetWavelengths() const { return this->Wavelengths; }
  /// Spectral values at the wavelength samples -> linear sRGB.
  std::array<double, 3> ToLinearSrgb(const std::vector<double>& spectrum) const;

  // --- sun
  /// Unit vector toward the sun.
  const Vector3& GetSunDirection() const { return this->ToSun; }
  /// Irradiance above the atmosphere per wavelength sample (luminance Y = Illuminance).
  const std::vector<double>& GetSunIrradiance() const { return this->SunIrradiance; }

  // --- air (absent when disabled)
  bool HasAtmosphere() const { return this->Air != nullptr; }
  const Atmosphere* GetAtmosphere() const { return this->Air.get(); }
  /// Scene point (m) -> earth-centred point (m).
  Vector3 EarthCentred(const Vector3& p) const;
  /// Sea-level coefficients (1/m): Rayleigh scattering (= extinction) per
  /// wavelength sample, and the grey Mie scattering and extinction. Multiply by
  /// Atmosphere::Density(h, H) for altitude h. Empty / 0 without atmosphere.
  const std::vector<double>& GetRayleighScatteringSeaLevel() const { return this->BetaRayleigh; }
  double GetMieScatteringSeaLevel() const { return this->BetaMieScattering; }
  double GetMieExtinctionSeaLevel() const { return this->BetaMieExtinction; }
  /// Per wavelength sample at scene point p (1/m): Rayleigh scattering (=
  /// extinction), Mie scattering, Mie extinction. Zero without atmosphere.
  /// The Mie values are those at 550 nm and ozone is left out here (exact for the
  /// scene format's air: MieAngstromExponent = 0, OzoneDobsonUnits = 0); the
  /// transmittances below include both (Atmosphere::OpticalDepth).
  void AtmosphereCoefficients(const Vector3& p, std::vector<double>& rayleighScattering,
    double& mieScattering, double& mieExtinction) const;
  /// Transmittance of the atmosphere from p toward the sun, per wavelength sample
  /// (0 where the earth blocks the sun; 1 without atmosphere).
  void SunAtmosphereTransmittance(const Vector3& p, std::vector<double>& transmittance) const;
  /// Transmittance of the atmosphere along the segment p0 -> p1, per wavelength sample.
  void AtmosphereTransmittanceBetween(
    const Vector3& p0, const Vector3& p1, std::vector<double>& transmittance) const;
  /// Distance along origin + t direction (unit) to the top of the atmosphere, or
  /// infinity without atmosphere.
  double DistanceToTopOfAtmosphere(const Vector3& origin, const Vector3& direction) const;

private:
  SunParameters Sun;
  SceneAtmosphere AirParameters;
  std::unique_ptr<SpectralSamples> Spectrum;
  std::vector<double> Wavelengths;
  Vector3 ToSun;
  std::vector<double> SunIrradiance;
  std::unique_ptr<Atmosphere> Air;
  std::vector<double> BetaRayleigh;
  double BetaMieScattering = 0.0;
  double BetaMieExtinction = 0.0;
};

} // namespace nimbus

#endif
