// Precomputed lightning (Physics/LightningBasis.h, 003 §4-§7): the relight from the basis
// against the direct multiple-scattering solve with the same point lights, exactness at
// the virtual lights, compression against the threshold, thread independence, refusals.
// Bounds: exact ones from rounding, the others from the measured values printed.
#include "LightningBasis.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

namespace
{
using nimbus::CloudLighting;
using nimbus::CloudOptics;
using nimbus::ExtinctionGrid;
using nimbus::PointLight;
using nimbus::Rgb;

/// An ellipsoidal cloud, 16 x 16 x 4 points 100 m apart, base at z = 1000 m, extinction
/// 0.02 /m at its centre falling to 0 at its rim (optical depth about 6 top to bottom).
ExtinctionGrid Cloud(int nx = 16, int ny = 16, int nz = 4)
{
  ExtinctionGrid grid;
  grid.Dimensions = { { nx, ny, nz } };
  grid.Origin = { { -50.0 * (nx - 1), -50.0 * (ny - 1), 1000.0 } };
  grid.Spacing = { { 100.0, 100.0, 100.0 } };
  grid.Extinction.resize(grid.NumberOfPoints());
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
      {
        const double x = (i - 0.5 * (nx - 1)) / (0.5 * nx), y = (j - 0.5 * (ny - 1)) / (0.5 * ny);
        const double z = (k - 0.5 * (nz - 1)) / (0.5 * nz + 0.5);
        const double r2 = x * x + y * y + z * z;
        grid.Extinction[grid.Index(i, j, k)] =
          r2 < 1.0 ? static_cast<float>(0.02 * (1.0 - r2)) : 0.0f;
      }
  return grid;
}

nimbus::VirtualLightGrid Lights(double interval = 400.0)
{
  nimbus::VirtualLightGridParameters p;
  p.Low = { { -800.0, -800.0, 0.0 } };
  p.High = { { 800.0, 800.0, 1400.0 } };
  p.CloudBottom = 1000.0;
  p.BaseInterval = interval;
  return nimbus::MakeVirtualLightGrid(p);
}

nimbus::MultipleScatteringField Direct(const ExtinctionGrid& cloud, const CloudOptics& optics,
  const std::vector<PointLight>& sources, const nimbus::LightningBasisOptions& o)
{
  CloudLighting lighting;
  lighting.HasSun = false;
  lighting.PointLights = sources;
  nimbus::MultipleScatteringOptions s;
  s.NumberOfDirections = o.NumberOfDirections;
  s.Orders = o.Orders;
  s.SkyLight = false;
  s.PointLightFirstScattering = o.IncludeFirstScattering;
  return nimbus::SolveMultipleScattering(cloud, optics, lighting, s);
}

/// RMS of a - b over the cloud's points (c_00 of every channel) relative to the RMS of b.
double RelativeRms(
  const ExtinctionGrid& cloud, const std::vector<float>& a, const std::vector<float>& b)
{
  double difference = 0.0, reference = 0.0;
  for (std::size_t i = 0; i < cloud.NumberOfPoints(); ++i)
  {
    if (cloud.Extinction[i] <= 0.0f)
    {
      continue;
    }
    for (int c = 0; c < 3; ++c)
    {
      const double x = a[12 * i + 4 * c], y = b[12 * i + 4 * c];
      difference += (x - y) * (x - y);
      reference += y * y;
    }
  }
  return std::sqrt(difference / reference);
}
/// 3 x 3 x 2 virtual lights 400 m apart around the 8 x 8 x 2 cloud (file and colour cases).
nimbus::VirtualLightGrid FewLights()
{
  nimbus::VirtualLightGridParameters p;
  p.Low = { { -400.0, -400.0, 600.0 } };
  p.High = { { 400.0, 400.0, 1200.0 } };
  p.CloudBottom = 1000.0;
  p.BaseInterval = 400.0;
  return nimbus::MakeVirtualLightGrid(p);
}

/// A cheap solve: 6 directions, 4 orders, 2 threads.
nimbus::LightningBasisOptions QuickOptions()
{
  nimbus::LightningBasisOptions o;
  o.NumberOfDirections = 6;
  o.Orders = 4;
  o.Threads = 2;
  return o;
}
} // namespace

// A source on a virtual light, xi = 0: the relight is the direct solve (linearity of
// 003 Eq. 1 and an exact codec), up to float rounding.
TEST(LightningBasis, ExactAtTheVirtualLights)
{
  const ExtinctionGrid cloud = Cloud();
  const CloudOptics optics;
  const nimbus::VirtualLightGrid lights = Lights();
  nimbus::LightningBasisOptions o;
  o.Threshold = 0.0;
  const nimbus::LightningBasis basis = nimbus::PrecomputeLightningBasis(cloud, optics, lights, o);
  std::printf("  %zu virtual lights, cloud %zu points: %.2f s\n", lights.NumberOfNodes(),
    cloud.NumberOfPoints(), basis.Seconds);
  const std::vector<PointLight> sources = {
    PointLight{ lights.Position(2, 2, 1), { { 3.0, 2.0, 1.0 } } },
    PointLight{ lights.Position(1, 3, 2), { { 0.5, 0.5, 0.5 } } },
  };
  const auto relit =
    nimbus::RelightLightning(basis, nimbus::DistributeToVirtualLights(lights, sources));
  const auto direct = Direct(cloud, optics, sources, o);
  const double error = RelativeRms(cloud, relit.Coefficients, direct.Coefficients);
  std::printf("  relight vs direct, sources on nodes, xi 0: relative RMS %.2e\n", error);
  EXPECT_LT(error, 1e-5);
}

// A stroke through and below the cloud: the relight against the direct solve with the
// stroke's own point sources (the trilinear spread to the virtual lights is the only
// approximation at xi = 0), with and without the first scattering in the basis, and the
// error and memory against xi. Measured values printed; docs/lightning.md has the table.
TEST(LightningBasis, StrokeAgainstDirectSolve)
{
  const ExtinctionGrid cloud = Cloud();
  const CloudOptics optics;
  const nimbus::VirtualLightGrid lights = Lights(400.0);
  nimbus::LightningParameters p;
  p.Start = { { 100.0, -50.0, 1250.0 } };
  p.Length = 1500.0;
  p.SegmentLength = 40.0;
  p.StopBelowHeight = 0.0;
  p.Seed = 3;
  const auto sources = nimbus::LightningPointSources(nimbus::GenerateLightning(p), 20.0);
  const std::vector<Rgb> e = nimbus::DistributeToVirtualLights(lights, sources);
  for (const bool first : { true, false })
  {
    nimbus::LightningBasisOptions o;
    o.Threshold = 0.0;
    o.IncludeFirstScattering = first;
    const auto solveStart = std::chrono::steady_clock::now();
    const auto direct = Direct(cloud, optics, sources, o);
    const double solveSeconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - solveStart).count();
    const nimbus::LightningBasis exact = nimbus::PrecomputeLightningBasis(cloud, optics, lights, o);
    const auto relitStart = std::chrono::steady_clock::now();
    const auto relit = nimbus::RelightLightning(exact, e);
    const double relitSeconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - relitStart).count();
    const double spread = RelativeRms(cloud, relit.Coefficients, direct.Coefficients);
    std::printf("  %s: %zu point sources, %zu virtual lights; precompute %.2f s, direct solve "
                "%.3f s, relight %.5f s (%.0fx); relative RMS %.4f\n",
      first ? "with the first scattering" : "orders >= 2 only", sources.size(),
      lights.NumberOfNodes(), exact.Seconds, solveSeconds, relitSeconds,
      solveSeconds / relitSeconds, spread);
    // Measured: 0.86 with the first scattering (the sources' 1/r^2 near the channel,
    // spread over nodes 400 m apart), 0.44 without; the solver keeps the power next to
    // each source (the cell average, CellAverage.h), which the nodes' spread moves
    // (0.63 and 0.35 with the centre's value, which lost that power in both). In the
    // picture the two agree to 0.1 % of the mean (docs/lightning.md).
    EXPECT_LT(spread, first ? 0.9 : 0.47);
    std::printf("  xi      kept coefficients  memory ratio  RMS vs xi 0\n");
    double previous = 0.0;
    for (double xi : { 1e-3, 1e-2, 1e-1 })
    {
      o.Threshold = xi;
      const nimbus::LightningBasis basis =
        nimbus::PrecomputeLightningBasis(cloud, optics, lights, o);
      const auto approx = nimbus::RelightLightning(basis, e);
      const double error = RelativeRms(cloud, approx.Coefficients, relit.Coefficients);
      std::printf("  %-7g %10.0f %14.1f %13.4f\n", xi, basis.CompressedBytes() / 8.0,
        basis.UncompressedBytes() / basis.CompressedBytes(), error);
      EXPECT_GE(error, previous) << "the error should grow with xi";
      previous = error;
      if (xi <= 1e-3)
      {
        // Measured at 1e-3 (xi relative to the basis's largest coefficient): 0.0086 with
        // the first scattering (1.3x less memory), 0.0148 for orders >= 2 (2.7x).
        EXPECT_LT(error, first ? 0.012 : 0.02) << xi;
      }
    }
  }
}

// The basis does not depend on the number of threads.
TEST(LightningBasis, IndependentOfThreads)
{
  const ExtinctionGrid cloud = Cloud(8, 8, 4);
  const nimbus::VirtualLightGrid lights = Lights(800.0);
  nimbus::LightningBasisOptions o;
  o.Threads = 1;
  const auto one = nimbus::PrecomputeLightningBasis(cloud, CloudOptics(), lights, o);
  o.Threads = 3;
  const auto three = nimbus::PrecomputeLightningBasis(cloud, CloudOptics(), lights, o);
  ASSERT_EQ(one.Fields.size(), three.Fields.size());
  for (std::size_t f = 0; f < one.Fields.size(); ++f)
  {
    ASSERT_EQ(one.Fields[f].Index, three.Fields[f].Index) << f;
    ASSERT_EQ(one.Fields[f].Value, three.Fields[f].Value) << f;
  }
}

// Refusals: a bad threshold, a cloud the solver refuses, a budget too small, a relight
// with the wrong number of intensities or a NaN one; progress reaches 1.
TEST(LightningBasis, BadInputRefused)
{
  const ExtinctionGrid cloud = Cloud(8, 8, 4);
  const nimbus::VirtualLightGrid lights = Lights(800.0);
  nimbus::LightningBasisOptions o;
  o.Threshold = std::nan("");
  EXPECT_THROW(
    nimbus::PrecomputeLightningBasis(cloud, CloudOptics(), lights, o), std::invalid_argument);
  o = nimbus::LightningBasisOptions();
  ExtinctionGrid broken = cloud;
  broken.Extinction[5] = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THROW(
    nimbus::PrecomputeLightningBasis(broken, CloudOptics(), lights, o), std::invalid_argument);
  o.MemoryBudgetBytes = 1024.0;
  try
  {
    nimbus::PrecomputeLightningBasis(cloud, CloudOptics(), lights, o);
    ADD_FAILURE() << "a 1 KiB budget was not refused";
  }
  catch (const std::length_error& e)
  {
    EXPECT_NE(std::string(e.what()).find("budget"), std::string::npos) << e.what();
  }
  o = nimbus::LightningBasisOptions();
  double last = 0.0;
  const auto basis =
    nimbus::PrecomputeLightningBasis(cloud, CloudOptics(), lights, o, [&](double f) { last = f; });
  EXPECT_EQ(last, 1.0);
  EXPECT_THROW(nimbus::RelightLightning(basis, std::vector<Rgb>(3)), std::invalid_argument);
  std::vector<Rgb> e(lights.NumberOfNodes(), Rgb{ { 0, 0, 0 } });
  e[1][2] = std::nan("");
  EXPECT_THROW(nimbus::RelightLightning(basis, e), std::invalid_argument);
  // Zero intensity everywhere: a dark cloud.
  e[1][2] = 0.0;
  const auto dark = nimbus::RelightLightning(basis, e);
  for (float v : dark.Coefficients)
  {
    ASSERT_EQ(v, 0.0f);
  }
}

// The disk cache's file: a round trip relights identically; another fingerprint, a
// truncation at every length and random byte damage are refused or read, never crash,
// and a refusal leaves the caller's basis as it was.
TEST(LightningBasis, FileRoundTripAndDamage)
{
  const ExtinctionGrid cloud = Cloud(8, 8, 2);
  nimbus::LightningBasisOptions o = QuickOptions();
  o.Threshold = 1e-2;
  const nimbus::VirtualLightGrid lights = FewLights();
  const nimbus::LightningBasis basis =
    nimbus::PrecomputeLightningBasis(cloud, CloudOptics(), lights, o);
  const std::string key = nimbus::LightningBasisFingerprint(cloud, CloudOptics(), lights, o);
  EXPECT_EQ(key.size(), 32u);

  // The fingerprint follows every input that changes the basis.
  ExtinctionGrid denser = cloud;
  denser.Extinction[10] *= 1.001f;
  CloudOptics forward;
  forward.G = 0.9;
  nimbus::LightningBasisOptions finer = o;
  finer.Threshold = 1e-3;
  nimbus::LightningBasisOptions threads = o;
  threads.Threads = 1;
  EXPECT_NE(key, nimbus::LightningBasisFingerprint(denser, CloudOptics(), lights, o));
  EXPECT_NE(key, nimbus::LightningBasisFingerprint(cloud, forward, lights, o));
  EXPECT_NE(key, nimbus::LightningBasisFingerprint(cloud, CloudOptics(), lights, finer));
  EXPECT_EQ(key, nimbus::LightningBasisFingerprint(cloud, CloudOptics(), lights, threads));

  const std::string path = ::testing::TempDir() + "nimbus-lightning-basis-test.bin";
  nimbus::WriteLightningBasis(basis, key, path);
  nimbus::LightningBasis read;
  std::string why;
  ASSERT_TRUE(nimbus::ReadLightningBasis(path, key, read, why)) << why;
  std::vector<Rgb> e(lights.NumberOfNodes());
  for (std::size_t l = 0; l < e.size(); ++l)
  {
    e[l] = { { 1.0 + l, 0.5, 2.0 } };
  }
  EXPECT_EQ(nimbus::RelightLightning(basis, e).Coefficients,
    nimbus::RelightLightning(read, e).Coefficients);
  EXPECT_DOUBLE_EQ(read.CompressedBytes(), basis.CompressedBytes());

  nimbus::LightningBasis untouched;
  EXPECT_FALSE(nimbus::ReadLightningBasis(path, std::string(32, '0'), untouched, why));
  EXPECT_NE(why.find("another basis"), std::string::npos) << why;
  EXPECT_FALSE(nimbus::ReadLightningBasis(path + ".missing", key, untouched, why));

  std::ifstream in(path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_GT(bytes.size(), 100u);
  const std::string damagedPath = path + ".damaged";
  const auto readBack = [&](const std::string& content)
  {
    {
      std::ofstream out(damagedPath, std::ios::binary | std::ios::trunc);
      out.write(content.data(), static_cast<std::streamsize>(content.size()));
    }
    nimbus::LightningBasis b;
    std::string reason;
    const bool ok = nimbus::ReadLightningBasis(damagedPath, key, b, reason);
    EXPECT_TRUE(ok || !reason.empty());
    EXPECT_TRUE(ok || b.Fields.empty());
    return ok;
  };
  int refused = 0;
  const std::size_t step = std::max<std::size_t>(1, bytes.size() / 400);
  for (std::size_t cut = 0; cut < bytes.size(); cut += step)
  {
    refused += readBack(bytes.substr(0, cut)) ? 0 : 1;
  }
  EXPECT_EQ(refused, static_cast<int>((bytes.size() + step - 1) / step)); // every truncation
  EXPECT_FALSE(readBack(bytes + "x"));
  std::uint64_t state = 12345;
  for (int trial = 0; trial < 300; ++trial)
  {
    std::string damaged = bytes;
    for (int flip = 0; flip < 4; ++flip)
    {
      state = state * 6364136223846793005ull + 1442695040888963407ull;
      damaged[(state >> 33) % damaged.size()] ^= static_cast<char>(1 + (state >> 13) % 255);
    }
    readBack(damaged); // refused or read; the check is that it returns sanely
  }
  std::remove(path.c_str());
  std::remove(damagedPath.c_str());
}

// Sources of one colour take the one-sum path (e_l = s_l k); sources of two colours the
// per-channel path; both agree with relighting each colour alone and adding.
TEST(LightningBasis, OneColourAndMixedColours)
{
  const ExtinctionGrid cloud = Cloud(8, 8, 2);
  const nimbus::LightningBasisOptions o = QuickOptions();
  const nimbus::VirtualLightGrid lights = FewLights();
  const nimbus::LightningBasis basis =
    nimbus::PrecomputeLightningBasis(cloud, CloudOptics(), lights, o);
  const std::size_t count = lights.NumberOfNodes();
  std::vector<Rgb> blue(count), red(count), both(count);
  for (std::size_t l = 0; l < count; ++l)
  {
    const double s = 1.0 + 0.37 * static_cast<double>(l % 5);
    blue[l] = { { 0.85 * s, 0.9 * s, 1.0 * s } };
    red[l] = { { l % 2 ? 2.0 : 0.0, 0.0, 0.0 } };
    both[l] = { { blue[l][0] + red[l][0], blue[l][1], blue[l][2] } };
  }
  const auto b = nimbus::RelightLightning(basis, blue).Coefficients;
  const auto r = nimbus::RelightLightning(basis, red).Coefficients;
  const auto m = nimbus::RelightLightning(basis, both).Coefficients;
  double worst = 0.0, peak = 0.0;
  for (std::size_t i = 0; i < m.size(); ++i)
  {
    worst = std::max(worst, static_cast<double>(std::abs(m[i] - (b[i] + r[i]))));
    peak = std::max(peak, static_cast<double>(std::abs(m[i])));
  }
  EXPECT_GT(peak, 0.0);
  EXPECT_LT(worst, 1e-5 * peak);
  // The one-colour field is the grey relight scaled per channel.
  std::vector<Rgb> grey(count);
  for (std::size_t l = 0; l < count; ++l)
  {
    grey[l] = { { blue[l][2], blue[l][2], blue[l][2] } };
  }
  const auto g = nimbus::RelightLightning(basis, grey).Coefficients;
  for (std::size_t i = 0; i < g.size(); i += 12)
  {
    for (int k = 0; k < 4; ++k)
    {
      EXPECT_NEAR(b[i + k], 0.85 * g[i + 8 + k], 1e-6 * peak);
      EXPECT_NEAR(b[i + 4 + k], 0.9 * g[i + 8 + k], 1e-6 * peak);
    }
  }
}
