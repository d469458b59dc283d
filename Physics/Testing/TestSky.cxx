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
#include "PreethamSky.h"
#include "Sky.h"
#include "SkyTesting.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
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
  EXPECT_LT(worstT, 1e-3); // measured 8.0e-4 (grazing rays near the top; 5.8e-4 without ozone)
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
  // Single scattering of the same air (the shared single-scattering model has the
  // reference renderer's grey air).
  const SkyModel single{ []
    {
      SkyParameters p;
      p.ScatteringOrders = 1;
      p.GroundAlbedo = 0.0;
      return p;
    }() };
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
      preetham.push_back(
        nimbus::PreethamZenithLuminance(nimbus::kDefaultTurbidity, (90.0 - elevation) * kDegree));
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
    if (elevations[i] >= 20.0 && elevations[i] <= 50.0)
    {
      worst = std::max(worst, std::abs(std::log(ratio)));
    }
    if (static_cast<int>(elevations[i]) % 10 == 0 || elevations[i] < 10.0)
    {
      std::printf("  sun %4.0f deg: zenith Y ours %.4e, Preetham (same T) %.3f kcd/m2, normalised "
                  "ratio %.3f\n",
        elevations[i], ours[i], preetham[i], ratio);
    }
  }
  std::printf("  worst |ln(normalised ratio)| over 20..50 deg: %.3f\n", worst);
  // Bound: measured 0.218 over 20..50 deg (ratio 0.80 at 20 deg, 1.14 at 50 deg),
  // rounded up. At the default turbidity 2 (aerosol optical depth 0.10 at 550 nm,
  // 3.8 times the grey aerosol of before) the zenith rises faster with the sun than
  // Preetham's fit: below 20 deg the sunlight crosses the aerosol layer at grazing
  // angles (ratio 0.63 at 10 deg, 0.38 at 4 deg) and above 50 deg the zenith is within
  // 40 deg of the sun, in the aerosol's forward lobe, which Preetham's smooth function
  // of the sun angle does not have (1.35 at 60 deg, 1.65 at 70 deg). Printed only; the
  // whole sky is compared in ValidationAgainstPreetham.
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
    EXPECT_GT(z[2] / z[0], 1.5); // measured 1.70 (2.0 with the grey aerosol of before)
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
    // Bounds: measured 1.7e-3 and 2.1e-2 (sun 45 deg; 1.3e-3 and 1.6e-2 with the
    // thinner grey aerosol of before), rounded up.
    EXPECT_LT(worstT, 2e-3);
    EXPECT_LT(worstL, 2.5e-2);
  }
}

namespace
{
/// CIE 1931 XYZ of linear sRGB (IEC 61966-2-1, D65; the inverse of XyzToLinearSrgb).
std::array<double, 3> LinearSrgbToXyz(const Rgb& c)
{
  return { { 0.4124564 * c[0] + 0.3575761 * c[1] + 0.1804375 * c[2],
    0.2126729 * c[0] + 0.7151522 * c[1] + 0.0721750 * c[2],
    0.0193339 * c[0] + 0.1191920 * c[1] + 0.9503041 * c[2] } };
}

double Median(std::vector<double> v)
{
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n == 0 ? 0.0 : (n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]));
}

/// CIE Standard General Sky (ISO 15469:2004 / CIE S 011/E:2003, from measured skies):
/// relative luminance L / L_zenith for view zenith Z, angle chi from the sun, sun zenith
/// Zs (rad): f(chi) phi(Z) / (f(Zs) phi(0)) with the gradation phi(Z) = 1 + a exp(b / cos Z)
/// and the indicatrix f(chi) = 1 + c (exp(d chi) - exp(d pi/2)) + e cos^2 chi. Clear-sky
/// types: 12 "clear, low luminance turbidity" (a, b, c, d, e) = (-1, -0.32, 10, -3, 0.45),
/// 13 "clear, polluted atmosphere" (-1, -0.32, 16, -3, 0.30).
double CieClearSky(int type, double Z, double chi, double Zs)
{
  const double a = -1.0, b = -0.32, d = -3.0;
  const double c = type == 13 ? 16.0 : 10.0, e = type == 13 ? 0.30 : 0.45;
  const auto f = [&](double x)
  { return 1.0 + c * (std::exp(d * x) - std::exp(d * kPi / 2.0)) + e * std::cos(x) * std::cos(x); };
  const auto phi = [&](double z) { return 1.0 + a * std::exp(b / std::max(std::cos(z), 1e-4)); };
  return f(chi) * phi(Z) / (f(Zs) * phi(0.0));
}

/// One direction of a published sky: view elevation and azimuth from the sun (deg), the
/// sky's luminance there (any unit: every comparison normalises) and CIE 1931 (x, y).
struct ReferenceSample
{
  enum Kind
  {
    Dome,   // the grid over the dome
    Ring,   // 3..15 deg from the sun
    Zenith, // straight up
  } Where;
  double Elevation, Azimuth, Luminance;
  std::array<double, 2> Xy;
};

/// The directions of a comparison: the dome, view elevations 2.5, 7.5, ..., 87.5 deg by
/// azimuths 0, 10, ..., 180 deg from the sun (the sky is symmetric about the sun's
/// vertical); rings 3, 5, 8, 12, 15 deg around the sun (12 directions each, those above
/// 2 deg elevation); the zenith. measurements/hosek-wilkie-reference.py samples the same.
std::vector<ReferenceSample> ComparisonDirections(double sunElevation)
{
  std::vector<ReferenceSample> out;
  for (double e = 2.5; e < 90.0; e += 5.0)
  {
    for (double az = 0.0; az <= 180.0; az += 10.0)
    {
      out.push_back({ ReferenceSample::Dome, e, az, 0.0, {} });
    }
  }
  const Vector3 s = Direction(sunElevation, 0.0);
  const Vector3 east{ { 1.0, 0.0, 0.0 } };
  const Vector3 u = nimbus::Normalized(nimbus::Cross(s, east));
  const Vector3 v = nimbus::Cross(s, u);
  for (double g : { 3.0, 5.0, 8.0, 12.0, 15.0 })
  {
    for (double psi = 0.0; psi < 360.0; psi += 30.0)
    {
      const double cg = std::cos(g * kDegree), sg = std::sin(g * kDegree);
      const double cp = std::cos(psi * kDegree), sp = std::sin(psi * kDegree);
      Vector3 w;
      for (int i = 0; i < 3; ++i)
      {
        w[i] = cg * s[i] + sg * (cp * u[i] + sp * v[i]);
      }
      if (w[2] < std::sin(2.0 * kDegree))
      {
        continue;
      }
      out.push_back({ ReferenceSample::Ring, std::asin(std::min(1.0, w[2])) / kDegree,
        std::atan2(w[0], w[1]) / kDegree, 0.0, {} });
    }
  }
  out.push_back({ ReferenceSample::Zenith, 90.0, 0.0, 0.0, {} });
  return out;
}

/// Preetham et al. 1999 at turbidity T and the sun's elevation, in those directions.
std::vector<ReferenceSample> PreethamReference(double turbidity, double sunElevation)
{
  const nimbus::PreethamSky preetham(turbidity, (90.0 - sunElevation) * kDegree);
  const Vector3 s = Direction(sunElevation, 0.0);
  std::vector<ReferenceSample> out = ComparisonDirections(sunElevation);
  for (ReferenceSample& x : out)
  {
    const Vector3 w = Direction(x.Elevation, x.Azimuth);
    const double zenith = std::acos(std::max(-1.0, std::min(1.0, w[2])));
    const double gamma = std::acos(std::max(-1.0, std::min(1.0, nimbus::Dot(w, s))));
    x.Luminance = preetham.Luminance(zenith, gamma);
    x.Xy = preetham.Chromaticity(zenith, gamma);
  }
  return out;
}

/// One sky (turbidity T, sun elevation) against a published sky and the CIE clear sky.
struct SkyComparison
{
  double Shape = 0.0;    // median over the dome of the normalised luminance ratio ours / theirs
  double Glow = 0.0;     // the same over directions 3..15 deg from the sun
  double MaxRatio = 0.0; // largest ratio on the dome (the brightest excess: the aureole)
  double CieShape = 0.0; // median ratio ours / CIE clear sky (type 12 for T < 3.5, else 13)
  double CieGlow = 0.0;  // the same 3..15 deg from the sun
  double Dx = 0.0;       // median over the dome of x_ours - x_theirs
  double Dy = 0.0;       // median over the dome of y_ours - y_theirs
  double ZenithDx = 0.0; // at the zenith
  double ZenithDy = 0.0;
};

/// Our sky against a reference sampled in ComparisonDirections. Each dome direction is
/// weighted by its solid angle (cos elevation; the two border azimuths by half); each
/// sky is normalised by its solid-angle mean over the dome's directions more than 20 deg
/// from the sun (so that the aureole, which Preetham's smooth fit does not have, does
/// not set the scale); then the ratio ours / theirs is taken per direction and its
/// median reported (shape over the dome, glow over the rings).
SkyComparison CompareSky(const SkyModel& model, double turbidity, double sunElevation,
  const std::vector<ReferenceSample>& reference)
{
  const SkyViewLut lut(model, sunElevation, 0.0);
  const double sunZenith = (90.0 - sunElevation) * kDegree;
  const int cieType = turbidity < 3.5 ? 12 : 13;
  const Vector3 s = Direction(sunElevation, 0.0);

  struct Sample
  {
    ReferenceSample::Kind Where;
    double Weight, Gamma, Ours, Theirs, Cie;
    std::array<double, 2> OursXy, TheirXy;
  };
  std::vector<Sample> samples;
  for (const ReferenceSample& r : reference)
  {
    const Vector3 w = Direction(r.Elevation, r.Azimuth);
    const double zenith = std::acos(std::max(-1.0, std::min(1.0, w[2])));
    const double gamma = std::acos(std::max(-1.0, std::min(1.0, nimbus::Dot(w, s))));
    const std::array<double, 3> xyz = LinearSrgbToXyz(lut.Radiance(w, 0.0));
    const double sum = xyz[0] + xyz[1] + xyz[2];
    const bool border = r.Azimuth == 0.0 || r.Azimuth == 180.0;
    samples.push_back(
      { r.Where, (border ? 0.5 : 1.0) * std::cos(r.Elevation * kDegree), gamma, xyz[1], r.Luminance,
        CieClearSky(cieType, zenith, gamma, sunZenith), { { xyz[0] / sum, xyz[1] / sum } }, r.Xy });
  }
  double ours = 0.0, theirs = 0.0, cie = 0.0;
  for (const Sample& x : samples)
  {
    if (x.Where == ReferenceSample::Dome && x.Gamma > 20.0 * kDegree)
    {
      ours += x.Weight * x.Ours;
      theirs += x.Weight * x.Theirs;
      cie += x.Weight * x.Cie;
    }
  }
  SkyComparison result;
  std::vector<double> shape, cieShape, dx, dy, glow, cieGlow;
  for (const Sample& x : samples)
  {
    const double ratio = (x.Ours / ours) / (x.Theirs / theirs);
    const double cieRatio = (x.Ours / ours) / (x.Cie / cie);
    if (x.Where == ReferenceSample::Dome)
    {
      shape.push_back(ratio);
      cieShape.push_back(cieRatio);
      result.MaxRatio = std::max(result.MaxRatio, ratio);
      dx.push_back(x.OursXy[0] - x.TheirXy[0]);
      dy.push_back(x.OursXy[1] - x.TheirXy[1]);
    }
    else if (x.Where == ReferenceSample::Ring)
    {
      glow.push_back(ratio);
      cieGlow.push_back(cieRatio);
    }
    else
    {
      result.ZenithDx = x.OursXy[0] - x.TheirXy[0];
      result.ZenithDy = x.OursXy[1] - x.TheirXy[1];
    }
  }
  result.Shape = Median(shape);
  result.Glow = Median(glow);
  result.CieShape = Median(cieShape);
  result.CieGlow = Median(cieGlow);
  result.Dx = Median(dx);
  result.Dy = Median(dy);
  return result;
}

/// Preetham's sky against another published one (the same normalisation as CompareSky):
/// the median over the dome of the normalised luminance ratio Preetham / reference.
double PublishedShapeRatio(
  double turbidity, double sunElevation, const std::vector<ReferenceSample>& reference)
{
  const std::vector<ReferenceSample> preetham = PreethamReference(turbidity, sunElevation);
  const Vector3 s = Direction(sunElevation, 0.0);
  std::vector<std::array<double, 2>> dome; // (Preetham, reference)
  double sumPreetham = 0.0, sumReference = 0.0;
  for (const ReferenceSample& r : reference)
  {
    if (r.Where != ReferenceSample::Dome)
    {
      continue;
    }
    const auto same = std::find_if(preetham.begin(), preetham.end(),
      [&](const ReferenceSample& p)
      {
        return p.Where == ReferenceSample::Dome && p.Elevation == r.Elevation &&
          p.Azimuth == r.Azimuth;
      });
    EXPECT_NE(same, preetham.end());
    if (same == preetham.end())
    {
      return 0.0;
    }
    const double weight =
      ((r.Azimuth == 0.0 || r.Azimuth == 180.0) ? 0.5 : 1.0) * std::cos(r.Elevation * kDegree);
    if (nimbus::Dot(Direction(r.Elevation, r.Azimuth), s) < std::cos(20.0 * kDegree))
    {
      sumPreetham += weight * same->Luminance;
      sumReference += weight * r.Luminance;
    }
    dome.push_back({ { same->Luminance, r.Luminance } });
  }
  std::vector<double> ratios;
  for (const auto& x : dome)
  {
    ratios.push_back((x[0] / sumPreetham) / (x[1] / sumReference));
  }
  return Median(ratios);
}

/// Hosek & Wilkie 2012 in ComparisonDirections, keyed by (turbidity, sun elevation):
/// read from Data/hosek-wilkie-reference.csv (measurements/hosek-wilkie-reference.py).
std::map<std::pair<int, int>, std::vector<ReferenceSample>> ReadHosekWilkieReference()
{
  std::map<std::pair<int, int>, std::vector<ReferenceSample>> out;
  std::ifstream file(NIMBUS_PHYSICS_TEST_DATA "/hosek-wilkie-reference.csv");
  std::string line;
  while (std::getline(file, line))
  {
    if (line.empty() || line[0] == '#' || line[0] == 't')
    {
      continue;
    }
    std::istringstream in(line);
    std::string field[8];
    for (std::string& f : field)
    {
      std::getline(in, f, ',');
    }
    const double x = std::stod(field[5]), y = std::stod(field[6]), z = std::stod(field[7]);
    const ReferenceSample::Kind where = field[2] == "dome"
      ? ReferenceSample::Dome
      : (field[2] == "ring" ? ReferenceSample::Ring : ReferenceSample::Zenith);
    out[{ std::stoi(field[0]), std::stoi(field[1]) }].push_back({ where, std::stod(field[3]),
      std::stod(field[4]), y, { { x / (x + y + z), y / (x + y + z) } } });
  }
  return out;
}
} // namespace

// The sky's shape and colour against a second published clear-sky model, Preetham, Shirley
// & Smits 1999 (PreethamSky.h), at the same turbidity, over sun elevations 1..90 deg and
// turbidities 2..5; the luminance shape also against the CIE Standard General Sky's clear
// types (measured skies). The validation proper is against Hosek & Wilkie 2012 (below):
// Preetham's and Hosek-Wilkie's shapes differ from each other by up to 70 % at T = 3..5
// (ValidationAgainstHosekWilkie prints it), so no sky can be within 10 % of both; their
// colours agree within 0.02. Bounds: measured values rounded (docs/sky.md).
TEST(Sky, ValidationAgainstPreetham)
{
  const double elevations[] = { 1.0, 2.0, 5.0, 10.0, 20.0, 30.0, 45.0, 60.0, 75.0, 90.0 };
  int shapeWithin = 0, colourWithin = 0, cases = 0;
  std::printf(
    "  T    sun | shape  glow3-15 max | CIE shape glow | median dx     dy | zenith dx  dy\n");
  for (double turbidity : { 2.0, 3.0, 4.0, 5.0 })
  {
    SkyParameters p;
    p.Atmosphere = nimbus::ClearSkyAtmosphere(turbidity);
    const SkyModel model(p);
    for (double elevation : elevations)
    {
      const SkyComparison c =
        CompareSky(model, turbidity, elevation, PreethamReference(turbidity, elevation));
      const bool shapeOk = std::abs(c.Shape - 1.0) <= 0.10;
      const bool colourOk = std::abs(c.Dx) <= 0.02 && std::abs(c.Dy) <= 0.02;
      shapeWithin += shapeOk ? 1 : 0;
      colourWithin += colourOk ? 1 : 0;
      ++cases;
      std::printf("  %.0f %6.0f | %.3f%s %.2f %.2f | %.3f %.2f | %+.4f %+.4f%s | %+.4f %+.4f\n",
        turbidity, elevation, c.Shape, shapeOk ? " " : "*", c.Glow, c.MaxRatio, c.CieShape,
        c.CieGlow, c.Dx, c.Dy, colourOk ? " " : "*", c.ZenithDx, c.ZenithDy);
      EXPECT_TRUE(std::isfinite(c.Shape) && std::isfinite(c.Dx) && std::isfinite(c.Dy));
      // The chromaticity within 0.02 of Preetham's for the sun at 20 deg and above
      // (measured: at most 0.0176); below, ours is up to 0.032 bluer (ozone).
      if (elevation >= 20.0)
      {
        EXPECT_LE(std::abs(c.Dx), 0.02) << "T " << turbidity << ", sun " << elevation;
        EXPECT_LE(std::abs(c.Dy), 0.02) << "T " << turbidity << ", sun " << elevation;
      }
      // The measured envelope elsewhere: shape 0.596..1.192 (Preetham's sky is flatter
      // than Hosek-Wilkie's and ours at T = 3..5), chromaticity up to 0.032, the glow
      // 3..15 deg from the sun 0.38..0.75 of the CIE clear sky's (whose circumsolar term,
      // from measured skies, is brighter than Hosek-Wilkie's and Preetham's).
      EXPECT_GT(c.Shape, 0.56) << turbidity << " " << elevation;
      EXPECT_LT(c.Shape, 1.25) << turbidity << " " << elevation;
      EXPECT_LT(std::abs(c.Dx), 0.035) << turbidity << " " << elevation;
      EXPECT_LT(std::abs(c.Dy), 0.035) << turbidity << " " << elevation;
      EXPECT_GT(c.CieGlow, 0.34) << turbidity << " " << elevation;
      EXPECT_LT(c.CieGlow, 0.8) << turbidity << " " << elevation;
    }
  }
  std::printf("  (* outside the goal) shape within 10 %%: %d of %d; chromaticity within 0.02: %d "
              "of %d\n",
    shapeWithin, cases, colourWithin, cases);
  // Measured 6 and 31 of 40: no fewer.
  EXPECT_GE(shapeWithin, 6);
  EXPECT_GE(colourWithin, 31);
}

// Validation against Hosek & Wilkie 2012 ("An Analytic Model for Full Spectral Sky-Dome
// Radiance", ACM TOG 31(4): fitted to path-traced spectral skies, with Preetham's
// turbidity and a ground albedo), evaluated by Blender's Cycles (the authors' CIE XYZ
// data set; measurements/hosek-wilkie-reference.py wrote the table), ground albedo 0.3 as
// ours, over sun elevations 1..90 deg and turbidities 2..5. Goal: medians of the
// normalised luminance ratio within 10 %, of the chromaticity differences within 0.02.
// Compared twice: with the same physics as Hosek-Wilkie (no ozone: their sky does not
// absorb in the Chappuis band; with ozone, ours is bluer at sunrise, as measured
// twilight skies are: OzoneKeepsTwilightBlue), and as the sky is built (300 DU).
TEST(Sky, ValidationAgainstHosekWilkie)
{
  const auto reference = ReadHosekWilkieReference();
  ASSERT_EQ(reference.size(), 40u) << "Data/hosek-wilkie-reference.csv";
  for (const double ozone : { 0.0, 300.0 })
  {
    int shapeWithin = 0, colourWithin = 0, cases = 0;
    std::printf("  ozone %.0f DU\n  T    sun | shape  glow3-15 max | median dx     dy | zenith "
                "dx  dy | Preetham/H-W shape\n",
      ozone);
    for (int turbidity : { 2, 3, 4, 5 })
    {
      SkyParameters p;
      p.Atmosphere = nimbus::ClearSkyAtmosphere(turbidity);
      p.Atmosphere.OzoneDobsonUnits = ozone;
      const SkyModel model(p);
      for (int elevation : { 1, 2, 5, 10, 20, 30, 45, 60, 75, 90 })
      {
        const auto found = reference.find({ turbidity, elevation });
        ASSERT_NE(found, reference.end()) << turbidity << " " << elevation;
        const SkyComparison c = CompareSky(model, turbidity, elevation, found->second);
        const double published = PublishedShapeRatio(turbidity, elevation, found->second);
        const bool shapeOk = std::abs(c.Shape - 1.0) <= 0.10;
        const bool colourOk = std::abs(c.Dx) <= 0.02 && std::abs(c.Dy) <= 0.02;
        shapeWithin += shapeOk ? 1 : 0;
        colourWithin += colourOk ? 1 : 0;
        ++cases;
        std::printf("  %d %6d | %.3f%s %.2f %.2f | %+.4f %+.4f%s | %+.4f %+.4f | %.3f\n", turbidity,
          elevation, c.Shape, shapeOk ? " " : "*", c.Glow, c.MaxRatio, c.Dx, c.Dy,
          colourOk ? " " : "*", c.ZenithDx, c.ZenithDy, published);
        // The two published models' shapes (measured 0.886..1.695).
        EXPECT_GT(published, 0.85);
        EXPECT_LT(published, 1.75);
        // The goal, in every case.
        EXPECT_TRUE(shapeOk) << "ozone " << ozone << ", T " << turbidity << ", sun " << elevation;
        if (ozone == 0.0 || elevation >= 5)
        {
          EXPECT_TRUE(colourOk) << "ozone " << ozone << ", T " << turbidity << ", sun "
                                << elevation;
        }
        else
        {
          // Ozone's blue at sunrise: ours bluer (y lower), measured -0.024..-0.040.
          EXPECT_LT(c.Dy, -0.02) << "T " << turbidity << ", sun " << elevation;
          EXPECT_GT(c.Dy, -0.045) << "T " << turbidity << ", sun " << elevation;
        }
        // The glow 3..15 deg from the sun, median ratio: measured 0.72..1.28.
        EXPECT_GT(c.Glow, 0.65) << turbidity << " " << elevation;
        EXPECT_LT(c.Glow, 1.4) << turbidity << " " << elevation;
      }
    }
    std::printf("  (* outside the goal) shape within 10 %%: %d of %d; chromaticity within 0.02: "
                "%d of %d\n",
      shapeWithin, cases, colourWithin, cases);
  }
}

// The haze knob at the ends of its range and bad values: finite skies from the zenith
// sun to below the horizon, clear errors for NaN and out-of-range turbidities.
TEST(Sky, TurbidityRange)
{
  for (double turbidity : { nimbus::kMinTurbidity, nimbus::kMaxTurbidity })
  {
    SkyParameters p;
    p.Atmosphere = nimbus::ClearSkyAtmosphere(turbidity);
    p.TransmittanceMuSize = 64; // coarse tables: stability, not accuracy
    p.TransmittanceRSize = 16;
    p.ScatteringMuSSize = 16;
    p.ScatteringRSize = 8;
    const SkyModel model(p);
    for (double elevation : { 90.0, 45.0, 1.0, 0.0, -1.0, -10.0 })
    {
      const Vector3 s = Direction(elevation, 0.0);
      const SkyViewLut lut(model, elevation, 0.0, 32, 16, 8);
      for (const Vector3& w : { Vector3{ { 0, 0, 1 } }, Direction(0.0, 0.0), Direction(0.5, 0.0),
             Direction(-0.5, 90.0), Direction(elevation, 0.0), Vector3{ { 0, 0, -1 } } })
      {
        const Rgb direct = model.Radiance(0.0, w, s);
        const Rgb table = lut.Radiance(w, 0.0);
        EXPECT_TRUE(Finite(direct) && Finite(table)) << turbidity << " " << elevation;
        EXPECT_GE(Y(direct), 0.0);
        EXPECT_GE(Y(table), 0.0);
      }
    }
  }
  const double nan = std::nan("");
  for (double bad : { nan, 0.5, 10.5, -3.0, std::numeric_limits<double>::infinity() })
  {
    EXPECT_THROW(nimbus::ClearSkyAtmosphere(bad), std::invalid_argument) << bad;
  }
  EXPECT_THROW(nimbus::PreethamSky(nan, 0.5), std::invalid_argument);
  EXPECT_THROW(nimbus::PreethamSky(3.0, 2.0), std::invalid_argument);
  SkyParameters bad;
  bad.Atmosphere.OzoneDobsonUnits = nan;
  EXPECT_THROW(SkyModel{ bad }, std::invalid_argument);
  bad = SkyParameters();
  bad.Atmosphere.MieAngstromExponent = 9.0;
  EXPECT_THROW(SkyModel{ bad }, std::invalid_argument);
}

// Ozone keeps the twilight zenith blue (its Chappuis band absorbs orange-red light on
// the long sunlit paths of twilight; Hulburt 1953): zenith B/R with and without ozone.
TEST(Sky, OzoneKeepsTwilightBlue)
{
  const SkyModel& withOzone = nimbus::testing::FullSkyModel();
  SkyParameters p;
  p.Atmosphere.OzoneDobsonUnits = 0.0;
  const SkyModel withoutOzone(p);
  for (double elevation : { 10.0, 0.0, -4.0 })
  {
    const Vector3 s = Direction(elevation, 0.0);
    const Rgb a = withOzone.Radiance(0.0, { { 0, 0, 1 } }, s);
    const Rgb b = withoutOzone.Radiance(0.0, { { 0, 0, 1 } }, s);
    std::printf("  sun %5.1f deg: zenith B/R with ozone %.2f, without %.2f\n", elevation,
      a[2] / a[0], b[2] / b[0]);
    EXPECT_GT(a[2] / a[0], b[2] / b[0]);
    if (elevation <= -4.0)
    {
      // Measured 3.11 with 300 DU and 0.98 without.
      EXPECT_GT(a[2] / a[0], 2.5);
      EXPECT_LT(b[2] / b[0], 1.2);
    }
  }
}
