// Sand dunes and wind ripples as height fields grown by a cellular automaton of
// saltation and creep (002 §5.1; Nishimori and Ouchi, Phys. Rev. Lett. 71, 197 (1993),
// "N&O" below; Onoue and Nishita, Pacific Graphics 2000, 002's reference [15]).
//
// A height field h(x, y) (metres of sand) lives on an nx x ny lattice of square cells of
// side dx (metres), periodic in x and y. The wind blows along +x. One step n -> n+1 is,
// in this order:
//   1. saltation (N&O Eq. 1, 002 §5.1 "the jump of sand grains caused by the wind"):
//      every cell lifts a layer q (metres) that lands L = L0 + b h (metres) downwind:
//        h(x) -> h(x) - q,   h(x + L) -> h(x + L) + q,
//      the landing split linearly between the two cells around x + L (so L need not be a
//      whole number of cells). With a bedrock (dunes), q is min(q, h): bare rock lifts
//      nothing, and a grain that lands hops on until it stays (a fraction
//      DepositionOnSand / DepositionOnRock of what lands stays each hop: Werner, Geology
//      23, 1107 (1995)). Cells in the wind shadow (below a line falling at
//      ShadowAngleDegrees from an upwind crest, Werner's shadow zone, or on a face lower
//      than its upwind neighbour, where the flow separates) lift nothing and keep all
//      that lands, which makes slip faces. Ripples (no bedrock) make one hop.
//   2. creep (N&O Eq. 2, 002 §5.1 "sand grains may move along the sand surface without
//      jumping"): grains roll toward lower neighbours,
//        h(x) -> h(x) + D [ (1/6) sum_nn h + (1/12) sum_nnn h - h(x) ]
//      over the 4 nearest and the 4 diagonal neighbours, D in [0, 1].
//   3. avalanches (002 §5.1: "the sand dunes are formed by considering the inclination in
//      the movement of sand grains"): where the slope between two neighbours exceeds the
//      angle of repose, a fifth of the excess height flows down, a few sweeps per step.
// Every rule moves sand between cells and never makes or destroys it: the total volume
// is conserved to rounding (each transfer is added to one cell and taken from another
// with the same double).
//
// Ripples (saltation and creep only, heights relative to the bed's mean, no bedrock)
// and dunes (all three, on a bedrock) are simulated separately at their own scales
// (002 §5.1) with different parameters; see RippleParameters() and DuneParameters().
//
// Threads and determinism: the wind is along the rows, so saltation scatters only within
// a row and rows are independent; creep and avalanches read the state before their
// sweep. Every output cell is written by one row's call in a fixed order, so results do
// not depend on the thread count (bit-identical). The initial bed's randomness is a hash
// of (seed, cell), so it does not depend on the order of anything either.
//
// Units: lengths and heights in metres, time in steps, angles in degrees, b and D
// dimensionless.
#ifndef NimbusDuneAutomaton_h
#define NimbusDuneAutomaton_h

#include "NimbusFiltersModule.h"

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace nimbus
{

struct SandParameters
{
  int Dimensions[2] = { 128, 128 }; // cells along x (downwind) and y
  double CellSizeMetres = 1.0;      // dx
  /// L0 of N&O Eq. 1: the jump of a grain from height 0, metres (>= 0).
  double SaltationLengthMetres = 4.0;
  /// b of N&O Eq. 1: metres of jump per metre of height (>= 0), L = L0 + b h, clamped at 0.
  double SaltationHeightGain = 1.0;
  /// q of N&O Eq. 1: sand lifted per cell and step, metres of height (>= 0).
  double SaltationDepthMetres = 0.1;
  /// With a bedrock: the lifted layer is q tanh(h / h_s) (at most h), h_s this depth,
  /// metres (>= 0; 0: min(q, h)). The sand flux then grows along a dune's stoss side and
  /// saturates near its crest.
  double SaturationDepthMetres = 0.0;
  /// With a bedrock: the fraction of the sand landing on sand (on bare rock) that stays; the
  /// rest hops on (at most 16 hops). In [0.01, 1]. Werner 1995: 0.6 and 0.4.
  double DepositionOnSand = 0.6;
  double DepositionOnRock = 0.4;
  /// D of N&O Eq. 2, in [0, 1].
  double CreepRate = 0.5;
  /// Heights are sand above a rock floor at 0 and stay >= 0 (dunes); off: heights are
  /// relative to the bed's mean and any sign (ripples).
  bool Bedrock = false;
  /// Wind-shadow angle, degrees in (0, 90); 0: no wind shadow.
  double ShadowAngleDegrees = 0.0;
  /// Angle of repose, degrees in (0, 90); 0: no avalanches.
  double ReposeAngleDegrees = 0.0;
  /// Avalanche sweeps per step (>= 0).
  int AvalancheSweeps = 4;
};

/// Wind ripples at the centimetre scale: 1 cm cells, L0 = 6 cm, b = 1, q = 3 mm, D = 0.2,
/// repose 30 degrees (about 8 cm between crests).
NIMBUSFILTERS_EXPORT SandParameters RippleParameters();
/// Dunes at the scale of metres: 2 m cells, L0 = 8 m, b = 0.02, q = 0.2 m, D = 0.2, shadow
/// 15 degrees, repose 34 degrees, deposition 0.6 on sand and 0.4 on rock, on a bedrock.
NIMBUSFILTERS_EXPORT SandParameters DuneParameters();

/// Empty when the parameters are usable, else a sentence naming the first bad one
/// (NaN, infinities, negative or zero sizes, out-of-range angles and rates).
NIMBUSFILTERS_EXPORT std::string CheckSandParameters(const SandParameters& parameters);

/// Uniform in [0, 1) from a hash of (seed, a, b) (splitmix64 finaliser): the same on every
/// platform, independent of call order.
NIMBUSFILTERS_EXPORT double HashUniform(std::uint64_t seed, std::uint64_t a, std::uint64_t b);

/// A random bed: mean + amplitude (u - 1/2), u = HashUniform(seed, x, y), metres.
NIMBUSFILTERS_EXPORT std::vector<double> RandomSandBed(
  int nx, int ny, double meanMetres, double amplitudeMetres, std::uint64_t seed);

class NIMBUSFILTERS_EXPORT SandAutomaton
{
public:
  /// Heights[x + nx y], metres; throws std::invalid_argument for bad parameters or a
  /// height field of the wrong size or with NaN/infinite values.
  SandAutomaton(const SandParameters& parameters, std::vector<double> heights);

  /// Runs `steps` steps on `threads` threads (0: one per hardware thread). progress, if
  /// given, is called after each step with the steps done in this call; when it returns
  /// false the run stops after that step (the state stays consistent).
  void Run(long long steps, int threads = 0,
    const std::function<bool(long long stepsDone)>& progress = nullptr);

  const std::vector<double>& Heights() const { return this->H; }
  const SandParameters& Parameters() const { return this->P; }
  long long StepCount() const { return this->Steps; }
  /// Sum of the heights times the cell area, m^3.
  double Volume() const;

private:
  void Saltation(int threads);
  void Creep(int threads);
  void Avalanche(int threads);

  SandParameters P;
  std::vector<double> H, Scratch;
  long long Steps = 0;
};

/// The ripple normal maps of 002 §5.2 at every level of detail: level k is the ripple
/// height field box-averaged to (n / 2^k)^2 cells (n x n, periodic, n a power of two
/// times 2^(levels-1)), its normals by central differences, (-dh/dx, -dh/dy, 1)
/// normalised, x fastest, 3 floats per texel. 002: 256^2, 128^2, 64^2, 32^2.
struct RippleNormalLevel
{
  int Size = 0;           // texels a side
  double TexelMetres = 0; // texel size
  std::vector<float> Normals;
  std::vector<float> Heights; // box-averaged heights, metres
};
NIMBUSFILTERS_EXPORT std::vector<RippleNormalLevel> RippleNormalPyramid(
  const std::vector<double>& heights, int size, double cellMetres, int levels);

/// 002 §5.2 step 2(b): the level of detail of a quadrilateral at `distance` from the
/// viewer: 0 (finest) closer than nearDistance, one level coarser per doubling of the
/// distance, at most levels - 1.
NIMBUSFILTERS_EXPORT int RippleLevelOfDetail(double distance, double nearDistance, int levels);

} // namespace nimbus

#endif
