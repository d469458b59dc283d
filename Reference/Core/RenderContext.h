// The runtime form of a scene that the reference renderers share: the camera,
// the density grid, the cloud's and atmosphere's optical coefficients per
// wavelength sample, the sun's spectral irradiance, the ground and background,
// and the spectrum -> linear sRGB conversion. Renderers differ only in how they
// integrate; everything physical comes from here, so they render the same scene.
//
// Units: metres, 1/m, wavelengths in nm; radiometry relative to the sun (see
// SceneDescription.h). The sun, the air and the colour conversion are those of
// Physics/SunAndAir.h, which the GPU mapper's atmosphere table uses too; scene point
// p maps to the earth-centred frame of Atmosphere.h as
// (p.x, p.y, EarthRadiusMetres + SceneAltitudeMetres + p.z).
#ifndef NimbusRenderContext_h
#define NimbusRenderContext_h

#include "Math.h"
#include "NimbusReferenceModule.h"

#include "Atmosphere.h"
#include "Camera.h"
#include "DensityGrid.h"
#include "PhaseFunctions.h"
#include "SceneDescription.h"
#include "SpectralColor.h"
#include "SunAndAir.h"

#include <array>
#include <memory>
#include <vector>

namespace nimbus
{

class NIMBUSREFERENCE_EXPORT RenderContext
{
public:
  using Vector3 = nimbus::Vector3;

  /// Validates the parts the renderers rely on (throws std::invalid_argument with
  /// the offending field's name).
  RenderContext(const SceneDescription& scene, DensityGrid grid);

  const SceneDescription& GetScene() const { return this->Scene; }
  const Camera& GetCamera() const { return this->ViewCamera; }
  const DensityGrid& GetGrid() const { return this->Grid; }

  /// The sun, the air and the spectrum of the scene (shared with the GPU path).
  const SunAndAir& GetSunAndAir() const { return *this->Light; }

  // --- spectrum
  const SpectralSamples& GetSpectrum() const { return this->Light->GetSpectrum(); }
  int GetNumberOfWavelengths() const { return static_cast<int>(this->GetWavelengths().size()); }
  const std::vector<double>& GetWavelengths() const { return this->Light->GetWavelengths(); }
  /// Spectral radiance at the wavelength samples -> linear sRGB.
  std::array<double, 3> ToLinearSrgb(const std::vector<double>& spectralRadiance) const
  {
    return this->Light->ToLinearSrgb(spectralRadiance);
  }

  // --- sun
  /// Unit vector toward the sun.
  const Vector3& GetSunDirection() const { return this->Light->GetSunDirection(); }
  /// Irradiance at the top of the atmosphere per wavelength sample (luminance Y = Illuminance).
  const std::vector<double>& GetSunIrradiance() const { return this->Light->GetSunIrradiance(); }

  // --- cloud (wavelength independent)
  /// sigma_t = ExtinctionPerDensity * density(p), 1/m.
  double CloudExtinction(const Vector3& p) const
  {
    return this->ExtinctionPerDensity * this->Grid.Sample(p);
  }
  /// Majorant of CloudExtinction over the grid, 1/m.
  double CloudMajorant() const { return this->ExtinctionPerDensity * this->Grid.GetMaximum(); }
  double GetCloudAlbedo() const { return this->Scene.Medium.SingleScatteringAlbedo; }
  const PhaseFunctionMixture& GetCloudPhase() const { return this->CloudPhase; }

  // --- atmosphere (absent when disabled): SunAndAir.h
  bool HasAtmosphere() const { return this->Light->HasAtmosphere(); }
  const Atmosphere* GetAtmosphere() const { return this->Light->GetAtmosphere(); }
  Vector3 EarthCentred(const Vector3& p) const { return this->Light->EarthCentred(p); }
  const std::vector<double>& GetRayleighScatteringSeaLevel() const
  {
    return this->Light->GetRayleighScatteringSeaLevel();
  }
  double GetMieScatteringSeaLevel() const { return this->Light->GetMieScatteringSeaLevel(); }
  double GetMieExtinctionSeaLevel() const { return this->Light->GetMieExtinctionSeaLevel(); }
  void AtmosphereCoefficients(const Vector3& p, std::vector<double>& rayleighScattering,
    double& mieScattering, double& mieExtinction) const
  {
    this->Light->AtmosphereCoefficients(p, rayleighScattering, mieScattering, mieExtinction);
  }
  void SunAtmosphereTransmittance(const Vector3& p, std::vector<double>& transmittance) const
  {
    this->Light->SunAtmosphereTransmittance(p, transmittance);
  }
  void AtmosphereTransmittanceBetween(
    const Vector3& p0, const Vector3& p1, std::vector<double>& transmittance) const
  {
    this->Light->AtmosphereTransmittanceBetween(p0, p1, transmittance);
  }
  double DistanceToTopOfAtmosphere(const Vector3& origin, const Vector3& direction) const
  {
    return this->Light->DistanceToTopOfAtmosphere(origin, direction);
  }

  // --- ground plane z = height (absent when disabled) and background
  bool HasGround() const { return this->Scene.Ground.Enabled; }
  double GetGroundHeight() const { return this->Scene.Ground.Height; }
  double GetGroundAlbedo() const { return this->Scene.Ground.Albedo; }
  /// Distance t > tMin along the ray to the ground plane, or infinity.
  double IntersectGround(const Vector3& origin, const Vector3& direction, double tMin) const;
  /// Background radiance per wavelength sample for rays that leave the scene
  /// ("constant": flat spectrum with luminance Radiance; "black" and
  /// "atmosphere": zero — the atmosphere's own scattering is integrated by the renderer).
  const std::vector<double>& GetBackgroundRadiance() const { return this->BackgroundRadiance; }
  bool BackgroundIsAtmosphere() const { return this->Scene.Background.Type == "atmosphere"; }

private:
  SceneDescription Scene;
  Camera ViewCamera;
  DensityGrid Grid;
  std::unique_ptr<SunAndAir> Light;
  double ExtinctionPerDensity;
  PhaseFunctionMixture CloudPhase;
  std::vector<double> BackgroundRadiance;
};

} // namespace nimbus

#endif
