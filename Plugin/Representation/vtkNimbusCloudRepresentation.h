/**
 * @class   vtkNimbusCloudRepresentation
 * @brief   ParaView volume representation that renders image data as a cloud.
 *
 * The "Cloud" representation type in ParaView: ParaView's own
 * vtkImageVolumeRepresentation (data delivery, outline LOD, scalar array
 * selection through ColorArrayName) with its volume mapper replaced by
 * vtkNimbusCloudVolumeMapper (shadow-view slices, paper 000). The selected
 * point or cell array is the cloud density; the colour and opacity transfer
 * functions are not used.
 *
 * Any grid: image data goes to the mapper as it is; rectilinear, structured and
 * unstructured grids, AMR and multiblock data are first resampled to an image of
 * SamplingDimensions points over their bounds (as ParaView's Volume resamples), the
 * memory checked first (ResampleMemoryBudgetMiB). Any units: DensityUnits says what
 * the array's values are (Physics/CloudOptics.h); other than a dimensionless density
 * the array is turned into extinction (1/m) before the mapper sees it
 * (CloudInputImage.h), and ExtinctionPerDensity is not used.
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
#include "vtkWeakPointer.h"  // for vtkWeakPointer

#include <string> // for std::string

class vtkImageData;
class vtkNimbusCloudVolumeMapper;
class vtkPVRenderView;
class vtkRenderer;

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
  /// What the density array's values mean (nimbus::DensityUnits, and 5: a typical
  /// cloud, estimated): 0 a dimensionless density times ExtinctionPerDensity
  /// (default), 1 extinction [1/m], 2 liquid water content [g/m^3], 3 liquid water
  /// mixing ratio [kg/kg] with the air's density (AirDensityArray [kg/m^3], or the
  /// U.S. Standard Atmosphere 1976 at each sample's altitude: SceneAltitudeMetres +
  /// up-axis height x MetresPerUnit), 4 ice water content [g/m^3], 5 scaled so that
  /// the cloud's median vertical optical thickness is TargetOpticalThickness
  /// (GetEstimatedExtinctionPerDensity says the scale found). Water contents take the
  /// droplet size from DropletSize: 0 the effective radius [um], 1 the droplet number
  /// concentration [1/cm^3] (liquid only). A change re-executes the representation.
  void SetDensityUnits(int value);
  vtkGetMacro(DensityUnits, int);
  void SetDropletSize(int value);
  vtkGetMacro(DropletSize, int);
  void SetDropletEffectiveRadiusMicrometres(double value);
  vtkGetMacro(DropletEffectiveRadiusMicrometres, double);
  void SetDropletNumberConcentrationPerCubicCentimetre(double value);
  vtkGetMacro(DropletNumberConcentrationPerCubicCentimetre, double);
  void SetAirDensityArray(const char* name);
  const char* GetAirDensityArray() { return this->AirDensityArray.c_str(); }
  void SetTargetOpticalThickness(double value);
  vtkGetMacro(TargetOpticalThickness, double);
  /// The scale the estimated units found at the last execution [1/m per unit value].
  vtkGetMacro(EstimatedExtinctionPerDensity, double);
  ///@}

  ///@{
  /// Non-image data: the resampled image's points per axis (0, the default: the data's
  /// own resolution, at most 256; CloudInputImage.h) and the
  /// memory budget of the resampled image [MiB; 0: half of the physical memory],
  /// checked before it is allocated. A change re-executes the representation.
  void SetSamplingDimensions(int x, int y, int z);
  vtkGetVector3Macro(SamplingDimensions, int);
  void SetResampleMemoryBudgetMiB(double value);
  vtkGetMacro(ResampleMemoryBudgetMiB, double);
  /// Whether the last execution resampled its input.
  vtkGetMacro(Resampled, bool);
  ///@}

  ///@{
  /// Which axis of the data points up (0 +X, 1 +Y, 2 +Z, 3 -Y): the sun, the sky, the
  /// ground and the air turn about it (vtkNimbusCloudVolumeMapper::SetUpAxis).
  void SetUpAxis(int value);
  int GetUpAxis();
  /// The ground never above the data's lowest point (default on).
  void SetGroundBelowData(bool value);
  bool GetGroundBelowData();
  ///@}

  ///@{
  /// Cloud optics: extinction per unit density [1/m] (dimensionless units only), single-scattering
  /// albedo, Cornette-Shanks g of the cloud, k_multi (000 Eq. 1).
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
  /// Quality: the rendering method (ray marching, the default here, or the paper's
  /// slices) and the march's step in voxels, slice count, a of theta_e : theta_s = 1 : a (000
  /// §4.2), shadow surface texels per side, atmosphere samples per pixel, largest density texture
  /// side (0: the GL limit).
  void SetRenderingMethod(int value);
  int GetRenderingMethod();
  void SetRayMarchStepTexels(double value);
  double GetRayMarchStepTexels();
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
  /// While on, every frame is drawn as an interactive one (the frame budget's reduced
  /// work), also ParaView's still renders: the GUI turns it on while an animation plays
  /// (a flash relit at every time step) and off when it stops, then renders once at full
  /// quality. Not saved in state files. Off by default.
  void SetPlaybackInteractive(bool value);
  bool GetPlaybackInteractive() const { return this->PlaybackInteractive; }
  ///@}

  ///@{
  /// Metres per world unit (also the altitudes of the mixing ratio's air and the
  /// estimate's column lengths: a change re-executes then); framebuffer = Exposure *
  /// radiance; sRGB encoding.
  void SetMetresPerUnit(double value);
  double GetMetresPerUnit();
  void SetExposure(double value);
  double GetExposure();
  void SetEncodeSrgb(bool value);
  bool GetEncodeSrgb();
  ///@}

  ///@{
  /// The view's own lights (vtkNimbusCloudVolumeMapper, "The view's own lights";
  /// docs/lights.md, docs/lights-paraview.md): the renderer's positional lights (the
  /// Light Inspector's lights with Positional on; ConeAngle < 90 degrees: a spotlight)
  /// light the haze, the cloud and the ground, drawn by the ray march only.
  /// LightSources 0 none, 1 the positional lights (default); LightIntensityScale
  /// [Y/sr per unit of a light's Intensity]; SpotEdgeWidthDegrees [deg];
  /// LightShaftMethod 0 ray marching (default), 1 virtual planes; LightSamples per
  /// light and ray; LightShaftDownsampling (the ray-marched shafts on 1 in n pixels per
  /// side, default 2); NumberOfVirtualPlanes; LightShadowMapSize [texels per face side,
  /// 0: no shadows of the opaque geometry]; LightCloudSteps [samples toward a light,
  /// 0: the cloud casts no shadow]; MaximumLights (up to 8).
  void SetLightSources(int value);
  int GetLightSources();
  void SetLightIntensityScale(double value);
  double GetLightIntensityScale();
  void SetSpotEdgeWidthDegrees(double value);
  double GetSpotEdgeWidthDegrees();
  void SetLightShaftMethod(int value);
  int GetLightShaftMethod();
  void SetLightSamples(int value);
  int GetLightSamples();
  void SetLightShaftDownsampling(int value);
  int GetLightShaftDownsampling();
  void SetNumberOfVirtualPlanes(int value);
  int GetNumberOfVirtualPlanes();
  void SetLightShadowMapSize(int value);
  int GetLightShadowMapSize();
  void SetLightCloudSteps(int value);
  int GetLightCloudSteps();
  void SetMaximumLights(int value);
  int GetMaximumLights();
  /// The light map (a gobo): an image file (.png, .jpg, .pgm/.ppm, .tif, any format
  /// vtkImageReader2Factory knows) read when the name changes; its luminance
  /// multiplies every spotlight's beam (vtkNimbusCloudVolumeMapper::SetLightMap). An
  /// empty name: no map. A file that cannot be read: an error, and no map. A name that
  /// is no file and has no image extension gives no map silently (ParaView's file field
  /// sets every partial name while one types).
  void SetLightMapFile(const char* name);
  const char* GetLightMapFile() { return this->LightMapFile.c_str(); }
  /// Fog for the lights without a cloud: the meteorological visibility in metres
  /// (the distance at which a black object fades to 2 % contrast: 3.912 / extinction).
  /// Above 0 it sets the air's Mie scattering at sea level to
  /// MieAlbedo x 3.912 / visibility, overriding Turbidity and MieScatteringPerMetre;
  /// 0 (the default): no fog, the haze is theirs.
  void SetFogVisibilityMetres(double value);
  double GetFogVisibilityMetres() { return this->FogVisibilityMetres; }
  ///@}

protected:
  vtkNimbusCloudRepresentation();
  ~vtkNimbusCloudRepresentation() override;

  /// Images as the superclass; any other data set or composite data set too (it is
  /// resampled to an image).
  int FillInputPortInformation(int port, vtkInformation* info) override;

  /// The input as the mapper's image: resampled when it is not an image, its density
  /// turned into extinction when DensityUnits says what it is. Null when there is no
  /// input on this process; throws std::runtime_error with a message for the user.
  vtkSmartPointer<vtkDataObject> PrepareCloudImage(vtkInformationVector* input);

  /// The distributed cloud's shared view of itself (see RequestData).
  void ShareDistributedView();

  /// Whether the units' conversion depends on the frame (altitudes, column lengths).
  bool UnitsDependOnFrame() const;

  /// The superclass's array selection and actor set-up; nothing that needs
  /// ParaView's own mappers.
  void UpdateMapperParameters() override;

  /// The superclass's data cache; under MPI (more than one process) also the
  /// distributed cloud's shared view of itself (docs/parallel.md): every
  /// rank's piece bounds and a coarse copy of the whole density (CoarseDensityMaxSide
  /// points on its longest side at most), summed over the ranks (collective: every
  /// rank of the data server executes it).
  int RequestData(vtkInformation* request, vtkInformationVector** inputVector,
    vtkInformationVector* outputVector) override;

  /// Before a render under ordered compositing: this piece's settings on the mapper
  /// (premultiplied output, the whole cloud's slice planes, the other pieces'
  /// shadow), and PlaceLayer() again at the start of the renderer's render (see there);
  /// without ordered compositing, none.
  void ConfigurePiece(vtkPVRenderView* view);

  /// Whether this rank, last in the compositing order for the view's camera, draws the
  /// air and the ground, and the bounds that make its image cover the view. Run at the
  /// start of each render of the view's renderer: only then does every rank hold the
  /// camera of the render (ParaView's synchronized renderers copy rank 0's camera to
  /// the other ranks when the renderer starts; a camera set from a script reaches them
  /// only then). Every rank must agree on the bottom rank, or none draws the air.
  void PlaceLayer(vtkPVRenderView* view);

  /// The view's renderer's StartEvent, observed after ParaView's own observer (the
  /// camera's synchronization, priority 0): PlaceLayer().
  void ObserveRendererStart(vtkPVRenderView* view);
  void OnRendererStart(vtkObject* caller, unsigned long event, void* data);
  void StopObservingRenderer();
  bool RemoveFromView(vtkView* view) override;
  vtkWeakPointer<vtkRenderer> ObservedRenderer;
  vtkWeakPointer<vtkPVRenderView> LayerView;
  unsigned long RendererStartTag = 0;

  /// The union of all ranks' piece bounds (invalid: not distributed) and the coarse
  /// whole density from the last RequestData.
  double WholeBounds[6] = { 1.0, -1.0, 1.0, -1.0, 1.0, -1.0 };
  vtkSmartPointer<vtkImageData> CoarseDensity;
  static constexpr int CoarseDensityMaxSide = 64;

  /// Owned through the superclass's VolumeMapper.
  vtkNimbusCloudVolumeMapper* CloudMapper = nullptr;

  int DensityUnits = 0;
  int DropletSize = 0;
  double DropletEffectiveRadiusMicrometres = 10.0;
  double DropletNumberConcentrationPerCubicCentimetre = 100.0;
  std::string AirDensityArray;
  double TargetOpticalThickness = 20.0;
  double EstimatedExtinctionPerDensity = 0.0;
  double UserExtinctionPerDensity = 0.02; // the mapper's default
  int SamplingDimensions[3] = { 0, 0, 0 };
  double ResampleMemoryBudgetMiB = 0.0;
  bool Resampled = false;
  bool ResampledFromCells = false;
  /// The density while no array is chosen (nimbus::DefaultDensityArray), if any.
  std::string DefaultDensityArray;
  bool DefaultDensityIsCells = false;

  /// The haze's three settings and the mapper's value from them: the fog if any, else
  /// the Mie scattering if >= 0, else the turbidity.
  void ApplyHaze();
  double Turbidity = 2.0;
  double MieScatteringOverride = -1.0;
  double FogVisibilityMetres = 0.0;
  bool PlaybackInteractive = false;
  double StillInteractiveUpdateRate = 1.0; // the mapper's, kept while PlaybackInteractive

  /// The light map's file name (the mapper holds the image read from it).
  std::string LightMapFile;

private:
  /// The mapper's progress during a long still render, as this representation's
  /// (ParaView's progress bar listens to the representation, not to its mapper).
  void ForwardMapperProgress(vtkObject* caller, unsigned long event, void* data);

  vtkNimbusCloudRepresentation(const vtkNimbusCloudRepresentation&) = delete;
  void operator=(const vtkNimbusCloudRepresentation&) = delete;
};

#endif
