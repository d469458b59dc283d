#include "vtkNimbusSmokeSource.h"

#include "SmokeSolver.h"
#include "Voxelize.h"

#include "vtkCellArray.h"
#include "vtkCellData.h"
#include "vtkCleanPolyData.h"
#include "vtkDataArray.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPolyData.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include "vtkTriangleFilter.h"
#include "vtkUnsignedCharArray.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>
#include <stdexcept>
#include <vector>

vtkStandardNewMacro(vtkNimbusSmokeSource);

namespace
{
struct SmokeState
{
  double Time = 0.0;
  std::vector<float> Density, Temperature, U, V, W;
  std::vector<double> Pressure; // the pressure solve's first guess
};
} // namespace

struct vtkNimbusSmokeSource::vtkInternals
{
  std::vector<double> Key; // what the states depend on
  std::map<int, SmokeState> Checkpoints;
  std::unique_ptr<nimbus::SmokeSolver> Solver;
  int SolverFrame = -1; // the frame the solver holds
  int LastFrame = -1;
  int LastSubsteps = 0;

  void Reset()
  {
    this->Checkpoints.clear();
    this->Solver.reset();
    this->SolverFrame = -1;
  }
};

vtkNimbusSmokeSource::vtkNimbusSmokeSource()
  : Internals(new vtkInternals)
{
  this->SetNumberOfInputPorts(1);
  this->SetNumberOfOutputPorts(1);
}

vtkNimbusSmokeSource::~vtkNimbusSmokeSource() = default;

int vtkNimbusSmokeSource::FillInputPortInformation(int, vtkInformation* info)
{
  info->Remove(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE());
  info->Append(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkImageData");
  info->Append(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkPolyData");
  info->Set(vtkAlgorithm::INPUT_IS_OPTIONAL(), 1);
  return 1;
}

int vtkNimbusSmokeSource::RequestInformation(
  vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  const int n[3] = { std::clamp(this->Dimensions[0], 1, 1024),
    std::clamp(this->Dimensions[1], 1, 1024), std::clamp(this->Dimensions[2], 1, 1024) };
  const int extent[6] = { 0, n[0] - 1, 0, n[1] - 1, 0, n[2] - 1 };
  outInfo->Set(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), extent, 6);
  const double h =
    std::isfinite(this->CellSizeMetres) && this->CellSizeMetres > 0.0 ? this->CellSizeMetres : 1.0;
  const double spacing[3] = { h, h, h };
  const double origin[3] = { this->Origin[0] + 0.5 * h, this->Origin[1] + 0.5 * h,
    this->Origin[2] + 0.5 * h };
  outInfo->Set(vtkDataObject::SPACING(), spacing, 3);
  outInfo->Set(vtkDataObject::ORIGIN(), origin, 3);
  outInfo->Remove(vtkStreamingDemandDrivenPipeline::TIME_STEPS());
  outInfo->Remove(vtkStreamingDemandDrivenPipeline::TIME_RANGE());
  if (std::isfinite(this->FrameDurationSeconds) && this->FrameDurationSeconds > 0.0)
  {
    std::vector<double> times(this->NumberOfFrames + 1);
    for (int f = 0; f <= this->NumberOfFrames; ++f)
    {
      times[f] = f * this->FrameDurationSeconds;
    }
    outInfo->Set(
      vtkStreamingDemandDrivenPipeline::TIME_STEPS(), times.data(), static_cast<int>(times.size()));
    const double range[2] = { 0.0, times.back() };
    outInfo->Set(vtkStreamingDemandDrivenPipeline::TIME_RANGE(), range, 2);
  }
  return 1;
}

int vtkNimbusSmokeSource::RequestUpdateExtent(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector*)
{
  // The obstacles are steady: the input is asked for no time.
  if (vtkInformation* inInfo = inputVector[0]->GetInformationObject(0))
  {
    inInfo->Remove(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP());
    if (inInfo->Has(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT()))
    {
      inInfo->Set(vtkStreamingDemandDrivenPipeline::UPDATE_EXTENT(),
        inInfo->Get(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT()), 6);
    }
  }
  return 1;
}

int vtkNimbusSmokeSource::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkImageData* output = vtkImageData::GetData(outputVector, 0);
  output->Initialize();
  vtkInternals& in = *this->Internals;

  nimbus::SmokeParameters p;
  for (int k = 0; k < 3; ++k)
  {
    p.Dimensions[k] = this->Dimensions[k];
    p.Origin[k] = this->Origin[k];
    p.Wind[k] = this->Wind[k];
  }
  p.CellSizeMetres = this->CellSizeMetres;
  p.AmbientTemperatureKelvin = this->AmbientTemperatureKelvin;
  p.WindCoupling = this->WindCoupling;
  p.CoolingPerSecond = this->CoolingPerSecond;
  p.DissipationPerSecond = this->DissipationPerSecond;
  p.VorticityConfinement = this->VorticityConfinement;
  p.SmagorinskyConstant = this->SmagorinskyConstant;
  p.Advection = this->Advection == 0 ? nimbus::SmokeAdvection::SemiLagrangian
                                     : nimbus::SmokeAdvection::MacCormack;
  p.Threads = this->NumberOfThreads;
  nimbus::SmokeEmitter emitter;
  for (int k = 0; k < 3; ++k)
  {
    emitter.Centre[k] = this->EmitterCentre[k];
    emitter.Velocity[k] = this->EmitterVelocity[k];
  }
  emitter.RadiusMetres = this->EmitterRadiusMetres;
  emitter.DensityPerSecond = this->EmitterDensityPerSecond;
  emitter.TemperatureKelvin = this->EmitterTemperatureKelvin;
  p.Emitters = { emitter };
  if (!(this->FrameDurationSeconds > 0.0) || !std::isfinite(this->FrameDurationSeconds) ||
    this->FrameDurationSeconds > 1e4)
  {
    vtkErrorMacro("Smoke: FrameDurationSeconds must be in (0, 1e4] seconds; no output.");
    in.Reset();
    return 1;
  }

  // The obstacles: one value per cell, as point data on the cells' grid or cell data on
  // the grid one larger; or a closed surface, voxelised (a cell is solid when its centre
  // is inside).
  vtkImageData* obstacleImage = vtkImageData::GetData(inputVector[0], 0);
  vtkPolyData* obstacleSurface = vtkPolyData::GetData(inputVector[0], 0);
  vtkMTimeType obstacleTime = 0;
  if (obstacleImage)
  {
    vtkDataArray* mask = obstacleImage->GetPointData()->GetArray("obstacle");
    bool cells = false;
    if (!mask)
    {
      mask = obstacleImage->GetCellData()->GetArray("obstacle");
      cells = true;
    }
    int dims[3];
    obstacleImage->GetDimensions(dims);
    bool fits = mask != nullptr;
    for (int k = 0; fits && k < 3; ++k)
    {
      fits = (cells ? std::max(dims[k] - 1, 1) : dims[k]) == this->Dimensions[k];
    }
    if (!fits)
    {
      vtkErrorMacro("Smoke: the obstacle input needs a point array \"obstacle\" with one value "
                    "per simulation cell ("
        << this->Dimensions[0] << " x " << this->Dimensions[1] << " x " << this->Dimensions[2]
        << " points, or cell data on one more point per axis); no output.");
      in.Reset();
      return 1;
    }
    p.Obstacles.resize(static_cast<std::size_t>(mask->GetNumberOfTuples()));
    for (vtkIdType i = 0; i < mask->GetNumberOfTuples(); ++i)
    {
      const double v = mask->GetComponent(i, 0);
      p.Obstacles[i] = (std::isfinite(v) && v != 0.0) ? 1 : 0;
    }
    obstacleTime = std::max(mask->GetMTime(), obstacleImage->GetMTime());
  }
  else if (obstacleSurface)
  {
    // Coincident points merged (closedness is read from shared points), polygons and
    // strips as triangles; lines and vertices bound no volume.
    vtkNew<vtkCleanPolyData> merged;
    merged->SetInputData(obstacleSurface);
    merged->PointMergingOn();
    merged->ConvertLinesToPointsOff();
    merged->ConvertPolysToLinesOff();
    merged->ConvertStripsToPolysOff();
    vtkNew<vtkTriangleFilter> triangles;
    triangles->SetInputConnection(merged->GetOutputPort());
    triangles->PassVertsOff();
    triangles->PassLinesOff();
    triangles->Update();
    vtkPolyData* surface = triangles->GetOutput();
    std::vector<nimbus::Vector3> points(static_cast<std::size_t>(surface->GetNumberOfPoints()));
    for (vtkIdType i = 0; i < surface->GetNumberOfPoints(); ++i)
    {
      surface->GetPoint(i, points[static_cast<std::size_t>(i)].data());
    }
    std::vector<std::array<std::int64_t, 3>> faces;
    faces.reserve(static_cast<std::size_t>(surface->GetNumberOfPolys()));
    vtkCellArray* polys = surface->GetPolys();
    vtkIdType count = 0;
    const vtkIdType* ids = nullptr;
    for (polys->InitTraversal(); polys->GetNextCell(count, ids);)
    {
      if (count == 3)
      {
        faces.push_back({ { ids[0], ids[1], ids[2] } });
      }
    }
    std::string problem;
    if (faces.empty() ||
      !nimbus::VoxelizeClosedSurface(
        points, faces, p.Dimensions, p.Origin, this->CellSizeMetres, p.Obstacles, problem))
    {
      vtkErrorMacro("Smoke: the obstacle surface can not be voxelised: "
        << (faces.empty() ? std::string("it has no polygons") : problem)
        << " (it must be a closed surface, in metres); no output.");
      in.Reset();
      return 1;
    }
    obstacleTime = obstacleSurface->GetMTime();
  }
  const std::string why = nimbus::CheckSmokeParameters(p);
  if (!why.empty())
  {
    vtkErrorMacro("Smoke: " << why << "; no output.");
    in.Reset();
    return 1;
  }

  // The states depend on everything above but the threads and the number of frames.
  std::vector<double> key = { static_cast<double>(p.Dimensions[0]),
    static_cast<double>(p.Dimensions[1]), static_cast<double>(p.Dimensions[2]), p.CellSizeMetres,
    p.Origin[0], p.Origin[1], p.Origin[2], p.Wind[0], p.Wind[1], p.Wind[2],
    p.AmbientTemperatureKelvin, p.WindCoupling, p.CoolingPerSecond, p.DissipationPerSecond,
    p.VorticityConfinement, p.SmagorinskyConstant, static_cast<double>(this->Advection),
    emitter.Centre[0], emitter.Centre[1], emitter.Centre[2], emitter.Velocity[0],
    emitter.Velocity[1], emitter.Velocity[2], emitter.RadiusMetres, emitter.DensityPerSecond,
    emitter.TemperatureKelvin, this->FrameDurationSeconds,
    static_cast<double>(this->CheckpointInterval),
    obstacleImage ? 1.0 : (obstacleSurface ? 2.0 : 0.0), static_cast<double>(obstacleTime) };
  if (key != in.Key)
  {
    in.Reset();
    in.Key = key;
  }

  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  double time = 0.0;
  if (outInfo->Has(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP()))
  {
    time = outInfo->Get(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP());
  }
  const int frame =
    std::clamp(static_cast<int>(std::floor(time / this->FrameDurationSeconds + 1e-9)), 0,
      this->NumberOfFrames);

  try
  {
    if (!in.Solver)
    {
      in.Solver.reset(new nimbus::SmokeSolver(p));
      in.SolverFrame = 0;
    }
    if (in.SolverFrame > frame)
    {
      // Back to the last checkpoint at or before the frame (frame 0: the initial state).
      auto checkpoint = in.Checkpoints.upper_bound(frame);
      if (checkpoint != in.Checkpoints.begin())
      {
        --checkpoint;
        const SmokeState& s = checkpoint->second;
        in.Solver->SetState(s.Time, s.Density, s.Temperature, s.U, s.V, s.W);
        in.Solver->SetPressureGuess(s.Pressure);
        in.SolverFrame = checkpoint->first;
      }
      else
      {
        in.Solver.reset(new nimbus::SmokeSolver(p));
        in.SolverFrame = 0;
      }
    }
    else
    {
      // Forward: from the solver, or from a later checkpoint if there is one.
      auto checkpoint = in.Checkpoints.upper_bound(frame);
      if (checkpoint != in.Checkpoints.begin())
      {
        --checkpoint;
        if (checkpoint->first > in.SolverFrame)
        {
          const SmokeState& s = checkpoint->second;
          in.Solver->SetState(s.Time, s.Density, s.Temperature, s.U, s.V, s.W);
          in.Solver->SetPressureGuess(s.Pressure);
          in.SolverFrame = checkpoint->first;
        }
      }
    }
    const int first = in.SolverFrame;
    in.LastSubsteps = 0;
    while (in.SolverFrame < frame)
    {
      const nimbus::SmokeStepReport report = in.Solver->Step(this->FrameDurationSeconds);
      in.LastSubsteps += report.Substeps;
      ++in.SolverFrame;
      if (in.SolverFrame % this->CheckpointInterval == 0)
      {
        SmokeState& s = in.Checkpoints[in.SolverFrame];
        s.Time = in.Solver->GetTime();
        s.Density = in.Solver->GetDensity();
        s.Temperature = in.Solver->GetTemperature();
        s.U = in.Solver->GetU();
        s.V = in.Solver->GetV();
        s.W = in.Solver->GetW();
        s.Pressure = in.Solver->GetPressureGuess();
      }
      this->UpdateProgress(static_cast<double>(in.SolverFrame - first) / (frame - first));
      if (this->CheckAbort())
      {
        output->Initialize();
        return 1;
      }
    }
  }
  catch (const std::exception& problem)
  {
    vtkErrorMacro("Smoke: " << problem.what() << "; no output.");
    in.Reset();
    return 1;
  }
  in.LastFrame = frame;

  const nimbus::SmokeSolver& solver = *in.Solver;
  const double h = p.CellSizeMetres;
  output->SetExtent(0, p.Dimensions[0] - 1, 0, p.Dimensions[1] - 1, 0, p.Dimensions[2] - 1);
  output->SetSpacing(h, h, h);
  output->SetOrigin(p.Origin[0] + 0.5 * h, p.Origin[1] + 0.5 * h, p.Origin[2] + 0.5 * h);
  const vtkIdType cells = static_cast<vtkIdType>(solver.NumberOfCells());
  vtkNew<vtkFloatArray> density, temperature, velocity;
  density->SetName("density");
  temperature->SetName("temperature");
  velocity->SetName("velocity");
  velocity->SetNumberOfComponents(3);
  density->SetNumberOfTuples(cells);
  temperature->SetNumberOfTuples(cells);
  velocity->SetNumberOfTuples(cells);
  std::copy(solver.GetDensity().begin(), solver.GetDensity().end(), density->GetPointer(0));
  std::copy(
    solver.GetTemperature().begin(), solver.GetTemperature().end(), temperature->GetPointer(0));
  const std::vector<float> v = solver.CellVelocities();
  std::copy(v.begin(), v.end(), velocity->GetPointer(0));
  output->GetPointData()->SetScalars(density);
  output->GetPointData()->AddArray(temperature);
  output->GetPointData()->AddArray(velocity);
  if (!p.Obstacles.empty())
  {
    // Where the solid cells are (1), to show them (a contour at 0.5, or a threshold).
    vtkNew<vtkUnsignedCharArray> obstacle;
    obstacle->SetName("obstacle");
    obstacle->SetNumberOfTuples(cells);
    std::copy(p.Obstacles.begin(), p.Obstacles.end(), obstacle->GetPointer(0));
    output->GetPointData()->AddArray(obstacle);
  }
  output->GetInformation()->Set(
    vtkDataObject::DATA_TIME_STEP(), frame * this->FrameDurationSeconds);
  return 1;
}

int vtkNimbusSmokeSource::GetLastFrame() const
{
  return this->Internals->LastFrame;
}

int vtkNimbusSmokeSource::GetLastSubsteps() const
{
  return this->Internals->LastSubsteps;
}

void vtkNimbusSmokeSource::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Dimensions: " << this->Dimensions[0] << " x " << this->Dimensions[1] << " x "
     << this->Dimensions[2] << "\n";
  os << indent << "CellSizeMetres: " << this->CellSizeMetres << "\n";
  os << indent << "Origin: " << this->Origin[0] << ", " << this->Origin[1] << ", "
     << this->Origin[2] << " m\n";
  os << indent << "Emitter: centre " << this->EmitterCentre[0] << ", " << this->EmitterCentre[1]
     << ", " << this->EmitterCentre[2] << " m, radius " << this->EmitterRadiusMetres << " m, "
     << this->EmitterDensityPerSecond << " /s, " << this->EmitterTemperatureKelvin
     << " K, velocity " << this->EmitterVelocity[0] << ", " << this->EmitterVelocity[1] << ", "
     << this->EmitterVelocity[2] << " m/s\n";
  os << indent << "AmbientTemperatureKelvin: " << this->AmbientTemperatureKelvin << "\n";
  os << indent << "Wind: " << this->Wind[0] << ", " << this->Wind[1] << ", " << this->Wind[2]
     << " m/s (coupling " << this->WindCoupling << " /s)\n";
  os << indent << "CoolingPerSecond: " << this->CoolingPerSecond << "\n";
  os << indent << "DissipationPerSecond: " << this->DissipationPerSecond << "\n";
  os << indent << "VorticityConfinement: " << this->VorticityConfinement << "\n";
  os << indent << "SmagorinskyConstant: " << this->SmagorinskyConstant << "\n";
  os << indent << "Advection: " << (this->Advection ? "MacCormack" : "semi-Lagrangian") << "\n";
  os << indent << "FrameDurationSeconds: " << this->FrameDurationSeconds << "\n";
  os << indent << "NumberOfFrames: " << this->NumberOfFrames << "\n";
  os << indent << "CheckpointInterval: " << this->CheckpointInterval << "\n";
  os << indent << "NumberOfThreads: " << this->NumberOfThreads << "\n";
}
