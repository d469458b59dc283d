/**
 * @class   vtkNimbusSkyBackground
 * @brief   The sky as a renderer's background: a prop drawn behind everything.
 *
 * Add it to a vtkRenderer (standalone VTK, Python, or a ParaView view through
 * the "Sky Background" representation) and every pixel where nothing opaque is
 * drawn shows the sky of its vtkNimbusSky, looked up per pixel in the sky-view
 * table along the pixel's view ray, with the limb-darkened sun disc. It is drawn
 * with the opaque props at the far plane (depth 1, depth test LEQUAL, no depth
 * write), so the order of the props does not matter, it has no bounds (camera
 * resets ignore it) and it is not pickable.
 *
 * Framebuffer values are display values: sRGB-encoded Exposure x radiance
 * (white-balanced, see vtkNimbusSky). A vtkNimbusCloudVolumeMapper given this prop
 * (vtkNimbusCloudVolumeMapper::SetSkyBackground) takes its sun, atmosphere and
 * display settings while the prop is visible, so that clouds, their shadows in
 * the air and the sky agree (see vtkNimbusCloudVolumeMapper::UseSceneSky). Where
 * the two are set up apart (ParaView's separate representations), the renderer
 * names its sky in its information (RENDERER_SKY_BACKGROUND) and the cloud's
 * side hands it to the mapper.
 *
 * The background is seen from the sky's observer (scene z = 0 at
 * SceneAltitudeMetres): the camera's height does not change it.
 *
 * GLSL: Shaders/vtkNimbusSkyBackgroundFS.glsl with nimbusSkyView.glsl (the
 * twin of nimbus::SkyViewLut::Radiance), shared with vtkNimbusSkyPass.
 */
#ifndef vtkNimbusSkyBackground_h
#define vtkNimbusSkyBackground_h

#include "NimbusRepresentationsModule.h" // for export macro
#include "vtkProp.h"

#include <memory> // for std::unique_ptr

class vtkInformationObjectBaseKey;
class vtkNimbusSky;
class vtkRenderer;

class NIMBUSREPRESENTATIONS_EXPORT vtkNimbusSkyBackground : public vtkProp
{
public:
  static vtkNimbusSkyBackground* New();
  vtkTypeMacro(vtkNimbusSkyBackground, vtkProp);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /// The sky (parameters and tables). A default vtkNimbusSky is created with the
  /// prop; setting nullptr is an error and keeps the current one.
  void SetSky(vtkNimbusSky* sky);
  vtkGetObjectMacro(Sky, vtkNimbusSky);
  ///@}

  /// Modified when the prop or its sky changed (the view re-renders).
  vtkMTimeType GetMTime() override;

  /// Number of sky frames drawn (tests).
  vtkGetMacro(NumberOfDraws, int);

  ///@{
  /// Whether this prop draws the sky (default on). Off, it stays visible as the
  /// view's sky (a cloud mapper still follows its sun, air and display settings) but
  /// draws nothing: under MPI the sky is the bottom layer of the composite, drawn by
  /// one rank only (ParaView's Sky Background representation sets it).
  vtkSetMacro(DrawSky, bool);
  vtkGetMacro(DrawSky, bool);
  vtkBooleanMacro(DrawSky, bool);
  ///@}

  /// Key of a vtkRenderer's information (vtkRenderer::GetInformation()): the sky
  /// background shown by that renderer. Set by whoever adds the background to the
  /// renderer for others to find (ParaView's "Sky Background" representation),
  /// removed with it; read by whoever sets up a cloud mapper in that renderer
  /// (vtkNimbusCloudVolumeMapper::SetSkyBackground).
  static vtkInformationObjectBaseKey* RENDERER_SKY_BACKGROUND();

  /// The sky background a renderer shows: the one its information names
  /// (RENDERER_SKY_BACKGROUND) when that one is visible, else the first visible one among
  /// its props, else the named one (nullptr when none). In ParaView every display of a
  /// data set carries a hidden Sky Background representation of its own, so a renderer
  /// may hold several backgrounds of which one is shown.
  static vtkNimbusSkyBackground* ShownIn(vtkRenderer* renderer);

  int RenderOpaqueGeometry(vtkViewport* viewport) override;
  vtkTypeBool HasTranslucentPolygonalGeometry() override { return 0; }
  void ReleaseGraphicsResources(vtkWindow* window) override;

protected:
  vtkNimbusSkyBackground();
  ~vtkNimbusSkyBackground() override;

  vtkNimbusSky* Sky = nullptr;
  int NumberOfDraws = 0;
  bool DrawSky = true;

private:
  vtkNimbusSkyBackground(const vtkNimbusSkyBackground&) = delete;
  void operator=(const vtkNimbusSkyBackground&) = delete;

  struct Internals;
  std::unique_ptr<Internals> Internal;
};

#endif
