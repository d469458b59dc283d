// The smoke solver (Filters/Core/SmokeSolver.h, 002 §4): the projection leaves the
// velocity divergence-free, nothing flows through obstacles, a hot plume rises and
// spreads, the advection's mass change is stated and bounded, a large time step is
// sub-stepped (and too large a one refused), threads do not change the result, bad
// parameters of every kind are refused with a message, and with open sides the wind
// blows through the box and a plume leans downwind. Bounds: from the values printed.
#include "SmokePressure.h"
#include "SmokeSolver.h"
#include "Voxelize.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <memory>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

namespace
{
using nimbus::SmokeParameters;
using nimbus::SmokeSolver;

SmokeParameters Small(int nx = 16, int ny = 16, int nz = 24)
{
  SmokeParameters p;
  p.Dimensions = { { nx, ny, nz } };
  p.CellSizeMetres = 0.25;
  p.Threads = 2;
  nimbus::SmokeEmitter e;
  e.Centre = { { 0.5 * nx * 0.25, 0.5 * ny * 0.25, 0.75 } };
  e.RadiusMetres = 0.6;
  e.DensityPerSecond = 2.0;
  e.TemperatureKelvin = 500.0;
  p.Emitters = { e };
  return p;
}

/// Height (z) of the smoke's centre of mass, its RMS horizontal radius and the top of
/// the plume (the highest cell centre holding more than 1 % of the largest density).
void Moments(const SmokeSolver& s, double& height, double& radius, double& top)
{
  const auto& n = s.GetParameters().Dimensions;
  const double h = s.GetParameters().CellSizeMetres;
  double mass = 0.0, z = 0.0, x = 0.0, y = 0.0;
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i)
      {
        const double d = s.GetDensity()[s.CellIndex(i, j, k)];
        mass += d;
        x += d * (i + 0.5) * h;
        y += d * (j + 0.5) * h;
        z += d * (k + 0.5) * h;
      }
  x /= mass;
  y /= mass;
  height = z / mass;
  double r2 = 0.0;
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i)
      {
        const double d = s.GetDensity()[s.CellIndex(i, j, k)];
        const double dx = (i + 0.5) * h - x, dy = (j + 0.5) * h - y;
        r2 += d * (dx * dx + dy * dy);
      }
  radius = std::sqrt(r2 / mass);
  double largest = 0.0;
  for (float d : s.GetDensity())
  {
    largest = std::max(largest, static_cast<double>(d));
  }
  top = 0.0;
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i)
      {
        if (s.GetDensity()[s.CellIndex(i, j, k)] > 0.01 * largest)
        {
          top = std::max(top, (k + 0.5) * h);
        }
      }
}
} // namespace

// A random velocity field projected: the RMS divergence falls by the solver's tolerance
// (relative residual 1e-7: the divergence is the residual / h^2).
TEST(SmokeSolver, ProjectionMakesDivergenceFree)
{
  SmokeParameters p = Small();
  p.Emitters.clear();
  SmokeSolver s(p);
  std::uint64_t state = 99;
  const auto random = [&state]()
  {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return static_cast<float>((state >> 40) * (1.0 / (1ull << 24)) * 2.0 - 1.0);
  };
  std::vector<float> u(s.GetU().size()), v(s.GetV().size()), w(s.GetW().size());
  for (auto* f : { &u, &v, &w })
  {
    for (float& x : *f)
    {
      x = random();
    }
  }
  s.SetState(0.0, s.GetDensity(), s.GetTemperature(), u, v, w);
  const nimbus::SmokeStepReport r = s.Step(1e-4);
  std::printf("  divergence %.3g -> %.3g 1/s (%d CG iterations, residual %.2g)\n",
    r.DivergenceBefore, r.DivergenceAfter, r.PressureIterations, r.PressureResidual);
  EXPECT_GT(r.DivergenceBefore, 1.0);
  EXPECT_LT(r.DivergenceAfter, 1e-5 * r.DivergenceBefore);
  const std::vector<double> divergence = s.Divergence();
  double worst = 0.0;
  for (double d : divergence)
  {
    worst = std::max(worst, std::abs(d));
  }
  EXPECT_LT(worst, 1e-4 * r.DivergenceBefore);
}

// An obstacle above the emitter: no face into it carries flow, no smoke inside it, and the
// plume goes around it.
TEST(SmokeSolver, NoFlowThroughObstacles)
{
  SmokeParameters p = Small();
  const auto& n = p.Dimensions;
  p.Obstacles.assign(static_cast<std::size_t>(n[0]) * n[1] * n[2], 0);
  for (int k = 8; k < 11; ++k)
    for (int j = 5; j < 11; ++j)
      for (int i = 5; i < 11; ++i)
      {
        p.Obstacles[(static_cast<std::size_t>(k) * n[1] + j) * n[0] + i] = 1;
      }
  SmokeSolver s(p);
  for (int step = 0; step < 40; ++step)
  {
    s.Step(0.05);
  }
  double inside = 0.0, faceFlow = 0.0, above = 0.0;
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i)
      {
        const std::size_t c = s.CellIndex(i, j, k);
        if (p.Obstacles[c])
        {
          inside += s.GetDensity()[c];
          // The six faces of a solid cell.
          faceFlow +=
            std::abs(s.GetU()[(static_cast<std::size_t>(k) * n[1] + j) * (n[0] + 1) + i]) +
            std::abs(s.GetU()[(static_cast<std::size_t>(k) * n[1] + j) * (n[0] + 1) + i + 1]) +
            std::abs(s.GetV()[(static_cast<std::size_t>(k) * (n[1] + 1) + j) * n[0] + i]) +
            std::abs(s.GetV()[(static_cast<std::size_t>(k) * (n[1] + 1) + j + 1) * n[0] + i]) +
            std::abs(s.GetW()[(static_cast<std::size_t>(k) * n[1] + j) * n[0] + i]) +
            std::abs(s.GetW()[(static_cast<std::size_t>(k + 1) * n[1] + j) * n[0] + i]);
        }
        else if (k >= 11)
        {
          above += s.GetDensity()[c];
        }
      }
  EXPECT_EQ(inside, 0.0);
  EXPECT_EQ(faceFlow, 0.0);
  EXPECT_GT(above, 0.0) << "the plume passes the obstacle";
}

// A hot plume rises and spreads: the centre of mass climbs and the horizontal radius
// grows beyond the emitter's; its mass changes with the advection by a stated amount.
TEST(SmokeSolver, BuoyantPlumeRisesAndSpreads)
{
  SmokeParameters p = Small();
  p.VorticityConfinement = 0.5;
  p.SmagorinskyConstant = 0.15;
  SmokeSolver s(p);
  for (int step = 0; step < 4; ++step)
  {
    s.Step(0.05);
  }
  double h0 = 0.0, r0 = 0.0, top0 = 0.0;
  Moments(s, h0, r0, top0);
  for (int step = 0; step < 36; ++step)
  {
    const nimbus::SmokeStepReport r = s.Step(0.05);
    EXPECT_LT(r.DivergenceAfter, 1e-5 * std::max(r.DivergenceBefore, 1e-30) + 1e-9);
  }
  double h1 = 0.0, r1 = 0.0, top1 = 0.0;
  Moments(s, h1, r1, top1);
  std::printf("  after 0.2 s and 2 s: centre of mass %.2f -> %.2f m, radius %.2f -> %.2f m, "
              "top %.2f -> %.2f m\n",
    h0, h1, r0, r1, top0, top1);
  EXPECT_GT(top1, top0 + 2.0);
  EXPECT_GT(h1, h0 + 0.2);
  EXPECT_GT(r1, r0);
}

// The advection's mass change: a blob carried by a steady flow (no emitter, no
// buoyancy) keeps its total within the measured bound.
TEST(SmokeSolver, AdvectionMassChangeBounded)
{
  for (const auto scheme :
    { nimbus::SmokeAdvection::SemiLagrangian, nimbus::SmokeAdvection::MacCormack })
  {
    SmokeParameters p = Small(24, 24, 24);
    p.Emitters.clear();
    p.Advection = scheme;
    SmokeSolver s(p);
    std::vector<float> density(s.GetDensity().size(), 0.0f);
    const auto& n = p.Dimensions;
    for (int k = 0; k < n[2]; ++k)
      for (int j = 0; j < n[1]; ++j)
        for (int i = 0; i < n[0]; ++i)
        {
          const double r2 =
            (i - 8.0) * (i - 8.0) + (j - 12.0) * (j - 12.0) + (k - 12.0) * (k - 12.0);
          density[s.CellIndex(i, j, k)] = r2 < 16.0 ? static_cast<float>(1.0 - r2 / 16.0) : 0.0f;
        }
    // A swirl about the z axis through the centre, divergence-free on the faces.
    std::vector<float> u(s.GetU().size()), v(s.GetV().size());
    for (int k = 0; k < n[2]; ++k)
      for (int j = 0; j < n[1]; ++j)
        for (int i = 0; i <= n[0]; ++i)
        {
          u[(static_cast<std::size_t>(k) * n[1] + j) * (n[0] + 1) + i] =
            static_cast<float>(-(j + 0.5 - 12.0) * 0.1);
        }
    for (int k = 0; k < n[2]; ++k)
      for (int j = 0; j <= n[1]; ++j)
        for (int i = 0; i < n[0]; ++i)
        {
          v[(static_cast<std::size_t>(k) * (n[1] + 1) + j) * n[0] + i] =
            static_cast<float>((i + 0.5 - 12.0) * 0.1);
        }
    s.SetState(0.0, density, s.GetTemperature(), u, v, s.GetW());
    const double before = s.TotalSmoke();
    for (int step = 0; step < 20; ++step)
    {
      s.Step(0.25);
    }
    const double change = s.TotalSmoke() / before - 1.0;
    std::printf("  %s: mass change %.4f after 20 steps (half a radian of swirl)\n",
      scheme == nimbus::SmokeAdvection::MacCormack ? "MacCormack" : "semi-Lagrangian", change);
    // Measured: semi-Lagrangian -1.3 % (its trilinear samples smear and lose a little at
    // the edge), MacCormack +12.4 % (not conservative: its correction adds where the blob
    // is steep; the clamp keeps it bounded, not exact).
    if (scheme == nimbus::SmokeAdvection::SemiLagrangian)
    {
      EXPECT_LT(std::abs(change), 0.03);
    }
    else
    {
      EXPECT_LT(std::abs(change), 0.2);
    }
  }
}

// A time step far beyond the CFL limit is sub-stepped (never blows up); one beyond
// MaxSubsteps is refused and leaves the state as it was.
TEST(SmokeSolver, LargeStepsSubsteppedOrRefused)
{
  SmokeParameters p = Small();
  p.Emitters[0].Velocity = { { 0.0, 0.0, 4.0 } };
  SmokeSolver s(p);
  const nimbus::SmokeStepReport r = s.Step(0.5);
  EXPECT_GT(r.Substeps, 1);
  for (float d : s.GetDensity())
  {
    ASSERT_TRUE(std::isfinite(d));
  }
  const std::vector<float> before = s.GetDensity();
  EXPECT_THROW(s.Step(1e5), std::runtime_error);
  EXPECT_EQ(s.GetDensity(), before);
  EXPECT_THROW(s.Step(0.0), std::invalid_argument);
  EXPECT_THROW(s.Step(std::nan("")), std::invalid_argument);
}

// The same result with 1 and 3 threads.
TEST(SmokeSolver, IndependentOfThreads)
{
  SmokeParameters p = Small();
  p.VorticityConfinement = 0.3;
  p.Threads = 1;
  SmokeSolver one(p);
  p.Threads = 3;
  SmokeSolver three(p);
  for (int step = 0; step < 5; ++step)
  {
    one.Step(0.05);
    three.Step(0.05);
  }
  EXPECT_EQ(one.GetDensity(), three.GetDensity());
  EXPECT_EQ(one.GetW(), three.GetW());
}

// Every kind of bad parameter is refused with a message naming it.
TEST(SmokeSolver, BadParametersRefused)
{
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<std::pair<std::string, SmokeParameters>> cases;
  const auto add = [&](const std::string& words, auto change)
  {
    SmokeParameters p = Small();
    change(p);
    cases.emplace_back(words, p);
  };
  add("cells per axis", [](SmokeParameters& p) { p.Dimensions = { { 0, 16, 16 } }; });
  add("cells per axis", [](SmokeParameters& p) { p.Dimensions = { { 16, 1, 16 } }; });
  add("cells per axis", [](SmokeParameters& p) { p.Dimensions = { { 16, 16, 5000 } }; });
  add("more than", [](SmokeParameters& p) { p.Dimensions = { { 1024, 1024, 1024 } }; });
  add("cell size", [nan](SmokeParameters& p) { p.CellSizeMetres = nan; });
  add("cell size", [](SmokeParameters& p) { p.CellSizeMetres = 0.0; });
  add("origin", [inf](SmokeParameters& p) { p.Origin[1] = inf; });
  add("wind", [nan](SmokeParameters& p) { p.Wind[2] = nan; });
  add("Gravity", [](SmokeParameters& p) { p.Gravity = -1.0; });
  add("EddyViscosity", [nan](SmokeParameters& p) { p.EddyViscosity = nan; });
  add("AmbientTemperatureKelvin", [](SmokeParameters& p) { p.AmbientTemperatureKelvin = 0.0; });
  add("MaxCfl", [](SmokeParameters& p) { p.MaxCfl = 0.0; });
  add("emitter 0", [nan](SmokeParameters& p) { p.Emitters[0].Centre[0] = nan; });
  add("emitter 0", [](SmokeParameters& p) { p.Emitters[0].RadiusMetres = 0.0; });
  add("emitter 0", [inf](SmokeParameters& p) { p.Emitters[0].DensityPerSecond = inf; });
  add("emitter 0", [nan](SmokeParameters& p) { p.Emitters[0].Velocity[2] = nan; });
  add("emitter 0", [](SmokeParameters& p) { p.Emitters[0].TemperatureKelvin = -5.0; });
  add("obstacle mask", [](SmokeParameters& p) { p.Obstacles.assign(10, 1); });
  add("every cell", [](SmokeParameters& p) { p.Obstacles.assign(16 * 16 * 24, 1); });
  add("PressureSolver",
    [](SmokeParameters& p) { p.PressureSolver = static_cast<nimbus::SmokePressureSolver>(7); });
  add("SideBoundaries",
    [](SmokeParameters& p) { p.SideBoundaries = static_cast<nimbus::SmokeSideBoundaries>(3); });
  for (const auto& c : cases)
  {
    try
    {
      SmokeSolver s(c.second);
      ADD_FAILURE() << "accepted: " << c.first;
    }
    catch (const std::invalid_argument& e)
    {
      EXPECT_NE(std::string(e.what()).find(c.first), std::string::npos) << e.what();
    }
  }
}

// ---- The pressure solve (SmokePressure.h: MGPCG) ----

namespace
{
// Uniform in [-1, 1).
struct Lcg
{
  std::uint64_t State;
  double operator()()
  {
    this->State = this->State * 6364136223846793005ull + 1442695040888963407ull;
    return (this->State >> 11) * (1.0 / (1ull << 53)) * 2.0 - 1.0;
  }
};

// About `fraction` of the cells solid at random, plus a closed box of solid shell
// holding a cavity of fluid shut in on every side when the grid has room for one.
std::vector<std::uint8_t> RandomObstacles(
  const std::array<int, 3>& n, double fraction, std::uint64_t seed, bool cavity)
{
  Lcg random{ seed };
  std::vector<std::uint8_t> solid(static_cast<std::size_t>(n[0]) * n[1] * n[2], 0);
  for (auto& s : solid)
  {
    s = 0.5 * (random() + 1.0) < fraction ? 1 : 0;
  }
  if (cavity && n[0] >= 6 && n[1] >= 6 && n[2] >= 8)
  {
    for (int k = 1; k < 6; ++k)
      for (int j = 1; j < 6; ++j)
        for (int i = 1; i < 6; ++i)
        {
          const bool shell = i == 1 || i == 5 || j == 1 || j == 5 || k == 1 || k == 5;
          solid[(static_cast<std::size_t>(k) * n[1] + j) * n[0] + i] = shell ? 1 : 0;
        }
  }
  return solid;
}

double Dot(const std::vector<double>& a, const std::vector<double>& b)
{
  double sum = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i)
  {
    sum += a[i] * b[i];
  }
  return sum;
}

// Random face velocities (the solver zeroes those next to solids).
void RandomVelocity(SmokeSolver& s, std::uint64_t seed)
{
  Lcg random{ seed };
  std::vector<float> u(s.GetU().size()), v(s.GetV().size()), w(s.GetW().size());
  for (auto* f : { &u, &v, &w })
  {
    for (float& x : *f)
    {
      x = static_cast<float>(random());
    }
  }
  s.SetState(0.0, s.GetDensity(), s.GetTemperature(), u, v, w);
}
} // namespace

// The multigrid V-cycle is symmetric positive definite (what CG needs), with obstacles, a
// shut-in cavity and odd dimensions.
TEST(SmokePressure, VCycleSymmetricPositiveDefinite)
{
  for (const auto& n : { std::array<int, 3>{ { 13, 11, 17 } }, std::array<int, 3>{ { 8, 8, 8 } },
         std::array<int, 3>{ { 33, 20, 9 } }, std::array<int, 3>{ { 2, 2, 2 } } })
  {
    const std::vector<std::uint8_t> solid = RandomObstacles(n, 0.15, 5, true);
    nimbus::SmokePressure mg(n, solid, 2);
    Lcg random{ 11 };
    std::vector<double> a(solid.size()), b(solid.size()), ma, mb;
    for (std::size_t c = 0; c < solid.size(); ++c)
    {
      a[c] = solid[c] ? 0.0 : random();
      b[c] = solid[c] ? 0.0 : random();
    }
    mg.Precondition(a, ma);
    mg.Precondition(b, mb);
    const double ab = Dot(ma, b), ba = Dot(a, mb);
    std::printf("  %d x %d x %d: %zu levels, <Ma, b> %.15g, <a, Mb> %.15g, <Ma, a> %.4g\n", n[0],
      n[1], n[2], mg.NumberOfLevels(), ab, ba, Dot(ma, a));
    EXPECT_NEAR(ab, ba, 1e-12 * (std::abs(ab) + std::abs(ba)) + 1e-300);
    EXPECT_GT(Dot(ma, a), 0.0);
    EXPECT_GT(Dot(mb, b), 0.0);
  }
}

// MGPCG's iterations stay about constant as the grid grows (IC-CG's grow with it), and
// the residual it reports is the true one.
TEST(SmokePressure, IterationsAboutConstantWithTheGrid)
{
  std::vector<int> iterations;
  for (int size : { 16, 24, 32, 48, 64 })
  {
    const std::array<int, 3> n{ { size, size, size } };
    // A block in the middle (an obstacle), the open top, random right-hand side.
    std::vector<std::uint8_t> solid(static_cast<std::size_t>(size) * size * size, 0);
    for (int k = size / 4; k < size / 2; ++k)
      for (int j = size / 4; j < 3 * size / 4; ++j)
        for (int i = size / 3; i < 2 * size / 3; ++i)
        {
          solid[(static_cast<std::size_t>(k) * size + j) * size + i] = 1;
        }
    nimbus::SmokePressure mg(n, solid, 2);
    Lcg random{ 3 };
    std::vector<double> b(solid.size()), x(solid.size(), 0.0), ax;
    for (std::size_t c = 0; c < b.size(); ++c)
    {
      b[c] = solid[c] ? 0.0 : random();
    }
    const auto start = std::chrono::steady_clock::now();
    const nimbus::SmokePressure::Result r = mg.Solve(b, x, 1e-7, 500);
    const double ms =
      1e3 * std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    mg.Apply(x, ax);
    double rr = 0.0, bb = 0.0;
    for (std::size_t c = 0; c < b.size(); ++c)
    {
      rr += (b[c] - ax[c]) * (b[c] - ax[c]);
      bb += b[c] * b[c];
    }
    std::printf("  %d^3: %zu levels, %d MGPCG iterations, residual %.3g (true %.3g), %.1f ms\n",
      size, mg.NumberOfLevels(), r.Iterations, r.Residual, std::sqrt(rr / bb), ms);
    EXPECT_LT(r.Residual, 1e-7);
    EXPECT_NEAR(std::sqrt(rr / bb), r.Residual, 1e-9);
    iterations.push_back(r.Iterations);
  }
  // Measured (a random right-hand side, from 0, tolerance 1e-7): 7, 7, 8, 8, 9 iterations
  // at 16^3, 24^3, 32^3, 48^3, 64^3 (IC-CG in the solver: 58 at 32^3, 115 at 64^3).
  const int least = *std::min_element(iterations.begin(), iterations.end());
  const int most = *std::max_element(iterations.begin(), iterations.end());
  EXPECT_LE(most, least + 6);
  EXPECT_LE(most, 25);
}

// Multigrid and incomplete Cholesky project a random field the same way (within the
// tolerance), with obstacles and odd dimensions; both leave it divergence-free.
TEST(SmokePressure, MultigridMatchesIncompleteCholesky)
{
  SmokeParameters p = Small(13, 11, 17);
  p.Emitters.clear();
  p.Obstacles = RandomObstacles(p.Dimensions, 0.12, 21, false);
  p.PressureTolerance = 1e-10;
  SmokeSolver mg(p);
  p.PressureSolver = nimbus::SmokePressureSolver::IncompleteCholesky;
  SmokeSolver ic(p);
  RandomVelocity(mg, 8);
  RandomVelocity(ic, 8);
  const nimbus::SmokeStepReport a = mg.Step(1e-4), b = ic.Step(1e-4);
  std::printf("  multigrid: %d iterations, divergence %.3g -> %.3g; incomplete Cholesky: %d "
              "iterations, %.3g -> %.3g\n",
    a.PressureIterations, a.DivergenceBefore, a.DivergenceAfter, b.PressureIterations,
    b.DivergenceBefore, b.DivergenceAfter);
  EXPECT_EQ(a.DivergenceBefore, b.DivergenceBefore);
  EXPECT_LT(a.DivergenceAfter, 1e-7 * a.DivergenceBefore);
  EXPECT_LT(b.DivergenceAfter, 1e-7 * b.DivergenceBefore);
  const std::vector<double> pa = mg.GetPressureGuess(), pb = ic.GetPressureGuess();
  ASSERT_EQ(pa.size(), pb.size());
  double diff = 0.0, size = 0.0;
  for (std::size_t i = 0; i < pa.size(); ++i)
  {
    diff = std::max(diff, std::abs(pa[i] - pb[i]));
    size = std::max(size, std::abs(pb[i]));
  }
  double velocity = 0.0;
  for (const auto& f : { std::make_pair(&mg.GetU(), &ic.GetU()),
         std::make_pair(&mg.GetV(), &ic.GetV()), std::make_pair(&mg.GetW(), &ic.GetW()) })
  {
    for (std::size_t i = 0; i < f.first->size(); ++i)
    {
      velocity = std::max(velocity, static_cast<double>(std::abs((*f.first)[i] - (*f.second)[i])));
    }
  }
  std::printf(
    "  largest pressure difference %.3g (of %.3g), velocity %.3g m/s\n", diff, size, velocity);
  EXPECT_LT(diff, 1e-6 * size);
  EXPECT_LT(velocity, 1e-5); // the random field's faces are up to 1 m/s (float: 6e-8)

  // At the default tolerance too, with a shut-in cavity: divergence-free either way.
  p.PressureTolerance = 1e-7;
  p.Obstacles = RandomObstacles(p.Dimensions, 0.12, 22, true);
  p.PressureSolver = nimbus::SmokePressureSolver::Multigrid;
  SmokeSolver cavity(p);
  RandomVelocity(cavity, 9);
  const nimbus::SmokeStepReport c = cavity.Step(1e-4);
  std::printf("  with a cavity: %d iterations, divergence %.3g -> %.3g\n", c.PressureIterations,
    c.DivergenceBefore, c.DivergenceAfter);
  EXPECT_LT(c.DivergenceAfter, 1e-5 * c.DivergenceBefore);
}

namespace
{
// Runs `p` on 1, 2 and 3 threads for `steps` steps of 0.05 s and expects bit-identical
// pressure iterations, residuals, fields and pressure guesses.
void ExpectSameFlowOnThreads123(SmokeParameters p, int steps)
{
  std::vector<std::unique_ptr<SmokeSolver>> solvers;
  for (int threads : { 1, 2, 3 })
  {
    p.Threads = threads;
    solvers.emplace_back(new SmokeSolver(p));
  }
  std::vector<nimbus::SmokeStepReport> last(3);
  for (int step = 0; step < steps; ++step)
  {
    for (int t = 0; t < 3; ++t)
    {
      last[t] = solvers[t]->Step(0.05);
    }
  }
  std::printf(
    "  %d iterations, residual %.3g\n", last[0].PressureIterations, last[0].PressureResidual);
  for (int t = 1; t < 3; ++t)
  {
    EXPECT_EQ(last[t].PressureIterations, last[0].PressureIterations);
    EXPECT_EQ(last[t].PressureResidual, last[0].PressureResidual);
    EXPECT_EQ(solvers[t]->GetDensity(), solvers[0]->GetDensity());
    EXPECT_EQ(solvers[t]->GetTemperature(), solvers[0]->GetTemperature());
    EXPECT_EQ(solvers[t]->GetU(), solvers[0]->GetU());
    EXPECT_EQ(solvers[t]->GetV(), solvers[0]->GetV());
    EXPECT_EQ(solvers[t]->GetW(), solvers[0]->GetW());
    EXPECT_EQ(solvers[t]->GetPressureGuess(), solvers[0]->GetPressureGuess());
  }
}
} // namespace

// Threads 1, 2 and 3 give bit-identical flows with obstacles on a grid large enough for
// the multigrid's fine levels to run in parallel (odd dimensions).
TEST(SmokePressure, IndependentOfThreadsWithObstacles)
{
  SmokeParameters p = Small(41, 37, 45); // 68265 cells: level 0 runs in parallel
  p.VorticityConfinement = 0.3;
  p.Obstacles = RandomObstacles(p.Dimensions, 0.05, 31, true);
  ExpectSameFlowOnThreads123(p, 4);
}

// A run restored from a checkpoint (state and pressure guess) repeats the same
// iterations and the same flow, bit for bit.
TEST(SmokePressure, RestoredRunRepeatsItself)
{
  SmokeParameters p = Small(12, 12, 20);
  p.Obstacles = RandomObstacles(p.Dimensions, 0.05, 41, false);
  SmokeSolver s(p);
  for (int step = 0; step < 3; ++step)
  {
    s.Step(0.05);
  }
  const std::vector<float> density = s.GetDensity(), temperature = s.GetTemperature(), u = s.GetU(),
                           v = s.GetV(), w = s.GetW();
  const std::vector<double> guess = s.GetPressureGuess();
  const double time = s.GetTime();
  std::vector<int> first;
  for (int step = 0; step < 2; ++step)
  {
    first.push_back(s.Step(0.05).PressureIterations);
  }
  SmokeSolver restored(p);
  restored.SetState(time, density, temperature, u, v, w);
  restored.SetPressureGuess(guess);
  for (int step = 0; step < 2; ++step)
  {
    EXPECT_EQ(restored.Step(0.05).PressureIterations, first[static_cast<std::size_t>(step)]);
  }
  EXPECT_EQ(restored.GetU(), s.GetU());
  EXPECT_EQ(restored.GetW(), s.GetW());
  EXPECT_EQ(restored.GetDensity(), s.GetDensity());
  EXPECT_EQ(restored.GetPressureGuess(), s.GetPressureGuess());
  EXPECT_THROW(restored.SetPressureGuess(std::vector<double>(3, 0.0)), std::invalid_argument);
}

// ---- Open sides: the wind blows through the box ----

namespace
{
/// The mean downwind (x) and total speed of the air over the fluid cells below layer
/// `layers` (the cells' centre velocities).
void MeanAirBelow(const SmokeSolver& s, int layers, double& downwind, double& speed)
{
  const auto& n = s.GetParameters().Dimensions;
  const std::vector<float> velocity = s.CellVelocities();
  const std::vector<std::uint8_t>& solid = s.GetParameters().Obstacles;
  double u = 0.0, length = 0.0;
  int cells = 0;
  for (int k = 0; k < layers; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i)
      {
        const std::size_t c = s.CellIndex(i, j, k);
        if (!solid.empty() && solid[c])
        {
          continue;
        }
        const float* v = &velocity[3 * c];
        u += v[0];
        length += std::sqrt(double(v[0]) * v[0] + double(v[1]) * v[1] + double(v[2]) * v[2]);
        ++cells;
      }
  downwind = u / cells;
  speed = length / cells;
}

/// The smoke's density-weighted centre (x, y, z) [m from the origin].
std::array<double, 3> Centroid(const SmokeSolver& s)
{
  const auto& n = s.GetParameters().Dimensions;
  const double h = s.GetParameters().CellSizeMetres;
  std::array<double, 3> centre{ { 0.0, 0.0, 0.0 } };
  double mass = 0.0;
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i)
      {
        const double d = s.GetDensity()[s.CellIndex(i, j, k)];
        mass += d;
        centre[0] += d * (i + 0.5) * h;
        centre[1] += d * (j + 0.5) * h;
        centre[2] += d * (k + 0.5) * h;
      }
  for (double& x : centre)
  {
    x /= mass;
  }
  return centre;
}

/// Still air, a wind of 1.5 m/s along x taken at 3 /s, no smoke, no heat.
SmokeParameters Windy(nimbus::SmokeSideBoundaries sides)
{
  SmokeParameters p = Small(16, 16, 24); // 4 x 4 x 6 m
  p.Emitters.clear();
  p.Wind = { { 1.5, 0.0, 0.0 } };
  p.WindCoupling = 3.0;
  p.SideBoundaries = sides;
  return p;
}
} // namespace

// Which sides are open: Automatic opens them with wind (and a coupling), never without.
TEST(SmokeSides, AutomaticOpensThemWithWind)
{
  SmokeParameters p = Small();
  EXPECT_FALSE(nimbus::SmokeSidesOpen(p)); // the default: no wind
  p.Wind = { { 0.0, 2.0, 0.0 } };
  EXPECT_FALSE(nimbus::SmokeSidesOpen(p)) << "wind without coupling does nothing";
  p.WindCoupling = 0.5;
  EXPECT_TRUE(nimbus::SmokeSidesOpen(p));
  p.SideBoundaries = nimbus::SmokeSideBoundaries::Walls;
  EXPECT_FALSE(nimbus::SmokeSidesOpen(p));
  p.Wind = { { 0.0, 0.0, 0.0 } };
  p.SideBoundaries = nimbus::SmokeSideBoundaries::Open;
  EXPECT_TRUE(nimbus::SmokeSidesOpen(p));
  EXPECT_TRUE(SmokeSolver(p).GetSidesOpen());
}

// Without wind, Automatic is walls bit for bit (a calm run is what it was before open
// sides existed); with wind and coupling, it is Open bit for bit.
TEST(SmokeSides, AutomaticIsWallsWithoutWindAndOpenWithIt)
{
  SmokeParameters p = Small();
  p.VorticityConfinement = 0.3;
  p.SmagorinskyConstant = 0.15;
  p.WindCoupling = 0.5; // no wind: the drag toward 0 still acts
  SmokeSolver automatic(p);
  p.SideBoundaries = nimbus::SmokeSideBoundaries::Walls;
  SmokeSolver walls(p);
  p.Wind = { { 1.0, 0.5, 0.0 } };
  p.SideBoundaries = nimbus::SmokeSideBoundaries::Automatic;
  SmokeSolver windy(p);
  p.SideBoundaries = nimbus::SmokeSideBoundaries::Open;
  SmokeSolver open(p);
  EXPECT_FALSE(automatic.GetSidesOpen());
  EXPECT_TRUE(windy.GetSidesOpen());
  for (int step = 0; step < 5; ++step)
  {
    automatic.Step(0.05);
    walls.Step(0.05);
    windy.Step(0.05);
    open.Step(0.05);
  }
  EXPECT_EQ(automatic.GetDensity(), walls.GetDensity());
  EXPECT_EQ(automatic.GetU(), walls.GetU());
  EXPECT_EQ(automatic.GetV(), walls.GetV());
  EXPECT_EQ(automatic.GetW(), walls.GetW());
  EXPECT_EQ(automatic.GetPressureGuess(), walls.GetPressureGuess());
  EXPECT_EQ(windy.GetDensity(), open.GetDensity());
  EXPECT_EQ(windy.GetU(), open.GetU());
  EXPECT_EQ(windy.GetW(), open.GetW());
  EXPECT_NE(windy.GetU(), automatic.GetU());
}

// The defect open sides fix: a steady wind of 1.5 m/s (coupling 3 /s, no heat, no
// smoke) in a box whose sides are walls is (nearly) a gradient, and the projection takes
// it away; with open sides it blows through. After one second, the mean air velocity in
// the lower half of the box: close to the wind with open sides, far from it with walls.
TEST(SmokeSides, WindBlowsThroughOpenSides)
{
  double downwind[2], speed[2];
  for (int open = 0; open < 2; ++open)
  {
    SmokeSolver s(
      Windy(open ? nimbus::SmokeSideBoundaries::Open : nimbus::SmokeSideBoundaries::Walls));
    nimbus::SmokeStepReport r;
    for (int step = 0; step < 20; ++step)
    {
      r = s.Step(0.05);
    }
    MeanAirBelow(s, s.GetParameters().Dimensions[2] / 2, downwind[open], speed[open]);
    double top = 0.0, topSpeed = 0.0;
    MeanAirBelow(s, s.GetParameters().Dimensions[2], top, topSpeed);
    std::printf("  %s: after 1 s, mean air velocity below 3 m %.3f m/s downwind (speed %.3f), "
                "whole box %.3f m/s; divergence %.3g -> %.3g 1/s\n",
      open ? "open sides" : "walls", downwind[open], speed[open], top, r.DivergenceBefore,
      r.DivergenceAfter);
    // The air is nearly divergence-free before the projection already (open: 8e-3 1/s);
    // after it, the floor is the float faces' rounding (1.5 m/s x 6e-8 / 0.25 m: ~4e-7
    // 1/s; measured 2.0e-7).
    EXPECT_LE(r.DivergenceAfter, 1e-5 * r.DivergenceBefore + 1e-6);
  }
  // The wind is taken as 1.5 (1 - exp(-3 t)) m/s: 1.43 m/s after a second.
  EXPECT_NEAR(downwind[1], 1.5, 0.15);
  EXPECT_NEAR(speed[1], 1.5, 0.15);
  EXPECT_LT(std::abs(downwind[0]), 0.5) << "walls: the projection removes the wind";
}

// A hot plume in a wind of 1.5 m/s leans downwind: its smoke's centre lies metres
// downwind of the calm plume's (which stays above the emitter), and its upper part
// further still.
TEST(SmokeSides, HotPlumeLeansDownwind)
{
  std::array<double, 3> centre[3];
  double mass[3];
  const char* names[3] = { "calm", "wind, walls", "wind, open sides" };
  for (int c = 0; c < 3; ++c)
  {
    SmokeParameters p = Small(32, 16, 24); // 8 x 4 x 6 m
    p.Emitters[0].Centre = { { 1.5, 2.0, 0.75 } };
    p.VorticityConfinement = 0.3;
    p.SmagorinskyConstant = 0.15;
    if (c > 0)
    {
      p.Wind = { { 1.5, 0.0, 0.0 } };
      p.WindCoupling = 2.0;
      p.SideBoundaries =
        c == 1 ? nimbus::SmokeSideBoundaries::Walls : nimbus::SmokeSideBoundaries::Automatic;
    }
    SmokeSolver s(p);
    for (int step = 0; step < 40; ++step)
    {
      s.Step(0.05);
    }
    centre[c] = Centroid(s);
    mass[c] = s.TotalSmoke();
    std::printf("  %s: after 2 s the smoke's centre is at x %.2f m, z %.2f m (emitter at x "
                "1.5 m), %.3f density m^3 in the box\n",
      names[c], centre[c][0], centre[c][2], mass[c]);
  }
  EXPECT_NEAR(centre[0][0], 1.5, 0.25) << "the calm plume rises above its emitter";
  EXPECT_GT(centre[2][0], centre[0][0] + 1.0) << "the open-sided plume leans downwind";
  EXPECT_GT(centre[2][0], centre[1][0] + 0.5) << "more than with walls";
  EXPECT_LT(centre[2][2], centre[0][2]) << "a leaning plume rises less high";
}

// The projection with open sides and obstacles (solid cells on the sides too): the
// velocity is divergence-free in the fluid cells, the side faces of fluid cells carry
// flow (not zeroed), those of solid cells none; the multigrid and the incomplete
// Cholesky solves (their matrices assembled independently) agree; with a shut-in cavity
// too (no comparison there: a cavity's pressure is defined up to a constant), and for a
// plume in a wind among obstacles, every projection.
TEST(SmokeSides, OpenSidesDivergenceFreeWithObstacles)
{
  SmokeParameters p = Small(13, 11, 17);
  p.Emitters.clear();
  p.SideBoundaries = nimbus::SmokeSideBoundaries::Open;
  p.Obstacles = RandomObstacles(p.Dimensions, 0.12, 23, false);
  p.PressureTolerance = 1e-10;
  SmokeSolver mg(p);
  p.PressureSolver = nimbus::SmokePressureSolver::IncompleteCholesky;
  SmokeSolver ic(p);
  RandomVelocity(mg, 12);
  RandomVelocity(ic, 12);
  const nimbus::SmokeStepReport a = mg.Step(1e-4), b = ic.Step(1e-4);
  std::printf("  open sides, multigrid: %d iterations, divergence %.3g -> %.3g; incomplete "
              "Cholesky: %d iterations, %.3g -> %.3g\n",
    a.PressureIterations, a.DivergenceBefore, a.DivergenceAfter, b.PressureIterations,
    b.DivergenceBefore, b.DivergenceAfter);
  EXPECT_GT(a.DivergenceBefore, 1.0);
  EXPECT_LT(a.DivergenceAfter, 1e-7 * a.DivergenceBefore);
  EXPECT_LT(b.DivergenceAfter, 1e-7 * b.DivergenceBefore);
  const std::vector<double> pa = mg.GetPressureGuess(), pb = ic.GetPressureGuess();
  double diff = 0.0, size = 0.0;
  for (std::size_t i = 0; i < pa.size(); ++i)
  {
    diff = std::max(diff, std::abs(pa[i] - pb[i]));
    size = std::max(size, std::abs(pb[i]));
  }
  std::printf("  largest pressure difference %.3g (of %.3g)\n", diff, size);
  EXPECT_LT(diff, 1e-6 * size);

  // The side faces: free on fluid cells, 0 on solid ones.
  const auto& n = p.Dimensions;
  const auto solid = [&](int i, int j, int k) { return p.Obstacles[mg.CellIndex(i, j, k)] != 0; };
  double fluidFaces = 0.0, solidFaces = 0.0;
  for (int k = 0; k < n[2]; ++k)
  {
    for (int j = 0; j < n[1]; ++j)
      for (int i : { 0, n[0] })
      {
        const double u =
          std::abs(mg.GetU()[(static_cast<std::size_t>(k) * n[1] + j) * (n[0] + 1) + i]);
        (solid(i == 0 ? 0 : n[0] - 1, j, k) ? solidFaces : fluidFaces) += u;
      }
    for (int j : { 0, n[1] })
      for (int i = 0; i < n[0]; ++i)
      {
        const double v =
          std::abs(mg.GetV()[(static_cast<std::size_t>(k) * (n[1] + 1) + j) * n[0] + i]);
        (solid(i, j == 0 ? 0 : n[1] - 1, k) ? solidFaces : fluidFaces) += v;
      }
  }
  EXPECT_GT(fluidFaces, 1.0);
  EXPECT_EQ(solidFaces, 0.0);

  // A shut-in cavity, at the default tolerance.
  p.PressureTolerance = 1e-7;
  p.PressureSolver = nimbus::SmokePressureSolver::Multigrid;
  p.Obstacles = RandomObstacles(p.Dimensions, 0.12, 23, true);
  SmokeSolver cavity(p);
  RandomVelocity(cavity, 13);
  const nimbus::SmokeStepReport c = cavity.Step(1e-4);
  std::printf("  open sides with a cavity: %d iterations, divergence %.3g -> %.3g\n",
    c.PressureIterations, c.DivergenceBefore, c.DivergenceAfter);
  EXPECT_LT(c.DivergenceAfter, 1e-5 * c.DivergenceBefore);

  // At the default tolerance, a plume among the obstacles in a wind: every projection
  // divergence-free (relative 1e-5).
  p.PressureSolver = nimbus::SmokePressureSolver::Multigrid;
  p.PressureTolerance = 1e-7;
  p.SideBoundaries = nimbus::SmokeSideBoundaries::Automatic;
  p.Wind = { { 1.0, -0.7, 0.0 } };
  p.WindCoupling = 1.0;
  p.Obstacles = RandomObstacles(p.Dimensions, 0.05, 24, true);
  nimbus::SmokeEmitter e;
  e.Centre = { { 1.6, 1.4, 2.0 } };
  e.RadiusMetres = 0.6;
  e.DensityPerSecond = 2.0;
  e.TemperatureKelvin = 500.0;
  p.Emitters = { e };
  p.VorticityConfinement = 0.3;
  SmokeSolver plume(p);
  ASSERT_TRUE(plume.GetSidesOpen());
  double worst = 0.0;
  for (int step = 0; step < 20; ++step)
  {
    const nimbus::SmokeStepReport r = plume.Step(0.05);
    worst = std::max(worst, r.DivergenceAfter / std::max(r.DivergenceBefore, 1e-30));
  }
  std::printf("  a plume in the wind among obstacles: worst divergence after/before %.3g\n", worst);
  EXPECT_LE(worst, 1e-5);
}

// The pressure operator with open sides: A applied to a constant pressure is, per fluid
// cell, the number of its open faces (the top's and the sides'); the V-cycle stays
// symmetric positive definite; MGPCG's iterations stay as few as with walls.
TEST(SmokeSides, PressureOperatorWithOpenSides)
{
  const std::array<int, 3> n{ { 9, 7, 6 } };
  nimbus::SmokePressure mg(n, {}, 2, 2, true);
  std::vector<double> ones(static_cast<std::size_t>(n[0]) * n[1] * n[2], 1.0), y;
  mg.Apply(ones, y);
  int wrong = 0;
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i)
      {
        const int faces = (i == 0) + (i == n[0] - 1) + (j == 0) + (j == n[1] - 1) + (k == n[2] - 1);
        wrong += y[(static_cast<std::size_t>(k) * n[1] + j) * n[0] + i] != faces ? 1 : 0;
      }
  EXPECT_EQ(wrong, 0);

  for (const auto& dims : { std::array<int, 3>{ { 13, 11, 17 } },
         std::array<int, 3>{ { 33, 20, 9 } }, std::array<int, 3>{ { 2, 2, 2 } } })
  {
    const std::vector<std::uint8_t> solid = RandomObstacles(dims, 0.15, 6, true);
    nimbus::SmokePressure open(dims, solid, 2, 2, true);
    Lcg random{ 13 };
    std::vector<double> a(solid.size()), b(solid.size()), ma, mb;
    for (std::size_t c = 0; c < solid.size(); ++c)
    {
      a[c] = solid[c] ? 0.0 : random();
      b[c] = solid[c] ? 0.0 : random();
    }
    open.Precondition(a, ma);
    open.Precondition(b, mb);
    const double ab = Dot(ma, b), ba = Dot(a, mb);
    EXPECT_NEAR(ab, ba, 1e-12 * (std::abs(ab) + std::abs(ba)) + 1e-300);
    EXPECT_GT(Dot(ma, a), 0.0);
  }

  int iterations[2];
  for (int sides = 0; sides < 2; ++sides)
  {
    const int size = 48;
    const std::array<int, 3> cube{ { size, size, size } };
    std::vector<std::uint8_t> solid(static_cast<std::size_t>(size) * size * size, 0);
    for (int k = size / 4; k < size / 2; ++k)
      for (int j = size / 4; j < 3 * size / 4; ++j)
        for (int i = size / 3; i < 2 * size / 3; ++i)
        {
          solid[(static_cast<std::size_t>(k) * size + j) * size + i] = 1;
        }
    nimbus::SmokePressure solver(cube, solid, 2, 2, sides == 1);
    Lcg random{ 3 };
    std::vector<double> b(solid.size()), x(solid.size(), 0.0);
    for (std::size_t c = 0; c < b.size(); ++c)
    {
      b[c] = solid[c] ? 0.0 : random();
    }
    const nimbus::SmokePressure::Result r = solver.Solve(b, x, 1e-7, 500);
    EXPECT_LT(r.Residual, 1e-7);
    iterations[sides] = r.Iterations;
  }
  std::printf(
    "  48^3: %d MGPCG iterations with walls, %d with open sides\n", iterations[0], iterations[1]);
  EXPECT_LE(iterations[1], iterations[0] + 3);
}

// With open sides and wind, threads 1, 2 and 3 give bit-identical flows (a grid large
// enough for the multigrid's fine level to run in parallel, obstacles, odd dimensions).
TEST(SmokeSides, IndependentOfThreadsWithOpenSides)
{
  SmokeParameters p = Small(41, 37, 45);
  p.VorticityConfinement = 0.3;
  p.Wind = { { 1.5, 0.5, 0.0 } };
  p.WindCoupling = 2.0;
  p.Obstacles = RandomObstacles(p.Dimensions, 0.05, 32, true);
  p.Threads = 1;
  ASSERT_TRUE(SmokeSolver(p).GetSidesOpen());
  ExpectSameFlowOnThreads123(p, 3);
}

// ---- Obstacles from a closed surface (Voxelize.h) ----

namespace
{
struct Mesh
{
  std::vector<nimbus::Vector3> Points;
  std::vector<std::array<std::int64_t, 3>> Triangles;
};

// A UV sphere of radius r at c (closed: poles are single points).
Mesh MakeSphere(const nimbus::Vector3& c, double r, int rings, int segments)
{
  Mesh m;
  m.Points.push_back({ { c[0], c[1], c[2] + r } });
  for (int i = 1; i < rings; ++i)
  {
    const double theta = M_PI * i / rings;
    for (int j = 0; j < segments; ++j)
    {
      const double phi = 2.0 * M_PI * j / segments;
      m.Points.push_back({ { c[0] + r * std::sin(theta) * std::cos(phi),
        c[1] + r * std::sin(theta) * std::sin(phi), c[2] + r * std::cos(theta) } });
    }
  }
  m.Points.push_back({ { c[0], c[1], c[2] - r } });
  const std::int64_t south = static_cast<std::int64_t>(m.Points.size()) - 1;
  auto ring = [&](int i, int j) { return 1 + (i - 1) * segments + (j % segments); };
  for (int j = 0; j < segments; ++j)
  {
    m.Triangles.push_back({ 0, ring(1, j), ring(1, j + 1) });
    m.Triangles.push_back({ south, ring(rings - 1, j + 1), ring(rings - 1, j) });
    for (int i = 1; i + 1 < rings; ++i)
    {
      m.Triangles.push_back({ ring(i, j), ring(i + 1, j), ring(i + 1, j + 1) });
      m.Triangles.push_back({ ring(i, j), ring(i + 1, j + 1), ring(i, j + 1) });
    }
  }
  return m;
}

// A box with corners lo and hi, rotated by angle about the axis through its centre.
Mesh MakeBox(const nimbus::Vector3& lo, const nimbus::Vector3& hi,
  const nimbus::Vector3& axis = { { 0, 0, 1 } }, double angle = 0.0)
{
  Mesh m;
  const nimbus::Vector3 centre{ { (lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, (lo[2] + hi[2]) / 2 } };
  const double n = nimbus::Length(axis);
  const nimbus::Vector3 u{ { axis[0] / n, axis[1] / n, axis[2] / n } };
  for (int corner = 0; corner < 8; ++corner)
  {
    const nimbus::Vector3 p{ { (corner & 1 ? hi[0] : lo[0]) - centre[0],
      (corner & 2 ? hi[1] : lo[1]) - centre[1], (corner & 4 ? hi[2] : lo[2]) - centre[2] } };
    // Rodrigues' rotation.
    const nimbus::Vector3 cross = nimbus::Cross(u, p);
    const double dot = nimbus::Dot(u, p);
    nimbus::Vector3 q;
    for (int k = 0; k < 3; ++k)
    {
      q[k] = centre[k] + p[k] * std::cos(angle) + cross[k] * std::sin(angle) +
        u[k] * dot * (1 - std::cos(angle));
    }
    m.Points.push_back(q);
  }
  const int faces[6][4] = { { 0, 2, 3, 1 }, { 4, 5, 7, 6 }, { 0, 1, 5, 4 }, { 2, 6, 7, 3 },
    { 0, 4, 6, 2 }, { 1, 3, 7, 5 } };
  for (const auto& f : faces)
  {
    m.Triangles.push_back({ f[0], f[1], f[2] });
    m.Triangles.push_back({ f[0], f[2], f[3] });
  }
  return m;
}

std::size_t CountSolid(const std::vector<std::uint8_t>& solid)
{
  std::size_t n = 0;
  for (const auto s : solid)
  {
    n += s;
  }
  return n;
}
} // namespace

// A box whose faces lie on cell faces and a box whose faces lie on cell centres' planes
// both give exactly the cells inside; a sphere's solid volume is its volume within the
// staircase error.
TEST(Voxelize, BoxesAndSphere)
{
  const std::array<int, 3> dims{ { 20, 20, 20 } };
  const nimbus::Vector3 origin{ { -5, -5, 0 } };
  const double h = 0.5;
  std::vector<std::uint8_t> solid;
  std::string error;
  // Faces on cell faces: cells 4..11 in x, 6..9 in y, 2..14 in z.
  Mesh box = MakeBox({ { -3, -2, 1 } }, { { 1, 0, 7.5 } });
  ASSERT_TRUE(
    nimbus::VoxelizeClosedSurface(box.Points, box.Triangles, dims, origin, h, solid, error))
    << error;
  EXPECT_EQ(CountSolid(solid), 8u * 4u * 13u);
  EXPECT_EQ(solid[(2 * 20 + 6) * 20 + 4], 1);
  EXPECT_EQ(solid[(14 * 20 + 9) * 20 + 11], 1);
  EXPECT_EQ(solid[(15 * 20 + 9) * 20 + 11], 0);
  EXPECT_EQ(solid[(14 * 20 + 9) * 20 + 12], 0);
  // Faces through cell centres (the worst case for a parity count: each face's plane
  // holds a layer of centres). The columns' offset (+x, +y) and the half-open rule in z
  // take the centres on the low x, y and z faces and leave those on the high ones:
  // 4 x 2 x 6 cells.
  Mesh centred = MakeBox({ { -2.75, -1.75, 1.25 } }, { { -0.75, -0.75, 4.25 } });
  ASSERT_TRUE(
    nimbus::VoxelizeClosedSurface(centred.Points, centred.Triangles, dims, origin, h, solid, error))
    << error;
  EXPECT_EQ(CountSolid(solid), 4u * 2u * 6u);

  // Sphere of radius 3 m in cells of 0.25 m: volume 113.1 m^3.
  const std::array<int, 3> fine{ { 32, 32, 32 } };
  const nimbus::Vector3 fineOrigin{ { -4, -4, -4 } };
  Mesh sphere = MakeSphere({ { 0.1, -0.2, 0.05 } }, 3.0, 48, 96);
  ASSERT_TRUE(nimbus::VoxelizeClosedSurface(
    sphere.Points, sphere.Triangles, fine, fineOrigin, 0.25, solid, error))
    << error;
  const double volume = static_cast<double>(CountSolid(solid)) * 0.25 * 0.25 * 0.25;
  const double exact = 4.0 / 3.0 * M_PI * 27.0;
  // Measured: 113.33 m^3 against 113.10 (+0.2 %).
  std::printf("sphere: solid volume %.2f m^3, exact %.2f m^3\n", volume, exact);
  EXPECT_NEAR(volume / exact, 1.0, 0.02) << volume << " vs " << exact;
}

// Many boxes turned by random angles about random axes: always closed, never an error,
// and their solid volume within the staircase error of the box's.
TEST(Voxelize, RotatedBoxesAlwaysClosed)
{
  std::mt19937 random(17);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const std::array<int, 3> dims{ { 24, 24, 24 } };
  const nimbus::Vector3 origin{ { -3, -3, -3 } };
  const double h = 0.25;
  double worst = 0.0;
  for (int trial = 0; trial < 200; ++trial)
  {
    const nimbus::Vector3 axis{ { unit(random), unit(random), unit(random) + 1e-3 } };
    Mesh box = MakeBox({ { -1.5, -1.0, -0.75 } }, { { 1.5, 1.0, 0.75 } }, axis, 3.0 * unit(random));
    std::vector<std::uint8_t> solid;
    std::string error;
    ASSERT_TRUE(
      nimbus::VoxelizeClosedSurface(box.Points, box.Triangles, dims, origin, h, solid, error))
      << "trial " << trial << ": " << error;
    const double volume = static_cast<double>(CountSolid(solid)) * h * h * h;
    worst = std::max(worst, std::abs(volume / 9.0 - 1.0));
  }
  // The staircase of a 3 x 2 x 1.5 m box in 0.25 m cells: measured worst 0.062.
  EXPECT_LT(worst, 0.08) << worst;
  std::printf("rotated boxes: worst volume error %.3f\n", worst);
}

// Open surfaces, bad indices and non-finite points are refused with a reason.
TEST(Voxelize, BadSurfacesRefused)
{
  const std::array<int, 3> dims{ { 8, 8, 8 } };
  const nimbus::Vector3 origin{ { -2, -2, -2 } };
  std::vector<std::uint8_t> solid;
  std::string error;
  Mesh open = MakeBox({ { -1, -1, -1 } }, { { 1, 1, 1 } });
  open.Triangles.pop_back(); // a hole
  EXPECT_FALSE(
    nimbus::VoxelizeClosedSurface(open.Points, open.Triangles, dims, origin, 0.5, solid, error));
  EXPECT_NE(error.find("not closed"), std::string::npos) << error;
  EXPECT_TRUE(solid.empty());

  Mesh bad = MakeBox({ { -1, -1, -1 } }, { { 1, 1, 1 } });
  bad.Triangles[3][1] = 99;
  EXPECT_FALSE(
    nimbus::VoxelizeClosedSurface(bad.Points, bad.Triangles, dims, origin, 0.5, solid, error));
  EXPECT_NE(error.find("index 99"), std::string::npos) << error;
  bad.Triangles[3][1] = -1;
  EXPECT_FALSE(
    nimbus::VoxelizeClosedSurface(bad.Points, bad.Triangles, dims, origin, 0.5, solid, error));

  for (const double v :
    { std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity() })
  {
    Mesh nan = MakeBox({ { -1, -1, -1 } }, { { 1, 1, 1 } });
    nan.Points[5][2] = v;
    EXPECT_FALSE(
      nimbus::VoxelizeClosedSurface(nan.Points, nan.Triangles, dims, origin, 0.5, solid, error));
    EXPECT_NE(error.find("non-finite"), std::string::npos) << error;
    EXPECT_FALSE(
      nimbus::VoxelizeClosedSurface(open.Points, open.Triangles, dims, origin, v, solid, error));
  }
  EXPECT_FALSE(nimbus::VoxelizeClosedSurface(
    open.Points, open.Triangles, { { 0, 8, 8 } }, origin, 0.5, solid, error));
  // An empty surface is fine: nothing solid.
  EXPECT_TRUE(nimbus::VoxelizeClosedSurface({}, {}, dims, origin, 0.5, solid, error));
  EXPECT_EQ(CountSolid(solid), 0u);
}
