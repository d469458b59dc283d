#include "vtkNimbusCloudSplatRepresentation.h"

#include "Sky.h" // nimbus::SkyModel: the sky's sun temperature
#include "vtkActor.h"
#include "vtkAlgorithm.h"
#include "vtkDataArray.h"
#include "vtkInformation.h"
#include "vtkInformationObjectBaseKey.h"
#include "vtkInformationVector.h"
#include "vtkNimbusCloudSplatMapper.h"
#include "vtkNimbusSky.h"
#include "vtkNimbusSkyBackground.h"
#include "vtkObjectFactory.h"
#include "vtkPVRenderView.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkPropCollection.h"
#include "vtkRenderer.h"

#include <algorithm>
#include <cmath>
#include <exception>

vtkStandardNewMacro(vtkNimbusCloudSplatRepresentation);

namespace
{
// The bounds of the balls themselves: each point grown by its own radius (balls the
// mapper skips, with a radius that is not positive and finite, by none), so that a
// camera reset frames the whole cloud and no more.
void GrowByRadii(vtkPolyData* balls, vtkDataArray* radii, double bounds[6])
{
  for (vtkIdType id = 0; id < balls->GetNumberOfPoints(); ++id)
  {
    const double radius = radii->GetComponent(id, 0);
    if (!std::isfinite(radius) || radius <= 0.0)
    {
      continue;
    }
    double point[3];
    balls->GetPoint(id, point);
    for (int axis = 0; axis < 3; ++axis)
    {
      bounds[2 * axis] = std::min(bounds[2 * axis], point[axis] - radius);
      bounds[2 * axis + 1] = std::max(bounds[2 * axis + 1], point[axis] + radius);
    }
  }
}

// The splats are drawn in the opaque pass and write no depth; the sky background,
// also drawn there, fills every pixel still at the far plane: drawn after the splats it
// would cover them. Props draw in the renderer's order, so the splats' actor is moved
// behind the sky's when the sky was added after it (then it stays there).
void KeepAfterSky(vtkRenderer* renderer, vtkActor* actor, vtkProp* sky)
{
  if (!sky)
  {
    return;
  }
  int index = 0;
  int actorIndex = -1;
  int skyIndex = -1;
  vtkCollectionSimpleIterator iterator;
  vtkPropCollection* props = renderer->GetViewProps();
  props->InitTraversal(iterator);
  while (vtkProp* prop = props->GetNextProp(iterator))
  {
    actorIndex = prop == actor ? index : actorIndex;
    skyIndex = prop == sky ? index : skyIndex;
    ++index;
  }
  if (actorIndex >= 0 && skyIndex > actorIndex)
  {
    renderer->RemoveActor(actor);
    renderer->AddActor(actor);
  }
}
}

vtkNimbusCloudSplatRepresentation::vtkNimbusCloudSplatRepresentation()
  : Balls(vtkSmartPointer<vtkPolyData>::New())
{
  this->Actor->SetMapper(this->Mapper);
  this->Actor->SetVisibility(this->GetVisibility());
  this->ApplySun();
}

vtkNimbusCloudSplatRepresentation::~vtkNimbusCloudSplatRepresentation() = default;

vtkNimbusCloudSplatMapper* vtkNimbusCloudSplatRepresentation::GetSplatMapper()
{
  return this->Mapper;
}

int vtkNimbusCloudSplatRepresentation::FillInputPortInformation(int, vtkInformation* info)
{
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkPolyData");
  info->Set(vtkAlgorithm::INPUT_IS_OPTIONAL(), 1);
  return 1;
}

int vtkNimbusCloudSplatRepresentation::RequestData(
  vtkInformation* request, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  // A new object each time: the view's delivery notices that the data changed.
  auto balls = vtkSmartPointer<vtkPolyData>::New();
  double bounds[6] = { 1.0, -1.0, 1.0, -1.0, 1.0, -1.0 };
  if (inputVector[0]->GetNumberOfInformationObjects() == 1)
  {
    vtkPolyData* input = vtkPolyData::GetData(inputVector[0], 0);
    if (input && input->GetPoints())
    {
      // Only the points and their arrays travel: the mapper draws no cells.
      balls->SetPoints(input->GetPoints());
      balls->GetPointData()->ShallowCopy(input->GetPointData());
      balls->GetBounds(bounds);
      vtkDataArray* radii = this->Mapper->GetRadiusArrayName()
        ? input->GetPointData()->GetArray(this->Mapper->GetRadiusArrayName())
        : nullptr;
      if (radii && radii->GetNumberOfComponents() == 1)
      {
        GrowByRadii(input, radii, bounds);
      }
    }
  }
  this->Balls = balls;
  std::copy(bounds, bounds + 6, this->BallBounds);
  return this->Superclass::RequestData(request, inputVector, outputVector);
}

int vtkNimbusCloudSplatRepresentation::ProcessViewRequest(
  vtkInformationRequestKey* requestType, vtkInformation* inInfo, vtkInformation* outInfo)
{
  if (!this->Superclass::ProcessViewRequest(requestType, inInfo, outInfo))
  {
    return 0; // hidden, or nothing to do
  }
  if (requestType == vtkPVView::REQUEST_UPDATE())
  {
    vtkPVView::SetPiece(inInfo, this, this->Balls);
    vtkPVRenderView::SetGeometryBounds(inInfo, this, this->BallBounds);
  }
  else if (requestType == vtkPVView::REQUEST_RENDER())
  {
    vtkDataObject* delivered = vtkPVView::GetDeliveredPiece(inInfo, this);
    this->Mapper->SetInputDataObject(delivered ? delivered : this->Balls.GetPointer());
    this->ApplySun();
  }
  return 1;
}

void vtkNimbusCloudSplatRepresentation::ApplySun()
{
  // The sky the view shows now (or none): the representations of a view are
  // separate, so the coupling goes through the renderer's information.
  vtkNimbusSky* sky = nullptr;
  vtkNimbusSkyBackground* background = nullptr;
  auto* view = vtkPVRenderView::SafeDownCast(this->GetView());
  if (this->UseSceneSky && view && view->GetRenderer() && view->GetRenderer()->GetInformation())
  {
    background = vtkNimbusSkyBackground::ShownIn(view->GetRenderer());
    sky = background && background->GetVisibility() ? background->GetSky() : nullptr;
    KeepAfterSky(view->GetRenderer(), this->Actor, background);
  }
  // Over the sky the mapper takes its sun, air and display too while it is drawn, as the
  // Cloud representation's mapper does (the sky's light, the air, the frame's encoding).
  this->Mapper->SetSkyBackground(background);
  double temperature = this->SunTemperatureKelvin;
  if (sky)
  {
    try
    {
      temperature = sky->GetSkyModel().GetParameters().SunTemperatureKelvin;
    }
    catch (const std::exception& error)
    {
      vtkErrorMacro("The view's sky is invalid, the splats keep their own sun: " << error.what());
      sky = nullptr;
      temperature = this->SunTemperatureKelvin;
    }
  }
  this->LastRenderUsedSceneSky = sky != nullptr;
  // Unchanged values leave the mapper (and its sun pass) untouched.
  this->Mapper->SetSunElevationDegrees(
    sky ? sky->GetSunElevationDegrees() : this->SunElevationDegrees);
  this->Mapper->SetSunAzimuthDegrees(sky ? sky->GetSunAzimuthDegrees() : this->SunAzimuthDegrees);
  this->Mapper->SetSunIlluminance(sky ? 1.0 : this->SunIlluminance); // the sky's sun: 1
  this->Mapper->SetSunTemperatureKelvin(temperature);
}

bool vtkNimbusCloudSplatRepresentation::AddToView(vtkView* view)
{
  auto* renderView = vtkPVRenderView::SafeDownCast(view);
  if (!renderView || !renderView->GetRenderer())
  {
    return false;
  }
  renderView->GetRenderer()->AddActor(this->Actor);
  return this->Superclass::AddToView(view);
}

bool vtkNimbusCloudSplatRepresentation::RemoveFromView(vtkView* view)
{
  auto* renderView = vtkPVRenderView::SafeDownCast(view);
  if (renderView && renderView->GetRenderer())
  {
    renderView->GetRenderer()->RemoveActor(this->Actor);
  }
  return this->Superclass::RemoveFromView(view);
}

void vtkNimbusCloudSplatRepresentation::SetVisibility(bool visible)
{
  this->Superclass::SetVisibility(visible);
  this->Actor->SetVisibility(visible);
}

//------------------------------------------------------------------------------
// The arrays re-execute the representation (the bounds grow by the radii); the sun,
// optics and display only re-render.
void vtkNimbusCloudSplatRepresentation::SetRadiusArrayName(const char* name)
{
  this->Mapper->SetRadiusArrayName(name);
  this->MarkModified();
}

const char* vtkNimbusCloudSplatRepresentation::GetRadiusArrayName()
{
  return this->Mapper->GetRadiusArrayName();
}

void vtkNimbusCloudSplatRepresentation::SetDensityArrayName(const char* name)
{
  this->Mapper->SetDensityArrayName(name);
  this->MarkModified();
}

const char* vtkNimbusCloudSplatRepresentation::GetDensityArrayName()
{
  return this->Mapper->GetDensityArrayName();
}

void vtkNimbusCloudSplatRepresentation::SetSunElevationDegrees(double value)
{
  this->SunElevationDegrees = std::isfinite(value) ? std::clamp(value, -90.0, 90.0) : 45.0;
  this->ApplySun();
  this->Modified();
}

void vtkNimbusCloudSplatRepresentation::SetSunAzimuthDegrees(double value)
{
  this->SunAzimuthDegrees = std::isfinite(value) ? value : 135.0;
  this->ApplySun();
  this->Modified();
}

void vtkNimbusCloudSplatRepresentation::SetSunIlluminance(double value)
{
  this->SunIlluminance = std::isfinite(value) ? std::max(value, 0.0) : 1.0;
  this->ApplySun();
  this->Modified();
}

void vtkNimbusCloudSplatRepresentation::SetSunTemperatureKelvin(double value)
{
  this->SunTemperatureKelvin = std::isfinite(value) ? std::clamp(value, 1000.0, 40000.0) : 5778.0;
  this->ApplySun();
  this->Modified();
}

void vtkNimbusCloudSplatRepresentation::SetUseSceneSky(bool value)
{
  this->UseSceneSky = value;
  this->ApplySun();
  this->Modified();
}

void vtkNimbusCloudSplatRepresentation::SetExtinctionPerDensity(double value)
{
  this->Mapper->SetExtinctionPerDensity(value);
}

double vtkNimbusCloudSplatRepresentation::GetExtinctionPerDensity()
{
  return this->Mapper->GetExtinctionPerDensity();
}

void vtkNimbusCloudSplatRepresentation::SetAlbedo(double value)
{
  this->Mapper->SetAlbedo(value);
}

double vtkNimbusCloudSplatRepresentation::GetAlbedo()
{
  return this->Mapper->GetAlbedo();
}

void vtkNimbusCloudSplatRepresentation::SetCloudG(double value)
{
  this->Mapper->SetCloudG(value);
}

double vtkNimbusCloudSplatRepresentation::GetCloudG()
{
  return this->Mapper->GetCloudG();
}

void vtkNimbusCloudSplatRepresentation::SetMetresPerUnit(double value)
{
  this->Mapper->SetMetresPerUnit(value);
}

double vtkNimbusCloudSplatRepresentation::GetMetresPerUnit()
{
  return this->Mapper->GetMetresPerUnit();
}

void vtkNimbusCloudSplatRepresentation::SetExposure(double value)
{
  this->Mapper->SetExposure(value);
}

double vtkNimbusCloudSplatRepresentation::GetExposure()
{
  return this->Mapper->GetExposure();
}

void vtkNimbusCloudSplatRepresentation::SetSunLightMethod(int value)
{
  this->Mapper->SetSunLightMethod(value);
}

int vtkNimbusCloudSplatRepresentation::GetSunLightMethod()
{
  return this->Mapper->GetSunLightMethod();
}

void vtkNimbusCloudSplatRepresentation::SetMultipleScattering(bool value)
{
  this->Mapper->SetMultipleScattering(value);
}

bool vtkNimbusCloudSplatRepresentation::GetMultipleScattering()
{
  return this->Mapper->GetMultipleScattering();
}

void vtkNimbusCloudSplatRepresentation::SetMultipleScatteringGridSize(int value)
{
  this->Mapper->SetMultipleScatteringGridSize(value);
}

int vtkNimbusCloudSplatRepresentation::GetMultipleScatteringGridSize()
{
  return this->Mapper->GetMultipleScatteringGridSize();
}

void vtkNimbusCloudSplatRepresentation::SetSkyLight(bool value)
{
  this->Mapper->SetSkyLight(value);
}

bool vtkNimbusCloudSplatRepresentation::GetSkyLight()
{
  return this->Mapper->GetSkyLight();
}

void vtkNimbusCloudSplatRepresentation::SetAerialPerspective(bool value)
{
  this->Mapper->SetAerialPerspective(value);
}

bool vtkNimbusCloudSplatRepresentation::GetAerialPerspective()
{
  return this->Mapper->GetAerialPerspective();
}

void vtkNimbusCloudSplatRepresentation::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "SunElevationDegrees: " << this->SunElevationDegrees << "\n";
  os << indent << "SunAzimuthDegrees: " << this->SunAzimuthDegrees << "\n";
  os << indent << "SunIlluminance: " << this->SunIlluminance << "\n";
  os << indent << "SunTemperatureKelvin: " << this->SunTemperatureKelvin << "\n";
  os << indent << "UseSceneSky: " << this->UseSceneSky << "\n";
  os << indent << "LastRenderUsedSceneSky: " << this->LastRenderUsedSceneSky << "\n";
  os << indent << "NumberOfBalls: " << this->Balls->GetNumberOfPoints() << "\n";
  os << indent << "Mapper:\n";
  this->Mapper->PrintSelf(os, indent.GetNextIndent());
}
