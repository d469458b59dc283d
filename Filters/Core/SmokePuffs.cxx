#include "SmokePuffs.h"

#include "Metaballs.h"
#include "ParallelFor.h"
#include "Random.h"
#include "SmokeSolver.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace nimbus
{
namespace
{
constexpr int kMaxPuffs = 1 << 26;
constexpr int kMaxSubsteps = 64; // per puff and step (at most one cell each)

// SplitMix64's finaliser (Steele, Lea & Flood 2014): a well-mixed 64-bit seed for step
// `step` of the run seeded `seed`, so each step's random numbers depend on (seed, step)
// only.
std::uint64_t StepSeed(std::uint64_t seed, std::uint64_t step)
{
  std::uint64_t z = seed + 0x9E3779B97F4A7C15ull * (step + 1);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

// True when x lies in the solver's grid, [Origin, Origin + n h) per axis, in a cell that
// is not solid.
bool InFluid(const Vector3& x, const SmokeParameters& s)
{
  int index[3];
  for (int a = 0; a < 3; ++a)
  {
    const double g = (x[a] - s.Origin[a]) / s.CellSizeMetres;
    if (!(g >= 0.0) || !(g < s.Dimensions[a]))
    {
      return false; // also NaN
    }
    index[a] = std::min(static_cast<int>(g), s.Dimensions[a] - 1);
  }
  if (s.Obstacles.empty())
  {
    return true;
  }
  const std::size_t c =
    (static_cast<std::size_t>(index[2]) * s.Dimensions[1] + index[1]) * s.Dimensions[0] + index[0];
  return s.Obstacles[c] == 0;
}

// The point carried by the solver's velocity for t seconds: midpoint (RK2) steps of at most
// one cell each at the speed found at the start.
Vector3 Carry(const SmokeSolver& solver, Vector3 x, double t)
{
  if (!(t > 0.0))
  {
    return x;
  }
  const double h = solver.GetParameters().CellSizeMetres;
  Vector3 v0 = solver.VelocityAt(x);
  const double cells = std::ceil(Length(v0) * t / h);
  const int substeps = cells >= kMaxSubsteps ? kMaxSubsteps : std::max(1, static_cast<int>(cells));
  const double tau = t / substeps;
  for (int s = 0; s < substeps; ++s)
  {
    if (s > 0)
    {
      v0 = solver.VelocityAt(x);
    }
    const Vector3 v1 = solver.VelocityAt(Along(x, v0, 0.5 * tau));
    x = Along(x, v1, tau);
  }
  return x;
}

// The grid indices [lo, hi] within `reach` of `centre` on an axis of n points at
// origin + spacing i, clipped to the grid in floating point before any conversion; false
// when none.
bool IndexRange(double centre, double reach, double origin, double spacing, int n, int& lo, int& hi)
{
  const double a = std::max(std::ceil((centre - reach - origin) / spacing), 0.0);
  const double b = std::min(std::floor((centre + reach - origin) / spacing), n - 1.0);
  if (!(a <= b))
  {
    return false;
  }
  lo = static_cast<int>(a);
  hi = static_cast<int>(b);
  return true;
}

void CheckPuff(const Puff& puff, std::size_t index)
{
  if (!IsFinite(puff.Position) || !(puff.Radius > 0.0) || !std::isfinite(puff.Radius) ||
    !(puff.Density >= 0.0) || !std::isfinite(puff.Density) || !(puff.Age >= 0.0) ||
    !std::isfinite(puff.Age))
  {
    std::ostringstream why;
    why << "nimbus::SmokePuffs::SetState: puff " << index
        << " needs a finite position, a radius > 0, a density >= 0 and an age >= 0";
    throw std::invalid_argument(why.str());
  }
}
} // namespace

std::string CheckPuffParameters(const PuffParameters& p)
{
  std::ostringstream why;
  struct Bound
  {
    const char* Name;
    double Value;
    bool Positive; // > 0, else >= 0
    double Largest;
  };
  const Bound bounds[] = { { "PuffsPerSecond", p.PuffsPerSecond, false, 1e9 },
    { "RadiusMetres", p.RadiusMetres, true, 1e6 },
    { "GrowthPerSecond", p.GrowthPerSecond, false, 1e9 },
    { "DensityPerPuff", p.DensityPerPuff, false, 1e9 },
    { "LifetimeSeconds", p.LifetimeSeconds, true, 1e9 } };
  for (const Bound& b : bounds)
  {
    const bool sign = b.Positive ? b.Value > 0.0 : b.Value >= 0.0;
    if (!sign || !std::isfinite(b.Value) || b.Value > b.Largest)
    {
      why << b.Name << " must be finite, " << (b.Positive ? "> 0" : ">= 0")
          << " and <= " << b.Largest << " (" << b.Value << ")";
      return why.str();
    }
  }
  if (p.MaxPuffs < 1 || p.MaxPuffs > kMaxPuffs)
  {
    why << "MaxPuffs must be in [1, " << kMaxPuffs << "] (" << p.MaxPuffs << ")";
    return why.str();
  }
  if (p.Threads < 0)
  {
    why << "Threads must be >= 0 (0: all cores) (" << p.Threads << ")";
    return why.str();
  }
  return "";
}

double WyvillFalloffIntegral(double radius)
{
  return 736.0 * kPi / 2835.0 * radius * radius * radius;
}

double PuffMass(const Puff& puff)
{
  return puff.Density * WyvillFalloffIntegral(puff.Radius);
}

SmokePuffs::SmokePuffs(const PuffParameters& parameters)
  : Parameters(parameters)
{
  const std::string why = CheckPuffParameters(parameters);
  if (!why.empty())
  {
    throw std::invalid_argument("nimbus::SmokePuffs: " + why);
  }
}

void SmokePuffs::SetState(const PuffState& state)
{
  if (state.Puffs.size() > static_cast<std::size_t>(this->Parameters.MaxPuffs))
  {
    throw std::invalid_argument("nimbus::SmokePuffs::SetState: more puffs than MaxPuffs");
  }
  if (!(state.EmissionCarry >= 0.0) || !(state.EmissionCarry < 1.0))
  {
    throw std::invalid_argument("nimbus::SmokePuffs::SetState: the carry must be in [0, 1)");
  }
  for (std::size_t i = 0; i < state.Puffs.size(); ++i)
  {
    CheckPuff(state.Puffs[i], i);
  }
  this->State = state;
}

void SmokePuffs::Step(double dt, const SmokeSolver& solver)
{
  if (!(dt > 0.0) || !std::isfinite(dt) || dt > 1e6)
  {
    throw std::invalid_argument("nimbus::SmokePuffs::Step: dt must be in (0, 1e6] seconds");
  }
  const PuffParameters& p = this->Parameters;
  const SmokeParameters& s = solver.GetParameters();
  // Worked on a copy, committed at the end (an exception leaves the state as it was).
  std::vector<Puff> puffs = this->State.Puffs;
  // The time each puff is carried in this step: dt, or a newborn's age.
  std::vector<double> travel(puffs.size(), dt);

  // 2. Emission (before the carrying, so that newborns are carried in the same parallel
  // pass): the m-th puff of the step is due when carry + rate tau reaches m.
  const double carry = this->State.EmissionCarry;
  const double due = carry + p.PuffsPerSecond * dt;
  const double whole = std::floor(due);
  const std::size_t capacity = static_cast<std::size_t>(p.MaxPuffs);
  const int perEmitter = static_cast<int>(std::min(whole, static_cast<double>(capacity)));
  Random random(StepSeed(p.Seed, this->State.Steps));
  for (const SmokeEmitter& e : s.Emitters)
  {
    if (!(e.DensityPerSecond > 0.0))
    {
      continue; // heat only, no smoke
    }
    for (int m = 1; m <= perEmitter && puffs.size() < capacity; ++m)
    {
      // A uniform point of the sphere: r = R cbrt(u) (the volume below r grows as r^3),
      // cos(theta) uniform in [-1, 1], phi uniform in [0, 2 pi).
      const double r = e.RadiusMetres * std::cbrt(random.Uniform());
      const double cosTheta = 1.0 - 2.0 * random.Uniform();
      const double sinTheta = std::sqrt(std::max(0.0, 1.0 - cosTheta * cosTheta));
      const double phi = 2.0 * kPi * random.Uniform();
      Puff puff;
      puff.Position = { { e.Centre[0] + r * sinTheta * std::cos(phi),
        e.Centre[1] + r * sinTheta * std::sin(phi), e.Centre[2] + r * cosTheta } };
      if (!InFluid(puff.Position, s))
      {
        continue;
      }
      const double born = (m - carry) / p.PuffsPerSecond; // after the step's start [s]
      puffs.push_back(puff);
      travel.push_back(std::clamp(dt - born, 0.0, dt));
    }
  }

  // 1. and 3. Carrying, ageing and growth: each puff by one thread.
  const double r0 = p.RadiusMetres;
  ParallelFor(puffs.size(), 256, p.Threads,
    [&](std::size_t begin, std::size_t end)
    {
      for (std::size_t i = begin; i < end; ++i)
      {
        Puff& puff = puffs[i];
        puff.Position = Carry(solver, puff.Position, travel[i]);
        puff.Age += travel[i];
        const double grown = 1.0 + p.GrowthPerSecond * puff.Age;
        puff.Radius = r0 * grown;
        puff.Density = p.DensityPerPuff / (grown * grown * grown);
      }
    });

  // 4. Removal, keeping the order.
  puffs.erase(std::remove_if(puffs.begin(), puffs.end(),
                [&](const Puff& puff)
                {
                  return !(puff.Age <= p.LifetimeSeconds) || !std::isfinite(puff.Radius) ||
                    !InFluid(puff.Position, s);
                }),
    puffs.end());

  this->State.Puffs.swap(puffs);
  this->State.EmissionCarry = std::clamp(due - whole, 0.0, std::nextafter(1.0, 0.0));
  ++this->State.Steps;
}

std::vector<float> SmokePuffs::Splat(
  const std::array<int, 3>& dims, const Vector3& origin, double spacing, int threads) const
{
  std::size_t points = 1;
  for (int a = 0; a < 3; ++a)
  {
    if (dims[a] < 1 || dims[a] > 4096)
    {
      throw std::invalid_argument("nimbus::SmokePuffs::Splat: dims must be 1 to 4096 each");
    }
    points *= static_cast<std::size_t>(dims[a]);
  }
  if (points > (std::size_t(1) << 30))
  {
    throw std::invalid_argument("nimbus::SmokePuffs::Splat: more than 2^30 points");
  }
  if (!(spacing > 0.0) || !std::isfinite(spacing) || !IsFinite(origin))
  {
    throw std::invalid_argument(
      "nimbus::SmokePuffs::Splat: the spacing must be > 0 and the origin finite");
  }
  const std::vector<Puff>& puffs = this->State.Puffs;
  const int nz = dims[2];
  // Per z plane, the puffs that reach it, in the puffs' order (compressed rows: the puffs
  // of plane k are list[first[k] .. first[k + 1])).
  std::vector<std::size_t> first(static_cast<std::size_t>(nz) + 1, 0);
  std::vector<std::array<int, 2>> planes(puffs.size(), { { 0, -1 } });
  for (std::size_t i = 0; i < puffs.size(); ++i)
  {
    const Puff& puff = puffs[i];
    int lo[3], hi[3];
    bool reaches = true;
    for (int a = 0; a < 3; ++a)
    {
      reaches = reaches &&
        IndexRange(puff.Position[a], puff.Radius, origin[a], spacing, dims[a], lo[a], hi[a]);
    }
    if (reaches)
    {
      planes[i] = { { lo[2], hi[2] } };
      for (int k = lo[2]; k <= hi[2]; ++k)
      {
        ++first[static_cast<std::size_t>(k) + 1];
      }
    }
  }
  for (int k = 0; k < nz; ++k)
  {
    first[k + 1] += first[k];
  }
  std::vector<std::size_t> list(first[nz]);
  {
    std::vector<std::size_t> next(first.begin(), first.end() - 1);
    for (std::size_t i = 0; i < puffs.size(); ++i)
    {
      for (int k = planes[i][0]; k <= planes[i][1]; ++k)
      {
        list[next[k]++] = i;
      }
    }
  }

  const std::size_t nx = static_cast<std::size_t>(dims[0]);
  const std::size_t plane = nx * static_cast<std::size_t>(dims[1]);
  std::vector<float> out(points, 0.0f);
  ParallelFor(static_cast<std::size_t>(nz), 1, threads,
    [&](std::size_t begin, std::size_t end)
    {
      std::vector<double> sum(plane);
      for (std::size_t k = begin; k < end; ++k)
      {
        std::fill(sum.begin(), sum.end(), 0.0);
        const double z = origin[2] + spacing * static_cast<double>(k);
        for (std::size_t l = first[k]; l < first[k + 1]; ++l)
        {
          const Puff& puff = puffs[list[l]];
          const double r2 = puff.Radius * puff.Radius;
          const double dz = z - puff.Position[2];
          const double reachY = std::sqrt(std::max(0.0, r2 - dz * dz));
          int j0, j1;
          if (!IndexRange(puff.Position[1], reachY, origin[1], spacing, dims[1], j0, j1))
          {
            continue;
          }
          for (int j = j0; j <= j1; ++j)
          {
            const double dy = origin[1] + spacing * j - puff.Position[1];
            const double dyz2 = dy * dy + dz * dz;
            const double reachX = std::sqrt(std::max(0.0, r2 - dyz2));
            int i0, i1;
            if (!IndexRange(puff.Position[0], reachX, origin[0], spacing, dims[0], i0, i1))
            {
              continue;
            }
            double* row = &sum[static_cast<std::size_t>(j) * nx];
            for (int i = i0; i <= i1; ++i)
            {
              const double dx = origin[0] + spacing * i - puff.Position[0];
              row[i] += puff.Density * WyvillFalloff(dx * dx + dyz2, r2);
            }
          }
        }
        float* target = &out[k * plane];
        for (std::size_t c = 0; c < plane; ++c)
        {
          target[c] = static_cast<float>(sum[c]);
        }
      }
    });
  return out;
}

} // namespace nimbus
