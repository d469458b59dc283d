/**
 * @class   vtkNimbusCloudSplatMapper
 * @brief   Metaball clouds drawn by two-pass billboard splatting (002 §3.3).
 *
 * Input: points, one per metaball, with a point array of radii (RadiusArrayName,
 * default "radius", world units) and one of centre densities (DensityArrayName,
 * default "density", dimensionless): vtkNimbusMetaballCloudSource's second output
 * (port 1). Each ball's density is d f(|x - c|^2 / R^2) with Nimbus's metaball
 * kernel (CloudSplats.h), its extinction ExtinctionPerDensity x that (1/m).
 *
 * The frame, as 002 §3.3:
 *  1. The sun's pass: the light from the sun at each ball. SunLightMethod chooses how:
 *     - AccumulationTexture (default; the GPU variant, no read-back): squares facing
 *       the sun, in a parallel projection along the sunlight, add their optical depth
 *       into a 3-D float texture of SunTextureLayers planes across the cloud
 *       (SunTextureSize^2 texels each): layer k holds the depth from the sun to its
 *       plane, each ball adding the part of its column in front of the plane
 *       (the precomputed partial-column table P(u, h)); the balls are sorted by their
 *       front toward the sun and layer k draws only those that reach its plane. Each
 *       ball then reads the texture at its centre (trilinear: between the two nearest
 *       planes) in the view pass's vertex shader: exp(-tau).
 *     - FramebufferReadBack (the paper's): a framebuffer cleared to 1; the balls,
 *       sorted by distance from the sun, nearest first, each read the pixel under
 *       its centre (glReadPixels: the sun's transmittance in front of it, times its
 *       own half column exp(-kappa C(0) / 2)) and then multiply the framebuffer by
 *       their attenuation ratio texture. One read per ball: slow (docs/splats.md).
 *  2. The view pass: squares facing the viewer, sorted back to front, each
 *     multiplying the framebuffer by its attenuation ratio a = exp(-kappa C(u)) (the
 *     precomputed billboard texture of the cumulative density C) and adding its
 *     colour Albedo x CornetteShanks(mu, CloudG) x the sun's colour x the sun's
 *     transmittance x (1 - a) x Exposure: single scattering with the sun's light taken
 *     at each ball's centre. With the accumulation texture and SunLightSamples > 0
 *     (default 8) each fragment instead integrates the light along its own ray through
 *     its ball, reading the texture at that many points (docs/splats.md: the light at
 *     the centre makes overlapping balls far too dark).
 * With MultipleScattering on (default off) the light scattered more than once is added:
 * the balls' density splatted onto a grid of MultipleScatteringGridSize points on its
 * longest side (CloudSplats.h SplatBallsOntoGrid), the sun's light of all orders solved
 * there (Physics/MultipleScattering.h, DiscreteDirections; the sky's light too over a sky,
 * below) and the in-scattered
 * radiance J(x, w) read from three 3-D textures at the fragment's samples (or at the
 * ball's centre), with the delta-M forward peak's part of the sun's light as the cloud
 * mapper adds it. Solved again only when the balls or the sun change.
 *
 * Over a Nimbus sky (SetSkyBackground: the vtkNimbusSkyBackground drawn behind the balls,
 * followed while it is visible; in ParaView the Cloud Splats representation hands it the
 * view's sky) the balls take that sky's sun
 * (elevation, azimuth, temperature, illuminance 1), air, ground albedo, metres per unit
 * and display scale (its exposure and white balance) instead of their own, as
 * vtkNimbusCloudVolumeMapper does over its sky background, and they get what the
 * Cloud representation's clouds get from it:
 *  - the sun reddened by the air down to each ball (the atmosphere table's E_sun(z),
 *    nimbus::BuildAtmosphereTable, the cloud mapper's row 0);
 *  - SkyLight (default on): the sky's and the ground's light on the balls, all orders,
 *    from the same solver and grid as MultipleScattering (Physics/MultipleScattering.h,
 *    DiscreteDirections, the sky seen from the balls' middle as a nimbus::SkyViewLut of
 *    the sky's model, 004 §3.5: the ground as upward sky light), as the cloud mapper's
 *    SkyLight; with MultipleScattering off the solve carries the sky alone;
 *  - AerialPerspective (default on): the air between the eye and each ball, its
 *    transmittance and in-scattered light from the sky's aerial-perspective table
 *    (nimbus::AerialPerspectiveLut, what vtkNimbusSkyPass applies to geometry):
 *    colour T_air C + (1 - a) L_air;
 *  - the frame's encoding: the balls composited over the sky's sRGB-encoded frame in
 *    linear light (decoded, blended, encoded).
 * The balls are drawn into a float target of the renderer's size (their colour and
 * coverage, 002 §3.3's blending) and composited over the frame once, as the lightning
 * glow (vtkNimbusLightningGlowMapper): one rounding to the frame's 8 bits instead of one
 * per ball.
 *
 * Units: radii and points in world units, MetresPerUnit metres each; the sun
 * (SunAzimuthDegrees from +y toward +x, SunElevationDegrees above the x-y plane: z is
 * up; SunIlluminance, SunTemperatureKelvin) as vtkNimbusCloudVolumeMapper and the
 * scene format, its colour the blackbody spectrum's linear sRGB above the air
 * (Physics/SunAndAir); radiance relative to the sun, x Exposure in the framebuffer
 * (linear, no sRGB encoding).
 *
 * The numeric setters refuse NaN and infinity (an error; the value is kept) and clamp
 * finite values to their ranges (Common/FiniteSetters.h).
 *
 * Drawn in the opaque pass after the props before it, as an emissive prop: depth-tested
 * against the scene's depth, writing none; opaque props drawn later are not hidden by
 * it. The actor's matrix moves the balls (its scale's cube root scales the radii).
 * GLSL: Shaders/cloudSplat{Sun,View}{VS,FS}.glsl. Needs OpenGL 4.2 for the read-back
 * variant (base instances).
 */
#ifndef vtkNimbusCloudSplatMapper_h
#define vtkNimbusCloudSplatMapper_h

#include "NimbusRepresentationsModule.h" // for export macro
#include "vtkPolyDataMapper.h"

#include <memory> // for std::unique_ptr

namespace nimbus
{
struct CloudLighting;
}
class vtkNimbusSky;
class vtkNimbusSkyBackground;
class vtkOpenGLRenderWindow;
class vtkShaderProgram;

class NIMBUSREPRESENTATIONS_EXPORT vtkNimbusCloudSplatMapper : public vtkPolyDataMapper
{
public:
  static vtkNimbusCloudSplatMapper* New();
  vtkTypeMacro(vtkNimbusCloudSplatMapper, vtkPolyDataMapper);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /// The point arrays of the balls' radii (world units; default "radius") and centre
  /// densities (dimensionless; default "density"), as vtkNimbusMetaballCloudSource's
  /// port 1 writes them.
  vtkSetStringMacro(RadiusArrayName);
  vtkGetStringMacro(RadiusArrayName);
  vtkSetStringMacro(DensityArrayName);
  vtkGetStringMacro(DensityArrayName);
  ///@}

  ///@{
  /// The sun, as vtkNimbusCloudVolumeMapper: azimuth from +y toward +x and elevation
  /// (degrees), the luminance of its irradiance (relative; default 1) and its
  /// blackbody temperature (K; default 5778).
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
  /// Cloud optics, as vtkNimbusCloudVolumeMapper: sigma_t = ExtinctionPerDensity x
  /// density (1/m; default 0.02), Albedo sigma_s / sigma_t (default 0.99), CloudG the
  /// Cornette-Shanks asymmetry (default 0.85).
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
  ///@}

  ///@{
  /// Metres per world unit (default 1) and the framebuffer's value per unit radiance
  /// (default 1).
  virtual void SetMetresPerUnit(double value);
  virtual double GetMetresPerUnitMinValue() { return 1e-9; }
  virtual double GetMetresPerUnitMaxValue() { return 1e9; }
  vtkGetMacro(MetresPerUnit, double);
  virtual void SetExposure(double value);
  virtual double GetExposureMinValue() { return 0.0; }
  virtual double GetExposureMaxValue() { return 1e9; }
  vtkGetMacro(Exposure, double);
  ///@}

  enum SunLightMethods
  {
    /// The GPU variant: a sun-facing 3-D texture of accumulated optical depth.
    AccumulationTexture = 0,
    /// 002 §3.3's framebuffer read-back, one pixel per ball.
    FramebufferReadBack = 1
  };
  ///@{
  /// How the sun's light reaches each ball (SunLightMethods; default AccumulationTexture).
  vtkSetClampMacro(SunLightMethod, int, 0, 1);
  vtkGetMacro(SunLightMethod, int);
  void SetSunLightMethodToAccumulationTexture() { this->SetSunLightMethod(AccumulationTexture); }
  void SetSunLightMethodToFramebufferReadBack() { this->SetSunLightMethod(FramebufferReadBack); }
  ///@}

  ///@{
  /// With the accumulation texture: the sun's light is integrated along each fragment's
  /// own ray through its ball at this many points (the texture read at each, this ball's
  /// own column toward the eye from the partial-column table) instead of taken at the
  /// ball's centre; 0: at the centre (002 §3.3's per-ball colour). Default 8.
  vtkSetClampMacro(SunLightSamples, int, 0, 64);
  vtkGetMacro(SunLightSamples, int);
  ///@}

  ///@{
  /// The sun pass's texture: texels per side (default 256; the read-back's
  /// framebuffer too) and planes along the light (AccumulationTexture; default 32).
  vtkSetClampMacro(SunTextureSize, int, 16, 8192);
  vtkGetMacro(SunTextureSize, int);
  vtkSetClampMacro(SunTextureLayers, int, 2, 512);
  vtkGetMacro(SunTextureLayers, int);
  ///@}

  ///@{
  /// Multiple scattering (default off): the sun's light scattered more than once, solved
  /// on a grid over the balls with MultipleScatteringGridSize points on its longest side
  /// (default 32; 4 to 256) and added to every fragment (docs/splats.md).
  vtkSetMacro(MultipleScattering, bool);
  vtkGetMacro(MultipleScattering, bool);
  vtkBooleanMacro(MultipleScattering, bool);
  vtkSetClampMacro(MultipleScatteringGridSize, int, 4, 256);
  vtkGetMacro(MultipleScatteringGridSize, int);
  /// Seconds of the last multiple-scattering solve (splatting, solver, upload) and the
  /// number of solves so far.
  double GetLastMultipleScatteringSeconds() const;
  int GetNumberOfMultipleScatteringSolves() const;
  ///@}

  ///@{
  /// The sky background the balls are drawn over (default none; add it to the renderer
  /// before the balls' actor): while it is visible its sky's sun, air and display replace
  /// the mapper's own (see the class comment), as vtkNimbusCloudVolumeMapper's
  /// SetSkyBackground. SkyLight: the sky's and the ground's light on the balls (default
  /// on); AerialPerspective: the air between the eye and the balls (default on). Both
  /// need a sky.
  virtual void SetSkyBackground(vtkNimbusSkyBackground* background);
  vtkGetObjectMacro(SkyBackground, vtkNimbusSkyBackground);
  vtkSetMacro(SkyLight, bool);
  vtkGetMacro(SkyLight, bool);
  vtkBooleanMacro(SkyLight, bool);
  vtkSetMacro(AerialPerspective, bool);
  vtkGetMacro(AerialPerspective, bool);
  vtkBooleanMacro(AerialPerspective, bool);
  /// Seconds of the last frame's air look-ups (per ball, on the CPU; 0 without a sky).
  double GetLastAirSeconds() const;
  ///@}

  /// Seconds of the last frame's sun pass and view pass (each ended by glFinish only
  /// when TimePasses is on; default off).
  vtkSetMacro(TimePasses, bool);
  vtkGetMacro(TimePasses, bool);
  double GetLastSunPassSeconds() const;
  double GetLastViewPassSeconds() const;
  /// The balls drawn by the last frame.
  vtkIdType GetLastNumberOfBalls() const;

  void Render(vtkRenderer* renderer, vtkActor* actor) override;
  void ReleaseGraphicsResources(vtkWindow* window) override;
  /// Drawn in the opaque pass (emissive, as the lightning glow).
  bool HasTranslucentPolygonalGeometry() override { return false; }

protected:
  vtkNimbusCloudSplatMapper();
  ~vtkNimbusCloudSplatMapper() override;

  char* RadiusArrayName = nullptr;
  char* DensityArrayName = nullptr;
  double SunAzimuthDegrees = 135.0;
  double SunElevationDegrees = 45.0;
  double SunIlluminance = 1.0;
  double SunTemperatureKelvin = 5778.0;
  double ExtinctionPerDensity = 0.02;
  double Albedo = 0.99;
  double CloudG = 0.85;
  double MetresPerUnit = 1.0;
  double Exposure = 1.0;
  int SunLightMethod = AccumulationTexture;
  int SunTextureSize = 256;
  int SunTextureLayers = 32;
  int SunLightSamples = 8;
  bool TimePasses = false;
  bool MultipleScattering = false;
  int MultipleScatteringGridSize = 32;
  vtkNimbusSkyBackground* SkyBackground = nullptr;
  vtkNimbusSky* Sky = nullptr; // the followed sky of this frame (not counted)
  bool SkyLight = true;
  bool AerialPerspective = true;

private:
  vtkNimbusCloudSplatMapper(const vtkNimbusCloudSplatMapper&) = delete;
  void operator=(const vtkNimbusCloudSplatMapper&) = delete;

  bool UpdateBalls(vtkPolyData* input, vtkActor* actor);
  void SunPassTexture(vtkOpenGLRenderWindow* window);
  void SunPassReadBack(vtkOpenGLRenderWindow* window);
  void ViewPass(vtkRenderer* renderer, vtkOpenGLRenderWindow* window);
  void DrawIntoFloatTarget(vtkRenderer* renderer, vtkOpenGLRenderWindow* window);
  void ComputeFrameSettings();
  void UpdateSunTint();
  void UpdateAir(vtkRenderer* renderer);
  void UpdateMultipleScattering(vtkOpenGLRenderWindow* window, const double toSun[3]);
  void SetMultipleScatteringUniforms(vtkShaderProgram* program);
  bool SkyLightOf(double zMiddle, const double sunTop[3], nimbus::CloudLighting& lighting);

  struct Internals;
  std::unique_ptr<Internals> Internal;
};

#endif
