/**
 * @class   vtkNimbusSkyPass
 * @brief   Sky background and aerial perspective as a render pass.
 *
 * Renders its delegate (e.g. vtkRenderStepsPass) into a colour + depth
 * framebuffer, then draws one full-screen quad that
 *  - where nothing was drawn (depth = 1): the sky from the vtkNimbusSky's
 *    sky-view table for the view ray (and the limb-darkened sun disc), and
 *  - where opaque geometry was drawn: colour x T + Exposure x in-scattering,
 *    T and the in-scattering from the sky's aerial-perspective table at the
 *    pixel's distance (depth buffer -> world position).
 * Framebuffer colours are taken as display (sRGB-encoded) values and composited
 * in linear sRGB. The depth is written back, so later passes can use it.
 * Translucent geometry and volumes write no depth and get no aerial perspective;
 * they are composited over the sky by their alpha (the delegate renders on
 * transparent black: the renderer's background is ignored while the pass is on).
 * The camera's altitude is the sky's SceneAltitudeMetres + camera z x MetresPerUnit;
 * both the sky-view table (vtkNimbusSky::GetSkyViewLutAt) and the
 * aerial-perspective table are seen from it. For the sky alone, without a pass,
 * see vtkNimbusSkyBackground.
 *
 * GLSL: Shaders/vtkNimbusSkyPassFS.glsl, the GPU twin of
 * nimbus::SkyViewLut::Radiance / AerialPerspectiveLut::Lookup (Physics/Sky.cxx).
 *
 * @code
 * vtkNew<vtkNimbusSkyPass> pass;  pass->SetSky(sky);
 * vtkNew<vtkRenderStepsPass> steps;  pass->SetDelegatePass(steps);
 * vtkOpenGLRenderer::SafeDownCast(renderer)->SetPass(pass);
 * @endcode
 */
#ifndef vtkNimbusSkyPass_h
#define vtkNimbusSkyPass_h

#include "NimbusRepresentationsModule.h" // for export macro
#include "vtkImageProcessingPass.h"

#include <memory> // for std::unique_ptr

class vtkNimbusSky;
class vtkOpenGLRenderWindow;
class vtkRenderer;

class NIMBUSREPRESENTATIONS_EXPORT vtkNimbusSkyPass : public vtkImageProcessingPass
{
public:
  static vtkNimbusSkyPass* New();
  vtkTypeMacro(vtkNimbusSkyPass, vtkImageProcessingPass);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /// The sky (parameters and tables). Required.
  void SetSky(vtkNimbusSky* sky);
  vtkGetObjectMacro(Sky, vtkNimbusSky);
  ///@}

  ///@{
  /// Apply aerial perspective to opaque geometry. Default on.
  vtkSetMacro(AerialPerspective, bool);
  vtkGetMacro(AerialPerspective, bool);
  vtkBooleanMacro(AerialPerspective, bool);
  ///@}

  void Render(const vtkRenderState* s) override;
  void ReleaseGraphicsResources(vtkWindow* w) override;

protected:
  vtkNimbusSkyPass();
  ~vtkNimbusSkyPass() override;

  vtkNimbusSky* Sky = nullptr;
  bool AerialPerspective = true;

private:
  vtkNimbusSkyPass(const vtkNimbusSkyPass&) = delete;
  void operator=(const vtkNimbusSkyPass&) = delete;

  /// The delegate pass into the colour and depth textures (the sky goes behind them).
  void RenderDelegate(const vtkRenderState* s, int width, int height);
  /// The sky-view and aerial-perspective tables seen from the camera's altitude (m),
  /// uploaded again only when the sky rebuilt them; false, with an error, when they
  /// cannot be built.
  bool UpdateTables(vtkOpenGLRenderWindow* window, double cameraAltitude);
  /// The full-screen quad: the sky where nothing was drawn, aerial perspective elsewhere.
  void DrawSky(vtkRenderer* renderer, int x, int y, int width, int height);

  struct Internals;
  std::unique_ptr<Internals> Internal;
};

#endif
