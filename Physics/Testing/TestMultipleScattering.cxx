// The multiple-scattering solver (MultipleScattering.h): its helpers, the
// discrete-direction system against closed forms and conservation laws, and the
// extremes of optical thickness, albedo, phase asymmetry, sun and grid size.
#include "MultipleScattering.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <limits>
#include <stdexcept>

namespace
{
using nimbus::CloudLighting;
using nimbus::CloudOptics;
using nimbus::ExtinctionGrid;
using nimbus::MultipleScatteringMethod;
using nimbus::MultipleScatteringOptions;
using nimbus::PhaseFunctionKind;
using nimbus::Vector3;

constexpr double kY00 = 0.28209479177387814;

ExtinctionGrid UniformCube(int n, double side, double sigma)
{
  ExtinctionGrid grid;
  grid.Dimensions = { { n, n, n } };
  const double h = n > 1 ? side / (n - 1) : side;
  grid.Spacing = { { h, h, h } };
  grid.Origin = { { -0.5 * side, -0.5 * side, -0.5 * side } };
  grid.Extinction.assign(grid.NumberOfPoints(), static_cast<float>(sigma));
  return grid;
}

CloudLighting UniformSky(double radiance)
{
  CloudLighting lighting;
  lighting.HasSun = false;
  lighting.Sky = [radiance](const Vector3&) {
    return nimbus::Rgb{ { radiance, radiance, radiance } };
  };
  return lighting;
}

// J(x, w) averaged over w at point index i, channel c: c_00 Y_00.
double MeanInScattering(const nimbus::MultipleScatteringField& field, std::size_t i, int c)
{
  return field.Coefficients[12 * i + 4 * c] * kY00;
}

TEST(MultipleScattering, FibonacciDirectionsAreUnitAndBalanced)
{
  for (int n : { 6, 26, 100 })
  {
    const auto d = nimbus::FibonacciDirections(n);
    ASSERT_EQ(d.size(), static_cast<std::size_t>(n));
    Vector3 sum{ { 0, 0, 0 } };
    for (const auto& v : d)
    {
      EXPECT_NEAR(nimbus::Length(v), 1.0, 1e-12);
      for (int c = 0; c < 3; ++c)
      {
        sum[c] += v[c];
      }
    }
    // Measured: 0.037 for 6 directions (a Fibonacci set that small is lopsided; the
    // solver normalises its phase matrix, so no light is lost), < 0.01 from 26 on.
    EXPECT_LT(nimbus::Length(sum) / n, n < 26 ? 0.04 : 0.01) << n;
  }
}

TEST(MultipleScattering, PhaseLegendreCoefficients)
{
  CloudOptics hg{ 1.0, PhaseFunctionKind::HenyeyGreenstein, 0.7 };
  EXPECT_NEAR(nimbus::PhaseLegendreCoefficient(hg, 1), 0.7, 1e-12);
  EXPECT_NEAR(nimbus::PhaseLegendreCoefficient(hg, 2), 0.49, 1e-12);
  for (double g : { 0.0, 0.5, 0.85, 0.99 })
  {
    CloudOptics cs{ 1.0, PhaseFunctionKind::CornetteShanks, g };
    EXPECT_NEAR(nimbus::PhaseLegendreCoefficient(cs, 0), 1.0, 1e-12);
    EXPECT_NEAR(nimbus::PhaseLegendreCoefficient(cs, 1), nimbus::CornetteShanksMeanCosine(g), 1e-7)
      << g;
  }
  CloudOptics rayleigh{ 1.0, PhaseFunctionKind::Rayleigh, 0.0 };
  EXPECT_NEAR(nimbus::PhaseLegendreCoefficient(rayleigh, 1), 0.0, 1e-12);
  EXPECT_NEAR(nimbus::PhaseLegendreCoefficient(rayleigh, 2), 0.1, 1e-9); // 3/4 (1 + mu^2): 1/10
}

TEST(MultipleScattering, DeltaMPeakLobeHasThePeaksForwardValue)
{
  for (double g : { 0.5, 0.7, 0.85, 0.95 })
  {
    CloudOptics cs{ 1.0, PhaseFunctionKind::CornetteShanks, g };
    const double k1 = nimbus::PhaseLegendreCoefficient(cs, 1);
    const double k2 = nimbus::PhaseLegendreCoefficient(cs, 2);
    const double truncatedG = (k1 - k2) / (1.0 - k2);
    const double lobeG = nimbus::DeltaMPeakLobeG(cs);
    // f HG(1; lobe) + (1 - f) HG(1; g') is the phase function's own forward value.
    EXPECT_NEAR(k2 * nimbus::HenyeyGreenstein(1.0, lobeG) +
        (1.0 - k2) * nimbus::HenyeyGreenstein(1.0, truncatedG),
      nimbus::CornetteShanks(1.0, g), 1e-9 * nimbus::CornetteShanks(1.0, g))
      << g;
    // The peak is narrower than the truncated phase function and than the whole one.
    EXPECT_GT(lobeG, truncatedG) << g;
    EXPECT_GT(lobeG, g) << g;
    EXPECT_LT(lobeG, 1.0) << g;
  }
  EXPECT_NEAR(nimbus::DeltaMPeakLobeG(CloudOptics{ 1.0, PhaseFunctionKind::CornetteShanks, 0.85 }),
    0.8723, 1e-4);
  // No peak to truncate: isotropic, Rayleigh (k1 = 0 < k2), backward.
  EXPECT_EQ(
    nimbus::DeltaMPeakLobeG(CloudOptics{ 1.0, PhaseFunctionKind::HenyeyGreenstein, 0.0 }), 0.0);
  EXPECT_EQ(nimbus::DeltaMPeakLobeG(CloudOptics{ 1.0, PhaseFunctionKind::Rayleigh, 0.0 }), 0.0);
  EXPECT_EQ(
    nimbus::DeltaMPeakLobeG(CloudOptics{ 1.0, PhaseFunctionKind::CornetteShanks, -0.5 }), 0.0);
  // g -> 1 stays finite.
  const double nearOne =
    nimbus::DeltaMPeakLobeG(CloudOptics{ 1.0, PhaseFunctionKind::CornetteShanks, 0.999999 });
  EXPECT_TRUE(std::isfinite(nearOne));
}

TEST(MultipleScattering, OpticalDepthOfAUniformCube)
{
  const ExtinctionGrid grid = UniformCube(9, 800.0, 0.01); // 100 m cells
  // Sun at the zenith: depth = sigma x the distance to the top plane.
  const auto depth = nimbus::OpticalDepthToward(grid, { { 0, 0, 1 } }, 2);
  for (int k = 0; k < 9; ++k)
  {
    EXPECT_NEAR(depth[grid.Index(4, 4, k)], 0.01 * 100.0 * (8 - k), 1e-5) << k;
  }
  // Oblique, 30 degrees from the zenith: the interior point 2 planes below the top
  // sees a path of 200 m / cos 30 inside the cube.
  const Vector3 toSun{ { std::sin(nimbus::kPi / 6), 0.0, std::cos(nimbus::kPi / 6) } };
  const auto oblique = nimbus::OpticalDepthToward(grid, toSun, 1);
  EXPECT_NEAR(oblique[grid.Index(4, 4, 6)], 0.01 * 200.0 / std::cos(nimbus::kPi / 6), 1e-4);
}

// Energy: with albedo 1 a cloud lit by the same radiance L0 from every direction
// holds L0 everywhere (no absorption: the isotropic field is the exact solution), so
// J = L0 at every point, for any phase function and optical thickness.
double WorstDeviationUnderUniformSky(double tau, double g, int orders, bool tail)
{
  const ExtinctionGrid grid = UniformCube(10, 900.0, tau / 900.0);
  CloudOptics optics{ 1.0, PhaseFunctionKind::CornetteShanks, g };
  MultipleScatteringOptions options;
  options.Orders = orders;
  options.ExtrapolateHigherOrders = tail;
  const auto field = nimbus::SolveMultipleScattering(grid, optics, UniformSky(2.0), options);
  double worst = 0.0;
  for (std::size_t i = 0; i < grid.NumberOfPoints(); ++i)
  {
    worst = std::max(worst, std::abs(MeanInScattering(field, i, 1) - 2.0) / 2.0);
  }
  return worst;
}

TEST(MultipleScattering, ConservativeCloudUnderUniformSkyHoldsTheSkyRadiance)
{
  for (double tau : { 1e-3, 1.0, 30.0, 300.0 })
  {
    for (double g : { 0.0, 0.85 })
    {
      // Iterated until an order carries < 1e-5 of the total (up to about 2000 orders
      // at tau 300, g 0: light diffuses about one mean free path per order), then the
      // geometric tail. Measured: <= 3.1e-7 up to tau 1, 5.8e-7 (tau 30), 7.7e-6 (tau
      // 300, g 0).
      EXPECT_LT(WorstDeviationUnderUniformSky(tau, g, 10000, true), 1e-4)
        << "tau " << tau << " g " << g;
    }
  }
  // The iteration alone, stopped by the same criterion: what it leaves is the
  // remainder the tail stands in for. Measured: 3.2e-6 (tau 1), 1.5e-3 (tau 30, g 0).
  for (double tau : { 1e-3, 1.0, 30.0 })
  {
    EXPECT_LT(WorstDeviationUnderUniformSky(tau, 0.0, 10000, false), 2e-3) << "tau " << tau;
  }
}

// The geometric tail after 128 orders, where the iteration is slow (isotropic, tau 30
// over 10 points): measured 4.3e-4 with the tail, 0.10 without (after 32 orders the
// dominant mode has not yet taken over: 0.47 and 0.82).
TEST(MultipleScattering, GeometricTailStandsInForTheOrdersNotComputed)
{
  const double with = WorstDeviationUnderUniformSky(30.0, 0.0, 128, true);
  const double without = WorstDeviationUnderUniformSky(30.0, 0.0, 128, false);
  EXPECT_LT(with, 0.05 * without);
  EXPECT_LT(with, 2e-3);
}

// The tail beyond Orders is a geometric series only once the ratio of successive orders
// has settled. A point light at the centre of a sphere 10 mean free paths deep, isotropic,
// albedo 0.99: the ratio falls from 0.989 (order 8) to 0.959 as the light reaches the
// boundary, and a tail taken at order 16 counted 1.49x the light (8 orders: 2.4x). The
// sun's ratio rises instead (16 orders: 0.91x). Both against 160 orders (the ratio settled,
// its tail under 1 %).
double TotalInScattering(const ExtinctionGrid& grid, const CloudLighting& lighting, int orders)
{
  const CloudOptics optics{ 0.99, PhaseFunctionKind::Isotropic, 0.0 };
  MultipleScatteringOptions options;
  options.Orders = orders;
  const auto field = nimbus::SolveMultipleScattering(grid, optics, lighting, options);
  double sum = 0.0;
  for (std::size_t i = 0; i < grid.NumberOfPoints(); ++i)
  {
    sum += field.Coefficients[12 * i];
  }
  return sum;
}

TEST(MultipleScattering, TailWaitsForTheRatioOfOrdersToSettle)
{
  const double radius = 500.0;
  ExtinctionGrid grid = UniformCube(17, 2.0 * radius, 0.02); // 62.5 m cells
  for (std::size_t i = 0; i < grid.NumberOfPoints(); ++i)
  {
    const int n = grid.Dimensions[0];
    const Vector3 p = grid.Position(i % n, (i / n) % n, i / (n * n));
    grid.Extinction[i] = nimbus::Length(p) < radius ? 0.02f : 0.0f;
  }
  CloudLighting deepLight;
  deepLight.HasSun = false;
  deepLight.PointLights.push_back({ { { 3.0, -2.0, 1.0 } }, { { 1e6, 1e6, 1e6 } } });
  CloudLighting sun;
  sun.Sun.ToLight = nimbus::Normalized(Vector3{ { 0.3, 0.2, 0.93 } });
  for (const CloudLighting* lighting : { &deepLight, &sun })
  {
    const double converged = TotalInScattering(grid, *lighting, 160);
    for (const int orders : { 8, 16 })
    {
      const double ratio = TotalInScattering(grid, *lighting, orders) / converged;
      std::printf("  %s, %d orders: %.4f of 160 orders\n", lighting == &sun ? "sun" : "deep light",
        orders, ratio);
      EXPECT_NEAR(ratio, 1.0, orders == 8 ? 0.06 : 0.01) << orders;
    }
  }
}

// Absorption: with albedo 0 nothing is scattered twice; J is the sky's light through
// the cloud, below L0 inside, and the sun adds nothing (its first order is the mapper's).
TEST(MultipleScattering, BlackCloudOnlyDimsTheSky)
{
  const ExtinctionGrid grid = UniformCube(8, 700.0, 10.0 / 700.0);
  CloudOptics optics{ 0.0, PhaseFunctionKind::CornetteShanks, 0.85 };
  CloudLighting lighting = UniformSky(1.0);
  lighting.HasSun = true;
  lighting.Sun.ToLight = { { 0, 0, 1 } };
  MultipleScatteringOptions options;
  const auto field = nimbus::SolveMultipleScattering(grid, optics, lighting, options);
  const double centre = MeanInScattering(field, grid.Index(4, 4, 4), 0);
  EXPECT_GT(centre, 0.0);
  EXPECT_LT(centre, 0.05); // tau 5 to the nearest face: exp(-5) = 0.007 at best
  lighting.Sky = nullptr;
  const auto dark = nimbus::SolveMultipleScattering(grid, optics, lighting, options);
  for (float c : dark.Coefficients)
  {
    EXPECT_EQ(c, 0.0f);
  }
}

// The second order in an optically thin cube lit by the sun at the zenith, isotropic
// phase: J2(centre) = sigma_s E / (4 pi) x <R>, <R> the mean over directions of the
// distance from the centre to the cube's surface (single scattering along every ray,
// no attenuation at tau << 1). Checked against <R> computed directly.
TEST(MultipleScattering, SecondOrderInAThinCubeMatchesTheChordIntegral)
{
  const double side = 1000.0, sigma = 1e-6;
  const ExtinctionGrid grid = UniformCube(17, side, sigma);
  CloudOptics optics{ 1.0, PhaseFunctionKind::Isotropic, 0.0 };
  CloudLighting lighting;
  lighting.Sun.ToLight = { { 0, 0, 1 } };
  lighting.Sun.ConstantIrradiance = { { 1, 1, 1 } };
  MultipleScatteringOptions options;
  options.Orders = 2;
  options.ExtrapolateHigherOrders = false;
  options.NumberOfDirections = 200;
  const auto field = nimbus::SolveMultipleScattering(grid, optics, lighting, options);
  double meanChord = 0.0;
  const auto many = nimbus::FibonacciDirections(20000);
  for (const auto& w : many)
  {
    const double m = std::max({ std::abs(w[0]), std::abs(w[1]), std::abs(w[2]) });
    meanChord += 0.5 * side / m;
  }
  meanChord /= many.size();
  const double expected = sigma * 1.0 / (4.0 * nimbus::kPi) * meanChord;
  const double got = MeanInScattering(field, grid.Index(8, 8, 8), 0);
  // Measured: ratio 0.9994 (200 directions; 0.9989 with 26, 1.0028 with 50).
  EXPECT_NEAR(got / expected, 1.0, 0.01) << got << " vs " << expected;
}

TEST(MultipleScattering, ResultsDoNotDependOnThreads)
{
  ExtinctionGrid grid = UniformCube(11, 1000.0, 0.01);
  for (std::size_t i = 0; i < grid.Extinction.size(); ++i)
  {
    grid.Extinction[i] *= static_cast<float>(0.5 + 0.5 * std::sin(0.37 * i));
  }
  CloudOptics optics;
  CloudLighting lighting = UniformSky(0.3);
  lighting.HasSun = true;
  lighting.Sun.ToLight = nimbus::Normalized({ { 0.3, -0.2, 0.8 } });
  lighting.PointLights.push_back({ { { 200, 0, -700 } }, { { 1e5, 1e5, 1e5 } } });
  MultipleScatteringOptions options;
  options.Orders = 8;
  options.Threads = 1;
  const auto one = nimbus::SolveMultipleScattering(grid, optics, lighting, options);
  options.Threads = 3;
  const auto three = nimbus::SolveMultipleScattering(grid, optics, lighting, options);
  EXPECT_EQ(one.Coefficients, three.Coefficients);
}

// The extremes: finite, non-negative mean radiance for every combination.
TEST(MultipleScattering, ExtremesStayFinite)
{
  const double elevations[] = { 90.0, 0.0, -10.0 };
  for (double tauPerCell : { 1e-3, 1.0, 1e4 })
  {
    for (double albedo : { 0.0, 1.0 })
    {
      for (double g : { -0.999, 0.0, 0.999 })
      {
        for (int n : { 1, 2, 6 })
        {
          for (double elevation : elevations)
          {
            for (auto method :
              { MultipleScatteringMethod::Octaves, MultipleScatteringMethod::DiscreteDirections })
            {
              ExtinctionGrid grid = UniformCube(n, 500.0, 0.0);
              for (float& e : grid.Extinction)
              {
                e = static_cast<float>(tauPerCell / grid.Spacing[0]);
              }
              CloudOptics optics{ albedo, PhaseFunctionKind::CornetteShanks, g };
              CloudLighting lighting = UniformSky(0.1);
              lighting.HasSun = true;
              const double e = elevation * nimbus::kPi / 180.0;
              lighting.Sun.ToLight = { { std::cos(e), 0.0, std::sin(e) } };
              MultipleScatteringOptions options;
              options.Method = method;
              options.Orders = 6;
              const auto field = nimbus::SolveMultipleScattering(grid, optics, lighting, options);
              for (std::size_t i = 0; i < grid.NumberOfPoints(); ++i)
              {
                const double mean = MeanInScattering(field, i, 0);
                ASSERT_TRUE(std::isfinite(mean));
                ASSERT_GE(mean, -1e-6);
                // Nothing brighter than the sun's and the sky's light can come out.
                ASSERT_LT(mean, 10.0) << tauPerCell << " " << albedo << " " << g << " " << n;
              }
            }
          }
        }
      }
    }
  }
}

TEST(MultipleScattering, BadInputIsRefusedWithAMessage)
{
  const CloudOptics optics;
  const CloudLighting lighting;
  const MultipleScatteringOptions options;
  auto expectRefused = [&](ExtinctionGrid grid, CloudOptics o, CloudLighting l,
                         MultipleScatteringOptions opt, const char* words)
  {
    const std::string message = nimbus::CheckMultipleScatteringInput(grid, o, l, opt);
    EXPECT_NE(message.find(words), std::string::npos) << message;
    EXPECT_THROW(nimbus::SolveMultipleScattering(grid, o, l, opt), std::invalid_argument);
  };
  const ExtinctionGrid good = UniformCube(3, 100.0, 0.01);
  EXPECT_EQ(nimbus::CheckMultipleScatteringInput(good, optics, lighting, options), "");
  for (float bad :
    { std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity(), -1.0f })
  {
    ExtinctionGrid grid = good;
    grid.Extinction[4] = bad;
    expectRefused(grid, optics, lighting, options, "extinction");
  }
  ExtinctionGrid empty = good;
  empty.Dimensions = { { 0, 3, 3 } };
  expectRefused(empty, optics, lighting, options, "at least one point");
  ExtinctionGrid shortGrid = good;
  shortGrid.Extinction.pop_back();
  expectRefused(shortGrid, optics, lighting, options, "values for");
  ExtinctionGrid flat = good;
  flat.Spacing[1] = 0.0;
  expectRefused(flat, optics, lighting, options, "spacing");
  expectRefused(
    good, CloudOptics{ 1.5, PhaseFunctionKind::CornetteShanks, 0.85 }, lighting, options, "albedo");
  expectRefused(good,
    CloudOptics{ 0.9, PhaseFunctionKind::CornetteShanks, std::numeric_limits<double>::quiet_NaN() },
    lighting, options, "asymmetry");
  CloudLighting nanSun;
  nanSun.Sun.ToLight = { { std::numeric_limits<double>::quiet_NaN(), 0, 1 } };
  expectRefused(good, optics, nanSun, options, "sun");
  MultipleScatteringOptions few = options;
  few.NumberOfDirections = 2;
  expectRefused(good, optics, lighting, few, "directions");
  MultipleScatteringOptions noOrders = options;
  noOrders.Orders = 1;
  expectRefused(good, optics, lighting, noOrders, "orders");
}

// A point light (lightning) beside the cloud: the cloud glows on its side, and the
// light it sends on travels away from the light (forward scattering).
TEST(MultipleScattering, PointLightLightsTheNearSide)
{
  const ExtinctionGrid grid = UniformCube(9, 800.0, 0.005);
  // Isotropic: with a forward peak the light scattered twice or more grows along the
  // way and is larger on the far side (the mapper adds the single scattering).
  CloudOptics optics{ 0.99, PhaseFunctionKind::Isotropic, 0.0 };
  CloudLighting lighting;
  lighting.HasSun = false;
  lighting.PointLights.push_back({ { { 1000, 0, 0 } }, { { 1e6, 1e6, 1e6 } } });
  MultipleScatteringOptions options;
  options.Orders = 10;
  const auto field = nimbus::SolveMultipleScattering(grid, optics, lighting, options);
  const double nearSide = MeanInScattering(field, grid.Index(7, 4, 4), 0);
  const double farSide = MeanInScattering(field, grid.Index(1, 4, 4), 0);
  EXPECT_GT(nearSide, 2.0 * farSide);
  // c_11 (the x component) < 0 at the centre: more light travels toward -x.
  EXPECT_LT(field.Coefficients[12 * grid.Index(4, 4, 4) + 3], 0.0f);
}

// The power a homogeneous cube takes from a point light inside it, summed over the
// solver's points from its first scattering J1 (the solve with PointLightFirstScattering
// less the one without): E = J1's c_00 / Y_00, and the ball of radius R inside the cube
// takes sum sigma E dV over its points, against the closed form 4 pi I (1 - exp(-sigma R)).
// The points next to the light take the cell average of T/r^2
// (CellAverage.h): their centre's value alone took 0.78 of the power with 0.8 mean
// free paths per cell and 0.93 with 0.2 (the loss the orders >= 2 then carried).
TEST(MultipleScattering, PointLightFirstScatteringKeepsThePowerNextToTheLight)
{
  const double side = 1200.0;
  for (const double sigma : { 0.005, 0.02 })
  {
    const ExtinctionGrid grid = UniformCube(31, side, sigma); // 40 m cells
    CloudOptics optics{ 0.99, PhaseFunctionKind::Isotropic, 0.0 };
    CloudLighting lighting;
    lighting.HasSun = false;
    // Off the grid's points, as a stroke's sources are.
    lighting.PointLights.push_back({ { { 13.0, -7.0, 5.0 } }, { { 1.0, 1.0, 1.0 } } });
    MultipleScatteringOptions options;
    options.Orders = 2;
    options.ExtrapolateHigherOrders = false;
    options.PointLightFirstScattering = true;
    const auto with = nimbus::SolveMultipleScattering(grid, optics, lighting, options);
    options.PointLightFirstScattering = false;
    const auto without = nimbus::SolveMultipleScattering(grid, optics, lighting, options);
    const double volume = grid.Spacing[0] * grid.Spacing[1] * grid.Spacing[2];
    double ball = 0.0;
    const double radius = 0.5 * side;
    for (std::size_t i = 0; i < grid.NumberOfPoints(); ++i)
    {
      const int n = grid.Dimensions[0];
      const Vector3 p = grid.Position(i % n, (i / n) % n, i / (n * n));
      const Vector3 d{ { p[0] - 13.0, p[1] + 7.0, p[2] - 5.0 } };
      if (nimbus::Length(d) > radius)
      {
        continue;
      }
      const double e = (with.Coefficients[12 * i] - without.Coefficients[12 * i]) / kY00;
      ball += grid.Extinction[i] * e * volume;
    }
    const double closed = 4.0 * nimbus::kPi * (1.0 - std::exp(-sigma * radius));
    std::printf("  sigma %.3f /m (%.1f mean free paths per cell): the ball takes %.4f of the "
                "closed form\n",
      sigma, sigma * grid.Spacing[0], ball / closed);
    EXPECT_NEAR(ball / closed, 1.0, 0.05) << sigma;
  }
}

// A spotlight (PointLight::Spot, SpotLight.h) 300 m below the base of a 1 km cube of
// cloud: its factor scales the light's irradiance wherever the solver computes it (the
// first scattering and the source of the higher orders).
struct SpotCase
{
  explicit SpotCase(double sigma)
    : Grid(UniformCube(11, 1000.0, sigma))
  {
  }
  ExtinctionGrid Grid;
  CloudOptics Optics{ 0.99, PhaseFunctionKind::CornetteShanks, 0.85 };
  Vector3 Light{ { 0.0, 0.0, -800.0 } };

  nimbus::MultipleScatteringField Solve(const nimbus::SpotProfile& spot, bool firstScattering) const
  {
    CloudLighting lighting;
    lighting.HasSun = false;
    lighting.PointLights.push_back({ this->Light, { { 1e6, 2e6, 3e6 } }, spot });
    MultipleScatteringOptions options;
    options.Orders = 10;
    options.PointLightFirstScattering = firstScattering;
    return nimbus::SolveMultipleScattering(this->Grid, this->Optics, lighting, options);
  }
  // The angle [degrees] between +z and grid point i seen from the light.
  double AngleFromAxis(std::size_t i) const
  {
    const int n = this->Grid.Dimensions[0];
    const Vector3 p = this->Grid.Position(i % n, (i / n) % n, i / (n * n));
    const Vector3 d{ { p[0] - this->Light[0], p[1] - this->Light[1], p[2] - this->Light[2] } };
    return std::acos(d[2] / nimbus::Length(d)) / nimbus::kDegree;
  }
};

nimbus::SpotProfile Beam(const Vector3& axis, double cone)
{
  nimbus::SpotProfile spot;
  spot.Axis = axis;
  spot.ConeHalfAngleDegrees = cone;
  return spot;
}

TEST(MultipleScattering, SpotlightMissingTheCloudPutsNoLightInIt)
{
  const SpotCase scene(0.002);
  for (bool first : { false, true })
  {
    // Pointing down, away from the cloud; and sideways, its 30-degree cone passing
    // beside the cube.
    for (const Vector3& axis : { Vector3{ { 0, 0, -1 } }, Vector3{ { 1, 0, 0 } } })
    {
      const auto field = scene.Solve(Beam(axis, 30.0), first);
      for (float c : field.Coefficients)
      {
        ASSERT_EQ(c, 0.0f) << first;
      }
    }
  }
}

TEST(MultipleScattering, SpotlightWithAWideConeIsThePointLight)
{
  const SpotCase scene(0.002);
  for (bool first : { false, true })
  {
    const auto point = scene.Solve(nimbus::SpotProfile{}, first);
    // 180 and 90 degrees: point lights. 75 degrees straight up: the whole cube lies
    // inside the cone (its widest angle, to the base's corners, is atan(707 / 300) =
    // 67 degrees), so every factor is exactly 1 too.
    for (double cone : { 180.0, 90.0, 75.0 })
    {
      const auto spot = scene.Solve(Beam({ { 0, 0, 1 } }, cone), first);
      EXPECT_EQ(spot.Coefficients, point.Coefficients) << cone << " " << first;
    }
  }
}

TEST(MultipleScattering, SpotlightWithABadBeamIsRefused)
{
  const SpotCase scene(0.002);
  const MultipleScatteringOptions options;
  auto message = [&](const nimbus::SpotProfile& spot)
  {
    CloudLighting lighting;
    lighting.HasSun = false;
    lighting.PointLights.push_back({ scene.Light, { { 1, 1, 1 } }, spot });
    return nimbus::CheckMultipleScatteringInput(scene.Grid, scene.Optics, lighting, options);
  };
  EXPECT_EQ(message(Beam({ { 0, 0, 1 } }, 30.0)), "");
  EXPECT_NE(message(Beam({ { 0, 0, 2 } }, 30.0)).find("axis"), std::string::npos);
  EXPECT_NE(
    message(Beam({ { 0, std::numeric_limits<double>::quiet_NaN(), 1 } }, 30.0)).find("axis"),
    std::string::npos);
  EXPECT_NE(message(Beam({ { 0, 0, 1 } }, std::numeric_limits<double>::quiet_NaN())).find("cone"),
    std::string::npos);
  EXPECT_NE(message(Beam({ { 0, 0, 1 } }, -5.0)).find("cone"), std::string::npos);
  nimbus::SpotProfile edge = Beam({ { 0, 0, 1 } }, 30.0);
  edge.EdgeWidthDegrees = -1.0;
  EXPECT_NE(message(edge).find("edge"), std::string::npos);
  // A point light's axis is not used: any axis passes.
  EXPECT_EQ(message(Beam({ { 0, 0, 0 } }, 180.0)), "");
}

// A 30-degree cone straight up into the cube. The first scattering is the point
// light's exactly inside the cone and 0 outside; the higher orders are less
// everywhere, since the cloud outside the cone no longer sends light in. In a thin
// cloud (optical thickness 0.2) the first scattering dominates, and J well inside
// the cone is the point light's within the share of those missing orders.
TEST(MultipleScattering, SpotlightLightsItsConeLikeThePointLight)
{
  const SpotCase scene(0.0002);
  const auto point = scene.Solve(nimbus::SpotProfile{}, true);
  const auto spot = scene.Solve(Beam({ { 0, 0, 1 } }, 30.0), true);
  const auto pointHigher = scene.Solve(nimbus::SpotProfile{}, false);
  const auto spotHigher = scene.Solve(Beam({ { 0, 0, 1 } }, 30.0), false);
  double worstInside = 0.0, largestOutside = 0.0, worstFirst = 0.0;
  int inside = 0, outside = 0;
  for (std::size_t i = 0; i < scene.Grid.NumberOfPoints(); ++i)
  {
    const double angle = scene.AngleFromAxis(i);
    for (int c = 0; c < 3; ++c)
    {
      const double p = MeanInScattering(point, i, c), s = MeanInScattering(spot, i, c);
      const double ph = MeanInScattering(pointHigher, i, c);
      const double sh = MeanInScattering(spotHigher, i, c);
      ASSERT_GT(p, 0.0);
      EXPECT_LE(s, p * (1.0 + 1e-6)) << i;
      EXPECT_LE(sh, ph * (1.0 + 1e-6)) << i;
      // The first scattering, J - J(orders >= 2): the point light's (factor 1) inside
      // the cone, none outside (float rounding of the sums; measured 1.2e-7 of J).
      const double firstPoint = p - ph, firstSpot = s - sh;
      if (angle < 29.9 || angle > 30.1)
      {
        const double expected = angle < 30.0 ? firstPoint : 0.0;
        EXPECT_NEAR(firstSpot, expected, 1e-5 * p) << i << " " << angle;
        worstFirst = std::max(worstFirst, std::abs(firstSpot - expected) / p);
      }
      if (angle < 10.0)
      {
        worstInside = std::max(worstInside, 1.0 - s / p);
        inside += c == 0;
      }
      else if (angle > 35.0)
      {
        largestOutside = std::max(largestOutside, s / p);
        outside += c == 0;
      }
    }
  }
  std::cout << inside << " points within 10 degrees of the axis: J at least " << 1.0 - worstInside
            << " of the point light's; " << outside << " beyond 35 degrees: at most "
            << largestOutside << "; first scattering off by at most " << worstFirst << " of J\n";
  // Measured: 0.9914 within 10 degrees (within 20: 0.986), at most 0.017 beyond 35.
  EXPECT_LT(worstInside, 0.02);
  EXPECT_LT(largestOutside, 0.05);
}
// --- The medium's own emission (CloudLighting::Emission) ------------------------------

CloudLighting Glowing(const ExtinctionGrid& grid, const nimbus::Rgb& eta)
{
  CloudLighting lighting;
  lighting.HasSun = false;
  lighting.Emission.resize(3 * grid.NumberOfPoints());
  for (std::size_t i = 0; i < grid.NumberOfPoints(); ++i)
  {
    for (int c = 0; c < 3; ++c)
    {
      lighting.Emission[3 * i + c] = grid.Extinction[i] > 0.0f ? static_cast<float>(eta[c]) : 0.0f;
    }
  }
  return lighting;
}

// Deep inside a large homogeneous glowing box the radiance is the equilibrium of the
// RTE, dL/ds = -sigma_t L + sigma_s J + eta = 0 with J = L: L = eta / (sigma_t (1 - a)),
// whatever the phase function; J (the emitted light of every order, scattered) is
// that radiance, isotropic.
TEST(MultipleScatteringEmission, DeepInsideAGlowingBoxTheRadianceIsTheEquilibrium)
{
  const double sigma = 2.0; // 1/m; the centre lies 20 optical depths from every face
  const ExtinctionGrid grid = UniformCube(25, 20.0, sigma);
  const nimbus::Rgb eta{ { 1.0, 0.5, 0.25 } };
  const std::size_t centre = grid.Index(12, 12, 12);
  for (double albedo : { 0.0, 0.6, 0.9 })
  {
    CloudOptics optics{ albedo, PhaseFunctionKind::HenyeyGreenstein, 0.3 };
    MultipleScatteringOptions options;
    options.Orders = 200;
    const auto field = nimbus::SolveMultipleScattering(grid, optics, Glowing(grid, eta), options);
    for (int c = 0; c < 3; ++c)
    {
      const double expected = eta[c] / (sigma * (1.0 - albedo));
      const double got = MeanInScattering(field, centre, c);
      // Measured: ratio 1.000000 (albedo 0), 0.999999 (0.6), 0.99856 (0.9: the orders'
      // tail); the degree-1 part is not exactly 0 (the 26 Fibonacci directions do not
      // sum to exactly 0, FibonacciDirectionsAreUnitAndBalanced).
      EXPECT_NEAR(got / expected, 1.0, 2e-3) << albedo << " " << c;
      for (int b = 1; b < 4; ++b)
      {
        const double ratio = std::abs(field.Coefficients[12 * centre + 4 * c + b]) / (got / kY00);
        std::cout << (b == 1 && c == 0 ? "albedo " + std::to_string(albedo) + ": J / closed form " +
              std::to_string(got / expected) + "\n"
                                       : "");
        EXPECT_LT(ratio, 0.01) << albedo << " " << c << " " << b;
      }
    }
  }
}

// The first scattering at the centre of a glowing sphere that absorbs only: the emitted
// radiance arriving from every direction is (eta / sigma)(1 - exp(-sigma R)), and with
// albedo 0 nothing is scattered again (J holds the first scattering alone: the same
// with 2 orders as with 200).
TEST(MultipleScatteringEmission, CentreOfAnAbsorbingGlowingSphere)
{
  const double radius = 8.0, sigma = 1.0 / radius; // sigma R = 1
  ExtinctionGrid grid = UniformCube(41, 20.0, sigma);
  for (int k = 0; k < 41; ++k)
  {
    for (int j = 0; j < 41; ++j)
    {
      for (int i = 0; i < 41; ++i)
      {
        const Vector3 p = grid.Position(i, j, k);
        grid.Extinction[grid.Index(i, j, k)] =
          nimbus::Length(p) <= radius ? static_cast<float>(sigma) : 0.0f;
      }
    }
  }
  const CloudLighting lighting = Glowing(grid, { { 1.0, 1.0, 1.0 } });
  CloudOptics optics{ 0.0, PhaseFunctionKind::CornetteShanks, 0.3 };
  MultipleScatteringOptions options;
  options.Orders = 200;
  const auto many = nimbus::SolveMultipleScattering(grid, optics, lighting, options);
  options.Orders = 2;
  const auto two = nimbus::SolveMultipleScattering(grid, optics, lighting, options);
  EXPECT_EQ(many.Coefficients, two.Coefficients);
  const double expected = (1.0 - std::exp(-sigma * radius)) / sigma;
  const double got = MeanInScattering(many, grid.Index(20, 20, 20), 0);
  std::cout << "glowing sphere's centre: J " << got << ", closed form " << expected << "\n";
  // Measured: ratio 0.995 (the sphere's trilinear edge on a grid of 0.5 m).
  EXPECT_NEAR(got / expected, 1.0, 0.02);
}

// J is linear in the sources: twice the emission gives twice J (exactly: a power of 2),
// the sun and the glow together give the sum of each alone, and an emission of zeros
// changes nothing (bit-identical).
TEST(MultipleScatteringEmission, JIsLinearInTheSources)
{
  ExtinctionGrid grid = UniformCube(11, 20.0, 0.5);
  for (std::size_t i = 0; i < grid.Extinction.size(); ++i)
  {
    grid.Extinction[i] *= static_cast<float>(0.5 + 0.5 * std::sin(0.37 * i));
  }
  CloudOptics optics{ 0.6, PhaseFunctionKind::CornetteShanks, 0.3 };
  MultipleScatteringOptions options;
  options.Orders = 400;
  options.ExtrapolateHigherOrders = false;
  CloudLighting glow = Glowing(grid, { { 0.3, 0.2, 0.1 } });
  for (std::size_t i = 0; i < grid.NumberOfPoints(); ++i)
  {
    glow.Emission[3 * i] *= static_cast<float>(1.0 + std::cos(0.11 * i));
  }
  CloudLighting twice = glow;
  for (float& e : twice.Emission)
  {
    e *= 2.0f;
  }
  CloudLighting sun = UniformSky(0.2);
  sun.HasSun = true;
  sun.Sun.ToLight = nimbus::Normalized({ { 0.3, -0.2, 0.8 } });
  CloudLighting both = sun;
  both.Emission = glow.Emission;
  CloudLighting zeros = sun;
  zeros.Emission.assign(glow.Emission.size(), 0.0f);
  const auto g = nimbus::SolveMultipleScattering(grid, optics, glow, options);
  const auto g2 = nimbus::SolveMultipleScattering(grid, optics, twice, options);
  const auto s = nimbus::SolveMultipleScattering(grid, optics, sun, options);
  const auto b = nimbus::SolveMultipleScattering(grid, optics, both, options);
  const auto z = nimbus::SolveMultipleScattering(grid, optics, zeros, options);
  EXPECT_EQ(s.Coefficients, z.Coefficients);
  double largest = 0.0, worstSum = 0.0;
  for (float c : b.Coefficients)
  {
    largest = std::max(largest, static_cast<double>(std::abs(c)));
  }
  for (std::size_t q = 0; q < g.Coefficients.size(); ++q)
  {
    EXPECT_EQ(g2.Coefficients[q], 2.0f * g.Coefficients[q]);
    worstSum = std::max(worstSum,
      std::abs(static_cast<double>(b.Coefficients[q]) - s.Coefficients[q] - g.Coefficients[q]));
  }
  std::cout << "sun + glow against each alone: " << worstSum / largest << " of the largest\n";
  // Measured: 2.4e-7 (float sums; each solve stops on its own order).
  EXPECT_LT(worstSum, 1e-5 * largest);
}

// Energy balance of a small glowing box in a larger empty grid: the power emitted,
// 4 pi sum eta dV, leaves as the power absorbed, 4 pi sum sigma_a <L> dV (<L> = c_00
// Y_00 the mean radiance), plus the power through the grid's faces, sum F . n dA (the
// flux F = integral L w dw from J's degree-1 coefficients: F = c_1 / (k_1 Y_1)).
TEST(MultipleScatteringEmission, EnergyBalanceOfASmallBox)
{
  const int n = 21;
  ExtinctionGrid grid = UniformCube(n, 10.0, 0.0); // 0.5 m spacing
  for (int k = 6; k <= 14; ++k)
  {
    for (int j = 6; j <= 14; ++j)
    {
      for (int i = 6; i <= 14; ++i)
      {
        grid.Extinction[grid.Index(i, j, k)] = 0.4f; // 1/m: 1.6 optical depths across
      }
    }
  }
  const double albedo = 0.6, g = 0.5;
  CloudOptics optics{ albedo, PhaseFunctionKind::HenyeyGreenstein, g };
  const CloudLighting lighting = Glowing(grid, { { 1.0, 1.0, 1.0 } });
  MultipleScatteringOptions options;
  options.Orders = 200;
  options.NumberOfDirections = 100;
  const auto field = nimbus::SolveMultipleScattering(grid, optics, lighting, options);
  const double h = grid.Spacing[0], cell = h * h * h;
  double emitted = 0.0, absorbed = 0.0, escaped = 0.0;
  for (std::size_t i = 0; i < grid.NumberOfPoints(); ++i)
  {
    emitted += 4.0 * nimbus::kPi * lighting.Emission[3 * i] * cell;
    absorbed += 4.0 * nimbus::kPi * (1.0 - albedo) * grid.Extinction[i] *
      MeanInScattering(field, i, 0) * cell;
  }
  constexpr double kY1 = 0.4886025119029199;
  // c_1-1, c_10, c_11 hold w_y, w_z, w_x.
  const int component[3] = { 3, 1, 2 };
  for (int axis = 0; axis < 3; ++axis)
  {
    for (int side = 0; side < 2; ++side)
    {
      for (int v = 0; v < n; ++v)
      {
        for (int u = 0; u < n; ++u)
        {
          int idx[3];
          idx[axis] = side ? n - 1 : 0;
          idx[(axis + 1) % 3] = u;
          idx[(axis + 2) % 3] = v;
          const double weight =
            (u == 0 || u == n - 1 ? 0.5 : 1.0) * (v == 0 || v == n - 1 ? 0.5 : 1.0);
          const double f =
            field.Coefficients[12 * grid.Index(idx[0], idx[1], idx[2]) + component[axis]] /
            (g * kY1);
          escaped += (side ? f : -f) * weight * h * h;
        }
      }
    }
  }
  std::cout << "glowing box: emitted " << emitted << ", absorbed " << absorbed << ", escaped "
            << escaped << ": balance " << (absorbed + escaped) / emitted << "\n";
  // Measured: 0.952 (absorbed 0.271, escaped 0.681 of the emitted power); the 4.8 %
  // missing were not split between the solver and this measure of the flux (a
  // trapezoid over the faces' grid points, the flux from degree-1 harmonics).
  EXPECT_NEAR((absorbed + escaped) / emitted, 1.0, 0.06);
}

TEST(MultipleScatteringEmission, BadEmissionIsRefused)
{
  const ExtinctionGrid grid = UniformCube(3, 100.0, 0.01);
  const CloudOptics optics;
  const MultipleScatteringOptions options;
  EXPECT_EQ(
    nimbus::CheckMultipleScatteringInput(grid, optics, Glowing(grid, { { 1, 1, 1 } }), options),
    "");
  auto expectRefused =
    [&](const CloudLighting& lighting, const MultipleScatteringOptions& opt, const char* words)
  {
    const std::string message = nimbus::CheckMultipleScatteringInput(grid, optics, lighting, opt);
    EXPECT_NE(message.find(words), std::string::npos) << message;
    EXPECT_THROW(
      nimbus::SolveMultipleScattering(grid, optics, lighting, opt), std::invalid_argument);
  };
  CloudLighting shortEmission = Glowing(grid, { { 1, 1, 1 } });
  shortEmission.Emission.pop_back();
  expectRefused(shortEmission, options, "3 per point");
  for (float bad :
    { std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity(), -1.0f })
  {
    CloudLighting lighting = Glowing(grid, { { 1, 1, 1 } });
    lighting.Emission[7] = bad;
    expectRefused(lighting, options, "emission must be finite");
  }
  for (auto method :
    { MultipleScatteringMethod::Octaves, MultipleScatteringMethod::ReferencePatterns })
  {
    MultipleScatteringOptions other = options;
    other.Method = method;
    expectRefused(Glowing(grid, { { 1, 1, 1 } }), other, "discrete-direction method only");
  }
  // None computes nothing and ignores it.
  MultipleScatteringOptions none = options;
  none.Method = MultipleScatteringMethod::None;
  const auto field =
    nimbus::SolveMultipleScattering(grid, optics, Glowing(grid, { { 1, 1, 1 } }), none);
  for (float c : field.Coefficients)
  {
    EXPECT_EQ(c, 0.0f);
  }
}
// The glow's first scattering apart (EmissionFirstScattering, EmissionFirstScatteringApart):
// the solve without it plus it is the whole solve; with albedo 0 it is the whole J.
TEST(MultipleScatteringEmission, FirstScatteringApartAddsUpToTheWhole)
{
  ExtinctionGrid grid = UniformCube(11, 20.0, 0.5);
  for (std::size_t i = 0; i < grid.Extinction.size(); ++i)
  {
    grid.Extinction[i] *= static_cast<float>(0.5 + 0.5 * std::sin(0.37 * i));
  }
  CloudLighting lighting = Glowing(grid, { { 0.3, 0.2, 0.1 } });
  lighting.Sky = [](const Vector3&) { return nimbus::Rgb{ { 0.1, 0.1, 0.1 } }; };
  for (double albedo : { 0.0, 0.6 })
  {
    CloudOptics optics{ albedo, PhaseFunctionKind::CornetteShanks, 0.3 };
    MultipleScatteringOptions options;
    options.Orders = 400;
    options.ExtrapolateHigherOrders = false;
    const auto whole = nimbus::SolveMultipleScattering(grid, optics, lighting, options);
    options.EmissionFirstScatteringApart = true;
    const auto rest = nimbus::SolveMultipleScattering(grid, optics, lighting, options);
    const auto first = nimbus::EmissionFirstScattering(grid, optics, lighting.Emission, options);
    double largest = 0.0, worst = 0.0;
    for (std::size_t q = 0; q < whole.Coefficients.size(); ++q)
    {
      largest = std::max(largest, static_cast<double>(std::abs(whole.Coefficients[q])));
      worst = std::max(worst,
        std::abs(static_cast<double>(whole.Coefficients[q]) - rest.Coefficients[q] - first[q]));
    }
    std::cout << "albedo " << albedo << ": whole - (rest + first) " << worst / largest
              << " of the largest\n";
    // Measured: 1e-7 (float sums).
    EXPECT_LT(worst, 1e-5 * largest) << albedo;
  }
  MultipleScatteringOptions octaves;
  octaves.Method = MultipleScatteringMethod::Octaves;
  EXPECT_THROW(nimbus::EmissionFirstScattering(grid, CloudOptics(), lighting.Emission, octaves),
    std::invalid_argument);
}
} // namespace
