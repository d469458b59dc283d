#include "vtkNimbusSceneDensitySource.h"

#include "SceneJson.h"
#include "vtkNimbusMetaballCloudSource.h"

#include "vtkDataArray.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include "vtkXMLImageDataReader.h"

#include <functional>
#include <map>
#include <stdexcept>

vtkStandardNewMacro(vtkNimbusSceneDensitySource);

namespace
{
using Setter = std::function<void(vtkNimbusMetaballCloudSource*, const std::vector<double>&)>;

// vtkNimbusMetaballCloudSource's parameters by name (SceneJson.cxx validates names and counts).
const std::map<std::string, Setter>& MetaballSetters()
{
  using S = vtkNimbusMetaballCloudSource;
  using V = std::vector<double>;
  static const std::map<std::string, Setter> setters = {
    { "Dimensions",
      [](S* s, const V& v) {
        s->SetDimensions(static_cast<int>(v[0]), static_cast<int>(v[1]), static_cast<int>(v[2]));
      } },
    { "Bounds", [](S* s, const V& v) { s->SetBounds(v[0], v[1], v[2], v[3], v[4], v[5]); } },
    { "Seed", [](S* s, const V& v) { s->SetSeed(static_cast<int>(v[0])); } },
    { "NumberOfLevels", [](S* s, const V& v) { s->SetNumberOfLevels(static_cast<int>(v[0])); } },
    { "NumberOfBaseBalls",
      [](S* s, const V& v) { s->SetNumberOfBaseBalls(static_cast<int>(v[0])); } },
    { "BaseBallRadiusRange", [](S* s, const V& v) { s->SetBaseBallRadiusRange(v[0], v[1]); } },
    { "FootprintRadius", [](S* s, const V& v) { s->SetFootprintRadius(v[0]); } },
    { "TowerHeight", [](S* s, const V& v) { s->SetTowerHeight(v[0]); } },
    { "BallsPerLevel", [](S* s, const V& v) { s->SetBallsPerLevel(static_cast<int>(v[0])); } },
    { "BallCountFactor", [](S* s, const V& v) { s->SetBallCountFactor(v[0]); } },
    { "RadiusScalePerLevel", [](S* s, const V& v) { s->SetRadiusScalePerLevel(v[0]); } },
    { "BallDensity", [](S* s, const V& v) { s->SetBallDensity(v[0]); } },
    { "IsoValue", [](S* s, const V& v) { s->SetIsoValue(v[0]); } },
    { "FlatBase", [](S* s, const V& v) { s->SetFlatBase(v[0] != 0.0); } },
    { "BaseHeight", [](S* s, const V& v) { s->SetBaseHeight(v[0]); } },
    { "BaseTransitionThickness", [](S* s, const V& v) { s->SetBaseTransitionThickness(v[0]); } },
  };
  return setters;
}
}

vtkNimbusSceneDensitySource::vtkNimbusSceneDensitySource()
{
  this->SetNumberOfInputPorts(0);
}

int vtkNimbusSceneDensitySource::RequestInformation(
  vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  this->Inner = nullptr;
  if (this->SceneFileName.empty())
  {
    vtkErrorMacro(<< "No SceneFileName given.");
    return 0;
  }
  nimbus::SceneDescription scene;
  try
  {
    scene = nimbus::LoadScene(this->SceneFileName);
  }
  catch (const std::exception& error)
  {
    vtkErrorMacro(<< error.what());
    return 0;
  }
  const nimbus::DensitySourceDescription& density = scene.Medium.Density;
  if (density.Type == "file")
  {
    vtkNew<vtkXMLImageDataReader> reader;
    if (!reader->CanReadFile(density.Path.c_str()))
    {
      vtkErrorMacro(<< this->SceneFileName << ": medium.density.path: cannot read '" << density.Path
                    << "' as a VTK image (.vti)");
      return 0;
    }
    reader->SetFileName(density.Path.c_str());
    this->Inner = reader;
    this->InnerArrayName = density.ArrayName;
  }
  else
  {
    vtkNew<vtkNimbusMetaballCloudSource> source;
    for (const auto& parameter : density.Parameters)
    {
      MetaballSetters().at(parameter.first)(source, parameter.second);
    }
    this->Inner = source;
    this->InnerArrayName = "density";
  }
  this->Inner->UpdateInformation();
  vtkInformation* innerInfo = this->Inner->GetOutputInformation(0);
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  outInfo->Set(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(),
    innerInfo->Get(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT()), 6);
  outInfo->Set(vtkDataObject::ORIGIN(), innerInfo->Get(vtkDataObject::ORIGIN()), 3);
  outInfo->Set(vtkDataObject::SPACING(), innerInfo->Get(vtkDataObject::SPACING()), 3);
  outInfo->Set(CAN_PRODUCE_SUB_EXTENT(), 0);
  vtkDataObject::SetPointDataActiveScalarInfo(outInfo, VTK_FLOAT, 1);
  return 1;
}

int vtkNimbusSceneDensitySource::RequestData(
  vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  vtkImageData* output = vtkImageData::GetData(outputVector, 0);
  output->Initialize();
  if (!this->Inner)
  {
    return 0;
  }
  this->Inner->Update();
  vtkImageData* volume = vtkImageData::SafeDownCast(this->Inner->GetOutputDataObject(0));
  vtkDataArray* values =
    volume ? volume->GetPointData()->GetArray(this->InnerArrayName.c_str()) : nullptr;
  if (!values || values->GetNumberOfComponents() != 1 || volume->GetNumberOfPoints() == 0)
  {
    vtkErrorMacro(<< this->SceneFileName
                  << ": the density volume has no one-component point array '"
                  << this->InnerArrayName << "'");
    return 0;
  }
  output->SetExtent(volume->GetExtent());
  output->SetOrigin(volume->GetOrigin());
  output->SetSpacing(volume->GetSpacing());
  vtkNew<vtkFloatArray> densityArray; // any numeric type is converted once, to float
  densityArray->DeepCopy(values);
  densityArray->SetName("density");
  output->GetPointData()->SetScalars(densityArray);
  return 1;
}

void vtkNimbusSceneDensitySource::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "SceneFileName: " << this->SceneFileName << "\n";
}
