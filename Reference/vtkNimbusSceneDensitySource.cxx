#include "vtkNimbusSceneDensitySource.h"

#include "MemoryBudget.h"
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
  : MemoryBudgetMiB(nimbus::DefaultMemoryBudgetMiB())
{
  this->SetNumberOfInputPorts(0);
}

int vtkNimbusSceneDensitySource::RequestInformation(
  vtkInformation* request, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  // No exception leaves the algorithm.
  try
  {
    return this->SetUpInner(request, inputVector, outputVector);
  }
  catch (const std::exception& error)
  {
    this->Inner = nullptr;
    vtkErrorMacro(<< this->SceneFileName << ": " << error.what());
  }
  catch (...)
  {
    this->Inner = nullptr;
    vtkErrorMacro(<< this->SceneFileName << ": setting up the density failed (unknown exception)");
  }
  return 0;
}

int vtkNimbusSceneDensitySource::SetUpInner(
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
  if (this->Medium > static_cast<int>(scene.Media.size()))
  {
    vtkErrorMacro(<< this->SceneFileName << ": Medium " << this->Medium << " asks for media["
                  << this->Medium - 1 << "], but the scene has " << scene.Media.size()
                  << " additional media");
    return 0;
  }
  const nimbus::DensitySourceDescription& density =
    this->Medium == 0 ? scene.Medium.Density : scene.Media[this->Medium - 1].Density;
  const std::string key =
    this->Medium == 0 ? "medium" : "media[" + std::to_string(this->Medium - 1) + "]";
  if (density.Type == "file")
  {
    vtkNew<vtkXMLImageDataReader> reader;
    if (!reader->CanReadFile(density.Path.c_str()))
    {
      vtkErrorMacro(<< this->SceneFileName << ": " << key << ".density.path: cannot read '"
                    << density.Path << "' as a VTK image (.vti)");
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
  try
  {
    return this->MakeVolume(output);
  }
  catch (const std::exception& error)
  {
    vtkErrorMacro(<< this->SceneFileName << ": making the density failed: " << error.what());
  }
  catch (...)
  {
    vtkErrorMacro(<< this->SceneFileName << ": making the density failed (unknown exception)");
  }
  output->Initialize();
  return 0;
}

int vtkNimbusSceneDensitySource::MakeVolume(vtkImageData* output)
{
  // The size before the volume is made: an allowed but huge grid (2^30 points)
  // must end in a message, not in VTK's abort on a failed allocation.
  int whole[6];
  this->Inner->GetOutputInformation(0)->Get(
    vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), whole);
  uint64_t points = 0;
  const bool representable = whole[1] >= whole[0] && whole[3] >= whole[2] && whole[5] >= whole[4] &&
    nimbus::CheckedProduct({ static_cast<uint64_t>(whole[1]) - whole[0] + 1,
                             static_cast<uint64_t>(whole[3]) - whole[2] + 1,
                             static_cast<uint64_t>(whole[5]) - whole[4] + 1 },
      points);
  const double budget = this->MemoryBudgetMiB > 0.0
    ? this->MemoryBudgetMiB * 1048576.0
    : static_cast<double>(nimbus::DefaultMemoryBudgetBytes());
  const std::string overBudget = nimbus::OverBudgetMessage("the density volume (" +
      std::to_string(whole[1] - whole[0] + 1) + "x" + std::to_string(whole[3] - whole[2] + 1) +
      "x" + std::to_string(whole[5] - whole[4] + 1) + " points, 12 bytes each)",
    representable ? 12.0 * static_cast<double>(points) : -1.0, budget);
  if (!overBudget.empty())
  {
    vtkErrorMacro(<< this->SceneFileName << ": " << overBudget
                  << " (set MemoryBudgetMiB to allow more)");
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
  output->SetDirectionMatrix(volume->GetDirectionMatrix());
  vtkNew<vtkFloatArray> densityArray; // any numeric type is converted once, to float
  densityArray->DeepCopy(values);
  densityArray->SetName("density");
  output->GetPointData()->SetScalars(densityArray);
  const nimbus::ValueCensus census = nimbus::TakeCensus(
    densityArray->GetPointer(0), static_cast<std::size_t>(densityArray->GetNumberOfValues()));
  if (!census.AllFiniteNonNegative())
  {
    vtkWarningMacro(<< this->SceneFileName << ": the density has " << nimbus::DescribeCensus(census)
                    << " among " << densityArray->GetNumberOfValues()
                    << " (densities must be finite and >= 0; the reference renderers refuse it)");
  }
  return 1;
}

void vtkNimbusSceneDensitySource::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "SceneFileName: " << this->SceneFileName << "\n";
  os << indent << "MemoryBudgetMiB: " << this->MemoryBudgetMiB << "\n";
  os << indent << "Medium: " << this->Medium << "\n";
}
