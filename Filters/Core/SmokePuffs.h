// Smoke puffs (002 §4): "we consider a 'set' of smoke particles ... This cluster is called
// a 'puff.' We use the metaball to define the density distribution of the puff. The motion
// of the smoke is simulated by moving metaballs according to the velocity field" computed
// by the fluid solver (SmokeSolver.h). Plain C++, no VTK.
//
// A puff is a metaball (Wyvill's degree-6 falloff, Metaballs.h) of radius R [m] and peak
// density D (dimensionless, what the renderer multiplies by its extinction per density).
// Its life, per Step(dt) of the puff system (after the solver's own Step):
//  1. the puffs alive are carried by the solver's velocity over dt [s]: a midpoint (RK2)
//     step x += dt v(x + dt/2 v(x)) of SmokeSolver::VelocityAt, split into sub-steps of
//     at most one cell each (at the speed found at the start, 64 sub-steps at most); the
//     velocity is the solver's after its step, held fixed over dt;
//  2. emission: each emitter of the solver with DensityPerSecond > 0 (one that only heats
//     emits no smoke, so no puffs) emits PuffsPerSecond puffs per second, the fraction of
//     a puff left over carried to the next step (so after time t, floor(rate t) or one
//     fewer per emitter, whatever the steps). The m-th puff of a step is born at the
//     instant its count is reached, at a uniformly random point of the emitter's sphere
//     (3 random numbers: r = R_e cbrt(u), a uniform direction), and carried for the rest
//     of the step (its age). Puffs born in a solid cell or outside the grid are dropped.
//     Emission stops while MaxPuffs puffs are alive (those puffs are lost, not delayed);
//  3. growth by turbulent spreading: R = R0 (1 + GrowthPerSecond age); the smoke each puff
//     carries stays the same, so its peak density falls as D = DensityPerPuff (R0 / R)^3
//     (the metaball's integral, PuffMass, is D R^3 times a constant);
//  4. removal: puffs older than LifetimeSeconds, outside the grid (the top is open: smoke
//     that rises out of it is gone) or in a solid cell of the solver's Obstacles.
//
// Deterministic: the random numbers of step s come from a generator seeded by (Seed, s),
// the emission order is fixed (emitter by emitter, puff by puff), each puff is moved by
// one thread; so the result does not depend on the thread count, and the state (puffs,
// the fraction carried, the step count) is all a checkpoint needs.
#ifndef nimbus_SmokePuffs_h
#define nimbus_SmokePuffs_h

#include "Math.h"
#include "NimbusFiltersModule.h"

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace nimbus
{
class SmokeSolver;

struct PuffParameters
{
  double PuffsPerSecond = 200.0; // per emitter (>= 0)
  double RadiusMetres = 0.3;     // R0, the metaball's radius at birth (> 0)
  double GrowthPerSecond = 0.1;  // R = R0 (1 + this age) (>= 0)
  double DensityPerPuff = 1.0;   // peak density at birth (>= 0); falls as (R0 / R)^3
  double LifetimeSeconds = 10.0; // older puffs are removed (> 0)
  int MaxPuffs = 100000;         // 1 to 2^26: no emission while this many are alive
  std::uint64_t Seed = 1;
  int Threads = 0; // for Step; 0: hardware concurrency
};

/// "" or the first thing wrong, naming the parameter: non-finite values, negative rates,
/// a radius or lifetime <= 0, values over their bounds (1e9 per second, 1e6 m, 1e9 s),
/// MaxPuffs outside [1, 2^26], Threads < 0.
NIMBUSFILTERS_EXPORT std::string CheckPuffParameters(const PuffParameters& p);

struct Puff
{
  Vector3 Position{ { 0, 0, 0 } }; // [m]
  double Radius = 0.0;             // [m]
  double Density = 0.0;            // peak (at the centre)
  double Age = 0.0;                // [s]
};

/// The integral of Wyvill's falloff (Metaballs.h) over space for radius R [m^3]:
/// 4 pi R^3 int_0^1 s^2 (1 - 22/9 s^2 + 17/9 s^4 - 4/9 s^6) ds = 736 pi / 2835 R^3
/// (= 0.1947 of the sphere's volume).
NIMBUSFILTERS_EXPORT double WyvillFalloffIntegral(double radius);

/// The smoke a puff carries, Density WyvillFalloffIntegral(Radius) [density m^3]: constant
/// over its life (see 3. above).
NIMBUSFILTERS_EXPORT double PuffMass(const Puff& puff);

/// Everything that decides the next steps (for checkpoints).
struct PuffState
{
  std::vector<Puff> Puffs;
  double EmissionCarry = 0.0; // the fraction of a puff carried to the next step, [0, 1)
  std::uint64_t Steps = 0;    // steps taken (seeds the next step's random numbers)
};

class NIMBUSFILTERS_EXPORT SmokePuffs
{
public:
  /// Throws std::invalid_argument with CheckPuffParameters's message.
  explicit SmokePuffs(const PuffParameters& parameters);

  /// Advances by dt seconds ((0, 1e6], finite; else std::invalid_argument) in the solver's
  /// current velocity field, emitting from its emitters (see the file comment).
  void Step(double dt, const SmokeSolver& solver);

  const PuffParameters& GetParameters() const { return this->Parameters; }
  const std::vector<Puff>& GetPuffs() const { return this->State.Puffs; }
  const PuffState& GetState() const { return this->State; }
  /// Replaces the state (a checkpoint's GetState()): the next steps then repeat exactly.
  /// Throws std::invalid_argument for non-finite or negative values, a radius <= 0, a
  /// carry outside [0, 1) or more than MaxPuffs puffs.
  void SetState(const PuffState& state);

  /// Splats all puffs as metaballs, Density WyvillFalloff(|p - Position|^2, Radius^2)
  /// summed (in double, in the puffs' order), onto a grid of points: point (i, j, k) at
  /// origin + spacing (i, j, k) [m], x fastest; dims 1 to 4096 each and 2^30 points at
  /// most, spacing > 0, all finite (else std::invalid_argument). threads: 0 = all cores.
  /// Each thread owns whole z planes, so the result is bit-identical for any thread count.
  std::vector<float> Splat(
    const std::array<int, 3>& dims, const Vector3& origin, double spacing, int threads) const;

private:
  PuffParameters Parameters;
  PuffState State;
};

} // namespace nimbus

#endif
