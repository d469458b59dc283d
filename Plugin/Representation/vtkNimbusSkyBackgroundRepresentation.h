/**
 * @class   vtkNimbusSkyBackgroundRepresentation
 * @brief   ParaView representation that makes its input's sky the render view's background.
 *
 * The "Sky Background" representation type of polygonal data in ParaView. While
 * it is visible in a render view, the view's renderer (vtkPVRenderView::GetRenderer())
 * holds a vtkNimbusSkyBackground: every pixel where nothing opaque is drawn shows
 * the sky. The renderer's information names it
 * (vtkNimbusSkyBackground::RENDERER_SKY_BACKGROUND), and the view's Cloud
 * representations hand it to their mappers, which light their clouds with that
 * sky's sun. Hidden, or removed from the view, the plain view background shows
 * again.
 *
 * The sky's parameters come from the input's field data: the one-tuple arrays
 * that vtkNimbusSkyDomeSource writes ("SunElevationDegrees", "SunAzimuthDegrees",
 * "MieScatteringPerMetre", "GroundAlbedo", "Exposure", "SceneAltitudeMetres", ..., see
 * vtkNimbusSkyDomeSource). A parameter without its array takes the vtkNimbusSky
 * default, so any polygonal data can be shown as the default sky. The input's
 * geometry is not drawn and not moved: only its field data is delivered (through
 * vtkPVView::SetPiece / GetDeliveredPiece, like ParaView's own representations),
 * and the sky has no bounds, so camera resets ignore it.
 *
 * Automatic exposure (AutomaticExposure, on by default): before each render the
 * sky is metered in the view's camera (a grid of view directions through the
 * frustum, the sky's display luminance at the input's Exposure), and when more
 * than 5 % of the sky in view would be brighter than 90 % of display white, the
 * exposure is lowered until that 95th percentile sits at 90 % of white. It is
 * never raised, so views away from the sun keep the input's Exposure (a clear
 * noon sky's brightest part, the band over the horizon, is at 0.80 to 0.87 of
 * white at the default Exposure 10, below the threshold); looking
 * toward the sun the glow around it no longer fills the frame with white. The
 * sky's vtkNimbusSky then holds the exposure used, which a Cloud representation
 * over this sky takes too (vtkNimbusSky::GetDisplayScale).
 */
#ifndef vtkNimbusSkyBackgroundRepresentation_h
#define vtkNimbusSkyBackgroundRepresentation_h

#include "NimbusCloudRepresentationModule.h" // for export macro
#include "vtkNew.h"                          // for vtkNew
#include "vtkPVDataRepresentation.h"
#include "vtkSmartPointer.h" // for vtkSmartPointer

class vtkNimbusSkyBackground;
class vtkRenderer;
class vtkPolyData;

class NIMBUSCLOUDREPRESENTATION_EXPORT vtkNimbusSkyBackgroundRepresentation
  : public vtkPVDataRepresentation
{
public:
  static vtkNimbusSkyBackgroundRepresentation* New();
  vtkTypeMacro(vtkNimbusSkyBackgroundRepresentation, vtkPVDataRepresentation);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /// Handles ParaView's view passes: REQUEST_UPDATE hands the parameters (field
  /// data only) to the view for delivery, REQUEST_RENDER configures the sky from
  /// the delivered parameters.
  int ProcessViewRequest(vtkInformationRequestKey* requestType, vtkInformation* inInfo,
    vtkInformation* outInfo) override;

  /// Adds the sky background to / removes it from the render view's renderer, and
  /// names it in / removes it from the renderer's information
  /// (vtkNimbusSkyBackground::RENDERER_SKY_BACKGROUND).
  bool AddToView(vtkView* view) override;
  bool RemoveFromView(vtkView* view) override;

  /// Shows or hides the sky background with the representation.
  void SetVisibility(bool visible) override;

  /// The prop added to the view's renderer (owned by the representation); its
  /// vtkNimbusSky holds the parameters applied at the last render.
  vtkNimbusSkyBackground* GetBackground();

  /// Number of renders at which the sky's parameters were taken from delivered
  /// data (tests).
  vtkGetMacro(NumberOfParameterUpdates, int);

  ///@{
  /// Lower the exposure when the sky in view is too bright (see the class
  /// comment). On by default.
  vtkSetMacro(AutomaticExposure, bool);
  vtkGetMacro(AutomaticExposure, bool);
  vtkBooleanMacro(AutomaticExposure, bool);
  ///@}

  /// The factor (in (0, 1]) that automatic exposure applied to the input's
  /// Exposure at the last render; 1 when off or when the view was not too bright.
  vtkGetMacro(LastExposureFactor, double);

protected:
  /// Name this representation's background in the renderer's information
  /// (vtkNimbusSkyBackground::RENDERER_SKY_BACKGROUND) while it is visible; take the name
  /// back when it is hidden.
  void NameInRenderer(vtkRenderer* renderer);
  vtkNimbusSkyBackgroundRepresentation();
  ~vtkNimbusSkyBackgroundRepresentation() override;

  /// Any vtkDataObject (optional: processes without the data have no input).
  int FillInputPortInformation(int port, vtkInformation* info) override;
  /// Keeps a data object with a shallow copy of the input's field data.
  int RequestData(vtkInformation* request, vtkInformationVector** inputVector,
    vtkInformationVector* outputVector) override;

  vtkNew<vtkNimbusSkyBackground> Background;
  /// What is delivered: an empty polydata with the input's field data.
  vtkSmartPointer<vtkPolyData> Parameters;
  int NumberOfParameterUpdates = 0;
  bool AutomaticExposure = true;
  double LastExposureFactor = 1.0;
  double InputExposure = -1.0; // the input's Exposure (-1: none delivered yet)

private:
  vtkNimbusSkyBackgroundRepresentation(const vtkNimbusSkyBackgroundRepresentation&) = delete;
  void operator=(const vtkNimbusSkyBackgroundRepresentation&) = delete;
};

#endif
