/**
 * @class   vtkNimbusCloudVolumeMapper
 * @brief   GPU cloud renderer with shadow-view slices (Miyazaki, Dobashi, Nishita; paper 000).
 *
 * Renders a scalar density vtkImageData (point or cell data, any numeric type,
 * converted once to a float 3-D texture on upload) with the whole method of 000:
 *
 *  - Shadow-view slices (000 §4.2): planes whose normal lies between the view
 *    and the sun directions with theta_e : theta_s = 1 : a (SliceAngleRatio),
 *    NumberOfSlices over the cloud box, traversed back-to-front when the camera
 *    looks toward the sun and front-to-back otherwise, blended as in §4.3.
 *  - The shadow surface (000 Eq. 10): a float render target facing the sun that
 *    accumulates the cloud's optical depth slice by slice (no temporary volume).
 *  - The atmosphere texture (rho_atm(h), g_sun_atm(h); rebuilt only when the sun
 *    or the atmosphere change) and the sampling-interval and Mie-phase textures
 *    (000 §4.4; rebuilt only when the camera or the sun change).
 *  - Scattering (000 Eqs. 5-10): cloud and atmosphere single scattering with
 *    Cornette-Shanks phase functions, the k_multi term, the sun reddened by the
 *    atmosphere, the background attenuated by g_view.
 *  - A ground plane lit by the attenuated sun and shadowed through the shadow
 *    surface, and shafts of light in the atmosphere beyond the cloud box.
 *  - Multiple scattering (003, 004; MultipleScatteringMethod, default discrete
 *    directions): the light the cloud scatters more than once and the sky's and the
 *    ground's light on it, solved on a downsampled grid (Physics/MultipleScattering.h)
 *    only when the density, sun, air, ground, optics or knobs change, and added per
 *    sample from three SH textures; docs/multiple-scattering.md.
 *  - Multiple scattering in the air (AirMultipleScattering, default on): the
 *    isotropic orders >= 2 of a sky model of the same air (Hillaire 2020 §5.5) in
 *    the air's source and the sky's light on the ground, neither shadowed by the
 *    cloud (rows 4 and 5 of the atmosphere texture, AtmosphereTable.h).
 *
 * Frame and units: the world's UpAxis (+Z by default; +X, +Y, -Y for data made y up
 * or x up) is up: the sun, the sky, the ground and the air turn with it, the data
 * and the camera stay where they are (Physics/UpAxis.h); MetresPerUnit metres per world unit (1 by
 * default); extinction in 1/m per unit density; radiance relative to the sun
 * (SunIlluminance = luminance of its irradiance above the atmosphere), in linear
 * sRGB, times Exposure in the framebuffer (EncodeSrgb applies the display
 * transfer function). The physics matches the CPU reference renderer
 * (vtkNimbusReferenceRenderer) for the same scene; see docs/svs-mapper.md for the
 * measured errors and costs.
 *
 * Over a Nimbus sky (SetSkyBackground: the vtkNimbusSkyBackground drawn behind
 * this cloud, while it is visible and UseSceneSky is on) the mapper takes that
 * sky's sun, atmosphere, ground albedo, observer altitude, length unit and
 * display settings instead of its own, and composites the cloud, its shadow on
 * the ground and its shafts over the sky as a difference from the clear sky, so
 * that where neither the cloud nor its shadow is the sky is left exactly as the
 * sky background drew it. The coupling is explicit: the mapper does not look
 * for a sky among the renderer's props (in ParaView the Cloud representation
 * hands it the view's sky, see vtkNimbusSkyBackground::RENDERER_SKY_BACKGROUND).
 *
 * Bad input ends in a message, not in a crash or a silent black frame: the
 * numeric setters refuse NaN and infinity (an error; the value is kept) and clamp
 * finite values to their ranges; no exception leaves Render (an error, and
 * nothing is drawn over the scene that frame); an unusable camera or volume
 * matrix, a singular direction matrix or a density that does not fit the texture
 * limits or TextureMemoryBudgetMiB is reported (once, not every frame); NaN,
 * infinite and negative densities are rendered as 0 with a warning per version
 * of the array. The input image's direction matrix (VTK 9.2) is honoured: the
 * density sits at origin + D (index * spacing), then the vtkVolume's matrix.
 *
 * Only what the scene needs runs: without atmosphere no atmosphere texture and
 * no atmosphere pass; without ground and atmosphere no passes outside the cloud
 * slices; without shafts no shadow look-ups in the atmosphere.
 *
 * A frame (Render) is a sequence of steps, each a method that sets the uniforms of
 * its own pass (the uniforms all passes share come from SetCommonUniforms): the
 * density texture (nimbus::CloudDensityTexture: uploads only when the data
 * changed), the frame's sun and air, its geometry, copies of the scene's colour
 * and depth, the atmosphere table, the interval/phase pass, the ray-ends pass, the
 * atmosphere sunward of the slices, the slices (eye pass, then shadow update),
 * the atmosphere beyond them, the radiance capture and the composite.
 */
#ifndef vtkNimbusCloudVolumeMapper_h
#define vtkNimbusCloudVolumeMapper_h

#include "NimbusRepresentationsModule.h"
#include "vtkVolumeMapper.h"

#include <memory> // for std::unique_ptr
#include <string> // for std::string
#include <vector> // for std::vector

class vtkImageData;
class vtkTextureObject;
class vtkMatrix4x4;
namespace nimbus
{
struct CloudLighting;
class SkyModel;
class SkyViewLut;
}
class vtkNimbusSky;
class vtkNimbusSkyBackground;
class vtkRenderer;
class vtkShaderProgram;
class vtkVolume;
class vtkWindow;

class NIMBUSREPRESENTATIONS_EXPORT vtkNimbusCloudVolumeMapper : public vtkVolumeMapper
{
public:
  static vtkNimbusCloudVolumeMapper* New();
  vtkTypeMacro(vtkNimbusCloudVolumeMapper, vtkVolumeMapper);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /// Cloud optics. ExtinctionPerDensity k_cl: sigma_t = k_cl * density [1/m];
  /// Albedo: sigma_s / sigma_t; CloudG: Cornette-Shanks asymmetry (000 Eq. 3);
  /// MultipleScattering: k_multi of 000 Eq. 1 (dimensionless; added to the
  /// 4pi-normalised phase function, i.e. k_multi/4pi per steradian here).
  virtual void SetExtinctionPerDensity(double value);
  virtual double GetExtinctionPerDensityMinValue() { return 0.0; }
  virtual double GetExtinctionPerDensityMaxValue() { return 1e6; }
  vtkGetMacro(ExtinctionPerDensity, double);
  virtual void SetAlbedo(double value);
  virtual double GetAlbedoMinValue() { return 0.0; }
  virtual double GetAlbedoMaxValue() { return 1.0; }
  vtkGetMacro(Albedo, double);
  virtual void SetCloudG(double value);
  virtual double GetCloudGMinValue() { return -0.999; }
  virtual double GetCloudGMaxValue() { return 0.999; }
  vtkGetMacro(CloudG, double);
  virtual void SetMultipleScattering(double value);
  virtual double GetMultipleScatteringMinValue() { return 0.0; }
  virtual double GetMultipleScatteringMaxValue() { return 100.0; }
  vtkGetMacro(MultipleScattering, double);
  ///@}

  ///@{
  /// Temperature emission (Planck's law): hot smoke and fire glow. Off by default. When on,
  /// every sample adds the emission coefficient (the source term of the radiative
  /// transfer equation, Physics/BlackbodyEmission.h)
  ///     eta = EmissionRadiancePerMetre rho B(T) / Y[B(EmissionReferenceTemperatureKelvin)]
  /// [Y/(sr m), the sun's relative units], with rho the density and T the input's array
  /// EmissionTemperatureArray (kelvin; default "temperature", what vtkNimbusSmokeSource
  /// writes): at the reference temperature a unit density emits EmissionRadiancePerMetre
  /// of luminance per metre (default 1); hotter is brighter and bluer (2000 K: 60x at a
  /// 1500 K reference), cooler dimmer and redder (1000 K: 3.5e-4x; smoke at 600 K: 1e-10x,
  /// nothing). The emitted light is attenuated on its way to the eye; with the
  /// discrete-direction multiple scattering (the default) the medium also scatters it,
  /// all orders (a source of the solve, Physics/MultipleScattering.h); with the other
  /// methods it is not scattered again (docs/smoke.md measures both against the path
  /// tracer).
  vtkSetMacro(TemperatureEmission, bool);
  vtkGetMacro(TemperatureEmission, bool);
  vtkBooleanMacro(TemperatureEmission, bool);
  vtkSetStdStringFromCharMacro(EmissionTemperatureArray);
  vtkGetCharFromStdStringMacro(EmissionTemperatureArray);
  virtual void SetEmissionRadiancePerMetre(double value);
  virtual double GetEmissionRadiancePerMetreMinValue() { return 0.0; }
  virtual double GetEmissionRadiancePerMetreMaxValue() { return 1e6; }
  vtkGetMacro(EmissionRadiancePerMetre, double);
  virtual void SetEmissionReferenceTemperatureKelvin(double value);
  virtual double GetEmissionReferenceTemperatureKelvinMinValue() { return 500.0; }
  virtual double GetEmissionReferenceTemperatureKelvinMaxValue() { return 50000.0; }
  vtkGetMacro(EmissionReferenceTemperatureKelvin, double);
  ///@}

  ///@{
  /// The lightning's light drawn the delta-M way (on by default): the solver's orders >= 2
  /// and the first scattering through the beam's reduced extinction (1 - f albedo) sigma,
  /// with the truncated phase function's asymmetry g' = (k1 - k2) / (1 - k2) in their
  /// degree-1 harmonics and (1 - f) of the scattering, f = k2 the forward peak the
  /// solver folds into the beam (Wiscombe 1977), plus the light the peak keeps on the
  /// beam: f albedo sigma E' through the peak's own lobe (widened by the beam's spread)
  /// and the full extinction, the sources' glow through the cloud. Off: J with the full
  /// phase function's k1 through the full extinction (in a thin cloud its clamped
  /// degree-1 lobe over-counts by up to a quarter at Cornette-Shanks 0.85; the delta-M
  /// view is the one measured against the path tracer, docs/lightning.md). Needs
  /// vtkNimbusLightningIllumination's first scattering on the density's grid (its
  /// "nimbus_lightning_first_scattering_reduced"); without it the lightning is drawn the
  /// plain way. The sun's terms do not change.
  vtkSetMacro(LightningDeltaMView, bool);
  vtkGetMacro(LightningDeltaMView, bool);
  vtkBooleanMacro(LightningDeltaMView, bool);
  ///@}

  /// How the light scattered more than once is computed (003, 004; see
  /// Physics/MultipleScattering.h and docs/multiple-scattering.md). The single
  /// scattering of the sun stays exact per sample (the slices); these add the rest:
  enum MultipleScatteringMethods
  {
    /// Nothing but k_multi (000 Eq. 1's constant, MultipleScattering above).
    MultipleScatteringNone = 0,
    /// Wrenninge et al. 2013's octaves in the shader (no precompute for the sun),
    /// plus the sky and the ground's light of order 1 (004 §3.5) when SkyLight.
    MultipleScatteringOctaves = 1,
    /// 004 §3.4's reference patterns, orders 2..MultipleScatteringOrders, plus
    /// the sky and ground light of order 1 (004 §3.5).
    MultipleScatteringReferencePatterns = 2,
    /// 003 Eq. 1's discrete-direction system iterated to all orders for the sun,
    /// the sky and the ground (the default).
    MultipleScatteringDiscreteDirections = 3
  };

  ///@{
  /// The method (MultipleScatteringMethods; default DiscreteDirections).
  vtkSetClampMacro(MultipleScatteringMethod, int, 0, 3);
  vtkGetMacro(MultipleScatteringMethod, int);
  void SetMultipleScatteringMethodToNone() { this->SetMultipleScatteringMethod(0); }
  void SetMultipleScatteringMethodToOctaves() { this->SetMultipleScatteringMethod(1); }
  void SetMultipleScatteringMethodToReferencePatterns() { this->SetMultipleScatteringMethod(2); }
  void SetMultipleScatteringMethodToDiscreteDirections() { this->SetMultipleScatteringMethod(3); }
  /// Discrete directions: the scatterings iterated explicitly (N: the radiance
  /// scattered 1..N times, so J of orders 2..N+1; stops earlier once converged; the
  /// rest is a geometric series). Default 32.
  vtkSetClampMacro(MultipleScatteringOrders, int, 2, 1000);
  vtkGetMacro(MultipleScatteringOrders, int);
  /// The solver's grid: the density texture's texels in blocks of this many per
  /// axis; 0 (the default): automatic, the smallest factor that leaves at most
  /// kAutomaticScatteringGridSide (32) points along the longest side (a 128^3
  /// cloud is solved on 32^3, a 96^3 one on 32^3 with blocks of 3).
  vtkSetClampMacro(MultipleScatteringDownsampling, int, 0, 256);
  vtkGetMacro(MultipleScatteringDownsampling, int);
  /// Directions of the discrete-direction system and of the sky-light look-ups
  /// (default 26, as 003 used).
  vtkSetClampMacro(MultipleScatteringDirections, int, 6, 1024);
  vtkGetMacro(MultipleScatteringDirections, int);
  /// Light from the sky and the ground on the cloud (004 §3.5; default on).
  vtkSetMacro(SkyLight, bool);
  vtkGetMacro(SkyLight, bool);
  vtkBooleanMacro(SkyLight, bool);
  /// Octaves: terms including the single scattering (1..16, default 4) and the
  /// per-octave scales of extinction a, scattering b and asymmetry c (0..1, 0.5).
  vtkSetClampMacro(Octaves, int, 1, 16);
  vtkGetMacro(Octaves, int);
  virtual void SetOctaveExtinctionScale(double value);
  virtual double GetOctaveExtinctionScaleMinValue() { return 0.01; }
  virtual double GetOctaveExtinctionScaleMaxValue() { return 1.0; }
  vtkGetMacro(OctaveExtinctionScale, double);
  virtual void SetOctaveScatteringScale(double value);
  virtual double GetOctaveScatteringScaleMinValue() { return 0.01; }
  virtual double GetOctaveScatteringScaleMaxValue() { return 1.0; }
  vtkGetMacro(OctaveScatteringScale, double);
  virtual void SetOctaveAsymmetryScale(double value);
  virtual double GetOctaveAsymmetryScaleMinValue() { return 0.01; }
  virtual double GetOctaveAsymmetryScaleMaxValue() { return 1.0; }
  vtkGetMacro(OctaveAsymmetryScale, double);
  /// Reference patterns: the highest order (2..8, default 3 as in 004; each order's
  /// small bias compounds: with all orders the sum comes out 1.6-1.9x a Monte Carlo
  /// reference, see docs/multiple-scattering.md),
  vtkSetClampMacro(PatternOrders, int, 2, 8);
  vtkGetMacro(PatternOrders, int);
  /// the sample space's half-width in grid points (default
  /// 6), the share of the contribution its kept paths cover (0.8, the paper's r)
  /// and the fraction of them evaluated per point (0.25).
  vtkSetClampMacro(PatternRadius, int, 1, 64);
  vtkGetMacro(PatternRadius, int);
  virtual void SetPatternContribution(double value);
  virtual double GetPatternContributionMinValue() { return 0.01; }
  virtual double GetPatternContributionMaxValue() { return 1.0; }
  vtkGetMacro(PatternContribution, double);
  virtual void SetPatternSelection(double value);
  virtual double GetPatternSelectionMinValue() { return 0.01; }
  virtual double GetPatternSelectionMaxValue() { return 1.0; }
  vtkGetMacro(PatternSelection, double);
  /// Memory the solver may take, MiB (0, the default: half of the physical memory).
  /// Estimated before allocating; above it the term is off, with an error.
  virtual void SetMultipleScatteringMemoryBudgetMiB(double value);
  virtual double GetMultipleScatteringMemoryBudgetMiBMinValue() { return 0.0; }
  virtual double GetMultipleScatteringMemoryBudgetMiBMaxValue() { return 1e12; }
  vtkGetMacro(MultipleScatteringMemoryBudgetMiB, double);
  /// Solves so far, the last one's seconds (the sky model and table when rebuilt,
  /// the grid, the solve, the upload), its estimated bytes and grid.
  int GetNumberOfMultipleScatteringSolves() const;
  double GetLastMultipleScatteringSeconds() const;
  double GetLastMultipleScatteringBytes() const;
  void GetMultipleScatteringGridDimensions(int dims[3]) const;
  static constexpr int kAutomaticScatteringGridSide = 32;
  ///@}

  ///@{
  /// The sun (nimbus::SunParameters, Physics/Sun.h): azimuth from north (+y) toward
  /// east (+x), elevation above the horizon (below it the earth blocks the sun when
  /// the atmosphere is on), the luminance of its irradiance above the atmosphere
  /// (relative units) and its blackbody temperature. Names carry the units.
  virtual void SetSunAzimuthDegrees(double value);
  virtual double GetSunAzimuthDegreesMinValue() { return -1e9; }
  virtual double GetSunAzimuthDegreesMaxValue() { return 1e9; }
  vtkGetMacro(SunAzimuthDegrees, double);
  virtual void SetSunElevationDegrees(double value);
  virtual double GetSunElevationDegreesMinValue() { return -90.0; }
  virtual double GetSunElevationDegreesMaxValue() { return 90.0; }
  vtkGetMacro(SunElevationDegrees, double);
  virtual void SetSunIlluminance(double value);
  virtual double GetSunIlluminanceMinValue() { return 0.0; }
  virtual double GetSunIlluminanceMaxValue() { return 1e9; }
  vtkGetMacro(SunIlluminance, double);
  virtual void SetSunTemperatureKelvin(double value);
  virtual double GetSunTemperatureKelvinMinValue() { return 1000.0; }
  virtual double GetSunTemperatureKelvinMaxValue() { return 40000.0; }
  vtkGetMacro(SunTemperatureKelvin, double);
  ///@}

  ///@{
  /// The air (nimbus::AtmosphereParameters, Physics/Atmosphere.h: Rayleigh + Mie,
  /// exponential densities over a spherical earth): the Rayleigh and Mie (haze)
  /// scattering coefficients at sea level, the Mie phase function's Cornette-Shanks
  /// asymmetry g, and the altitude above sea level of world z = 0. The same names
  /// as vtkNimbusSky and the scene format; the other parameters keep their defaults.
  vtkSetMacro(Atmosphere, bool);
  vtkGetMacro(Atmosphere, bool);
  vtkBooleanMacro(Atmosphere, bool);
  virtual void SetMieScatteringPerMetre(double value);
  virtual double GetMieScatteringPerMetreMinValue() { return 0.0; }
  virtual double GetMieScatteringPerMetreMaxValue() { return 1.0; }
  vtkGetMacro(MieScatteringPerMetre, double);
  /// The haze in the sky's words: turbidity T in [1, 10] (1: no aerosol, 2 very clear,
  /// 3 clear, 5 light haze, 10 hazy; vtkNimbusSky::SetTurbidity) sets
  /// MieScatteringPerMetre to nimbus::MieScatteringFromTurbidity(T) for this air (aerosol
  /// optical depth 0.025 (T - 1) at 550 nm, albedo 0.9, scale height 1.2 km: 1.875e-5 /m
  /// at T = 2); GetTurbidity is the inverse of the current MieScatteringPerMetre (2.07
  /// for the default 2e-5). Out-of-range values are clamped, NaN refused with an error.
  virtual void SetTurbidity(double turbidity);
  virtual double GetTurbidity();
  virtual void SetMieG(double value);
  virtual double GetMieGMinValue() { return -0.999; }
  virtual double GetMieGMaxValue() { return 0.999; }
  vtkGetMacro(MieG, double);
  virtual void SetRayleighScatteringPerMetre(double value);
  virtual double GetRayleighScatteringPerMetreMinValue() { return 0.0; }
  virtual double GetRayleighScatteringPerMetreMaxValue() { return 1.0; }
  vtkGetMacro(RayleighScatteringPerMetre, double);
  virtual void SetSceneAltitudeMetres(double value);
  virtual double GetSceneAltitudeMetresMinValue() { return 0.0; }
  virtual double GetSceneAltitudeMetresMaxValue() { return 50000.0; }
  vtkGetMacro(SceneAltitudeMetres, double);
  ///@}

  ///@{
  /// Multiple scattering in the air (default on; needs Atmosphere): the air's
  /// source gains the isotropic term of the scattering orders >= 2 of Hillaire 2020
  /// (§5.5), (sigma_s,R rho_R + sigma_s,M rho_M) M_ms(r, mu_s), and the ground the
  /// sky's light, albedo/pi E_sky(mu_s), both from a nimbus::SkyModel of the
  /// frame's air and ground albedo (Physics/Sky.h; built only when this is on and
  /// the air or the albedo changed). Neither term is shadowed by the cloud (the
  /// light of the higher orders comes from the whole sky, not the sun's direction;
  /// the cloud's occlusion of the sky is ignored). Off: single scattering in the
  /// air and a ground lit by the sun alone (as 000).
  vtkSetMacro(AirMultipleScattering, bool);
  vtkGetMacro(AirMultipleScattering, bool);
  vtkBooleanMacro(AirMultipleScattering, bool);
  ///@}

  ///@{
  /// Which axis of the world points up (nimbus::UpAxis: 0 +X, 1 +Y, 2 +Z (default),
  /// 3 -Y). The sun's azimuth and elevation, the ground plane, the altitude of the
  /// air and the sky are taken about that axis; the data and the camera are not
  /// moved (a y-up file looks right from a y-up camera). Over a Nimbus sky the sky's
  /// up axis is used (vtkNimbusSky::UpAxis).
  virtual void SetUpAxis(int value);
  vtkGetMacro(UpAxis, int);
  ///@}

  ///@{
  /// Ground plane at height GroundHeight along the up axis (world units) with a
  /// grey Lambertian albedo. With GroundBelowData (default on) the ground is never
  /// above the data's lowest point: it lies at min(GroundHeight, the bottom of the
  /// data's box), so a cloud that reaches below GroundHeight is not cut by it
  /// (GetLastGroundHeight says where it was drawn). Off: exactly at GroundHeight.
  vtkSetMacro(GroundBelowData, bool);
  vtkGetMacro(GroundBelowData, bool);
  vtkBooleanMacro(GroundBelowData, bool);
  double GetLastGroundHeight() const;
  vtkSetMacro(Ground, bool);
  vtkGetMacro(Ground, bool);
  vtkBooleanMacro(Ground, bool);
  virtual void SetGroundHeight(double value);
  virtual double GetGroundHeightMinValue() { return -1e30; }
  virtual double GetGroundHeightMaxValue() { return 1e30; }
  vtkGetMacro(GroundHeight, double);
  virtual void SetGroundAlbedo(double value);
  virtual double GetGroundAlbedoMinValue() { return 0.0; }
  virtual double GetGroundAlbedoMaxValue() { return 1.0; }
  vtkGetMacro(GroundAlbedo, double);
  ///@}

  ///@{
  /// Shafts of light: the atmosphere is shadowed by the cloud (needs Atmosphere).
  vtkSetMacro(Shafts, bool);
  vtkGetMacro(Shafts, bool);
  vtkBooleanMacro(Shafts, bool);
  ///@}

  ///@{
  /// Quality knobs. NumberOfSlices: shadow-view slices over the cloud box (the
  /// main knob); SliceAngleRatio: a of theta_e : theta_s = 1 : a (000 §4.2);
  /// ShadowSurfaceSize: texels per side of the shadow surface; AtmosphereSteps:
  /// samples of the air per ray outside the cloud box, in front of it and again
  /// behind it; where a ray can be in the cloud's shadow (the shafts), one more
  /// per slice plane it crosses there, from AtmosphereSteps / 2 to
  /// min(2 AtmosphereSteps, slices). Default 32: at 16 the march's quadrature
  /// differs from the slices' by up to 3 of 255 levels in the sky toward the sun, a
  /// visible outline of an empty box (docs/svs-mapper.md, Atmosphere steps).
  vtkSetClampMacro(NumberOfSlices, int, 1, 8192);
  vtkGetMacro(NumberOfSlices, int);
  virtual void SetSliceAngleRatio(double value);
  virtual double GetSliceAngleRatioMinValue() { return 0.01; }
  virtual double GetSliceAngleRatioMaxValue() { return 100.0; }
  vtkGetMacro(SliceAngleRatio, double);
  vtkSetClampMacro(ShadowSurfaceSize, int, 1, 16384);
  vtkGetMacro(ShadowSurfaceSize, int);
  vtkSetClampMacro(AtmosphereSteps, int, 1, 4096);
  vtkGetMacro(AtmosphereSteps, int);
  ///@}

  ///@{
  /// How the cloud is drawn (docs/ray-march.md):
  ///  - ShadowViewSlicing (0, the default of this class): the paper's method (000):
  ///    NumberOfSlices slices, each seen from the eye and added to a shadow surface
  ///    facing the sun, then the air outside the box marched per pixel.
  ///  - RayMarching (1, the default of ParaView's Cloud representation): one pass
  ///    per frame that marches each view ray through the box with a step of
  ///    RayMarchStepTexels texels, reading the sun's transmittance through the cloud
  ///    from a volume on the density's texels (computed on the CPU when the
  ///    density, the sun or the optics change: SunDepthVolume.h), skipping empty
  ///    blocks and stopping where the cloud is opaque; the air comes from a
  ///    look-up volume over the view (Hillaire 2020's aerial perspective), and the
  ///    cloud's shadow in it is marched only where it can fall (one sample per four
  ///    texels, at most AtmosphereSteps / 2). Ten to thirty times faster than 256
  ///    slices, as close to the path tracer; it loses where a shadow's edge is finer
  ///    than the density's texels. One piece of a distributed cloud
  ///    (PieceCompositing) is always drawn by slicing.
  enum
  {
    ShadowViewSlicing = 0,
    RayMarching = 1
  };
  vtkSetClampMacro(RenderingMethod, int, ShadowViewSlicing, RayMarching);
  vtkGetMacro(RenderingMethod, int);
  void SetRenderingMethodToShadowViewSlicing() { this->SetRenderingMethod(ShadowViewSlicing); }
  void SetRenderingMethodToRayMarching() { this->SetRenderingMethod(RayMarching); }
  /// The ray march's step in texels of the density (the smallest texel side; default
  /// 2: measured against the path tracer as accurate as 1 at two thirds of the time,
  /// docs/ray-march.md). Larger: faster, with more grain in thin cloud and softer detail.
  virtual void SetRayMarchStepTexels(double value);
  virtual double GetRayMarchStepTexelsMinValue() { return 0.05; }
  virtual double GetRayMarchStepTexelsMaxValue() { return 16.0; }
  vtkGetMacro(RayMarchStepTexels, double);
  /// Times the sun-depth volume was computed (tests and benchmarks), and the seconds
  /// of the last computation.
  int GetNumberOfSunDepthBuilds() const;
  double GetLastSunDepthSeconds() const;
  ///@}

  ///@{
  /// The view's own lights (docs/lights.md): lamps and spotlights of the renderer
  /// (vtkLight, ParaView's Light Inspector) light the air's haze, the cloud and the
  /// ground, with the shadows of the view's opaque geometry (a shadow map per light) and
  /// of the cloud (its optical depth toward the light). Drawn by the ray-marched method
  /// (RayMarching) only; the slices ignore them.
  ///  - LightSources: NoLights (0), or PositionalLights (1, the default): the switched-on
  ///    positional lights of the renderer (vtkLight::GetPositional; a ConeAngle below 90
  ///    degrees makes a spotlight; the headlight and the light kit are not positional).
  ///  - A light of Intensity I and DiffuseColor c has the radiant intensity
  ///    LightIntensityScale x I x c on the beam's axis, in Y/sr of the sun's relative
  ///    units per channel of linear sRGB: at d metres it gives the irradiance
  ///    LightIntensityScale I c / d^2 (a sun of that illuminance, at normal incidence).
  ///  - SpotEdgeWidthDegrees: the soft edge inside every spotlight's cone (vtkLight has
  ///    none): full light within ConeAngle - width of the axis, none beyond ConeAngle.
  ///  - SetLightMap: an image whose luminance multiplies every spotlight's beam, mapped
  ///    over the cone as a slide projector throws it (002 §6.2's light map; a gobo or
  ///    a stained-glass window; Physics/SpotLight.h for the frame). nullptr: none.
  ///  - LightShaftMethod: how the haze's in-scattering is integrated along the view
  ///    rays: LightShaftsByRayMarching (0, the default; LightSamples (default 16)
  ///    equi-angular samples per light inside its beam, on 1 in LightShaftDownsampling
  ///    pixels per side) or LightShaftsByVirtualPlanes (1,
  ///    002 §6.2: NumberOfVirtualPlanes planes parallel to the screen over the lit depth,
  ///    drawn back to front and added to the picture).
  ///  - LightShadowMapSize: texels per side of each of a light's six shadow-map faces
  ///    (0: the opaque geometry casts no shadow). LightCloudSteps (default 48): samples of
  ///    the cloud between a texel of the lights' transmittance volume (at most 64^3 over
  ///    the density's box, redrawn when the density or a light moves) and the light (0:
  ///    the cloud casts no shadow in the beams).
  ///  - MaximumLights: at most this many lights (up to 8), the brightest at the scene
  ///    first; the others are left out with a warning. Lights whose beam misses the
  ///    scene's bounds cost nothing.
  enum
  {
    NoLights = 0,
    PositionalLights = 1
  };
  vtkSetClampMacro(LightSources, int, NoLights, PositionalLights);
  vtkGetMacro(LightSources, int);
  virtual void SetLightIntensityScale(double value);
  virtual double GetLightIntensityScaleMinValue() { return 0.0; }
  virtual double GetLightIntensityScaleMaxValue() { return 1e12; }
  vtkGetMacro(LightIntensityScale, double);
  virtual void SetSpotEdgeWidthDegrees(double value);
  virtual double GetSpotEdgeWidthDegreesMinValue() { return 0.0; }
  virtual double GetSpotEdgeWidthDegreesMaxValue() { return 90.0; }
  vtkGetMacro(SpotEdgeWidthDegrees, double);
  virtual void SetLightMap(vtkImageData* image);
  vtkGetObjectMacro(LightMap, vtkImageData);
  enum
  {
    LightShaftsByRayMarching = 0,
    LightShaftsByVirtualPlanes = 1
  };
  vtkSetClampMacro(LightShaftMethod, int, LightShaftsByRayMarching, LightShaftsByVirtualPlanes);
  vtkGetMacro(LightShaftMethod, int);
  vtkSetClampMacro(LightSamples, int, 1, 1024);
  vtkGetMacro(LightSamples, int);
  /// The ray-marched shafts are drawn on 1 / LightShaftDownsampling of the pixels per
  /// side in their own pass and brought to every pixel by depth-aware weights (1: in the
  /// march, at every pixel; default 2, a quarter of the pixels).
  vtkSetClampMacro(LightShaftDownsampling, int, 1, 4);
  vtkGetMacro(LightShaftDownsampling, int);
  vtkSetClampMacro(NumberOfVirtualPlanes, int, 1, 4096);
  vtkGetMacro(NumberOfVirtualPlanes, int);
  vtkSetClampMacro(LightShadowMapSize, int, 0, 4096);
  vtkGetMacro(LightShadowMapSize, int);
  vtkSetClampMacro(LightCloudSteps, int, 0, 256);
  vtkGetMacro(LightCloudSteps, int);
  vtkSetClampMacro(MaximumLights, int, 0, 8);
  vtkGetMacro(MaximumLights, int);
  /// The lights the last frame drew, and the shadow casters it drew into their maps.
  int GetNumberOfLightsLastRender() const;
  int GetNumberOfShadowCastersLastRender() const;
  ///@}

  ///@{
  /// Time each pass on the GPU with timer queries (GL_TIME_ELAPSED; default off: the
  /// mapper then waits for the frame's queries at its end). GetLastPassTimes: the last
  /// frame drawn in full, "pass seconds; pass seconds; ..." in the order of the passes
  /// (the slices and their shadow updates summed as "slices"); empty when off.
  vtkSetMacro(TimePasses, bool);
  vtkGetMacro(TimePasses, bool);
  vtkBooleanMacro(TimePasses, bool);
  const char* GetLastPassTimes() const;
  ///@}

  ///@{
  /// Jittered slices (default on): each pixel's slice planes, and each shadow
  /// texel's, are shifted by a fixed fraction of the slice spacing in
  /// [-1/2, 1/2) (interleaved gradient noise of the pixel), so the planes do not
  /// meet a cloud's edges at the same depth in neighbouring pixels: the
  /// diagonal hatching on sharp-edged clouds and the streaks in their shadows
  /// become a fine, static grain. Off: the paper's planes (000 §4.2).
  vtkSetMacro(SliceJitter, bool);
  vtkGetMacro(SliceJitter, bool);
  vtkBooleanMacro(SliceJitter, bool);
  ///@}

  ///@{
  /// Automatic quality (docs/svs-mapper.md, "Frame budget"). Quality in (0, 1] is
  /// the fraction of a full frame's work that still frames do: 1 renders
  /// NumberOfSlices slices into the whole viewport with a ShadowSurfaceSize shadow
  /// surface; lower levels take fewer slices (down to a quarter), then a smaller
  /// image (down to 1/16 per side, upscaled in the composite) and shadow surface
  /// (nimbus::ComputeFrameLevel). While the render window asks for an interactive
  /// frame (its DesiredUpdateRate >= InteractiveUpdateRate: ParaView's interactive
  /// renders ask 5 frames/s, VTK's interactor 15, still renders less than 0.01) the
  /// mapper picks the highest level at most Quality that its measured cost model
  /// (nimbus::FrameCostModel: the passes' seconds of the frames before, against their
  /// levels) predicts to take at most FrameBudgetMilliseconds; the next still frame
  /// returns to Quality. FrameBudgetMilliseconds 0: interactive frames use Quality.
  virtual void SetFrameBudgetMilliseconds(double value);
  virtual double GetFrameBudgetMillisecondsMinValue() { return 0.0; }
  virtual double GetFrameBudgetMillisecondsMaxValue() { return 1e7; }
  vtkGetMacro(FrameBudgetMilliseconds, double);
  virtual void SetQuality(double value);
  virtual double GetQualityMinValue();
  virtual double GetQualityMaxValue() { return 1.0; }
  vtkGetMacro(Quality, double);
  virtual void SetInteractiveUpdateRate(double value);
  virtual double GetInteractiveUpdateRateMinValue() { return 1e-6; }
  virtual double GetInteractiveUpdateRateMaxValue() { return 1e6; }
  vtkGetMacro(InteractiveUpdateRate, double);
  /// The last frame drawn: its quality level, image scale (rendered pixels per
  /// viewport pixel, per side) and slices; whether it was interactive; whether it
  /// reused the cloud image of the frame before (nothing the cloud depends on had
  /// changed: the camera, the viewport, the data, the mapper's and the sky's
  /// settings, the opaque geometry's depth); the seconds of its passes (0 when
  /// reused); whether it was aborted (the render window's AbortRender, or
  /// SetAbortExecute, seen between slices once the frame has taken a second).
  double GetLastFrameQuality() const;
  double GetLastFrameImageScale() const;
  int GetLastFrameSlices() const;
  bool GetLastFrameInteractive() const;
  bool GetLastFrameReused() const;
  double GetLastFrameSeconds() const;
  bool GetLastFrameAborted() const;
  ///@}

  ///@{
  /// Metres per world unit (distances and heights are converted with it).
  virtual void SetMetresPerUnit(double value);
  virtual double GetMetresPerUnitMinValue() { return 1e-9; }
  virtual double GetMetresPerUnitMaxValue() { return 1e9; }
  vtkGetMacro(MetresPerUnit, double);
  ///@}

  ///@{
  /// Framebuffer value = Exposure * radiance (+ attenuated background); with
  /// EncodeSrgb the result (and the background read from the framebuffer) is
  /// treated as display-encoded sRGB.
  virtual void SetExposure(double value);
  virtual double GetExposureMinValue() { return 0.0; }
  virtual double GetExposureMaxValue() { return 1e9; }
  vtkGetMacro(Exposure, double);
  vtkSetMacro(EncodeSrgb, bool);
  vtkGetMacro(EncodeSrgb, bool);
  vtkBooleanMacro(EncodeSrgb, bool);
  ///@}

  ///@{
  /// The sky drawn behind this cloud (nullptr by default; the mapper keeps a
  /// reference). Set it when the cloud is rendered in front of a
  /// vtkNimbusSkyBackground, usually the one in the same renderer; the mapper does
  /// not search the renderer for one. ParaView's Cloud representation sets the
  /// view's sky (vtkNimbusSkyBackground::RENDERER_SKY_BACKGROUND) before each render.
  virtual void SetSkyBackground(vtkNimbusSkyBackground* background);
  vtkGetObjectMacro(SkyBackground, vtkNimbusSkyBackground);
  ///@}

  ///@{
  /// Follow the sky of the SkyBackground (default on): while one is set and
  /// visible (and the mapper is not Unlit), its vtkNimbusSky replaces the sun
  /// (SunAzimuthDegrees, SunElevationDegrees, SunIlluminance 1,
  /// SunTemperatureKelvin the sky's), the air
  /// (RayleighScatteringPerMetre, MieScatteringPerMetre, MieG, SceneAltitudeMetres),
  /// GroundHeight (sea level), GroundAlbedo, MetresPerUnit, Exposure and EncodeSrgb
  /// (the sky's exposure and white balance, sRGB on); the background is the sky
  /// and the cloud is composited over it as I = S - T_cl S_clear + T_cl L_sky
  /// (svsCompositeFS.glsl), which costs a second accumulation target.
  vtkSetMacro(UseSceneSky, bool);
  vtkGetMacro(UseSceneSky, bool);
  vtkBooleanMacro(UseSceneSky, bool);
  /// Whether the last render followed a scene sky, and that sky's sun elevation
  /// (degrees; the mapper's own when it did not).
  bool GetLastRenderUsedSceneSky() const;
  double GetLastSunElevationDegrees() const;
  ///@}

  ///@{
  /// Benchmark floor: composite the same slices without any lighting (no shadow
  /// surface, no atmosphere, no ground). Not for pictures.
  vtkSetMacro(Unlit, bool);
  vtkGetMacro(Unlit, bool);
  ///@}

  ///@{
  /// Largest texture side used for the density (0: the GL limit). Larger volumes
  /// are downsampled with a warning. Lower it to save GPU memory.
  vtkSetClampMacro(MaximumTextureSize, int, 0, 1 << 16);
  vtkGetMacro(MaximumTextureSize, int);
  ///@}

  ///@{
  /// Memory the density texture may take, MiB (0, the default: half of the
  /// physical memory, nimbus::DefaultMemoryBudgetBytes). Counted as 8 bytes per
  /// texel (the texture and its converted copy). A volume over the budget is
  /// downsampled further, with a warning; one that cannot fit even at one texel
  /// is not drawn (an error).
  virtual void SetTextureMemoryBudgetMiB(double value);
  virtual double GetTextureMemoryBudgetMiBMinValue() { return 0.0; }
  virtual double GetTextureMemoryBudgetMiBMaxValue() { return 1e12; }
  vtkGetMacro(TextureMemoryBudgetMiB, double);
  ///@}

  ///@{
  /// Keep a float copy of each frame's radiance (before Exposure and the
  /// background): an image of the viewport size with the 4-component point array
  /// "radiance" = (linear sRGB radiance, cloud transmittance). For measurements
  /// that must not be limited by an 8-bit framebuffer.
  vtkSetMacro(CaptureRadiance, bool);
  vtkGetMacro(CaptureRadiance, bool);
  vtkBooleanMacro(CaptureRadiance, bool);
  vtkImageData* GetRadianceImage();
  ///@}

  ///@{
  /// One piece of a distributed cloud (docs/parallel.md). Under MPI each
  /// rank renders its piece and ParaView composites the ranks' images in visibility
  /// order with the premultiplied "over" operator (IceT). ParaView's Cloud
  /// representation sets these; a VTK program composing its own images may too.
  ///  - PieceCompositing: this image is one layer of such a composite.
  ///  - DrawOutsideRegions (with PieceCompositing): this layer is the bottom one (the
  ///    rank last in the compositing order): it draws the air (all of it, also in
  ///    the other pieces' boxes) and the ground, their shafts and the cloud's shadow
  ///    on them, over the view's background (PieceBackground: the renderer's
  ///    background colour, which ParaView's parallel framebuffer is cleared
  ///    without), opaque. Without it the layer is premultiplied (radiance, 1 - T_cl)
  ///    of this piece's cloud over a transparent framebuffer, plus the air in front
  ///    of the piece weighted by 1 - T_cl, which the bottom layer's air loses under it.
  ///  - SlicingBounds (world): the slice planes are those of this box (the whole
  ///    cloud's), kept where they cut the piece, so every piece samples the planes a
  ///    single renderer would.
  ///    Invalid (min > max, the default): the piece's own box.
  ///  - ExternalDensity: a coarse copy of the WHOLE density (point scalars, world
  ///    origin and spacing, no direction matrix) through which the sun reaches this
  ///    piece from the other pieces (ExternalShadow.h); nullptr: no other pieces.
  vtkSetMacro(PieceCompositing, bool);
  vtkGetMacro(PieceCompositing, bool);
  vtkBooleanMacro(PieceCompositing, bool);
  vtkSetMacro(DrawOutsideRegions, bool);
  vtkGetMacro(DrawOutsideRegions, bool);
  vtkBooleanMacro(DrawOutsideRegions, bool);
  vtkSetVector3Macro(PieceBackground, double);
  vtkGetVector3Macro(PieceBackground, double);
  vtkSetVector6Macro(SlicingBounds, double);
  vtkGetVector6Macro(SlicingBounds, double);
  void SetExternalDensity(vtkImageData* coarse);
  vtkImageData* GetExternalDensity();
  ///@}

  ///@{
  /// The input's bounds; for the piece that draws the air and the ground
  /// (PieceCompositing and DrawOutsideRegions) together with ViewCoverBounds, a
  /// box (world) whose projection covers the whole view: ParaView's compositor
  /// (IceT) keeps of each rank's image only the pixels its props' bounds cover, and
  /// that piece's pixels are the whole view. The representation sets it from the
  /// camera before each render (a box around the view frustum between the cloud's
  /// distance and twice it, which does not contain the eye); Render clears it, so
  /// that a camera reset between renders sees the cloud's own bounds. Setting it does
  /// not modify the mapper (a per-render hint: an unchanged frame is still reused).
  double* GetBounds() VTK_SIZEHINT(6) override;
  using Superclass::GetBounds;
  void SetViewCoverBounds(const double bounds[6]);
  vtkGetVector6Macro(ViewCoverBounds, double);
  ///@}

  /// Counters of the last render and of the uploads so far (for tests and
  /// benchmarks): volume uploads, atmosphere-table builds, interval/phase builds,
  /// passes drawn in the last frame.
  int GetNumberOfVolumeUploads() const;
  int GetNumberOfAtmosphereBuilds() const;
  int GetNumberOfIntervalPhaseBuilds() const;
  int GetNumberOfPassesLastRender() const;
  /// Whether the last render traversed the slices back to front.
  bool GetLastBackToFront() const;
  /// Dimensions of the density texture last uploaded.
  void GetTextureDimensions(int dims[3]) const;

  /// The scalar mode, without Modified(): the array it selects is resolved every
  /// frame and is part of the frame's reuse key, and ParaView's Cloud representation
  /// sets it twice per render with Solid Color (its superclass the point field data
  /// mode, then the representation the default mode that finds the active scalars);
  /// a Modified() each time would keep any frame from being reused.
  void SetScalarMode(int mode) override;

  void Render(vtkRenderer* renderer, vtkVolume* volume) override;
  void ReleaseGraphicsResources(vtkWindow* window) override;

protected:
  vtkNimbusCloudVolumeMapper();
  ~vtkNimbusCloudVolumeMapper() override;

  double ExtinctionPerDensity = 0.02;
  double Albedo = 0.99;
  bool TemperatureEmission = false;
  bool LightningDeltaMView = true;
  std::string EmissionTemperatureArray = "temperature";
  double EmissionRadiancePerMetre = 1.0;
  double EmissionReferenceTemperatureKelvin = 1500.0;
  double CloudG = 0.85;
  double MultipleScattering = 0.0;
  int MultipleScatteringMethod = MultipleScatteringDiscreteDirections;
  int MultipleScatteringOrders = 32;
  int MultipleScatteringDownsampling = 0;
  int MultipleScatteringDirections = 26;
  bool SkyLight = true;
  int Octaves = 4;
  double OctaveExtinctionScale = 0.5;
  double OctaveScatteringScale = 0.5;
  double OctaveAsymmetryScale = 0.5;
  int PatternOrders = 3;
  int PatternRadius = 6;
  double PatternContribution = 0.8;
  double PatternSelection = 0.25;
  double MultipleScatteringMemoryBudgetMiB = 0.0;
  // The sun's defaults are nimbus::SunParameters' (Physics/Sun.h), set in the constructor.
  double SunAzimuthDegrees = 0.0;
  double SunElevationDegrees = 0.0;
  double SunIlluminance = 1.0;
  double SunTemperatureKelvin = 5778.0;
  bool Atmosphere = true;
  double MieScatteringPerMetre = 2.0e-5;
  double MieG = 0.76;
  double RayleighScatteringPerMetre = 13.5e-6;
  double SceneAltitudeMetres = 0.0;
  bool AirMultipleScattering = true;
  bool Ground = true;
  double GroundHeight = 0.0;
  bool GroundBelowData = true;
  int UpAxis = 2;
  double GroundAlbedo = 0.2;
  bool Shafts = true;
  int NumberOfSlices = 256;
  double SliceAngleRatio = 1.0;
  int ShadowSurfaceSize = 512;
  int AtmosphereSteps = 32;
  int RenderingMethod = ShadowViewSlicing;
  int LightSources = PositionalLights;
  double LightIntensityScale = 1.0;
  double SpotEdgeWidthDegrees = 2.0;
  vtkImageData* LightMap = nullptr;
  int LightShaftMethod = LightShaftsByRayMarching;
  int LightSamples = 16;
  int LightShaftDownsampling = 2;
  int NumberOfVirtualPlanes = 64;
  int LightShadowMapSize = 256;
  int LightCloudSteps = 48;
  int MaximumLights = 8;
  double RayMarchStepTexels = 2.0;
  bool TimePasses = false;
  bool SliceJitter = true;
  double MetresPerUnit = 1.0;
  double Exposure = 1.0;
  bool EncodeSrgb = false;
  bool Unlit = false;
  int MaximumTextureSize = 0;
  double TextureMemoryBudgetMiB = 0.0;
  bool CaptureRadiance = false;
  bool UseSceneSky = true;
  bool PieceCompositing = false;
  bool DrawOutsideRegions = true;
  double PieceBackground[3] = { 0.0, 0.0, 0.0 };
  double SlicingBounds[6] = { 1.0, -1.0, 1.0, -1.0, 1.0, -1.0 };
  double PieceBounds[6] = { 1.0, -1.0, 1.0, -1.0, 1.0, -1.0 };
  double ViewCoverBounds[6] = { 1.0, -1.0, 1.0, -1.0, 1.0, -1.0 };
  vtkNimbusSkyBackground* SkyBackground = nullptr;
  double FrameBudgetMilliseconds = 200.0;
  double Quality = 1.0;
  double InteractiveUpdateRate = 1.0;

private:
  vtkNimbusCloudVolumeMapper(const vtkNimbusCloudVolumeMapper&) = delete;
  void operator=(const vtkNimbusCloudVolumeMapper&) = delete;

  /// What one frame computes once and its passes read (defined in the .cxx).
  struct FrameState;

  ///@{
  /// Render's boundary: the frame (false when a step ended it), an error reported
  /// once until a frame succeeds or another error comes, and the clean-up after an
  /// exception.
  bool RenderFrame(vtkRenderer* renderer, vtkVolume* volume, FrameState& frame);
  void ReportFrameError(const std::string& message);
  void AbandonFrame(FrameState& frame);
  ///@}

  ///@{
  /// The steps of Render, in order. The bool steps end the frame when false.
  bool UpdateDensityTexture(vtkRenderer* renderer, FrameState& frame);
  bool ComputeFrameSettings(FrameState& frame);
  bool ComputeFrameGeometry(vtkRenderer* renderer, vtkVolume* volume, FrameState& frame);
  void ChooseFrameLevel(vtkRenderer* renderer, FrameState& frame);
  std::vector<double> FrameReuseKey(const FrameState& frame);
  bool ComputeDataToWorld(vtkVolume* volume, vtkMatrix4x4* dataToWorld);
  void PlaceGroundBelowData(FrameState& frame);
  void CopySceneColorAndDepth(FrameState& frame);
  bool UpdateAtmosphereTable(FrameState& frame);
  void UpdateMultipleScattering(FrameState& frame);
  void UpdateLightning(FrameState& frame);
  void UseLightningTarget(const FrameState& frame, bool on);
  void UpdateEmission(FrameState& frame);
  const nimbus::SkyViewLut* CloudSkyView(const FrameState& frame, double cloudAltitude);
  const nimbus::SkyModel& FrameSkyModel(const FrameState& frame);
  static std::vector<double> FrameSkyKey(const FrameState& frame);
  void BeginPasses(const FrameState& frame);
  void ClearShadowSurface(const FrameState& frame);
  void UpdateExternalShadow(FrameState& frame);
  void RenderIntervalPhase(const FrameState& frame);
  void RenderRayEnds(const FrameState& frame);
  void ClearAccumulation(const FrameState& frame);
  void RenderOutsideRegion(const FrameState& frame, bool behindBox);
  bool RenderSlices(vtkRenderer* renderer, const FrameState& frame);
  // The ray-marched method (RayMarching).
  bool UsesRayMarching() const;
  void EnsureImageTarget(vtkTextureObject* target, const FrameState& frame);
  void UpdateSunDepthVolume(FrameState& frame);
  void RenderAirFroxels(const FrameState& frame);
  void RenderCloudMarch(const FrameState& frame);
  // The view's lights (docs/lights.md).
  void UpdateViewLights(vtkRenderer* renderer, FrameState& frame);
  void UpdateLightMapTexture(FrameState& frame);
  void UpdateLightCloudVolume(FrameState& frame);
  bool ShaftsApart(const FrameState& frame) const;
  void RenderLightShafts(const FrameState& frame);
  void SetViewLightUniforms(vtkShaderProgram* program, const FrameState& frame);
  void AddViewLightsToSolve(const FrameState& frame, double cloudMiddleZ,
    nimbus::CloudLighting& lighting, std::vector<double>& key);
  vtkDataArray* EmissionForSolve(const FrameState& frame, std::vector<double>& key) const;
  void RenderVirtualPlanes(const FrameState& frame);
  void SetCloudLightUniforms(vtkShaderProgram* program, const FrameState& frame);
  void CaptureRadianceImage(const FrameState& frame);
  void RenderComposite(const FrameState& frame);
  void EndPasses(const FrameState& frame);
  ///@}

  ///@{
  /// Pieces of the steps: the sky this frame follows (or nullptr), the uniforms
  /// every pass shares, one slice seen from the eye (scissored to `scissor`
  /// unless nullptr) and its optical depth added to the shadow surface (within
  /// the texels `texels`).
  vtkNimbusSky* GetFollowedSky();
  void SetCommonUniforms(vtkShaderProgram* program, const FrameState& frame);
  void RenderSliceFromEye(
    const FrameState& frame, vtkShaderProgram* program, float offset, const int* scissor);
  void RenderSliceShadow(
    const FrameState& frame, vtkShaderProgram* program, float offset, const int texels[4]);
  ///@}

  struct Internals;
  std::unique_ptr<Internals> Internal;
};

#endif
