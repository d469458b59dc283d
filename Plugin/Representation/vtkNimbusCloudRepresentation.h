/**
 * @class   vtkNimbusCloudRepresentation
 * @brief   ParaView volume representation that renders image data as a cloud.
 *
 * The "Cloud" representation type of image data in ParaView: ParaView's own
 * vtkImageVolumeRepresentation (data delivery, outline LOD, scalar array
 * selection through ColorArrayName) with its volume mapper replaced by
 * vtkNimbusCloudVolumeMapper (shadow-view slices, paper 000). The selected
 * point or cell array is the cloud density; the colour and opacity transfer
 * functions are not used.
 *
 * The cloud, multiple-scattering, sun, atmosphere, ground and quality
 * parameters are forwarded to the mapper as they are set (see
 * vtkNimbusCloudVolumeMapper for their units and the equations they enter). Like the mapper
 * settings of the superclass (e.g. SetBlendMode) they do not call MarkModified(): a lighting change
 * re-renders the delivered data and never re-executes the representation, so
 * the density texture is not uploaded again.
 */
#ifndef vtkNimbusCloudRepresentation_h
#define vtkNimbusCloudRepresentation_h

#include "NimbusCloudRepresentationModule.h" // for export macro
#include "vtkImageVolumeRepresentation.h"
#include "vtkSmartPointer.h" // for vtkSmartPointer

class vtkImageData;
class vtkNimbusCloudVolumeMapper;
class vtkPVRenderView;

class NIMBUSCLOUDREPRESENTATION_EXPORT vtkNimbusCloudRepresentation
  : public vtkImageVolumeRepresentation
{
public:
  static vtkNimbusCloudRepresentation* New();
  vtkTypeMacro(vtkNimbusCloudRepresentation, vtkImageVolumeRepresentation);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /// The mapper this representation renders with (owned by the representation).
  vtkNimbusCloudVolumeMapper* GetCloudMapper();

  /// The superclass's view passes; before each render (REQUEST_RENDER) the mapper
  /// also gets the sky background the view's renderer shows
  /// (vtkNimbusSkyBackground::RENDERER_SKY_BACKGROUND, set by the "Sky Background"
  /// representation; none when the view has none).
  int ProcessViewRequest(vtkInformationRequestKey* requestType, vtkInformation* inInfo,
    vtkInformation* outInfo) override;

  ///@{
  /// Cloud optics: extinction per unit density [1/m], single-scattering albedo,
  /// Cornette-Shanks g of the cloud, k_multi (000 Eq. 1).
  void SetExtinctionPerDensity(double value);
  double GetExtinctionPerDensity();
  void SetAlbedo(double value);
  double GetAlbedo();
  void SetCloudG(double value);
  double GetCloudG();
  void SetMultipleScattering(double value);
  double GetMultipleScattering();
  ///@}

  ///@{
  /// Temperature emission (vtkNimbusCloudVolumeMapper): on/off, the temperature array
  /// (K), the luminance per metre of a unit density at the reference temperature, and
  /// that temperature (K).
  void SetTemperatureEmission(bool value);
  bool GetTemperatureEmission();
  void SetEmissionTemperatureArray(const char* name);
  const char* GetEmissionTemperatureArray();
  void SetEmissionRadiancePerMetre(double value);
  double GetEmissionRadiancePerMetre();
  void SetEmissionReferenceTemperatureKelvin(double value);
  double GetEmissionReferenceTemperatureKelvin();
  ///@}

  ///@{
  /// Multiple scattering (vtkNimbusCloudVolumeMapper::MultipleScatteringMethods):
  /// the method (0 None, 1 Octaves, 2 Reference patterns, 3 Discrete directions),
  /// explicit orders, solver grid downsampling [texels per cell], directions, sky
  /// and ground light; the octaves' count and per-octave scales; the reference
  /// patterns' radius [cells], contribution and selection; the solver's memory
  /// budget [MiB; 0: half of the physical memory].
  void SetMultipleScatteringMethod(int value);
  int GetMultipleScatteringMethod();
  void SetMultipleScatteringOrders(int value);
  int GetMultipleScatteringOrders();
  void SetMultipleScatteringDownsampling(int value);
  int GetMultipleScatteringDownsampling();
  void SetMultipleScatteringDirections(int value);
  int GetMultipleScatteringDirections();
  void SetSkyLight(bool value);
  bool GetSkyLight();
  void SetOctaves(int value);
  int GetOctaves();
  void SetOctaveExtinctionScale(double value);
  double GetOctaveExtinctionScale();
  void SetOctaveScatteringScale(double value);
  double GetOctaveScatteringScale();
  void SetOctaveAsymmetryScale(double value);
  double GetOctaveAsymmetryScale();
  void SetPatternRadius(int value);
  int GetPatternRadius();
  void SetPatternContribution(double value);
  double GetPatternContribution();
  void SetPatternSelection(double value);
  double GetPatternSelection();
  void SetMultipleScatteringMemoryBudgetMiB(double value);
  double GetMultipleScatteringMemoryBudgetMiB();
  ///@}

  ///@{
  /// Sun: azimuth [deg from +y toward +x], elevation [deg], illuminance above
  /// the atmosphere (relative), blackbody temperature [K].
  void SetSunAzimuthDegrees(double value);
  double GetSunAzimuthDegrees();
  void SetSunElevationDegrees(double value);
  double GetSunElevationDegrees();
  void SetSunIlluminance(double value);
  double GetSunIlluminance();
  void SetSunTemperatureKelvin(double value);
  double GetSunTemperatureKelvin();
  ///@}

  ///@{
  /// Atmosphere: on/off, haze, haze g, Rayleigh scattering at sea level [1/m],
  /// altitude of z = 0 [m]. The haze is Turbidity (default 2; the mapper's
  /// SetTurbidity) unless MieScatteringPerMetre (the aerosol scattering at sea level,
  /// 1/m) is >= 0, which then sets it directly whatever the order of the two calls
  /// (ParaView's "Mie Scattering (Per Metre)", advanced; -1 = from Turbidity), as
  /// vtkNimbusSkyDomeSource does.
  void SetAtmosphere(bool value);
  bool GetAtmosphere();
  void SetTurbidity(double value);
  double GetTurbidity() { return this->Turbidity; }
  void SetMieScatteringPerMetre(double value);
  double GetMieScatteringPerMetre() { return this->MieScatteringOverride; }
  void SetMieG(double value);
  double GetMieG();
  void SetRayleighScatteringPerMetre(double value);
  double GetRayleighScatteringPerMetre();
  void SetSceneAltitudeMetres(double value);
  double GetSceneAltitudeMetres();
  ///@}

  ///@{
  /// Ground plane z = GroundHeight (world units), Lambertian albedo; shafts of light.
  void SetGround(bool value);
  bool GetGround();
  void SetGroundHeight(double value);
  double GetGroundHeight();
  void SetGroundAlbedo(double value);
  double GetGroundAlbedo();
  void SetShafts(bool value);
  bool GetShafts();
  void SetAirMultipleScattering(bool value);
  bool GetAirMultipleScattering();
  ///@}

  ///@{
  /// Follow the Nimbus sky shown in the same view ("Sky Background"): its sun,
  /// air, ground albedo and exposure replace the cloud's own (see
  /// vtkNimbusCloudVolumeMapper::SetUseSceneSky). On by default.
  void SetUseSceneSky(bool value);
  bool GetUseSceneSky();
  ///@}

  ///@{
  /// Quality: slice count, a of theta_e : theta_s = 1 : a (000 §4.2), shadow
  /// surface texels per side, atmosphere samples per pixel, largest density
  /// texture side (0: the GL limit).
  void SetNumberOfSlices(int value);
  int GetNumberOfSlices();
  void SetSliceAngleRatio(double value);
  double GetSliceAngleRatio();
  void SetShadowSurfaceSize(int value);
  int GetShadowSurfaceSize();
  void SetAtmosphereSteps(int value);
  int GetAtmosphereSteps();
  void SetSliceJitter(bool value);
  bool GetSliceJitter();
  void SetMaximumTextureSize(int value);
  int GetMaximumTextureSize();
  void SetTextureMemoryBudgetMiB(double value);
  double GetTextureMemoryBudgetMiB();
  ///@}

  ///@{
  /// Automatic quality (vtkNimbusCloudVolumeMapper::SetQuality): ParaView's
  /// interactive renders (a camera drag) fit the cloud's passes into the frame
  /// budget [ms; 0: no lowering], still renders draw at Quality (1: full).
  void SetFrameBudgetMilliseconds(double value);
  double GetFrameBudgetMilliseconds();
  void SetQuality(double value);
  double GetQuality();
  ///@}

  ///@{
  /// Metres per world unit; framebuffer = Exposure * radiance; sRGB encoding.
  void SetMetresPerUnit(double value);
  double GetMetresPerUnit();
  void SetExposure(double value);
  double GetExposure();
  void SetEncodeSrgb(bool value);
  bool GetEncodeSrgb();
  ///@}

protected:
  vtkNimbusCloudRepresentation();
  ~vtkNimbusCloudRepresentation() override;

  /// The superclass's array selection and actor set-up; nothing that needs
  /// ParaView's own mappers.
  void UpdateMapperParameters() override;

  /// The superclass's data cache; under MPI (more than one process) also the
  /// distributed cloud's shared view of itself (issue 18, docs/parallel.md): every
  /// rank's piece bounds and a coarse copy of the whole density (CoarseDensityMaxSide
  /// points on its longest side at most), summed over the ranks (collective: every
  /// rank of the data server executes it).
  int RequestData(vtkInformation* request, vtkInformationVector** inputVector,
    vtkInformationVector* outputVector) override;

  /// Before a render under ordered compositing: this piece's settings on the mapper
  /// (premultiplied output, the whole cloud's slice planes, the other pieces'
  /// shadow) and whether this rank, last in the compositing order for the view's
  /// camera, draws the air and the ground; without ordered compositing, none.
  void ConfigurePiece(vtkPVRenderView* view);

  /// The union of all ranks' piece bounds (invalid: not distributed) and the coarse
  /// whole density from the last RequestData.
  double WholeBounds[6] = { 1.0, -1.0, 1.0, -1.0, 1.0, -1.0 };
  vtkSmartPointer<vtkImageData> CoarseDensity;
  static constexpr int CoarseDensityMaxSide = 64;

  /// Owned through the superclass's VolumeMapper.
  vtkNimbusCloudVolumeMapper* CloudMapper = nullptr;

  /// The haze's two settings and the mapper's value from them.
  void ApplyHaze();
  double Turbidity = 2.0;
  double MieScatteringOverride = -1.0;

private:
  /// The mapper's progress during a long still render, as this representation's
  /// (ParaView's progress bar listens to the representation, not to its mapper).
  void ForwardMapperProgress(vtkObject* caller, unsigned long event, void* data);

  vtkNimbusCloudRepresentation(const vtkNimbusCloudRepresentation&) = delete;
  void operator=(const vtkNimbusCloudRepresentation&) = delete;
};

#endif
