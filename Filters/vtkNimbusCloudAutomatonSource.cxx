#include "vtkNimbusCloudAutomatonSource.h"

#include "CloudAutomaton.h"

#include "vtkDataArray.h"
#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkStreamingDemandDrivenPipeline.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <map>
#include <stdexcept>
#include <vector>

vtkStandardNewMacro(vtkNimbusCloudAutomatonSource);

struct vtkNimbusCloudAutomatonSource::vtkInternals
{
  // What the cache below was computed for: the source's and the input's MTime.
  bool Valid = false;
  vtkMTimeType SourceTime = 0;
  vtkMTimeType InputTime = 0;

  nimbus::CloudSmoothingParameters Smoothing;
  std::unique_ptr<nimbus::CloudAutomaton> Automaton;
  std::map<std::int64_t, nimbus::CloudAutomatonState> Checkpoints;
  std::map<std::int64_t, std::vector<float>> Densities; // smoothed cld of recent steps

  void Clear()
  {
    this->Valid = false;
    this->Automaton.reset();
    this->Checkpoints.clear();
    this->Densities.clear();
  }
};

namespace
{
constexpr int MaximumCachedDensities = 4;

bool AllFinite(const double* values, int count)
{
  for (int i = 0; i < count; ++i)
  {
    if (!std::isfinite(values[i]))
    {
      return false;
    }
  }
  return true;
}

// Point spacing of the grid covering the bounds (one point: the whole length, or 1).
double AxisSpacing(int points, double low, double high)
{
  if (points > 1)
  {
    return (high - low) / (points - 1);
  }
  return high > low ? high - low : 1.0;
}
}

vtkNimbusCloudAutomatonSource::vtkNimbusCloudAutomatonSource()
  : Internals(new vtkInternals)
{
  this->SetNumberOfInputPorts(1);
  this->SetNumberOfOutputPorts(1);
  this->Dimensions[0] = 128;
  this->Dimensions[1] = 128;
  this->Dimensions[2] = 32;
  const double bounds[6] = { -6400.0, 6400.0, -6400.0, 6400.0, 1000.0, 2600.0 };
  std::copy(bounds, bounds + 6, this->Bounds);
  this->Seed = 1;
  this->ExtinctionProbability = 0.05;
  this->HumidityProbability = 0.002;
  this->ActivationProbability = 0.0002;
  this->InitialHumidity = 0.3;
  this->InitialActivation = 0.001;
  this->Wind[0] = this->Wind[1] = 0.0;
  this->Shear[0] = this->Shear[1] = 0.0;
  this->PeriodicBoundary = true;
  this->StepDuration = 1.0;
  this->NumberOfTimeSteps = 100;
  this->SmoothingRadius = 2.5;
  this->InterpolateInTime = true;
  this->NumberOfThreads = 0;
  this->CheckpointInterval = 10;
  this->MaximumNumberOfCheckpoints = 16;
  this->NumberOfStepsComputed = 0;
}

vtkNimbusCloudAutomatonSource::~vtkNimbusCloudAutomatonSource() = default;

int vtkNimbusCloudAutomatonSource::FillInputPortInformation(int, vtkInformation* info)
{
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkImageData");
  info->Set(vtkAlgorithm::INPUT_IS_OPTIONAL(), 1);
  return 1;
}

int vtkNimbusCloudAutomatonSource::RequestInformation(
  vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  int extent[6] = { 0, -1, 0, -1, 0, -1 };
  double origin[3] = { 0.0, 0.0, 0.0 };
  double spacing[3] = { 1.0, 1.0, 1.0 };
  const int* d = this->Dimensions;
  if (d[0] >= 1 && d[1] >= 1 && d[2] >= 1 && AllFinite(this->Bounds, 6))
  {
    for (int a = 0; a < 3; ++a)
    {
      extent[2 * a + 1] = d[a] - 1;
      spacing[a] = AxisSpacing(d[a], this->Bounds[2 * a], this->Bounds[2 * a + 1]);
      origin[a] =
        d[a] > 1 ? this->Bounds[2 * a] : 0.5 * (this->Bounds[2 * a] + this->Bounds[2 * a + 1]);
    }
  }
  outInfo->Set(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), extent, 6);
  outInfo->Set(vtkDataObject::ORIGIN(), origin, 3);
  outInfo->Set(vtkDataObject::SPACING(), spacing, 3);
  vtkDataObject::SetPointDataActiveScalarInfo(outInfo, VTK_FLOAT, 1);

  outInfo->Remove(vtkStreamingDemandDrivenPipeline::TIME_STEPS());
  outInfo->Remove(vtkStreamingDemandDrivenPipeline::TIME_RANGE());
  if (this->StepDuration > 0.0 && std::isfinite(this->StepDuration))
  {
    std::vector<double> times(static_cast<std::size_t>(this->NumberOfTimeSteps) + 1);
    for (std::size_t k = 0; k < times.size(); ++k)
    {
      times[k] = static_cast<double>(k) * this->StepDuration;
    }
    outInfo->Set(
      vtkStreamingDemandDrivenPipeline::TIME_STEPS(), times.data(), static_cast<int>(times.size()));
    const double range[2] = { 0.0, times.back() };
    outInfo->Set(vtkStreamingDemandDrivenPipeline::TIME_RANGE(), range, 2);
  }
  return 1;
}

int vtkNimbusCloudAutomatonSource::RequestUpdateExtent(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector*)
{
  // The probability image is used whole, and as a static field (no time request upstream).
  if (vtkInformation* inInfo = inputVector[0]->GetInformationObject(0))
  {
    int wholeExtent[6];
    inInfo->Get(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), wholeExtent);
    inInfo->Set(vtkStreamingDemandDrivenPipeline::UPDATE_EXTENT(), wholeExtent, 6);
    inInfo->Remove(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP());
  }
  return 1;
}

int vtkNimbusCloudAutomatonSource::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  vtkImageData* output = vtkImageData::GetData(outputVector, 0);
  output->Initialize();
  vtkImageData* input = inputVector[0]->GetNumberOfInformationObjects() > 0
    ? vtkImageData::GetData(inputVector[0], 0)
    : nullptr;
  auto& internals = *this->Internals;

  // --- parameters ---------------------------------------------------------------------------
  const int* d = this->Dimensions;
  if (d[0] < 1 || d[1] < 1 || d[2] < 1)
  {
    vtkErrorMacro(<< "Dimensions must be >= 1 along every axis, got (" << d[0] << ", " << d[1]
                  << ", " << d[2] << ").");
    return 1;
  }
  if (!AllFinite(this->Bounds, 6))
  {
    vtkErrorMacro(<< "Bounds must be finite numbers.");
    return 1;
  }
  for (int a = 0; a < 3; ++a)
  {
    if (!(this->Bounds[2 * a] < this->Bounds[2 * a + 1]))
    {
      vtkErrorMacro(<< "Bounds must satisfy min < max on every axis; axis " << a << " has ("
                    << this->Bounds[2 * a] << ", " << this->Bounds[2 * a + 1] << ").");
      return 1;
    }
  }
  if (!(this->StepDuration > 0.0) || !std::isfinite(this->StepDuration))
  {
    vtkErrorMacro(<< "StepDuration must be a finite number of seconds > 0, got "
                  << this->StepDuration << ".");
    return 1;
  }
  if (!AllFinite(this->Wind, 2) || !AllFinite(this->Shear, 2))
  {
    vtkErrorMacro(<< "Wind and Shear must be finite.");
    return 1;
  }

  const vtkMTimeType inputTime = input ? input->GetMTime() : 0;
  if (!internals.Valid || internals.SourceTime != this->GetMTime() ||
    internals.InputTime != inputTime)
  {
    internals.Clear();
    nimbus::CloudAutomatonParameters p;
    std::copy(d, d + 3, p.Dimensions);
    p.Seed = static_cast<std::uint64_t>(static_cast<std::uint32_t>(this->Seed));
    p.Extinction = nimbus::ProbabilityField::Uniform(this->ExtinctionProbability);
    p.HumiditySupply = nimbus::ProbabilityField::Uniform(this->HumidityProbability);
    p.ActivationSupply = nimbus::ProbabilityField::Uniform(this->ActivationProbability);
    p.InitialHumidity = this->InitialHumidity;
    p.InitialActivation = this->InitialActivation;
    // m/s -> cells per step; (m/s)/m -> cells per step per layer.
    const double dz = AxisSpacing(d[2], this->Bounds[4], this->Bounds[5]);
    for (int a = 0; a < 2; ++a)
    {
      const double spacing = AxisSpacing(d[a], this->Bounds[2 * a], this->Bounds[2 * a + 1]);
      p.Wind[a] = this->Wind[a] * this->StepDuration / spacing;
      p.Shear[a] = this->Shear[a] * dz * this->StepDuration / spacing;
    }
    p.Boundary =
      this->PeriodicBoundary ? nimbus::CloudBoundary::Periodic : nimbus::CloudBoundary::Open;
    p.NumberOfThreads = this->NumberOfThreads;

    if (input)
    {
      int inDims[3];
      input->GetDimensions(inDims);
      const char* names[3] = { "p_ext", "p_hum", "p_act" };
      nimbus::ProbabilityField* fields[3] = { &p.Extinction, &p.HumiditySupply,
        &p.ActivationSupply };
      for (int f = 0; f < 3; ++f)
      {
        vtkDataArray* array = input->GetPointData()->GetArray(names[f]);
        if (!array)
        {
          continue;
        }
        const bool volume = inDims[0] == d[0] && inDims[1] == d[1] && inDims[2] == d[2];
        const bool plane = inDims[0] == d[0] && inDims[1] == d[1] && inDims[2] == 1;
        if (!volume && !plane)
        {
          vtkErrorMacro(<< "The input probability image is " << inDims[0] << " x " << inDims[1]
                        << " x " << inDims[2] << " points; it must match Dimensions (" << d[0]
                        << " x " << d[1] << " x " << d[2] << ") or be a 2-D map of " << d[0]
                        << " x " << d[1] << " x 1.");
          return 1;
        }
        if (array->GetNumberOfComponents() != 1)
        {
          vtkErrorMacro(<< "Input array \"" << names[f] << "\" must have one component, it has "
                        << array->GetNumberOfComponents() << ".");
          return 1;
        }
        std::vector<float> values(static_cast<std::size_t>(array->GetNumberOfTuples()));
        for (vtkIdType i = 0; i < array->GetNumberOfTuples(); ++i)
        {
          values[i] = static_cast<float>(array->GetComponent(i, 0));
        }
        *fields[f] = volume ? nimbus::ProbabilityField::Volume(std::move(values))
                            : nimbus::ProbabilityField::Plane(std::move(values));
      }
    }
    try
    {
      internals.Automaton = std::make_unique<nimbus::CloudAutomaton>(p);
    }
    catch (const std::exception& error)
    {
      vtkErrorMacro(<< "Cannot set up the cloud automaton: " << error.what()
                    << " (input arrays p_ext, p_hum, p_act must hold probabilities in [0, 1]).");
      internals.Clear();
      return 1;
    }
    internals.Smoothing.Radius = this->SmoothingRadius;
    internals.Smoothing.NumberOfThreads = this->NumberOfThreads;
    internals.Valid = true;
    internals.SourceTime = this->GetMTime();
    internals.InputTime = inputTime;
    this->NumberOfStepsComputed = 0;
  }

  // --- which steps --------------------------------------------------------------------------
  double time = 0.0;
  if (outInfo->Has(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP()))
  {
    time = outInfo->Get(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP());
  }
  if (!std::isfinite(time))
  {
    time = 0.0;
  }
  const double lastStep = static_cast<double>(this->NumberOfTimeSteps);
  const double stepPosition = std::clamp(time / this->StepDuration, 0.0, lastStep);
  std::int64_t step = static_cast<std::int64_t>(std::floor(stepPosition));
  double fraction = stepPosition - static_cast<double>(step);
  // Times that are meant to be step k but land a rounding error below it.
  if (fraction > 1.0 - 1e-9)
  {
    ++step;
    fraction = 0.0;
  }
  if (!this->InterpolateInTime || fraction < 1e-9)
  {
    fraction = 0.0;
  }
  const std::int64_t lastNeeded = fraction > 0.0 ? step + 1 : step;

  // --- run the automaton from the nearest state at or before the first step needed -------------
  nimbus::CloudAutomaton& automaton = *internals.Automaton;
  auto needs = [&](std::int64_t s) { return internals.Densities.count(s) == 0; };
  std::int64_t firstMissing = -1;
  for (std::int64_t s = step; s <= lastNeeded; ++s)
  {
    if (needs(s))
    {
      firstMissing = s;
      break;
    }
  }
  if (firstMissing >= 0)
  {
    // Nearest checkpoint at or before firstMissing, unless the live state is nearer.
    auto checkpoint = internals.Checkpoints.upper_bound(firstMissing);
    const bool haveCheckpoint = checkpoint != internals.Checkpoints.begin();
    const std::int64_t checkpointStep = haveCheckpoint ? std::prev(checkpoint)->first : 0;
    if (automaton.GetStep() > firstMissing || automaton.GetStep() < checkpointStep)
    {
      if (haveCheckpoint)
      {
        automaton.SetState(std::prev(checkpoint)->second);
      }
      else
      {
        automaton.Reset();
      }
    }
    const std::int64_t start = automaton.GetStep();
    const double total = static_cast<double>(lastNeeded - start + 1);
    for (;;)
    {
      const std::int64_t s = automaton.GetStep();
      if (s % this->CheckpointInterval == 0 && s > 0 && this->MaximumNumberOfCheckpoints > 0 &&
        internals.Checkpoints.count(s) == 0)
      {
        internals.Checkpoints.emplace(s, automaton.GetState());
        // Over the limit: drop the checkpoint closest to its predecessor (keeps them spread).
        while (static_cast<int>(internals.Checkpoints.size()) > this->MaximumNumberOfCheckpoints)
        {
          auto victim = internals.Checkpoints.begin();
          std::int64_t smallestGap = victim->first;
          for (auto it = std::next(internals.Checkpoints.begin());
               it != internals.Checkpoints.end(); ++it)
          {
            const std::int64_t gap = it->first - std::prev(it)->first;
            if (gap < smallestGap)
            {
              smallestGap = gap;
              victim = it;
            }
          }
          internals.Checkpoints.erase(victim);
        }
      }
      if (s >= step && s <= lastNeeded && needs(s))
      {
        std::vector<float> density;
        nimbus::SmoothCloud(automaton, internals.Smoothing, density);
        internals.Densities[s] = std::move(density);
      }
      if (s >= lastNeeded)
      {
        break;
      }
      this->UpdateProgress(static_cast<double>(s - start + 1) / total);
      if (this->CheckAbort())
      {
        return 1;
      }
      automaton.Step();
      ++this->NumberOfStepsComputed;
    }
    // Keep only the densities nearest to the ones just used.
    while (static_cast<int>(internals.Densities.size()) > MaximumCachedDensities)
    {
      auto first = internals.Densities.begin();
      auto last = std::prev(internals.Densities.end());
      internals.Densities.erase((step - first->first) > (last->first - step) ? first : last);
    }
  }

  // --- output -----------------------------------------------------------------------------
  const std::vector<float>& a = internals.Densities.at(step);
  vtkNew<vtkFloatArray> density;
  density->SetName("density");
  density->SetNumberOfTuples(static_cast<vtkIdType>(a.size()));
  float* out = density->GetPointer(0);
  if (fraction > 0.0)
  {
    const std::vector<float>& b = internals.Densities.at(step + 1);
    const float t = static_cast<float>(fraction);
    for (std::size_t i = 0; i < a.size(); ++i)
    {
      out[i] = a[i] + t * (b[i] - a[i]); // same as nimbus::InterpolateDensity
    }
  }
  else
  {
    std::copy(a.begin(), a.end(), out);
  }

  int extent[6];
  double origin[3], spacing[3];
  outInfo->Get(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), extent);
  outInfo->Get(vtkDataObject::ORIGIN(), origin);
  outInfo->Get(vtkDataObject::SPACING(), spacing);
  output->SetExtent(extent);
  output->SetOrigin(origin);
  output->SetSpacing(spacing);
  output->GetPointData()->SetScalars(density);
  vtkNew<vtkDoubleArray> stepArray;
  stepArray->SetName("AutomatonStep");
  stepArray->InsertNextValue(static_cast<double>(step) + fraction);
  output->GetFieldData()->AddArray(stepArray);
  output->GetInformation()->Set(vtkDataObject::DATA_TIME_STEP(), time);
  this->UpdateProgress(1.0);
  return 1;
}

void vtkNimbusCloudAutomatonSource::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Dimensions: " << this->Dimensions[0] << " " << this->Dimensions[1] << " "
     << this->Dimensions[2] << "\n";
  os << indent << "Bounds:";
  for (double b : this->Bounds)
  {
    os << " " << b;
  }
  os << "\n";
  os << indent << "Seed: " << this->Seed << "\n";
  os << indent << "ExtinctionProbability: " << this->ExtinctionProbability << "\n";
  os << indent << "HumidityProbability: " << this->HumidityProbability << "\n";
  os << indent << "ActivationProbability: " << this->ActivationProbability << "\n";
  os << indent << "InitialHumidity: " << this->InitialHumidity << "\n";
  os << indent << "InitialActivation: " << this->InitialActivation << "\n";
  os << indent << "Wind: " << this->Wind[0] << " " << this->Wind[1] << "\n";
  os << indent << "Shear: " << this->Shear[0] << " " << this->Shear[1] << "\n";
  os << indent << "PeriodicBoundary: " << (this->PeriodicBoundary ? "On" : "Off") << "\n";
  os << indent << "StepDuration: " << this->StepDuration << "\n";
  os << indent << "NumberOfTimeSteps: " << this->NumberOfTimeSteps << "\n";
  os << indent << "SmoothingRadius: " << this->SmoothingRadius << "\n";
  os << indent << "InterpolateInTime: " << (this->InterpolateInTime ? "On" : "Off") << "\n";
  os << indent << "NumberOfThreads: " << this->NumberOfThreads << "\n";
  os << indent << "CheckpointInterval: " << this->CheckpointInterval << "\n";
  os << indent << "MaximumNumberOfCheckpoints: " << this->MaximumNumberOfCheckpoints << "\n";
  os << indent << "NumberOfStepsComputed: " << this->NumberOfStepsComputed << "\n";
}
