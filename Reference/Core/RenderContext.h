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
#include "Occluders.h"
#include "PhaseFunctions.h"
#include "SceneDescription.h"
#include "SpectralColor.h"
#include "SpotLight.h"
#include "SunAndAir.h"

#include <array>
#include <memory>
#include <vector>

namespace nimbus
{

/// The grids of a version-3 scene beyond the main medium's density, all on the main
/// density's grid geometry (same dimensions, origin and spacing; checked).
struct NIMBUSREFERENCE_EXPORT SceneFields
{
  /// scene.Media[i]'s density, one per additional medium.
  std::vector<DensityGrid> MediaDensities;
  /// scene.Medium.Emission's field when its source is "array" or "blackbody" (the
  /// temperature, K) (else empty).
  DensityGrid Emission;
  /// scene.Media[i].Emission's field when its source is "array" (else empty or absent).
  std::vector<DensityGrid> MediaEmissions;
};

/// One participating medium at run time: the main one (index 0) or an additional one.
/// sigma_t(p) = ExtinctionPerDensity density(p), sigma_s = Albedo sigma_t; emission
/// coefficient eta(p, lambda) = EmissionScale field(p) EmissionSpectrum(lambda),
/// Y/(sr m) (EmissionSpectrum has luminance 1; field = the density for "from_density").
struct NIMBUSREFERENCE_EXPORT MediumComponent
{
  const DensityGrid* Density = nullptr;
  double ExtinctionPerDensity = 0.0;
  double Albedo = 0.0;
  PhaseFunctionMixture Phase;
  bool Emits = false;
  const DensityGrid* EmissionField = nullptr; // Density for "from_density" and "blackbody"
  double EmissionScale = 0.0;
  std::vector<double> EmissionSpectrum;
  /// "blackbody": per wavelength, the voxels' density_i B(lambda, T_i) / Y[B(T_ref)]
  /// (sampled trilinearly; eta = EmissionScale times it). Empty otherwise.
  std::vector<DensityGrid> BlackbodyEmission;
};

/// A light of the scene broken into elements for next-event estimation: a point, a spot
/// or one straight segment of a polyline. Intensity is the element's total luminous-like
/// intensity, Y/sr: a point's `intensity`, a spot's on its axis, a segment's
/// intensity_per_metre x length.
struct NIMBUSREFERENCE_EXPORT LightElement
{
  Vector3 A{ { 0.0, 0.0, 0.0 } }; // the point, or the segment's first end, m
  Vector3 B{ { 0.0, 0.0, 0.0 } }; // the segment's second end (= A for a point), m
  double Intensity = 0.0;         // Y / sr
  bool IsSegment = false;
  int Light = 0; // index in scene.Lights (and in GetLightSpectra())
  /// Version 4, a spot: the cone (Spot.Axis unit) and the light map (null: none; it
  /// points into the context's own copy of the scene).
  bool IsSpot = false;
  SpotProfile Spot;
  const LightMapDescription* Map = nullptr;
};

/// A light map's luminance at (u, v) (LightMapDescription's conventions): bilinear
/// between pixel centres, clamped to the edge pixels inside [0, 1]^2, 0 outside.
NIMBUSREFERENCE_EXPORT double SampleLightMap(const LightMapDescription& map, double u, double v);

/// What multiplies a light element's Intensity toward unit direction w (from the light):
/// 1 for points and segments; SpotFactor(w) x the light map at
/// SpotLightMapCoordinates(w) for a spot (Physics/SpotLight.h).
NIMBUSREFERENCE_EXPORT double LightElementFactor(const LightElement& light, const Vector3& w);

class NIMBUSREFERENCE_EXPORT RenderContext
{
public:
  using Vector3 = nimbus::Vector3;

  /// Validates the parts the renderers rely on (throws std::invalid_argument with
  /// the offending field's name). `fields` holds the grids of additional media and of
  /// "array" emission fields (version 3); a scene that needs one it lacks is an error,
  /// and so is (version 4) a light map or a mesh whose pixels or triangles the
  /// description lacks (Reference/SceneAssets.h reads them).
  RenderContext(const SceneDescription& scene, DensityGrid grid, SceneFields fields = {});
  /// Not copied or moved: GetMedia() points into the context's own grids.
  RenderContext(const RenderContext&) = delete;
  RenderContext& operator=(const RenderContext&) = delete;

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

  // --- cloud (wavelength independent): the sum over the media
  /// sigma_t = sum_i ExtinctionPerDensity_i * density_i(p), 1/m: the extinction grid
  /// (the main density, or the sum of the media's extinctions on the shared grid)
  /// times its scale.
  double CloudExtinction(const Vector3& p) const
  {
    return this->ExtinctionScale * this->GetExtinctionGrid().Sample(p);
  }
  /// Majorant of CloudExtinction over the grid, 1/m.
  double CloudMajorant() const
  {
    return this->ExtinctionScale * this->GetExtinctionGrid().GetMaximum();
  }
  /// The grid whose values times GetExtinctionScale() are sigma_t (1/m): the main
  /// density with ExtinctionPerDensity when there is one medium (so one-medium scenes
  /// are computed exactly as before version 3), else the summed extinction with 1.
  /// Trilinear interpolation is linear, so the sum interpolates as the media do.
  const DensityGrid& GetExtinctionGrid() const
  {
    return this->Media.size() > 1 ? this->SummedExtinction : this->Grid;
  }
  double GetExtinctionScale() const { return this->ExtinctionScale; }
  /// The media: [0] the main one, then scene.Media in order.
  const std::vector<MediumComponent>& GetMedia() const { return this->Media; }
  bool HasAdditionalMedia() const { return this->Media.size() > 1; }
  bool HasEmission() const { return this->AnyEmission; }
  /// Point lights, spots and polyline segments (scene.Lights), with positive intensity.
  const std::vector<LightElement>& GetLightElements() const { return this->Lights; }
  /// Per scene light: the blackbody spectrum at the sample wavelengths, luminance 1.
  const std::vector<std::vector<double>>& GetLightSpectra() const { return this->LightSpectra; }
  double GetCloudAlbedo() const { return this->Scene.Medium.SingleScatteringAlbedo; }
  /// Version 4: the scene's occluders (boxes and meshes placed by Scale and Translate),
  /// in a bounding volume hierarchy; empty without occluders.
  const OccluderSet& GetOccluders() const { return this->Occluders; }
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
  void SetUpVersion3(const SceneDescription& scene);
  void SetUpSpot(std::size_t index, LightElement& element) const;
  void SetUpVersion4();

  SceneDescription Scene;
  Camera ViewCamera;
  DensityGrid Grid;
  std::unique_ptr<SunAndAir> Light;
  double ExtinctionPerDensity;
  PhaseFunctionMixture CloudPhase;
  SceneFields Fields; // owns the additional grids the Media point to
  DensityGrid SummedExtinction;
  double ExtinctionScale = 0.0;
  std::vector<MediumComponent> Media;
  bool AnyEmission = false;
  std::vector<LightElement> Lights;
  std::vector<std::vector<double>> LightSpectra;
  OccluderSet Occluders;
  std::vector<double> BackgroundRadiance;
};

} // namespace nimbus

#endif
