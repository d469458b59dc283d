/**
 * @class   vtkNimbusLightningGlowMapper
 * @brief   The glow of the air around lightning strokes (003 §8): emissive splats facing
 *          the camera at the strokes' point sources, each with the single-scattering profile
 *          of a point source in air.
 *
 * Input: vtkNimbusLightningSource's point sources (port 1: vertices with point data
 * "intensity", radiant intensity in units where the sun's irradiance is 1). Every source
 * of intensity I lights the air around it; a view ray passing it at distance b sees the
 * single-scattered radiance L(b) = sigma_s I / (4 b) (Physics/Lightning.h,
 * LightningGlowRadiance: isotropic scattering, the air's extinction over the glow
 * neglected). The mapper draws one camera-facing quad of radius GlowRadiusMetres per
 * source, the profile L(b) x Exposure x Color in its fragments, cut off smoothly at the
 * radius (x (1 - (b/R)^2)^2) and held at the channel's radius near the centre. Along a
 * channel the quads sum to the glow of a line source, about (sigma_s I' / 2) ln(2R / d) at
 * distance d for I' per metre (tested), the paper's texture-mapped quads along the strokes
 * with the texture computed per fragment.
 *
 * The quads are summed in a 32-bit float RGBA target of the renderer's size (each source's
 * intensity a float too), depth-tested against a copy of the depth the scene has when the
 * glow is drawn (opaque geometry drawn before it hides it; the glow itself writes no
 * depth), and the sum is added to the frame once (one rounding to its colour): many faint
 * splats, each below the frame's 8-bit step, add up. Drawn in the opaque pass, as an
 * emissive prop (after the actors added before it); not drawn for selection (picking).
 * A multisampled frame's depth cannot be copied: there the glow is not hidden by opaque
 * geometry (a warning, once). GLSL: Shaders/lightningGlow{SplatVS,SplatFS,CompositeFS}.glsl.
 *
 * AirScatteringPerMetre defaults to 1e-3 /m: air in rain and haze (a visibility of about
 * 4 km), as under a thunderstorm; clear air (about 3e-5 /m) makes a glow 30 times fainter,
 * invisible at night beside the channel.
 */
#ifndef vtkNimbusLightningGlowMapper_h
#define vtkNimbusLightningGlowMapper_h

#include "NimbusRepresentationsModule.h" // for export macro
#include "vtkPolyDataMapper.h"

#include <memory> // for std::unique_ptr

class vtkDataArray;
class vtkOpenGLRenderWindow;

class NIMBUSREPRESENTATIONS_EXPORT vtkNimbusLightningGlowMapper : public vtkPolyDataMapper
{
public:
  static vtkNimbusLightningGlowMapper* New();
  vtkTypeMacro(vtkNimbusLightningGlowMapper, vtkPolyDataMapper);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /// sigma_s of the air (1/m; default 1e-3: rain and haze).
  virtual void SetAirScatteringPerMetre(double value);
  virtual double GetAirScatteringPerMetreMinValue() { return 0.0; }
  virtual double GetAirScatteringPerMetreMaxValue() { return 1.0; }
  vtkGetMacro(AirScatteringPerMetre, double);
  ///@}

  ///@{
  /// The radius of each source's glow (metres, default 300) and the channel's radius,
  /// inside which the profile stays at its value there (metres, default 2).
  virtual void SetGlowRadiusMetres(double value);
  virtual double GetGlowRadiusMetresMinValue() { return 1e-3; }
  virtual double GetGlowRadiusMetresMaxValue() { return 1e6; }
  vtkGetMacro(GlowRadiusMetres, double);
  virtual void SetChannelRadiusMetres(double value);
  virtual double GetChannelRadiusMetresMinValue() { return 1e-3; }
  virtual double GetChannelRadiusMetresMaxValue() { return 1e3; }
  vtkGetMacro(ChannelRadiusMetres, double);
  ///@}

  ///@{
  /// Exposure (as the cloud mapper's: multiplies the radiance; default 1), the light's
  /// colour (default 0.85, 0.9, 1) and metres per world unit (default 1).
  virtual void SetExposure(double value);
  virtual double GetExposureMinValue() { return 0.0; }
  virtual double GetExposureMaxValue() { return 1e6; }
  vtkGetMacro(Exposure, double);
  vtkSetVector3Macro(Color, double);
  vtkGetVector3Macro(Color, double);
  virtual void SetMetresPerUnit(double value);
  virtual double GetMetresPerUnitMinValue() { return 1e-9; }
  virtual double GetMetresPerUnitMaxValue() { return 1e9; }
  vtkGetMacro(MetresPerUnit, double);
  ///@}

  void Render(vtkRenderer* renderer, vtkActor* actor) override;
  void ReleaseGraphicsResources(vtkWindow* window) override;
  /// Emissive: drawn in the opaque pass (as VTK's emissive point Gaussians).
  bool HasTranslucentPolygonalGeometry() override { return false; }

protected:
  vtkNimbusLightningGlowMapper();
  ~vtkNimbusLightningGlowMapper() override;

  double AirScatteringPerMetre = 1e-3;
  double GlowRadiusMetres = 300.0;
  double ChannelRadiusMetres = 2.0;
  double Exposure = 1.0;
  double Color[3] = { 0.85, 0.9, 1.0 };
  double MetresPerUnit = 1.0;

private:
  vtkNimbusLightningGlowMapper(const vtkNimbusLightningGlowMapper&) = delete;
  void operator=(const vtkNimbusLightningGlowMapper&) = delete;

  void UpdateSplatVertices(vtkPolyData* input, vtkDataArray* intensity);
  void DrawSplats(vtkRenderer* renderer, vtkActor* actor, vtkOpenGLRenderWindow* window);

  struct Internals;
  std::unique_ptr<Internals> Internal;
};

#endif
