// 004 §3.4's reference patterns (Physics/MultipleScatteringPatterns.h): with the whole
// grid in the pattern and every path evaluated, orders 2 and 3 equal a brute-force sum
// over all pairs (triples) of grid points with the same discretisation; the stochastic
// selection of paths is unbiased; results do not depend on the thread count; no light
// without extinction or scattering; finite for optically huge cells and tiny grids;
// J_2 grows as tau and J_3 as tau^2 in thin clouds; forward scattering
// carries the order-2 light away from the sun; progress ends at 1 and may abort.
#include "MultipleScatteringPatterns.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <functional>
#include <stdexcept>
#include <vector>

namespace
{
using nimbus::CloudOptics;
using nimbus::DirectionalLight;
using nimbus::ExtinctionGrid;
using nimbus::MultipleScatteringOptions;
using nimbus::PhaseFunctionKind;
using nimbus::Rgb;
using nimbus::Vector3;

constexpr double kY00 = 0.28209479177387814; // 1 / (2 sqrt(pi)), as EvaluateInScattering
constexpr double kY1 = 0.4886025119029199;   // sqrt(3 / (4 pi))

/// A grid of nx x ny x nz points with extinction sigma(i, j, k) [1/m].
ExtinctionGrid MakeGrid(
  int nx, int ny, int nz, const Vector3& spacing, const std::function<double(int, int, int)>& sigma)
{
  ExtinctionGrid grid;
  grid.Dimensions = { { nx, ny, nz } };
  grid.Origin = { { -100, 50, 1000 } };
  grid.Spacing = spacing;
  grid.Extinction.resize(grid.NumberOfPoints());
  for (int k = 0; k < nz; ++k)
  {
    for (int j = 0; j < ny; ++j)
    {
      for (int i = 0; i < nx; ++i)
      {
        grid.Extinction[grid.Index(i, j, k)] = static_cast<float>(sigma(i, j, k));
      }
    }
  }
  return grid;
}

/// Axes rotated about (1, 2, 3) by 0.7 rad (orthonormal).
std::array<Vector3, 3> RotatedAxes()
{
  const Vector3 u = nimbus::Normalized({ { 1, 2, 3 } });
  const double c = std::cos(0.7), s = std::sin(0.7);
  std::array<Vector3, 3> axes;
  for (int a = 0; a < 3; ++a)
  {
    Vector3 e{ { 0, 0, 0 } };
    e[a] = 1;
    const Vector3 cross = nimbus::Cross(u, e);
    const double dot = nimbus::Dot(u, e);
    for (int q = 0; q < 3; ++q)
    {
      axes[a][q] = e[q] * c + cross[q] * s + u[q] * dot * (1 - c);
    }
  }
  return axes;
}

Vector3 WorldPosition(const ExtinctionGrid& grid, int i, int j, int k)
{
  Vector3 p = grid.Origin;
  const double t[3] = { i * grid.Spacing[0], j * grid.Spacing[1], k * grid.Spacing[2] };
  for (int a = 0; a < 3; ++a)
  {
    for (int q = 0; q < 3; ++q)
    {
      p[q] += t[a] * grid.Axes[a][q];
    }
  }
  return p;
}

/// Sun light with a colour that changes with height, and a made-up optical depth
/// toward it (the solver takes it as given).
DirectionalLight TestSun(const Vector3& toLight)
{
  DirectionalLight sun;
  sun.ToLight = nimbus::Normalized(toLight);
  sun.Irradiance = [](double z) {
    return Rgb{ { 1.0 + 0.001 * (z - 1000), 0.8, 0.6 - 0.0005 * (z - 1000) } };
  };
  return sun;
}

std::vector<float> TestSunDepth(const ExtinctionGrid& grid)
{
  std::vector<float> depth(grid.NumberOfPoints());
  for (std::size_t p = 0; p < depth.size(); ++p)
  {
    depth[p] = static_cast<float>(0.05 * (p % 7) + 0.02 * (p % 3));
  }
  return depth;
}

MultipleScatteringOptions FullPattern(int orders)
{
  MultipleScatteringOptions options;
  options.Method = nimbus::MultipleScatteringMethod::ReferencePatterns;
  options.Orders = orders;
  options.PatternRadius = 64;
  options.PatternContribution = 1.0;
  options.PatternSelection = 1.0;
  options.Threads = 2;
  return options;
}

std::vector<float> Solve(const ExtinctionGrid& grid, const CloudOptics& optics,
  const DirectionalLight& sun, const MultipleScatteringOptions& options,
  const std::vector<float>& sunDepth)
{
  std::vector<float> coefficients(12 * grid.NumberOfPoints(), 0.0f);
  nimbus::AddReferencePatternOrders(grid, optics, sun, options, sunDepth, coefficients, nullptr);
  return coefficients;
}

/// The orders 2 (and 3) of J at every point by brute force over all pairs of grid
/// points (plus each point's self cell, the solver's closed form), for extinction that is affine in
/// the grid coordinates: then the trilinear extinction and the trapezoid rule are exact, tau(j ->
/// P) = r (sigma_j + sigma_P) / 2. k1: the phase function's first Legendre coefficient, given here
/// independently.
struct BruteForce
{
  std::vector<float> Order2, Order3;
};

BruteForce BruteForceOrders(const ExtinctionGrid& grid, const CloudOptics& optics,
  const DirectionalLight& sun, const std::vector<float>& sunDepth, double k1, bool order3)
{
  const std::size_t count = grid.NumberOfPoints();
  std::vector<Vector3> position(count);
  std::vector<std::array<int, 3>> ijk(count);
  for (int k = 0; k < grid.Dimensions[2]; ++k)
  {
    for (int j = 0; j < grid.Dimensions[1]; ++j)
    {
      for (int i = 0; i < grid.Dimensions[0]; ++i)
      {
        position[grid.Index(i, j, k)] = WorldPosition(grid, i, j, k);
        ijk[grid.Index(i, j, k)] = { { i, j, k } };
      }
    }
  }
  const double dV = grid.Spacing[0] * grid.Spacing[1] * grid.Spacing[2];
  const double selfRadius = std::cbrt(3.0 * dV / (4.0 * nimbus::kPi));
  const Vector3 fromSun{ { -sun.ToLight[0], -sun.ToLight[1], -sun.ToLight[2] } };
  // previous == nullptr: order 2 from the sun; else from that order's SH field.
  const auto gather = [&](const std::vector<float>* previous)
  {
    std::vector<float> field(12 * count, 0.0f);
    for (std::size_t p = 0; p < count; ++p)
    {
      double c[12] = {};
      for (std::size_t q = 0; q < count; ++q)
      {
        if (q == p)
        {
          continue;
        }
        Vector3 d;
        for (int a = 0; a < 3; ++a)
        {
          d[a] = position[p][a] - position[q][a];
        }
        const double r = nimbus::Length(d);
        const Vector3 s{ { d[0] / r, d[1] / r, d[2] / r } };
        const double tau = r * 0.5 * (grid.Extinction[p] + grid.Extinction[q]);
        const double transport = optics.Albedo * grid.Extinction[q] * std::exp(-tau) * dV / (r * r);
        for (int ch = 0; ch < 3; ++ch)
        {
          double J;
          if (!previous)
          {
            J = nimbus::EvaluatePhaseFunction(optics.Phase, nimbus::Dot(s, fromSun), optics.G) *
              sun.IrradianceAt(position[q][2])[ch] * std::exp(-double(sunDepth[q]));
          }
          else
          {
            const float* a = previous->data() + 12 * q + 4 * ch;
            J = std::max(0.0, kY00 * a[0] + kY1 * (a[1] * s[1] + a[2] * s[2] + a[3] * s[0]));
          }
          const double e = transport * J;
          c[4 * ch + 0] += e * kY00;
          c[4 * ch + 1] += e * k1 * kY1 * s[1];
          c[4 * ch + 2] += e * k1 * kY1 * s[2];
          c[4 * ch + 3] += e * k1 * kY1 * s[0];
        }
      }
      // The self cell (a sphere of the cell's volume): albedo (1 - exp(-sigma R)) times
      // the order-n light at p through the phase function.
      const double share = optics.Albedo * (1.0 - std::exp(-grid.Extinction[p] * selfRadius));
      const double harmonics[4] = { kY00, kY1 * fromSun[1], kY1 * fromSun[2], kY1 * fromSun[0] };
      for (int ch = 0; ch < 3; ++ch)
      {
        for (int lm = 0; lm < 4; ++lm)
        {
          const double kl = lm == 0 ? 1.0 : k1;
          c[4 * ch + lm] += !previous ? share * kl * kl * harmonics[lm] *
              sun.IrradianceAt(position[p][2])[ch] * std::exp(-double(sunDepth[p]))
                                      : share * kl * (*previous)[12 * p + 4 * ch + lm];
        }
      }
      for (int m = 0; m < 12; ++m)
      {
        field[12 * p + m] = static_cast<float>(c[m]);
      }
    }
    return field;
  };
  BruteForce result;
  result.Order2 = gather(nullptr);
  if (order3)
  {
    result.Order3 = gather(&result.Order2);
  }
  return result;
}

/// |a - b| <= relative * scale per coefficient, scale the largest |b| of its channel.
void ExpectFieldsNear(const std::vector<float>& a, const std::vector<float>& b, double relative)
{
  ASSERT_EQ(a.size(), b.size());
  for (int ch = 0; ch < 3; ++ch)
  {
    double scale = 0.0;
    for (std::size_t p = 0; p < b.size() / 12; ++p)
    {
      for (int lm = 0; lm < 4; ++lm)
      {
        scale = std::max(scale, std::abs(double(b[12 * p + 4 * ch + lm])));
      }
    }
    ASSERT_GT(scale, 0.0);
    double worst = 0.0;
    for (std::size_t p = 0; p < b.size() / 12; ++p)
    {
      for (int lm = 0; lm < 4; ++lm)
      {
        const std::size_t m = 12 * p + 4 * ch + lm;
        worst = std::max(worst, std::abs(double(a[m]) - b[m]) / scale);
      }
    }
    EXPECT_LE(worst, relative) << "channel " << ch;
  }
}
} // namespace

// The whole grid as the pattern, every path evaluated: order 2 equals the brute-force
// double sum, for a rotated grid with unequal spacings, extinction varying across it
// and a forward-scattering phase function (so the degree-1 terms and their signs count).
TEST(ReferencePatterns, Order2EqualsBruteForce)
{
  ExtinctionGrid grid = MakeGrid(6, 5, 4, { { 10, 12, 15 } },
    [](int i, int j, int k) { return 0.004 * (1.0 + 0.3 * i - 0.1 * j + 0.2 * k); });
  grid.Axes = RotatedAxes();
  CloudOptics optics;
  optics.Albedo = 0.9;
  optics.Phase = PhaseFunctionKind::HenyeyGreenstein;
  optics.G = 0.6;
  const DirectionalLight sun = TestSun({ { 0.3, -0.2, 1.0 } });
  const std::vector<float> depth = TestSunDepth(grid);
  const std::vector<float> solved = Solve(grid, optics, sun, FullPattern(2), depth);
  const BruteForce brute = BruteForceOrders(grid, optics, sun, depth, optics.G, false);
  // Measured: <= 1e-7 of each channel's largest coefficient (float storage, order of
  // the sums).
  ExpectFieldsNear(solved, brute.Order2, 2e-6);
}

// Order 3 from the stored order-2 field (clamped SH), with an isotropic pattern.
TEST(ReferencePatterns, Order3EqualsBruteForce)
{
  const ExtinctionGrid grid = MakeGrid(5, 5, 4, { { 10, 10, 10 } },
    [](int i, int j, int k) { return 0.01 * (1.0 + 0.2 * i + 0.1 * j - 0.15 * k); });
  CloudOptics optics;
  optics.Albedo = 0.95;
  optics.Phase = PhaseFunctionKind::HenyeyGreenstein;
  optics.G = 0.8;
  const DirectionalLight sun = TestSun({ { -0.5, 0.2, 0.8 } });
  const std::vector<float> depth = TestSunDepth(grid);
  const std::vector<float> two = Solve(grid, optics, sun, FullPattern(2), depth);
  const std::vector<float> three = Solve(grid, optics, sun, FullPattern(3), depth);
  const BruteForce brute = BruteForceOrders(grid, optics, sun, depth, optics.G, true);
  std::vector<float> order3(three.size());
  for (std::size_t m = 0; m < three.size(); ++m)
  {
    order3[m] = three[m] - two[m];
  }
  ExpectFieldsNear(two, brute.Order2, 2e-6);
  // Measured: <= 4e-7 (order 3 is the difference of two float fields).
  ExpectFieldsNear(order3, brute.Order3, 4e-6);
}

// Light from the zenith, forward scattering: the order-2 light at the cube's centre
// travels down (c_10 < 0); from the nadir, up; isotropic: no preferred direction.
TEST(ReferencePatterns, ForwardScatteringCarriesLightAwayFromTheSun)
{
  const ExtinctionGrid grid =
    MakeGrid(9, 9, 9, { { 10, 10, 10 } }, [](int, int, int) { return 0.01; });
  const std::vector<float> depth(grid.NumberOfPoints(), 0.0f);
  const std::size_t centre = 12 * grid.Index(4, 4, 4);
  CloudOptics optics;
  optics.Phase = PhaseFunctionKind::HenyeyGreenstein;
  optics.G = 0.8;
  MultipleScatteringOptions options = FullPattern(2);
  DirectionalLight sun;
  sun.ToLight = { { 0, 0, 1 } };
  const std::vector<float> down = Solve(grid, optics, sun, options, depth);
  EXPECT_GT(down[centre + 0], 0.0f);
  // c_10 / c_00: measured -1.24 (-k_1 Y_1 / Y_00 = -1.39 for light all straight down).
  EXPECT_LT(down[centre + 2], -1.0f * down[centre + 0]);
  EXPECT_NEAR(down[centre + 1], 0.0f, 1e-5f * down[centre + 0]);
  EXPECT_NEAR(down[centre + 3], 0.0f, 1e-5f * down[centre + 0]);
  sun.ToLight = { { 0, 0, -1 } };
  const std::vector<float> up = Solve(grid, optics, sun, options, depth);
  EXPECT_NEAR(up[centre + 2], -down[centre + 2], 1e-5f * down[centre + 0]);
  optics.Phase = PhaseFunctionKind::Isotropic;
  const std::vector<float> iso = Solve(grid, optics, sun, options, depth);
  for (int lm = 1; lm < 4; ++lm)
  {
    EXPECT_NEAR(iso[centre + lm], 0.0f, 1e-5f * iso[centre + 0]);
  }
}

// Order 2 at points of a uniform cube against the continuous integral over the cube
// (midpoint rule in directions and distance), with the exact optical depth toward the
// sun: the lattice sum plus the self cell approximates the volume integral. The cube
// is the grid's points' cells, the grid's box grown by half a cell.
TEST(ReferencePatterns, Order2ApproachesTheContinuousIntegral)
{
  const int n = 13;
  const double h = 10.0, side = n * h; // the cloud: [0, side]^3, points at (i + 1/2) h
  const Vector3 toLight = nimbus::Normalized({ { 0.2, 0.1, 1.0 } });
  // Distance from x (box coordinates [m]) to the box's surface along d.
  const auto exit = [side](const Vector3& x, const Vector3& d)
  {
    double t = 1e300;
    for (int a = 0; a < 3; ++a)
    {
      if (d[a] > 1e-12)
      {
        t = std::min(t, (side - x[a]) / d[a]);
      }
      else if (d[a] < -1e-12)
      {
        t = std::min(t, -x[a] / d[a]);
      }
    }
    return std::max(0.0, t);
  };
  for (const double sigma : { 0.01, 0.04 }) // tau per cell 0.1 and 0.4
  {
    ExtinctionGrid grid =
      MakeGrid(n, n, n, { { h, h, h } }, [sigma](int, int, int) { return sigma; });
    grid.Origin = { { h / 2, h / 2, h / 2 } };
    std::vector<float> depth(grid.NumberOfPoints());
    for (int k = 0; k < n; ++k)
    {
      for (int j = 0; j < n; ++j)
      {
        for (int i = 0; i < n; ++i)
        {
          depth[grid.Index(i, j, k)] = static_cast<float>(
            sigma * exit({ { (i + 0.5) * h, (j + 0.5) * h, (k + 0.5) * h } }, toLight));
        }
      }
    }
    CloudOptics optics;
    optics.Albedo = 1.0;
    optics.Phase = PhaseFunctionKind::HenyeyGreenstein;
    optics.G = 0.5;
    DirectionalLight sun;
    sun.ToLight = toLight;
    const std::vector<float> solved = Solve(grid, optics, sun, FullPattern(2), depth);
    for (const std::array<int, 3> point : { std::array<int, 3>{ { 6, 6, 6 } },
           std::array<int, 3>{ { 6, 6, 11 } }, std::array<int, 3>{ { 2, 8, 4 } } })
    {
      const Vector3 P{ { (point[0] + 0.5) * h, (point[1] + 0.5) * h, (point[2] + 0.5) * h } };
      // c_lm = k_l integral over the direction t toward the source (light travels
      // along s = -t) of Y_lm(s) integral_0^exit albedo sigma p(s . -L) exp(-sigma r)
      // exp(-sigma exit(P + r t, L)) dr.
      const int thetas = 64, phis = 128, steps = 128;
      double c[4] = { 0, 0, 0, 0 };
      for (int it = 0; it < thetas; ++it)
      {
        const double mu = -1.0 + (it + 0.5) * 2.0 / thetas, st = std::sqrt(1.0 - mu * mu);
        for (int ip = 0; ip < phis; ++ip)
        {
          const double phi = (ip + 0.5) * 2.0 * nimbus::kPi / phis;
          const Vector3 t{ { st * std::cos(phi), st * std::sin(phi), mu } };
          const Vector3 s{ { -t[0], -t[1], -t[2] } };
          const double rmax = exit(P, t), dr = rmax / steps;
          double radial = 0.0;
          for (int ir = 0; ir < steps; ++ir)
          {
            const double r = (ir + 0.5) * dr;
            radial += std::exp(-sigma * r - sigma * exit(nimbus::Along(P, t, r), toLight)) * dr;
          }
          const double e = optics.Albedo * sigma * radial *
            nimbus::HenyeyGreenstein(-nimbus::Dot(s, toLight), optics.G) * (2.0 / thetas) *
            (2.0 * nimbus::kPi / phis);
          c[0] += e * kY00;
          c[1] += e * optics.G * kY1 * s[1];
          c[2] += e * optics.G * kY1 * s[2];
          c[3] += e * optics.G * kY1 * s[0];
        }
      }
      const std::size_t at = 12 * grid.Index(point[0], point[1], point[2]);
      for (int lm = 0; lm < 4; ++lm)
      {
        // Measured: c_00 within 0.2 % (tau per cell 0.1) and 1.5 % (0.4), c_1m within
        // 2.4 % of c_00; without the self cell c_00 is 6 % and 22 % low.
        EXPECT_NEAR(solved[at + lm], c[lm], (lm == 0 ? 0.025 : 0.03) * std::abs(c[0]))
          << "sigma " << sigma << " point " << point[0] << " " << point[1] << " " << point[2]
          << " coefficient " << lm;
      }
    }
  }
}

// 004 §3.4's stochastic selection (drawn in proportion to the pattern's weights, see
// MultipleScatteringPatterns.cxx): the mean over seeds of the order-2 field approaches
// the one with every kept path evaluated (measured |mean - expected| < 1 standard
// error with 2000 seeds), and one estimate's spread is moderate.
TEST(ReferencePatterns, StochasticSelectionIsUnbiased)
{
  const ExtinctionGrid grid = MakeGrid(12, 12, 12, { { 20, 20, 20 } },
    [](int i, int j, int k)
    {
      const double r2 = (i - 5.5) * (i - 5.5) + (j - 6.0) * (j - 6.0) + 2 * (k - 5.0) * (k - 5.0);
      return 0.02 * std::exp(-r2 / 12.0);
    });
  CloudOptics optics;
  const DirectionalLight sun = TestSun({ { 0.4, 0.3, 1.0 } });
  const std::vector<float> depth = TestSunDepth(grid);
  MultipleScatteringOptions options;
  options.Orders = 2;
  options.PatternRadius = 4;
  options.PatternContribution = 0.8;
  options.PatternSelection = 1.0;
  options.Threads = 2;
  const std::vector<float> reference = Solve(grid, optics, sun, options, depth);
  options.PatternSelection = 0.25;
  const int seeds = 200;
  const std::size_t probes[] = { 12 * grid.Index(5, 6, 5), 12 * grid.Index(3, 7, 6),
    12 * grid.Index(8, 4, 4) };
  std::vector<std::vector<double>> samples(std::size(probes) * 12);
  for (int seed = 0; seed < seeds; ++seed)
  {
    options.Seed = 1000 + seed;
    const std::vector<float> estimate = Solve(grid, optics, sun, options, depth);
    for (std::size_t probe = 0; probe < std::size(probes); ++probe)
    {
      for (int m = 0; m < 12; ++m)
      {
        samples[12 * probe + m].push_back(estimate[probes[probe] + m]);
      }
    }
  }
  for (std::size_t probe = 0; probe < std::size(probes); ++probe)
  {
    for (int m = 0; m < 12; m += 4) // c_00 of each channel
    {
      const std::vector<double>& x = samples[12 * probe + m];
      double mean = 0.0, variance = 0.0;
      for (const double v : x)
      {
        mean += v / x.size();
      }
      for (const double v : x)
      {
        variance += (v - mean) * (v - mean) / (x.size() - 1);
      }
      const double standardError = std::sqrt(variance / x.size());
      const double expected = reference[probes[probe] + m];
      EXPECT_GT(standardError, 1e-4 * expected) << "the selection is not random";
      // The spread of one estimate: measured 9-15 % (drawn uniformly: 29-34 %).
      EXPECT_LT(std::sqrt(variance), 0.2 * expected) << "probe " << probe;
      EXPECT_LT(std::abs(mean - expected), 4.0 * standardError)
        << "probe " << probe << " coefficient " << m << ": mean " << mean << " expected "
        << expected << " standard error " << standardError;
    }
  }
}

// Where the cloud is the uniform sample space (uniform extinction, light and sun depth,
// the pattern inside the cloud), the kept paths carry exactly the share r of the
// total, so dividing their sum by r gives the full sum of J_2's c_00 (float rounding).
TEST(ReferencePatterns, KeptShareRestoresTheTotalInAUniformCloud)
{
  const ExtinctionGrid grid =
    MakeGrid(13, 13, 13, { { 10, 10, 10 } }, [](int, int, int) { return 0.02; });
  const std::vector<float> depth(grid.NumberOfPoints(), 0.3f);
  CloudOptics optics; // Cornette-Shanks, g = 0.85
  DirectionalLight sun;
  sun.ToLight = nimbus::Normalized({ { 0.3, -0.4, 1.0 } });
  MultipleScatteringOptions options = FullPattern(2);
  options.PatternRadius = 6;
  const std::size_t centre = 12 * grid.Index(6, 6, 6);
  const std::vector<float> all = Solve(grid, optics, sun, options, depth);
  for (const double r : { 0.5, 0.8, 0.95 })
  {
    options.PatternContribution = r;
    const std::vector<float> kept = Solve(grid, optics, sun, options, depth);
    for (int ch = 0; ch < 3; ++ch)
    {
      EXPECT_NEAR(kept[centre + 4 * ch], all[centre + 4 * ch], 1e-5 * all[centre + 4 * ch])
        << "r " << r;
    }
  }
}

TEST(ReferencePatterns, IndependentOfThreads)
{
  const ExtinctionGrid grid = MakeGrid(14, 13, 12, { { 20, 20, 25 } },
    [](int i, int j, int k)
    { return (i + 2 * j + 3 * k) % 5 == 0 ? 0.0 : 0.002 * (1 + (i * j + k) % 7); });
  CloudOptics optics;
  const DirectionalLight sun = TestSun({ { 0.1, 0.7, 0.5 } });
  const std::vector<float> depth = TestSunDepth(grid);
  MultipleScatteringOptions options;
  options.Orders = 3;
  options.PatternRadius = 3;
  options.PatternContribution = 0.8;
  options.PatternSelection = 0.25;
  options.Threads = 1;
  const std::vector<float> one = Solve(grid, optics, sun, options, depth);
  options.Threads = 3;
  const std::vector<float> three = Solve(grid, optics, sun, options, depth);
  EXPECT_EQ(one, three);
  EXPECT_GT(*std::max_element(one.begin(), one.end()), 0.0f);
}

// No extinction or no scattering: nothing added (the coefficients are added to).
TEST(ReferencePatterns, NoLightWithoutScattering)
{
  const DirectionalLight sun = TestSun({ { 0, 0, 1 } });
  const MultipleScatteringOptions options = FullPattern(3);
  const std::vector<float> start(12 * 6 * 6 * 6, 0.25f);
  {
    const ExtinctionGrid grid =
      MakeGrid(6, 6, 6, { { 10, 10, 10 } }, [](int, int, int) { return 0.0; });
    std::vector<float> coefficients = start;
    nimbus::AddReferencePatternOrders(
      grid, CloudOptics(), sun, options, TestSunDepth(grid), coefficients, nullptr);
    EXPECT_EQ(coefficients, start);
  }
  {
    const ExtinctionGrid grid =
      MakeGrid(6, 6, 6, { { 10, 10, 10 } }, [](int, int, int) { return 0.01; });
    CloudOptics optics;
    optics.Albedo = 0.0;
    std::vector<float> coefficients = start;
    nimbus::AddReferencePatternOrders(
      grid, optics, sun, options, TestSunDepth(grid), coefficients, nullptr);
    EXPECT_EQ(coefficients, start);
  }
}

// Extinction 1e4 per metre (tau 1e4 per cell) and a single-point grid: finite.
TEST(ReferencePatterns, FiniteForExtremeGrids)
{
  const DirectionalLight sun = TestSun({ { 0.2, 0.1, 1 } });
  MultipleScatteringOptions options;
  options.Orders = 4;
  options.PatternRadius = 3;
  const auto allFinite = [](const std::vector<float>& c)
  { return std::all_of(c.begin(), c.end(), [](float v) { return std::isfinite(v); }); };
  {
    const ExtinctionGrid grid =
      MakeGrid(8, 8, 8, { { 1, 1, 1 } }, [](int, int, int) { return 1e4; });
    std::vector<float> depth(grid.NumberOfPoints());
    for (int k = 0; k < 8; ++k)
    {
      for (int p = 0; p < 64; ++p)
      {
        depth[64 * k + p] = static_cast<float>(1e4 * (7 - k));
      }
    }
    const std::vector<float> c = Solve(grid, CloudOptics(), sun, options, depth);
    EXPECT_TRUE(allFinite(c));
    EXPECT_GE(c[12 * grid.Index(4, 4, 7)], 0.0f);
  }
  {
    const ExtinctionGrid grid =
      MakeGrid(1, 1, 1, { { 10, 10, 10 } }, [](int, int, int) { return 0.01; });
    const std::vector<float> c = Solve(grid, CloudOptics(), sun, options, { 0.0f });
    EXPECT_TRUE(allFinite(c));
  }
  {
    const ExtinctionGrid grid =
      MakeGrid(1, 1, 5, { { 10, 10, 10 } }, [](int, int, int) { return 0.01; });
    const std::vector<float> c = Solve(grid, CloudOptics(), sun, options, TestSunDepth(grid));
    EXPECT_TRUE(allFinite(c));
    EXPECT_GT(c[12 * 2], 0.0f);
  }
}

// Thin clouds: J_n, per unit scattering coefficient, grows as tau^(n-1), so the
// light the cloud emits, sigma_s J_n, as tau^n: doubling the extinction doubles J_2
// and quadruples J_3 (sun depth held at 0).
TEST(ReferencePatterns, OrdersScaleAsPowersOfOpticalDepth)
{
  const auto orders = [](double sigma)
  {
    const ExtinctionGrid grid =
      MakeGrid(8, 8, 8, { { 10, 10, 10 } }, [sigma](int, int, int) { return sigma; });
    CloudOptics optics;
    optics.Phase = PhaseFunctionKind::Isotropic;
    optics.Albedo = 1.0;
    DirectionalLight sun;
    const std::vector<float> depth(grid.NumberOfPoints(), 0.0f);
    const std::size_t centre = 12 * grid.Index(4, 4, 4);
    const double two = Solve(grid, optics, sun, FullPattern(2), depth)[centre];
    const double three = Solve(grid, optics, sun, FullPattern(3), depth)[centre] - two;
    return std::array<double, 2>{ { two, three } };
  };
  const double sigma = 0.02 / 70; // tau 0.02 across the cube
  const std::array<double, 2> thin = orders(sigma), thicker = orders(2 * sigma);
  // Measured ratios: 1.984 and 3.936; the transmittance inside the cube keeps them a
  // little below 2 and 4.
  EXPECT_NEAR(thicker[0] / thin[0], 2.0, 0.03);
  EXPECT_LT(thicker[0] / thin[0], 2.0);
  EXPECT_NEAR(thicker[1] / thin[1], 4.0, 0.1);
  EXPECT_LT(thicker[1] / thin[1], 4.0);
}

TEST(ReferencePatterns, ProgressEndsAtOneAndMayAbort)
{
  const ExtinctionGrid grid =
    MakeGrid(10, 10, 10, { { 10, 10, 10 } }, [](int, int, int) { return 0.01; });
  MultipleScatteringOptions options;
  options.Orders = 3;
  options.PatternRadius = 2;
  options.Threads = 3;
  std::vector<double> fractions;
  std::vector<float> coefficients(12 * grid.NumberOfPoints(), 0.0f);
  nimbus::AddReferencePatternOrders(grid, CloudOptics(), TestSun({ { 0, 0, 1 } }), options,
    TestSunDepth(grid), coefficients, [&](double f) { fractions.push_back(f); });
  ASSERT_FALSE(fractions.empty());
  EXPECT_TRUE(std::is_sorted(fractions.begin(), fractions.end()));
  EXPECT_GE(fractions.front(), 0.0);
  EXPECT_EQ(fractions.back(), 1.0);
  EXPECT_THROW(nimbus::AddReferencePatternOrders(grid, CloudOptics(), TestSun({ { 0, 0, 1 } }),
                 options, TestSunDepth(grid), coefficients,
                 [](double f)
                 {
                   if (f > 0.3)
                   {
                     throw std::runtime_error("cancelled");
                   }
                 }),
    std::runtime_error);
  std::vector<float> wrongSize(5);
  EXPECT_THROW(nimbus::AddReferencePatternOrders(grid, CloudOptics(), TestSun({ { 0, 0, 1 } }),
                 options, TestSunDepth(grid), wrongSize, nullptr),
    std::invalid_argument);
}
