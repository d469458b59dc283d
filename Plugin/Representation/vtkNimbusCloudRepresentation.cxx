#include "vtkNimbusCloudRepresentation.h"

#include "vtkBoundingBox.h"
#include "vtkCamera.h"
#include "vtkCellData.h"
#include "vtkCommand.h"
#include "vtkDataArray.h"
#include "vtkDataObject.h"
#include "vtkDataSetAttributes.h"
#include "vtkDoubleArray.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkImageReader2.h"
#include "vtkImageReader2Factory.h"
#include "vtkInformation.h"
#include "vtkInformationObjectBaseKey.h"
#include "vtkInformationVector.h"
#include "vtkMath.h"
#include "vtkMatrix4x4.h"
#include "vtkMultiProcessController.h"
#include "vtkOrderedCompositingHelper.h"
#include "vtkPVLODVolume.h"
#include "vtkPVRenderView.h"
#include "vtkPVRenderViewDataDeliveryManager.h"
#include "vtkPointData.h"
#include "vtkRenderer.h"

#include "vtkNimbusCloudVolumeMapper.h"
#include "vtkNimbusSkyBackground.h"
#include "vtkObjectFactory.h"

#include "Atmosphere.h" // nimbus::AtmosphereParameters (the haze's albedo)
#include "CloudInputImage.h"
#include "NimbusCompositingOrder.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include <vtksys/SystemTools.hxx>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <vector>

vtkStandardNewMacro(vtkNimbusCloudRepresentation);

vtkNimbusCloudRepresentation::vtkNimbusCloudRepresentation()
{
  // Replace the superclass's vtkMultiBlockVolumeMapper; the superclass connects
  // the delivered data to VolumeMapper at each render request.
  this->CloudMapper = vtkNimbusCloudVolumeMapper::New();
  // ParaView's Cloud is drawn by the ray march unless the user picks the paper's slices.
  this->CloudMapper->SetRenderingMethodToRayMarching();
  this->VolumeMapper.TakeReference(this->CloudMapper);
  this->CloudMapper->AddObserver(
    vtkCommand::ProgressEvent, this, &vtkNimbusCloudRepresentation::ForwardMapperProgress);
  this->ApplyHaze();
}

void vtkNimbusCloudRepresentation::SetTurbidity(double value)
{
  if (!std::isfinite(value))
  {
    vtkErrorMacro("SetTurbidity(" << value << "): not a finite number; ignored");
    return;
  }
  if (value != this->Turbidity)
  {
    this->Turbidity = value;
    this->ApplyHaze();
    this->Modified();
  }
}

void vtkNimbusCloudRepresentation::SetMieScatteringPerMetre(double value)
{
  if (!std::isfinite(value))
  {
    vtkErrorMacro("SetMieScatteringPerMetre(" << value << "): not a finite number; ignored");
    return;
  }
  if (value != this->MieScatteringOverride)
  {
    this->MieScatteringOverride = value;
    this->ApplyHaze();
    this->Modified();
  }
}

void vtkNimbusCloudRepresentation::SetFogVisibilityMetres(double value)
{
  if (!std::isfinite(value) || value < 0.0)
  {
    vtkErrorMacro("SetFogVisibilityMetres(" << value
                                            << "): the visibility must be a finite number of "
                                               "metres, 0 or more (0: no fog); ignored");
    return;
  }
  if (value != this->FogVisibilityMetres)
  {
    this->FogVisibilityMetres = value;
    this->ApplyHaze();
    this->Modified();
  }
}

void vtkNimbusCloudRepresentation::ApplyHaze()
{
  if (this->FogVisibilityMetres > 0.0)
  {
    // Visibility V = 3.912 / extinction (Koschmieder, 2 % contrast); the haze's
    // extinction is its scattering / MieAlbedo. The mapper clamps to its range (1/m).
    constexpr double kKoschmieder = 3.912;
    this->CloudMapper->SetMieScatteringPerMetre(
      nimbus::AtmosphereParameters().MieAlbedo * kKoschmieder / this->FogVisibilityMetres);
  }
  else if (this->MieScatteringOverride >= 0.0)
  {
    this->CloudMapper->SetMieScatteringPerMetre(this->MieScatteringOverride);
  }
  else
  {
    this->CloudMapper->SetTurbidity(this->Turbidity);
  }
}

void vtkNimbusCloudRepresentation::ForwardMapperProgress(vtkObject*, unsigned long, void*)
{
  this->UpdateProgress(this->CloudMapper->GetProgress());
}

vtkNimbusCloudRepresentation::~vtkNimbusCloudRepresentation()
{
  this->StopObservingRenderer();
}

vtkNimbusCloudVolumeMapper* vtkNimbusCloudRepresentation::GetCloudMapper()
{
  return this->CloudMapper;
}

int vtkNimbusCloudRepresentation::ProcessViewRequest(
  vtkInformationRequestKey* requestType, vtkInformation* inInfo, vtkInformation* outInfo)
{
  if (!this->Superclass::ProcessViewRequest(requestType, inInfo, outInfo))
  {
    return 0; // hidden, or nothing to do
  }
  if (requestType == vtkPVView::REQUEST_RENDER())
  {
    // The sky the view shows now (or none): the representations of a view are
    // separate, so the coupling goes through the renderer's information.
    auto* view = vtkPVRenderView::SafeDownCast(this->GetView());
    this->CloudMapper->SetSkyBackground(
      view ? vtkNimbusSkyBackground::ShownIn(view->GetRenderer()) : nullptr);
    this->ConfigurePiece(view);
  }
  return 1;
}

int vtkNimbusCloudRepresentation::FillInputPortInformation(int port, vtkInformation* info)
{
  this->Superclass::FillInputPortInformation(port, info);
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkDataSet");
  info->Append(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkCompositeDataSet");
  return 1;
}

//------------------------------------------------------------------------------
// The superclass's data cache, from the prepared image; under MPI (more than one
// process) also the distributed cloud's shared view of itself.
int vtkNimbusCloudRepresentation::RequestData(
  vtkInformation* request, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkSmartPointer<vtkDataObject> prepared;
  try
  {
    prepared = this->PrepareCloudImage(inputVector[0]);
  }
  catch (const std::exception& error)
  {
    vtkErrorMacro("Cloud: " << error.what() << " The cloud is not drawn.");
    prepared = vtkSmartPointer<vtkImageData>::New(); // an empty image: nothing drawn
  }
  int result = 0;
  if (prepared && inputVector[0]->GetNumberOfInformationObjects() == 1)
  {
    // The superclass reads the image and its whole extent from the input's
    // information: the same information with the prepared image in it.
    vtkNew<vtkInformationVector> substitute;
    vtkNew<vtkInformation> info;
    info->Copy(inputVector[0]->GetInformationObject(0));
    info->Set(vtkDataObject::DATA_OBJECT(), prepared);
    if (auto* image = vtkImageData::SafeDownCast(prepared))
    {
      if (this->Resampled || this->DensityUnits != 0)
      {
        info->Set(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), image->GetExtent(), 6);
      }
    }
    substitute->Append(info);
    vtkInformationVector* inputs[1] = { substitute };
    result = this->Superclass::RequestData(request, inputs, outputVector);
  }
  else
  {
    result = this->Superclass::RequestData(request, inputVector, outputVector);
  }
  this->ShareDistributedView();
  return result;
}

//------------------------------------------------------------------------------
vtkSmartPointer<vtkDataObject> vtkNimbusCloudRepresentation::PrepareCloudImage(
  vtkInformationVector* input)
{
  this->Resampled = false;
  this->ResampledFromCells = false;
  this->EstimatedExtinctionPerDensity = 0.0;
  vtkDataObject* data =
    input->GetNumberOfInformationObjects() == 1 ? vtkDataObject::GetData(input, 0) : nullptr;
  if (!data)
  {
    return nullptr;
  }
  nimbus::CloudInputSettings settings;
  std::copy(this->SamplingDimensions, this->SamplingDimensions + 3, settings.SamplingDimensions);
  settings.MemoryBudgetBytes = this->ResampleMemoryBudgetMiB * 1024.0 * 1024.0;
  settings.Units = this->DensityUnits;
  settings.Optics.Size = static_cast<nimbus::DropletSize>(this->DropletSize);
  settings.Optics.EffectiveRadiusMicrometres = this->DropletEffectiveRadiusMicrometres;
  settings.Optics.NumberConcentrationPerCubicCentimetre =
    this->DropletNumberConcentrationPerCubicCentimetre;
  settings.AirDensityArray = this->AirDensityArray;
  settings.TargetOpticalThickness = this->TargetOpticalThickness;
  settings.Up = static_cast<nimbus::UpAxis>(this->CloudMapper->GetUpAxis());
  settings.MetresPerUnit = this->CloudMapper->GetMetresPerUnit();
  settings.SceneAltitudeMetres = this->CloudMapper->GetSceneAltitudeMetres();

  bool resampled = false;
  vtkSmartPointer<vtkImageData> image = nimbus::CloudImageOf(data, settings, resampled);
  this->Resampled = resampled;
  vtkInformation* info = this->GetInputArrayInformation(0);
  const char* name = info && info->Has(vtkDataObject::FIELD_NAME())
    ? info->Get(vtkDataObject::FIELD_NAME())
    : nullptr;
  bool cellData = info && info->Has(vtkDataObject::FIELD_ASSOCIATION()) &&
    info->Get(vtkDataObject::FIELD_ASSOCIATION()) == vtkDataObject::FIELD_ASSOCIATION_CELLS;
  this->DefaultDensityArray.clear();
  if (!name || !name[0])
  {
    // No array chosen (Coloring is Solid Color): the density is the active scalars, or
    // else the first one-component array (a NetCDF reader sets no active scalars).
    this->DefaultDensityArray = nimbus::DefaultDensityArray(image, this->DefaultDensityIsCells);
    name = this->DefaultDensityArray.empty() ? nullptr : this->DefaultDensityArray.c_str();
    cellData = this->DefaultDensityIsCells;
  }
  if (resampled && cellData)
  {
    // The resampled image holds every array as point data.
    this->ResampledFromCells = true;
    cellData = false;
  }
  if (this->DensityUnits != 0 && name && name[0] && image->GetNumberOfPoints() > 0)
  {
    double estimate = 0.0;
    image = nimbus::WithExtinction(image, name, cellData, settings, estimate);
    this->EstimatedExtinctionPerDensity = estimate;
  }
  this->CloudMapper->SetExtinctionPerDensity(
    this->DensityUnits != 0 ? 1.0 : this->UserExtinctionPerDensity);
  return image;
}

//------------------------------------------------------------------------------
// Every rank's piece bounds and a coarse copy of the whole density, summed over the
// ranks (collective: every rank of the data server executes it).
void vtkNimbusCloudRepresentation::ShareDistributedView()
{
  for (int c = 0; c < 6; ++c)
  {
    this->WholeBounds[c] = (c % 2) ? -1.0 : 1.0;
  }
  this->CoarseDensity = nullptr;
  vtkMultiProcessController* controller = vtkMultiProcessController::GetGlobalController();
  if (!controller || controller->GetNumberOfProcesses() < 2)
  {
    return;
  }
  // Every rank takes part in both collectives below, with or without a piece.
  vtkImageData* piece = vtkImageData::SafeDownCast(this->Cache);
  vtkDataArray* density = nullptr;
  bool cellData = false;
  if (piece && piece->GetNumberOfPoints() > 0)
  {
    vtkInformation* info = this->GetInputArrayInformation(0);
    const char* name = info && info->Has(vtkDataObject::FIELD_NAME())
      ? info->Get(vtkDataObject::FIELD_NAME())
      : nullptr;
    const int association = info && info->Has(vtkDataObject::FIELD_ASSOCIATION())
      ? info->Get(vtkDataObject::FIELD_ASSOCIATION())
      : vtkDataObject::FIELD_ASSOCIATION_POINTS;
    if (name && name[0])
    {
      cellData = association == vtkDataObject::FIELD_ASSOCIATION_CELLS;
      density =
        cellData ? piece->GetCellData()->GetArray(name) : piece->GetPointData()->GetArray(name);
    }
    if (!density)
    {
      density = piece->GetPointData()->GetScalars();
      cellData = false;
      if (!density)
      {
        density = piece->GetCellData()->GetScalars();
        cellData = density != nullptr;
      }
    }
  }
  // Bounds (world, no actor transform) and spacing of each rank's piece.
  double mine[9] = { 1.0, -1.0, 1.0, -1.0, 1.0, -1.0, 0.0, 0.0, 0.0 };
  if (density)
  {
    piece->GetBounds(mine);
    piece->GetSpacing(mine + 6);
  }
  const int ranks = controller->GetNumberOfProcesses();
  std::vector<double> all(9 * static_cast<std::size_t>(ranks));
  controller->AllGather(mine, all.data(), 9);
  vtkBoundingBox whole;
  double spacing[3] = { 0.0, 0.0, 0.0 };
  for (int r = 0; r < ranks; ++r)
  {
    const double* b = &all[9 * static_cast<std::size_t>(r)];
    if (b[0] <= b[1] && b[2] <= b[3] && b[4] <= b[5])
    {
      whole.AddBounds(b);
      for (int a = 0; a < 3; ++a)
      {
        spacing[a] = std::max(spacing[a], b[6 + a]);
      }
    }
  }
  if (!whole.IsValid() || !(spacing[0] > 0.0 && spacing[1] > 0.0 && spacing[2] > 0.0))
  {
    return;
  }
  whole.GetBounds(this->WholeBounds);
  // The coarse lattice: the whole box, every `step` data points, at most
  // CoarseDensityMaxSide points on a side; each rank adds its points' density to the
  // nearest lattice point (sum and count), the sums are added over the ranks, and
  // the mean is the coarse density (a box filter of the step's width).
  int dims[3];
  double coarseSpacing[3];
  for (int a = 0; a < 3; ++a)
  {
    const double length = this->WholeBounds[2 * a + 1] - this->WholeBounds[2 * a];
    const int points = static_cast<int>(std::lround(length / spacing[a])) + 1;
    const int step = std::max(1, (points + CoarseDensityMaxSide - 2) / (CoarseDensityMaxSide - 1));
    dims[a] = std::max(1, (points - 1 + step - 1) / step + 1);
    coarseSpacing[a] = length > 0.0 && dims[a] > 1 ? length / (dims[a] - 1) : spacing[a];
  }
  const std::size_t count = static_cast<std::size_t>(dims[0]) * dims[1] * dims[2];
  std::vector<double> sums(2 * count, 0.0); // sum, then count
  if (density)
  {
    const vtkIdType n = cellData ? piece->GetNumberOfCells() : piece->GetNumberOfPoints();
    int extent[6];
    piece->GetExtent(extent);
    const int nx = cellData ? std::max(extent[1] - extent[0], 1) : extent[1] - extent[0] + 1;
    const int ny = cellData ? std::max(extent[3] - extent[2], 1) : extent[3] - extent[2] + 1;
    const double* origin = piece->GetOrigin();
    const double* own = piece->GetSpacing();
    for (vtkIdType id = 0; id < n; ++id)
    {
      const int ijk[3] = { static_cast<int>(id % nx), static_cast<int>((id / nx) % ny),
        static_cast<int>(id / (static_cast<vtkIdType>(nx) * ny)) };
      std::size_t lattice = 0;
      std::size_t stride = 1;
      for (int a = 0; a < 3; ++a)
      {
        const double x = origin[a] + (extent[2 * a] + ijk[a] + (cellData ? 0.5 : 0.0)) * own[a];
        const int i = std::min(dims[a] - 1,
          std::max(
            0, static_cast<int>(std::lround((x - this->WholeBounds[2 * a]) / coarseSpacing[a]))));
        lattice += stride * static_cast<std::size_t>(i);
        stride *= static_cast<std::size_t>(dims[a]);
      }
      const double v = density->GetComponent(id, 0);
      sums[lattice] += std::isfinite(v) ? std::max(v, 0.0) : 0.0;
      sums[count + lattice] += 1.0;
    }
  }
  std::vector<double> total(sums.size(), 0.0);
  controller->AllReduce(
    sums.data(), total.data(), static_cast<vtkIdType>(sums.size()), vtkCommunicator::SUM_OP);
  vtkNew<vtkFloatArray> values;
  values->SetName("density");
  values->SetNumberOfTuples(static_cast<vtkIdType>(count));
  for (std::size_t i = 0; i < count; ++i)
  {
    values->SetValue(static_cast<vtkIdType>(i),
      total[count + i] > 0.0 ? static_cast<float>(total[i] / total[count + i]) : 0.0f);
  }
  this->CoarseDensity = vtkSmartPointer<vtkImageData>::New();
  this->CoarseDensity->SetOrigin(this->WholeBounds[0], this->WholeBounds[2], this->WholeBounds[4]);
  this->CoarseDensity->SetSpacing(coarseSpacing);
  this->CoarseDensity->SetDimensions(dims);
  this->CoarseDensity->GetPointData()->SetScalars(values);
  return;
}

void vtkNimbusCloudRepresentation::ConfigurePiece(vtkPVRenderView* view)
{
  vtkNimbusCloudVolumeMapper* mapper = this->CloudMapper;
  if (!this->CoarseDensity || !nimbus::IsOrderedCompositing(view))
  {
    this->StopObservingRenderer();
    mapper->SetPieceCompositing(false);
    mapper->SetDrawOutsideRegions(true);
    mapper->SetExternalDensity(nullptr);
    const double none[6] = { 1.0, -1.0, 1.0, -1.0, 1.0, -1.0 };
    mapper->SetSlicingBounds(none);
    mapper->SetViewCoverBounds(none);
    return;
  }
  mapper->SetPieceCompositing(true);
  mapper->SetExternalDensity(this->CoarseDensity);
  mapper->SetSlicingBounds(this->WholeBounds);
  double background[3] = { 0.0, 0.0, 0.0 };
  if (view->GetRenderer())
  {
    view->GetRenderer()->GetBackground(background);
  }
  mapper->SetPieceBackground(background);
  // A first placement with this rank's camera now; the renderer's start places the layer
  // again with the camera of the render, the same on every rank.
  this->PlaceLayer(view);
  this->ObserveRendererStart(view);
}

void vtkNimbusCloudRepresentation::ObserveRendererStart(vtkPVRenderView* view)
{
  vtkRenderer* renderer = view->GetRenderer();
  this->LayerView = view;
  if (renderer == this->ObservedRenderer && this->RendererStartTag != 0)
  {
    return;
  }
  this->StopObservingRenderer();
  if (renderer)
  {
    // Below ParaView's synchronized renderers (priority 0), which give every rank rank
    // 0's camera in their StartEvent observer.
    constexpr float afterCameraSynchronization = -1.0f;
    this->RendererStartTag = renderer->AddObserver(vtkCommand::StartEvent, this,
      &vtkNimbusCloudRepresentation::OnRendererStart, afterCameraSynchronization);
    this->ObservedRenderer = renderer;
  }
}

void vtkNimbusCloudRepresentation::OnRendererStart(vtkObject*, unsigned long, void*)
{
  vtkPVRenderView* view = this->LayerView;
  if (view && this->CloudMapper->GetPieceCompositing() && this->GetVisibility())
  {
    this->PlaceLayer(view);
  }
}

void vtkNimbusCloudRepresentation::StopObservingRenderer()
{
  if (this->ObservedRenderer && this->RendererStartTag != 0)
  {
    this->ObservedRenderer->RemoveObserver(this->RendererStartTag);
  }
  this->ObservedRenderer = nullptr;
  this->RendererStartTag = 0;
}

bool vtkNimbusCloudRepresentation::RemoveFromView(vtkView* view)
{
  if (vtkPVRenderView::SafeDownCast(view) == this->LayerView)
  {
    this->StopObservingRenderer();
    this->LayerView = nullptr;
  }
  return this->Superclass::RemoveFromView(view);
}

void vtkNimbusCloudRepresentation::PlaceLayer(vtkPVRenderView* view)
{
  vtkNimbusCloudVolumeMapper* mapper = this->CloudMapper;
  // The last rank in IceT's order (ParaView's own helper, same boxes, same camera)
  // is the bottom layer: it draws the air and the ground.
  const bool bottom = nimbus::IsLastInCompositingOrder(view);
  mapper->SetDrawOutsideRegions(bottom);
  // The bottom piece's pixels are the whole view: its prop bounds must project onto
  // all of it (IceT composites only the pixels a rank's bounds cover), without
  // containing the eye. The frustum's corner rays between a distance d and 2 d, widened
  // by half for safety: d is the cloud's distance, kept inside the clipping range, and
  // at least a thousandth of the cloud's size (a camera whose clipping range has
  // collapsed, the cloud behind it, still gets a box apart from the eye).
  double cover[6] = { 1.0, -1.0, 1.0, -1.0, 1.0, -1.0 };
  vtkCamera* camera = view->GetActiveCamera();
  if (bottom && camera && view->GetRenderer())
  {
    vtkBoundingBox box;
    const double* eye = camera->GetPosition();
    vtkBoundingBox whole(this->WholeBounds);
    double centre[3];
    whole.GetCenter(centre);
    const double distance = std::max(std::sqrt(vtkMath::Distance2BetweenPoints(eye, centre)), 1e-6);
    const double* range = camera->GetClippingRange();
    const double nearest =
      std::max(1e-3 * whole.GetDiagonalLength(), std::max(range[0], std::min(distance, range[1])));
    int* size = view->GetRenderer()->GetSize();
    const double aspect = size && size[1] > 0 ? static_cast<double>(size[0]) / size[1] : 1.0;
    vtkMatrix4x4* toWorld = camera->GetCompositeProjectionTransformMatrix(aspect, -1.0, 1.0);
    vtkNew<vtkMatrix4x4> inverse;
    vtkMatrix4x4::Invert(toWorld, inverse);
    for (int corner = 0; corner < 4; ++corner)
    {
      const double ndc[4] = { (corner & 1) ? 1.5 : -1.5, (corner & 2) ? 1.5 : -1.5, 0.0, 1.0 };
      double p[4];
      inverse->MultiplyPoint(ndc, p);
      double ray[3] = { p[0] / p[3] - eye[0], p[1] / p[3] - eye[1], p[2] / p[3] - eye[2] };
      vtkMath::Normalize(ray);
      for (const double d : { nearest, 2.0 * nearest })
      {
        box.AddPoint(eye[0] + d * ray[0], eye[1] + d * ray[1], eye[2] + d * ray[2]);
      }
    }
    if (!box.ContainsPoint(eye))
    {
      box.GetBounds(cover);
    }
  }
  mapper->SetViewCoverBounds(cover);
}

void vtkNimbusCloudRepresentation::UpdateMapperParameters()
{
  // Selects the density array (ColorArrayName, point or cell data) on the
  // mapper, sets the actor's mapper and hides it while no array is selected.
  // The branches for ParaView's own mappers are no-ops for this mapper.
  this->Superclass::UpdateMapperParameters();
  // ParaView picks a colour array by itself only for the types it knows by name
  // ("Volume", "Slice"); with "Cloud" chosen while colouring is Solid Color there
  // is none, and the superclass hides the actor. A density has an obvious default:
  // the active scalars (point, else cell), as a standalone vtkVolumeMapper uses.
  vtkInformation* info = this->GetInputArrayInformation(0);
  const bool hasArray = info && info->Has(vtkDataObject::FIELD_NAME()) &&
    info->Get(vtkDataObject::FIELD_NAME()) && info->Get(vtkDataObject::FIELD_NAME())[0] != 0;
  if (!hasArray && !this->DefaultDensityArray.empty())
  {
    this->CloudMapper->SelectScalarArray(this->DefaultDensityArray.c_str());
    if (this->DefaultDensityIsCells && !this->Resampled)
    {
      this->CloudMapper->SetScalarModeToUseCellFieldData();
    }
    else
    {
      this->CloudMapper->SetScalarModeToUsePointFieldData();
    }
    this->Actor->SetVisibility(this->GetVisibility());
  }
  else if (!hasArray)
  {
    this->CloudMapper->SelectScalarArray(static_cast<const char*>(nullptr));
    this->CloudMapper->SetScalarModeToDefault();
    this->Actor->SetVisibility(this->GetVisibility());
  }
  else if (this->ResampledFromCells)
  {
    this->CloudMapper->SetScalarModeToUsePointFieldData();
  }
}

// Setters forward to the mapper without MarkModified(): the mapper's own
// Modified() makes the next render use the value, and the delivered data (and
// the uploaded density texture) stay as they are.
#define NIMBUS_FORWARD(name, type)                                                                 \
  void vtkNimbusCloudRepresentation::Set##name(type value)                                         \
  {                                                                                                \
    this->CloudMapper->Set##name(value);                                                           \
  }                                                                                                \
  type vtkNimbusCloudRepresentation::Get##name()                                                   \
  {                                                                                                \
    return this->CloudMapper->Get##name();                                                         \
  }

NIMBUS_FORWARD(Albedo, double)
NIMBUS_FORWARD(CloudG, double)
NIMBUS_FORWARD(TemperatureEmission, bool)
NIMBUS_FORWARD(EmissionRadiancePerMetre, double)
NIMBUS_FORWARD(EmissionReferenceTemperatureKelvin, double)
NIMBUS_FORWARD(MultipleScattering, double)
NIMBUS_FORWARD(MultipleScatteringMethod, int)
NIMBUS_FORWARD(MultipleScatteringOrders, int)
NIMBUS_FORWARD(MultipleScatteringDownsampling, int)
NIMBUS_FORWARD(MultipleScatteringDirections, int)
NIMBUS_FORWARD(SkyLight, bool)
NIMBUS_FORWARD(Octaves, int)
NIMBUS_FORWARD(OctaveExtinctionScale, double)
NIMBUS_FORWARD(OctaveScatteringScale, double)
NIMBUS_FORWARD(OctaveAsymmetryScale, double)
NIMBUS_FORWARD(PatternRadius, int)
NIMBUS_FORWARD(PatternContribution, double)
NIMBUS_FORWARD(PatternSelection, double)
NIMBUS_FORWARD(MultipleScatteringMemoryBudgetMiB, double)
NIMBUS_FORWARD(SunAzimuthDegrees, double)
NIMBUS_FORWARD(SunElevationDegrees, double)
NIMBUS_FORWARD(SunIlluminance, double)
NIMBUS_FORWARD(SunTemperatureKelvin, double)
NIMBUS_FORWARD(Atmosphere, bool)
NIMBUS_FORWARD(MieG, double)
NIMBUS_FORWARD(RayleighScatteringPerMetre, double)
NIMBUS_FORWARD(Ground, bool)
NIMBUS_FORWARD(GroundHeight, double)
NIMBUS_FORWARD(GroundBelowData, bool)
NIMBUS_FORWARD(GroundAlbedo, double)
NIMBUS_FORWARD(Shafts, bool)
NIMBUS_FORWARD(AirMultipleScattering, bool)
NIMBUS_FORWARD(UseSceneSky, bool)
NIMBUS_FORWARD(RenderingMethod, int)
NIMBUS_FORWARD(RayMarchStepTexels, double)
NIMBUS_FORWARD(NumberOfSlices, int)
NIMBUS_FORWARD(SliceAngleRatio, double)
NIMBUS_FORWARD(ShadowSurfaceSize, int)
NIMBUS_FORWARD(AtmosphereSteps, int)
NIMBUS_FORWARD(SliceJitter, bool)
NIMBUS_FORWARD(MaximumTextureSize, int)
NIMBUS_FORWARD(TextureMemoryBudgetMiB, double)
NIMBUS_FORWARD(Exposure, double)
NIMBUS_FORWARD(EncodeSrgb, bool)
NIMBUS_FORWARD(FrameBudgetMilliseconds, double)
NIMBUS_FORWARD(Quality, double)
NIMBUS_FORWARD(LightSources, int)
NIMBUS_FORWARD(LightIntensityScale, double)
NIMBUS_FORWARD(SpotEdgeWidthDegrees, double)
NIMBUS_FORWARD(LightShaftMethod, int)
NIMBUS_FORWARD(LightSamples, int)
NIMBUS_FORWARD(LightShaftDownsampling, int)
NIMBUS_FORWARD(NumberOfVirtualPlanes, int)
NIMBUS_FORWARD(LightShadowMapSize, int)
NIMBUS_FORWARD(LightCloudSteps, int)
NIMBUS_FORWARD(MaximumLights, int)

#undef NIMBUS_FORWARD

// The units' conversion depends on the frame: the mixing ratio's standard
// atmosphere (altitudes) and the estimate (column lengths in metres).
// The mapper draws a frame as interactive when the render window's desired update rate
// is at least its InteractiveUpdateRate (ParaView's still renders ask about 0.002 frames/s):
// at its least, 1e-6 frames/s, every frame is. Only the mapper changes (no Modified() here:
// the representation's data is not prepared again).
void vtkNimbusCloudRepresentation::SetPlaybackInteractive(bool value)
{
  if (value == this->PlaybackInteractive)
  {
    return;
  }
  this->PlaybackInteractive = value;
  vtkNimbusCloudVolumeMapper* mapper = this->CloudMapper;
  if (value)
  {
    this->StillInteractiveUpdateRate = mapper->GetInteractiveUpdateRate();
    mapper->SetInteractiveUpdateRate(mapper->GetInteractiveUpdateRateMinValue());
  }
  else
  {
    mapper->SetInteractiveUpdateRate(this->StillInteractiveUpdateRate);
  }
}

bool vtkNimbusCloudRepresentation::UnitsDependOnFrame() const
{
  return (this->DensityUnits == static_cast<int>(nimbus::DensityUnits::LiquidWaterMixingRatio) &&
           this->AirDensityArray.empty()) ||
    this->DensityUnits == nimbus::kEstimatedDensityUnits;
}

void vtkNimbusCloudRepresentation::SetExtinctionPerDensity(double value)
{
  this->CloudMapper->SetExtinctionPerDensity(value); // refuses NaN, clamps
  this->UserExtinctionPerDensity = this->CloudMapper->GetExtinctionPerDensity();
  if (this->DensityUnits != 0)
  {
    this->CloudMapper->SetExtinctionPerDensity(1.0); // the array is extinction already
  }
}

double vtkNimbusCloudRepresentation::GetExtinctionPerDensity()
{
  return this->UserExtinctionPerDensity;
}

void vtkNimbusCloudRepresentation::SetMetresPerUnit(double value)
{
  const double before = this->CloudMapper->GetMetresPerUnit();
  this->CloudMapper->SetMetresPerUnit(value);
  if (this->CloudMapper->GetMetresPerUnit() != before && this->UnitsDependOnFrame())
  {
    this->MarkModified();
  }
}

double vtkNimbusCloudRepresentation::GetMetresPerUnit()
{
  return this->CloudMapper->GetMetresPerUnit();
}

void vtkNimbusCloudRepresentation::SetSceneAltitudeMetres(double value)
{
  const double before = this->CloudMapper->GetSceneAltitudeMetres();
  this->CloudMapper->SetSceneAltitudeMetres(value);
  if (this->CloudMapper->GetSceneAltitudeMetres() != before && this->UnitsDependOnFrame())
  {
    this->MarkModified();
  }
}

double vtkNimbusCloudRepresentation::GetSceneAltitudeMetres()
{
  return this->CloudMapper->GetSceneAltitudeMetres();
}

void vtkNimbusCloudRepresentation::SetUpAxis(int value)
{
  const int before = this->CloudMapper->GetUpAxis();
  this->CloudMapper->SetUpAxis(value); // refuses values that are not an axis
  if (this->CloudMapper->GetUpAxis() != before && this->UnitsDependOnFrame())
  {
    this->MarkModified();
  }
}

int vtkNimbusCloudRepresentation::GetUpAxis()
{
  return this->CloudMapper->GetUpAxis();
}

void vtkNimbusCloudRepresentation::SetDensityUnits(int value)
{
  if (!nimbus::IsDensityUnits(value) && value != nimbus::kEstimatedDensityUnits)
  {
    vtkErrorMacro("SetDensityUnits(" << value << "): not a choice of units (0 to "
                                     << nimbus::kEstimatedDensityUnits << "); the units stay "
                                     << this->DensityUnits);
    return;
  }
  if (value != this->DensityUnits)
  {
    this->DensityUnits = value;
    this->MarkModified();
  }
}

void vtkNimbusCloudRepresentation::SetDropletSize(int value)
{
  if (!nimbus::IsDropletSize(value))
  {
    vtkErrorMacro(
      "SetDropletSize(" << value << "): 0 (effective radius) or 1 (number concentration)");
    return;
  }
  if (value != this->DropletSize)
  {
    this->DropletSize = value;
    this->MarkModified();
  }
}

// The optics' numbers: NaN and infinity refused (CheckCloudOptics refuses the rest
// with a message at the next execution).
#define NIMBUS_OPTICS_SETTER(name)                                                                 \
  void vtkNimbusCloudRepresentation::Set##name(double value)                                       \
  {                                                                                                \
    if (!std::isfinite(value))                                                                     \
    {                                                                                              \
      vtkErrorMacro("Set" #name "(" << value << "): not a finite number; ignored");                \
      return;                                                                                      \
    }                                                                                              \
    if (value != this->name)                                                                       \
    {                                                                                              \
      this->name = value;                                                                          \
      this->MarkModified();                                                                        \
    }                                                                                              \
  }
NIMBUS_OPTICS_SETTER(DropletEffectiveRadiusMicrometres)
NIMBUS_OPTICS_SETTER(DropletNumberConcentrationPerCubicCentimetre)
NIMBUS_OPTICS_SETTER(TargetOpticalThickness)
NIMBUS_OPTICS_SETTER(ResampleMemoryBudgetMiB)
#undef NIMBUS_OPTICS_SETTER

void vtkNimbusCloudRepresentation::SetAirDensityArray(const char* name)
{
  const std::string value = name ? name : "";
  if (value != this->AirDensityArray)
  {
    this->AirDensityArray = value;
    this->MarkModified();
  }
}

void vtkNimbusCloudRepresentation::SetSamplingDimensions(int x, int y, int z)
{
  const int dims[3] = { std::max(x, 0), std::max(y, 0), std::max(z, 0) }; // 0: automatic
  if (!std::equal(dims, dims + 3, this->SamplingDimensions))
  {
    std::copy(dims, dims + 3, this->SamplingDimensions);
    this->MarkModified();
  }
}

void vtkNimbusCloudRepresentation::SetEmissionTemperatureArray(const char* name)
{
  this->CloudMapper->SetEmissionTemperatureArray(name);
}

const char* vtkNimbusCloudRepresentation::GetEmissionTemperatureArray()
{
  return this->CloudMapper->GetEmissionTemperatureArray();
}

// The light map: read with the reader the factory picks for the file (by its
// contents and extension); any failure leaves no map and says why.
void vtkNimbusCloudRepresentation::SetLightMapFile(const char* name)
{
  const std::string value = name ? name : "";
  if (value == this->LightMapFile)
  {
    return;
  }
  this->LightMapFile = value;
  this->CloudMapper->SetLightMap(nullptr);
  if (value.empty())
  {
    return;
  }
  if (!vtksys::SystemTools::FileExists(value, true))
  {
    // ParaView's file field sets the name at every keystroke: the partial names typed on
    // the way ("/da", "/data/gob") are not reported, only a missing image file's name.
    std::string extension =
      vtksys::SystemTools::LowerCase(vtksys::SystemTools::GetFilenameLastExtension(value));
    static const char* const imageExtensions[] = { ".png", ".jpg", ".jpeg", ".pgm", ".ppm", ".pnm",
      ".tif", ".tiff", ".bmp" };
    if (std::find(std::begin(imageExtensions), std::end(imageExtensions), extension) !=
      std::end(imageExtensions))
    {
      vtkErrorMacro("Light Map File '" << value
                                       << "': no such file; the spotlights shine without a "
                                          "light map.");
    }
    return;
  }
  vtkSmartPointer<vtkImageReader2> reader;
  reader.TakeReference(vtkImageReader2Factory::CreateImageReader2(value.c_str()));
  if (!reader)
  {
    vtkErrorMacro("Light Map File '" << value
                                     << "': not an image format VTK reads (.png, .jpg, "
                                        ".pgm/.ppm, .tif, .bmp); the spotlights shine "
                                        "without a light map.");
    return;
  }
  reader->SetFileName(value.c_str());
  reader->Update();
  vtkImageData* image = reader->GetOutput();
  int dims[3] = { 0, 0, 0 };
  if (image)
  {
    image->GetDimensions(dims);
  }
  if (reader->GetErrorCode() != 0 || !image || dims[0] < 1 || dims[1] < 1 ||
    !image->GetPointData()->GetScalars())
  {
    vtkErrorMacro("Light Map File '" << value << "': the " << reader->GetDescriptiveName()
                                     << " reader could not read an image from it; the "
                                        "spotlights shine without a light map.");
    return;
  }
  vtkNew<vtkImageData> copy;
  copy->ShallowCopy(image);
  this->CloudMapper->SetLightMap(copy);
}

void vtkNimbusCloudRepresentation::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Turbidity: " << this->Turbidity << "\n";
  os << indent << "DensityUnits: " << this->DensityUnits << " (extinction per density "
     << this->UserExtinctionPerDensity << " 1/m; estimated " << this->EstimatedExtinctionPerDensity
     << " 1/m per unit)\n";
  os << indent << "DropletSize: " << this->DropletSize << ", effective radius "
     << this->DropletEffectiveRadiusMicrometres << " um, number concentration "
     << this->DropletNumberConcentrationPerCubicCentimetre << " /cm^3\n";
  os << indent << "AirDensityArray: '" << this->AirDensityArray << "'\n";
  os << indent << "TargetOpticalThickness: " << this->TargetOpticalThickness << "\n";
  os << indent << "SamplingDimensions: " << this->SamplingDimensions[0] << " "
     << this->SamplingDimensions[1] << " " << this->SamplingDimensions[2]
     << " (resampled: " << this->Resampled << ")\n";
  os << indent << "ResampleMemoryBudgetMiB: " << this->ResampleMemoryBudgetMiB << "\n";
  os << indent
     << "MieScatteringPerMetre (override, -1 = from Turbidity): " << this->MieScatteringOverride
     << "\n";
  os << indent << "FogVisibilityMetres (0 = no fog): " << this->FogVisibilityMetres << "\n";
  os << indent << "LightMapFile: '" << this->LightMapFile << "'\n";
  os << indent << "WholeBounds (all ranks' pieces): " << this->WholeBounds[0] << " .. "
     << this->WholeBounds[1] << ", " << this->WholeBounds[2] << " .. " << this->WholeBounds[3]
     << ", " << this->WholeBounds[4] << " .. " << this->WholeBounds[5] << "\n";
  os << indent << "CoarseDensity: " << this->CoarseDensity.GetPointer() << "\n";
  os << indent << "Bottom layer placed at the renderer's start: "
     << (this->RendererStartTag != 0 ? "yes" : "no") << "\n";
  os << indent << "CloudMapper:\n";
  this->CloudMapper->PrintSelf(os, indent.GetNextIndent());
}
