// Unit tests of the cloud cellular automaton core (002 §3; rules in shared/papers/README.md):
// hand-worked cases of each rule, the f_act neighbourhood, boundaries, wind and shear,
// randomness statistics, determinism, thread-count independence, smoothing, extremes.
#include "CloudAutomaton.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <tuple>
#include <vector>

using nimbus::CloudAutomaton;
using nimbus::CloudAutomatonParameters;
using nimbus::CloudBoundary;
using nimbus::ProbabilityField;
using Field = nimbus::CloudAutomaton::Field;

namespace
{
// Deterministic rules only: no supply, no extinction, empty start.
CloudAutomatonParameters Quiet(int nx, int ny, int nz, CloudBoundary boundary)
{
  CloudAutomatonParameters p;
  p.Dimensions[0] = nx;
  p.Dimensions[1] = ny;
  p.Dimensions[2] = nz;
  p.Extinction = ProbabilityField::Uniform(0.0);
  p.HumiditySupply = ProbabilityField::Uniform(0.0);
  p.ActivationSupply = ProbabilityField::Uniform(0.0);
  p.InitialHumidity = 0.0;
  p.InitialActivation = 0.0;
  p.Boundary = boundary;
  p.NumberOfThreads = 1;
  return p;
}

// A busy configuration: all processes, wind and shear, 2-D and 3-D probability fields.
CloudAutomatonParameters Busy(int threads)
{
  CloudAutomatonParameters p;
  p.Dimensions[0] = 70;
  p.Dimensions[1] = 33;
  p.Dimensions[2] = 13;
  p.Seed = 12345;
  std::vector<float> plane(70 * 33), volume(70 * 33 * 13);
  for (std::size_t i = 0; i < plane.size(); ++i)
  {
    plane[i] = static_cast<float>(0.02 * (i % 7));
  }
  for (std::size_t i = 0; i < volume.size(); ++i)
  {
    volume[i] = static_cast<float>(0.001 * (i % 11));
  }
  p.Extinction = ProbabilityField::Uniform(0.07);
  p.HumiditySupply = ProbabilityField::Plane(plane);
  p.ActivationSupply = ProbabilityField::Volume(volume);
  p.InitialHumidity = 0.4;
  p.InitialActivation = 0.01;
  p.Wind[0] = 0.7;
  p.Wind[1] = -0.3;
  p.Shear[0] = 0.15;
  p.Shear[1] = 0.05;
  p.NumberOfThreads = threads;
  return p;
}

bool SameState(const nimbus::CloudAutomatonState& a, const nimbus::CloudAutomatonState& b)
{
  return a.Step == b.Step && a.Hum == b.Hum && a.Act == b.Act && a.Cld == b.Cld;
}
}

// --- growth rules (hand-worked) ---------------------------------------------------------

TEST(CloudAutomatonRules, HandWorkedTwoCells)
{
  // Step 0: hum at A = (5,5,5), act at B = (6,5,5), nothing else.
  CloudAutomaton ca(Quiet(12, 12, 12, CloudBoundary::Open));
  ca.Set(Field::Hum, 5, 5, 5, true);
  ca.Set(Field::Act, 6, 5, 5, true);
  ca.Step();
  // A: act' = !act & hum & f_act (B is its x+1 neighbour) = 1; hum' = hum & !act = 1.
  // B: cld' = cld | act = 1, act' = 0 (act was set), hum' = 0.
  EXPECT_TRUE(ca.Get(Field::Act, 5, 5, 5));
  EXPECT_TRUE(ca.Get(Field::Hum, 5, 5, 5));
  EXPECT_FALSE(ca.Get(Field::Cld, 5, 5, 5));
  EXPECT_TRUE(ca.Get(Field::Cld, 6, 5, 5));
  EXPECT_FALSE(ca.Get(Field::Act, 6, 5, 5));
  EXPECT_EQ(ca.Count(Field::Act), 1u);
  EXPECT_EQ(ca.Count(Field::Hum), 1u);
  EXPECT_EQ(ca.Count(Field::Cld), 1u);
  ca.Step();
  // A: hum' = hum & !act = 0, cld' = 1, act' = 0. B unchanged (cld stays, p_ext = 0).
  EXPECT_FALSE(ca.Get(Field::Hum, 5, 5, 5));
  EXPECT_FALSE(ca.Get(Field::Act, 5, 5, 5));
  EXPECT_TRUE(ca.Get(Field::Cld, 5, 5, 5));
  EXPECT_TRUE(ca.Get(Field::Cld, 6, 5, 5));
  EXPECT_EQ(ca.Count(Field::Act), 0u);
  EXPECT_EQ(ca.Count(Field::Hum), 0u);
  EXPECT_EQ(ca.Count(Field::Cld), 2u);
  ca.Step(); // a fixed point without supply or extinction
  EXPECT_EQ(ca.Count(Field::Cld), 2u);
  EXPECT_EQ(ca.GetStep(), 3);
}

TEST(CloudAutomatonRules, ActNeedsHumidityAndIsNotSelfSustaining)
{
  CloudAutomaton ca(Quiet(8, 8, 8, CloudBoundary::Open));
  ca.Set(Field::Act, 3, 3, 3, true); // act next to a dry cell: nothing spreads
  ca.Step();
  EXPECT_EQ(ca.Count(Field::Act), 0u);
  EXPECT_EQ(ca.Count(Field::Cld), 1u);
  // hum and act in the same cell: act' = !act... = 0, hum' = 0, cld' = 1.
  ca.Clear();
  ca.Set(Field::Act, 3, 3, 3, true);
  ca.Set(Field::Hum, 3, 3, 3, true);
  ca.Step();
  EXPECT_EQ(ca.Count(Field::Act), 0u);
  EXPECT_EQ(ca.Count(Field::Hum), 0u);
  EXPECT_TRUE(ca.Get(Field::Cld, 3, 3, 3));
}

// Every offset of the f_act neighbourhood triggers, nothing else does (the papers README's list:
// (+-1,0,0), (+-2,0,0), (0,+-1,0), (0,+-2,0), (0,0,+1), (0,0,-1), (0,0,-2)).
TEST(CloudAutomatonRules, ActivationNeighbourhood)
{
  struct Case
  {
    int dx, dy, dz;
    bool triggers;
  };
  const Case cases[] = { { 1, 0, 0, true }, { -1, 0, 0, true }, { 2, 0, 0, true },
    { -2, 0, 0, true }, { 0, 1, 0, true }, { 0, -1, 0, true }, { 0, 2, 0, true },
    { 0, -2, 0, true }, { 0, 0, 1, true }, { 0, 0, -1, true }, { 0, 0, -2, true },
    { 0, 0, 2, false }, { 3, 0, 0, false }, { -3, 0, 0, false }, { 0, 3, 0, false },
    { 0, 0, -3, false }, { 1, 1, 0, false }, { 1, 0, 1, false }, { 0, 1, -1, false },
    { 0, 0, 0, false } };
  // 130 cells along x: the centre x = 64 sits at bit 0 of the second word, so the
  // x neighbours cross word boundaries; the same again at x = 63 (bit 63).
  for (const int cx : { 64, 63, 5 })
  {
    for (const Case& c : cases)
    {
      CloudAutomaton ca(Quiet(130, 9, 9, CloudBoundary::Open));
      ca.Set(Field::Hum, cx, 4, 4, true);
      ca.Set(Field::Act, cx + c.dx, 4 + c.dy, 4 + c.dz, true);
      ca.Step();
      EXPECT_EQ(ca.Get(Field::Act, cx, 4, 4), c.triggers && !(c.dx == 0 && c.dy == 0 && c.dz == 0))
        << "x " << cx << " offset (" << c.dx << ", " << c.dy << ", " << c.dz << ")";
    }
  }
}

TEST(CloudAutomatonRules, PeriodicAndOpenBoundaries)
{
  // nx = 70: x wraps from 69 to 0 across the second (partial) word.
  struct Case
  {
    int hx, hy, hz, ax, ay, az;
    bool periodicTriggers;
  };
  const Case cases[] = {
    { 0, 3, 3, 69, 3, 3, true },  // x - 1 wraps
    { 0, 3, 3, 68, 3, 3, true },  // x - 2 wraps
    { 1, 3, 3, 69, 3, 3, true },  // x - 2 wraps
    { 69, 3, 3, 0, 3, 3, true },  // x + 1 wraps
    { 68, 3, 3, 0, 3, 3, true },  // x + 2 wraps
    { 69, 3, 3, 1, 3, 3, true },  // x + 2 wraps
    { 67, 3, 3, 0, 3, 3, false }, // distance 3
    { 5, 0, 3, 5, 7, 3, true },   // y - 1 wraps (ny = 8)
    { 5, 1, 3, 5, 7, 3, true },   // y - 2 wraps
    { 5, 6, 3, 5, 0, 3, true },   // y + 2 wraps
    { 5, 3, 0, 5, 3, 7, false },  // z never wraps (nz = 8)
    { 5, 3, 7, 5, 3, 0, false },
  };
  for (const Case& c : cases)
  {
    for (const auto boundary : { CloudBoundary::Open, CloudBoundary::Periodic })
    {
      CloudAutomaton ca(Quiet(70, 8, 8, boundary));
      ca.Set(Field::Hum, c.hx, c.hy, c.hz, true);
      ca.Set(Field::Act, c.ax, c.ay, c.az, true);
      ca.Step();
      const bool expected = boundary == CloudBoundary::Periodic && c.periodicTriggers;
      EXPECT_EQ(ca.Get(Field::Act, c.hx, c.hy, c.hz), expected)
        << (boundary == CloudBoundary::Periodic ? "periodic" : "open") << " hum (" << c.hx << ","
        << c.hy << "," << c.hz << ") act (" << c.ax << "," << c.ay << "," << c.az << ")";
    }
  }
}

TEST(CloudAutomatonRules, ActivationFrontSpreadsTwoCellsPerStep)
{
  // A line of humid cells along x with act at x = 0: f_act reaches 2 cells, and a cell
  // that was act cannot be act again, so the front moves 2 cells every 2 steps... the
  // hand-worked sequence: step 1 act at {1, 2}; step 2 act at {3, 4}; step 3 {5, 6}.
  CloudAutomaton ca(Quiet(20, 1, 1, CloudBoundary::Open));
  for (int x = 1; x < 20; ++x)
  {
    ca.Set(Field::Hum, x, 0, 0, true);
  }
  ca.Set(Field::Act, 0, 0, 0, true);
  for (int step = 1; step <= 3; ++step)
  {
    ca.Step();
    for (int x = 0; x < 20; ++x)
    {
      const bool act = x == 2 * step - 1 || x == 2 * step;
      EXPECT_EQ(ca.Get(Field::Act, x, 0, 0), act) << "step " << step << " x " << x;
      // cld: every cell that was act before this step
      EXPECT_EQ(ca.Get(Field::Cld, x, 0, 0), x <= 2 * step - 2) << "step " << step << " x " << x;
    }
  }
}

// --- extinction and supply ----------------------------------------------------------------

TEST(CloudAutomatonSupply, ProbabilitiesZeroAndOne)
{
  auto p = Quiet(70, 5, 3, CloudBoundary::Open);
  const std::size_t cells = 70 * 5 * 3;
  p.HumiditySupply = ProbabilityField::Uniform(1.0);
  p.ActivationSupply = ProbabilityField::Uniform(1.0);
  CloudAutomaton ca(p);
  ca.Step();
  // Every cell (and no padding bit) set.
  EXPECT_EQ(ca.Count(Field::Hum), cells);
  EXPECT_EQ(ca.Count(Field::Act), cells);
  EXPECT_EQ(ca.Count(Field::Cld), 0u);
  ca.Step(); // act everywhere -> cld everywhere (p_ext = 0 keeps it)
  EXPECT_EQ(ca.Count(Field::Cld), cells);

  p.Extinction = ProbabilityField::Uniform(1.0);
  CloudAutomaton dying(p);
  dying.StepTo(5);
  EXPECT_EQ(dying.Count(Field::Cld), 0u); // p_ext = 1 removes every cloud cell each step
}

TEST(CloudAutomatonSupply, FrequenciesMatchProbabilities)
{
  // One step from an empty state: hum = (rnd < p_hum), act = (rnd < p_act); from a full
  // cloud with no act: cld survives with probability 1 - p_ext. Binomial: 5 sigma bounds.
  const int nx = 200, ny = 100, nz = 10;
  const double n = static_cast<double>(nx) * ny * nz;
  for (const bool asField : { false, true })
  {
    for (const double prob : { 0.3, 0.01, 0.0007 })
    {
      auto p = Quiet(nx, ny, nz, CloudBoundary::Periodic);
      p.Seed = 99;
      if (asField)
      {
        p.HumiditySupply = ProbabilityField::Plane(std::vector<float>(nx * ny, float(prob)));
        p.ActivationSupply =
          ProbabilityField::Volume(std::vector<float>(nx * ny * nz, float(prob)));
        p.Extinction = ProbabilityField::Plane(std::vector<float>(nx * ny, float(prob)));
      }
      else
      {
        p.HumiditySupply = ProbabilityField::Uniform(prob);
        p.ActivationSupply = ProbabilityField::Uniform(prob);
        p.Extinction = ProbabilityField::Uniform(prob);
      }
      const double pf = asField ? double(float(prob)) : prob;
      const double sigma = std::sqrt(n * pf * (1 - pf));
      CloudAutomaton ca(p);
      ca.Step();
      EXPECT_NEAR(ca.Count(Field::Hum), n * pf, 5 * sigma) << prob << " field " << asField;
      EXPECT_NEAR(ca.Count(Field::Act), n * pf, 5 * sigma) << prob << " field " << asField;
      // Extinction: a full cloud and no act at step 0, so after one step
      // cld = (cld OR act) AND NOT (rnd < p_ext) survives in a fraction 1 - p_ext.
      CloudAutomaton full(p);
      for (int z = 0; z < nz; ++z)
        for (int y = 0; y < ny; ++y)
          for (int x = 0; x < nx; ++x)
            full.Set(Field::Cld, x, y, z, true);
      full.Step();
      EXPECT_NEAR(full.Count(Field::Cld), n * (1 - pf), 5 * sigma) << prob;
    }
  }
}

TEST(CloudAutomatonSupply, SpatialFieldsShapeWhereThingsHappen)
{
  // A 2-D map: p_hum = 1 on the left half, 0 on the right, at every height.
  const int nx = 90, ny = 6, nz = 4;
  auto p = Quiet(nx, ny, nz, CloudBoundary::Open);
  std::vector<float> map(nx * ny, 0.0f);
  for (int y = 0; y < ny; ++y)
    for (int x = 0; x < nx / 2; ++x)
      map[x + nx * y] = 1.0f;
  p.HumiditySupply = ProbabilityField::Plane(map);
  // A 3-D field: p_act = 1 in one cell only.
  std::vector<float> volume(nx * ny * nz, 0.0f);
  volume[70 + nx * (2 + ny * 3)] = 1.0f;
  p.ActivationSupply = ProbabilityField::Volume(volume);
  CloudAutomaton ca(p);
  ca.Step();
  for (int z = 0; z < nz; ++z)
    for (int y = 0; y < ny; ++y)
      for (int x = 0; x < nx; ++x)
      {
        ASSERT_EQ(ca.Get(Field::Hum, x, y, z), x < nx / 2) << x << " " << y << " " << z;
        ASSERT_EQ(ca.Get(Field::Act, x, y, z), x == 70 && y == 2 && z == 3);
      }
}

// --- wind ------------------------------------------------------------------------------------

TEST(CloudAutomatonWind, WholeCellShiftsAddUpExactly)
{
  // Hand-worked: v = 0.5 -> 0, 1, 0, 1; v = -0.5 -> -1, 0, -1, 0; v = 2.25 -> 2, 2, 2, 3.
  EXPECT_EQ(nimbus::WindShift(0.5, 0), 0);
  EXPECT_EQ(nimbus::WindShift(0.5, 1), 1);
  EXPECT_EQ(nimbus::WindShift(-0.5, 0), -1);
  EXPECT_EQ(nimbus::WindShift(-0.5, 1), 0);
  const int expected[] = { 2, 2, 2, 3 };
  for (int n = 0; n < 4; ++n)
  {
    EXPECT_EQ(nimbus::WindShift(2.25, n), expected[n]);
  }
  for (const double v : { 0.1, 0.7, -0.3, 1.0 / 3.0, -2.6, 5.0 })
  {
    std::int64_t total = 0;
    for (int n = 0; n < 1000; ++n)
    {
      total += nimbus::WindShift(v, n);
    }
    EXPECT_EQ(total, static_cast<std::int64_t>(std::floor(v * 1000))) << v;
  }
}

TEST(CloudAutomatonWind, FieldsMoveWithTheWind)
{
  // Quiet rules: the only change is the shift. nx = 130 so shifts cross words.
  const int nx = 130, ny = 11, nz = 3;
  const std::vector<std::tuple<int, int, int>> cells = { { 0, 0, 0 }, { 63, 5, 1 }, { 64, 10, 2 },
    { 129, 3, 1 }, { 127, 0, 0 } };
  for (const auto boundary : { CloudBoundary::Periodic, CloudBoundary::Open })
  {
    for (const auto& wind :
      std::vector<std::pair<int, int>>{ { 3, -2 }, { -67, 1 }, { 0, 4 }, { 200, 0 } })
    {
      auto p = Quiet(nx, ny, nz, boundary);
      p.Wind[0] = wind.first;
      p.Wind[1] = wind.second;
      CloudAutomaton ca(p);
      for (const auto& c : cells)
      {
        // One field per cell kind, to check all three move.
        ca.Set(Field::Cld, std::get<0>(c), std::get<1>(c), std::get<2>(c), true);
      }
      ca.Set(Field::Hum, 10, 4, 1, true); // isolated hum moves too
      ca.Step();
      std::size_t inside = 0;
      for (const auto& c : cells)
      {
        long long x = std::get<0>(c) + wind.first, y = std::get<1>(c) + wind.second;
        if (boundary == CloudBoundary::Periodic)
        {
          x = ((x % nx) + nx) % nx;
          y = ((y % ny) + ny) % ny;
        }
        else if (x < 0 || x >= nx || y < 0 || y >= ny)
        {
          continue; // blown out of an open grid
        }
        ++inside;
        EXPECT_TRUE(ca.Get(Field::Cld, int(x), int(y), std::get<2>(c)))
          << "wind (" << wind.first << "," << wind.second << ") cell " << std::get<0>(c);
      }
      EXPECT_EQ(ca.Count(Field::Cld), inside);
      long long hx = 10 + wind.first, hy = 4 + wind.second;
      if (boundary == CloudBoundary::Periodic)
      {
        hx = ((hx % nx) + nx) % nx;
        hy = ((hy % ny) + ny) % ny;
      }
      const bool hIn = hx >= 0 && hx < nx && hy >= 0 && hy < ny;
      EXPECT_EQ(ca.Count(Field::Hum), hIn ? 1u : 0u);
      if (hIn)
      {
        EXPECT_TRUE(ca.Get(Field::Hum, int(hx), int(hy), 1));
      }
    }
  }
}

TEST(CloudAutomatonWind, ShearMovesHigherLayersFaster)
{
  // Wind 0.5 cell/step at the ground plus 1 cell/step per layer: layer z moves
  // floor((0.5 + z) n) cells in n steps.
  const int nx = 100, ny = 4, nz = 5;
  auto p = Quiet(nx, ny, nz, CloudBoundary::Periodic);
  p.Wind[0] = 0.5;
  p.Shear[0] = 1.0;
  CloudAutomaton ca(p);
  for (int z = 0; z < nz; ++z)
  {
    ca.Set(Field::Cld, 10, 2, z, true);
  }
  ca.StepTo(3);
  for (int z = 0; z < nz; ++z)
  {
    const int x = (10 + static_cast<int>(std::floor((0.5 + z) * 3))) % nx;
    EXPECT_TRUE(ca.Get(Field::Cld, x, 2, z)) << "layer " << z;
  }
  EXPECT_EQ(ca.Count(Field::Cld), static_cast<std::size_t>(nz));
}

// --- determinism -------------------------------------------------------------------------

TEST(CloudAutomatonDeterminism, SameSeedSameStateDifferentSeedDiffers)
{
  CloudAutomaton a(Busy(1)), b(Busy(1));
  a.StepTo(25);
  b.StepTo(25);
  EXPECT_TRUE(SameState(a.GetState(), b.GetState()));
  EXPECT_GT(a.Count(Field::Cld), 0u);
  auto p = Busy(1);
  p.Seed = 12346;
  CloudAutomaton c(p);
  c.StepTo(25);
  EXPECT_FALSE(SameState(a.GetState(), c.GetState()));
}

TEST(CloudAutomatonDeterminism, ThreadCountDoesNotMatter)
{
  CloudAutomaton reference(Busy(1));
  reference.StepTo(30);
  for (const int threads : { 2, 3, 7, 13, 64 })
  {
    CloudAutomaton ca(Busy(threads));
    ca.StepTo(30);
    EXPECT_TRUE(SameState(reference.GetState(), ca.GetState())) << threads << " threads";
  }
  std::vector<float> d1, d4;
  nimbus::CloudSmoothingParameters s1, s4;
  s1.NumberOfThreads = 1;
  s4.NumberOfThreads = 4;
  nimbus::SmoothCloud(reference, s1, d1);
  nimbus::SmoothCloud(reference, s4, d4);
  EXPECT_EQ(d1, d4);
}

TEST(CloudAutomatonDeterminism, CheckpointsResumeExactly)
{
  CloudAutomaton straight(Busy(2));
  straight.StepTo(10);
  const nimbus::CloudAutomatonState checkpoint = straight.GetState();
  straight.StepTo(40);

  CloudAutomaton resumed(Busy(1));
  resumed.StepTo(3); // somewhere else first
  resumed.SetState(checkpoint);
  resumed.StepTo(40);
  EXPECT_TRUE(SameState(straight.GetState(), resumed.GetState()));

  resumed.Reset();
  EXPECT_EQ(resumed.GetStep(), 0);
  resumed.StepTo(40);
  EXPECT_TRUE(SameState(straight.GetState(), resumed.GetState()));
}

TEST(CloudAutomatonDeterminism, StepToStopsWhenAskedAndRefusesToGoBack)
{
  CloudAutomaton ca(Busy(1));
  int calls = 0;
  EXPECT_FALSE(ca.StepTo(10,
    [&](double fraction)
    {
      EXPECT_GE(fraction, 0.0);
      EXPECT_LT(fraction, 1.0);
      return ++calls < 4;
    }));
  EXPECT_EQ(ca.GetStep(), 3);
  EXPECT_THROW(ca.StepTo(2), std::invalid_argument);
}

// --- smoothing and time interpolation -------------------------------------------------------

TEST(CloudSmoothing, KernelIsNormalisedAndSmooth)
{
  // One cloud cell in the middle of an open 15^3 grid; R = 2.5 cells.
  CloudAutomaton ca(Quiet(15, 15, 15, CloudBoundary::Open));
  ca.Set(Field::Cld, 7, 7, 7, true);
  std::vector<float> density;
  nimbus::CloudSmoothingParameters s;
  s.Radius = 2.5;
  nimbus::SmoothCloud(ca, s, density);
  double sum = 0.0;
  for (float d : density)
  {
    sum += d;
    EXPECT_GE(d, 0.0f);
  }
  EXPECT_NEAR(sum, 1.0, 1e-5);
  // Hand-worked 1-D weights, R = 2.5: f(0) = 1, f(1) = 0.655420, f(2) = 0.092736
  // (q = d^2/R^2 in 1 - 22/9 q + 17/9 q^2 - 4/9 q^3), sum 2.496312, w0 = 0.400591.
  const double w0 = 0.400591, w1 = 0.655420 / 2.496312, w2 = 0.092736 / 2.496312;
  auto at = [&](int x, int y, int z) { return density[x + 15 * (y + 15 * z)]; };
  EXPECT_NEAR(at(7, 7, 7), w0 * w0 * w0, 2e-6);
  EXPECT_NEAR(at(8, 7, 7), w1 * w0 * w0, 2e-6);
  EXPECT_NEAR(at(7, 5, 9), w0 * w2 * w2, 2e-6);
  EXPECT_EQ(at(7, 7, 10), 0.0f); // |d| = 3 >= R
  EXPECT_EQ(at(6, 7, 7), at(8, 7, 7));
  EXPECT_EQ(at(7, 6, 7), at(7, 7, 8));
}

TEST(CloudSmoothing, FullCloudIsOneExceptAtOpenFaces)
{
  auto p = Quiet(20, 9, 6, CloudBoundary::Periodic);
  p.ActivationSupply = ProbabilityField::Uniform(1.0);
  CloudAutomaton ca(p);
  ca.StepTo(2); // act everywhere after step 1, cld everywhere after step 2
  ASSERT_EQ(ca.Count(Field::Cld), 20u * 9 * 6);
  std::vector<float> density;
  nimbus::SmoothCloud(ca, nimbus::CloudSmoothingParameters(), density);
  // Periodic x, y: 1 inside; z open: the bottom and top layers miss d = -1, -2 (or +1, +2):
  // (w0 + w1 + w2) = (1 + 0.655420 + 0.092736) / 2.496312 = 0.700296.
  for (int z = 0; z < 6; ++z)
  {
    const double expected =
      (z == 0 || z == 5) ? 0.700296 : ((z == 1 || z == 4) ? 1 - 0.092736 / 2.496312 : 1.0);
    EXPECT_NEAR(density[3 + 20 * (4 + 9 * z)], expected, 2e-6) << "layer " << z;
    EXPECT_NEAR(density[19 + 20 * (0 + 9 * z)], expected, 2e-6) << "layer " << z;
  }
}

TEST(CloudSmoothing, RadiusOneIsTheIdentityAndInterpolationIsLinear)
{
  CloudAutomaton ca(Busy(1));
  ca.StepTo(12);
  std::vector<float> a, b, mid;
  nimbus::CloudSmoothingParameters identity;
  identity.Radius = 1.0;
  nimbus::SmoothCloud(ca, identity, a);
  std::size_t ones = 0;
  for (float v : a)
  {
    ASSERT_TRUE(v == 0.0f || v == 1.0f);
    ones += v == 1.0f;
  }
  EXPECT_EQ(ones, ca.Count(Field::Cld));
  ca.Step();
  nimbus::SmoothCloud(ca, identity, b);
  nimbus::InterpolateDensity(a, b, 0.0, mid);
  EXPECT_EQ(mid, a);
  nimbus::InterpolateDensity(a, b, 1.0, mid);
  EXPECT_EQ(mid, b);
  nimbus::InterpolateDensity(a, b, 0.25, mid);
  for (std::size_t i = 0; i < a.size(); ++i)
  {
    ASSERT_FLOAT_EQ(mid[i], 0.75f * a[i] + 0.25f * b[i]);
  }
  EXPECT_THROW(nimbus::InterpolateDensity(a, b, 1.5, mid), std::invalid_argument);
  EXPECT_THROW(
    nimbus::InterpolateDensity(a, std::vector<float>(3), 0.5, mid), std::invalid_argument);
}

// --- extremes and errors ------------------------------------------------------------------

TEST(CloudAutomatonExtremes, OneVoxelGrid)
{
  for (const auto boundary : { CloudBoundary::Open, CloudBoundary::Periodic })
  {
    // Probabilities 0: hum from the initial state stays, nothing else happens. (Periodic:
    // the cell is its own x/y neighbour, but act is never set, so nothing changes.)
    auto p = Quiet(1, 1, 1, boundary);
    p.InitialHumidity = 1.0;
    CloudAutomaton quiet(p);
    quiet.StepTo(10);
    EXPECT_TRUE(quiet.Get(Field::Hum, 0, 0, 0));
    EXPECT_FALSE(quiet.Get(Field::Act, 0, 0, 0));
    EXPECT_FALSE(quiet.Get(Field::Cld, 0, 0, 0));

    // Probabilities 1: hum and act are resupplied every step, cld is always extinguished.
    p.InitialActivation = 1.0;
    p.Extinction = ProbabilityField::Uniform(1.0);
    p.HumiditySupply = ProbabilityField::Uniform(1.0);
    p.ActivationSupply = ProbabilityField::Uniform(1.0);
    p.Wind[0] = 0.6;
    p.Shear[1] = 2.0;
    CloudAutomaton busy(p);
    busy.StepTo(7);
    // Open: the wind of the last step (n = 6) moved 1 cell (floor(4.2) - floor(3.6)), so
    // the cell blew out of the grid and empty air came in; periodic: it came back.
    ASSERT_EQ(nimbus::WindShift(0.6, 6), 1);
    const bool kept = boundary == CloudBoundary::Periodic;
    EXPECT_EQ(busy.Get(Field::Hum, 0, 0, 0), kept);
    EXPECT_EQ(busy.Get(Field::Act, 0, 0, 0), kept);
    busy.Step(); // n = 7: floor(4.8) - floor(4.2) = 0, nothing moves
    EXPECT_TRUE(busy.Get(Field::Hum, 0, 0, 0));
    EXPECT_TRUE(busy.Get(Field::Act, 0, 0, 0));
    EXPECT_FALSE(busy.Get(Field::Cld, 0, 0, 0));

    // Smoothing one cloud cell: periodic x, y fold every tap back onto the cell
    // (1 x 1 x w0 = 0.400591); open keeps only the centre tap (w0^3).
    busy.Set(Field::Cld, 0, 0, 0, true);
    std::vector<float> density;
    nimbus::SmoothCloud(busy, nimbus::CloudSmoothingParameters(), density);
    ASSERT_EQ(density.size(), 1u);
    const double w0 = 0.400591;
    EXPECT_NEAR(density[0], boundary == CloudBoundary::Periodic ? w0 : w0 * w0 * w0, 2e-6);
  }
}

TEST(CloudAutomatonExtremes, FlatGridsAndLongRuns)
{
  // 1 x N x 1 and N x 1 x 1 lines and a 1-layer sheet run with every process on.
  for (const auto& dims : std::vector<std::tuple<int, int, int>>{
         { 1, 50, 1 }, { 50, 1, 1 }, { 64, 64, 1 }, { 1, 1, 40 } })
  {
    auto p = Busy(2);
    p.Dimensions[0] = std::get<0>(dims);
    p.Dimensions[1] = std::get<1>(dims);
    p.Dimensions[2] = std::get<2>(dims);
    p.HumiditySupply = ProbabilityField::Uniform(0.05);
    p.ActivationSupply = ProbabilityField::Uniform(0.01);
    CloudAutomaton ca(p);
    ca.StepTo(200);
    std::vector<float> density;
    nimbus::SmoothCloud(ca, nimbus::CloudSmoothingParameters(), density);
    for (float d : density)
    {
      ASSERT_TRUE(std::isfinite(d) && d >= 0.0f && d <= 1.0f + 1e-6f);
    }
  }
}

TEST(CloudAutomatonExtremes, InvalidParametersGiveClearErrors)
{
  auto expectError = [](const CloudAutomatonParameters& p, const std::string& word)
  {
    try
    {
      CloudAutomaton ca(p);
      ADD_FAILURE() << "no error, expected one naming " << word;
    }
    catch (const std::invalid_argument& error)
    {
      EXPECT_NE(std::string(error.what()).find(word), std::string::npos) << error.what();
    }
  };
  auto p = Quiet(4, 4, 4, CloudBoundary::Open);
  p.Dimensions[1] = 0;
  expectError(p, "Dimensions");
  p = Quiet(4, 4, 4, CloudBoundary::Open);
  p.Extinction = ProbabilityField::Uniform(1.5);
  expectError(p, "Extinction");
  p.Extinction = ProbabilityField::Uniform(std::nan(""));
  expectError(p, "Extinction");
  p = Quiet(4, 4, 4, CloudBoundary::Open);
  p.HumiditySupply = ProbabilityField::Plane(std::vector<float>(15, 0.1f));
  expectError(p, "HumiditySupply");
  p = Quiet(4, 4, 4, CloudBoundary::Open);
  p.ActivationSupply = ProbabilityField::Volume(std::vector<float>(64, -0.1f));
  expectError(p, "ActivationSupply");
  p = Quiet(4, 4, 4, CloudBoundary::Open);
  p.Wind[0] = std::numeric_limits<double>::infinity();
  expectError(p, "Wind");
  p = Quiet(4, 4, 4, CloudBoundary::Open);
  p.InitialHumidity = -1;
  expectError(p, "InitialHumidity");

  CloudAutomaton ca(Quiet(4, 4, 4, CloudBoundary::Open));
  EXPECT_THROW(ca.Get(Field::Cld, 4, 0, 0), std::out_of_range);
  nimbus::CloudAutomatonState wrong;
  wrong.Hum.resize(3);
  EXPECT_THROW(ca.SetState(wrong), std::invalid_argument);
  std::vector<float> density;
  nimbus::CloudSmoothingParameters bad;
  bad.Radius = std::nan("");
  EXPECT_THROW(nimbus::SmoothCloud(ca, bad, density), std::invalid_argument);
}

// --- the packed implementation against a naive one, cell by cell ----------------------------

namespace
{
// The rules written cell by cell on plain bool arrays (no randomness, integer wind).
struct NaiveState
{
  int nx, ny, nz;
  bool periodic;
  std::vector<char> hum, act, cld;
  int Index(int x, int y, int z) const { return x + nx * (y + ny * z); }
  // Value at (x, y, z) with the boundary rules; false outside.
  bool At(const std::vector<char>& f, int x, int y, int z) const
  {
    if (z < 0 || z >= nz)
      return false;
    if (x < 0 || x >= nx || y < 0 || y >= ny)
    {
      if (!periodic)
        return false;
      x = ((x % nx) + nx) % nx;
      y = ((y % ny) + ny) % ny;
    }
    return f[Index(x, y, z)] != 0;
  }
  void Step(int windX, int windY)
  {
    static const int offsets[][3] = { { 1, 0, 0 }, { -1, 0, 0 }, { 2, 0, 0 }, { -2, 0, 0 },
      { 0, 1, 0 }, { 0, -1, 0 }, { 0, 2, 0 }, { 0, -2, 0 }, { 0, 0, 1 }, { 0, 0, -1 },
      { 0, 0, -2 } };
    std::vector<char> h(hum.size()), a(act.size()), c(cld.size());
    for (int z = 0; z < nz; ++z)
      for (int y = 0; y < ny; ++y)
        for (int x = 0; x < nx; ++x)
        {
          bool f = false;
          for (const auto& o : offsets)
            f = f || At(act, x + o[0], y + o[1], z + o[2]);
          const int i = Index(x, y, z);
          h[i] = hum[i] && !act[i];
          c[i] = cld[i] || act[i];
          a[i] = !act[i] && hum[i] && f;
        }
    // wind: the value at (x, y) comes from (x - windX, y - windY)
    for (int z = 0; z < nz; ++z)
      for (int y = 0; y < ny; ++y)
        for (int x = 0; x < nx; ++x)
        {
          const int i = Index(x, y, z);
          hum[i] = At(h, x - windX, y - windY, z);
          act[i] = At(a, x - windX, y - windY, z);
          cld[i] = At(c, x - windX, y - windY, z);
        }
  }
};
}

TEST(CloudAutomatonRules, PackedMatchesNaiveCellByCell)
{
  for (const int nx : { 1, 2, 3, 5, 63, 64, 65, 130 })
  {
    for (const auto boundary : { CloudBoundary::Open, CloudBoundary::Periodic })
    {
      for (const auto& wind : std::vector<std::pair<int, int>>{ { 0, 0 }, { 1, -1 }, { -3, 2 } })
      {
        auto p = Quiet(nx, 6, 5, boundary);
        p.InitialHumidity = 0.6; // a random start, then the deterministic rules
        p.InitialActivation = 0.05;
        p.Wind[0] = wind.first;
        p.Wind[1] = wind.second;
        p.Seed = static_cast<std::uint64_t>(nx);
        CloudAutomaton ca(p);
        ca.Set(Field::Act, nx / 2, 3, 2, true); // at least one act on the tiny grids
        NaiveState naive{ nx, 6, 5, boundary == CloudBoundary::Periodic, {}, {}, {} };
        const int cells = nx * 6 * 5;
        naive.hum.resize(cells);
        naive.act.resize(cells);
        naive.cld.resize(cells);
        for (int z = 0; z < 5; ++z)
          for (int y = 0; y < 6; ++y)
            for (int x = 0; x < nx; ++x)
            {
              naive.hum[naive.Index(x, y, z)] = ca.Get(Field::Hum, x, y, z);
              naive.act[naive.Index(x, y, z)] = ca.Get(Field::Act, x, y, z);
            }
        // The comparison is not vacuous: act and cld occur (on tiny open grids a strong
        // wind blows everything out in one step, so count before each step).
        std::size_t seen = 0;
        for (int step = 1; step <= 6; ++step)
        {
          seen += ca.Count(Field::Act) + ca.Count(Field::Cld);
          ca.Step();
          naive.Step(wind.first, wind.second);
          for (int z = 0; z < 5; ++z)
            for (int y = 0; y < 6; ++y)
              for (int x = 0; x < nx; ++x)
              {
                const int i = naive.Index(x, y, z);
                ASSERT_EQ(ca.Get(Field::Hum, x, y, z), naive.hum[i] != 0)
                  << "nx " << nx << " step " << step << " at " << x << "," << y << "," << z;
                ASSERT_EQ(ca.Get(Field::Act, x, y, z), naive.act[i] != 0)
                  << "nx " << nx << " step " << step << " at " << x << "," << y << "," << z;
                ASSERT_EQ(ca.Get(Field::Cld, x, y, z), naive.cld[i] != 0)
                  << "nx " << nx << " step " << step << " at " << x << "," << y << "," << z;
              }
        }
        EXPECT_GT(seen, 0u) << "nx " << nx;
      }
    }
  }
}
