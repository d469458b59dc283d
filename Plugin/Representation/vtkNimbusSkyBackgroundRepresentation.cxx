#include "vtkNimbusSkyBackgroundRepresentation.h"

#include "NimbusCompositingOrder.h"

#include "vtkAlgorithm.h"
#include "vtkCamera.h"
#include "vtkDataObject.h"
#include "vtkFieldData.h"
#include "vtkInformation.h"
#include "vtkInformationObjectBaseKey.h"
#include "vtkInformationVector.h"
#include "vtkMatrix4x4.h"
#include "vtkNew.h"
#include "vtkNimbusSky.h"
#include "vtkNimbusSkyBackground.h"
#include "vtkNimbusSkyDomeSource.h"
#include "vtkObjectFactory.h"
#include "vtkPVRenderView.h"
#include "vtkPolyData.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"

#include <algorithm>
#include <cmath>
#include <vector>

vtkStandardNewMacro(vtkNimbusSkyBackgroundRepresentation);

namespace
{
// Automatic exposure: the share of the sky in view allowed above the white point,
// and that white point (display luminance, linear; 1 = white).
constexpr double MeteredFraction = 0.95;
constexpr double WhitePoint = 0.9;
constexpr int MeterGrid = 16; // view directions per side of the frustum

// The factor automatic exposure applies for a camera and a viewport aspect ratio
// (width / height), with the sky's current Exposure: min(1, WhitePoint / Y95), Y95
// the MeteredFraction percentile of the sky's display luminance over a grid of
// view directions through the frustum.
double MeterExposureFactor(vtkNimbusSky* sky, vtkCamera* camera, double aspect);
}

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
      this->InputExposure = this->Background->GetSky()->GetExposure();
    }
    // Under MPI with ordered compositing (a Cloud in the view), the sky is the bottom
    // layer of the composite: only the rank last in IceT's order draws it.
    auto* renderView = vtkPVRenderView::SafeDownCast(this->GetView());
    this->Background->SetDrawSky(nimbus::IsLastInCompositingOrder(renderView));
    // The input's Exposure is now on the sky; lower it if this view needs it.
    vtkNimbusSky* sky = this->Background->GetSky();
    if (sky && this->InputExposure >= 0.0)
    {
      sky->SetExposure(this->InputExposure);
    }
    auto* view = vtkPVRenderView::SafeDownCast(this->GetView());
    if (!this->AutomaticExposure || !sky || !view || !view->GetRenderer())
    {
      this->LastExposureFactor = 1.0;
    }
    else
    {
      // A screenshot larger than the view is rendered in tiles, each with the
      // camera narrowed to its part of the frame (vtkWindowToImageFilter): the tiles
      // keep the factor metered for the whole frame, or they would differ.
      vtkRenderer* renderer = view->GetRenderer();
      vtkRenderWindow* window = renderer->GetRenderWindow();
      const bool tiled = window && (window->GetTileScale()[0] > 1 || window->GetTileScale()[1] > 1);
      if (!tiled)
      {
        this->LastExposureFactor =
          MeterExposureFactor(sky, renderer->GetActiveCamera(), renderer->GetTiledAspectRatio());
      }
      if (this->LastExposureFactor < 1.0)
      {
        sky->SetExposure(sky->GetExposure() * this->LastExposureFactor);
      }
    }
  }
  return 1;
}

namespace
{
double MeterExposureFactor(vtkNimbusSky* sky, vtkCamera* camera, double aspect)
{
  if (!sky || !camera || !(aspect > 0.0) || !(sky->GetExposure() > 0.0))
  {
    return 1.0;
  }
  // Normalised device coordinates -> world, for both projections: a view ray
  // runs from the near plane (z = -1) through the middle of the depth range (z = 0).
  vtkNew<vtkMatrix4x4> inverse;
  vtkMatrix4x4::Invert(camera->GetCompositeProjectionTransformMatrix(aspect, -1.0, 1.0), inverse);
  auto unproject = [&inverse](double x, double y, double z, double world[3])
  {
    const double in[4] = { x, y, z, 1.0 };
    double out[4];
    inverse->MultiplyPoint(in, out);
    for (int i = 0; i < 3; ++i)
    {
      world[i] = out[i] / out[3];
    }
  };
  std::vector<double> luminance;
  luminance.reserve(MeterGrid * MeterGrid);
  for (int j = 0; j < MeterGrid; ++j)
  {
    for (int i = 0; i < MeterGrid; ++i)
    {
      const double x = -1.0 + (i + 0.5) * 2.0 / MeterGrid;
      const double y = -1.0 + (j + 0.5) * 2.0 / MeterGrid;
      double nearPoint[3], middlePoint[3], direction[3];
      unproject(x, y, -1.0, nearPoint);
      unproject(x, y, 0.0, middlePoint);
      double length = 0.0;
      for (int c = 0; c < 3; ++c)
      {
        direction[c] = middlePoint[c] - nearPoint[c];
        length += direction[c] * direction[c];
      }
      length = std::sqrt(length);
      if (!(length > 0.0) || !std::isfinite(length))
      {
        continue;
      }
      for (double& c : direction)
      {
        c /= length;
      }
      double rgb[3];
      sky->GetDisplayColor(direction, rgb); // linear, at the current Exposure
      luminance.push_back(0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]);
    }
  }
  if (luminance.empty())
  {
    return 1.0;
  }
  auto percentile = luminance.begin() +
    std::min<std::ptrdiff_t>(static_cast<std::ptrdiff_t>(MeteredFraction * luminance.size()),
      static_cast<std::ptrdiff_t>(luminance.size()) - 1);
  std::nth_element(luminance.begin(), percentile, luminance.end());
  const double bright = *percentile;
  return bright > WhitePoint && std::isfinite(bright) ? WhitePoint / bright : 1.0;
}
}

void vtkNimbusSkyBackgroundRepresentation::SetVisibility(bool visible)
{
  this->Superclass::SetVisibility(visible);
  this->Background->SetVisibility(visible);
  auto* renderView = vtkPVRenderView::SafeDownCast(this->GetView());
  if (renderView && renderView->GetRenderer())
  {
    this->NameInRenderer(renderView->GetRenderer());
  }
}

// The renderer names the visible sky for the view's Cloud representations
// (vtkNimbusSkyBackground::ShownIn): every display of a data set carries a hidden Sky
// Background representation, which must not take the name from the one shown.
void vtkNimbusSkyBackgroundRepresentation::NameInRenderer(vtkRenderer* renderer)
{
  vtkInformation* information = renderer->GetInformation();
  if (this->GetVisibility())
  {
    information->Set(vtkNimbusSkyBackground::RENDERER_SKY_BACKGROUND(), this->Background);
  }
  else if (information->Get(vtkNimbusSkyBackground::RENDERER_SKY_BACKGROUND()) == this->Background)
  {
    information->Remove(vtkNimbusSkyBackground::RENDERER_SKY_BACKGROUND());
  }
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
  this->NameInRenderer(renderer);
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
  os << indent << "AutomaticExposure: " << this->AutomaticExposure << "\n";
  os << indent << "LastExposureFactor: " << this->LastExposureFactor << "\n";
}
