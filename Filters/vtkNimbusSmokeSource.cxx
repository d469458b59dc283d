#include "vtkNimbusSmokeSource.h"

#include "PieceExtent.h"
#include "SmokePuffs.h"
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
#include <array>
#include <cmath>
#include <cstdint>
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
  nimbus::PuffState Puffs;      // with puffs on
};

// Trilinear interpolation of a cell-centred field (n cells per axis, x fastest) at a point
// given in cell coordinates (cell c's centre at c + 1/2), clamped to the centres.
float SampleCells(
  const std::vector<float>& field, const std::array<int, 3>& n, double x, double y, double z)
{
  const double at[3] = { x - 0.5, y - 0.5, z - 0.5 };
  int i0[3];
  double f[3];
  for (int a = 0; a < 3; ++a)
  {
    const double c = std::clamp(at[a], 0.0, static_cast<double>(n[a] - 1));
    i0[a] = std::min(static_cast<int>(c), std::max(n[a] - 2, 0));
    f[a] = n[a] > 1 ? c - i0[a] : 0.0;
  }
  double value = 0.0;
  for (int corner = 0; corner < 8; ++corner)
  {
    int idx[3];
    double w = 1.0;
    for (int a = 0; a < 3; ++a)
    {
      const int step = (corner >> a) & 1;
      idx[a] = std::min(i0[a] + step, n[a] - 1);
      w *= step ? f[a] : 1.0 - f[a];
    }
    value += w * field[(static_cast<std::size_t>(idx[2]) * n[1] + idx[1]) * n[0] + idx[0]];
  }
  return static_cast<float>(value);
}

// The simulation's temperature, density ("grid_density") and velocity at the points r times
// finer per axis (trilinear), and the obstacles there (a fine point takes its cell's value).
void SampleOnFinerPoints(const nimbus::SmokeSolver& solver, const nimbus::SmokeParameters& p, int r,
  const std::array<int, 3>& dims, vtkFloatArray* temperature, vtkFloatArray* gridDensity,
  vtkFloatArray* velocity, std::vector<std::uint8_t>& obstacles)
{
  const vtkIdType points = static_cast<vtkIdType>(dims[0]) * dims[1] * dims[2];
  std::vector<std::uint8_t> fine(obstacles.empty() ? 0 : static_cast<std::size_t>(points));
  for (int k = 0; k < dims[2]; ++k)
    for (int j = 0; j < dims[1]; ++j)
      for (int i = 0; i < dims[0]; ++i)
      {
        const vtkIdType id = (static_cast<vtkIdType>(k) * dims[1] + j) * dims[0] + i;
        // In the simulation's cell coordinates (cell c spans [c, c + 1]).
        const double x = (i + 0.5) / r, y = (j + 0.5) / r, z = (k + 0.5) / r;
        temperature->SetValue(id, SampleCells(solver.GetTemperature(), p.Dimensions, x, y, z));
        gridDensity->SetValue(id, SampleCells(solver.GetDensity(), p.Dimensions, x, y, z));
        const nimbus::Vector3 at{ { p.Origin[0] + x * p.CellSizeMetres,
          p.Origin[1] + y * p.CellSizeMetres, p.Origin[2] + z * p.CellSizeMetres } };
        const nimbus::Vector3 v = solver.VelocityAt(at);
        velocity->SetTuple3(id, v[0], v[1], v[2]);
        if (!fine.empty())
        {
          fine[static_cast<std::size_t>(id)] = obstacles[solver.CellIndex(i / r, j / r, k / r)];
        }
      }
  obstacles.swap(fine);
}
} // namespace

struct vtkNimbusSmokeSource::vtkInternals
{
  std::vector<double> Key; // what the states depend on
  std::map<int, SmokeState> Checkpoints;
  std::unique_ptr<nimbus::SmokeSolver> Solver;
  std::unique_ptr<nimbus::SmokePuffs> Puffs; // with puffs on
  int SolverFrame = -1;                      // the frame the solver holds
  int LastFrame = -1;
  int LastSubsteps = 0;
  bool WarnedSubsteps = false; // said once per set of parameters

  void Reset()
  {
    this->Checkpoints.clear();
    this->Solver.reset();
    this->Puffs.reset();
    this->SolverFrame = -1;
  }

  // The solver's (and the puffs') state at SolverFrame, kept to go back to.
  void SaveCheckpoint()
  {
    SmokeState& s = this->Checkpoints[this->SolverFrame];
    s.Time = this->Solver->GetTime();
    s.Density = this->Solver->GetDensity();
    s.Temperature = this->Solver->GetTemperature();
    s.U = this->Solver->GetU();
    s.V = this->Solver->GetV();
    s.W = this->Solver->GetW();
    s.Pressure = this->Solver->GetPressureGuess();
    if (this->Puffs)
    {
      s.Puffs = this->Puffs->GetState();
    }
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
  // With puffs, PuffResolution points per cell and axis.
  const int r = this->Puffs ? this->PuffResolution : 1;
  const int n[3] = { r * std::clamp(this->Dimensions[0], 1, 1024),
    r * std::clamp(this->Dimensions[1], 1, 1024), r * std::clamp(this->Dimensions[2], 1, 1024) };
  const int extent[6] = { 0, n[0] - 1, 0, n[1] - 1, 0, n[2] - 1 };
  outInfo->Set(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), extent, 6);
  const double h =
    (std::isfinite(this->CellSizeMetres) && this->CellSizeMetres > 0.0 ? this->CellSizeMetres
                                                                       : 1.0) /
    r;
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
  // Pieces: the whole simulation runs, the requested extent is output (see RequestData).
  outInfo->Set(CAN_PRODUCE_SUB_EXTENT(), 1);
  return 1;
}

int vtkNimbusSmokeSource::RequestUpdateExtent(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector*)
{
  // The obstacles are steady: the input is asked for no time.
  if (vtkInformation* inInfo = inputVector[0]->GetInformationObject(0))
  {
    inInfo->Remove(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP());
    // Every piece simulates the whole domain: the whole obstacle input, without ghosts.
    nimbus::RequestWholeInput(inInfo);
    if (inInfo->Has(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT()))
    {
      inInfo->Set(vtkStreamingDemandDrivenPipeline::UPDATE_EXTENT(),
        inInfo->Get(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT()), 6);
    }
  }
  return 1;
}

// What one RequestData builds before it steps the solver: the solver's and the puffs'
// parameters, and where the obstacles came from (for the key the states depend on).
struct vtkNimbusSmokeSource::SmokeSetup
{
  nimbus::SmokeParameters Parameters;
  nimbus::SmokeEmitter Emitter;
  nimbus::PuffParameters PuffParameters;
  double ObstacleKind = 0.0; // 0: none, 1: an image, 2: a surface
  vtkMTimeType ObstacleTime = 0;
};

int vtkNimbusSmokeSource::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkImageData* output = vtkImageData::GetData(outputVector, 0);
  output->Initialize();
  vtkInternals& in = *this->Internals;
  this->WarnOnceAboutPieces(outputVector);

  SmokeSetup setup;
  this->FillSmokeParameters(setup);
  if (!(this->FrameDurationSeconds > 0.0) || !std::isfinite(this->FrameDurationSeconds) ||
    this->FrameDurationSeconds > 1e4)
  {
    vtkErrorMacro("Smoke: FrameDurationSeconds must be in (0, 1e4] seconds; no output.");
    in.Reset();
    return 1;
  }
  if (!this->ReadObstacles(inputVector[0], setup))
  {
    in.Reset();
    return 1;
  }
  const std::string why = nimbus::CheckSmokeParameters(setup.Parameters);
  if (!why.empty())
  {
    vtkErrorMacro("Smoke: " << why << "; no output.");
    in.Reset();
    return 1;
  }
  if (!this->FillPuffParameters(setup))
  {
    in.Reset();
    return 1;
  }
  this->ForgetStatesIfChanged(setup);

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
    this->MoveSolverToCheckpoint(setup, frame);
    if (!this->StepSolverTo(setup, frame))
    {
      output->Initialize(); // aborted
      return 1;
    }
  }
  catch (const std::exception& problem)
  {
    vtkErrorMacro("Smoke: " << problem.what() << "; no output.");
    in.Reset();
    return 1;
  }
  in.LastFrame = frame;

  this->FillOutput(setup, output);
  // Pieces: the pressure solve is global, so every piece runs the whole simulation
  // (redundantly: memory and time are not divided between ranks) and outputs its extent.
  nimbus::CropToRequestedExtent(output, outputVector->GetInformationObject(0));
  output->GetInformation()->Set(
    vtkDataObject::DATA_TIME_STEP(), frame * this->FrameDurationSeconds);
  return 1;
}

void vtkNimbusSmokeSource::WarnOnceAboutPieces(vtkInformationVector* outputVector)
{
  static bool warnedRanks = false; // once per process
  const int pieces = outputVector->GetInformationObject(0)->Get(
    vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_PIECES());
  if (pieces > 1 && !warnedRanks)
  {
    warnedRanks = true;
    vtkWarningMacro("Smoke on " << pieces
                                << " ranks (pieces): every rank simulates the whole "
                                   "domain (the pressure solve is global) and keeps its piece; "
                                   "more ranks make it neither faster nor smaller per rank.");
  }
}

void vtkNimbusSmokeSource::FillSmokeParameters(SmokeSetup& setup) const
{
  nimbus::SmokeParameters& p = setup.Parameters;
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
  p.SideBoundaries = this->SideBoundaries == 1 ? nimbus::SmokeSideBoundaries::Walls
    : this->SideBoundaries == 2                ? nimbus::SmokeSideBoundaries::Open
                                               : nimbus::SmokeSideBoundaries::Automatic;
  p.Threads = this->NumberOfThreads;
  nimbus::SmokeEmitter& emitter = setup.Emitter;
  for (int k = 0; k < 3; ++k)
  {
    emitter.Centre[k] = this->EmitterCentre[k];
    emitter.Velocity[k] = this->EmitterVelocity[k];
  }
  emitter.RadiusMetres = this->EmitterRadiusMetres;
  emitter.DensityPerSecond = this->EmitterDensityPerSecond;
  emitter.TemperatureKelvin = this->EmitterTemperatureKelvin;
  p.Emitters = { emitter };
}

bool vtkNimbusSmokeSource::ReadObstacles(vtkInformationVector* inputVector, SmokeSetup& setup)
{
  // The obstacles: one value per cell, as point data on the cells' grid or cell data on
  // the grid one larger; or a closed surface, voxelised (a cell is solid when its centre
  // is inside).
  vtkImageData* obstacleImage = vtkImageData::GetData(inputVector, 0);
  vtkPolyData* obstacleSurface = vtkPolyData::GetData(inputVector, 0);
  setup.ObstacleKind = obstacleImage ? 1.0 : (obstacleSurface ? 2.0 : 0.0);
  if (obstacleImage)
  {
    return this->ReadObstacleImage(obstacleImage, setup);
  }
  if (obstacleSurface)
  {
    return this->VoxelizeObstacleSurface(obstacleSurface, setup);
  }
  return true;
}

bool vtkNimbusSmokeSource::ReadObstacleImage(vtkImageData* obstacleImage, SmokeSetup& setup)
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
    return false;
  }
  std::vector<std::uint8_t>& obstacles = setup.Parameters.Obstacles;
  obstacles.resize(static_cast<std::size_t>(mask->GetNumberOfTuples()));
  for (vtkIdType i = 0; i < mask->GetNumberOfTuples(); ++i)
  {
    const double v = mask->GetComponent(i, 0);
    obstacles[i] = (std::isfinite(v) && v != 0.0) ? 1 : 0;
  }
  setup.ObstacleTime = std::max(mask->GetMTime(), obstacleImage->GetMTime());
  return true;
}

bool vtkNimbusSmokeSource::VoxelizeObstacleSurface(vtkPolyData* obstacleSurface, SmokeSetup& setup)
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
  nimbus::SmokeParameters& p = setup.Parameters;
  std::string problem;
  if (faces.empty() ||
    !nimbus::VoxelizeClosedSurface(
      points, faces, p.Dimensions, p.Origin, this->CellSizeMetres, p.Obstacles, problem))
  {
    vtkErrorMacro("Smoke: the obstacle surface can not be voxelised: "
      << (faces.empty() ? std::string("it has no polygons") : problem)
      << " (it must be a closed surface, in metres); no output.");
    return false;
  }
  setup.ObstacleTime = obstacleSurface->GetMTime();
  return true;
}

bool vtkNimbusSmokeSource::FillPuffParameters(SmokeSetup& setup)
{
  // Puffs: each carries the smoke of 1 / PuffsPerSecond seconds of the emitter's,
  // DensityPerSecond V_emitter / PuffsPerSecond [density m^3], as a metaball of
  // WyvillFalloffIntegral(R0) per unit peak density.
  nimbus::PuffParameters& pp = setup.PuffParameters;
  pp.PuffsPerSecond = this->PuffsPerSecond;
  pp.RadiusMetres = this->PuffRadiusMetres;
  pp.GrowthPerSecond = this->PuffGrowthPerSecond;
  pp.LifetimeSeconds = this->PuffLifetimeSeconds;
  pp.Threads = this->NumberOfThreads;
  if (!this->Puffs)
  {
    return true;
  }
  const double emitterVolume = 4.0 / 3.0 * M_PI * std::pow(this->EmitterRadiusMetres, 3.0); // m^3
  pp.DensityPerPuff = this->PuffsPerSecond > 0.0 && this->PuffRadiusMetres > 0.0
    ? this->EmitterDensityPerSecond * emitterVolume /
      (this->PuffsPerSecond * nimbus::WyvillFalloffIntegral(this->PuffRadiusMetres))
    : 0.0;
  const std::string puffWhy = nimbus::CheckPuffParameters(pp);
  if (!puffWhy.empty() || !std::isfinite(pp.DensityPerPuff))
  {
    vtkErrorMacro("Smoke: puffs: "
      << (puffWhy.empty() ? "the density per puff is not finite" : puffWhy) << "; no output.");
    return false;
  }
  return true;
}

void vtkNimbusSmokeSource::ForgetStatesIfChanged(const SmokeSetup& setup)
{
  const nimbus::SmokeParameters& p = setup.Parameters;
  const nimbus::SmokeEmitter& emitter = setup.Emitter;
  const nimbus::PuffParameters& pp = setup.PuffParameters;
  // The states depend on everything above but the threads and the number of frames.
  std::vector<double> key = { static_cast<double>(p.Dimensions[0]),
    static_cast<double>(p.Dimensions[1]), static_cast<double>(p.Dimensions[2]), p.CellSizeMetres,
    p.Origin[0], p.Origin[1], p.Origin[2], p.Wind[0], p.Wind[1], p.Wind[2],
    p.AmbientTemperatureKelvin, p.WindCoupling, p.CoolingPerSecond, p.DissipationPerSecond,
    p.VorticityConfinement, p.SmagorinskyConstant, static_cast<double>(this->Advection),
    static_cast<double>(p.SideBoundaries), emitter.Centre[0], emitter.Centre[1], emitter.Centre[2],
    emitter.Velocity[0], emitter.Velocity[1], emitter.Velocity[2], emitter.RadiusMetres,
    emitter.DensityPerSecond, emitter.TemperatureKelvin, this->FrameDurationSeconds,
    static_cast<double>(this->CheckpointInterval), setup.ObstacleKind,
    static_cast<double>(setup.ObstacleTime), this->Puffs ? 1.0 : 0.0, pp.PuffsPerSecond,
    pp.RadiusMetres, pp.GrowthPerSecond, pp.LifetimeSeconds };
  vtkInternals& in = *this->Internals;
  if (key != in.Key)
  {
    in.Reset();
    in.Key = key;
    in.WarnedSubsteps = false;
  }
}

void vtkNimbusSmokeSource::MoveSolverToCheckpoint(const SmokeSetup& setup, int frame)
{
  vtkInternals& in = *this->Internals;
  const auto restart = [&]()
  {
    in.Solver.reset(new nimbus::SmokeSolver(setup.Parameters));
    in.Puffs.reset(this->Puffs ? new nimbus::SmokePuffs(setup.PuffParameters) : nullptr);
    in.SolverFrame = 0;
  };
  const auto restore = [&](int checkpointFrame, const SmokeState& s)
  {
    in.Solver->SetState(s.Time, s.Density, s.Temperature, s.U, s.V, s.W);
    in.Solver->SetPressureGuess(s.Pressure);
    if (in.Puffs)
    {
      in.Puffs->SetState(s.Puffs);
    }
    in.SolverFrame = checkpointFrame;
  };
  if (!in.Solver)
  {
    restart();
  }
  if (in.SolverFrame > frame)
  {
    // Back to the last checkpoint at or before the frame (frame 0: the initial state).
    auto checkpoint = in.Checkpoints.upper_bound(frame);
    if (checkpoint != in.Checkpoints.begin())
    {
      --checkpoint;
      restore(checkpoint->first, checkpoint->second);
    }
    else
    {
      restart();
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
        restore(checkpoint->first, checkpoint->second);
      }
    }
  }
}

bool vtkNimbusSmokeSource::StepSolverTo(const SmokeSetup& setup, int frame)
{
  vtkInternals& in = *this->Internals;
  const int first = in.SolverFrame;
  in.LastSubsteps = 0;
  while (in.SolverFrame < frame)
  {
    const nimbus::SmokeStepReport report = in.Solver->Step(this->FrameDurationSeconds);
    in.LastSubsteps += report.Substeps;
    if (report.Substeps > 1 && !in.WarnedSubsteps)
    {
      // Said once per set of parameters: the frames stay stable, but cost more.
      in.WarnedSubsteps = true;
      vtkWarningMacro("Smoke: frame " << in.SolverFrame + 1 << " took " << report.Substeps
                                      << " sub-steps: the air moved more than "
                                      << setup.Parameters.MaxCfl << " cells in one frame (up to "
                                      << report.MaxSpeed
                                      << " m/s), so each frame is split "
                                         "to stay stable and costs that many times more. "
                                         "Shorter frames or larger cells avoid it.");
    }
    if (in.Puffs)
    {
      in.Puffs->Step(this->FrameDurationSeconds, *in.Solver);
    }
    ++in.SolverFrame;
    if (in.SolverFrame % this->CheckpointInterval == 0)
    {
      in.SaveCheckpoint();
    }
    this->UpdateProgress(static_cast<double>(in.SolverFrame - first) / (frame - first));
    if (this->CheckAbort())
    {
      return false;
    }
  }
  return true;
}

void vtkNimbusSmokeSource::FillOutput(const SmokeSetup& setup, vtkImageData* output)
{
  vtkInternals& in = *this->Internals;
  const nimbus::SmokeParameters& p = setup.Parameters;
  const nimbus::SmokeSolver& solver = *in.Solver;
  // Output points: the cells' centres, or with puffs PuffResolution per cell and axis.
  const int r = in.Puffs ? this->PuffResolution : 1;
  const double h = p.CellSizeMetres / r;
  const std::array<int, 3> dims{ { r * p.Dimensions[0], r * p.Dimensions[1],
    r * p.Dimensions[2] } };
  output->SetExtent(0, dims[0] - 1, 0, dims[1] - 1, 0, dims[2] - 1);
  output->SetSpacing(h, h, h);
  const nimbus::Vector3 first{ { p.Origin[0] + 0.5 * h, p.Origin[1] + 0.5 * h,
    p.Origin[2] + 0.5 * h } };
  output->SetOrigin(first.data());
  const vtkIdType points = static_cast<vtkIdType>(dims[0]) * dims[1] * dims[2];
  vtkNew<vtkFloatArray> density, temperature, velocity;
  density->SetName("density");
  temperature->SetName("temperature");
  velocity->SetName("velocity");
  velocity->SetNumberOfComponents(3);
  density->SetNumberOfTuples(points);
  temperature->SetNumberOfTuples(points);
  velocity->SetNumberOfTuples(points);
  std::vector<std::uint8_t> obstacles = p.Obstacles;
  if (r == 1)
  {
    std::copy(solver.GetDensity().begin(), solver.GetDensity().end(), density->GetPointer(0));
    std::copy(
      solver.GetTemperature().begin(), solver.GetTemperature().end(), temperature->GetPointer(0));
    const std::vector<float> v = solver.CellVelocities();
    std::copy(v.begin(), v.end(), velocity->GetPointer(0));
  }
  else
  {
    // The simulation's fields at the finer points (trilinear); its own density as
    // "grid_density" beside the puffs'.
    vtkNew<vtkFloatArray> gridDensity;
    gridDensity->SetName("grid_density");
    gridDensity->SetNumberOfTuples(points);
    SampleOnFinerPoints(solver, p, r, dims, temperature, gridDensity, velocity, obstacles);
    output->GetPointData()->AddArray(gridDensity);
  }
  if (in.Puffs)
  {
    const std::vector<float> splat = in.Puffs->Splat(dims, first, h, this->NumberOfThreads);
    std::copy(splat.begin(), splat.end(), density->GetPointer(0));
  }
  output->GetPointData()->SetScalars(density);
  output->GetPointData()->AddArray(temperature);
  output->GetPointData()->AddArray(velocity);
  if (!obstacles.empty())
  {
    // Where the solid cells are (1), to show them (a contour at 0.5, or a threshold).
    vtkNew<vtkUnsignedCharArray> obstacle;
    obstacle->SetName("obstacle");
    obstacle->SetNumberOfTuples(points);
    std::copy(obstacles.begin(), obstacles.end(), obstacle->GetPointer(0));
    output->GetPointData()->AddArray(obstacle);
  }
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
  os << indent << "SideBoundaries: "
     << (this->SideBoundaries == 1      ? "walls"
            : this->SideBoundaries == 2 ? "open"
                                        : "automatic (open with wind)")
     << "\n";
  os << indent << "FrameDurationSeconds: " << this->FrameDurationSeconds << "\n";
  os << indent << "NumberOfFrames: " << this->NumberOfFrames << "\n";
  os << indent << "CheckpointInterval: " << this->CheckpointInterval << "\n";
  os << indent << "NumberOfThreads: " << this->NumberOfThreads << "\n";
  os << indent << "Puffs: " << (this->Puffs ? "on" : "off") << " (" << this->PuffsPerSecond
     << " /s, radius " << this->PuffRadiusMetres << " m growing " << this->PuffGrowthPerSecond
     << " /s, lifetime " << this->PuffLifetimeSeconds << " s, resolution " << this->PuffResolution
     << ")\n";
}
