// The sky model's single scattering (Physics/Sky.h) against the reference renderer's
// clear sky (Reference/Core: nimbus::SingleScatteringRadiance with an empty density
// grid, no ground plane: the same Atmosphere, Planck 5778 K sun of luminance 1, 16
// wavelengths). The sky's other tests need no reference: Physics/Testing/TestSky.cxx.
//
// Every bound below is set from the measured value printed by the test (see
// docs/sky.md for the table); units: radiance relative to the sun (Y = 1).
#include "Math.h"
#include "Sky.h"
#include "SkyTesting.h"

#include "DensityGrid.h"
#include "RenderContext.h"
#include "SceneDescription.h"
#include "SingleScatteringRenderer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

namespace
{
using nimbus::SkyModel;
using nimbus::SkyParameters;
using nimbus::SkyViewLut;
using nimbus::Vector3;
using nimbus::testing::RelativeError;
using nimbus::testing::Rgb;
using nimbus::testing::Y;

using nimbus::kDegree;

Vector3 Direction(double elevationDeg, double azimuthDeg)
{
  return nimbus::SunDirection(elevationDeg, azimuthDeg);
}

/// Reference context: empty grid, atmosphere, no ground plane (the earth sphere is black).
std::unique_ptr<nimbus::RenderContext> ReferenceContext(double sunElevation, double altitude)
{
  nimbus::SceneDescription scene;
  scene.Sun.ElevationDegrees = sunElevation;
  scene.Sun.AzimuthDegrees = 0.0;
  scene.Ground.Enabled = false;
  scene.Atmosphere.SceneAltitudeMetres = altitude;
  scene.SpectralSamples = 16;
  return std::make_unique<nimbus::RenderContext>(scene,
    nimbus::DensityGrid({ { 2, 2, 2 } }, { { 0.0, 0.0, -1.0e6 } }, { { 50.0, 50.0, 50.0 } },
      std::vector<float>(8, 0.0f)));
}

} // namespace

// Single scattering, LUT path (sky-view table of a K = 1 model) against the reference
// renderer over the whole upper dome at sun elevations 90, 45, 10, 2, -4 degrees.
// Per direction: max over channels |L_lut - L_ref| / max(Y_ref, 1e-3 Y_max), Y_max the
// brightest direction of that dome: at -4 degrees single scattering away from the sun
// is lit only far above the earth's shadow, 1e-4..1e-6 of the bright part, and a
// relative error of nearly nothing is not a useful measure there (the floor's share
// of directions is printed).
TEST(Sky, SingleScatteringAgainstReference)
{
  const SkyModel& model = nimbus::testing::SingleScatteringSkyModel();
  for (double elevation : { 90.0, 45.0, 10.0, 2.0, -4.0 })
  {
    const auto context = ReferenceContext(elevation, 0.0);
    const SkyViewLut lut(model, elevation, 0.0);
    struct Sample
    {
      Vector3 w;
      Rgb ref, lut, march;
    };
    std::vector<Sample> samples;
    double yMax = 0.0;
    for (double e = 0.0; e <= 90.0; e += 5.0)
    {
      for (double az = 0.0; az < 360.0; az += 20.0)
      {
        const double viewElevation =
          std::max(e, 0.5); // the reference ray must not graze the sphere
        Sample sample;
        sample.w = Direction(viewElevation, az + 7.0);
        sample.ref = context->ToLinearSrgb(
          nimbus::SingleScatteringRadiance(*context, { { 0.0, 0.0, 0.0 } }, sample.w, 0.125));
        sample.lut = lut.Radiance(sample.w, 0.0);
        sample.march = model.Radiance(0.0, sample.w, Direction(elevation, 0.0), false);
        yMax = std::max(yMax, Y(sample.ref));
        samples.push_back(sample);
      }
    }
    double worstLut = 0.0, worstMarch = 0.0, sumLut = 0.0;
    int floored = 0;
    Vector3 worstDirection{ { 0, 0, 0 } };
    for (const Sample& sample : samples)
    {
      const double floor = 1e-3 * yMax;
      floored += Y(sample.ref) < floor ? 1 : 0;
      const double eLut = RelativeError(sample.lut, sample.ref, floor);
      if (eLut > worstLut)
      {
        worstLut = eLut;
        worstDirection = sample.w;
      }
      worstMarch = std::max(worstMarch, RelativeError(sample.march, sample.ref, floor));
      sumLut += eLut;
    }
    std::printf("  sun %5.1f deg: LUT vs reference max %.2e (mean %.2e; worst at view elevation "
                "%.1f, azimuth from sun %.0f), direct march max %.2e; %d of %zu directions below "
                "the floor\n",
      elevation, worstLut, sumLut / samples.size(), std::asin(worstDirection[2]) / kDegree,
      std::atan2(worstDirection[0], worstDirection[1]) / kDegree, worstMarch, floored,
      samples.size());
    // Bounds: the measured maxima rounded up (sun >= 2 deg: 5.5e-3, of which the
    // march itself 2.7e-3; -4 deg: 4.4e-2 at the earth's shadow edge on the horizon).
    EXPECT_LT(worstLut, elevation >= 2.0 ? 6e-3 : 5e-2) << "sun elevation " << elevation;
    EXPECT_LT(worstMarch, 4e-3) << "sun elevation " << elevation;
  }
}
