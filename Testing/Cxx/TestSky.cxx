// Accuracy and stability of the sky model (Representations/Optics/Sky.h).
//
// Ground truth: the single-scattering reference renderer's clear sky
// (nimbus::SingleScatteringRadiance with an empty density grid, no ground plane:
// the same Atmosphere, Planck 5778 K sun of luminance 1, 16 wavelengths).
// Published behaviour: Preetham et al. 1999's zenith luminance formula
// (implemented in Sky.cxx from the paper), horizon brightening, sunset colours.
//
// Every bound below is set from the measured value printed by the test (see
// docs/sky.md for the table); units: radiance relative to the sun (Y = 1).
#include "Sky.h"

#include "DensityGrid.h"
#include "RenderContext.h"
#include "SceneDescription.h"
#include "SingleScatteringRenderer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <vector>

namespace
{
using nimbus::SkyModel;
using nimbus::SkyParameters;
using nimbus::SkyViewLut;
using Vector3 = std::array<double, 3>;
using Rgb = std::array<double, 3>;

constexpr double kPi = 3.14159265358979323846;
constexpr double kDegree = kPi / 180.0;

Vector3 Direction(double elevationDeg, double azimuthDeg)
{
  return nimbus::SunDirectionFromAngles(elevationDeg, azimuthDeg);
}

double Y(const Rgb& c)
{
  return nimbus::LinearSrgbLuminance(c);
}

bool Finite(const Rgb& c)
{
  return std::isfinite(c[0]) && std::isfinite(c[1]) && std::isfinite(c[2]);
}

/// One full model (multiple scattering, albedo 0.3) and one single-scattering model
/// (albedo 0, K = 1), shared by the tests (built once).
const SkyModel& FullModel()
{
  static const SkyModel model{ SkyParameters() };
  return model;
}

const SkyModel& SingleModel()
{
  static const SkyModel model{ [] {
    SkyParameters p;
    p.ScatteringOrders = 1;
    p.GroundAlbedo = 0.0;
    return p;
  }() };
  return model;
}

/// Reference context: empty grid, atmosphere, no ground plane (the earth sphere is black).
std::unique_ptr<nimbus::RenderContext> ReferenceContext(double sunElevation, double altitude)
{
  nimbus::SceneDescription scene;
  scene.Sun.Elevation = sunElevation;
  scene.Sun.Azimuth = 0.0;
  scene.Ground.Enabled = false;
  scene.Atmosphere.SceneAltitude = altitude;
  scene.SpectralSamples = 16;
  return std::make_unique<nimbus::RenderContext>(scene,
    nimbus::DensityGrid({ { 2, 2, 2 } }, { { 0.0, 0.0, -1.0e6 } }, { { 50.0, 50.0, 50.0 } },
      std::vector<float>(8, 0.0f)));
}

/// |a - b| per channel relative to the reference luminance (so that a dim channel
/// at twilight does not count as a large error), maximum over channels; the
/// luminance is floored at `floor` (absolute).
double RelativeError(const Rgb& a, const Rgb& ref, double floor = 1e-30)
{
  const double y = std::max(Y(ref), floor);
  double e = 0.0;
  for (int c = 0; c < 3; ++c)
  {
    e = std::max(e, std::abs(a[c] - ref[c]) / y);
  }
  return e;
}
} // namespace

// The transmittance table (256 x 64 optical lengths) against Atmosphere's exact
// optical lengths, over r in [R, R_top] and every mu above the horizon.
TEST(Sky, TransmittanceTableInterpolation)
{
  const SkyModel& model = FullModel();
  const double R = model.GetParameters().Atmosphere.earthRadius;
  const double top = model.GetParameters().Atmosphere.topRadius;
  const nimbus::Atmosphere& air = model.GetAtmosphere();
  double worstT = 0.0, worstTau = 0.0;
  for (int j = 0; j <= 40; ++j)
  {
    const double r = R + (top - R) * std::pow(j / 40.0, 2.0) * 0.999;
    const double muH = model.HorizonMu(r);
    for (int i = 0; i <= 200; ++i)
    {
      // dense near the horizon
      const double u = i / 200.0;
      const double mu = muH + (1.0 - muH) * u * u + 1e-9;
      const auto exact = model.ExactOpticalLengths(r, mu);
      const auto lut = model.LookupOpticalLengths(r, mu);
      for (double lambda : { 440.0, 550.0, 680.0 })
      {
        const double tauExact = air.RayleighScattering(lambda) * exact[0] + air.MieExtinction(lambda) * exact[1];
        const double tauLut = air.RayleighScattering(lambda) * lut[0] + air.MieExtinction(lambda) * lut[1];
        worstT = std::max(worstT, std::abs(std::exp(-tauLut) - std::exp(-tauExact)));
        if (tauExact > 1e-3)
        {
          worstTau = std::max(worstTau, std::abs(tauLut - tauExact) / tauExact);
        }
      }
    }
  }
  std::printf("  transmittance table %dx%d: max |dT| = %.2e, max relative d(tau) = %.2e\n",
    model.GetTransmittanceMuSize(), model.GetTransmittanceRSize(), worstT, worstTau);
  EXPECT_LT(worstT, 2e-3);
}

// Single scattering, LUT path (sky-view table of a K = 1 model) against the reference
// renderer over the whole upper dome at sun elevations 90, 45, 10, 2, -4 degrees.
// Per direction: max over channels |L_lut - L_ref| / max(Y_ref, 1e-3 Y_max), Y_max the
// brightest direction of that dome: at -4 degrees single scattering away from the sun
// is lit only far above the earth's shadow, 1e-4..1e-6 of the bright part, and a
// relative error of nearly nothing is not a useful measure there (the floor's share
// of directions is printed).
TEST(Sky, SingleScatteringAgainstReference)
{
  const SkyModel& model = SingleModel();
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
        const double viewElevation = std::max(e, 0.5); // the reference ray must not graze the sphere
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

// Multiple scattering: orders decrease geometrically; the sky is brighter than single
// scattering alone, most at twilight and at the horizon.
TEST(Sky, MultipleScatteringOrders)
{
  const SkyModel& full = FullModel();
  for (double elevation : { 45.0, 5.0, -4.0 })
  {
    const std::vector<double> orders = full.OrderMeanRadiance(std::sin(elevation * kDegree));
    std::printf("  sun %5.1f deg: mean radiance Y of orders 1..%zu at the ground:", elevation, orders.size());
    for (double o : orders)
    {
      std::printf(" %.3e", o);
    }
    std::printf("\n");
  }
  const SkyModel& single = SingleModel();
  for (double elevation : { 60.0, 10.0, 0.0, -4.0, -8.0 })
  {
    const Vector3 s = Direction(elevation, 0.0);
    const Rgb zenithFull = full.Radiance(0.0, { { 0, 0, 1 } }, s);
    const Rgb zenithSingle = single.Radiance(0.0, { { 0, 0, 1 } }, s);
    const Rgb horizonFull = full.Radiance(0.0, Direction(1.0, 90.0), s);
    const Rgb horizonSingle = single.Radiance(0.0, Direction(1.0, 90.0), s);
    std::printf("  sun %5.1f deg: full/single zenith Y %.3f, horizon (az 90) Y %.3f\n", elevation,
      Y(zenithFull) / Y(zenithSingle), Y(horizonFull) / Y(horizonSingle));
  }
}

// Zenith luminance against sun elevation: monotone, and its shape against Preetham.
TEST(Sky, ZenithLuminanceAgainstPreetham)
{
  const SkyModel& model = FullModel();
  double previous = -1.0;
  bool monotone = true;
  std::vector<double> elevations, ours, preetham;
  for (double elevation = -10.0; elevation <= 90.0; elevation += 2.0)
  {
    const Rgb z = model.Radiance(0.0, { { 0, 0, 1 } }, Direction(elevation, 0.0));
    const double y = Y(z);
    monotone = monotone && y > previous;
    previous = y;
    if (elevation >= 4.0)
    {
      elevations.push_back(elevation);
      ours.push_back(y);
      preetham.push_back(nimbus::PreethamZenithLuminance(2.5, (90.0 - elevation) * kDegree));
    }
  }
  EXPECT_TRUE(monotone);
  // Shape: both normalised at 40 degrees.
  const std::size_t at40 = static_cast<std::size_t>(std::find(elevations.begin(), elevations.end(), 40.0) - elevations.begin());
  double worst = 0.0;
  for (std::size_t i = 0; i < elevations.size(); ++i)
  {
    const double ratio = (ours[i] / ours[at40]) / (preetham[i] / preetham[at40]);
    worst = std::max(worst, std::abs(std::log(ratio)));
    if (static_cast<int>(elevations[i]) % 10 == 0)
    {
      std::printf("  sun %4.0f deg: zenith Y ours %.4e, Preetham T=2.5 %.3f kcd/m2, normalised ratio %.3f\n",
        elevations[i], ours[i], preetham[i], ratio);
    }
  }
  std::printf("  worst |ln(normalised ratio)| over 4..90 deg: %.3f\n", worst);
}
