#include "vtkNimbusSkyBackgroundRepresentation.h"

#include "vtkAlgorithm.h"
#include "vtkDataObject.h"
#include "vtkFieldData.h"
#include "vtkInformation.h"
#include "vtkInformationObjectBaseKey.h"
#include "vtkInformationVector.h"
#include "vtkNimbusSky.h"
#include "vtkNimbusSkyBackground.h"
#include "vtkNimbusSkyDomeSource.h"
#include "vtkObjectFactory.h"
#include "vtkPVRenderView.h"
#include "vtkPolyData.h"
#include "vtkRenderer.h"

vtkStandardNewMacro(vtkNimbusSkyBackgroundRepresentation);

vtkNimbusSkyBackgroundRepresentation::vtkNimbusSkyBackgroundRepresentation()
  : Parameters(vtkSmartPointer<vtkPolyData>::New())
{
  this->Background->SetVisibility(this->GetVisibility());
}

vtkNimbusSkyBackgroundRepresentation::~vtkNimbusSkyBackgroundRepresentation() = default;

vtkNimbusSkyBackground* vtkNimbusSkyBackgroundRepresentation::GetBackground()
{
  return this->Background;
}

int vtkNimbusSkyBackgroundRepresentation::FillInputPortInformation(int, vtkInformation* info)
{
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkDataObject");
  // Processes that render but hold no data (the client of a remote server,
  // render-server ranks) get the delivered parameters instead of an input.
  info->Set(vtkAlgorithm::INPUT_IS_OPTIONAL(), 1);
  return 1;
}

int vtkNimbusSkyBackgroundRepresentation::RequestData(
  vtkInformation* request, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  // A new object each time: the view's delivery notices that the data changed.
  auto parameters = vtkSmartPointer<vtkPolyData>::New();
  if (inputVector[0]->GetNumberOfInformationObjects() == 1)
  {
    vtkDataObject* input = vtkDataObject::GetData(inputVector[0], 0);
    if (input && input->GetFieldData())
    {
      // Only the field data travels: the geometry (e.g. the dome) is not drawn.
      vtkNew<vtkFieldData> fieldData;
      fieldData->ShallowCopy(input->GetFieldData());
      parameters->SetFieldData(fieldData);
    }
  }
  this->Parameters = parameters;
  return this->Superclass::RequestData(request, inputVector, outputVector);
}

int vtkNimbusSkyBackgroundRepresentation::ProcessViewRequest(
  vtkInformationRequestKey* requestType, vtkInformation* inInfo, vtkInformation* outInfo)
{
  if (!this->Superclass::ProcessViewRequest(requestType, inInfo, outInfo))
  {
    return 0; // hidden, or nothing to do
  }
  if (requestType == vtkPVView::REQUEST_UPDATE())
  {
    vtkPVView::SetPiece(inInfo, this, this->Parameters);
  }
  else if (requestType == vtkPVView::REQUEST_RENDER())
  {
    if (vtkDataObject* delivered = vtkPVView::GetDeliveredPiece(inInfo, this))
    {
      // Unchanged values leave the sky (and its tables) untouched.
      vtkNimbusSkyDomeSource::ApplySkyParameters(
        delivered->GetFieldData(), this->Background->GetSky());
      ++this->NumberOfParameterUpdates;
    }
  }
  return 1;
}

void vtkNimbusSkyBackgroundRepresentation::SetVisibility(bool visible)
{
  this->Superclass::SetVisibility(visible);
  this->Background->SetVisibility(visible);
}

bool vtkNimbusSkyBackgroundRepresentation::AddToView(vtkView* view)
{
  auto* renderView = vtkPVRenderView::SafeDownCast(view);
  if (!renderView)
  {
    return false; // the sky is a render view's background only
  }
  vtkRenderer* renderer = renderView->GetRenderer();
  renderer->AddViewProp(this->Background);
  // Named for the view's Cloud representations (vtkNimbusCloudRepresentation).
  renderer->GetInformation()->Set(
    vtkNimbusSkyBackground::RENDERER_SKY_BACKGROUND(), this->Background);
  return this->Superclass::AddToView(view);
}

bool vtkNimbusSkyBackgroundRepresentation::RemoveFromView(vtkView* view)
{
  auto* renderView = vtkPVRenderView::SafeDownCast(view);
  if (!renderView)
  {
    return false;
  }
  vtkRenderer* renderer = renderView->GetRenderer();
  renderer->RemoveViewProp(this->Background);
  vtkInformation* information = renderer->GetInformation();
  if (information->Get(vtkNimbusSkyBackground::RENDERER_SKY_BACKGROUND()) == this->Background)
  {
    information->Remove(vtkNimbusSkyBackground::RENDERER_SKY_BACKGROUND());
  }
  return this->Superclass::RemoveFromView(view);
}

void vtkNimbusSkyBackgroundRepresentation::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Background: " << this->Background.GetPointer() << "\n";
  os << indent << "NumberOfParameterUpdates: " << this->NumberOfParameterUpdates << "\n";
}
