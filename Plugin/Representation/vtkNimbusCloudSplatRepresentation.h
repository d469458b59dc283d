/**
 * @class   vtkNimbusCloudSplatRepresentation
 * @brief   ParaView representation that draws points with radius and density arrays as
 *          metaball cloud splats.
 *
 * The "Cloud Splats" representation type of polygonal data in ParaView: each point is a
 * metaball (its radius and centre density from two point arrays, RadiusArrayName and
 * DensityArrayName, by default "radius" and "density", as the Nimbus Metaball Cloud
 * source's second output "Metaballs" has them), drawn by vtkNimbusCloudSplatMapper
 * (two-pass billboard splatting, 002 §3.3; docs/splats.md). Only the points and their
 * point data are delivered to the view (vtkPVView::SetPiece / GetDeliveredPiece, like
 * ParaView's own representations); the view's bounds are the points' bounds grown by the
 * largest radius, so that a camera reset shows the whole balls.
 *
 * The sun, optics and display settings are forwarded to the mapper as they are set (see
 * vtkNimbusCloudSplatMapper for their units); they do not re-execute the
 * representation. UseSceneSky (on by default): while a Nimbus Sky is shown in the same
 * view ("Sky Background": the visible vtkNimbusSkyBackground among the renderer's props,
 * which may not be the one RENDERER_SKY_BACKGROUND names), the balls are drawn over that
 * sky as the Cloud representation's clouds are (the mapper's SetSkyBackground): its sun (elevation,
 * azimuth and temperature, illuminance 1) reddened by the air down to each ball, the sky's and the
 * ground's light on them, the air between the eye and them, its metres per unit and its display
 * scale (exposure and white balance; the frame sRGB-encoded as the sky's); the representation's own
 * sun, exposure and metres per unit apply without a sky.
 */
#ifndef vtkNimbusCloudSplatRepresentation_h
#define vtkNimbusCloudSplatRepresentation_h

#include "NimbusCloudRepresentationModule.h" // for export macro
#include "vtkNew.h"                          // for vtkNew
#include "vtkPVDataRepresentation.h"
#include "vtkSmartPointer.h" // for vtkSmartPointer

class vtkActor;
class vtkNimbusCloudSplatMapper;
class vtkPolyData;

class NIMBUSCLOUDREPRESENTATION_EXPORT vtkNimbusCloudSplatRepresentation
  : public vtkPVDataRepresentation
{
public:
  static vtkNimbusCloudSplatRepresentation* New();
  vtkTypeMacro(vtkNimbusCloudSplatRepresentation, vtkPVDataRepresentation);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /// REQUEST_UPDATE hands the balls and their bounds to the view for delivery;
  /// REQUEST_RENDER gives the delivered balls to the mapper and, with UseSceneSky, the
  /// view's sky's sun.
  int ProcessViewRequest(vtkInformationRequestKey* requestType, vtkInformation* inInfo,
    vtkInformation* outInfo) override;

  /// Adds the actor to / removes it from the render view's renderer.
  bool AddToView(vtkView* view) override;
  bool RemoveFromView(vtkView* view) override;

  /// Shows or hides the balls with the representation.
  void SetVisibility(bool visible) override;

  /// The mapper this representation draws with (owned by the representation).
  vtkNimbusCloudSplatMapper* GetSplatMapper();

  ///@{
  /// The point arrays of the radii (world units) and centre densities (no unit).
  void SetRadiusArrayName(const char* name);
  const char* GetRadiusArrayName();
  void SetDensityArrayName(const char* name);
  const char* GetDensityArrayName();
  ///@}

  ///@{
  /// The sun: elevation and azimuth (degrees; azimuth from +y toward +x), the luminance
  /// of its irradiance (relative), its blackbody temperature (K).
  void SetSunElevationDegrees(double value);
  vtkGetMacro(SunElevationDegrees, double);
  void SetSunAzimuthDegrees(double value);
  vtkGetMacro(SunAzimuthDegrees, double);
  void SetSunIlluminance(double value);
  vtkGetMacro(SunIlluminance, double);
  void SetSunTemperatureKelvin(double value);
  vtkGetMacro(SunTemperatureKelvin, double);
  ///@}

  ///@{
  /// Follow the sun of the Nimbus Sky shown in the same view (default on).
  void SetUseSceneSky(bool value);
  vtkGetMacro(UseSceneSky, bool);
  /// Whether the last render took the sun from the view's sky.
  vtkGetMacro(LastRenderUsedSceneSky, bool);
  ///@}

  ///@{
  /// Optics and display, forwarded to the mapper: extinction per unit density (1/m),
  /// albedo, Cornette-Shanks g, metres per world unit, framebuffer value per unit
  /// radiance, and how the sun's light reaches each ball (0 a GPU texture, 1 read back
  /// per ball).
  void SetExtinctionPerDensity(double value);
  double GetExtinctionPerDensity();
  void SetAlbedo(double value);
  double GetAlbedo();
  void SetCloudG(double value);
  double GetCloudG();
  void SetMetresPerUnit(double value);
  double GetMetresPerUnit();
  void SetExposure(double value);
  double GetExposure();
  void SetSunLightMethod(int value);
  int GetSunLightMethod();
  ///@}

  ///@{
  /// The light scattered more than once (off by default), solved on a grid over the
  /// balls of MultipleScatteringGridSize points on its longest side (4 to 256, default
  /// 32), forwarded to the mapper (vtkNimbusCloudSplatMapper::SetMultipleScattering).
  void SetMultipleScattering(bool value);
  bool GetMultipleScattering();
  void SetMultipleScatteringGridSize(int value);
  int GetMultipleScatteringGridSize();
  ///@}

  ///@{
  /// Over the view's sky: its and the ground's light on the balls, and the air between
  /// the camera and them (both on by default; vtkNimbusCloudSplatMapper::SetSkyLight,
  /// SetAerialPerspective).
  void SetSkyLight(bool value);
  bool GetSkyLight();
  void SetAerialPerspective(bool value);
  bool GetAerialPerspective();
  ///@}

protected:
  vtkNimbusCloudSplatRepresentation();
  ~vtkNimbusCloudSplatRepresentation() override;

  /// Polygonal data (optional: processes without the data get the delivered balls).
  int FillInputPortInformation(int port, vtkInformation* info) override;
  /// Keeps the input's points and point data and their bounds grown by the radii.
  int RequestData(vtkInformation* request, vtkInformationVector** inputVector,
    vtkInformationVector* outputVector) override;

  /// The mapper's sun: the view's sky's (UseSceneSky and a visible sky) or ours.
  void ApplySun();

  vtkNew<vtkNimbusCloudSplatMapper> Mapper;
  vtkNew<vtkActor> Actor;
  /// What is delivered: the input's points and point data, no cells.
  vtkSmartPointer<vtkPolyData> Balls;
  double BallBounds[6] = { 1.0, -1.0, 1.0, -1.0, 1.0, -1.0 };

  double SunElevationDegrees = 45.0;
  double SunAzimuthDegrees = 135.0;
  double SunIlluminance = 1.0;
  double SunTemperatureKelvin = 5778.0;
  bool UseSceneSky = true;
  bool LastRenderUsedSceneSky = false;

private:
  vtkNimbusCloudSplatRepresentation(const vtkNimbusCloudSplatRepresentation&) = delete;
  void operator=(const vtkNimbusCloudSplatRepresentation&) = delete;
};

#endif
