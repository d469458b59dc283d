#include "vtkNimbusCloudRepresentation.h"

#include "vtkCommand.h"
#include "vtkDataObject.h"
#include "vtkInformation.h"
#include "vtkInformationObjectBaseKey.h"
#include "vtkPVLODVolume.h"
#include "vtkPVRenderView.h"
#include "vtkRenderer.h"

#include "vtkNimbusCloudVolumeMapper.h"
#include "vtkNimbusSkyBackground.h"
#include "vtkObjectFactory.h"

#include <cmath>

vtkStandardNewMacro(vtkNimbusCloudRepresentation);

vtkNimbusCloudRepresentation::vtkNimbusCloudRepresentation()
{
  // Replace the superclass's vtkMultiBlockVolumeMapper; the superclass connects
  // the delivered data to VolumeMapper at each render request.
  this->CloudMapper = vtkNimbusCloudVolumeMapper::New();
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

void vtkNimbusCloudRepresentation::ApplyHaze()
{
  if (this->MieScatteringOverride >= 0.0)
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

vtkNimbusCloudRepresentation::~vtkNimbusCloudRepresentation() = default;

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
    vtkNimbusSkyBackground* sky = nullptr;
    auto* view = vtkPVRenderView::SafeDownCast(this->GetView());
    if (view && view->GetRenderer() && view->GetRenderer()->GetInformation())
    {
      sky = vtkNimbusSkyBackground::SafeDownCast(view->GetRenderer()->GetInformation()->Get(
        vtkNimbusSkyBackground::RENDERER_SKY_BACKGROUND()));
    }
    this->CloudMapper->SetSkyBackground(sky);
  }
  return 1;
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
  if (!hasArray)
  {
    this->CloudMapper->SelectScalarArray(static_cast<const char*>(nullptr));
    this->CloudMapper->SetScalarModeToDefault();
    this->Actor->SetVisibility(this->GetVisibility());
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

NIMBUS_FORWARD(ExtinctionPerDensity, double)
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
NIMBUS_FORWARD(SceneAltitudeMetres, double)
NIMBUS_FORWARD(Ground, bool)
NIMBUS_FORWARD(GroundHeight, double)
NIMBUS_FORWARD(GroundAlbedo, double)
NIMBUS_FORWARD(Shafts, bool)
NIMBUS_FORWARD(AirMultipleScattering, bool)
NIMBUS_FORWARD(UseSceneSky, bool)
NIMBUS_FORWARD(NumberOfSlices, int)
NIMBUS_FORWARD(SliceAngleRatio, double)
NIMBUS_FORWARD(ShadowSurfaceSize, int)
NIMBUS_FORWARD(AtmosphereSteps, int)
NIMBUS_FORWARD(SliceJitter, bool)
NIMBUS_FORWARD(MaximumTextureSize, int)
NIMBUS_FORWARD(TextureMemoryBudgetMiB, double)
NIMBUS_FORWARD(MetresPerUnit, double)
NIMBUS_FORWARD(Exposure, double)
NIMBUS_FORWARD(EncodeSrgb, bool)
NIMBUS_FORWARD(FrameBudgetMilliseconds, double)
NIMBUS_FORWARD(Quality, double)

#undef NIMBUS_FORWARD

void vtkNimbusCloudRepresentation::SetEmissionTemperatureArray(const char* name)
{
  this->CloudMapper->SetEmissionTemperatureArray(name);
}

const char* vtkNimbusCloudRepresentation::GetEmissionTemperatureArray()
{
  return this->CloudMapper->GetEmissionTemperatureArray();
}

void vtkNimbusCloudRepresentation::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Turbidity: " << this->Turbidity << "\n";
  os << indent
     << "MieScatteringPerMetre (override, -1 = from Turbidity): " << this->MieScatteringOverride
     << "\n";
  os << indent << "CloudMapper:\n";
  this->CloudMapper->PrintSelf(os, indent.GetNextIndent());
}
