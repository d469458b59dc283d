// What a Nimbus scene is: everything needed to render it, in physical units,
// independent of the renderer. Read from and written to versioned JSON by
// SceneJson.h (format documented in docs/scene-format.md).
//
// Frame and units: metres; z is up; x east, y north. Angles in degrees in the
// description. Coefficients in 1/m. Radiometry is relative: the sun's
// irradiance at the top of the atmosphere has luminance Y = Sun.Illuminance
// (so a white Lambertian plane facing that sun has radiance Y = Illuminance/pi).
#ifndef NimbusSceneDescription_h
#define NimbusSceneDescription_h

#include "Atmosphere.h"
#include "Sun.h"

#include <array>
#include <string>
#include <utility>
#include <vector>

namespace nimbus
{

struct CameraDescription
{
  std::array<double, 3> Position{ { 0.0, -6000.0, 1500.0 } }; // m
  std::array<double, 3> FocalPoint{ { 0.0, 0.0, 1600.0 } };   // m
  std::array<double, 3> ViewUp{ { 0.0, 0.0, 1.0 } };
  double ViewAngle = 35.0; // vertical, degrees
  int Width = 256;         // pixels
  int Height = 256;        // pixels
};

/// One term of a phase function (004 Eq. 4 mixtures have several).
struct PhaseComponentDescription
{
  std::string Type =
    "cornette_shanks"; // "isotropic", "rayleigh", "henyey_greenstein", "cornette_shanks"
  double G = 0.85;     // asymmetry (ignored by isotropic and rayleigh)
  double Weight = 1.0; // mixture weight (normalised over the components)
};

/// Where the density comes from. Either a VTK image file or a Nimbus source.
struct DensitySourceDescription
{
  std::string Type = "metaball_cloud"; // "file" or "metaball_cloud"
  std::string Path;                    // "file": .vti path; relative ones are resolved
                                       // against the scene file's folder when read
  std::string ArrayName = "density";   // "file": the point-data array to use
  /// "metaball_cloud": vtkNimbusMetaballCloudSource parameters (name -> value(s)),
  /// e.g. {"Dimensions": [96, 96, 64], "Seed": [1]}; unknown names are rejected.
  std::vector<std::pair<std::string, std::vector<double>>> Parameters;
};

/// Version 3: a per-voxel emission field (hot smoke). The source term added along a
/// ray is eta(x) ds, eta(x) = RadiancePerMetre * field(x): radiance (luminance Y,
/// relative units) emitted per metre of path per unit field value, Y/(sr m), with the
/// blackbody spectrum of TemperatureKelvin normalised to luminance 1 (as the sun's).
/// The field is the medium's density ("from_density") or another point-data array
/// of the medium's .vti ("array"; only for "file" densities), on the density's grid.
/// "blackbody" (hot smoke and fire, Planck's law; Physics/BlackbodyEmission.h): the array is
/// a temperature T [K] and each voxel emits eta_i(lambda) = RadiancePerMetre density_i
/// B(lambda, T_i) / Y[B(TemperatureKelvin)] (hotter: brighter and bluer), trilinear
/// between voxels as the density is; TemperatureKelvin is then the reference temperature
/// at which a unit density emits RadiancePerMetre of luminance per metre.
struct EmissionDescription
{
  bool Enabled = false;
  std::string Source = "from_density"; // "from_density", "array" or "blackbody"
  std::string ArrayName;         // "array", "blackbody": the point-data array of the density's file
  double RadiancePerMetre = 0.0; // Y / (sr m) per unit field value
  double TemperatureKelvin = 1500.0; // K, blackbody spectrum
};

struct MediumDescription
{
  DensitySourceDescription Density;
  double ExtinctionPerDensity = 0.02;   // sigma_t per unit density, 1/m
  double SingleScatteringAlbedo = 0.99; // sigma_s / sigma_t
  /// k_multi of 000 Eq. 1: a constant added to the 4pi-normalised cloud phase
  /// function that stands in for multiple scattering (dimensionless, >= 0; 0 =
  /// pure single scattering). The single-scattering reference includes it so that
  /// fast renderers with the same term are compared like for like; the path
  /// tracer simulates multiple scattering itself and ignores it.
  double MultipleScatteringConstant = 0.0;
  std::vector<PhaseComponentDescription> Phase{ PhaseComponentDescription{} };
  EmissionDescription Emission; // version 3; disabled by default
};

/// Version 4: a spot light's light map (a gobo), the luminance that multiplies the
/// spot's intensity toward each direction of its beam. The scene file names the image
/// (Path); the pixels are read by VTK glue (Reference/SceneAssets.h, used by
/// vtkNimbusReferenceRenderer), or filled directly by code that builds a description.
/// Pixel (c, r) is Luminance[r * Width + c]: column c at u = (c + 0.5) / Width, row r at
/// v = 1 - (r + 0.5) / Height, row 0 the image file's first row (the top of the picture as
/// an image viewer shows it, thrown upright: Physics/SpotLight.h); (u, v) as
/// SpotLightMapCoordinates gives them. Sampled bilinearly between pixel centres (clamped to the
/// edge pixels within [0, 1]^2), 0 outside [0, 1]^2. Values are linear luminance, >= 0 (an 8-bit or
/// 16-bit PNG is decoded from sRGB, a PGM/PPM is linear; colour images give Y of linear sRGB).
struct LightMapDescription
{
  std::string Path;             // resolved, absolute; "" = no light map
  int Width = 0;                // pixels
  int Height = 0;               // pixels
  std::vector<float> Luminance; // Width * Height values, or empty until read
};

/// Version 3: a light other than the sun. Lights have zero measure (points, lines):
/// camera rays never see them directly; they light the scene by next-event estimation.
/// Radiometry in the sun's relative units: a point light of Intensity I (luminance Y
/// per steradian) at distance d in vacuum gives the irradiance Y = I / d^2 at normal
/// incidence, as a sun of illuminance I / d^2 would.
/// Version 4 adds "spot": a point light whose intensity toward a direction w (from the
/// light) is Intensity x SpotFactor(w) x light map(w) (Physics/SpotLight.h).
struct LightDescription
{
  std::string Type = "point"; // "point", "polyline" or (version 4) "spot"
  /// "point", "spot": the light's position, m.
  std::array<double, 3> Position{ { 0.0, 0.0, 0.0 } };
  /// "point": radiant intensity's luminance, Y / sr (isotropic); "spot": on the axis.
  double Intensity = 1.0;
  /// "spot": the beam's axis, away from the light (any non-zero length; stored as
  /// given, normalised by the renderers).
  std::array<double, 3> Direction{ { 0.0, 0.0, -1.0 } };
  /// "spot": the half angle between the axis and the cone's edge, degrees, in (0, 90)
  /// (VTK's vtkLight::ConeAngle).
  double ConeAngleDegrees = 30.0;
  /// "spot": the soft edge's width inside the cone, degrees, in [0, ConeAngleDegrees].
  double EdgeDegrees = 0.0;
  /// "spot": optional light map (empty Path and Luminance: none).
  LightMapDescription LightMap;
  /// "polyline" (a lightning channel): at least 2 vertices, m.
  std::vector<std::array<double, 3>> Vertices;
  /// "polyline": each element dl of the channel radiates isotropically with intensity
  /// IntensityPerMetre dl: Y / (sr m).
  double IntensityPerMetre = 1.0;
  double TemperatureKelvin = 6500.0; // K, blackbody spectrum normalised to luminance 1
};

/// Version 3: a medium beside the main one (smoke beside cloud), with its own density
/// (on the main medium's grid geometry), albedo, phase and optional emission. The total
/// extinction is the sum over the media.
struct AdditionalMediumDescription
{
  DensitySourceDescription Density;
  double ExtinctionPerDensity = 0.02;   // 1/m per unit density
  double SingleScatteringAlbedo = 0.99; // sigma_s / sigma_t
  std::vector<PhaseComponentDescription> Phase{ PhaseComponentDescription{} };
  EmissionDescription Emission;
};

/// Version 4: an opaque surface in the scene: a grey Lambertian reflector of albedo
/// Albedo that stops every ray (camera, scattered and shadow rays). Surfaces are
/// two-sided: a box is its six faces, a mesh its triangles.
struct OccluderDescription
{
  std::string Type = "box"; // "box" or "mesh"
  /// "box": opposite corners, m; Min <= Max on every axis (equal: a flat rectangle).
  std::array<double, 3> Min{ { 0.0, 0.0, 0.0 } };
  std::array<double, 3> Max{ { 0.0, 0.0, 0.0 } };
  /// "mesh": a .ply or .obj file, resolved and absolute like a density's path.
  std::string Path;
  /// "mesh": a vertex x of the file is placed at Scale x + Translate (m).
  std::array<double, 3> Translate{ { 0.0, 0.0, 0.0 } };
  double Scale = 1.0;
  double Albedo = 0.0; // grey Lambertian, in [0, 1]; 0 = black
  /// "mesh": the triangles in the file's coordinates (before Scale and Translate), three
  /// consecutive vertices each; read by VTK glue (Reference/SceneAssets.h) or filled
  /// directly. Empty until read.
  std::vector<std::array<double, 3>> TriangleVertices;
};

struct GroundDescription
{
  bool Enabled = true;
  double Height = 0.0; // z of the ground plane, m
  double Albedo = 0.2; // Lambertian, grey (all wavelengths)
};

struct BackgroundDescription
{
  /// "black"; "constant" (a grey radiance with luminance Y = Radiance at every
  /// wavelength); "atmosphere" (only what the atmosphere scatters along the view
  /// ray up to the top of the atmosphere: the single-scattered sky; needs
  /// Atmosphere.Enabled).
  std::string Type = "atmosphere";
  double Radiance = 0.0; // for "constant": luminance Y, same relative units as the sun
};

struct SceneDescription
{
  static constexpr int kFormatVersion = 4;
  std::string Name;
  std::string Description;
  CameraDescription Camera;
  MediumDescription Medium;
  SunParameters Sun;          // the sun (Physics/Sun.h)
  SceneAtmosphere Atmosphere; // the air and the scene's place in it (Physics/Atmosphere.h)
  GroundDescription Ground;
  BackgroundDescription Background;
  /// Wavelengths the renderers sample (SpectralSamples; 16 = measured ΔE 0.02).
  int SpectralSamples = 16;
  std::vector<LightDescription> Lights;           // version 3
  std::vector<AdditionalMediumDescription> Media; // version 3
  std::vector<OccluderDescription> Occluders;     // version 4

  /// True when the scene uses a version-3 feature (lights, emission, media).
  bool UsesVersion3Features() const
  {
    if (!this->Lights.empty() || !this->Media.empty() || this->Medium.Emission.Enabled)
    {
      return true;
    }
    return false;
  }

  /// True when the scene uses a version-4 feature (spot lights, occluders).
  bool UsesVersion4Features() const
  {
    for (const LightDescription& light : this->Lights)
    {
      if (light.Type == "spot")
      {
        return true;
      }
    }
    return !this->Occluders.empty();
  }
};

} // namespace nimbus

#endif
