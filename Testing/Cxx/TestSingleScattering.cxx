// Closed-form validation of the single-scattering reference renderer
// (Reference/Core/SingleScatteringRenderer.h).
//
// Homogeneous media come from DensityGrid::Constant (2 points per axis, so the grid
// "minimum spacing" is the smallest box edge and the cloud step is
// StepScale × that edge). Units: metres, 1/m; radiance relative to the sun.
#include "Math.h"
#include "SingleScatteringRenderer.h"

#include "DensityGrid.h"
#include "PhaseFunctions.h"
#include "RenderContext.h"
#include "SceneDescription.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <vector>

namespace
{
using nimbus::DensityGrid;
using nimbus::Dot;
using nimbus::RenderContext;
using nimbus::SceneDescription;
using nimbus::Vector3;

using nimbus::kDegree;
using nimbus::kPi;

/// No atmosphere, no ground, black background, HG phase.
SceneDescription PlainScene(double sunElevation, double sunAzimuth, double g = 0.6)
{
  SceneDescription scene;
  scene.Atmosphere.Enabled = false;
  scene.Ground.Enabled = false;
  scene.Background.Type = "black";
  scene.Sun.ElevationDegrees = sunElevation;
  scene.Sun.AzimuthDegrees = sunAzimuth;
  scene.Sun.Illuminance = 1.0;
  scene.Medium.ExtinctionPerDensity = 0.01;
  scene.Medium.SingleScatteringAlbedo = 0.9;
  scene.Medium.Phase = { nimbus::PhaseComponentDescription{ "henyey_greenstein", g, 1.0 } };
  scene.SpectralSamples = 8;
  scene.Camera.Width = 16;
  scene.Camera.Height = 16;
  return scene;
}

/// Slab z in [0, D], wide enough in x, y that every ray here leaves through z faces.
constexpr double kSlabThickness = 100.0; // m
constexpr double kSlabHalfWidth = 1e4;   // m
DensityGrid Slab(float density = 1.0f)
{
  return DensityGrid::Constant({ { -kSlabHalfWidth, -kSlabHalfWidth, 0.0 } },
    { { kSlabHalfWidth, kSlabHalfWidth, kSlabThickness } }, density);
}

Vector3 Direction(double elevationDeg, double azimuthDeg)
{
  const double e = elevationDeg * kDegree, a = azimuthDeg * kDegree;
  return { { std::cos(e) * std::sin(a), std::cos(e) * std::cos(a), std::sin(e) } };
}

/// Single scattering of a homogeneous slab z in [0, D] (σ_t, σ_s = albedo σ_t),
/// sun direction s (s_z > 0, light enters through z = D), view ray v, per unit sun
/// irradiance (multiply by E(λ)). μ = dot(s, v).
///  Reflection (camera above, v_z < 0), depth y = D - z below the top, path length
///  along the view ray dt = dy/|v_z|:
///    L = σ_s p(μ) ∫_0^D e^{-σ y/|v_z|} e^{-σ y/s_z} dy/|v_z|
///      = σ_s p(μ) (1 - e^{-σ D (1/|v_z| + 1/s_z)}) / (σ (1 + |v_z|/s_z)).
///  Transmission (camera below, v_z > 0), height z above the bottom:
///    L = σ_s p(μ) ∫_0^D e^{-σ z/v_z} e^{-σ (D - z)/s_z} dz/v_z
///      = σ_s p(μ) e^{-σ D/s_z} (1 - e^{-k D}) / (k v_z),  k = σ (1/v_z - 1/s_z)
///    (D/v_z for k = 0).
double SlabSingleScattering(
  double sigma, double albedo, double phase, const Vector3& s, const Vector3& v)
{
  const double D = kSlabThickness;
  if (v[2] < 0.0)
  {
    const double a = std::abs(v[2]);
    return albedo * sigma * phase * -std::expm1(-sigma * D * (1.0 / a + 1.0 / s[2])) /
      (sigma * (1.0 + a / s[2]));
  }
  const double k = sigma * (1.0 / v[2] - 1.0 / s[2]);
  const double integral = std::abs(k * D) < 1e-12 ? D : -std::expm1(-k * D) / k;
  return albedo * sigma * phase * std::exp(-sigma * D / s[2]) * integral / v[2];
}

double MaxRelativeDifference(const std::vector<double>& a, const std::vector<double>& b)
{
  double m = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i)
  {
    m = std::max(m, std::abs(a[i] - b[i]) / std::max(std::abs(b[i]), 1e-300));
  }
  return m;
}

bool AllFinite(const nimbus::FloatImage& image)
{
  return std::all_of(
    image.Pixels.begin(), image.Pixels.end(), [](float v) { return std::isfinite(v); });
}

/// A smooth blob (σ_t up to ExtinctionPerDensity) on an n³ grid, spacing h, centred at c.
DensityGrid Blob(int n, double h, const Vector3& centre)
{
  std::vector<float> values(static_cast<std::size_t>(n) * n * n);
  const double half = 0.5 * (n - 1) * h;
  for (int k = 0; k < n; ++k)
  {
    for (int j = 0; j < n; ++j)
    {
      for (int i = 0; i < n; ++i)
      {
        const double x = (i * h - half) / half, y = (j * h - half) / half,
                     z = (k * h - half) / half;
        const double r2 = x * x + y * y + 1.5 * z * z;
        const double ripple =
          0.15 * std::sin(7.0 * x) * std::sin(5.0 * y + 1.0) * std::cos(6.0 * z);
        values[(static_cast<std::size_t>(k) * n + j) * n + i] =
          static_cast<float>(std::max(0.0, std::min(1.0, 1.6 * (0.7 - r2) + ripple)));
      }
    }
  }
  return DensityGrid({ { n, n, n } }, { { centre[0] - half, centre[1] - half, centre[2] - half } },
    { { h, h, h } }, std::move(values));
}

} // namespace

// 1. Beer–Lambert through a non-scattering slab against a constant background:
//    L = L_b exp(-σ_t d / |cos θ|).
TEST(SingleScattering, BeerLambertSlab)
{
  SceneDescription scene = PlainScene(45.0, 0.0);
  scene.Medium.SingleScatteringAlbedo = 0.0;
  scene.Background.Type = "constant";
  scene.Background.Radiance = 2.0;
  const RenderContext context(scene, Slab());
  const double sigma = scene.Medium.ExtinctionPerDensity;
  for (double zenith : { 0.0, 30.0, 60.0, 80.0 })
  {
    for (double stepScale : { 0.5, 0.13, 0.02 })
    {
      const Vector3 v = Direction(90.0 - zenith, 30.0);
      const std::vector<double> L =
        nimbus::SingleScatteringRadiance(context, { { 5.0, -3.0, -500.0 } }, v, stepScale);
      const double expected = 2.0 * std::exp(-sigma * kSlabThickness / std::cos(zenith * kDegree));
      for (double value : L)
      {
        EXPECT_NEAR(value / expected - 1.0, 0.0, 1e-4) << "zenith " << zenith;
      }
    }
  }
}

// 2. Single scattering from a homogeneous slab against the closed form; the error
//    of the exponential midpoint rule falls as h² (ratio 4 per halving).
TEST(SingleScattering, SlabClosedFormSecondOrder)
{
  const SceneDescription scene = PlainScene(60.0, 90.0);
  const RenderContext context(scene, Slab());
  const Vector3 s = context.GetSunDirection();
  const double sigma = scene.Medium.ExtinctionPerDensity,
               albedo = scene.Medium.SingleScatteringAlbedo;
  const std::vector<double>& E = context.GetSunIrradiance();

  struct Case
  {
    const char* name;
    Vector3 origin, direction;
  };
  const Case cases[] = {
    { "reflection", { { 0.0, 0.0, 400.0 } }, Direction(-50.0, 200.0) },
    { "transmission", { { 0.0, 0.0, -400.0 } }, Direction(70.0, 60.0) },
    { "transmission, forward", { { 0.0, 0.0, -400.0 } }, Direction(55.0, 80.0) },
  };
  for (const Case& c : cases)
  {
    const double phase = nimbus::HenyeyGreenstein(Dot(s, c.direction), 0.6);
    const double expected = SlabSingleScattering(sigma, albedo, phase, s, c.direction);
    double previousError = 0.0;
    std::printf("  %-22s closed form %.9e\n", c.name, expected);
    for (double stepScale : { 0.5, 0.25, 0.125, 0.0625, 0.03125 })
    {
      const std::vector<double> L =
        nimbus::SingleScatteringRadiance(context, c.origin, c.direction, stepScale);
      double error = 0.0;
      for (std::size_t i = 0; i < L.size(); ++i)
      {
        error = std::max(error, std::abs(L[i] / (E[i] * expected) - 1.0));
      }
      std::printf("    step %6.3f m  relative error %.3e  ratio %.3f\n", stepScale * kSlabThickness,
        error, previousError > 0.0 ? previousError / error : 0.0);
      if (previousError > 0.0)
      {
        EXPECT_GT(previousError / error, 3.5) << c.name << " step scale " << stepScale;
        EXPECT_LT(previousError / error, 4.5) << c.name << " step scale " << stepScale;
      }
      // Leading error term C (σh)², h the step along the view ray; measured C ≈ 0.1 for
      // the reflection and ≈ 0.04 for the transmission cases (see the printout).
      EXPECT_LT(error, 0.12 * std::pow(sigma * stepScale * kSlabThickness, 2)) << c.name;
      previousError = error;
    }
  }
}

// 3. The refinement loop: stops below the tolerance and its estimate is close to
//    the true error against the closed form (per pixel: reflection from the slab).
TEST(SingleScattering, RefinementEstimateMatchesTrueError)
{
  SceneDescription scene = PlainScene(60.0, 90.0);
  scene.Camera.Position = { { 0.0, -150.0, 400.0 } };
  scene.Camera.FocalPoint = { { 0.0, 0.0, 100.0 } };
  scene.Camera.ViewAngle = 30.0;
  scene.Medium.ExtinctionPerDensity = 0.02;
  const RenderContext context(scene, Slab());
  const Vector3 s = context.GetSunDirection();
  const nimbus::Camera& camera = context.GetCamera();

  nimbus::FloatImage exact(camera.GetWidth(), camera.GetHeight());
  for (int j = 0; j < exact.Height; ++j)
  {
    for (int i = 0; i < exact.Width; ++i)
    {
      const Vector3 v = camera.RayDirection(i + 0.5, j + 0.5);
      ASSERT_LT(v[2], 0.0);
      const double scalar = SlabSingleScattering(scene.Medium.ExtinctionPerDensity,
        scene.Medium.SingleScatteringAlbedo, nimbus::HenyeyGreenstein(Dot(s, v), 0.6), s, v);
      std::vector<double> spectrum = context.GetSunIrradiance();
      for (double& value : spectrum)
      {
        value *= scalar;
      }
      const std::array<double, 3> rgb = context.ToLinearSrgb(spectrum);
      std::copy(rgb.begin(), rgb.end(), exact.At(i, j));
    }
  }
  for (double tolerance : { 1e-2, 1e-3, 1e-4 })
  {
    nimbus::SingleScatteringSettings settings;
    settings.StepScale = 0.5;
    settings.RelativeTolerance = tolerance;
    settings.MaxRefinements = 10;
    settings.Threads = 2;
    std::vector<double> progress;
    const nimbus::SingleScatteringResult result =
      nimbus::RenderSingleScattering(context, settings, [&](double f) { progress.push_back(f); });
    double diff2 = 0.0, value2 = 0.0;
    for (std::size_t k = 0; k < exact.Pixels.size(); ++k)
    {
      diff2 += std::pow(static_cast<double>(result.Image.Pixels[k]) - exact.Pixels[k], 2);
      value2 += std::pow(static_cast<double>(exact.Pixels[k]), 2);
    }
    const double trueError = std::sqrt(diff2 / value2);
    std::printf("  tolerance %.0e: passes %d, final step scale %.5f, estimate %.3e, true %.3e "
                "(ratio %.2f), %.3f s\n",
      tolerance, result.Passes, result.FinalStepScale, result.EstimatedRelativeError, trueError,
      trueError / result.EstimatedRelativeError, result.Seconds);
    EXPECT_LT(result.EstimatedRelativeError, tolerance);
    EXPECT_LT(trueError, 2.0 * tolerance);
    EXPECT_GT(trueError / result.EstimatedRelativeError, 0.5);
    EXPECT_LT(trueError / result.EstimatedRelativeError, 2.0);
    EXPECT_DOUBLE_EQ(result.FinalStepScale, 0.5 * std::pow(0.5, result.Passes - 1));
    ASSERT_FALSE(progress.empty());
    EXPECT_TRUE(std::is_sorted(progress.begin(), progress.end()));
    EXPECT_DOUBLE_EQ(progress.back(), 1.0);
  }
}

// 3b. The same on a heterogeneous cloud (trilinear blob, with and without the
//     atmosphere): the estimate against a reference rendered at 1/16 of the final step.
//     Trilinear densities have kinks at cell faces, so successive differences fall
//     by 3–6 (not exactly 4) per halving here; the estimate is good to a small factor.
TEST(SingleScattering, RefinementEstimateOnBlob)
{
  for (bool atmosphere : { false, true })
  {
    SceneDescription scene;
    scene.Atmosphere.Enabled = atmosphere;
    scene.Background.Type = atmosphere ? "atmosphere" : "black";
    scene.Camera.Width = 16;
    scene.Camera.Height = 16;
    scene.Camera.FocalPoint = { { 0.0, 0.0, 1800.0 } };
    scene.SpectralSamples = 8;
    scene.Medium.ExtinctionPerDensity = 0.01;
    const RenderContext context(scene, Blob(16, 200.0, { { 0.0, 0.0, 1800.0 } }));
    nimbus::SingleScatteringSettings settings;
    settings.RelativeTolerance = 2e-3;
    settings.Threads = 2;
    const nimbus::SingleScatteringResult result = nimbus::RenderSingleScattering(context, settings);
    const nimbus::FloatImage reference =
      nimbus::RenderSingleScatteringPass(context, result.FinalStepScale / 16.0, 2);
    double diff2 = 0.0, value2 = 0.0;
    for (std::size_t k = 0; k < reference.Pixels.size(); ++k)
    {
      diff2 += std::pow(static_cast<double>(result.Image.Pixels[k]) - reference.Pixels[k], 2);
      value2 += std::pow(static_cast<double>(reference.Pixels[k]), 2);
    }
    const double trueError = std::sqrt(diff2 / value2);
    std::printf("  %-13s passes %d, step scale %.4f, estimate %.3e, true %.3e (ratio %.2f)\n",
      atmosphere ? "atmosphere" : "no atmosphere", result.Passes, result.FinalStepScale,
      result.EstimatedRelativeError, trueError, trueError / result.EstimatedRelativeError);
    EXPECT_LT(result.EstimatedRelativeError, settings.RelativeTolerance);
    EXPECT_LT(trueError, 3.0 * result.EstimatedRelativeError);
    EXPECT_GT(trueError, result.EstimatedRelativeError / 3.0);
  }
}

// 4a. Sign of the scattering angle: with g > 0 the cloud is brighter with the sun
//     behind it (μ = +1) than behind the camera (μ = -1), by p(1)/p(-1) when thin.
TEST(SingleScattering, ForwardScatteringIsBrighter)
{
  const double g = 0.7;
  const Vector3 origin{ { 0.0, -5000.0, 0.0 } }, v{ { 0.0, 1.0, 0.0 } };
  auto render = [&](double azimuth)
  {
    SceneDescription scene = PlainScene(0.0, azimuth, g);
    scene.Medium.ExtinctionPerDensity = 1e-5; // optical thickness 1e-3: thin
    scene.Medium.SingleScatteringAlbedo = 1.0;
    const RenderContext context(
      scene, DensityGrid::Constant({ { -50.0, -50.0, -50.0 } }, { { 50.0, 50.0, 50.0 } }, 1.0f));
    return nimbus::SingleScatteringRadiance(context, origin, v, 0.25)[3];
  };
  const double forward = render(0.0);    // sun toward +y: behind the cloud
  const double backward = render(180.0); // sun toward -y: behind the camera
  const double expected = nimbus::HenyeyGreenstein(1.0, g) / nimbus::HenyeyGreenstein(-1.0, g);
  std::printf("  forward/backward %.4f, p(1)/p(-1) %.4f\n", forward / backward, expected);
  EXPECT_GT(forward, backward);
  EXPECT_NEAR(forward / backward / expected, 1.0, 3e-3);
}

// 4b. The cloud shadows the ground: the lit ground has exactly A/π E s_z; the
//     shadowed point is attenuated by exp(-σ × the sun path through the box).
TEST(SingleScattering, GroundShadowUnderCloud)
{
  SceneDescription scene = PlainScene(45.0, 90.0); // sun toward +x, 45° up
  scene.Ground.Enabled = true;
  scene.Ground.Albedo = 0.3;
  scene.Medium.ExtinctionPerDensity = 0.02;
  const RenderContext context(scene,
    DensityGrid::Constant({ { -500.0, -500.0, 1000.0 } }, { { 500.0, 500.0, 1500.0 } }, 1.0f));
  const Vector3 down{ { 0.0, 0.0, -1.0 } };
  const std::vector<double> lit =
    nimbus::SingleScatteringRadiance(context, { { 1250.0, 0.0, 100.0 } }, down, 0.5);
  const std::vector<double> shadow =
    nimbus::SingleScatteringRadiance(context, { { -1250.0, 0.0, 100.0 } }, down, 0.5);
  const std::vector<double>& E = context.GetSunIrradiance();
  const double sunPath = 500.0 / std::sin(45.0 * kDegree); // through z in [1000, 1500]
  for (std::size_t i = 0; i < E.size(); ++i)
  {
    EXPECT_NEAR(lit[i] / (0.3 / kPi * E[i] * std::sin(45.0 * kDegree)), 1.0, 1e-12);
    EXPECT_NEAR(shadow[i] / lit[i] / std::exp(-0.02 * sunPath), 1.0, 1e-9);
  }

  // The same in an image: a camera looking down at both points.
  scene.Camera.Position = { { 0.0, -3000.0, 800.0 } };
  scene.Camera.FocalPoint = { { 0.0, 0.0, 0.0 } };
  scene.Camera.ViewAngle = 60.0;
  scene.Camera.Width = 32;
  scene.Camera.Height = 16;
  const RenderContext imageContext(scene, context.GetGrid());
  const nimbus::FloatImage image = nimbus::RenderSingleScatteringPass(imageContext, 0.5, 2);
  // Find the pixels whose rays hit the ground nearest to the lit and shadow points.
  auto pixelNear = [&](double x)
  {
    int best = 0;
    double bestDistance = 1e300;
    for (int i = 0; i < image.Width; ++i)
    {
      for (int j = 0; j < image.Height; ++j)
      {
        const Vector3 v = imageContext.GetCamera().RayDirection(i + 0.5, j + 0.5);
        if (v[2] >= 0.0)
        {
          continue;
        }
        const double t = -800.0 / v[2];
        const double distance = std::hypot(v[0] * t - x, -3000.0 + v[1] * t);
        if (distance < bestDistance)
        {
          bestDistance = distance;
          best = j * image.Width + i;
        }
      }
    }
    return image.Pixels[3 * best + 1];
  };
  EXPECT_LT(pixelNear(-1250.0), 0.01 * pixelNear(1250.0));
  EXPECT_TRUE(AllFinite(image));
}

// 4c. The image does not depend on the thread count (bitwise).
TEST(SingleScattering, ThreadCountIndependent)
{
  SceneDescription scene; // atmosphere, ground and sky on
  scene.Camera.Width = 20;
  scene.Camera.Height = 14;
  scene.SpectralSamples = 8;
  const RenderContext context(scene, Blob(24, 150.0, { { 0.0, 0.0, 1800.0 } }));
  const nimbus::FloatImage one = nimbus::RenderSingleScatteringPass(context, 0.5, 1);
  const nimbus::FloatImage four = nimbus::RenderSingleScatteringPass(context, 0.5, 4);
  ASSERT_EQ(one.Pixels.size(), four.Pixels.size());
  EXPECT_EQ(
    0, std::memcmp(one.Pixels.data(), four.Pixels.data(), one.Pixels.size() * sizeof(float)));
  EXPECT_TRUE(AllFinite(one));
  double sum = 0.0;
  for (float value : one.Pixels)
  {
    sum += value;
  }
  EXPECT_GT(sum, 0.0);
}

// 4d. Stability: finite everywhere, spectral radiance >= 0.
TEST(SingleScattering, StabilityCases)
{
  struct Case
  {
    const char* name;
    SceneDescription scene;
    DensityGrid grid;
  };
  std::vector<Case> cases;
  auto base = [](double elevation)
  {
    SceneDescription scene; // default: atmosphere, ground, sky background
    scene.Sun.ElevationDegrees = elevation;
    scene.Camera.Width = 8;
    scene.Camera.Height = 8;
    scene.SpectralSamples = 8;
    return scene;
  };
  const DensityGrid blob = Blob(12, 300.0, { { 0.0, 0.0, 1800.0 } });
  cases.push_back({ "zero density", base(45.0),
    DensityGrid({ { 4, 4, 4 } }, { { -600.0, -600.0, 1000.0 } }, { { 400.0, 400.0, 400.0 } },
      std::vector<float>(64, 0.0f)) });
  {
    SceneDescription scene = base(30.0);
    scene.Medium.ExtinctionPerDensity = 1e4 / 1650.0; // optical thickness ~1e4 across the blob
    cases.push_back({ "optical thickness 1e4", scene, blob });
  }
  for (double g : { 0.9999, -0.9999 })
  {
    SceneDescription scene = base(10.0);
    scene.Medium.Phase = { nimbus::PhaseComponentDescription{ "henyey_greenstein", g, 1.0 } };
    scene.Sun.AzimuthDegrees = 0.0; // toward the camera's view direction (+y)
    cases.push_back({ g > 0 ? "g = +0.9999" : "g = -0.9999", scene, blob });
  }
  cases.push_back({ "sun at the zenith", base(90.0), blob });
  cases.push_back({ "sun at the horizon", base(0.0), blob });
  cases.push_back({ "sun 5 deg below", base(-5.0), blob });
  {
    SceneDescription scene = base(45.0);
    scene.Medium.ExtinctionPerDensity = 0.002;
    scene.Camera.Position = { { 0.0, -100.0, 1800.0 } };
    scene.Camera.FocalPoint = { { 0.0, 1000.0, 1900.0 } };
    cases.push_back({ "camera inside the cloud", scene, blob });
  }
  cases.push_back({ "one-voxel grid", base(45.0),
    DensityGrid(
      { { 1, 1, 1 } }, { { 0.0, 0.0, 1600.0 } }, { { 500.0, 500.0, 500.0 } }, { 1.0f }) });
  {
    SceneDescription scene = base(45.0);
    scene.Atmosphere.Enabled = false;
    scene.Background.Type = "constant";
    scene.Background.Radiance = 0.5;
    scene.Medium.ExtinctionPerDensity = 1e4 / 500.0;
    cases.push_back({ "no atmosphere, one voxel, thick", scene,
      DensityGrid(
        { { 1, 1, 1 } }, { { 0.0, 0.0, 1600.0 } }, { { 500.0, 500.0, 500.0 } }, { 1.0f }) });
  }
  {
    SceneDescription scene = base(-5.0);
    scene.Atmosphere.Enabled = false;
    scene.Background.Type = "black";
    cases.push_back({ "no atmosphere, sun below, ground", scene, blob });
  }
  {
    SceneDescription scene = base(20.0);
    scene.Ground.Enabled = false;
    cases.push_back({ "atmosphere without ground", scene, blob });
  }

  for (const Case& c : cases)
  {
    const RenderContext context(c.scene, c.grid);
    const nimbus::FloatImage image = nimbus::RenderSingleScatteringPass(context, 0.5, 2);
    EXPECT_TRUE(AllFinite(image)) << c.name;
    const nimbus::Camera& camera = context.GetCamera();
    double luminance = 0.0;
    for (int j = 0; j < 8; j += 3)
    {
      for (int i = 0; i < 8; i += 3)
      {
        const std::vector<double> L = nimbus::SingleScatteringRadiance(
          context, camera.GetPosition(), camera.RayDirection(i + 0.5, j + 0.5), 0.5);
        for (double value : L)
        {
          EXPECT_TRUE(std::isfinite(value) && value >= 0.0) << c.name << " " << value;
        }
        luminance += context.GetSpectrum().ToXyz(L)[1];
      }
    }
    std::printf("  %-34s mean Y of 9 rays %.4e\n", c.name, luminance / 9.0);
  }
}

// The atmosphere's sun transmittance, interpolated between exact knots along the
// ray, against RenderContext::SunAtmosphereTransmittance (exact, per point).
TEST(SingleScattering, SunAtmosphereKnots)
{
  double worst = 0.0;
  for (double elevation : { 60.0, 20.0, 5.0, 1.0, 0.0, -1.0, -5.0 })
  {
    SceneDescription scene;
    scene.Sun.ElevationDegrees = elevation;
    scene.SpectralSamples = 8;
    const RenderContext context(scene, Slab());
    const double spacing = nimbus::detail::SunAtmosphereKnotSpacing(context);
    double caseWorst = 0.0;
    for (const Vector3& v : { Direction(0.0, 30.0), Direction(10.0, 150.0), Direction(-3.0, 80.0),
           Direction(60.0, 200.0), Direction(0.5, 135.0) })
    {
      const Vector3 o{ { 0.0, -6000.0, 1500.0 } };
      double tEnd = context.DistanceToTopOfAtmosphere(o, v);
      tEnd = std::min(tEnd, context.IntersectGround(o, v, 0.0));
      for (int k = 0; k <= 40; ++k)
      {
        const double t = tEnd * std::pow(k / 40.0, 2);
        const Vector3 x{ { o[0] + t * v[0], o[1] + t * v[1], o[2] + t * v[2] } };
        std::vector<double> exact;
        context.SunAtmosphereTransmittance(x, exact);
        const std::vector<double> interpolated =
          nimbus::detail::InterpolatedSunAtmosphereTransmittance(context, o, v, tEnd, t);
        for (std::size_t i = 0; i < exact.size(); ++i)
        {
          caseWorst = std::max(caseWorst, std::abs(exact[i] - interpolated[i]));
        }
      }
    }
    std::printf(
      "  sun %5.1f deg: knot spacing %7.0f m, max |ΔT| %.2e\n", elevation, spacing, caseWorst);
    worst = std::max(worst, caseWorst);
  }
  EXPECT_LT(worst, 1e-4);
}

// Atmosphere only (no cloud): the renderer's sky along a ray against a brute-force
// fine uniform midpoint rule built only from RenderContext's exact functions.
TEST(SingleScattering, SkyAgainstBruteForce)
{
  for (double elevation : { 40.0, 8.0 })
  {
    SceneDescription scene;
    scene.Sun.ElevationDegrees = elevation;
    scene.Sun.AzimuthDegrees = 100.0;
    scene.SpectralSamples = 8;
    scene.Ground.Enabled = false;
    const RenderContext context(scene,
      DensityGrid({ { 2, 2, 2 } }, { { 0.0, 0.0, 0.0 } }, { { 50.0, 50.0, 50.0 } },
        std::vector<float>(8, 0.0f)));
    const Vector3 o{ { 0.0, 0.0, 500.0 } };
    for (const Vector3& v : { Direction(30.0, 90.0), Direction(3.0, 270.0) })
    {
      const double mu = Dot(context.GetSunDirection(), v);
      const nimbus::Atmosphere& air = *context.GetAtmosphere();
      const double tEnd = context.DistanceToTopOfAtmosphere(o, v);
      // Brute force: 3000 steps, fine near the camera (t = tEnd u³).
      const int n = 3000;
      const int nl = context.GetNumberOfWavelengths();
      std::vector<double> L(nl, 0.0), tau(nl, 0.0), beta, Tsun;
      for (int k = 0; k < n; ++k)
      {
        const double ta = tEnd * std::pow(double(k) / n, 3),
                     tb = tEnd * std::pow(double(k + 1) / n, 3);
        const double tm = 0.5 * (ta + tb), dt = tb - ta;
        const Vector3 x{ { o[0] + tm * v[0], o[1] + tm * v[1], o[2] + tm * v[2] } };
        double mieS, mieE;
        context.AtmosphereCoefficients(x, beta, mieS, mieE);
        context.SunAtmosphereTransmittance(x, Tsun);
        for (int i = 0; i < nl; ++i)
        {
          const double sigma = beta[i] + mieE;
          const double J = context.GetSunIrradiance()[i] * Tsun[i] *
            (beta[i] * air.RayleighPhase(mu) + mieS * air.MiePhase(mu));
          L[i] += std::exp(-(tau[i] + 0.5 * sigma * dt)) * J * dt;
          tau[i] += sigma * dt;
        }
      }
      const std::vector<double> coarse = nimbus::SingleScatteringRadiance(context, o, v, 0.5);
      const std::vector<double> fine = nimbus::SingleScatteringRadiance(context, o, v, 0.125);
      const double errorCoarse = MaxRelativeDifference(coarse, L);
      const double errorFine = MaxRelativeDifference(fine, L);
      std::printf("  sun %4.1f deg, view elevation %4.1f deg: relative error s=0.5 %.2e, "
                  "s=0.125 %.2e\n",
        elevation, std::asin(v[2]) / kDegree, errorCoarse, errorFine);
      EXPECT_LT(errorFine, 2e-3);
      EXPECT_LT(errorFine, errorCoarse);
    }
  }
}

// Empty-space skipping is exact: a blob with zero regions renders like the same blob
// whose zeros are replaced by 1e-30 (no block is empty, nothing is skipped).
TEST(SingleScattering, EmptySpaceSkippingIsExact)
{
  for (bool atmosphere : { false, true })
  {
    SceneDescription scene;
    scene.Atmosphere.Enabled = atmosphere;
    scene.Background.Type = atmosphere ? "atmosphere" : "constant";
    scene.Background.Radiance = 0.3;
    scene.Camera.Width = 12;
    scene.Camera.Height = 12;
    scene.SpectralSamples = 8;
    scene.Medium.ExtinctionPerDensity = 0.01;
    const DensityGrid sparse = Blob(23, 150.0, { { 0.0, 0.0, 1800.0 } });
    std::vector<float> values = sparse.GetValues();
    std::size_t zeros = 0;
    for (float& value : values)
    {
      zeros += value == 0.0f;
      value = std::max(value, 1e-30f);
    }
    ASSERT_GT(zeros, values.size() / 3);
    const DensityGrid dense(
      sparse.GetDimensions(), sparse.GetOrigin(), sparse.GetSpacing(), values);
    const nimbus::FloatImage a =
      nimbus::RenderSingleScatteringPass(RenderContext(scene, sparse), 0.5, 2);
    const nimbus::FloatImage b =
      nimbus::RenderSingleScatteringPass(RenderContext(scene, dense), 0.5, 2);
    double worst = 0.0;
    for (std::size_t k = 0; k < a.Pixels.size(); ++k)
    {
      worst =
        std::max(worst, std::abs(double(a.Pixels[k]) - b.Pixels[k]) / std::max(1e-6f, b.Pixels[k]));
    }
    std::printf(
      "  %s: max relative difference %.2e\n", atmosphere ? "atmosphere" : "no atmosphere", worst);
    EXPECT_LT(worst, 1e-6);
  }
}

TEST(SingleScattering, InvalidArguments)
{
  const RenderContext context(PlainScene(45.0, 0.0), Slab());
  EXPECT_THROW(nimbus::RenderSingleScatteringPass(context, 0.0, 1), std::invalid_argument);
  EXPECT_THROW(nimbus::RenderSingleScatteringPass(context, std::nan(""), 1), std::invalid_argument);
  EXPECT_THROW(
    nimbus::SingleScatteringRadiance(context, { { 0.0, 0.0, 0.0 } }, { { 0.0, 0.0, 2.0 } }, 0.5),
    std::invalid_argument);
  nimbus::SingleScatteringSettings settings;
  settings.StepScale = -1.0;
  EXPECT_THROW(nimbus::RenderSingleScattering(context, settings), std::invalid_argument);
}
