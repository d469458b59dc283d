// Accuracy and stability of the sky model (Physics/Sky.h).
//
// The single-scattering sky against the reference renderer needs the reference module:
// Testing/Cxx/TestSkyAgainstReference.cxx. Here, with Nimbus::Physics alone:
// Published behaviour: Preetham et al. 1999's zenith luminance formula
// (implemented in Sky.cxx from the paper), horizon brightening, sunset colours.
//
// Every bound below is set from the measured value printed by the test (see
// docs/sky.md for the table); units: radiance relative to the sun (Y = 1).
#include "Math.h"
#include "Sky.h"
#include "SkyTesting.h"

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
using nimbus::Vector3;
using nimbus::testing::RelativeError;
using nimbus::testing::Rgb;
using nimbus::testing::Y;

using nimbus::kDegree;
using nimbus::kPi;

Vector3 Direction(double elevationDeg, double azimuthDeg)
{
  return nimbus::SunDirection(elevationDeg, azimuthDeg);
}

bool Finite(const Rgb& c)
{
  return std::isfinite(c[0]) && std::isfinite(c[1]) && std::isfinite(c[2]);
}

} // namespace

// The transmittance table (256 x 64 optical lengths) against Atmosphere's exact
// optical lengths, over r in [R, R_top] and every mu above the horizon.
TEST(Sky, TransmittanceTableInterpolation)
{
  const SkyModel& model = nimbus::testing::FullSkyModel();
  const double R = model.GetParameters().Atmosphere.EarthRadiusMetres;
  const double top = model.GetParameters().Atmosphere.TopRadiusMetres;
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
        const double tauExact =
          air.RayleighScattering(lambda) * exact[0] + air.MieExtinction(lambda) * exact[1];
        const double tauLut =
          air.RayleighScattering(lambda) * lut[0] + air.MieExtinction(lambda) * lut[1];
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
  EXPECT_LT(worstT, 1e-3); // measured 5.8e-4 (grazing rays near the top)
}

// Multiple scattering: orders decrease geometrically; the sky is brighter than single
// scattering alone, most at twilight and at the horizon.
TEST(Sky, MultipleScatteringOrders)
{
  const SkyModel& full = nimbus::testing::FullSkyModel();
  for (double elevation : { 45.0, 5.0, -4.0 })
  {
    const std::vector<double> orders = full.OrderMeanRadiance(std::sin(elevation * kDegree));
    std::printf(
      "  sun %5.1f deg: mean radiance Y of orders 1..%zu at the ground:", elevation, orders.size());
    for (double o : orders)
    {
      std::printf(" %.3e", o);
    }
    std::printf("\n");
  }
  const SkyModel& single = nimbus::testing::SingleScatteringSkyModel();
  for (double elevation : { 60.0, 10.0, 0.0, -4.0, -8.0 })
  {
    const Vector3 s = Direction(elevation, 0.0);
    const Rgb zenithFull = full.Radiance(0.0, { { 0, 0, 1 } }, s);
    const Rgb zenithSingle = single.Radiance(0.0, { { 0, 0, 1 } }, s);
    const Rgb horizonFull = full.Radiance(0.0, Direction(1.0, 90.0), s);
    const Rgb horizonSingle = single.Radiance(0.0, Direction(1.0, 90.0), s);
    std::printf("  sun %5.1f deg: zenith Y full %.3e single %.3e, horizon (az 90) Y full %.3e "
                "single %.3e\n",
      elevation, Y(zenithFull), Y(zenithSingle), Y(horizonFull), Y(horizonSingle));
    // Multiple scattering only adds light.
    EXPECT_GE(Y(zenithFull), Y(zenithSingle));
    EXPECT_GE(Y(horizonFull), Y(horizonSingle));
    if (elevation <= -8.0)
    {
      // The zenith column is entirely in the earth's shadow (shadow height at the
      // zenith R (1/cos 8 deg - 1) = 62 km > 60 km): only multiple scattering lights it.
      EXPECT_EQ(Y(zenithSingle), 0.0);
      EXPECT_GT(Y(zenithFull), 0.0);
    }
  }
  // The orders decrease: each order's mean radiance at the ground is below the previous one.
  for (double elevation : { 60.0, 10.0, 0.0, -6.0 })
  {
    const std::vector<double> orders = full.OrderMeanRadiance(std::sin(elevation * kDegree));
    ASSERT_GE(orders.size(), 2u);
    for (std::size_t k = 1; k < orders.size(); ++k)
    {
      EXPECT_LT(orders[k], orders[k - 1]) << "sun " << elevation << " order " << k + 1;
    }
  }
}

// Zenith luminance against sun elevation: monotone, and its shape against Preetham.
TEST(Sky, ZenithLuminanceAgainstPreetham)
{
  const SkyModel& model = nimbus::testing::FullSkyModel();
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
  const std::size_t at40 = static_cast<std::size_t>(
    std::find(elevations.begin(), elevations.end(), 40.0) - elevations.begin());
  double worst = 0.0;
  for (std::size_t i = 0; i < elevations.size(); ++i)
  {
    const double ratio = (ours[i] / ours[at40]) / (preetham[i] / preetham[at40]);
    if (elevations[i] <= 70.0)
    {
      worst = std::max(worst, std::abs(std::log(ratio)));
    }
    if (static_cast<int>(elevations[i]) % 10 == 0 || elevations[i] < 10.0)
    {
      std::printf(
        "  sun %4.0f deg: zenith Y ours %.4e, Preetham T=2.5 %.3f kcd/m2, normalised ratio %.3f\n",
        elevations[i], ours[i], preetham[i], ratio);
    }
  }
  std::printf("  worst |ln(normalised ratio)| over 4..70 deg: %.3f\n", worst);
  // Bound: measured 0.215 (normalised ratio 0.81 at 4 deg, 0.97..1.11 over 8..70 deg),
  // rounded up. Above 70 deg the zenith enters the Mie aureole of this aerosol
  // (g = 0.76), which Preetham's fit (a smooth function of the sun angle only) does
  // not have: ratio 1.41 at 80 deg, printed only.
  EXPECT_LT(worst, 0.25);
}

// Published behaviour, quantitatively (linear sRGB, CIE chromaticity through the
// sRGB primaries).
TEST(Sky, PublishedBehaviour)
{
  const SkyModel& model = nimbus::testing::FullSkyModel();
  // Blue zenith at noon: B/R of the zenith.
  {
    const Rgb z = model.Radiance(0.0, { { 0, 0, 1 } }, Direction(60.0, 0.0));
    std::printf(
      "  sun 60 deg: zenith rgb %.3e %.3e %.3e, B/R %.2f\n", z[0], z[1], z[2], z[2] / z[0]);
    EXPECT_GT(z[2] / z[0], 1.5); // measured 2.0
  }
  // Sunset: near the sun on the horizon red/orange (R > G > B, R/B large), while the
  // zenith stays blue (B > R).
  {
    const Vector3 s = Direction(1.0, 0.0);
    const Rgb nearSun = model.Radiance(0.0, Direction(2.0, 10.0), s);
    const Rgb zenith = model.Radiance(0.0, { { 0, 0, 1 } }, s);
    std::printf("  sun 1 deg: near the sun rgb %.3e %.3e %.3e (R/B %.1f), zenith B/R %.2f\n",
      nearSun[0], nearSun[1], nearSun[2], nearSun[0] / std::max(nearSun[2], 1e-30),
      zenith[2] / zenith[0]);
    EXPECT_GT(nearSun[0], nearSun[1]);
    EXPECT_GT(nearSun[1], nearSun[2]);
    EXPECT_GT(nearSun[0], 3.0 * std::max(nearSun[2], 0.0)); // orange-red: measured R/B > 10
    EXPECT_GT(zenith[2], zenith[0]);
  }
  // Horizon brightening (away from the sun, sun at 45 deg): the horizon is brighter and
  // whiter (lower B/R) than the sky 30 degrees up in the same azimuth.
  {
    const Vector3 s = Direction(45.0, 0.0);
    const Rgb horizon = model.Radiance(0.0, Direction(2.0, 90.0), s);
    const Rgb up = model.Radiance(0.0, Direction(30.0, 90.0), s);
    std::printf(
      "  sun 45 deg, azimuth 90 from the sun: Y(2 deg)/Y(30 deg) = %.2f, B/R %.2f vs %.2f\n",
      Y(horizon) / Y(up), horizon[2] / horizon[0], up[2] / up[0]);
    EXPECT_GT(Y(horizon), 1.2 * Y(up));
    EXPECT_LT(horizon[2] / horizon[0], up[2] / up[0]);
  }
}

// Stability: finite, non-negative (luminance) radiance at the extremes.
TEST(Sky, Extremes)
{
  const SkyModel& model = nimbus::testing::FullSkyModel();
  const double alts[] = { 0.0, 10000.0, 59999.0, 100000.0, 1.0e6 };
  for (double altitude : alts)
  {
    for (double elevation : { 90.0, 0.0, -10.0, -90.0 })
    {
      const Vector3 s = Direction(elevation, 30.0);
      const SkyViewLut lut(model, elevation, altitude, 16, 8, 8);
      for (const Vector3& w :
        { Vector3{ { 0, 0, 1 } }, Vector3{ { 0, 0, -1 } }, Direction(0.0, 10.0),
          Direction(1e-7, 200.0), Direction(-1e-7, 200.0), Direction(-89.0, 5.0) })
      {
        const Rgb direct = model.Radiance(altitude, w, s);
        const Rgb table = lut.Radiance(w, 30.0);
        EXPECT_TRUE(Finite(direct) && Finite(table)) << altitude << " " << elevation;
        EXPECT_GE(Y(direct), 0.0);
        EXPECT_GE(Y(table), 0.0);
      }
    }
  }
  // Observer far above the atmosphere looking away from it: nothing.
  const Rgb space = model.Radiance(1.0e6, { { 0, 0, 1 } }, Direction(45.0, 0.0));
  EXPECT_EQ(Y(space), 0.0);
  // The transmittance toward the sun: 1 at the top looking up, 0 through the earth.
  std::vector<double> t(model.GetSunIrradiance().size());
  model.SunTransmittance(model.GetParameters().Atmosphere.TopRadiusMetres, 1.0, t.data());
  EXPECT_NEAR(t[0], 1.0, 1e-6);
  model.SunTransmittance(model.GetParameters().Atmosphere.EarthRadiusMetres, -0.5, t.data());
  EXPECT_EQ(t[0], 0.0);
  // Bad parameters: one clear error naming the field.
  SkyParameters bad;
  bad.GroundAlbedo = 1.5;
  EXPECT_THROW(SkyModel{ bad }, std::invalid_argument);
  bad = SkyParameters();
  bad.ScatteringOrders = 0;
  EXPECT_THROW(SkyModel{ bad }, std::invalid_argument);
  EXPECT_THROW(SkyViewLut(model, 120.0, 0.0), std::invalid_argument);
  EXPECT_THROW(SkyViewLut(model, 10.0, -5.0), std::invalid_argument);
}

// Continuity (no seams): the LUT against the direct march on the rows next to the
// horizon, at the azimuth borders (toward and away from the sun) and across the
// zenith; and the radiance as a function of the sun elevation through the horizon
// and down to -10 degrees.
TEST(Sky, Continuity)
{
  const SkyModel& model = nimbus::testing::FullSkyModel();
  for (double altitude : { 0.0, 2000.0, 30000.0 })
  {
    for (double elevation : { 30.0, 3.0, -3.0, -10.0 })
    {
      const SkyViewLut lut(model, elevation, altitude);
      const Vector3 s = Direction(elevation, 0.0);
      double yMax = 0.0;
      for (double e = -5.0; e <= 90.0; e += 5.0)
      {
        for (double az = 0.0; az <= 180.0; az += 30.0)
        {
          yMax = std::max(yMax, Y(model.Radiance(altitude, Direction(e, az), s)));
        }
      }
      const double horizon = 90.0 -
        std::acos(model.HorizonMu(model.GetParameters().Atmosphere.EarthRadiusMetres + altitude)) /
          kDegree;
      double worst = 0.0, worstDe = 0.0, worstAz = 0.0;
      for (double de : { -1.0, -0.1, -0.01, 0.01, 0.1, 1.0 })
      {
        for (double az : { 0.0, 0.2, 90.0, 179.8, 180.0 })
        {
          const Vector3 w = Direction(horizon + de, az);
          const Rgb a = lut.Radiance(w, 0.0);
          const Rgb b = model.Radiance(altitude, w, s);
          const double e = RelativeError(a, b, 1e-3 * yMax);
          if (e > worst)
          {
            worst = e;
            worstDe = de;
            worstAz = az;
          }
        }
      }
      for (double az : { 0.0, 90.0, 180.0 })
      {
        const Vector3 w = Direction(89.99, az);
        worst = std::max(
          worst, RelativeError(lut.Radiance(w, 0.0), model.Radiance(altitude, w, s), 1e-3 * yMax));
      }
      std::printf("  altitude %6.0f m, sun %5.1f deg: LUT vs march at the horizon/borders max %.2e "
                  "(at %+.2f deg from the horizon, azimuth %.1f from the sun)\n",
        altitude, elevation, worst, worstDe, worstAz);
      // Bounds: measured max 3.9e-2 up to 2 km; at 30 km with the sun at -10 deg,
      // 0.17 just above the horizon toward the sun (the limb's twilight glow grows
      // x30 within 1 deg there; the 64 upper rows under-resolve it): a known weakness.
      EXPECT_LT(worst, altitude <= 2000.0 ? 0.05 : (elevation > -5.0 ? 0.02 : 0.2));
    }
  }
  // Sun elevation sweep: zenith and horizon radiance change smoothly (no jump between
  // steps of 0.25 degree larger than 3x the neighbouring steps' mean).
  for (double viewElevation : { 90.0, 0.5, -0.5 })
  {
    std::vector<double> y;
    for (double elevation = -10.0; elevation <= 6.0; elevation += 0.25)
    {
      y.push_back(
        Y(model.Radiance(0.0, Direction(viewElevation, 120.0), Direction(elevation, 0.0))));
    }
    double worstJump = 0.0;
    for (std::size_t i = 2; i + 2 < y.size(); ++i)
    {
      const double d = std::abs(std::log(y[i + 1] / y[i]));
      const double around = 0.25 *
        (std::abs(std::log(y[i] / y[i - 1])) + std::abs(std::log(y[i - 1] / y[i - 2])) +
          std::abs(std::log(y[i + 2] / y[i + 1])) + std::abs(std::log(y[i + 1] / y[i])));
      worstJump = std::max(worstJump, d / around);
      EXPECT_TRUE(std::isfinite(d));
    }
    std::printf(
      "  view elevation %5.1f: worst step / local mean step of ln Y over sun -10..6 deg: %.2f\n",
      viewElevation, worstJump);
    EXPECT_LT(worstJump, 3.0);
  }
}

// Aerial perspective: the table against the direct march.
TEST(Sky, AerialPerspectiveTable)
{
  const SkyModel& model = nimbus::testing::FullSkyModel();
  for (double elevation : { 45.0, 3.0 })
  {
    const nimbus::AerialPerspectiveLut table(model, elevation, 500.0);
    const double R = model.GetParameters().Atmosphere.EarthRadiusMetres;
    const Vector3 camera{ { 0.0, 0.0, R + 500.0 } };
    const Vector3 s = Direction(elevation, 40.0);
    double worstT = 0.0, worstL = 0.0;
    for (double d : { 300.0, 2000.0, 10000.0, 40000.0, 90000.0 })
    {
      for (double e : { -20.0, -2.0, 0.0, 5.0, 30.0 })
      {
        for (double az : { 0.0, 40.0, 100.0, 220.0 })
        {
          const Vector3 w = Direction(e, az);
          const Vector3 p{ { camera[0] + d * w[0], camera[1] + d * w[1], camera[2] + d * w[2] } };
          Rgb t0, l0, t1, l1;
          model.AerialPerspective(camera, p, s, t0, l0, 256);
          table.Lookup(w, d, 40.0, t1, l1);
          for (int c = 0; c < 3; ++c)
          {
            worstT = std::max(worstT, std::abs(t1[c] - t0[c]));
          }
          worstL = std::max(worstL, RelativeError(l1, l0, 1e-3));
        }
      }
    }
    std::printf("  sun %4.1f deg: aerial-perspective table vs march: max |dT| %.2e, max inscatter "
                "error %.2e (relative, floor 1e-3)\n",
      elevation, worstT, worstL);
    // Bounds: measured 1.3e-3 and 1.6e-2 (sun 45 and 3 deg), rounded up.
    EXPECT_LT(worstT, 2e-3);
    EXPECT_LT(worstL, 2e-2);
  }
}
