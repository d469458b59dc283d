#include "vtkNimbusCloudAutomatonSource.h"

#include "CloudAutomaton.h"
#include "FiniteSetters.h"
#include "GridParameters.h"
#include "MemoryBudget.h"
#include "PieceExtent.h"

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
#include "vtkSmartPointer.h"
#include "vtkStreamingDemandDrivenPipeline.h"

#if VTK_MODULE_ENABLE_VTK_ParallelCore
#include "vtkCommunicator.h"
#include "vtkMultiProcessController.h"
#endif

#include <algorithm>
#include <cmath>
#include <iterator>
#include <map>
#include <new>
#include <sstream>
#include <stdexcept>
#include <string>
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
  int DensityBox[6] = { 0, -1, 0, -1, 0, -1 };          // the cells Densities cover

  // A distributed run (see the class description): this rank, the ranks, the layers it owns
  // and holds. Ranks 1 and the whole grid otherwise.
  bool Distributed = false;
  int Rank = 0, Ranks = 1;
  int Owned[2] = { 0, 0 }, Held[2] = { 0, 0 };
#if VTK_MODULE_ENABLE_VTK_ParallelCore
  vtkCommunicator* Communicator = nullptr;
#endif

  // Whether the ranks share the automaton for this request (one piece per rank), this rank's
  // layers, and the cells its densities cover (DensityBox); clears what no longer fits.
  void ChooseRanks(vtkNimbusCloudAutomatonSource* self, vtkInformation* outInfo,
    const int extent[6], bool anyPoint);
  // The memory budget's message when this rank's share (its held layers, its densities'
  // cells) would not fit; empty when it fits.
  std::string OverBudget(
    vtkNimbusCloudAutomatonSource* self, bool withInput, double cellCount) const;
  // Keeps a copy of the automaton's state at step s when it is a checkpoint step.
  void KeepCheckpoint(std::int64_t s, int interval, int maximum);
  // The smoothed cld of the automaton's current step over DensityBox (the piece's rows
  // gathered first when distributed). Returns the bytes of rows received.
  std::uint64_t Smooth(std::vector<float>& density, int ny);
  // After a step: the halo exchange when distributed. Returns the bytes sent.
  std::uint64_t AfterStep();
  // The density array of `extent` from the cached densities of `step` and `step + 1`.
  vtkSmartPointer<vtkFloatArray> Crop(
    std::int64_t step, double fraction, const int extent[6], bool anyPoint) const;

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
// Valid ranges (see the class documentation).
constexpr double MaximumLength = 1.0e8;        // m
constexpr double MinimumStepDuration = 1.0e-6; // s (ParaView's time steps stay distinct)
constexpr double MaximumStepDuration = 1.0e9;  // s (about 32 years)
constexpr double MaximumCellsPerStep = 1.0e6;  // wind shift of one layer, cells per step
constexpr double MaximumWork = 1.0e11;         // cell updates of one request (minutes)
constexpr double StepOverhead = 65536.0;       // fixed cost of a step, in cell updates
constexpr double MiB = 1048576.0;

std::string Number(double value)
{
  std::ostringstream text;
  text.precision(3);
  text << value;
  return text.str();
}

bool ValidStepDuration(double seconds)
{
  return seconds >= MinimumStepDuration && seconds <= MaximumStepDuration;
}

using nimbus::AllFinite;

// Point spacing of the grid covering the bounds (one point: the whole length, or 1).
double AxisSpacing(int points, double low, double high)
{
  if (points > 1)
  {
    return (high - low) / (points - 1);
  }
  return high > low ? high - low : 1.0;
}

#if VTK_MODULE_ENABLE_VTK_ParallelCore
constexpr int HaloTag = 93017;
using Field = nimbus::CloudAutomaton::Field;
constexpr Field Fields[3] = { Field::Hum, Field::Act, Field::Cld };

/// After a step: the owned layers next to each neighbour go to it (2 up, 1 down), the halo
/// layers come from it. Even ranks send first, odd ranks receive first, so blocking sends
/// never wait on each other. Returns the bytes this rank sent.
std::uint64_t ExchangeHalo(vtkCommunicator* communicator, nimbus::CloudAutomaton& automaton,
  int rank, int ranks, const int owned[2], const int held[2])
{
  const std::size_t layerWords = static_cast<std::size_t>(automaton.GetParameters().Dimensions[1]) *
    static_cast<std::size_t>(automaton.WordsPerRow());
  std::vector<std::uint64_t> buffer;
  std::uint64_t sent = 0;
  auto pack = [&](int z0, int z1)
  {
    buffer.clear();
    for (const Field f : Fields)
    {
      for (int z = z0; z < z1; ++z)
      {
        const std::uint64_t* layer = automaton.Layer(f, z);
        buffer.insert(buffer.end(), layer, layer + layerWords);
      }
    }
  };
  auto unpack = [&](int z0, int z1)
  {
    std::size_t at = 0;
    for (const Field f : Fields)
    {
      for (int z = z0; z < z1; ++z, at += layerWords)
      {
        std::copy_n(buffer.data() + at, layerWords, automaton.Layer(f, z));
      }
    }
  };
  auto send = [&](int to, int z0, int z1)
  {
    pack(z0, z1);
    communicator->Send(reinterpret_cast<const unsigned long*>(buffer.data()),
      static_cast<vtkIdType>(buffer.size()), to, HaloTag);
    sent += 8 * buffer.size();
  };
  auto receive = [&](int from, int z0, int z1)
  {
    buffer.resize(3 * layerWords * static_cast<std::size_t>(z1 - z0));
    communicator->Receive(reinterpret_cast<unsigned long*>(buffer.data()),
      static_cast<vtkIdType>(buffer.size()), from, HaloTag);
    unpack(z0, z1);
  };
  const bool even = rank % 2 == 0;
  const bool up = rank + 1 < ranks, down = rank > 0;
  // Upward: my top owned layers become the halo below the next rank's slab.
  for (int phase = 0; phase < 2; ++phase)
  {
    if ((phase == 0) == even && up)
    {
      send(rank + 1, owned[1] - nimbus::CloudHaloBelow, owned[1]);
    }
    if ((phase == 0) != even && down)
    {
      receive(rank - 1, held[0], owned[0]);
    }
  }
  // Downward: my bottom owned layer becomes the halo above the previous rank's slab.
  for (int phase = 0; phase < 2; ++phase)
  {
    if ((phase == 0) == even && down)
    {
      send(rank - 1, owned[0], owned[0] + nimbus::CloudHaloAbove);
    }
    if ((phase == 0) != even && up)
    {
      receive(rank + 1, owned[1], held[1]);
    }
  }
  return sent;
}

/// The rows (y) within `halo` of a box's [y0, y1], in the grid (wrapped when periodic),
/// distinct and ascending; none for an empty box.
std::vector<int> RowsAround(const int box[6], int halo, int ny, bool periodic)
{
  std::vector<int> rows;
  if (box[0] > box[1] || box[2] > box[3] || box[4] > box[5])
  {
    return rows;
  }
  std::vector<char> used(static_cast<std::size_t>(ny), 0);
  for (int y = box[2] - halo; y <= box[3] + halo; ++y)
  {
    if (y >= 0 && y < ny)
    {
      used[y] = 1;
    }
    else if (periodic)
    {
      used[((y % ny) + ny) % ny] = 1;
    }
  }
  for (int y = 0; y < ny; ++y)
  {
    if (used[y])
    {
      rows.push_back(y);
    }
  }
  return rows;
}

/// The cld rows every rank needs for its box (its piece's cells, `halo` around in y and z),
/// scattered by the ranks that own their layers (one ScatterV per rank). `table` receives,
/// for each (y, z - zLow) of this rank's box, the row's words (nullptr where not needed).
/// Returns the bytes received.
std::uint64_t GatherRows(vtkCommunicator* communicator, nimbus::CloudAutomaton& automaton, int rank,
  int ranks, const int box[6], int halo, std::vector<std::uint64_t>& storage,
  std::vector<const std::uint64_t*>& table, int& zLow)
{
  const auto& p = automaton.GetParameters();
  const int ny = p.Dimensions[1], nz = p.Dimensions[2];
  const bool periodic = p.Boundary == nimbus::CloudBoundary::Periodic;
  const std::size_t W = static_cast<std::size_t>(automaton.WordsPerRow());
  std::vector<int> boxes(static_cast<std::size_t>(6 * ranks));
  communicator->AllGather(box, boxes.data(), 6);
  // Layers [lo, hi] of rank r's box within the grid; rows of its box.
  std::vector<std::vector<int>> rows(static_cast<std::size_t>(ranks));
  std::vector<int> lo(static_cast<std::size_t>(ranks)), hi(static_cast<std::size_t>(ranks));
  for (int r = 0; r < ranks; ++r)
  {
    const int* b = boxes.data() + 6 * r;
    rows[r] = RowsAround(b, halo, ny, periodic);
    lo[r] = std::max(0, b[4] - halo);
    hi[r] = rows[r].empty() ? lo[r] - 1 : std::min(nz - 1, b[5] + halo);
  }
  zLow = lo[rank];
  const int layers = std::max(0, hi[rank] - lo[rank] + 1);
  table.assign(static_cast<std::size_t>(ny) * layers, nullptr);
  storage.assign(rows[rank].size() * static_cast<std::size_t>(layers) * W, 0);
  std::size_t received = 0;
  std::vector<std::uint64_t> sendBuffer;
  std::vector<vtkIdType> lengths(static_cast<std::size_t>(ranks)),
    offsets(static_cast<std::size_t>(ranks));
  for (int root = 0; root < ranks; ++root)
  {
    int owned[2], held[2];
    nimbus::DistributedLayers(nz, root, ranks, owned, held);
    // What `root` sends rank r: rows[r] of its owned layers within r's box, z then y.
    auto range = [&](int r, int& z0, int& z1)
    {
      z0 = std::max(owned[0], lo[r]);
      z1 = std::min(owned[1] - 1, hi[r]);
    };
    if (rank == root)
    {
      sendBuffer.clear();
      for (int r = 0; r < ranks; ++r)
      {
        int z0, z1;
        range(r, z0, z1);
        offsets[r] = static_cast<vtkIdType>(sendBuffer.size());
        for (int z = z0; z <= z1; ++z)
        {
          const std::uint64_t* layer = automaton.Layer(Field::Cld, z);
          for (const int y : rows[r])
          {
            sendBuffer.insert(sendBuffer.end(), layer + y * W, layer + (y + 1) * W);
          }
        }
        lengths[r] = static_cast<vtkIdType>(sendBuffer.size()) - offsets[r];
      }
    }
    int z0, z1;
    range(rank, z0, z1);
    const std::size_t count = z1 >= z0 ? (z1 - z0 + 1) * rows[rank].size() * W : 0;
    std::uint64_t* target = storage.data() + received;
    communicator->ScatterV(reinterpret_cast<const unsigned long*>(sendBuffer.data()),
      reinterpret_cast<unsigned long*>(target), lengths.data(), offsets.data(),
      static_cast<vtkIdType>(count), root);
    for (int z = z0; z <= z1; ++z)
    {
      for (const int y : rows[rank])
      {
        table[static_cast<std::size_t>(z - zLow) * ny + y] = target;
        target += W;
      }
    }
    received += count;
  }
  return 8 * received;
}
#endif
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
  // Defaults that give separate cumulus drifting downwind at time 0 (formation regions, a
  // spin-up, wind and shear), after Dobashi et al. 2000.
  this->ExtinctionProbability = 0.06;
  this->HumidityProbability = 0.1;
  this->ActivationProbability = 0.005;
  this->InitialHumidity = 0.0;
  this->InitialActivation = 0.0;
  this->Wind[0] = 4.0;
  this->Wind[1] = 0.0;
  this->Shear[0] = 0.002;
  this->Shear[1] = 0.0;
  this->NumberOfFormationRegions = 10;
  this->FormationRegionRadiusRange[0] = 400.0;
  this->FormationRegionRadiusRange[1] = 700.0;
  this->SpinUpSteps = 40;
  this->PeriodicBoundary = false;
  this->StepDuration = 10.0;
  this->NumberOfTimeSteps = 100;
  this->SmoothingRadius = 2.5;
  this->InterpolateInTime = true;
  this->NumberOfThreads = 0;
  this->CheckpointInterval = 10;
  this->MaximumNumberOfCheckpoints = 16;
  this->NumberOfStepsComputed = 0;
  this->MemoryBudgetMiB = nimbus::DefaultMemoryBudgetMiB();
  this->MemoryBudgetRangeMiB[0] = 1.0;
  this->MemoryBudgetRangeMiB[1] = this->MemoryBudgetMiB;
}

vtkNimbusCloudAutomatonSource::~vtkNimbusCloudAutomatonSource() = default;

nimbusDefineFiniteSetter(vtkNimbusCloudAutomatonSource, ExtinctionProbability)

  nimbusDefineFiniteSetter(vtkNimbusCloudAutomatonSource, HumidityProbability)

    nimbusDefineFiniteSetter(vtkNimbusCloudAutomatonSource, ActivationProbability)

      nimbusDefineFiniteSetter(vtkNimbusCloudAutomatonSource, InitialHumidity)

        nimbusDefineFiniteSetter(vtkNimbusCloudAutomatonSource, InitialActivation)

          nimbusDefineFiniteSetter(vtkNimbusCloudAutomatonSource, SmoothingRadius)

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
  // Pieces: the whole grid is computed, the requested extent output (see Generate).
  outInfo->Set(CAN_PRODUCE_SUB_EXTENT(), 1);

  outInfo->Remove(vtkStreamingDemandDrivenPipeline::TIME_STEPS());
  outInfo->Remove(vtkStreamingDemandDrivenPipeline::TIME_RANGE());
  if (ValidStepDuration(this->StepDuration))
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
    nimbus::RequestWholeInput(inInfo); // every piece uses the whole input
    inInfo->Remove(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP());
  }
  return 1;
}

bool vtkNimbusCloudAutomatonSource::CheckParameters()
{
  const std::string gridProblem = nimbus::CheckGridParameters(
    this->MemoryBudgetMiB, this->Dimensions, this->Bounds, MaximumLength);
  if (!gridProblem.empty())
  {
    vtkErrorMacro(<< gridProblem);
    return false;
  }
  const int* d = this->Dimensions;
  if (!ValidStepDuration(this->StepDuration))
  {
    vtkErrorMacro(<< "StepDuration must be between " << MinimumStepDuration << " and "
                  << MaximumStepDuration << " seconds, got " << this->StepDuration << ".");
    return false;
  }
  const struct
  {
    const char* Name;
    double Value;
  } probabilities[] = { { "ExtinctionProbability", this->ExtinctionProbability },
    { "HumidityProbability", this->HumidityProbability },
    { "ActivationProbability", this->ActivationProbability },
    { "InitialHumidity", this->InitialHumidity },
    { "InitialActivation", this->InitialActivation } };
  for (const auto& probability : probabilities)
  {
    if (!(probability.Value >= 0.0 && probability.Value <= 1.0))
    {
      vtkErrorMacro(<< probability.Name << " must be a probability in [0, 1], got "
                    << probability.Value << ".");
      return false;
    }
  }
  if (!(this->SmoothingRadius >= 0.0 && this->SmoothingRadius <= 16.0))
  {
    vtkErrorMacro(<< "SmoothingRadius must be in [0, 16] cells, got " << this->SmoothingRadius
                  << ".");
    return false;
  }
  if (this->NumberOfFormationRegions > 0 &&
    !(AllFinite(this->FormationRegionRadiusRange, 2) && this->FormationRegionRadiusRange[0] > 0.0 &&
      this->FormationRegionRadiusRange[1] > 0.0 &&
      this->FormationRegionRadiusRange[0] <= MaximumLength &&
      this->FormationRegionRadiusRange[1] <= MaximumLength))
  {
    vtkErrorMacro(<< "FormationRegionRadiusRange must be two finite lengths in (0, "
                  << MaximumLength << "] m, got (" << this->FormationRegionRadiusRange[0] << ", "
                  << this->FormationRegionRadiusRange[1] << ").");
    return false;
  }
  if (!AllFinite(this->Wind, 2) || !AllFinite(this->Shear, 2))
  {
    vtkErrorMacro(<< "Wind and Shear must be finite.");
    return false;
  }
  // m/s -> cells per step; the top layer moves fastest.
  const double dz = AxisSpacing(d[2], this->Bounds[4], this->Bounds[5]);
  for (int a = 0; a < 2; ++a)
  {
    const double spacing = AxisSpacing(d[a], this->Bounds[2 * a], this->Bounds[2 * a + 1]);
    const double bottom = std::abs(this->Wind[a]) * this->StepDuration / spacing;
    const double top =
      bottom + std::abs(this->Shear[a]) * dz * (d[2] - 1) * this->StepDuration / spacing;
    if (!(top <= MaximumCellsPerStep))
    {
      vtkErrorMacro(<< "Wind " << this->Wind[a] << " m/s and Shear " << this->Shear[a]
                    << " (m/s)/m along " << (a == 0 ? "x" : "y") << " move the clouds "
                    << Number(top) << " cells per step (StepDuration " << this->StepDuration
                    << " s, cells of " << spacing << " m), more than the limit of "
                    << Number(MaximumCellsPerStep) << ".");
      return false;
    }
  }
  return true;
}

int vtkNimbusCloudAutomatonSource::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkImageData* output = vtkImageData::GetData(outputVector, 0);
  output->Initialize();
  if (!this->CheckParameters())
  {
    this->Internals->Clear();
    return 1;
  }
  try
  {
    return this->Generate(inputVector, outputVector);
  }
  catch (const std::bad_alloc&)
  {
    vtkErrorMacro(<< "Out of memory while running the cloud automaton; lower Dimensions or "
                     "MaximumNumberOfCheckpoints, or MemoryBudgetMiB.");
  }
  catch (const std::length_error& error)
  {
    vtkErrorMacro(<< "The cloud automaton is too large (" << error.what()
                  << "); lower Dimensions.");
  }
  catch (const std::exception& error)
  {
    vtkErrorMacro(<< "Cannot run the cloud automaton: " << error.what());
  }
  this->Internals->Clear();
  output->Initialize();
  return 1;
}

void vtkNimbusCloudAutomatonSource::vtkInternals::ChooseRanks(
  vtkNimbusCloudAutomatonSource* self, vtkInformation* outInfo, const int extent[6], bool anyPoint)
{
  const int* d = self->Dimensions;
  bool distributed = false;
  int rank = 0, ranks = 1;
#if VTK_MODULE_ENABLE_VTK_ParallelCore
  vtkMultiProcessController* controller = vtkMultiProcessController::GetGlobalController();
  this->Communicator = controller ? controller->GetCommunicator() : nullptr;
  if (this->Communicator && controller->GetNumberOfProcesses() > 1)
  {
    using SDDP = vtkStreamingDemandDrivenPipeline;
    const int pieces = outInfo->Has(SDDP::UPDATE_NUMBER_OF_PIECES())
      ? outInfo->Get(SDDP::UPDATE_NUMBER_OF_PIECES())
      : 1;
    const int piece =
      outInfo->Has(SDDP::UPDATE_PIECE_NUMBER()) ? outInfo->Get(SDDP::UPDATE_PIECE_NUMBER()) : 0;
    ranks = controller->GetNumberOfProcesses();
    rank = controller->GetLocalProcessId();
    // Every rank asks for its own piece (pvbatch, pvserver): they step together.
    distributed = pieces == ranks && piece == rank && d[2] >= 2 * ranks;
  }
#else
  (void)outInfo;
#endif
  if (!distributed)
  {
    rank = 0;
    ranks = 1;
  }
  if (distributed != this->Distributed || rank != this->Rank || ranks != this->Ranks)
  {
    this->Clear();
    this->Distributed = distributed;
    this->Rank = rank;
    this->Ranks = ranks;
  }
  if (distributed)
  {
    nimbus::DistributedLayers(d[2], rank, ranks, this->Owned, this->Held);
  }
  else
  {
    this->Owned[0] = this->Held[0] = 0;
    this->Owned[1] = this->Held[1] = d[2];
  }
  std::copy(this->Owned, this->Owned + 2, self->OwnedLayers);
  // The cells the densities are smoothed on: the piece when distributed, else the whole grid.
  int box[6] = { 0, d[0] - 1, 0, d[1] - 1, 0, d[2] - 1 };
  if (distributed)
  {
    std::copy(extent, extent + 6, box);
    if (!anyPoint)
    {
      box[1] = box[3] = box[5] = -1;
      box[0] = box[2] = box[4] = 0;
    }
  }
  if (!std::equal(box, box + 6, this->DensityBox))
  {
    this->Densities.clear();
    std::copy(box, box + 6, this->DensityBox);
  }
}

std::string vtkNimbusCloudAutomatonSource::vtkInternals::OverBudget(
  vtkNimbusCloudAutomatonSource* self, bool withInput, double cellCount) const
{
  const int* d = self->Dimensions;
  const int* densityBox = this->DensityBox;
  // This rank's share: its held layers, and the cells of its densities.
  const double heldLayers = static_cast<double>(this->Held[1] - this->Held[0]);
  // The formation regions' probabilities are kept for the owned layers only.
  const double ownedCells = cellCount / d[2] * (this->Owned[1] - this->Owned[0]);
  double densityCells = 1.0;
  for (int a = 0; a < 3; ++a)
  {
    densityCells *= std::max(0, densityBox[2 * a + 1] - densityBox[2 * a] + 1);
  }
  // One state: three bit fields, rows padded to 64-bit words.
  const double stateBytes = 3.0 * 8.0 * std::ceil(d[0] / 64.0) * d[1] * heldLayers;
  const double lastStep =
    static_cast<double>(self->NumberOfTimeSteps) + static_cast<double>(self->SpinUpSteps);
  const double checkpoints = std::min(static_cast<double>(self->MaximumNumberOfCheckpoints),
    std::floor(lastStep / self->CheckpointInterval));
  // Floats per cell: the cached densities (up to 2 more while a request runs), the
  // smoothing's two buffers and the output array; 8 bytes per cell per input map.
  const double bytes = stateBytes * (2.0 + checkpoints) +
    4.0 * densityCells * (MaximumCachedDensities + 2 + 2 + 1) +
    (withInput ? 24.0 * cellCount : 0.0) +
    (self->NumberOfFormationRegions > 0 ? 12.0 * ownedCells : 0.0);
  std::ostringstream what;
  what << "the cloud automaton (" << d[0] << " x " << d[1] << " x " << d[2] << " cells, "
       << checkpoints << " checkpoints)";
  return nimbus::OverBudgetMessage(what.str(), bytes, self->MemoryBudgetMiB * MiB);
}

void vtkNimbusCloudAutomatonSource::vtkInternals::KeepCheckpoint(
  std::int64_t s, int interval, int maximum)
{
  if (s % interval != 0 || s <= 0 || maximum <= 0 || this->Checkpoints.count(s) != 0)
  {
    return;
  }
  this->Checkpoints.emplace(s, this->Automaton->GetState());
  // Over the limit: drop the checkpoint closest to its predecessor (keeps them spread).
  while (static_cast<int>(this->Checkpoints.size()) > maximum)
  {
    auto victim = this->Checkpoints.begin();
    std::int64_t smallestGap = victim->first;
    for (auto it = std::next(this->Checkpoints.begin()); it != this->Checkpoints.end(); ++it)
    {
      const std::int64_t gap = it->first - std::prev(it)->first;
      if (gap < smallestGap)
      {
        smallestGap = gap;
        victim = it;
      }
    }
    this->Checkpoints.erase(victim);
  }
}

std::uint64_t vtkNimbusCloudAutomatonSource::vtkInternals::Smooth(
  std::vector<float>& density, int ny)
{
  if (!this->Distributed)
  {
    nimbus::SmoothCloud(*this->Automaton, this->Smoothing, density);
    return 0;
  }
  std::uint64_t received = 0;
#if VTK_MODULE_ENABLE_VTK_ParallelCore
  // The cld rows around the piece, from the ranks that own them; then the piece's share of
  // SmoothCloud, bit for bit.
  std::vector<std::uint64_t> storage;
  std::vector<const std::uint64_t*> table;
  int zLow = 0;
  received = GatherRows(this->Communicator, *this->Automaton, this->Rank, this->Ranks,
    this->DensityBox, nimbus::SmoothingHalo(this->Smoothing), storage, table, zLow);
  const int* box = this->DensityBox;
  if (box[0] <= box[1] && box[2] <= box[3] && box[4] <= box[5])
  {
    nimbus::SmoothCloudBox(
      this->Automaton->GetParameters(), this->Smoothing, box,
      [&](int y, int z) { return table[static_cast<std::size_t>(z - zLow) * ny + y]; }, density);
  }
#else
  (void)ny;
#endif
  return received;
}

std::uint64_t vtkNimbusCloudAutomatonSource::vtkInternals::AfterStep()
{
#if VTK_MODULE_ENABLE_VTK_ParallelCore
  if (this->Distributed)
  {
    return ExchangeHalo(
      this->Communicator, *this->Automaton, this->Rank, this->Ranks, this->Owned, this->Held);
  }
#endif
  return 0;
}

vtkSmartPointer<vtkFloatArray> vtkNimbusCloudAutomatonSource::vtkInternals::Crop(
  std::int64_t step, double fraction, const int extent[6], bool anyPoint) const
{
  const std::vector<float>& a = this->Densities.at(step);
  const std::vector<float>* b = fraction > 0.0 ? &this->Densities.at(step + 1) : nullptr;
  const std::size_t rowLength = anyPoint ? static_cast<std::size_t>(extent[1] - extent[0] + 1) : 0;
  const std::size_t points =
    anyPoint ? rowLength * (extent[3] - extent[2] + 1) * (extent[5] - extent[4] + 1) : 0;
  auto density = vtkSmartPointer<vtkFloatArray>::New();
  density->SetName("density");
  density->SetNumberOfTuples(static_cast<vtkIdType>(points));
  float* out = density->GetPointer(0);
  const float t = static_cast<float>(fraction);
  // The densities cover DensityBox (the whole grid, or this rank's piece).
  const int* box = this->DensityBox;
  for (int k = extent[4]; anyPoint && k <= extent[5]; ++k)
  {
    for (int j = extent[2]; j <= extent[3]; ++j)
    {
      const std::size_t first =
        (static_cast<std::size_t>(k - box[4]) * (box[3] - box[2] + 1) + (j - box[2])) *
          (box[1] - box[0] + 1) +
        (extent[0] - box[0]);
      for (std::size_t i = 0; i < rowLength; ++i, ++out)
      {
        const float va = a[first + i];
        // Same as nimbus::InterpolateDensity.
        *out = b ? va + t * ((*b)[first + i] - va) : va;
      }
    }
  }
  return density;
}

bool vtkNimbusCloudAutomatonSource::SetUpAutomaton(vtkImageData* input, const int held[2])
{
  auto& internals = *this->Internals;
  const int* d = this->Dimensions;
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
  p.Layers[0] = held[0];
  p.Layers[1] = held[1];
  // The automaton steps the owned layers only (the others are the halo, replaced after every
  // step): probabilities per owned layer (the whole grid unless distributed).
  const int* owned = internals.Owned;
  p.Owned[0] = owned[0];
  p.Owned[1] = owned[1];
  const std::size_t plane = static_cast<std::size_t>(d[0]) * d[1];
  const std::size_t first = plane * owned[0], last = plane * owned[1];
  if (this->NumberOfFormationRegions > 0)
  {
    // Regions in cells: the radii (metres) over the horizontal spacing, vertical semi-axes
    // half the horizontal ones, centres at 30 % of the height.
    const double sx = AxisSpacing(d[0], this->Bounds[0], this->Bounds[1]);
    const double sy = AxisSpacing(d[1], this->Bounds[2], this->Bounds[3]);
    const double radius[2] = { this->FormationRegionRadiusRange[0],
      this->FormationRegionRadiusRange[1] };
    const double cellRadius[2] = { radius[0] / sx, radius[1] / sx };
    std::vector<nimbus::FormationRegion> regions =
      nimbus::RandomFormationRegions(d, this->NumberOfFormationRegions, cellRadius, 1.0,
        0.3 * (d[2] - 1), p.Seed, p.Boundary == nimbus::CloudBoundary::Open);
    for (nimbus::FormationRegion& region : regions)
    {
      const double metres = region.Radius[0] * sx;
      region.Radius[1] = metres / sy;
      region.Radius[2] = 0.5 * metres / dz;
    }
    const std::vector<float> weights = nimbus::FormationRegionWeights(
      d, regions, p.Boundary == nimbus::CloudBoundary::Periodic, owned[0], owned[1]);
    std::vector<float> hum(weights.size()), act(weights.size());
    for (std::size_t i = 0; i < weights.size(); ++i)
    {
      hum[i] = static_cast<float>(this->HumidityProbability * weights[i]);
      act[i] = static_cast<float>(this->ActivationProbability * weights[i]);
    }
    p.HumiditySupply = nimbus::ProbabilityField::Volume(std::move(hum));
    p.ActivationSupply = nimbus::ProbabilityField::Volume(std::move(act));
  }

  if (input)
  {
    int inDims[3];
    input->GetDimensions(inDims);
    const char* names[3] = { "p_ext", "p_hum", "p_act" };
    nimbus::ProbabilityField* fields[3] = { &p.Extinction, &p.HumiditySupply, &p.ActivationSupply };
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
                      << " x " << d[1] << " x " << d[2] << ") or be a 2-D map of " << d[0] << " x "
                      << d[1] << " x 1.");
        return false;
      }
      if (array->GetNumberOfComponents() != 1)
      {
        vtkErrorMacro(<< "Input array \"" << names[f] << "\" must have one component, it has "
                      << array->GetNumberOfComponents() << ".");
        return false;
      }
      const vtkIdType expected = static_cast<vtkIdType>(inDims[0]) * inDims[1] * inDims[2];
      if (array->GetNumberOfTuples() != expected)
      {
        vtkErrorMacro(<< "Input array \"" << names[f] << "\" has " << array->GetNumberOfTuples()
                      << " values for " << expected << " points.");
        return false;
      }
      std::vector<float> values(static_cast<std::size_t>(array->GetNumberOfTuples()));
      std::size_t aboveOne = 0;
      vtkIdType firstBad = -1;
      for (vtkIdType i = 0; i < array->GetNumberOfTuples(); ++i)
      {
        values[i] = static_cast<float>(array->GetComponent(i, 0));
        aboveOne += values[i] > 1.0f && std::isfinite(values[i]) ? 1 : 0;
        if (firstBad < 0 && !(values[i] >= 0.0f && values[i] <= 1.0f))
        {
          firstBad = i;
        }
      }
      // Bad values where they enter, counted (the core names the first one).
      const nimbus::ValueCensus census = nimbus::TakeCensus(values.data(), values.size());
      if (!census.AllFiniteNonNegative() || aboveOne > 0)
      {
        std::string problems = nimbus::DescribeCensus(census);
        if (aboveOne > 0)
        {
          problems +=
            (problems.empty() ? "" : " and ") + std::to_string(aboveOne) + " values above 1";
        }
        const char* core[3] = { "Extinction", "HumiditySupply", "ActivationSupply" };
        vtkErrorMacro(<< "Input array \"" << names[f] << "\" (" << core[f] << ") has " << problems
                      << ", the first " << values[firstBad] << " at index " << firstBad
                      << "; probabilities must be in [0, 1] (an 8-bit image needs scaling "
                         "by 1/255 first).");
        return false;
      }
      if (volume)
      {
        values = std::vector<float>(values.begin() + first, values.begin() + last);
      }
      *fields[f] = volume ? nimbus::ProbabilityField::Volume(std::move(values))
                          : nimbus::ProbabilityField::Plane(std::move(values));
    }
  }
  try
  {
    internals.Automaton = std::make_unique<nimbus::CloudAutomaton>(std::move(p));
  }
  catch (const std::exception& error)
  {
    vtkErrorMacro(<< "Cannot set up the cloud automaton: " << error.what()
                  << " (input arrays p_ext, p_hum, p_act must hold probabilities in [0, 1]).");
    return false;
  }
  return true;
}

int vtkNimbusCloudAutomatonSource::Generate(
  vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  vtkImageData* output = vtkImageData::GetData(outputVector, 0);
  vtkImageData* input = inputVector[0]->GetNumberOfInformationObjects() > 0
    ? vtkImageData::GetData(inputVector[0], 0)
    : nullptr;
  auto& internals = *this->Internals;
  const int* d = this->Dimensions;
  // --- one piece per rank: the ranks share the automaton by layers -----------------------------
  int extent[6];
  const bool anyPoint = nimbus::RequestedExtent(outInfo, extent);
  internals.ChooseRanks(this, outInfo, extent, anyPoint);
  this->HaloBytesPerStep = 0;
  this->PieceGatherBytes = 0;
  // --- memory: states, checkpoints, cached densities, output and input maps ----------------
  std::uint64_t cells = 0;
  if (!nimbus::CheckedProduct({ static_cast<std::uint64_t>(d[0]), static_cast<std::uint64_t>(d[1]),
                                static_cast<std::uint64_t>(d[2]) },
        cells))
  {
    vtkErrorMacro(<< "Dimensions (" << d[0] << ", " << d[1] << ", " << d[2]
                  << ") have more cells than 64 bits can count.");
    return 1;
  }
  const double cellCount = static_cast<double>(cells);
  const std::string overBudget = internals.OverBudget(this, input != nullptr, cellCount);
  if (!overBudget.empty())
  {
    vtkErrorMacro(<< overBudget
                  << " (MemoryBudgetMiB); lower Dimensions or MaximumNumberOfCheckpoints, or "
                     "raise MemoryBudgetMiB.");
    internals.Clear();
    return 1;
  }

  const vtkMTimeType inputTime = input ? input->GetMTime() : 0;
  if (!internals.Valid || internals.SourceTime != this->GetMTime() ||
    internals.InputTime != inputTime)
  {
    internals.Clear();
    if (!this->SetUpAutomaton(input, internals.Held))
    {
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
  const double lastTimeStep = static_cast<double>(this->NumberOfTimeSteps);
  const double stepPosition = std::clamp(time / this->StepDuration, 0.0, lastTimeStep) +
    static_cast<double>(this->SpinUpSteps);
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
    // Work of this request, from the state it starts at.
    const int radiusCells = static_cast<int>(std::ceil(std::max(1.0, this->SmoothingRadius)));
    const double work = static_cast<double>(lastNeeded - start) * (cellCount + StepOverhead) +
      2.0 * cellCount * (1.0 + 3.0 * (2.0 * radiusCells - 1.0));
    if (!(work <= MaximumWork))
    {
      vtkErrorMacro(<< "Time " << time << " s is automaton step " << lastNeeded << "; from the "
                    << "nearest cached state (step " << start << ") that needs about "
                    << Number(work) << " cell updates (" << d[0] << " x " << d[1] << " x " << d[2]
                    << " cells), more than the limit of " << Number(MaximumWork)
                    << " (minutes of work); lower NumberOfTimeSteps or Dimensions, or raise "
                       "StepDuration.");
      return 1;
    }
    // About 200 progress reports per request, an abort check every step.
    const std::int64_t reportEvery = std::max<std::int64_t>(1, (lastNeeded - start) / 200);
    for (;;)
    {
      const std::int64_t s = automaton.GetStep();
      internals.KeepCheckpoint(s, this->CheckpointInterval, this->MaximumNumberOfCheckpoints);
      if (s >= step && s <= lastNeeded && needs(s))
      {
        std::vector<float> density;
        this->PieceGatherBytes += static_cast<vtkIdType>(internals.Smooth(density, d[1]));
        internals.Densities[s] = std::move(density);
      }
      if (s >= lastNeeded)
      {
        break;
      }
      if ((s - start) % reportEvery == 0)
      {
        this->UpdateProgress(static_cast<double>(s - start + 1) / total);
      }
      if (this->CheckAbort())
      {
        return 1;
      }
      automaton.Step();
      this->HaloBytesPerStep = static_cast<vtkIdType>(internals.AfterStep());
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

  // --- output: the requested extent ----------------------------------------------------------
  // Pieces: distributed, the densities are this rank's piece (its slab stepped with the
  // halo exchange, the piece smoothed from the gathered rows); otherwise the whole grid's,
  // cropped to the requested extent. Either way bit-identical to the serial output there.
  double origin[3], spacing[3];
  outInfo->Get(vtkDataObject::ORIGIN(), origin);
  outInfo->Get(vtkDataObject::SPACING(), spacing);
  vtkSmartPointer<vtkFloatArray> density = internals.Crop(step, fraction, extent, anyPoint);
  const float* out = density->GetPointer(0);
  if (!anyPoint)
  {
    std::fill(extent, extent + 6, 0);
    extent[1] = extent[3] = extent[5] = -1;
  }
  output->SetExtent(extent);
  output->SetOrigin(origin);
  output->SetSpacing(spacing);
  output->GetPointData()->SetScalars(density);
  vtkNew<vtkDoubleArray> stepArray;
  stepArray->SetName("AutomatonStep");
  stepArray->InsertNextValue(static_cast<double>(step) + fraction);
  output->GetFieldData()->AddArray(stepArray);
  output->GetInformation()->Set(vtkDataObject::DATA_TIME_STEP(), time);
  // The smoothed field is a weighted mean of 0/1 cells: in [0, 1] unless something broke.
  const nimbus::ValueCensus census =
    nimbus::TakeCensus(out, static_cast<std::size_t>(density->GetNumberOfTuples()));
  if (!census.AllFiniteNonNegative())
  {
    vtkErrorMacro(<< "The density has " << nimbus::DescribeCensus(census)
                  << "; the output is withheld.");
    output->Initialize();
    return 1;
  }
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
  os << indent << "NumberOfFormationRegions: " << this->NumberOfFormationRegions << "\n";
  os << indent << "FormationRegionRadiusRange: " << this->FormationRegionRadiusRange[0] << " "
     << this->FormationRegionRadiusRange[1] << "\n";
  os << indent << "SpinUpSteps: " << this->SpinUpSteps << "\n";
  os << indent << "PeriodicBoundary: " << (this->PeriodicBoundary ? "On" : "Off") << "\n";
  os << indent << "StepDuration: " << this->StepDuration << "\n";
  os << indent << "NumberOfTimeSteps: " << this->NumberOfTimeSteps << "\n";
  os << indent << "SmoothingRadius: " << this->SmoothingRadius << "\n";
  os << indent << "InterpolateInTime: " << (this->InterpolateInTime ? "On" : "Off") << "\n";
  os << indent << "NumberOfThreads: " << this->NumberOfThreads << "\n";
  os << indent << "CheckpointInterval: " << this->CheckpointInterval << "\n";
  os << indent << "MaximumNumberOfCheckpoints: " << this->MaximumNumberOfCheckpoints << "\n";
  os << indent << "NumberOfStepsComputed: " << this->NumberOfStepsComputed << "\n";
  os << indent << "MemoryBudgetMiB: " << this->MemoryBudgetMiB << "\n";
}
