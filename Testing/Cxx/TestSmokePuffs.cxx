// Smoke puffs (Filters/Core/SmokePuffs.h, 002 §4): metaballs carried by the solver's flow.
// They move with the air (a wind-driven flow: mean displacement against the mean air
// velocity; a rigid swirl: each puff back on its circle), are emitted at the stated rate
// (the fraction carried) inside their emitter, grow keeping their smoke, are splatted
// with the metaball's analytic integral, never sit in an obstacle or outside the grid,
// do not depend on the thread count, repeat exactly from a checkpoint, and bad parameters
// are refused with their name. Bounds: from the values printed.
#include "SmokePuffs.h"

#include "Metaballs.h"
#include "SmokeSolver.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace
{
using nimbus::Puff;
using nimbus::PuffParameters;
using nimbus::PuffState;
using nimbus::SmokeParameters;
using nimbus::SmokePuffs;
using nimbus::SmokeSolver;
using nimbus::Vector3;

// The grid of TestSmokeSolver: 16 x 16 x 24 cells of 0.25 m, one hot emitter low in the
// middle.
SmokeParameters Small()
{
  SmokeParameters p;
  p.Dimensions = { { 16, 16, 24 } };
  p.CellSizeMetres = 0.25;
  p.Threads = 2;
  nimbus::SmokeEmitter e;
  e.Centre = { { 2.0, 2.0, 0.75 } };
  e.RadiusMetres = 0.6;
  e.DensityPerSecond = 2.0;
  e.TemperatureKelvin = 600.0;
  p.Emitters = { e };
  return p;
}

PuffParameters Puffs()
{
  PuffParameters p;
  p.Threads = 2;
  return p;
}

// In the grid and in no solid cell (the test's own check, not the library's).
bool InFluid(const Vector3& x, const SmokeParameters& s)
{
  int c[3];
  for (int a = 0; a < 3; ++a)
  {
    const double g = (x[a] - s.Origin[a]) / s.CellSizeMetres;
    if (!(g >= 0.0 && g < s.Dimensions[a]))
    {
      return false;
    }
    c[a] = static_cast<int>(std::floor(g));
  }
  return s.Obstacles.empty() ||
    s.Obstacles[(static_cast<std::size_t>(c[2]) * s.Dimensions[1] + c[1]) * s.Dimensions[0] +
      c[0]] == 0;
}

bool SamePuffs(const std::vector<Puff>& a, const std::vector<Puff>& b)
{
  return a.size() == b.size() &&
    (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(Puff)) == 0);
}

// Puffs on a regular block of points (radius 0.3 m, density 1, age 0).
std::vector<Puff> Block(const Vector3& low, const Vector3& high, int perAxis)
{
  std::vector<Puff> puffs;
  for (int k = 0; k < perAxis; ++k)
    for (int j = 0; j < perAxis; ++j)
      for (int i = 0; i < perAxis; ++i)
      {
        Puff puff;
        const double t[3] = { (i + 0.5) / perAxis, (j + 0.5) / perAxis, (k + 0.5) / perAxis };
        for (int a = 0; a < 3; ++a)
        {
          puff.Position[a] = low[a] + t[a] * (high[a] - low[a]);
        }
        puff.Radius = 0.3;
        puff.Density = 1.0;
        puffs.push_back(puff);
      }
  return puffs;
}
} // namespace

// VelocityAt: the face values at the faces' centres, trilinear between them, finite and
// clamped outside the grid.
TEST(SmokePuffs, VelocityAtSamplesTheFaces)
{
  SmokeParameters p = Small();
  p.Emitters.clear();
  p.Origin = { { -1.0, 2.0, 0.5 } };
  SmokeSolver s(p);
  std::vector<float> u(s.GetU().size()), v(s.GetV().size()), w(s.GetW().size());
  std::uint64_t state = 7;
  for (auto* f : { &u, &v, &w })
  {
    for (float& x : *f)
    {
      state = state * 6364136223846793005ull + 1442695040888963407ull;
      x = static_cast<float>((state >> 40) * (1.0 / (1ull << 24)) - 0.5);
    }
  }
  s.SetState(0.0, s.GetDensity(), s.GetTemperature(), u, v, w);
  const auto& n = p.Dimensions;
  const double h = p.CellSizeMetres;
  const Vector3& o = p.Origin;
  // Interior faces (the walls' are zeroed by SetState).
  const int i = 5, j = 7, k = 11;
  const std::size_t iu = (static_cast<std::size_t>(k) * n[1] + j) * (n[0] + 1) + i;
  const std::size_t iv = (static_cast<std::size_t>(k) * (n[1] + 1) + j) * n[0] + i;
  const std::size_t iw = (static_cast<std::size_t>(k) * n[1] + j) * n[0] + i;
  EXPECT_EQ(s.VelocityAt({ { o[0] + h * i, o[1] + h * (j + 0.5), o[2] + h * (k + 0.5) } })[0],
    static_cast<double>(s.GetU()[iu]));
  EXPECT_EQ(s.VelocityAt({ { o[0] + h * (i + 0.5), o[1] + h * j, o[2] + h * (k + 0.5) } })[1],
    static_cast<double>(s.GetV()[iv]));
  EXPECT_EQ(s.VelocityAt({ { o[0] + h * (i + 0.5), o[1] + h * (j + 0.5), o[2] + h * k } })[2],
    static_cast<double>(s.GetW()[iw]));
  // Half-way between two u faces along x: their mean.
  EXPECT_NEAR(
    s.VelocityAt({ { o[0] + h * (i + 0.5), o[1] + h * (j + 0.5), o[2] + h * (k + 0.5) } })[0],
    0.5 * (s.GetU()[iu] + s.GetU()[iu + 1]), 1e-7);
  const double inf = std::numeric_limits<double>::infinity();
  for (const Vector3& far : { Vector3{ { -1e300, 0.0, 0.0 } }, Vector3{ { 0.0, inf, -inf } } })
  {
    const Vector3 velocity = s.VelocityAt(far);
    EXPECT_TRUE(nimbus::IsFinite(velocity));
  }
  EXPECT_THROW(s.VelocityAt({ { 0.0, std::nan(""), 0.0 } }), std::invalid_argument);
}

// A wind-driven flow (drag toward 1.5 m/s in x, no buoyancy): puffs placed in it are
// carried, their mean displacement equal to the mean air velocity at their positions
// times the time; with no emitter nothing is emitted. (The sides are walls on purpose, for
// a flow that is not uniform: in a box walled in x a uniform drag is mostly a pressure
// gradient, which the projection removes: the air moves where the open top lets it,
// 0.4-0.6 m/s at 4-5 m of the 6 m measured, 0.03 m/s at 1 m. So the puffs start high.
// With open sides, the default with wind, it blows through uniformly: 0.75 m in 0.5 s.)
TEST(SmokePuffs, CarriedByTheAir)
{
  SmokeParameters p = Small();
  p.Emitters.clear();
  p.Gravity = 0.0;
  p.Wind = { { 1.5, 0.0, 0.0 } };
  p.WindCoupling = 20.0;
  p.SideBoundaries = nimbus::SmokeSideBoundaries::Walls;
  SmokeSolver s(p);
  const double dt = 0.05;
  for (int step = 0; step < 5; ++step)
  {
    s.Step(dt);
  }
  SmokePuffs empty(Puffs());
  SmokePuffs puffs(Puffs());
  PuffState start;
  start.Puffs = Block({ { 1.5, 1.5, 4.0 } }, { { 2.5, 2.5, 5.0 } }, 5);
  puffs.SetState(start);
  Vector3 expected{ { 0, 0, 0 } };
  const int steps = 10;
  for (int step = 0; step < steps; ++step)
  {
    s.Step(dt);
    // The mean air velocity at the puffs, at the start and the end of their step (the
    // trapezoid rule in time along each path).
    Vector3 before{ { 0, 0, 0 } };
    for (const Puff& puff : puffs.GetPuffs())
    {
      const Vector3 v = s.VelocityAt(puff.Position);
      for (int a = 0; a < 3; ++a)
      {
        before[a] += v[a] / puffs.GetPuffs().size();
      }
    }
    puffs.Step(dt, s);
    empty.Step(dt, s);
    ASSERT_EQ(puffs.GetPuffs().size(), start.Puffs.size()) << "a puff left the block's region";
    Vector3 after{ { 0, 0, 0 } };
    for (const Puff& puff : puffs.GetPuffs())
    {
      const Vector3 v = s.VelocityAt(puff.Position);
      for (int a = 0; a < 3; ++a)
      {
        after[a] += v[a] / puffs.GetPuffs().size();
      }
    }
    for (int a = 0; a < 3; ++a)
    {
      expected[a] += 0.5 * (before[a] + after[a]) * dt;
    }
  }
  EXPECT_TRUE(empty.GetPuffs().empty()) << "no emitter, no puffs";
  Vector3 moved{ { 0, 0, 0 } };
  for (std::size_t i = 0; i < start.Puffs.size(); ++i)
  {
    for (int a = 0; a < 3; ++a)
    {
      moved[a] +=
        (puffs.GetPuffs()[i].Position[a] - start.Puffs[i].Position[a]) / start.Puffs.size();
    }
  }
  const double error = std::sqrt((moved[0] - expected[0]) * (moved[0] - expected[0]) +
    (moved[1] - expected[1]) * (moved[1] - expected[1]) +
    (moved[2] - expected[2]) * (moved[2] - expected[2]));
  std::printf("  in %.2f s: mean displacement (%.4f, %.4f, %.4f) m, mean air velocity x time "
              "(%.4f, %.4f, %.4f) m, difference %.2g m (%.2g of it)\n",
    steps * dt, moved[0], moved[1], moved[2], expected[0], expected[1], expected[2], error,
    error / nimbus::Length(expected));
  EXPECT_GT(expected[0], 0.15) << "the air moves";
  // Measured: 7.3e-5 of it (the trapezoid rule in time against the puffs' midpoint
  // steps); a first-order (Euler) step gives 1.1e-2.
  EXPECT_LT(error, 1e-3 * nimbus::Length(expected));
}

// A rigid swirl about a vertical axis set on the faces (linear in x and y, so trilinear
// sampling is exact away from the walls): every puff stays on its circle and turns by
// omega t.
TEST(SmokePuffs, FollowARigidSwirl)
{
  SmokeParameters p = Small();
  p.Emitters.clear();
  SmokeSolver s(p);
  const auto& n = p.Dimensions;
  const double h = p.CellSizeMetres, omega = 0.5, cx = 2.0, cy = 2.0;
  std::vector<float> u(s.GetU().size()), v(s.GetV().size());
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i <= n[0]; ++i)
      {
        u[(static_cast<std::size_t>(k) * n[1] + j) * (n[0] + 1) + i] =
          static_cast<float>(-omega * ((j + 0.5) * h - cy));
      }
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j <= n[1]; ++j)
      for (int i = 0; i < n[0]; ++i)
      {
        v[(static_cast<std::size_t>(k) * (n[1] + 1) + j) * n[0] + i] =
          static_cast<float>(omega * ((i + 0.5) * h - cx));
      }
  s.SetState(0.0, s.GetDensity(), s.GetTemperature(), u, v, s.GetW());
  SmokePuffs puffs(Puffs());
  PuffState start;
  start.Puffs = Block({ { 1.0, 1.0, 2.0 } }, { { 3.0, 3.0, 4.0 } }, 4);
  puffs.SetState(start);
  const double dt = 0.1;
  const int steps = 20;
  for (int step = 0; step < steps; ++step)
  {
    puffs.Step(dt, s);
  }
  ASSERT_EQ(puffs.GetPuffs().size(), start.Puffs.size());
  double worst = 0.0;
  for (std::size_t i = 0; i < start.Puffs.size(); ++i)
  {
    const Vector3& a = start.Puffs[i].Position;
    const double angle = omega * steps * dt;
    const double x = cx + std::cos(angle) * (a[0] - cx) - std::sin(angle) * (a[1] - cy);
    const double y = cy + std::sin(angle) * (a[0] - cx) + std::cos(angle) * (a[1] - cy);
    const Vector3& b = puffs.GetPuffs()[i].Position;
    worst = std::max(worst, std::hypot(b[0] - x, b[1] - y));
    EXPECT_EQ(b[2], a[2]);
  }
  std::printf(
    "  1 rad of swirl in %d steps: worst distance from the exact point %.2g m\n", steps, worst);
  // Measured: 4.4e-4 m (the midpoint rule's error, r (omega dt)^3 / 6 per step); an Euler
  // step gives 2.7e-2 m.
  EXPECT_LT(worst, 1e-3);
}

// Emission: rate x time per emitter within one puff whatever the step (the fraction
// carried), inside the emitter's sphere and uniform in its volume; an emitter that only
// heats emits none; MaxPuffs caps the count; the lifetime removes the old.
TEST(SmokePuffs, EmissionRate)
{
  SmokeParameters sp = Small();
  sp.Emitters[0].RadiusMetres = 0.5;
  nimbus::SmokeEmitter second = sp.Emitters[0];
  second.Centre = { { 3.0, 1.5, 4.0 } };
  nimbus::SmokeEmitter heatOnly = sp.Emitters[0];
  heatOnly.Centre = { { 1.0, 3.0, 2.0 } };
  heatOnly.DensityPerSecond = 0.0;
  sp.Emitters = { sp.Emitters[0], heatOnly, second };
  SmokeSolver s(sp); // at rest: the puffs stay where they are born
  PuffParameters pp = Puffs();
  pp.PuffsPerSecond = 37.3;
  pp.GrowthPerSecond = 0.5;
  SmokePuffs puffs(pp);
  const double dt = 0.013;
  int worst = 0;
  for (int step = 1; step <= 100; ++step)
  {
    puffs.Step(dt, s);
    const double due = pp.PuffsPerSecond * dt * step;
    const int count = static_cast<int>(puffs.GetPuffs().size());
    ASSERT_EQ(count % 2, 0);
    EXPECT_LE(std::abs(count / 2 - due), 1.0) << "step " << step;
    worst = std::max(worst, static_cast<int>(std::ceil(std::abs(count / 2 - due))));
  }
  std::printf("  %zu puffs from 2 emitters in 1.3 s at 37.3 per second (48.49 each)\n",
    puffs.GetPuffs().size());
  double massChange = 0.0;
  const Puff newborn{ { { 0, 0, 0 } }, pp.RadiusMetres, pp.DensityPerPuff, 0.0 };
  for (const Puff& puff : puffs.GetPuffs())
  {
    const bool inFirst =
      nimbus::Length(
        { { puff.Position[0] - 2.0, puff.Position[1] - 2.0, puff.Position[2] - 0.75 } }) <= 0.5;
    const bool inSecond =
      nimbus::Length(
        { { puff.Position[0] - 3.0, puff.Position[1] - 1.5, puff.Position[2] - 4.0 } }) <= 0.5;
    EXPECT_TRUE(inFirst || inSecond);
    EXPECT_GE(puff.Age, 0.0);
    EXPECT_LE(puff.Age, 1.3);
    EXPECT_DOUBLE_EQ(puff.Radius, pp.RadiusMetres * (1.0 + pp.GrowthPerSecond * puff.Age));
    massChange = std::max(massChange, std::abs(PuffMass(puff) / PuffMass(newborn) - 1.0));
  }
  EXPECT_LT(massChange, 1e-12) << "growing keeps the smoke";

  // Uniform in the volume: (r / R)^3 is uniform in [0, 1), mean 1/2; and centred.
  pp.PuffsPerSecond = 4000.0;
  sp.Emitters = { sp.Emitters[0] };
  SmokeSolver one(sp);
  SmokePuffs many(pp);
  many.Step(1.0, one);
  double cubes = 0.0;
  Vector3 mean{ { 0, 0, 0 } };
  for (const Puff& puff : many.GetPuffs())
  {
    const Vector3 d{ { puff.Position[0] - 2.0, puff.Position[1] - 2.0, puff.Position[2] - 0.75 } };
    cubes += std::pow(nimbus::Length(d) / 0.5, 3) / many.GetPuffs().size();
    for (int a = 0; a < 3; ++a)
    {
      mean[a] += d[a] / many.GetPuffs().size();
    }
  }
  std::printf("  %zu puffs in one step: mean (r/R)^3 %.4f (1/2), mean offset (%.4f, %.4f, "
              "%.4f) m\n",
    many.GetPuffs().size(), cubes, mean[0], mean[1], mean[2]);
  EXPECT_EQ(many.GetPuffs().size(), 4000u);
  EXPECT_NEAR(cubes, 0.5, 0.02); // 4 standard errors (0.29 / sqrt(4000) = 0.0046)
  EXPECT_LT(nimbus::Length(mean), 0.03);

  // MaxPuffs caps; the lifetime removes: a steady count of rate x lifetime.
  pp.PuffsPerSecond = 100.0;
  pp.MaxPuffs = 10;
  SmokePuffs capped(pp);
  pp.MaxPuffs = 100000;
  pp.LifetimeSeconds = 0.5;
  SmokePuffs shortLived(pp);
  for (int step = 0; step < 50; ++step)
  {
    capped.Step(0.04, one);
    shortLived.Step(0.04, one);
  }
  EXPECT_EQ(capped.GetPuffs().size(), 10u);
  EXPECT_LE(std::abs(static_cast<double>(shortLived.GetPuffs().size()) - 50.0), 1.0);
  for (const Puff& puff : shortLived.GetPuffs())
  {
    EXPECT_LE(puff.Age, 0.5);
  }
}

// The splat's integral (sum x spacing^3) against the metaballs' analytic integral,
// 736 pi / 2835 R^3 per unit density, for puffs inside the grid; a puff's centre on a
// grid point holds its density.
TEST(SmokePuffs, SplatIntegral)
{
  // The closed form against a quadrature of Wyvill's falloff over r.
  double radial = 0.0;
  const int m = 200000;
  for (int i = 0; i < m; ++i)
  {
    const double r = (i + 0.5) / m;
    radial += 4.0 * nimbus::kPi * r * r * nimbus::WyvillFalloff(r * r, 1.0) / m;
  }
  EXPECT_NEAR(radial, nimbus::WyvillFalloffIntegral(1.0), 1e-9);

  SmokePuffs puffs(Puffs());
  PuffState state;
  std::uint64_t seed = 3;
  const auto uniform = [&seed]()
  {
    seed = seed * 6364136223846793005ull + 1442695040888963407ull;
    return (seed >> 11) * 0x1.0p-53;
  };
  double mass = 0.0;
  for (int i = 0; i < 200; ++i)
  {
    Puff puff;
    puff.Radius = 0.3 + 0.3 * uniform();
    puff.Density = 0.5 + uniform();
    for (int a = 0; a < 3; ++a)
    {
      puff.Position[a] = 0.6 + 2.8 * uniform(); // the grid spans [0, 4] m
    }
    state.Puffs.push_back(puff);
    mass += nimbus::PuffMass(puff);
  }
  puffs.SetState(state);
  for (const double spacing : { 0.2, 0.1, 0.05 })
  {
    const int points = static_cast<int>(std::lround(4.0 / spacing)) + 1;
    const std::vector<float> grid =
      puffs.Splat({ { points, points, points } }, { { 0.0, 0.0, 0.0 } }, spacing, 2);
    double sum = 0.0;
    for (float d : grid)
    {
      sum += d;
    }
    const double error = sum * spacing * spacing * spacing / mass - 1.0;
    std::printf("  spacing %.2f m (radii %.1f-%.1f spacings): splat integral / analytic - 1 = "
                "%.2g\n",
      spacing, 0.3 / spacing, 0.6 / spacing, error);
    // Measured: -5.2e-4, -9.7e-6, -6.9e-7.
    EXPECT_LT(std::abs(error), spacing > 0.15 ? 2e-3 : (spacing > 0.07 ? 5e-5 : 5e-6));
  }

  PuffState one;
  one.Puffs = { Puff{ { { 1.0, 1.5, 0.5 } }, 0.4, 0.75, 0.0 } };
  puffs.SetState(one);
  const std::vector<float> grid = puffs.Splat({ { 9, 9, 9 } }, { { 0.0, 0.5, -0.5 } }, 0.25, 1);
  EXPECT_EQ(grid[(static_cast<std::size_t>(4) * 9 + 4) * 9 + 4], 0.75f);
  EXPECT_EQ(grid[(static_cast<std::size_t>(4) * 9 + 4) * 9 + 6], 0.0f) << "beyond the radius";
}

// A rising plume past an obstacle: after every step no puff is in a solid cell or outside
// the grid, and the puffs rise and pass the block.
TEST(SmokePuffs, NeverInObstaclesOrOutside)
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
  PuffParameters pp = Puffs();
  pp.PuffsPerSecond = 300.0;
  SmokePuffs puffs(pp);
  std::size_t bad = 0, most = 0;
  double highest = 0.0;
  for (int step = 0; step < 60; ++step)
  {
    s.Step(0.05);
    puffs.Step(0.05, s);
    for (const Puff& puff : puffs.GetPuffs())
    {
      bad += InFluid(puff.Position, p) ? 0 : 1;
      highest = std::max(highest, puff.Position[2]);
    }
    most = std::max(most, puffs.GetPuffs().size());
  }
  std::printf("  3 s of plume: %zu puffs now (%zu at most), the highest at %.2f m (the block: "
              "2-2.75 m)\n",
    puffs.GetPuffs().size(), most, highest);
  // Without the removal, 55 (puff, step) pairs are in the block or outside.
  EXPECT_EQ(bad, 0u);
  EXPECT_GT(puffs.GetPuffs().size(), 100u);
  EXPECT_GT(highest, 3.0) << "the puffs rise past the block (its top: 2.75 m)";
}

// The step and the splat do not depend on the thread count (bit-identical).
TEST(SmokePuffs, IndependentOfThreads)
{
  SmokeParameters p = Small();
  p.VorticityConfinement = 0.3;
  SmokeSolver s(p);
  std::vector<SmokePuffs> runs;
  for (const int threads : { 1, 2, 3 })
  {
    PuffParameters pp = Puffs();
    pp.PuffsPerSecond = 2000.0;
    pp.Threads = threads;
    runs.emplace_back(pp);
  }
  for (int step = 0; step < 10; ++step)
  {
    s.Step(0.05);
    for (SmokePuffs& run : runs)
    {
      run.Step(0.05, s);
    }
    EXPECT_TRUE(SamePuffs(runs[0].GetPuffs(), runs[1].GetPuffs())) << "step " << step;
    EXPECT_TRUE(SamePuffs(runs[0].GetPuffs(), runs[2].GetPuffs())) << "step " << step;
  }
  EXPECT_GT(runs[0].GetPuffs().size(), 500u);
  const std::vector<float> one = runs[0].Splat({ { 33, 33, 49 } }, { { 0, 0, 0 } }, 0.125, 1);
  for (const int threads : { 2, 3, 0 })
  {
    const std::vector<float> other =
      runs[0].Splat({ { 33, 33, 49 } }, { { 0, 0, 0 } }, 0.125, threads);
    ASSERT_EQ(other.size(), one.size());
    EXPECT_EQ(std::memcmp(one.data(), other.data(), one.size() * sizeof(float)), 0)
      << threads << " threads";
  }
}

// A checkpoint (the state into a fresh object) repeats the next steps exactly; an object
// that did not restore it does not.
TEST(SmokePuffs, CheckpointRepeats)
{
  SmokeParameters p = Small();
  SmokeSolver s(p);
  PuffParameters pp = Puffs();
  pp.PuffsPerSecond = 123.4;
  SmokePuffs original(pp);
  for (int step = 0; step < 8; ++step)
  {
    s.Step(0.05);
    original.Step(0.05, s);
  }
  const PuffState saved = original.GetState();
  SmokePuffs restored(pp);
  restored.SetState(saved);
  SmokePuffs fresh(pp); // the same puffs but not the carry nor the step count
  PuffState puffsOnly;
  puffsOnly.Puffs = saved.Puffs;
  fresh.SetState(puffsOnly);
  for (int step = 0; step < 8; ++step)
  {
    s.Step(0.05);
    original.Step(0.05, s);
    restored.Step(0.05, s);
    fresh.Step(0.05, s);
  }
  EXPECT_TRUE(SamePuffs(original.GetPuffs(), restored.GetPuffs()));
  EXPECT_EQ(original.GetState().EmissionCarry, restored.GetState().EmissionCarry);
  EXPECT_EQ(original.GetState().Steps, restored.GetState().Steps);
  EXPECT_FALSE(SamePuffs(original.GetPuffs(), fresh.GetPuffs()));
}

// Bad parameters of every kind, refused with the parameter's name; bad states, steps and
// splat grids refused too.
TEST(SmokePuffs, BadParametersRefused)
{
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<std::pair<std::string, PuffParameters>> cases;
  struct Field
  {
    const char* Name;
    double PuffParameters::*Member;
    bool Positive;
  };
  const Field fields[] = { { "PuffsPerSecond", &PuffParameters::PuffsPerSecond, false },
    { "RadiusMetres", &PuffParameters::RadiusMetres, true },
    { "GrowthPerSecond", &PuffParameters::GrowthPerSecond, false },
    { "DensityPerPuff", &PuffParameters::DensityPerPuff, false },
    { "LifetimeSeconds", &PuffParameters::LifetimeSeconds, true } };
  for (const Field& f : fields)
  {
    std::vector<double> values = { nan, -nan, inf, -inf, -1.0, -1e-300,
      -std::numeric_limits<double>::max(), std::numeric_limits<double>::max(), 1e10 };
    if (f.Positive)
    {
      values.push_back(0.0);
      values.push_back(-0.0);
    }
    for (double value : values)
    {
      PuffParameters p = Puffs();
      p.*f.Member = value;
      cases.emplace_back(f.Name, p);
    }
  }
  for (int value :
    { 0, -1, std::numeric_limits<int>::min(), (1 << 26) + 1, std::numeric_limits<int>::max() })
  {
    PuffParameters p = Puffs();
    p.MaxPuffs = value;
    cases.emplace_back("MaxPuffs", p);
  }
  for (int value : { -1, std::numeric_limits<int>::min() })
  {
    PuffParameters p = Puffs();
    p.Threads = value;
    cases.emplace_back("Threads", p);
  }
  std::printf("  %zu bad parameter sets\n", cases.size());
  for (const auto& c : cases)
  {
    EXPECT_NE(nimbus::CheckPuffParameters(c.second).find(c.first), std::string::npos)
      << c.first << ": " << nimbus::CheckPuffParameters(c.second);
    try
    {
      SmokePuffs puffs(c.second);
      ADD_FAILURE() << "accepted: " << c.first;
    }
    catch (const std::invalid_argument& e)
    {
      EXPECT_NE(std::string(e.what()).find(c.first), std::string::npos) << e.what();
    }
  }
  EXPECT_EQ(nimbus::CheckPuffParameters(Puffs()), "");

  // States, steps and grids.
  SmokePuffs puffs(Puffs());
  const Puff good{ { { 1, 1, 1 } }, 0.3, 1.0, 0.0 };
  std::vector<PuffState> states(8);
  for (PuffState& state : states)
  {
    state.Puffs = { good };
  }
  states[0].Puffs[0].Position[1] = nan;
  states[1].Puffs[0].Radius = 0.0;
  states[2].Puffs[0].Density = -1.0;
  states[3].Puffs[0].Age = inf;
  states[4].EmissionCarry = 1.0;
  states[5].EmissionCarry = nan;
  states[6].Puffs.assign(100001, good);
  states[7].Puffs[0].Radius = nan;
  for (const PuffState& state : states)
  {
    EXPECT_THROW(puffs.SetState(state), std::invalid_argument);
  }
  EXPECT_TRUE(puffs.GetPuffs().empty()) << "a refused state changes nothing";
  SmokeParameters sp = Small();
  SmokeSolver s(sp);
  for (double dt : { 0.0, -1.0, nan, inf, 2e6 })
  {
    EXPECT_THROW(puffs.Step(dt, s), std::invalid_argument);
  }
  EXPECT_THROW(puffs.Splat({ { 0, 4, 4 } }, { { 0, 0, 0 } }, 0.1, 1), std::invalid_argument);
  EXPECT_THROW(puffs.Splat({ { 4, 4, 5000 } }, { { 0, 0, 0 } }, 0.1, 1), std::invalid_argument);
  EXPECT_THROW(
    puffs.Splat({ { 4096, 4096, 100 } }, { { 0, 0, 0 } }, 0.1, 1), std::invalid_argument);
  EXPECT_THROW(puffs.Splat({ { 4, 4, 4 } }, { { 0, 0, 0 } }, 0.0, 1), std::invalid_argument);
  EXPECT_THROW(puffs.Splat({ { 4, 4, 4 } }, { { 0, 0, 0 } }, nan, 1), std::invalid_argument);
  EXPECT_THROW(puffs.Splat({ { 4, 4, 4 } }, { { 0, inf, 0 } }, 0.1, 1), std::invalid_argument);
}
