// The first scattering of point sources on the medium's grid (Physics/FirstScattering.h)
// against closed forms: the inverse square in vacuum, exp(-sigma r) / r^2 in a homogeneous
// medium, the power a homogeneous medium takes from a source at its centre, a shadow, a
// source outside the grid, merging, thread independence and refusals. Bounds from the
// measured values printed.
#include "FirstScattering.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <stdexcept>
#include <vector>

namespace
{
using nimbus::ExtinctionGrid;
using nimbus::FirstScatteringField;
using nimbus::ScalarPointSource;
using nimbus::Vector3;

/// A cube of n^3 points `spacing` metres apart, centred on the origin, extinction sigma.
ExtinctionGrid Cube(int n, double spacing, double sigma)
{
  ExtinctionGrid grid;
  grid.Dimensions = { { n, n, n } };
  const double half = 0.5 * spacing * (n - 1);
  grid.Origin = { { -half, -half, -half } };
  grid.Spacing = { { spacing, spacing, spacing } };
  grid.Extinction.assign(grid.NumberOfPoints(), static_cast<float>(sigma));
  return grid;
}

double E(const ExtinctionGrid& g, const FirstScatteringField& f, int i, int j, int k)
{
  return f.Values[4 * g.Index(i, j, k)];
}

TEST(FirstScattering, InverseSquareInVacuumAndItsDirection)
{
  // "Vacuum": 1e-12 /m, so that the field is computed everywhere (it is only where the
  // medium scatters) with a transmittance of 1 - 1e-10.
  const ExtinctionGrid grid = Cube(21, 10.0, 1e-12);
  const FirstScatteringField f =
    nimbus::ComputeFirstScattering(grid, { { { { 0, 0, 0 } }, 1000.0 } }, 1);
  double worst = 0.0;
  for (int k = 0; k < 21; k += 3)
    for (int j = 0; j < 21; j += 2)
      for (int i = 0; i < 21; ++i)
      {
        const Vector3 x = grid.Position(i, j, k);
        const double r2 = nimbus::Dot(x, x);
        if (std::max({ std::abs(i - 10), std::abs(j - 10), std::abs(k - 10) }) < 2)
        {
          continue; // the cell averages (below)
        }
        const double expected = 1000.0 / r2;
        worst = std::max(worst, std::abs(E(grid, f, i, j, k) / expected - 1.0));
        // F = E x / |x| exactly for one source.
        const float* v = &f.Values[4 * grid.Index(i, j, k)];
        const double r = std::sqrt(r2);
        for (int a = 0; a < 3; ++a)
        {
          EXPECT_NEAR(v[1 + a], v[0] * x[a] / r, 1e-5 * v[0]);
        }
      }
  std::printf("vacuum: worst relative error of 1000 / r^2: %.2e\n", worst);
  EXPECT_LT(worst, 1e-5);
  // The source's own point: the cell average of 1/r^2 over a 10 m cube about the source,
  // (1/V) integral of 1/r^2 = 7.6741 / h^2 (6 x 0.5 x the integral of 1/(0.25 + x^2 + y^2) over a
  // unit square).
  const double own = E(grid, f, 10, 10, 10) / 1000.0 * 100.0;
  std::printf("own cell: <1/r^2> h^2 = %.4f (exact 7.6741)\n", own);
  EXPECT_NEAR(own, 7.6741, 0.01 * 7.6741);
}

TEST(FirstScattering, HomogeneousMediumAttenuates)
{
  // sigma = 0.02 /m on 10 m spacing: along the axes and diagonals the propagation is exact
  // (the predecessors are grid points); elsewhere the bilinear step smooths tau a little.
  const double sigma = 0.02;
  const ExtinctionGrid grid = Cube(41, 10.0, sigma);
  const FirstScatteringField f =
    nimbus::ComputeFirstScattering(grid, { { { { 0, 0, 0 } }, 1.0 } }, 2);
  double worstAxis = 0.0, worstAll = 0.0, worstFar = 0.0;
  for (int k = 0; k < 41; ++k)
    for (int j = 0; j < 41; ++j)
      for (int i = 0; i < 41; ++i)
      {
        const int di = i - 20, dj = j - 20, dk = k - 20;
        if (std::max({ std::abs(di), std::abs(dj), std::abs(dk) }) < 2)
        {
          continue;
        }
        const Vector3 x = grid.Position(i, j, k);
        const double r = nimbus::Length(x);
        const double tau = -std::log(E(grid, f, i, j, k) * r * r);
        const double error = std::abs(tau / (sigma * r) - 1.0);
        worstAll = std::max(worstAll, error);
        if (std::max({ std::abs(di), std::abs(dj), std::abs(dk) }) >= 8)
        {
          worstFar = std::max(worstFar, error);
        }
        const bool straight = (di == 0 && dj == 0) || (di == 0 && dk == 0) ||
          (dj == 0 && dk == 0) || (std::abs(di) == std::abs(dj) && std::abs(dj) == std::abs(dk));
        if (straight)
        {
          worstAxis = std::max(worstAxis, error);
        }
      }
  std::printf("homogeneous: worst relative error of tau: axes and diagonals %.2e, all %.2e, "
              "8 or more steps away %.2e\n",
    worstAxis, worstAll, worstFar);
  EXPECT_LT(worstAxis, 1e-5);
  EXPECT_LT(worstAll, 0.03);
}

TEST(FirstScattering, PowerTakenByTheMediumIsKept)
{
  // A source at the centre of a homogeneous cube: the medium takes
  // P = I integral over directions of (1 - exp(-sigma L(w))) dw (L the distance to the
  // cube's face); integral sigma E dV over the grid's cells must give it. The mean free
  // path is one to four grid steps: the near field (cell averages) carries much of it.
  for (double sigma : { 0.025, 0.05, 0.1 })
  {
    const int n = 41;
    const double h = 10.0, half = 0.5 * h * n; // the cells' outer faces
    const ExtinctionGrid grid = Cube(n, h, sigma);
    const FirstScatteringField f =
      nimbus::ComputeFirstScattering(grid, { { { { 0, 0, 0 } }, 1.0 } }, 2);
    double taken = 0.0;
    for (std::size_t i = 0; i < grid.NumberOfPoints(); ++i)
    {
      taken += sigma * f.Values[4 * i] * h * h * h;
    }
    // The closed form by quadrature over the sphere (Fibonacci directions).
    const int m = 200000;
    double expected = 0.0;
    for (int q = 0; q < m; ++q)
    {
      const double z = 1.0 - (2.0 * q + 1.0) / m, rho = std::sqrt(1.0 - z * z);
      const double phi = q * 2.399963229728653;
      const double d[3] = { rho * std::cos(phi), rho * std::sin(phi), z };
      const double l = half / std::max({ std::abs(d[0]), std::abs(d[1]), std::abs(d[2]) });
      expected += (1.0 - std::exp(-sigma * l)) * 4.0 * nimbus::kPi / m;
    }
    std::printf("sigma %.3f /m (mean free path %.1f steps): power taken %.5f, closed form %.5f "
                "(ratio %.4f)\n",
      sigma, 1.0 / (sigma * h), taken, expected, taken / expected);
    EXPECT_NEAR(taken / expected, 1.0, 0.02);
  }
}

TEST(FirstScattering, OpaqueWallCastsAShadowAndSourcesOutsideTheGrid)
{
  // A wall at x = 0 (optical depth 50 across one step) between a source at x = -95 m and
  // the half x > 0; vacuum elsewhere.
  ExtinctionGrid grid = Cube(21, 10.0, 1e-12);
  for (int k = 0; k < 21; ++k)
    for (int j = 0; j < 21; ++j)
    {
      grid.Extinction[grid.Index(10, j, k)] = 5.0f;
    }
  const FirstScatteringField f =
    nimbus::ComputeFirstScattering(grid, { { { { -95, 0, 0 } }, 1.0 } }, 1);
  EXPECT_LT(E(grid, f, 15, 10, 10), 1e-12);
  EXPECT_NEAR(E(grid, f, 5, 10, 10) * 45.0 * 45.0, 1.0, 1e-5);

  // A source 1 km below the grid: the bottom face sees 1/r^2 unattenuated, the points above
  // the same through the vacuum of the grid; a lower grid point's light is its own.
  const ExtinctionGrid empty = Cube(21, 10.0, 1e-12);
  const FirstScatteringField below =
    nimbus::ComputeFirstScattering(empty, { { { { 30, -20, -1000 } }, 1e6 } }, 2);
  double worst = 0.0;
  for (std::size_t i = 0; i < empty.NumberOfPoints(); i += 7)
  {
    const Vector3 x = empty.Position(static_cast<double>(i % 21),
      static_cast<double>((i / 21) % 21), static_cast<double>(i / 441));
    const double r2 =
      (x[0] - 30) * (x[0] - 30) + (x[1] + 20) * (x[1] + 20) + (x[2] + 1000) * (x[2] + 1000);
    worst = std::max(worst, std::abs(below.Values[4 * i] * r2 / 1e6 - 1.0));
  }
  EXPECT_LT(worst, 1e-5);
}

TEST(FirstScattering, MergesSourcesOfOneCellAndThreadsAgree)
{
  ExtinctionGrid grid = Cube(24, 10.0, 1e-12);
  std::mt19937 random(7);
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  for (float& s : grid.Extinction)
  {
    s = static_cast<float>(0.02 * (u(random) + 0.5));
  }
  std::vector<ScalarPointSource> sources;
  for (int s = 0; s < 60; ++s)
  {
    // Even sources at x < -20 m, odd ones at x > 20 m: the halves share no cell.
    const double x = (s % 2 ? 1.0 : -1.0) * (20.0 + 20.0 * (u(random) + 0.5));
    sources.push_back({ { { x, 40.0 * u(random), 300.0 * u(random) } }, 1.0 + s });
  }
  const FirstScatteringField one = nimbus::ComputeFirstScattering(grid, sources, 1);
  const FirstScatteringField three = nimbus::ComputeFirstScattering(grid, sources, 3);
  EXPECT_LE(one.MergedSources, 60);
  double worst = 0.0;
  for (std::size_t i = 0; i < one.Values.size(); ++i)
  {
    // Relative to the point's E (F's components may cancel to nothing).
    worst =
      std::max(worst, std::abs(one.Values[i] - three.Values[i]) / (one.Values[i - i % 4] + 1e-30));
  }
  EXPECT_LT(worst, 1e-6);
  // Linearity: the two halves combined give the whole (sources merge within a half).
  std::vector<ScalarPointSource> a, b;
  for (std::size_t s = 0; s < sources.size(); ++s)
  {
    (s % 2 ? b : a).push_back(sources[s]);
  }
  const FirstScatteringField fa = nimbus::ComputeFirstScattering(grid, a, 2);
  const FirstScatteringField fb = nimbus::ComputeFirstScattering(grid, b, 2);
  const FirstScatteringField sum = nimbus::CombineFirstScattering({ &fa, &fb }, { 1.0, 1.0 });
  worst = 0.0;
  for (std::size_t i = 0; i < sum.Values.size(); i += 4)
  {
    worst = std::max(worst, std::abs(sum.Values[i] - one.Values[i]) / (one.Values[i] + 1e-30));
  }
  EXPECT_LT(worst, 1e-5);
}

TEST(FirstScattering, DegreeOneHarmonicsAndTheForwardPeak)
{
  // J1 = (E + 3 k1 F . w) / (4 pi): the Funk-Hecke form of one source's E p(w . w0).
  const float up[4] = { 2.0f, 0.0f, 0.0f, 2.0f };
  EXPECT_NEAR(nimbus::EvaluateFirstScattering(up, { { 0, 0, 1 } }, 0.3),
    2.0 * (1 + 0.9) / (4 * nimbus::kPi), 1e-7);
  EXPECT_EQ(nimbus::EvaluateFirstScattering(up, { { 0, 0, -1 } }, 0.9), 0.0); // clamped
  // The forward peak: T' = f exp(-tau) + (1 - f) exp(-(1 - f a) tau) along an axis of a
  // homogeneous medium (there the propagation is exact).
  const double sigma = 0.02, f = 0.6, a = 0.99;
  const ExtinctionGrid grid = Cube(31, 10.0, sigma);
  nimbus::FirstScatteringForwardPeak peak;
  peak.Fraction = f;
  peak.Albedo = a;
  const FirstScatteringField field =
    nimbus::ComputeFirstScattering(grid, { { { { 0, 0, 0 } }, 1.0 } }, 2, nullptr, peak);
  for (int i = 17; i < 31; i += 3)
  {
    const double r = (i - 15) * 10.0, tau = sigma * r;
    const double expected = (f * std::exp(-tau) + (1 - f) * std::exp(-(1 - f * a) * tau)) / (r * r);
    EXPECT_NEAR(E(grid, field, i, 15, 15) / expected, 1.0, 1e-5) << "r " << r;
  }
  peak.Fraction = 1.0;
  EXPECT_THROW(nimbus::ComputeFirstScattering(grid, { { { { 0, 0, 0 } }, 1.0 } }, 1, nullptr, peak),
    std::invalid_argument);
}

TEST(FirstScattering, DeltaMBeamSpreadsWithItsPeakScatterings)
{
  // The plain field (T') and the reduced one (through (1 - f a) sigma) of one source in a
  // homogeneous medium, as vtkNimbusLightningIllumination computes them: their ratio gives
  // the beam's mean cosine exp(-f a tau (1 - g_peak)) along an axis.
  const double sigma = 0.02, f = 0.78, a = 0.99, lobeG = 0.87;
  const ExtinctionGrid grid = Cube(31, 10.0, sigma);
  nimbus::FirstScatteringForwardPeak peak;
  peak.Fraction = f;
  peak.Albedo = a;
  const FirstScatteringField plain =
    nimbus::ComputeFirstScattering(grid, { { { { 0, 0, 0 } }, 1.0 } }, 2, nullptr, peak);
  const FirstScatteringField reduced = nimbus::ComputeFirstScattering(
    Cube(31, 10.0, (1 - f * a) * sigma), { { { { 0, 0, 0 } }, 1.0 } }, 2, nullptr);
  for (int i = 17; i < 31; i += 3)
  {
    const double tau = sigma * (i - 15) * 10.0;
    const double cosine = nimbus::DeltaMBeamMeanCosine(
      E(grid, plain, i, 15, 15), E(grid, reduced, i, 15, 15), f, lobeG);
    // Measured to 2e-8 (the fields are floats).
    EXPECT_NEAR(cosine, std::exp(-f * a * tau * (1 - lobeG)), 1e-7) << "tau " << tau;
  }
  // Where nothing says how the beam spread: 1. Never above 1 nor below 0.
  EXPECT_EQ(nimbus::DeltaMBeamMeanCosine(1.0, 0.0, f, lobeG), 1.0);
  EXPECT_EQ(nimbus::DeltaMBeamMeanCosine(1.0, 1.0, 0.0, lobeG), 1.0);
  EXPECT_EQ(nimbus::DeltaMBeamMeanCosine(1.0, 1.0, f, 0.0), 1.0);
  EXPECT_EQ(nimbus::DeltaMBeamMeanCosine(std::nan(""), 1.0, f, lobeG), 1.0);
  EXPECT_EQ(nimbus::DeltaMBeamMeanCosine(5.0, 1.0, f, lobeG), 1.0); // E > E': rounding
  EXPECT_EQ(nimbus::DeltaMBeamMeanCosine(0.0, 1.0, f, lobeG), 0.0); // all scattered
}

TEST(FirstScattering, RefusesBadInputAndHandlesExtremes)
{
  const ExtinctionGrid grid = Cube(4, 10.0, 0.01);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  for (const ScalarPointSource& bad :
    std::vector<ScalarPointSource>{ { { { nan, 0, 0 } }, 1.0 }, { { { 0, inf, 0 } }, 1.0 },
      { { { 0, 0, 0 } }, -1.0 }, { { { 0, 0, 0 } }, nan }, { { { 0, 0, 0 } }, inf } })
  {
    EXPECT_THROW(nimbus::ComputeFirstScattering(grid, { bad }, 1), std::invalid_argument);
  }
  ExtinctionGrid broken = grid;
  broken.Extinction[3] = static_cast<float>(nan);
  EXPECT_THROW(
    nimbus::ComputeFirstScattering(broken, { { { { 0, 0, 0 } }, 1.0 } }, 1), std::invalid_argument);
  // One point, a huge extinction, zero intensity, a source 1e9 m away: finite.
  ExtinctionGrid dot = Cube(1, 10.0, 1e6);
  for (const ScalarPointSource& s : std::vector<ScalarPointSource>{
         { { { 0, 0, 0 } }, 1.0 }, { { { 1e9, 0, 0 } }, 1.0 }, { { { 0, 0, 0 } }, 0.0 } })
  {
    const FirstScatteringField f = nimbus::ComputeFirstScattering(dot, { s }, 1);
    for (float v : f.Values)
    {
      EXPECT_TRUE(std::isfinite(v));
    }
  }
  const FirstScatteringField none = nimbus::ComputeFirstScattering(grid, {}, 2);
  for (float v : none.Values)
  {
    EXPECT_EQ(v, 0.0f);
  }
}
} // namespace
