#include "vtkNimbusReferenceRenderer.h"

#include "FiniteSetters.h"

#include "DensityGrid.h"
#include "DensityGridFromImage.h"
#include "MemoryBudget.h"
#include "PathTracer.h"
#include "RenderContext.h"
#include "SceneAssets.h"
#include "SceneJson.h"
#include "SingleScatteringRenderer.h"
#include "vtkNimbusSceneDensitySource.h"

#include "vtkCallbackCommand.h"
#include "vtkCommand.h"
#include "vtkDataArray.h"
#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkMatrix3x3.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include "vtkXMLImageDataReader.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>
#include <stdexcept>
#include <thread>

vtkStandardNewMacro(vtkNimbusReferenceRenderer);

// Setters with a range refuse NaN and infinity at once (the value is kept) and clamp
// finite values (Common/FiniteSetters.h).
nimbusDefineFiniteSetter(vtkNimbusReferenceRenderer, TimeLimitSeconds);
nimbusDefineFiniteSetter(vtkNimbusReferenceRenderer, TargetImageRelativeError);

struct vtkNimbusReferenceRenderer::vtkInternals
{
  std::unique_ptr<nimbus::SceneDescription> Scene;
};

namespace
{
/// Thrown by the progress callback when the user aborts (AbortExecute).
struct RenderAborted
{
};

/// Empty when the image's direction matrix is the identity (the renderers place
/// the grid by origin and spacing only); else why it cannot be used.
std::string DirectionMatrixProblem(vtkImageData* image)
{
  vtkMatrix3x3* direction = image->GetDirectionMatrix();
  if (!direction || direction->IsIdentity())
  {
    return std::string();
  }
  std::string elements;
  for (int i = 0; i < 3; ++i)
  {
    for (int j = 0; j < 3; ++j)
    {
      elements += (elements.empty() ? "" : " ") + std::to_string(direction->GetElement(i, j));
    }
  }
  return "the density image has a direction matrix that is not the identity (" + elements +
    "): the reference renderers place the grid by origin and spacing along x, y, z only. "
    "Resample it onto an axis-aligned image (e.g. vtkImageReslice) first";
}

// "45 s", "12 min", "3.4 h".
std::string FormatDuration(double seconds)
{
  std::ostringstream text;
  text.precision(seconds < 3600.0 ? 0 : 2);
  text << std::fixed;
  if (seconds < 120.0)
  {
    text << seconds << " s";
  }
  else if (seconds < 3600.0 * 2.0)
  {
    text << seconds / 60.0 << " min";
  }
  else
  {
    text.precision(1);
    text << seconds / 3600.0 << " h";
  }
  return text.str();
}

vtkSmartPointer<vtkFloatArray> ToArray(const nimbus::FloatImage& image, const char* name)
{
  auto array = vtkSmartPointer<vtkFloatArray>::New();
  array->SetName(name);
  array->SetNumberOfComponents(3);
  array->SetNumberOfTuples(static_cast<vtkIdType>(image.Width) * image.Height);
  std::copy(image.Pixels.begin(), image.Pixels.end(), array->GetPointer(0));
  return array;
}

void AddFieldValue(vtkFieldData* fieldData, const char* name, double value)
{
  vtkNew<vtkDoubleArray> array;
  array->SetName(name);
  array->InsertNextValue(value);
  fieldData->AddArray(array);
}
}

vtkNimbusReferenceRenderer::vtkNimbusReferenceRenderer()
  : MemoryBudgetMiB(nimbus::DefaultMemoryBudgetMiB())
  , Internals(new vtkInternals)
{
  this->SetNumberOfInputPorts(1);
}

vtkNimbusReferenceRenderer::~vtkNimbusReferenceRenderer() = default;

int vtkNimbusReferenceRenderer::FillInputPortInformation(int, vtkInformation* info)
{
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkImageData");
  info->Set(vtkAlgorithm::INPUT_IS_OPTIONAL(), 1);
  return 1;
}

int vtkNimbusReferenceRenderer::RequestInformation(
  vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  this->Internals->Scene.reset();
  if (this->SceneFileName.empty())
  {
    vtkErrorMacro(<< "No SceneFileName given.");
    return 0;
  }
  try
  {
    this->Internals->Scene =
      std::make_unique<nimbus::SceneDescription>(nimbus::LoadScene(this->SceneFileName));
    // Version 4: the light maps' pixels and the meshes' triangles the scene names.
    try
    {
      nimbus::LoadSceneAssets(*this->Internals->Scene);
    }
    catch (const std::invalid_argument& error)
    {
      this->Internals->Scene.reset();
      throw std::invalid_argument(this->SceneFileName + ": " + error.what());
    }
  }
  catch (const std::exception& error)
  {
    vtkErrorMacro(<< error.what());
    return 0;
  }
  catch (...)
  {
    vtkErrorMacro(<< this->SceneFileName << ": reading the scene failed (unknown exception)");
    return 0;
  }
  const nimbus::SceneDescription& scene = *this->Internals->Scene;
  const int extent[6] = { 0, scene.Camera.Width - 1, 0, scene.Camera.Height - 1, 0, 0 };
  const double origin[3] = { 0.0, 0.0, 0.0 };
  const double spacing[3] = { 1.0, 1.0, 1.0 };
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  outInfo->Set(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), extent, 6);
  outInfo->Set(vtkDataObject::ORIGIN(), origin, 3);
  outInfo->Set(vtkDataObject::SPACING(), spacing, 3);
  vtkDataObject::SetPointDataActiveScalarInfo(outInfo, VTK_FLOAT, 3);
  return 1;
}

int vtkNimbusReferenceRenderer::RequestUpdateExtent(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector*)
{
  // The whole density volume, whatever part of the image is asked for.
  if (vtkInformation* inInfo = inputVector[0]->GetInformationObject(0))
  {
    inInfo->Set(vtkStreamingDemandDrivenPipeline::UPDATE_EXTENT(),
      inInfo->Get(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT()), 6);
  }
  return 1;
}

int vtkNimbusReferenceRenderer::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkImageData* output = vtkImageData::GetData(outputVector, 0);
  output->Initialize();
  if (!this->Internals->Scene)
  {
    return 0; // RequestInformation reported why
  }
  // No exception leaves the algorithm: bad input ends in an error and an empty output.
  try
  {
    return this->Render(inputVector, output);
  }
  catch (const RenderAborted&)
  {
    output->Initialize();
    vtkDebugMacro(<< "Aborted.");
    return 1;
  }
  catch (const std::exception& error)
  {
    output->Initialize();
    vtkErrorMacro(<< "rendering failed: " << error.what());
    return 0;
  }
  catch (...)
  {
    output->Initialize();
    vtkErrorMacro(<< "rendering failed (unknown exception)");
    return 0;
  }
}

namespace
{
/// The grids of a version-3 scene beyond the main density (RenderContext's SceneFields):
/// additional media (a .vti array, or a metaball cloud made by vtkNimbusSceneDensitySource
/// with Medium = i + 1) and "array" emission fields, read from their .vti files (each file
/// once). Throws std::invalid_argument naming the scene key of what cannot be read.
nimbus::SceneFields SceneFieldsOf(
  const nimbus::SceneDescription& scene, const std::string& sceneFile, double budgetMiB)
{
  nimbus::SceneFields fields;
  std::map<std::string, vtkSmartPointer<vtkImageData>> images;
  auto grid = [&images](const std::string& path, const std::string& array,
                const std::string& key) -> nimbus::DensityGrid
  {
    vtkSmartPointer<vtkImageData>& image = images[path];
    if (!image)
    {
      vtkNew<vtkXMLImageDataReader> reader;
      if (!reader->CanReadFile(path.c_str()))
      {
        throw std::invalid_argument(key + ": cannot read '" + path + "' as a VTK image (.vti)");
      }
      reader->SetFileName(path.c_str());
      reader->Update();
      image = reader->GetOutput();
    }
    vtkDataArray* values = image->GetPointData()->GetArray(array.c_str());
    if (!values || values->GetNumberOfComponents() != 1)
    {
      throw std::invalid_argument(
        key + ": '" + path + "' has no one-component point array '" + array + "'");
    }
    const std::string direction = DirectionMatrixProblem(image);
    if (!direction.empty())
    {
      throw std::invalid_argument(key + ": " + direction);
    }
    try
    {
      return nimbus::DensityGridFromImage(image, values);
    }
    catch (const std::invalid_argument& error)
    {
      throw std::invalid_argument(key + ": array '" + array + "': " + error.what());
    }
  };
  if (scene.Medium.Emission.Enabled &&
    (scene.Medium.Emission.Source == "array" || scene.Medium.Emission.Source == "blackbody"))
  {
    fields.Emission = grid(
      scene.Medium.Density.Path, scene.Medium.Emission.ArrayName, "scene.medium.emission.array");
  }
  for (std::size_t i = 0; i < scene.Media.size(); ++i)
  {
    const nimbus::AdditionalMediumDescription& m = scene.Media[i];
    const std::string key = "scene.media[" + std::to_string(i) + "]";
    if (m.Density.Type == "file")
    {
      fields.MediaDensities.push_back(grid(m.Density.Path, m.Density.ArrayName, key + ".density"));
    }
    else
    {
      vtkNew<vtkNimbusSceneDensitySource> source;
      source->SetSceneFileName(sceneFile.c_str());
      source->SetMedium(static_cast<int>(i) + 1);
      source->SetMemoryBudgetMiB(budgetMiB);
      source->Update();
      vtkImageData* volume = source->GetOutput();
      vtkDataArray* values = volume->GetPointData()->GetArray("density");
      if (!values || volume->GetNumberOfPoints() == 0)
      {
        throw std::invalid_argument(key + ".density: the " + m.Density.Type + " was not made");
      }
      try
      {
        fields.MediaDensities.push_back(nimbus::DensityGridFromImage(volume, values));
      }
      catch (const std::invalid_argument& error)
      {
        throw std::invalid_argument(key + ".density: " + error.what());
      }
    }
    fields.MediaEmissions.emplace_back();
    if (m.Emission.Enabled && (m.Emission.Source == "array" || m.Emission.Source == "blackbody"))
    {
      fields.MediaEmissions.back() =
        grid(m.Density.Path, m.Emission.ArrayName, key + ".emission.array");
    }
  }
  return fields;
}

/// The scene's own density (vtkNimbusSceneDensitySource), when no image is connected.
vtkSmartPointer<vtkImageData> SceneDensity(
  const std::string& sceneFileName, double budgetMiB, std::string& densityErrors)
{
  vtkNew<vtkNimbusSceneDensitySource> sceneDensity;
  sceneDensity->SetSceneFileName(sceneFileName.c_str());
  sceneDensity->SetMemoryBudgetMiB(budgetMiB);
  // Its errors become part of this algorithm's one error (observers of this
  // algorithm see why), its warnings are passed on as they come.
  vtkNew<vtkCallbackCommand> relay;
  relay->SetClientData(&densityErrors);
  relay->SetCallback(
    [](vtkObject*, unsigned long, void* clientData, void* callData)
    {
      auto* text = static_cast<std::string*>(clientData);
      std::string message = static_cast<const char*>(callData);
      const std::size_t object = message.find("): "); // "vtkClass (0x...): "
      message = object == std::string::npos ? message : message.substr(object + 3);
      while (!message.empty() && (message.back() == '\n' || message.back() == ' '))
      {
        message.pop_back();
      }
      *text += (text->empty() ? "" : "; ") + message;
    });
  sceneDensity->AddObserver(vtkCommand::ErrorEvent, relay);
  sceneDensity->Update();
  return sceneDensity->GetOutput();
}

/// The renderers' context: the density as a float grid (its errors name the array) and the
/// scene's fields.
std::unique_ptr<nimbus::RenderContext> MakeRenderContext(const nimbus::SceneDescription& scene,
  vtkImageData* volume, vtkDataArray* values, const std::string& arrayName,
  const std::string& sceneFileName, double budgetMiB)
{
  nimbus::DensityGrid grid;
  try
  {
    grid = nimbus::DensityGridFromImage(volume, values);
  }
  catch (const std::invalid_argument& error)
  {
    throw std::invalid_argument("density array '" + arrayName + "': " + error.what());
  }
  return std::make_unique<nimbus::RenderContext>(
    scene, std::move(grid), SceneFieldsOf(scene, sceneFileName, budgetMiB));
}

/// The warning when a pilot forecasts more time to the target image error than the time
/// limit (or over an hour without one), else empty.
std::string PilotForecast(const std::string& sceneFileName,
  const nimbus::PathTracingEstimate& estimate, double target, double limit)
{
  if ((limit > 0.0 && estimate.SecondsToTarget > limit) ||
    (limit == 0.0 && estimate.SecondsToTarget > 3600.0))
  {
    std::ostringstream message;
    message.precision(2);
    message << sceneFileName << ": a pilot (" << estimate.PilotPixels << " pixels x "
            << estimate.PilotSamplesPerPixel << " samples, " << estimate.PilotSeconds
            << " s) forecasts about " << FormatDuration(estimate.SecondsToTarget)
            << " to reach an image error of " << 100.0 * target << " %";
    if (limit > 0.0)
    {
      const double reachable = target * std::sqrt(estimate.SecondsToTarget / std::max(limit, 1e-9));
      message << "; the time limit of " << FormatDuration(limit)
              << " will end the render first, at about " << 100.0 * reachable << " %";
    }
    return message.str();
  }
  return std::string();
}
} // namespace

int vtkNimbusReferenceRenderer::Render(vtkInformationVector** inputVector, vtkImageData* output)
{
  const nimbus::SceneDescription& scene = *this->Internals->Scene;
  const double budget = this->MemoryBudgetMiB > 0.0
    ? this->MemoryBudgetMiB * 1048576.0
    : static_cast<double>(nimbus::DefaultMemoryBudgetBytes());
  const double pixels =
    static_cast<double>(scene.Camera.Width) * static_cast<double>(scene.Camera.Height);
  // The output arrays (radiance and, for path tracing, its standard error: 3
  // floats per pixel each), before the density is even made.
  const double outputBytes = pixels * 3.0 * sizeof(float) * (this->Mode == PATH_TRACING ? 2 : 1);
  std::string overBudget = nimbus::OverBudgetMessage("the rendered image (" +
      std::to_string(scene.Camera.Width) + "x" + std::to_string(scene.Camera.Height) + " pixels)",
    outputBytes, budget);
  if (!overBudget.empty())
  {
    vtkErrorMacro(<< this->SceneFileName << ": " << overBudget
                  << " (set MemoryBudgetMiB to allow more)");
    return 0;
  }

  // The density: the connected image, or the scene's own.
  vtkSmartPointer<vtkImageData> volume = vtkImageData::GetData(inputVector[0], 0);
  std::string arrayName = this->DensityArrayName;
  if (!volume)
  {
    std::string densityErrors;
    volume = SceneDensity(this->SceneFileName, budget / 1048576.0, densityErrors);
    arrayName = "density";
    if (volume->GetNumberOfPoints() == 0)
    {
      vtkErrorMacro(<< "no density volume: "
                    << (densityErrors.empty() ? std::string("(no reason given)") : densityErrors));
      return 0;
    }
  }
  vtkDataArray* values = volume->GetPointData()->GetArray(arrayName.c_str());
  if (!values || values->GetNumberOfComponents() != 1)
  {
    vtkErrorMacro(<< "The density input has no one-component point array '" << arrayName << "'.");
    return 0;
  }
  const std::string directionProblem = DirectionMatrixProblem(volume);
  if (!directionProblem.empty())
  {
    vtkErrorMacro(<< directionProblem << ".");
    return 0;
  }
  // The float copy of the density for the renderers.
  overBudget = nimbus::OverBudgetMessage("the density grid (" +
      std::to_string(values->GetNumberOfTuples()) + " floats) and the rendered image",
    static_cast<double>(values->GetNumberOfTuples()) * sizeof(float) + outputBytes, budget);
  if (!overBudget.empty())
  {
    vtkErrorMacro(<< overBudget << " (set MemoryBudgetMiB to allow more)");
    return 0;
  }

  const std::unique_ptr<nimbus::RenderContext> context =
    MakeRenderContext(scene, volume, values, arrayName, this->SceneFileName, budget / 1048576.0);
  const double renderBudget =
    budget - static_cast<double>(values->GetNumberOfTuples()) * sizeof(float) - outputBytes;

  // Progress comes from worker threads too; only the calling thread reports it and
  // looks for an abort (which stops the render after the pixels being worked on).
  const std::thread::id caller = std::this_thread::get_id();
  auto progress = [this, caller](double fraction)
  {
    if (std::this_thread::get_id() == caller)
    {
      this->UpdateProgress(std::min(1.0, std::max(0.0, fraction)));
      if (this->CheckAbort())
      {
        throw RenderAborted();
      }
    }
  };

  nimbus::FloatImage radiance, standardError;
  double estimatedError = 0.0, seconds = 0.0, samplesPerPixel = 0.0;
  double stoppedAtTimeLimit = 0.0, reachedImageTarget = 0.0;
  if (this->Mode == SINGLE_SCATTERING)
  {
    nimbus::SingleScatteringSettings settings;
    settings.StepScale = this->StepScale;
    settings.RelativeTolerance = this->RelativeTolerance;
    settings.MaxRefinements = this->MaxRefinements;
    settings.Threads = this->NumberOfThreads;
    settings.MemoryBudgetBytes = std::max(1.0, renderBudget);
    nimbus::SingleScatteringResult result =
      nimbus::RenderSingleScattering(*context, settings, progress);
    radiance = std::move(result.Image);
    estimatedError = result.EstimatedRelativeError;
    seconds = result.Seconds;
  }
  else
  {
    nimbus::PathTracingSettings settings;
    settings.MinSamplesPerPixel = this->MinSamplesPerPixel;
    settings.MaxSamplesPerPixel = this->MaxSamplesPerPixel;
    settings.TargetRelativeError = this->TargetRelativeError;
    settings.MaxScatteringOrder = this->MaxScatteringOrder;
    settings.Seed = static_cast<std::uint64_t>(static_cast<std::uint32_t>(this->Seed));
    settings.Threads = this->NumberOfThreads;
    settings.MemoryBudgetBytes = std::max(1.0, renderBudget);
    settings.TimeLimitSeconds = this->TimeLimitSeconds;
    settings.TargetImageRelativeError = this->TargetImageRelativeError;
    settings.LightTracing = this->LightTracing;
    settings.LightPathsPerBatch = static_cast<std::uint64_t>(this->LightPathsPerBatch);
    this->CurrentImageRelativeError = 0.0;
    this->CurrentSamplesPerPixel = 0.0;
    this->EstimatedSecondsToTarget = 0.0;
    if (this->TargetImageRelativeError > 0.0 && !this->LightTracing)
    {
      // Before the render, a pilot's forecast of the time to the target; said when it
      // is over the time limit (or over an hour without one).
      const nimbus::PathTracingEstimate estimate =
        nimbus::EstimatePathTracingTime(*context, settings, this->TargetImageRelativeError);
      this->EstimatedSecondsToTarget = estimate.SecondsToTarget;
      const std::string forecast = PilotForecast(
        this->SceneFileName, estimate, this->TargetImageRelativeError, this->TimeLimitSeconds);
      if (!forecast.empty())
      {
        vtkWarningMacro(<< forecast << ".");
      }
    }
    settings.OnRound = [this](const nimbus::PathTracingRound& round)
    {
      this->CurrentImageRelativeError = round.ImageRelativeError;
      this->CurrentSamplesPerPixel = round.MeanSamplesPerPixel;
    };
    nimbus::PathTracingResult result = nimbus::RenderPathTraced(*context, settings, progress);
    stoppedAtTimeLimit = result.StoppedAtTimeLimit ? 1.0 : 0.0;
    reachedImageTarget = result.ReachedImageTarget ? 1.0 : 0.0;
    radiance = std::move(result.Image);
    standardError = std::move(result.StandardError);
    samplesPerPixel = result.MeanSamplesPerPixel;
    seconds = result.Seconds;
    // Image-wide relative error: RMS standard error over RMS radiance.
    estimatedError = result.ImageRelativeError;
  }

  // Never a silent NaN or infinity: a scene the reader accepts should not make
  // one, so one is a bug to report, not a picture to show.
  // (The renderers check too; this guards any future one.)
  const std::string nonFinite = nimbus::NonFiniteMessage(radiance);
  if (!nonFinite.empty())
  {
    vtkErrorMacro(<< this->SceneFileName << ": the render has " << nonFinite
                  << "; no image is output.");
    return 0;
  }

  output->SetExtent(0, radiance.Width - 1, 0, radiance.Height - 1, 0, 0);
  output->GetPointData()->SetScalars(ToArray(radiance, "radiance"));
  if (!standardError.Pixels.empty())
  {
    output->GetPointData()->AddArray(ToArray(standardError, "standard_error"));
  }
  vtkFieldData* fieldData = output->GetFieldData();
  AddFieldValue(fieldData, "EstimatedRelativeError", estimatedError);
  AddFieldValue(fieldData, "RenderSeconds", seconds);
  AddFieldValue(fieldData, "SamplesPerPixel", samplesPerPixel);
  if (this->Mode == PATH_TRACING)
  {
    AddFieldValue(fieldData, "StoppedAtTimeLimit", stoppedAtTimeLimit);
    AddFieldValue(fieldData, "ReachedImageTarget", reachedImageTarget);
    AddFieldValue(fieldData, "EstimatedSecondsToTarget", this->EstimatedSecondsToTarget);
  }
  this->UpdateProgress(1.0);
  return 1;
}

std::string vtkNimbusReferenceRenderer::GetCanonicalSceneJson()
{
  try
  {
    return nimbus::SceneToJson(nimbus::LoadScene(this->SceneFileName));
  }
  catch (const std::exception& error)
  {
    vtkErrorMacro(<< error.what());
    return std::string();
  }
}

void vtkNimbusReferenceRenderer::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "SceneFileName: " << this->SceneFileName << "\n";
  os << indent << "DensityArrayName: " << this->DensityArrayName << "\n";
  os << indent << "Mode: " << (this->Mode == SINGLE_SCATTERING ? "SingleScattering" : "PathTracing")
     << "\n";
  os << indent << "StepScale: " << this->StepScale << "\n";
  os << indent << "RelativeTolerance: " << this->RelativeTolerance << "\n";
  os << indent << "MaxRefinements: " << this->MaxRefinements << "\n";
  os << indent << "MinSamplesPerPixel: " << this->MinSamplesPerPixel << "\n";
  os << indent << "MaxSamplesPerPixel: " << this->MaxSamplesPerPixel << "\n";
  os << indent << "TargetRelativeError: " << this->TargetRelativeError << "\n";
  os << indent << "TimeLimitSeconds: " << this->TimeLimitSeconds << "\n";
  os << indent << "TargetImageRelativeError: " << this->TargetImageRelativeError << "\n";
  os << indent << "EstimatedSecondsToTarget: " << this->EstimatedSecondsToTarget << "\n";
  os << indent << "LightTracing: " << this->LightTracing << "\n";
  os << indent << "LightPathsPerBatch: " << this->LightPathsPerBatch << "\n";
  os << indent << "MaxScatteringOrder: " << this->MaxScatteringOrder << "\n";
  os << indent << "Seed: " << this->Seed << "\n";
  os << indent << "NumberOfThreads: " << this->NumberOfThreads << "\n";
  os << indent << "MemoryBudgetMiB: " << this->MemoryBudgetMiB << "\n";
}
