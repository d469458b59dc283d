// Benchmark (not a test) of precomputed lightning (003 §4-§7): the seed's case
// (a cloud grid of 32x32x4 points 200 m apart, as if downsampled 4x from 128x128x16;
// virtual lights 20x20x6 by 003 Eq. 4; n_dir 26) precomputed, its memory against xi, the
// relight of a stroke against the direct multiple-scattering solve with the same point
// sources (time and error), and the cost per virtual light against the cloud grid and
// n_dir.
//
//   BenchLightning [threads = 2] [--quick]
//
// --quick: a quarter of the lights (10x10x6) for a short run. Every ratio compares
// timings taken in this one run. Errors: relative RMS of the SH coefficient c_00 over the
// cloud's points (sum over points and channels of (a - b)^2 over the sum of b^2), and the
// same over the brightest 10 % of the cloud's points (what a picture shows most).
#include "LightningBasis.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

namespace
{
using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point start)
{
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// An ellipsoidal cumulus: nx x ny x nz points `spacing` apart, base at 1000 m,
// extinction 0.02 /m at the centre falling to 0 at the rim.
nimbus::ExtinctionGrid Cloud(int nx, int ny, int nz, double spacing)
{
  nimbus::ExtinctionGrid grid;
  grid.Dimensions = { { nx, ny, nz } };
  grid.Spacing = { { spacing, spacing, spacing } };
  grid.Origin = { { -0.5 * spacing * (nx - 1), -0.5 * spacing * (ny - 1), 1000.0 } };
  grid.Extinction.resize(grid.NumberOfPoints());
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
      {
        const double x = (i - 0.5 * (nx - 1)) / (0.45 * nx), y = (j - 0.5 * (ny - 1)) / (0.45 * ny);
        const double z = (k - 0.5 * (nz - 1)) / (0.5 * nz + 0.5);
        const double r2 = x * x + y * y + z * z;
        grid.Extinction[grid.Index(i, j, k)] = r2 < 1 ? static_cast<float>(0.02 * (1 - r2)) : 0.0f;
      }
  return grid;
}

nimbus::MultipleScatteringField Direct(const nimbus::ExtinctionGrid& cloud,
  const std::vector<nimbus::PointLight>& sources, int directions, int threads)
{
  nimbus::CloudLighting lighting;
  lighting.HasSun = false;
  lighting.PointLights = sources;
  nimbus::MultipleScatteringOptions s;
  s.NumberOfDirections = directions;
  s.Orders = nimbus::LightningBasisOptions().Orders; // the basis's own (16)
  s.SkyLight = false;
  s.PointLightFirstScattering = true;
  s.Threads = threads;
  return nimbus::SolveMultipleScattering(cloud, nimbus::CloudOptics(), lighting, s);
}

struct Errors
{
  double All = 0.0, Brightest = 0.0;
};

Errors RelativeRms(
  const nimbus::ExtinctionGrid& cloud, const std::vector<float>& a, const std::vector<float>& b)
{
  std::vector<double> reference;
  for (std::size_t i = 0; i < cloud.NumberOfPoints(); ++i)
  {
    if (cloud.Extinction[i] > 0.0f)
    {
      reference.push_back(b[12 * i]);
    }
  }
  std::sort(reference.begin(), reference.end());
  const double bright = reference.empty() ? 0.0 : reference[reference.size() * 9 / 10];
  double d[2] = { 0, 0 }, r[2] = { 0, 0 };
  for (std::size_t i = 0; i < cloud.NumberOfPoints(); ++i)
  {
    if (cloud.Extinction[i] <= 0.0f)
    {
      continue;
    }
    for (int c = 0; c < 3; ++c)
    {
      const double x = a[12 * i + 4 * c], y = b[12 * i + 4 * c];
      for (int s = 0; s < 2; ++s)
      {
        if (s == 1 && b[12 * i] < bright)
        {
          continue;
        }
        d[s] += (x - y) * (x - y);
        r[s] += y * y;
      }
    }
  }
  return { std::sqrt(d[0] / r[0]), std::sqrt(d[1] / r[1]) };
}

double Median(std::vector<double> v)
{
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}
} // namespace

int main(int argc, char** argv)
{
  int threads = 2;
  bool quick = false;
  for (int i = 1; i < argc; ++i)
  {
    if (std::strcmp(argv[i], "--quick") == 0)
    {
      quick = true;
    }
    else
    {
      threads = std::max(1, std::atoi(argv[i]));
    }
  }

  // 1. The seed's case.
  const nimbus::ExtinctionGrid cloud = Cloud(32, 32, 4, 200.0);
  nimbus::VirtualLightGridParameters p;
  p.Low = { { -3200.0, -3200.0, 0.0 } };
  p.High = { { 3200.0, 3200.0, 1800.0 } };
  p.CloudBottom = 1000.0;
  p.BaseInterval = 6400.0 / (quick ? 9 : 19);
  const nimbus::VirtualLightGrid lights = nimbus::MakeVirtualLightGrid(p);
  std::printf("cloud grid 32x32x4 (200 m), virtual lights %zux%zux%zu = %zu, n_dir 26, %d "
              "threads\n",
    lights.Nodes[0].size(), lights.Nodes[1].size(), lights.Nodes[2].size(), lights.NumberOfNodes(),
    threads);
  nimbus::LightningBasisOptions o;
  o.Threads = threads;
  o.Threshold = 0.0;
  const nimbus::LightningBasis exact =
    nimbus::PrecomputeLightningBasis(cloud, nimbus::CloudOptics(), lights, o);
  std::printf("precompute (xi = 0, %d orders): %.1f s (%.1f ms per light per thread)\n", o.Orders,
    exact.Seconds, 1000.0 * exact.Seconds * threads / lights.NumberOfNodes());

  // A stroke from inside the cloud to the ground.
  nimbus::LightningParameters stroke;
  stroke.Start = { { 300.0, -200.0, 1400.0 } };
  stroke.Length = 2500.0;
  stroke.StopBelowHeight = 0.0;
  stroke.Intensity = 100.0;
  stroke.Seed = 5;
  const auto sources = nimbus::LightningPointSources(nimbus::GenerateLightning(stroke), 10.0);
  const std::vector<nimbus::Rgb> e = nimbus::DistributeToVirtualLights(lights, sources);
  std::vector<double> directTimes, directTimesOne;
  nimbus::MultipleScatteringField direct;
  for (int r = 0; r < 3; ++r)
  {
    auto start = Clock::now();
    direct = Direct(cloud, sources, 26, threads);
    directTimes.push_back(Seconds(start));
    start = Clock::now();
    Direct(cloud, sources, 26, 1);
    directTimesOne.push_back(Seconds(start));
  }
  std::printf("stroke: %zu point sources; direct solve %.3f s (%d threads), %.3f s (1 thread)\n",
    sources.size(), Median(directTimes), threads, Median(directTimesOne));

  double globalLargest = 0.0;
  for (const nimbus::SparseHaarField& f : exact.Fields)
  {
    for (float v : f.Value)
    {
      globalLargest = std::max(globalLargest, static_cast<double>(std::abs(v)));
    }
  }
  const auto relit0 = nimbus::RelightLightning(exact, e);
  for (const bool global : { false, true })
  {
    std::printf("\nthreshold relative to %s\n%-7s %10s %8s %11s %11s %14s %10s %12s\n",
      global ? "the whole basis's largest coefficient" : "each field's largest coefficient", "xi",
      "basis MB", "ratio", "relight ms", "x direct", "RMS vs direct", "brightest", "RMS vs xi 0");
    for (const double xi : { 0.0, 1e-4, 1e-3, 1e-2, 3e-2, 1e-1 })
    {
      if (global && xi == 0.0)
      {
        continue;
      }
      nimbus::LightningBasis basis = exact;
      if (xi > 0.0)
      {
        for (nimbus::SparseHaarField& f : basis.Fields)
        {
          double largest = globalLargest;
          if (!global)
          {
            largest = 0.0;
            for (float v : f.Value)
            {
              largest = std::max(largest, static_cast<double>(std::abs(v)));
            }
          }
          nimbus::DropHaarCoefficients(f, xi * largest);
        }
      }
      std::vector<double> times;
      nimbus::MultipleScatteringField relit;
      for (int r = 0; r < 9; ++r)
      {
        const auto start = Clock::now();
        relit = nimbus::RelightLightning(basis, nimbus::DistributeToVirtualLights(lights, sources));
        times.push_back(Seconds(start));
      }
      const Errors error = RelativeRms(cloud, relit.Coefficients, direct.Coefficients);
      const Errors compression = RelativeRms(cloud, relit.Coefficients, relit0.Coefficients);
      std::printf("%-7g %10.1f %8.1f %11.2f %11.0f %14.4f %10.4f %12.4f\n", xi,
        basis.CompressedBytes() / 1048576.0, basis.UncompressedBytes() / basis.CompressedBytes(),
        1000.0 * Median(times), Median(directTimes) / Median(times), error.All, error.Brightest,
        compression.All);
    }
  }
  std::printf("(uncompressed: %.1f MB as floats, 4 SH fields per light)\n",
    exact.UncompressedBytes() / 1048576.0);

  // 2. Cost per virtual light against the cloud grid and n_dir: one solve of three
  // lights (the basis's packing: one per colour channel), one thread, divided by 3.
  std::printf("\ncost per virtual light (ms, one thread; precompute = lights x this / "
              "threads)\n%-14s",
    "cloud grid");
  const int directionCounts[] = { 14, 26, 50, 98 };
  for (int nd : directionCounts)
  {
    std::printf(" %9s%-3d", "n_dir ", nd);
  }
  std::printf("\n");
  const int grids[][3] = { { 16, 16, 4 }, { 32, 32, 4 }, { 32, 32, 8 }, { 64, 64, 8 } };
  for (const auto& g : grids)
  {
    if (quick && g[0] == 64)
    {
      continue;
    }
    const nimbus::ExtinctionGrid c = Cloud(g[0], g[1], g[2], 6400.0 / g[0]);
    std::printf("%3dx%3dx%-6d", g[0], g[1], g[2]);
    for (int nd : directionCounts)
    {
      std::vector<double> t;
      for (int r = 0; r < 3; ++r)
      {
        std::vector<nimbus::PointLight> three;
        for (int l = 0; l < 3; ++l)
        {
          nimbus::Rgb unit{ { 0, 0, 0 } };
          unit[l] = 1.0;
          three.push_back({ { { 300.0 * l, 100.0 * r, 600.0 } }, unit });
        }
        const auto start = Clock::now();
        Direct(c, three, nd, 1);
        t.push_back(Seconds(start) / 3.0);
      }
      std::printf(" %12.1f", 1000.0 * Median(t));
    }
    std::printf("\n");
  }
  return 0;
}
