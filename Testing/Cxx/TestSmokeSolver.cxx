// The smoke solver (Filters/Core/SmokeSolver.h, issue 17): the projection leaves the
// velocity divergence-free, nothing flows through obstacles, a hot plume rises and
// spreads, the advection's mass change is stated and bounded, a large time step is
// sub-stepped (and too large a one refused), threads do not change the result, and bad
// parameters of every kind are refused with a message. Bounds: from the values printed.
#include "SmokeSolver.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
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
