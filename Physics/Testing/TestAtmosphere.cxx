// Tests for Atmosphere.h: optical lengths against closed forms and brute-force
// integrals, horizon / ground / top-of-atmosphere edge cases.
#include "Atmosphere.h"
#include "Math.h"
#include "PhaseFunctions.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

namespace
{
using V = nimbus::Atmosphere::Vector3;
using nimbus::kPi;
constexpr double R = 6360000.0;
constexpr double Rtop = 6420000.0;

double Deg(double d)
{
  return d * kPi / 180.0;
}

// Point at altitude h above the "north pole" and a unit direction with the given
// elevation (angle above the local horizontal) in the x-z plane.
V At(double h)
{
  return { 0.0, 0.0, R + h };
}
V Elevation(double degrees)
{
  return { std::cos(Deg(degrees)), 0.0, std::sin(Deg(degrees)) };
}

// Independent brute force: distance from p (inside the atmosphere) along unit d
// to the top sphere, and the midpoint rule with n steps of exp(-(|p + s d| - R)/H).
double ExitDistance(const V& p, const V& d, double radius)
{
  const double b = p[0] * d[0] + p[1] * d[1] + p[2] * d[2];
  const double c = p[0] * p[0] + p[1] * p[1] + p[2] * p[2] - radius * radius;
  return -b + std::sqrt(b * b - c);
}
double MidpointLength(const V& p, const V& d, double s0, double s1, double H, long n)
{
  const double ds = (s1 - s0) / static_cast<double>(n);
  double sum = 0.0;
  for (long i = 0; i < n; ++i)
  {
    const double s = s0 + (static_cast<double>(i) + 0.5) * ds;
    const double x = p[0] + s * d[0], y = p[1] + s * d[1], z = p[2] + s * d[2];
    sum += std::exp(-(std::sqrt(x * x + y * y + z * z) - R) / H);
  }
  return sum * ds;
}

bool Finite(const nimbus::OpticalLengths& l)
{
  return std::isfinite(l.RayleighLengthMetres) && std::isfinite(l.MieLengthMetres) &&
    l.RayleighLengthMetres >= 0.0 && l.MieLengthMetres >= 0.0;
}
} // namespace

TEST(Atmosphere, DefaultParameters)
{
  const nimbus::Atmosphere atm;
  const nimbus::AtmosphereParameters& p = atm.GetParameters();
  EXPECT_EQ(p.EarthRadiusMetres, 6360000.0);
  EXPECT_EQ(p.TopRadiusMetres, 6420000.0);
  EXPECT_EQ(p.RayleighScaleHeightMetres, 8000.0);
  EXPECT_EQ(p.MieScaleHeightMetres, 1200.0);
  // Nishita / Bruneton beta_R: 5.8e-6, 13.5e-6, 33.1e-6 1/m at 680, 550, 440 nm.
  EXPECT_NEAR(atm.RayleighScattering(680.0), 5.8e-6, 0.01 * 5.8e-6);
  EXPECT_DOUBLE_EQ(atm.RayleighScattering(550.0), 13.5e-6);
  EXPECT_NEAR(atm.RayleighScattering(440.0), 33.1e-6, 0.01 * 33.1e-6);
  EXPECT_DOUBLE_EQ(atm.MieScattering(440.0), 2.0e-5);
  EXPECT_DOUBLE_EQ(atm.MieExtinction(440.0), 2.0e-5 / 0.9);
  EXPECT_GT(atm.MiePhase(1.0), atm.MiePhase(0.0)); // forward peak, g = 0.76
  EXPECT_NEAR(atm.Altitude(At(1234.5)), 1234.5, 1e-9);
  EXPECT_DOUBLE_EQ(atm.Density(0.0, 8000.0), 1.0);
  EXPECT_DOUBLE_EQ(atm.Density(-10.0, 8000.0), 1.0);
  EXPECT_EQ(atm.Density(60001.0, 8000.0), 0.0);
}

TEST(Atmosphere, VerticalMatchesClosedForm)
{
  const nimbus::Atmosphere atm;
  double worst = 0.0;
  for (double H : { 8000.0, 1200.0, 300.0, 25000.0 })
  {
    for (double h : { 1.0, 100.0, 1000.0, 5000.0, 20000.0, 59999.0 })
    {
      const double exact = H * -std::expm1(-h / H); // H (1 - e^{-h/H})
      const double L = atm.OpticalLength(At(0.0), At(h), H);
      const double Lrev = atm.OpticalLength(At(h), At(0.0), H);
      EXPECT_NEAR(L, exact, 1e-9 * exact) << "H=" << H << " h=" << h;
      EXPECT_NEAR(Lrev, exact, 1e-9 * exact) << "H=" << H << " h=" << h;
      worst = std::max(worst, std::abs(L / exact - 1.0));
    }
  }
  // Beyond the top the density is 0: ground -> 100 km equals ground -> top.
  EXPECT_NEAR(atm.OpticalLength(At(0.0), At(100000.0), 8000.0), 8000.0 * -std::expm1(-7.5), 1e-6);
  std::printf("vertical closed form: max relative error %.2e\n", worst);
}

TEST(Atmosphere, SlantPathsMatchBruteForce)
{
  const nimbus::Atmosphere atm;
  const long n = 2000000;
  double worst = 0.0;
  for (double H : { 8000.0, 1200.0 })
  {
    for (double elevation : { 90.0, 30.0, 5.0, 1.0, 0.0, -0.5 })
    {
      const V p = At(1000.0);
      const V d = Elevation(elevation);
      const nimbus::OpticalLengths l = atm.OpticalLengthsToTop(p, d);
      ASSERT_FALSE(l.HitsGround) << elevation; // horizon dip from 1 km is 1.01 deg
      const double L = H == 8000.0 ? l.RayleighLengthMetres : l.MieLengthMetres;
      const double ref = MidpointLength(p, d, 0.0, ExitDistance(p, d, Rtop), H, n);
      const double rel = std::abs(L / ref - 1.0);
      std::printf("H=%5.0f elevation %5.1f deg: L = %.9e m, brute force %.9e m, rel.err %.1e\n", H,
        elevation, L, ref, rel);
      EXPECT_LT(rel, 1e-6);
      worst = std::max(worst, rel);
    }
  }
  // Ground observer, exactly horizontal ray (grazing, not blocked).
  for (double H : { 8000.0, 1200.0 })
  {
    const nimbus::OpticalLengths l = atm.OpticalLengthsToTop(At(0.0), { 1.0, 0.0, 0.0 });
    EXPECT_FALSE(l.HitsGround);
    const double L = H == 8000.0 ? l.RayleighLengthMetres : l.MieLengthMetres;
    const V d = { 1.0, 0.0, 0.0 };
    const double ref = MidpointLength(At(0.0), d, 0.0, ExitDistance(At(0.0), d, Rtop), H, n);
    EXPECT_LT(std::abs(L / ref - 1.0), 1e-6) << H;
    worst = std::max(worst, std::abs(L / ref - 1.0));
  }
  std::printf("slant paths: max relative error vs 2e6-step midpoint %.2e\n", worst);
}

TEST(Atmosphere, NearHorizonFiniteAndMonotone)
{
  const nimbus::Atmosphere atm;
  for (double h : { 0.0, 1000.0 })
  {
    double previousR = std::numeric_limits<double>::infinity();
    double previousM = previousR;
    const double lowest = h > 0.0 ? -1.0 : 0.0; // dip of the horizon from 1 km: 1.014 deg
    for (double e = lowest; e <= 3.0 + 1e-12; e += 0.01)
    {
      const nimbus::OpticalLengths l = atm.OpticalLengthsToTop(At(h), Elevation(e));
      ASSERT_TRUE(Finite(l)) << e;
      ASSERT_FALSE(l.HitsGround) << e;
      EXPECT_LT(l.RayleighLengthMetres, previousR) << "h=" << h << " e=" << e;
      EXPECT_LT(l.MieLengthMetres, previousM) << "h=" << h << " e=" << e;
      previousR = l.RayleighLengthMetres;
      previousM = l.MieLengthMetres;
    }
  }
}

TEST(Atmosphere, BelowHorizonHitsGround)
{
  const nimbus::Atmosphere atm;
  // From the ground any downward ray is blocked immediately.
  for (double e : { -1e-9, -0.1, -0.5, -10.0, -90.0 })
  {
    const nimbus::OpticalLengths l = atm.OpticalLengthsToTop(At(0.0), Elevation(e));
    EXPECT_TRUE(l.HitsGround) << e;
    EXPECT_TRUE(Finite(l));
    EXPECT_EQ(atm.Transmittance(l, 550.0), 0.0);
    EXPECT_EQ(atm.TransmittanceToTop(At(0.0), Elevation(e), 550.0), 0.0);
  }
  // From 1 km, 5 deg down: integrated up to the ground hit only.
  const V p = At(1000.0);
  const V d = Elevation(-5.0);
  const nimbus::OpticalLengths l = atm.OpticalLengthsToTop(p, d);
  EXPECT_TRUE(l.HitsGround);
  const double b = p[2] * d[2];
  const double sHit = -b - std::sqrt(b * b - (p[2] * p[2] - R * R));
  const V ground = { sHit * d[0], 0.0, p[2] + sHit * d[2] };
  EXPECT_NEAR(
    l.RayleighLengthMetres, atm.OpticalLength(p, ground, 8000.0), 1e-9 * l.RayleighLengthMetres);
  EXPECT_NEAR(l.MieLengthMetres, atm.OpticalLength(p, ground, 1200.0), 1e-9 * l.MieLengthMetres);
  EXPECT_EQ(atm.Transmittance(l, 680.0), 0.0);
  // Just beyond the horizon dip (1.0141 deg) the ray hits; just above it, it does not.
  const double dip = std::acos(R / (R + 1000.0)) * 180.0 / kPi;
  EXPECT_TRUE(atm.OpticalLengthsToTop(p, Elevation(-dip - 1e-4)).HitsGround);
  EXPECT_FALSE(atm.OpticalLengthsToTop(p, Elevation(-dip + 1e-4)).HitsGround);
}

TEST(Atmosphere, ZenithSun)
{
  const nimbus::Atmosphere atm;
  const nimbus::OpticalLengths l = atm.OpticalLengthsToTop(At(0.0), { 0.0, 0.0, 1.0 });
  const double LR = 8000.0 * -std::expm1(-60000.0 / 8000.0);
  const double LM = 1200.0 * -std::expm1(-60000.0 / 1200.0);
  EXPECT_NEAR(l.RayleighLengthMetres, LR, 1e-9 * LR);
  EXPECT_NEAR(l.MieLengthMetres, LM, 1e-9 * LM);
  for (double lambda : { 440.0, 550.0, 680.0 })
  {
    const double tau = atm.RayleighScattering(lambda) * LR + 2.0e-5 / 0.9 * LM;
    EXPECT_NEAR(atm.OpticalDepth(l, lambda), tau, 1e-12);
    EXPECT_NEAR(atm.TransmittanceToTop(At(0.0), { 0.0, 0.0, 5.0 }, lambda), std::exp(-tau), 1e-12);
  }
  // Sea-level vertical transmittance at 550 nm: tau = 0.1079 + 0.0267.
  std::printf("zenith transmittance 440/550/680 nm: %.4f %.4f %.4f\n", atm.Transmittance(l, 440.0),
    atm.Transmittance(l, 550.0), atm.Transmittance(l, 680.0));
}

TEST(Atmosphere, TopOfAtmosphereStart)
{
  const nimbus::Atmosphere atm;
  const V top = At(60000.0);
  const nimbus::OpticalLengths up = atm.OpticalLengthsToTop(top, { 0.0, 0.0, 1.0 });
  EXPECT_EQ(up.RayleighLengthMetres, 0.0);
  EXPECT_EQ(up.MieLengthMetres, 0.0);
  EXPECT_FALSE(up.HitsGround);
  EXPECT_EQ(atm.Transmittance(up, 550.0), 1.0);
  const nimbus::OpticalLengths flat = atm.OpticalLengthsToTop(top, { 1.0, 0.0, 0.0 });
  EXPECT_TRUE(Finite(flat));
  EXPECT_EQ(flat.RayleighLengthMetres, 0.0); // tangent to the top sphere
  // 5 deg down from the top: passes above the 7.8 deg horizon dip.
  const V d = Elevation(-5.0);
  const nimbus::OpticalLengths l = atm.OpticalLengthsToTop(top, d);
  EXPECT_FALSE(l.HitsGround);
  const double ref = MidpointLength(top, d, 0.0, ExitDistance(top, d, Rtop), 8000.0, 2000000);
  EXPECT_NEAR(l.RayleighLengthMetres, ref, 1e-6 * ref);
  // 30 deg down hits the ground.
  const nimbus::OpticalLengths down = atm.OpticalLengthsToTop(top, Elevation(-30.0));
  EXPECT_TRUE(down.HitsGround);
  EXPECT_TRUE(Finite(down));
  EXPECT_GT(down.RayleighLengthMetres, 0.0);
}

TEST(Atmosphere, ObserverAboveAtmosphere)
{
  const nimbus::Atmosphere atm;
  const V p = At(200000.0);
  // Looking away or missing the atmosphere: zero length, transmittance 1.
  for (const V& d : { V{ 0.0, 0.0, 1.0 }, V{ 1.0, 0.0, 0.0 }, V{ 1.0, 0.0, -0.1 } })
  {
    const nimbus::OpticalLengths l = atm.OpticalLengthsToTop(p, d);
    EXPECT_EQ(l.RayleighLengthMetres, 0.0);
    EXPECT_EQ(l.MieLengthMetres, 0.0);
    EXPECT_FALSE(l.HitsGround);
  }
  // Straight down: the full vertical column, then the ground.
  const nimbus::OpticalLengths down = atm.OpticalLengthsToTop(p, { 0.0, 0.0, -1.0 });
  EXPECT_TRUE(down.HitsGround);
  const double LR = 8000.0 * -std::expm1(-60000.0 / 8000.0);
  EXPECT_NEAR(down.RayleighLengthMetres, LR, 1e-9 * LR);
  // Limb ray with tangent altitude 20 km: through the atmosphere and out again.
  const double rt = R + 20000.0;
  const double pr = R + 200000.0;
  const double sinA = rt / pr; // angle between -p and d
  const V d = { sinA, 0.0, -std::sqrt(1.0 - sinA * sinA) };
  const nimbus::OpticalLengths limb = atm.OpticalLengthsToTop(p, d);
  EXPECT_FALSE(limb.HitsGround);
  // Brute force over the chord through the top sphere.
  const double b = p[2] * d[2];
  const double disc = b * b - (pr * pr - Rtop * Rtop);
  const double ref =
    MidpointLength(p, d, -b - std::sqrt(disc), -b + std::sqrt(disc), 8000.0, 2000000);
  EXPECT_NEAR(limb.RayleighLengthMetres, ref, 1e-6 * ref);
  std::printf("limb ray (tangent altitude 20 km): L_R = %.6e m, brute force %.6e m\n",
    limb.RayleighLengthMetres, ref);
}

TEST(Atmosphere, PointBelowGroundIsClamped)
{
  const nimbus::Atmosphere atm;
  const nimbus::OpticalLengths a = atm.OpticalLengthsToTop(At(-100.0), Elevation(20.0));
  const nimbus::OpticalLengths b = atm.OpticalLengthsToTop(At(0.0), Elevation(20.0));
  EXPECT_NEAR(a.RayleighLengthMetres, b.RayleighLengthMetres, 1e-9 * b.RayleighLengthMetres);
  EXPECT_NEAR(a.MieLengthMetres, b.MieLengthMetres, 1e-9 * b.MieLengthMetres);
  const nimbus::OpticalLengths c = atm.OpticalLengthsToTop({ 0.0, 0.0, 0.0 }, { 0.0, 1.0, 0.0 });
  EXPECT_TRUE(Finite(c));
  EXPECT_NEAR(c.RayleighLengthMetres, 8000.0 * -std::expm1(-7.5), 1e-6);
  const nimbus::OpticalLengths e = atm.OpticalLengthsToTop(At(-100.0), Elevation(0.0));
  EXPECT_TRUE(Finite(e));
  EXPECT_FALSE(e.HitsGround);
}

TEST(Atmosphere, InvalidInput)
{
  const nimbus::Atmosphere atm;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(atm.OpticalLengthsToTop(At(0.0), { 0.0, 0.0, 0.0 }), std::invalid_argument);
  EXPECT_THROW(atm.OpticalLengthsToTop(At(0.0), { nan, 0.0, 1.0 }), std::invalid_argument);
  EXPECT_THROW(atm.OpticalLengthsToTop({ nan, 0.0, R }, { 0.0, 0.0, 1.0 }), std::invalid_argument);
  EXPECT_THROW(atm.OpticalLength(At(0.0), At(10.0), 0.0), std::invalid_argument);
  EXPECT_EQ(atm.OpticalLength(At(10.0), At(10.0), 8000.0), 0.0);
  nimbus::AtmosphereParameters bad;
  bad.TopRadiusMetres = bad.EarthRadiusMetres;
  EXPECT_THROW(nimbus::Atmosphere{ bad }, std::invalid_argument);
}

TEST(Atmosphere, SegmentSymmetricAndAdditive)
{
  const nimbus::Atmosphere atm;
  const V a = At(500.0);
  const V b = { 300000.0, 0.0, R + 2000.0 };
  const double ab = atm.OpticalLength(a, b, 1200.0);
  EXPECT_NEAR(ab, atm.OpticalLength(b, a, 1200.0), 1e-10 * ab);
  const V mid = { 0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1]), 0.5 * (a[2] + b[2]) };
  EXPECT_NEAR(
    ab, atm.OpticalLength(a, mid, 1200.0) + atm.OpticalLength(mid, b, 1200.0), 1e-10 * ab);
  const double T = atm.TransmittanceBetween(a, b, 550.0);
  EXPECT_GT(T, 0.0);
  EXPECT_LT(T, 1.0);
}

// The GPU mapper's closed-form view optical length (flat layers, FlatLayerOpticalLength;
// its GLSL twin is checked by TestShaderTwins) against the spherical earth's exact one:
// the approximation error over cloud-scene paths, up to 30 km long, from the ground to
// 5 km, at every elevation down to 2 degrees. Vertical paths are exact in both.
TEST(Atmosphere, FlatLayerOpticalLengthAgainstSphericalEarth)
{
  const nimbus::Atmosphere atm;
  EXPECT_DOUBLE_EQ(nimbus::FlatLayerOpticalLength(0.0, 1.0, 1000.0, 8000.0),
    8000.0 * (1.0 - std::exp(-1000.0 / 8000.0)));
  double worst = 0.0;
  for (double scaleHeight : { 1200.0, 8000.0 })
  {
    for (double altitude : { 0.0, 1000.0, 5000.0 })
    {
      for (double elevation : { 2.0, 5.0, 15.0, 45.0, 90.0, -5.0, -45.0 })
      {
        for (double distance : { 100.0, 3000.0, 10000.0, 30000.0 })
        {
          const double c = std::cos(Deg(elevation)), s = std::sin(Deg(elevation));
          if (altitude + distance * s < 0.0)
          {
            continue; // below the ground
          }
          const V start = At(altitude);
          const V end = { distance * c, 0.0, start[2] + distance * s };
          const double exact = atm.OpticalLength(start, end, scaleHeight);
          const double flat = nimbus::FlatLayerOpticalLength(altitude, s, distance, scaleHeight);
          worst = std::max(worst, std::abs(flat - exact) / exact);
        }
      }
    }
  }
  std::printf("flat-layer optical length against the spherical earth: worst relative "
              "error %.3g (paths up to 30 km, elevations down to 2 deg)\n",
    worst);
  EXPECT_LT(worst, 0.05); // measured 3.0e-2, the longest path at the lowest elevation
}

// Below sea level the density is the sea level's (Atmosphere::Density): the closed
// form splits the path at h = 0. Against a fine midpoint sum of the clamped profile,
// for eyes below and above sea level, rays up, down and level.
TEST(Atmosphere, FlatLayerOpticalLengthBelowSeaLevel)
{
  double worst = 0.0;
  for (double altitude : { -3000.0, -500.0, -1.0, 0.0, 300.0, 2000.0 })
  {
    for (double cosZenith : { -1.0, -0.3, -0.01, -1e-7, 0.0, 1e-7, 0.01, 0.3, 1.0 })
    {
      for (double distance : { 50.0, 2000.0, 20000.0 })
      {
        const double scaleHeight = 1200.0;
        const int n = 200000;
        double sum = 0.0;
        for (int i = 0; i < n; ++i)
        {
          const double h = altitude + (i + 0.5) * distance / n * cosZenith;
          sum += std::exp(-std::max(h, 0.0) / scaleHeight) * distance / n;
        }
        const double flat =
          nimbus::FlatLayerOpticalLength(altitude, cosZenith, distance, scaleHeight);
        ASSERT_TRUE(std::isfinite(flat));
        worst = std::max(worst, std::abs(flat - sum) / sum);
      }
    }
  }
  EXPECT_LT(worst, 1e-6); // the midpoint sum's own error at the kink: < 1e-7
  // Entirely below sea level: the length itself.
  EXPECT_DOUBLE_EQ(nimbus::FlatLayerOpticalLength(-100.0, -0.5, 700.0, 8000.0), 700.0);
}

// Angstrom exponent, ozone and turbidity (Atmosphere.h): the published relations.
TEST(Atmosphere, AngstromOzoneAndTurbidity)
{
  nimbus::AtmosphereParameters p;
  p.MieAngstromExponent = 1.3;
  p.OzoneDobsonUnits = 300.0;
  const nimbus::Atmosphere air(p);
  // Angstrom 1929: beta_M(lambda) = beta_M(550) (550 / lambda)^alpha.
  EXPECT_DOUBLE_EQ(air.MieScattering(550.0), p.MieScatteringPerMetre);
  EXPECT_NEAR(air.MieScattering(440.0) / air.MieScattering(550.0), std::pow(1.25, 1.3), 1e-12);
  EXPECT_NEAR(air.MieExtinction(700.0), air.MieScattering(700.0) / p.MieAlbedo, 1e-18);
  // Ozone: Chappuis peak about 5e-25 m^2 near 600 nm, a thousand times less at 400 nm.
  EXPECT_NEAR(nimbus::OzoneCrossSection(605.0), 5.019e-25, 1e-30);
  EXPECT_LT(nimbus::OzoneCrossSection(400.0), 1e-26);
  EXPECT_GT(nimbus::OzoneCrossSection(600.0), 4e-25);
  // The vertical column is the Dobson amount: tau_O3 = DU 2.687e20 sigma (the
  // profile's column is 15 km of the peak density).
  const double R = p.EarthRadiusMetres;
  const nimbus::OpticalLengths up =
    air.OpticalLengthsToTop({ { 0.0, 0.0, R } }, { { 0.0, 0.0, 1.0 } });
  EXPECT_NEAR(up.OzoneLengthMetres, 15000.0, 1e-6);
  const double tauO3 = air.OzoneAbsorption(600.0) * up.OzoneLengthMetres;
  EXPECT_NEAR(tauO3, 300.0 * 2.687e20 * nimbus::OzoneCrossSection(600.0), 1e-9);
  std::printf("  ozone 300 DU: vertical optical depth %.4f at 600 nm, %.5f at 450 nm\n", tauO3,
    air.OzoneAbsorption(450.0) * up.OzoneLengthMetres);
  EXPECT_GT(tauO3, 0.03); // about 0.04 (Chappuis band)
  EXPECT_LT(tauO3, 0.05);
  // Transmittance includes the ozone.
  nimbus::AtmosphereParameters noOzone = p;
  noOzone.OzoneDobsonUnits = 0.0;
  const nimbus::Atmosphere clean(noOzone);
  EXPECT_NEAR(
    air.Transmittance(up, 600.0) / clean.Transmittance(up, 600.0), std::exp(-tauO3), 1e-12);
  EXPECT_EQ(clean.OzoneDensity(25000.0), 0.0);
  EXPECT_DOUBLE_EQ(air.OzoneDensity(25000.0), 1.0);
  EXPECT_DOUBLE_EQ(air.OzoneDensity(5000.0), 0.0);
  // The vertical aerosol optical depth of the atmosphere at 550 nm is
  // kAerosolOpticalDepthPerTurbidity (T - 1) (0.025 (T - 1): Atmosphere.h).
  for (double turbidity : { 1.0, 2.0, 2.5, 5.0, 10.0 })
  {
    const nimbus::AtmosphereParameters a = nimbus::ClearSkyAtmosphere(turbidity);
    const nimbus::Atmosphere hazy(a);
    const nimbus::OpticalLengths column =
      hazy.OpticalLengthsToTop({ { 0.0, 0.0, R } }, { { 0.0, 0.0, 1.0 } });
    const double aod = hazy.MieExtinction(550.0) * column.MieLengthMetres;
    EXPECT_NEAR(aod, 0.025 * (turbidity - 1.0), 1e-9 + 1e-9 * aod) << turbidity;
    EXPECT_NEAR(nimbus::TurbidityFromMieScattering(a.MieScatteringPerMetre, a), turbidity, 1e-9);
    EXPECT_NEAR(nimbus::CornetteShanksMeanCosine(a.MieG), 0.70, 1e-9);
  }
  EXPECT_THROW(nimbus::ClearSkyAtmosphere(std::nan("")), std::invalid_argument);
  EXPECT_THROW(nimbus::MieScatteringFromTurbidity(0.5, p), std::invalid_argument);
  EXPECT_THROW(nimbus::TurbidityFromMieScattering(-1.0, p), std::invalid_argument);
  nimbus::AtmosphereParameters bad = p;
  bad.OzoneDobsonUnits = -1.0;
  EXPECT_THROW(nimbus::Atmosphere{ bad }, std::invalid_argument);
}
