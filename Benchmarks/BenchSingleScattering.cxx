// Timing of the single-scattering reference renderer (plain main(), prints a table).
//
//   BenchSingleScattering [quick]
//
// Scene: the default SceneDescription camera (6 km south of the cloud, 35°) looking
// at a smooth cloud-like blob filling a cube of 128 × 31 m ≈ 4 km (the same physical
// cloud resampled at 32³…256³), σ_t up to ExtinctionPerDensity = 0.05 /m, albedo
// 0.99, Cornette–Shanks g = 0.85, sun 45° up at azimuth 135°. Times are wall-clock
// seconds with hardware-concurrency threads.
#include "SingleScatteringRenderer.h"

#include "DensityGrid.h"
#include "RenderContext.h"
#include "SceneDescription.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <thread>
#include <vector>

namespace
{
constexpr double kCloudSize = 127.0 * 31.0; // m, edge of the cloud box

/// A smooth blob with a few lumps (density in [0, 1]) on an n³ grid spanning
/// kCloudSize, centred at (0, 0, 2500) m; the same function at every resolution.
nimbus::DensityGrid CloudBlob(int n)
{
  const double h = kCloudSize / (n - 1);
  std::vector<float> values(static_cast<std::size_t>(n) * n * n);
  struct Lump
  {
    double x, y, z, r;
  };
  const Lump lumps[] = { { 0.0, 0.0, -0.2, 0.55 }, { 0.35, 0.1, 0.05, 0.35 },
    { -0.3, -0.2, 0.1, 0.4 }, { 0.05, 0.35, 0.2, 0.3 }, { -0.1, -0.3, 0.35, 0.25 } };
  for (int k = 0; k < n; ++k)
  {
    for (int j = 0; j < n; ++j)
    {
      for (int i = 0; i < n; ++i)
      {
        const double x = 2.0 * i / (n - 1) - 1.0, y = 2.0 * j / (n - 1) - 1.0,
                     z = 2.0 * k / (n - 1) - 1.0;
        double field = 0.0;
        for (const Lump& l : lumps)
        {
          const double d2 =
            ((x - l.x) * (x - l.x) + (y - l.y) * (y - l.y) + (z - l.z) * (z - l.z)) / (l.r * l.r);
          field += std::exp(-2.0 * d2);
        }
        const double detail =
          0.12 * std::sin(9.0 * x + 1.0) * std::sin(8.0 * y) * std::sin(10.0 * z + 2.0);
        values[(static_cast<std::size_t>(k) * n + j) * n + i] =
          static_cast<float>(std::max(0.0, std::min(1.0, 1.8 * (field - 0.45) + detail)));
      }
    }
  }
  const double half = 0.5 * kCloudSize;
  return nimbus::DensityGrid(
    { { n, n, n } }, { { -half, -half, 2500.0 - half } }, { { h, h, h } }, std::move(values));
}

nimbus::SceneDescription CloudScene(int pixels, bool atmosphere)
{
  nimbus::SceneDescription scene;
  scene.Camera.FocalPoint = { { 0.0, 0.0, 2300.0 } };
  scene.Camera.Width = pixels;
  scene.Camera.Height = pixels;
  scene.Medium.ExtinctionPerDensity = 0.05;
  scene.Atmosphere.Enabled = atmosphere;
  scene.Ground.Enabled = true;
  scene.Background.Type = atmosphere ? "atmosphere" : "black";
  return scene;
}

double Seconds(const std::chrono::steady_clock::time_point& start)
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

double PassSeconds(const nimbus::RenderContext& context, double stepScale)
{
  const auto start = std::chrono::steady_clock::now();
  const nimbus::FloatImage image = nimbus::RenderSingleScatteringPass(context, stepScale, 0);
  return Seconds(start);
}
} // namespace

int main(int argc, char** argv)
{
  const bool quick = argc > 1 && std::strcmp(argv[1], "quick") == 0;
  std::printf("threads: %u\n\n", std::thread::hardware_concurrency());

  std::printf("One pass, step scale 0.5, 256x256 unless noted (seconds)\n");
  std::printf("%-8s %-10s %-12s %-12s\n", "grid", "spacing", "no atmos.", "atmosphere");
  for (int n : { 32, 64, 128, 256 })
  {
    if (quick && n > 64)
    {
      break;
    }
    const nimbus::DensityGrid grid = CloudBlob(n);
    const int pixels = n == 256 ? 128 : 256;
    const nimbus::RenderContext plain(CloudScene(pixels, false), grid);
    const nimbus::RenderContext sky(CloudScene(pixels, true), grid);
    std::printf("%4d^3    %6.1f m   %8.2f     %8.2f%s\n", n, grid.GetMinimumSpacing(),
      PassSeconds(plain, 0.5), PassSeconds(sky, 0.5), pixels != 256 ? "   (128x128)" : "");
    std::fflush(stdout);
  }

  const nimbus::DensityGrid grid = CloudBlob(quick ? 64 : 128);
  std::printf("\nImage size, %d^3, step scale 0.5, atmosphere (seconds)\n", quick ? 64 : 128);
  for (int pixels : { 64, 128, 256 })
  {
    const nimbus::RenderContext sky(CloudScene(pixels, true), grid);
    std::printf("%4dx%-4d %8.2f\n", pixels, pixels, PassSeconds(sky, 0.5));
    std::fflush(stdout);
  }

  std::printf(
    "\nStep refinement, %d^3, 128x128, atmosphere (seconds per pass)\n", quick ? 64 : 128);
  {
    const nimbus::RenderContext sky(CloudScene(128, true), grid);
    for (double s : { 1.0, 0.5, 0.25, 0.125 })
    {
      std::printf("step scale %-6.3f %8.2f\n", s, PassSeconds(sky, s));
      std::fflush(stdout);
    }
  }

  std::printf("\nConverged image (RenderSingleScattering, StepScale 0.5, tolerance 1e-3), "
              "%d^3, 256x256\n",
    quick ? 64 : 128);
  for (bool atmosphere : { false, true })
  {
    const nimbus::RenderContext context(CloudScene(256, atmosphere), grid);
    nimbus::SingleScatteringSettings settings;
    const nimbus::SingleScatteringResult result = nimbus::RenderSingleScattering(context, settings);
    std::printf("%-12s passes %d, final step scale %.4f, estimated error %.2e, %.2f s\n",
      atmosphere ? "atmosphere" : "no atmos.", result.Passes, result.FinalStepScale,
      result.EstimatedRelativeError, result.Seconds);
    std::fflush(stdout);
  }
  return 0;
}
