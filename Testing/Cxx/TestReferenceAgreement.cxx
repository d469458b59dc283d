// The two reference renderers agree: single scattering (deterministic, converged)
// equals the path tracer restricted to one scattering event (MaxScatteringOrder 1,
// rays through pixel centres) within the path tracer's standard errors, on a
// heterogeneous cloud with and without the atmosphere and ground.
#include "DensityGrid.h"
#include "PathTracer.h"
#include "RenderContext.h"
#include "SingleScatteringRenderer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <vector>

namespace
{
// A lumpy cloud: two overlapping smooth blobs, 24 x 24 x 16 points over 2 x 2 x 1.3 km.
nimbus::DensityGrid LumpyCloud()
{
  const std::array<int, 3> dims{ { 24, 24, 16 } };
  const nimbus::DensityGrid::Vector3 origin{ { -1000.0, -1000.0, 1000.0 } };
  const nimbus::DensityGrid::Vector3 spacing{ { 2000.0 / 23, 2000.0 / 23, 1300.0 / 15 } };
  std::vector<float> values;
  for (int k = 0; k < dims[2]; ++k)
    for (int j = 0; j < dims[1]; ++j)
      for (int i = 0; i < dims[0]; ++i)
      {
        const double x = origin[0] + i * spacing[0], y = origin[1] + j * spacing[1],
                     z = origin[2] + k * spacing[2];
        const double a =
          std::exp(-((x + 250) * (x + 250) + y * y + (z - 1600) * (z - 1600)) / 2.0e5);
        const double b = std::exp(
          -((x - 300) * (x - 300) + (y - 200) * (y - 200) + (z - 1700) * (z - 1700)) / 1.2e5);
        values.push_back(static_cast<float>(a + 0.8 * b));
      }
  return nimbus::DensityGrid(dims, origin, spacing, std::move(values));
}

nimbus::SceneDescription SmallScene(bool atmosphere)
{
  nimbus::SceneDescription scene;
  scene.Camera.Position = { { 300.0, -4000.0, 1500.0 } };
  scene.Camera.FocalPoint = { { 0.0, 0.0, 1550.0 } };
  scene.Camera.ViewAngle = 40.0;
  scene.Camera.Width = 12;
  scene.Camera.Height = 9;
  scene.Medium.ExtinctionPerDensity = 0.004; // optical thickness ~ 4 through the core
  scene.Medium.SingleScatteringAlbedo = 0.95;
  scene.Medium.Phase = { { "cornette_shanks", 0.7, 0.95 }, { "rayleigh", 0.0, 0.05 } };
  scene.Sun.ElevationDegrees = 35.0;
  scene.Sun.AzimuthDegrees = 200.0;
  scene.Atmosphere.Enabled = atmosphere;
  scene.Ground.Enabled = atmosphere;
  // Black surroundings: the path tracer's one bounce would also scatter a constant
  // background into the cloud, which single scattering of the sun (000 Eq. 1) omits.
  scene.Background.Type = atmosphere ? "atmosphere" : "black";
  scene.SpectralSamples = 8;
  return scene;
}

void ExpectAgreement(bool atmosphere)
{
  const nimbus::RenderContext context(SmallScene(atmosphere), LumpyCloud());
  nimbus::SingleScatteringSettings deterministic;
  deterministic.RelativeTolerance = 1e-4;
  const nimbus::SingleScatteringResult single =
    nimbus::RenderSingleScattering(context, deterministic);

  nimbus::PathTracingSettings monteCarlo;
  monteCarlo.MaxScatteringOrder = 1;
  monteCarlo.PixelJitter = false;
  monteCarlo.MinSamplesPerPixel = monteCarlo.MaxSamplesPerPixel = 4096;
  monteCarlo.Seed = 5;
  const nimbus::PathTracingResult traced = nimbus::RenderPathTraced(context, monteCarlo);

  // Per pixel and channel: |difference| within 4 standard errors plus the single-
  // scattering renderer's own estimated error, and the normalised differences
  // spread like a unit normal (RMS near 1). Pixels where no path scattered at all
  // (0 +- 0: a cloud's faint edge, optical depth ~1e-6) carry no variance
  // estimate; there single scattering must be faint (< 1e-3 of the image's peak).
  double peak = 0.0;
  for (float value : single.Image.Pixels)
  {
    peak = std::max(peak, static_cast<double>(value));
  }
  double sumZ2 = 0.0;
  int count = 0, outliers = 0, noEvents = 0;
  for (std::size_t i = 0; i < single.Image.Pixels.size(); ++i)
  {
    const double reference = single.Image.Pixels[i];
    const double mean = traced.Image.Pixels[i];
    const double standardError = traced.StandardError.Pixels[i];
    if (mean == 0.0 && standardError == 0.0)
    {
      ++noEvents;
      EXPECT_LT(std::abs(reference), 1e-3 * peak) << "value " << i;
      continue;
    }
    const double sigma =
      standardError + single.EstimatedRelativeError * std::abs(reference) + 1e-12;
    const double z = (mean - reference) / sigma;
    sumZ2 += z * z;
    ++count;
    outliers += std::abs(z) > 4.0 ? 1 : 0;
  }
  const double rmsZ = std::sqrt(sumZ2 / count);
  std::cout << (atmosphere ? "with" : "without") << " atmosphere: RMS z = " << rmsZ << ", "
            << outliers << " of " << count << " beyond 4 sigma, " << noEvents
            << " without any scattering event\n";
  EXPECT_LE(outliers, count / 100); // at most 1 % (expected ~0.006 %)
  EXPECT_LT(rmsZ, 1.5);
}
}

TEST(ReferenceAgreement, SingleScatteringEqualsOneBouncePathTracingWithoutAtmosphere)
{
  ExpectAgreement(false);
}

TEST(ReferenceAgreement, SingleScatteringEqualsOneBouncePathTracingWithAtmosphere)
{
  ExpectAgreement(true);
}
