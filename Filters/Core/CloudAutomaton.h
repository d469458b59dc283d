// Cloud cellular automaton (002 §3; Dobashi et al., SIGGRAPH 2000). The rules the
// extracted text of 002 lost are written out in shared/papers/README.md.
//
// Three boolean fields live on an nx x ny x nz grid of cells (x fastest, z up):
//   hum  water vapour,  act  phase-transition factor,  cld  cloud.
// One step n -> n+1 is, in this order:
//   1. growth (002 §3, shared/papers/README.md):
//        hum' = hum AND NOT act
//        cld' = cld OR act
//        act' = NOT act AND hum AND f_act
//      f_act(x,y,z) is true when act is set in any of the cells at offsets
//      (+-1,0,0), (+-2,0,0), (0,+-1,0), (0,+-2,0), (0,0,+1), (0,0,-1), (0,0,-2)
//      (evaluated on the state before the step);
//   2. extinction and supply, with per-cell probabilities:
//        cld' = cld' AND NOT (rnd < p_ext),  hum' = hum' OR (rnd < p_hum),
//        act' = act' OR (rnd < p_act);
//   3. wind: every field moves by the whole-cell shift of step n along x and y
//      (see WindShift: fractional winds accumulate exactly, shear makes the wind
//      grow with height).
//
// Bit-packed: 64 cells per std::uint64_t along x, rows padded to whole words (the
// padding bits are always 0). Steps are multithreaded over z slabs.
//
// Determinism: every random number is a counter-based hash of (seed, step,
// stream, cell or word index), so a state depends only on the parameters, the
// seed and the step number -- not on the number of threads, nor on how the steps
// were split between calls. Checkpoints (State) can be taken and restored.
//
// Units: lengths in cells, time in steps, wind in cells per step, shear in cells
// per step per cell of height; probabilities are per cell and per step.
#ifndef NimbusCloudAutomaton_h
#define NimbusCloudAutomaton_h

#include "NimbusFiltersModule.h"

#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

namespace nimbus
{

/// A per-cell probability: one value everywhere, a 2-D map over (x, y) applied to
/// every height, or a full 3-D field. Values must lie in [0, 1].
struct ProbabilityField
{
  enum class Kind
  {
    Uniform, // Value everywhere
    Plane,   // Values[x + nx * y], the same at every z
    Volume   // Values[x + nx * (y + ny * z)]
  };
  Kind Type = Kind::Uniform;
  double Value = 0.0;
  std::vector<float> Values;

  static ProbabilityField Uniform(double value);
  static ProbabilityField Plane(std::vector<float> values);
  static ProbabilityField Volume(std::vector<float> values);
};

/// How the automaton treats the x and y faces of the grid. z is always open:
/// nothing is above the top layer or below the bottom one.
enum class CloudBoundary
{
  Open,    // outside cells are empty; wind carries empty cells in
  Periodic // the grid wraps around in x and y
};

struct CloudAutomatonParameters
{
  int Dimensions[3] = { 64, 64, 16 }; // cells along x, y, z (each >= 1)
  std::uint64_t Seed = 1;
  ProbabilityField Extinction = ProbabilityField::Uniform(0.1);          // p_ext
  ProbabilityField HumiditySupply = ProbabilityField::Uniform(0.001);    // p_hum
  ProbabilityField ActivationSupply = ProbabilityField::Uniform(0.0005); // p_act
  /// Probabilities of hum and act at step 0 (cld starts empty).
  double InitialHumidity = 0.3;
  double InitialActivation = 0.001;
  /// Wind at the bottom layer (z = 0), cells per step, and its growth per layer of
  /// height: the wind of layer z is Wind + z * Shear.
  double Wind[2] = { 0.0, 0.0 };
  double Shear[2] = { 0.0, 0.0 };
  CloudBoundary Boundary = CloudBoundary::Periodic;
  /// Worker threads; 0 = std::thread::hardware_concurrency(). Results do not depend on it.
  int NumberOfThreads = 0;
  /// The layers this automaton holds: z in [Layers[0], Layers[1]) of the grid's
  /// Dimensions[2] (Layers[1] < 0: to the top; the default holds the whole grid). A slab of a
  /// distributed run (DistributedLayers): its states hold only these layers, a Volume
  /// probability field gives nx*ny values per held layer, and every random number, wind
  /// shift and probability stays the one of the global cell (z = Layers[0] + local layer),
  /// so the held layers equal the whole grid's as long as the layers just outside are
  /// right: Step treats the layers beyond the slab as empty, and the caller replaces the
  /// outermost held layers (the halo) with their owners' after every step.
  int Layers[2] = { 0, -1 };
  /// The held layers this automaton steps: z in [Owned[0], Owned[1]) (Owned[0] < 0: all the
  /// held layers, the default). The others are a distributed run's halo, which the caller
  /// replaces with their owners' after every step: Step leaves them empty, and the Plane and
  /// Volume probability fields keep thresholds for the stepped layers only (a Volume field
  /// gives nx*ny values per stepped layer), 8 bytes per cell of the halo saved with the
  /// formation regions.
  int Owned[2] = { -1, -1 };
};

/// A distributed run's split of nz layers between `ranks`: rank r owns
/// [nz r / ranks, nz (r + 1) / ranks) and holds 2 more layers below and 1 above (the reach
/// of f_act in z; the wind moves only along x and y), within the grid. `owned` and `held`
/// receive [begin, end). Needs nz >= 2 ranks (every rank owns 2 layers or more).
NIMBUSFILTERS_EXPORT void DistributedLayers(int nz, int rank, int ranks, int owned[2], int held[2]);

/// Layers below and above the owned ones that a distributed run refreshes after each step.
constexpr int CloudHaloBelow = 2;
constexpr int CloudHaloAbove = 1;

/// The whole automaton state at one step (a checkpoint).
struct CloudAutomatonState
{
  std::int64_t Step = 0;
  std::vector<std::uint64_t> Hum, Act, Cld;
};

/// Whole-cell shift of step n for a wind of `cellsPerStep`: floor(v (n+1)) - floor(v n),
/// so the shifts of steps 0..n-1 add up to floor(v n) -- a fractional wind moves
/// the field on average v cells per step, with no rounding drift.
NIMBUSFILTERS_EXPORT std::int64_t WindShift(double cellsPerStep, std::int64_t step);

class NIMBUSFILTERS_EXPORT CloudAutomaton
{
public:
  enum class Field
  {
    Hum,
    Act,
    Cld
  };

  /// Validates the parameters (throws std::invalid_argument with a message naming
  /// the parameter) and sets up step 0.
  explicit CloudAutomaton(const CloudAutomatonParameters& parameters);
  /// The same, taking the parameters' arrays over (no copy of the probability fields).
  explicit CloudAutomaton(CloudAutomatonParameters&& parameters);

  /// The parameters; the values of Plane and Volume probability fields are dropped once they
  /// are turned into the per-cell thresholds the steps use (ProbabilityField::Values is empty
  /// then, its Type kept), which would otherwise double their memory.
  const CloudAutomatonParameters& GetParameters() const { return this->Parameters; }
  std::int64_t GetStep() const { return this->Current.Step; }

  /// Back to the seeded initial state of step 0.
  void Reset();

  /// Advances one step.
  void Step();

  /// Advances to `step` (>= GetStep()). `progress(fraction)` is called between
  /// steps; returning false stops early (GetStep() tells where). Returns true when
  /// `step` was reached.
  bool StepTo(std::int64_t step, const std::function<bool(double)>& progress = nullptr);

  const CloudAutomatonState& GetState() const { return this->Current; }
  /// Restores a state taken from an automaton with the same parameters (sizes checked).
  void SetState(const CloudAutomatonState& state);

  /// Cell (x, y, z), z global (within the held layers).
  bool Get(Field field, int x, int y, int z) const;
  void Set(Field field, int x, int y, int z, bool value);
  /// Clears all three fields (for hand-built test states).
  void Clear();
  std::size_t Count(Field field) const;

  int WordsPerRow() const { return this->RowWords; }
  /// The held layers [FirstLayer, FirstLayer + HeldLayers) (Parameters.Layers resolved).
  int FirstLayer() const { return this->Z0; }
  int HeldLayers() const { return this->NZ; }
  /// The stepped layers [FirstOwnedLayer, FirstOwnedLayer + OwnedLayers) (Parameters.Owned
  /// resolved).
  int FirstOwnedLayer() const { return this->Z0 + this->O0; }
  int OwnedLayers() const { return this->ON; }
  /// Words of field `field` at global layer z (held), ny rows of WordsPerRow() words:
  /// where a distributed run reads and replaces halo layers.
  std::uint64_t* Layer(Field field, int z);

private:
  /// Step's wind: Scratch moved into Current by step n's shifts (or swapped).
  void MoveWithTheWind(std::int64_t n);
  void ValidateAndPrepare();
  void InitialState();
  std::vector<std::uint64_t>& Data(Field field);
  const std::vector<std::uint64_t>& Data(Field field) const;

  CloudAutomatonParameters Parameters;
  int RowWords = 1;
  int Z0 = 0, NZ = 1; // held layers
  int O0 = 0, ON = 1; // stepped layers, O0 counted from Z0
  std::uint64_t TailMask = ~std::uint64_t(0);
  int Threads = 1;
  // Probability thresholds on a 24-bit uniform integer: event when r < threshold.
  std::vector<std::uint32_t> ExtinctionThresholds, HumidityThresholds, ActivationThresholds;
  CloudAutomatonState Current;
  CloudAutomatonState Scratch;
};

/// A formation region: where vapour and activation are supplied, so that separate clouds
/// form there (Dobashi et al. 2000 give the supply probabilities the shape of ellipsoids).
/// A Gaussian ellipsoid: centre and semi-axes (its standard deviations), in cells.
struct FormationRegion
{
  double Center[3] = { 0.0, 0.0, 0.0 };
  double Radius[3] = { 1.0, 1.0, 1.0 };
};

/// Per-cell weight in [0, 1] on the grid `dimensions` (x fastest): the largest
/// exp(-r^2 / 2) over the regions, r the distance from a region's centre in units of its
/// semi-axes, 0 where r > 3. With `periodic`, regions wrap around in x and y (nearest image).
/// Only layers [zBegin, zEnd) (zEnd < 0: to the top), the same values as the whole grid's.
NIMBUSFILTERS_EXPORT std::vector<float> FormationRegionWeights(const int dimensions[3],
  const std::vector<FormationRegion>& regions, bool periodic, int zBegin = 0, int zEnd = -1);

/// `count` regions drawn from `seed` (the same on every platform): centres uniform over x
/// and y at height `centerHeight`, horizontal semi-axes uniform in `horizontalRadius` (low,
/// high) and the same ratio vertical/horizontal `aspect` for all; a centre is redrawn (up to
/// 64 times, for the first 256 regions) while it lies within 1.5 times the sum of the horizontal
/// semi-axes of an earlier one, so that the clouds stay apart where there is room. Units: cells.
/// With `inside`, centres keep three horizontal semi-axes from the x and y faces (where the
/// grid is wide enough), so that open faces do not cut the clouds.
NIMBUSFILTERS_EXPORT std::vector<FormationRegion> RandomFormationRegions(const int dimensions[3],
  int count, const double horizontalRadius[2], double aspect, double centerHeight,
  std::uint64_t seed, bool inside = false);

/// Options of the smoothing of cld into a continuous density.
struct CloudSmoothingParameters
{
  /// Kernel radius in cells: the separable product kernel
  /// w(dx) w(dy) w(dz), w(d) = WyvillFalloff(d^2, R^2) (004 §4's degree-6 field),
  /// normalised to sum 1. R <= 1 means no smoothing.
  double Radius = 2.5;
  int NumberOfThreads = 0;
};

/// Density in [0, 1]: the cld field smoothed by the kernel above (002 §3, papers README:
/// "the boolean cld field smoothed over a small 3-D neighbourhood with a smooth
/// kernel"). x/y boundaries follow the automaton's, z is open. `density` is
/// resized to nx*ny*nz (x fastest).
NIMBUSFILTERS_EXPORT void SmoothCloud(const CloudAutomaton& automaton,
  const CloudSmoothingParameters& smoothing, std::vector<float>& density);

/// Same, for a stored state of an automaton with these parameters.
NIMBUSFILTERS_EXPORT void SmoothCloud(const CloudAutomatonParameters& parameters,
  const CloudAutomatonState& state, const CloudSmoothingParameters& smoothing,
  std::vector<float>& density);

/// Cells beyond a box that SmoothCloudBox reads on each side: ceil(max(1, Radius)) - 1.
NIMBUSFILTERS_EXPORT int SmoothingHalo(const CloudSmoothingParameters& smoothing);

/// SmoothCloud's values at the cells of `box` (x0, x1, y0, y1, z0, z1 inclusive, global), bit
/// for bit, from the cld rows around it: `row(y, z)` returns the WordsPerRow() words of whole
/// row (y, z) for y within SmoothingHalo() of the box (wrapped into the grid when periodic,
/// else inside it) and z within it inside the grid. `density` is resized to the box's cells
/// (x fastest). What a rank of a distributed run computes for its piece.
NIMBUSFILTERS_EXPORT void SmoothCloudBox(const CloudAutomatonParameters& parameters,
  const CloudSmoothingParameters& smoothing, const int box[6],
  const std::function<const std::uint64_t*(int y, int z)>& row, std::vector<float>& density);

/// Linear interpolation in time between the densities of two consecutive steps:
/// out = (1 - t) a + t b, t in [0, 1] (002 §3: no flicker between steps).
NIMBUSFILTERS_EXPORT void InterpolateDensity(
  const std::vector<float>& a, const std::vector<float>& b, double t, std::vector<float>& out);

} // namespace nimbus

#endif
