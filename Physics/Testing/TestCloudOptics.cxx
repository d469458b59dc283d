// What the values of a density array mean (CloudOptics.h): hand computations, the 1976
// standard atmosphere's tables, Fu (1996)'s ice law, the one-click estimate, validation
// and the extremes.
#include "CloudOptics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

namespace
{

using nimbus::CloudOpticsParameters;
using nimbus::DensityUnits;
using nimbus::DropletSize;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kPi = 3.14159265358979323846;

// Geometric altitude [m] of a geopotential height [m] (r0 = 6356.766 km).
double GeometricFromGeopotential(double h)
{
  const double r0 = 6356766.0;
  return r0 * h / (r0 - h);
}

TEST(CloudOptics, LiquidWaterContentOfTheCheck)
{
  // 3 LWC / (2 rho_w r_e) = 3 * 0.3e-3 kg/m^3 / (2 * 1000 kg/m^3 * 10e-6 m)
  //                      = 9e-4 / 0.02 = 0.045 /m  (45 per km).
  EXPECT_NEAR(nimbus::ExtinctionFromLiquidWaterContent(0.3, 10.0), 0.045, 1e-15);
  // Linear in the content, inverse in the radius: 1.5 LWC / r_e.
  EXPECT_NEAR(nimbus::ExtinctionFromLiquidWaterContent(1.0, 5.0), 0.3, 1e-15);
  CloudOpticsParameters p;
  p.Units = DensityUnits::LiquidWaterContent;
  p.EffectiveRadiusMicrometres = 10.0;
  EXPECT_NEAR(nimbus::ExtinctionPerMetre(p, 0.3, kNaN), 0.045, 1e-15);
}

TEST(CloudOptics, MixingRatioAtSeaLevelIsAContent)
{
  // q = 1 g/kg = 1e-3 kg/kg in air of 1.225 kg/m^3: LWC = 1000 g/kg * 1e-3 * 1.225
  // = 1.225 g/m^3, so sigma_t = 1.5 * 1.225 / 10 = 0.18375 /m.
  EXPECT_NEAR(nimbus::LiquidWaterContentFromMixingRatio(1e-3, 1.225), 1.225, 1e-15);
  CloudOpticsParameters q;
  q.Units = DensityUnits::LiquidWaterMixingRatio;
  CloudOpticsParameters lwc = q;
  lwc.Units = DensityUnits::LiquidWaterContent;
  EXPECT_NEAR(nimbus::ExtinctionPerMetre(q, 1e-3, 1.225), 0.18375, 1e-15);
  EXPECT_NEAR(
    nimbus::ExtinctionPerMetre(q, 1e-3, 1.225), nimbus::ExtinctionPerMetre(lwc, 1.225, 0.0), 1e-15);
  // The standard atmosphere's sea level is that air (1.2249992 kg/m^3 computed, 1.2250 printed).
  EXPECT_NEAR(
    nimbus::ExtinctionPerMetre(q, 1e-3, nimbus::StandardAtmosphereAirDensity(0.0)), 0.18375, 2e-7);
  // With a number concentration too (the same LWC, so the same extinction).
  q.Size = lwc.Size = DropletSize::NumberConcentration;
  EXPECT_NEAR(
    nimbus::ExtinctionPerMetre(q, 1e-3, 1.225), nimbus::ExtinctionPerMetre(lwc, 1.225, 0.0), 1e-15);
  // No air, or an unknown one: nothing.
  EXPECT_EQ(nimbus::ExtinctionPerMetre(q, 1e-3, 0.0), 0.0);
  EXPECT_EQ(nimbus::ExtinctionPerMetre(q, 1e-3, kNaN), 0.0);
}

TEST(CloudOptics, StandardAtmosphereTables)
{
  // U.S. Standard Atmosphere 1976, its table by geometric altitude (5 digits).
  struct Row
  {
    double Z, Rho;
  };
  const Row geometric[] = { { 0.0, 1.2250 }, { 1000.0, 1.1117 }, { 5000.0, 0.73643 },
    { 11000.0, 0.36480 }, { 20000.0, 0.088910 }, { -5000.0, 1.9311 }, { 86000.0, 6.958e-6 } };
  for (const Row& row : geometric)
  {
    EXPECT_NEAR(nimbus::StandardAtmosphereAirDensity(row.Z) / row.Rho, 1.0, 1e-4) << row.Z;
  }
  // The layer values 1.2250, 0.73612, 0.36391, 0.088035 kg/m^3 belong to the geopotential
  // heights 0, 5, 11 (tropopause) and 20 km, i.e. the geometric altitudes 0, 5003.9,
  // 11019.1 and 20063.1 m.
  const Row geopotential[] = { { 0.0, 1.2250 }, { 5000.0, 0.73612 }, { 11000.0, 0.36391 },
    { 20000.0, 0.088035 } };
  for (const Row& row : geopotential)
  {
    const double z = GeometricFromGeopotential(row.Z);
    EXPECT_NEAR(nimbus::StandardAtmosphereAirDensity(z) / row.Rho, 1.0, 1e-4) << row.Z;
  }
  EXPECT_NEAR(GeometricFromGeopotential(11000.0), 11019.07, 0.01);
  // Temperature and pressure at the tropopause (geopotential 11 km): 216.65 K, 22632 Pa.
  const nimbus::StandardAtmosphereState tropopause =
    nimbus::StandardAtmosphere(GeometricFromGeopotential(11000.0));
  EXPECT_NEAR(tropopause.TemperatureKelvin, 216.65, 1e-9);
  EXPECT_NEAR(tropopause.PressurePascals, 22632.06, 0.05);
  // Above 86 km the isothermal continuation, an approximation: the 1976 table has
  // 5.6044e-7 kg/m^3 at 100 km, the continuation 5.797e-7 (3.4 % more).
  EXPECT_NEAR(nimbus::StandardAtmosphereAirDensity(100000.0) / 5.6044e-7, 1.0343, 0.001);
}

TEST(CloudOptics, StandardAtmosphereIsHydrostaticAndContinuous)
{
  // dP/dZ = -rho g(Z), g(Z) = g0 (r0 / (r0 + Z))^2, by central differences.
  const double g0 = 9.80665, r0 = 6356766.0, step = 0.5;
  for (double z = -4000.0; z <= 85000.0; z += 1500.0)
  {
    const double dp = (nimbus::StandardAtmosphere(z + step).PressurePascals -
                        nimbus::StandardAtmosphere(z - step).PressurePascals) /
      (2.0 * step);
    const double g = g0 * (r0 / (r0 + z)) * (r0 / (r0 + z));
    EXPECT_NEAR(dp / (-nimbus::StandardAtmosphereAirDensity(z) * g), 1.0, 1e-6) << z;
  }
  // No jump at the layer bases (geopotential 11, 20, 32, 47, 51, 71 and 84.852 km).
  for (const double h : { 11000.0, 20000.0, 32000.0, 47000.0, 51000.0, 71000.0, 84852.0 })
  {
    const double z = GeometricFromGeopotential(h);
    const double below = nimbus::StandardAtmosphereAirDensity(z - 1e-3);
    const double above = nimbus::StandardAtmosphereAirDensity(z + 1e-3);
    EXPECT_NEAR(above / below, 1.0, 1e-6) << h;
  }
  // Held below -5 km; vanishing far up; NaN is sea level.
  EXPECT_EQ(
    nimbus::StandardAtmosphereAirDensity(-1e6), nimbus::StandardAtmosphereAirDensity(-5000.0));
  EXPECT_EQ(nimbus::StandardAtmosphereAirDensity(kInf), 0.0);
  EXPECT_EQ(
    nimbus::StandardAtmosphereAirDensity(-kInf), nimbus::StandardAtmosphereAirDensity(-5000.0));
  EXPECT_EQ(nimbus::StandardAtmosphereAirDensity(kNaN), 1.225);
  EXPECT_LT(nimbus::StandardAtmosphereAirDensity(1e7), 1e-300);
}

TEST(CloudOptics, EffectiveRadiusFromNumberRoundTrips)
{
  // LWC 0.3 g/m^3, N 100 /cm^3, k 0.8: r_e^3 = 3 * 3e-4 kg/m^3 / (4 pi 1000 kg/m^3 * 0.8 *
  // 1e8 /m^3) = 8.953e-16 m^3, r_e = 9.638 um.
  const double re = nimbus::EffectiveRadiusFromNumberConcentration(0.3, 100.0);
  EXPECT_NEAR(re, 9.637866, 1e-5);
  for (const double lwc : { 0.01, 0.3, 2.0 })
  {
    for (const double n : { 10.0, 100.0, 1000.0 })
    {
      const double r = nimbus::EffectiveRadiusFromNumberConcentration(lwc, n) * 1e-6; // m
      // Back: LWC = (4/3) pi k r_e^3 N rho_w [kg/m^3] -> g/m^3.
      const double back = 4.0 / 3.0 * kPi * 0.8 * r * r * r * n * 1e6 * 1000.0 * 1e3;
      EXPECT_NEAR(back / lwc, 1.0, 1e-12);
      // The extinction written without the radius agrees with the LWC formula.
      EXPECT_NEAR(nimbus::ExtinctionFromLiquidWaterContentAndNumber(lwc, n) /
          nimbus::ExtinctionFromLiquidWaterContent(lwc, r * 1e6),
        1.0, 1e-12);
    }
  }
  // Ten times the droplets, same water: radius / 10^(1/3).
  EXPECT_NEAR(
    nimbus::EffectiveRadiusFromNumberConcentration(0.3, 1000.0), re / std::cbrt(10.0), 1e-9);
  EXPECT_EQ(nimbus::EffectiveRadiusFromNumberConcentration(0.0, 100.0), 0.0);
  EXPECT_EQ(nimbus::EffectiveRadiusFromNumberConcentration(0.3, 0.0), 0.0);
}

TEST(CloudOptics, EveryUnitGivesItsCumulusExtinction)
{
  // A typical cumulus: LWC 0.3 g/m^3, r_e 10 um -> 0.045 /m.
  CloudOpticsParameters p;
  p.Units = DensityUnits::Dimensionless; // k 0.05 /m per unit: a value of 0.9
  EXPECT_NEAR(nimbus::ExtinctionPerMetre(p, 0.9, 0.0), 0.045, 1e-15);
  p.Units = DensityUnits::ExtinctionPerMetre;
  EXPECT_EQ(nimbus::ExtinctionPerMetre(p, 0.045, 0.0), 0.045);
  p.Units = DensityUnits::LiquidWaterContent;
  EXPECT_NEAR(nimbus::ExtinctionPerMetre(p, 0.3, 0.0), 0.045, 1e-15);
  // Mixing ratio at 1 km: rho_air 1.1117 kg/m^3, q = 0.3 / (1000 * 1.1117) = 2.6986e-4 kg/kg.
  p.Units = DensityUnits::LiquidWaterMixingRatio;
  const double air = nimbus::StandardAtmosphereAirDensity(1000.0);
  EXPECT_NEAR(air, 1.1117, 1e-4);
  EXPECT_NEAR(nimbus::ExtinctionPerMetre(p, 0.3 / (1000.0 * air), air), 0.045, 1e-15);
  // Number concentration giving r_e = 10 um: N = 3 LWC / (4 pi rho_w k r_e^3)
  // = 9e-4 / (4 pi 1000 * 0.8 * 1e-15) /m^3 = 89.52 /cm^3.
  p.Units = DensityUnits::LiquidWaterContent;
  p.Size = DropletSize::NumberConcentration;
  p.NumberConcentrationPerCubicCentimetre = 89.5246554891911;
  EXPECT_NEAR(nimbus::ExtinctionPerMetre(p, 0.3, 0.0), 0.045, 1e-12);
  // Ice of the same content and radius: 1.5e-3 * 0.3 / (917 * 10e-6) = 0.049073 /m;
  // a cirrus-like IWC 0.02 g/m^3, r_e 30 um: 1.0905e-3 /m.
  p.Units = DensityUnits::IceWaterContent;
  p.Size = DropletSize::NumberConcentration; // ice ignores it: always the radius
  EXPECT_NEAR(nimbus::ExtinctionPerMetre(p, 0.3, 0.0), 0.0490731, 1e-7);
  p.EffectiveRadiusMicrometres = 30.0;
  EXPECT_NEAR(nimbus::ExtinctionPerMetre(p, 0.02, 0.0), 1.09051e-3, 1e-8);
}

TEST(CloudOptics, IceAgreesWithFu1996VisibleBand)
{
  // Fu (1996) Eq. 3.9a, band 0.2-0.7 um: sigma_t = IWC (a0 + a1 / D_ge), D_ge = r_e / 0.64952.
  const double a0 = -2.9172062e-05, a1 = 2.5192544;
  for (const double re : { 5.0, 10.0, 20.0, 50.0, 70.0 })
  {
    const double fu = 0.1 * (a0 + a1 * 0.64952 / re);
    EXPECT_NEAR(nimbus::ExtinctionFromIceWaterContent(0.1, re) / fu, 1.0, 1e-3) << re;
  }
}

TEST(CloudOptics, EstimateOnASlab)
{
  // 2 x 2 columns (x fastest), 11 points 100 m apart along z. Column integrals by the
  // trapezoid rule:
  //   (0,0): 2 at k = 3..7, 0 around: 2 * 5 * 100 m = 1000
  //   (1,0): 1 at k = 3..7:               500
  //   (0,1): 4 at every k (ends count half): 4 * 10 * 100 m = 4000
  //   (1,1): empty, not counted.
  // Median of {500, 1000, 4000} = 1000, so k = 20 / 1000 = 0.02 /m per unit.
  const int nx = 2, ny = 2, nz = 11;
  std::vector<float> grid(nx * ny * nz, 0.0f);
  auto at = [&](int i, int j, int k) -> float& { return grid[i + nx * (j + ny * k)]; };
  for (int k = 0; k < nz; ++k)
  {
    if (k >= 3 && k <= 7)
    {
      at(0, 0, k) = 2.0f;
      at(1, 0, k) = 1.0f;
    }
    at(0, 1, k) = 4.0f;
  }
  const double k = nimbus::EstimateExtinctionPerDensity(grid.data(), nx, ny, nz, 100.0);
  EXPECT_NEAR(k, 0.02, 1e-15);
  EXPECT_NEAR(
    nimbus::EstimateExtinctionPerDensity(grid.data(), nx, ny, nz, 100.0, 10.0), 0.01, 1e-15);
  // Non-finite and negative values where the grid had nothing: unchanged.
  at(1, 1, 5) = std::numeric_limits<float>::quiet_NaN();
  at(1, 1, 6) = -3.0f;
  at(0, 0, 0) = std::numeric_limits<float>::quiet_NaN();
  at(1, 0, 10) = std::numeric_limits<float>::infinity();
  at(0, 0, 9) = -std::numeric_limits<float>::infinity();
  EXPECT_EQ(nimbus::EstimateExtinctionPerDensity(grid.data(), nx, ny, nz, 100.0), k);
  // A fourth column (2000) makes the count even: median (1000 + 2000) / 2, k = 20 / 1500.
  at(1, 1, 5) = 20.0f; // a tent of half-width 100 m: 20 * 100 m = 2000
  EXPECT_NEAR(
    nimbus::EstimateExtinctionPerDensity(grid.data(), nx, ny, nz, 100.0), 20.0 / 1500.0, 1e-15);
  // One column, 4 at every point: the trapezoid rule's 4 * 10 * 100 m = 4000 (not the
  // 4 * 11 * 100 m = 4400 of a plain sum: the field spans 1000 m), so k = 20 / 4000.
  std::vector<float> column(nz, 4.0f);
  EXPECT_NEAR(nimbus::EstimateExtinctionPerDensity(column.data(), 1, 1, nz, 100.0), 0.005, 1e-15);
  // Nothing to estimate from.
  std::vector<float> empty(nx * ny * nz, 0.0f);
  EXPECT_EQ(nimbus::EstimateExtinctionPerDensity(empty.data(), nx, ny, nz, 100.0), 0.0);
  EXPECT_EQ(nimbus::EstimateExtinctionPerDensity(grid.data(), nx, ny, 1, 100.0), 0.0);
  EXPECT_EQ(nimbus::EstimateExtinctionPerDensity(nullptr, nx, ny, nz, 100.0), 0.0);
  EXPECT_EQ(nimbus::EstimateExtinctionPerDensity(grid.data(), nx, ny, nz, kNaN), 0.0);
  EXPECT_EQ(nimbus::EstimateExtinctionPerDensity(grid.data(), nx, ny, nz, 100.0, -1.0), 0.0);
  // Tiny densities: clamped to what CheckCloudOptics accepts.
  std::vector<float> faint(nx * ny * nz, 1e-30f);
  EXPECT_EQ(nimbus::EstimateExtinctionPerDensity(faint.data(), nx, ny, nz, 1.0),
    nimbus::kMaxExtinctionPerDensity);
}

TEST(CloudOptics, CheckRefusesBadValues)
{
  CloudOpticsParameters p;
  EXPECT_EQ(nimbus::CheckCloudOptics(p), "");
  p.ExtinctionPerDensity = kNaN;
  EXPECT_NE(nimbus::CheckCloudOptics(p).find("extinction per density"), std::string::npos);
  p.ExtinctionPerDensity = -1.0;
  EXPECT_NE(nimbus::CheckCloudOptics(p).find("-1"), std::string::npos);
  p.ExtinctionPerDensity = 0.0; // an invisible cloud is allowed
  EXPECT_EQ(nimbus::CheckCloudOptics(p), "");

  p.Units = DensityUnits::LiquidWaterContent;
  p.EffectiveRadiusMicrometres = 0.0;
  EXPECT_NE(nimbus::CheckCloudOptics(p).find("effective radius"), std::string::npos);
  p.EffectiveRadiusMicrometres = kNaN;
  EXPECT_NE(nimbus::CheckCloudOptics(p).find("nan"), std::string::npos);
  p.EffectiveRadiusMicrometres = 2e4;
  EXPECT_NE(nimbus::CheckCloudOptics(p), "");
  p.EffectiveRadiusMicrometres = 10.0;
  EXPECT_EQ(nimbus::CheckCloudOptics(p), "");

  p.Units = DensityUnits::LiquidWaterMixingRatio;
  p.Size = DropletSize::NumberConcentration;
  p.NumberConcentrationPerCubicCentimetre = -5.0;
  EXPECT_NE(nimbus::CheckCloudOptics(p).find("number concentration"), std::string::npos);
  p.NumberConcentrationPerCubicCentimetre = kNaN;
  EXPECT_NE(nimbus::CheckCloudOptics(p), "");
  p.NumberConcentrationPerCubicCentimetre = 100.0;
  EXPECT_EQ(nimbus::CheckCloudOptics(p), "");

  p.Units = DensityUnits::IceWaterContent;
  p.EffectiveRadiusMicrometres = -1.0;
  EXPECT_NE(nimbus::CheckCloudOptics(p).find("effective radius"), std::string::npos);

  p.Units = static_cast<DensityUnits>(7);
  EXPECT_NE(nimbus::CheckCloudOptics(p).find("density units 7"), std::string::npos);
  p.Units = DensityUnits::LiquidWaterContent;
  p.Size = static_cast<DropletSize>(2);
  EXPECT_NE(nimbus::CheckCloudOptics(p).find("droplet size"), std::string::npos);
  // Refused parameters give no extinction.
  EXPECT_EQ(nimbus::ExtinctionPerMetre(p, 0.3, 1.0), 0.0);
}

TEST(CloudOptics, UnitsNames)
{
  for (int i = -1; i <= 5; ++i)
  {
    EXPECT_EQ(nimbus::IsDensityUnits(i), i >= 0 && i <= 4) << i;
  }
  EXPECT_EQ(static_cast<int>(DensityUnits::LiquidWaterMixingRatio), 3);
  EXPECT_EQ(
    nimbus::DensityUnitsName(DensityUnits::LiquidWaterContent), "liquid water content (g/m^3)");
  EXPECT_EQ(nimbus::DensityUnitsName(static_cast<DensityUnits>(9)), "unknown density units");
  EXPECT_TRUE(nimbus::IsDropletSize(1));
  EXPECT_FALSE(nimbus::IsDropletSize(2));
}

TEST(CloudOptics, ExtremesAreFiniteAndNonNegative)
{
  const double largestFloat = std::numeric_limits<float>::max();
  const double values[] = { 0.0, -1.0, -kInf, kInf, kNaN, 1e-320, 1e-30, 1.0, 1e30, 1e300,
    std::numeric_limits<double>::max() };
  const double airs[] = { kNaN, -1.0, 0.0, 1.225, 1e300 };
  for (int units = 0; units <= 4; ++units)
  {
    for (int size = 0; size <= 1; ++size)
    {
      for (const double radius : { 1e-6, 10.0, 1e4 })
      {
        CloudOpticsParameters p;
        p.Units = static_cast<DensityUnits>(units);
        p.Size = static_cast<DropletSize>(size);
        p.EffectiveRadiusMicrometres = radius;
        p.NumberConcentrationPerCubicCentimetre = radius; // 1e-6 .. 1e4 /cm^3
        p.ExtinctionPerDensity = radius < 1.0 ? 0.0 : 1e6;
        for (const double air : airs)
        {
          for (const double value : values)
          {
            const double sigma = nimbus::ExtinctionPerMetre(p, value, air);
            EXPECT_TRUE(std::isfinite(sigma) && sigma >= 0.0 && sigma <= largestFloat)
              << units << " " << size << " " << radius << " " << air << " " << value;
            if (!(value > 0.0) || std::isinf(value))
            {
              EXPECT_EQ(sigma, 0.0) << value; // NaN, Inf, 0 and negative values: nothing
            }
          }
        }
      }
    }
  }
  // The helpers themselves, at extreme arguments.
  for (const double a : { 0.0, -1.0, kNaN, kInf, 1e-320, 1e300 })
  {
    for (const double b : { 0.0, -1.0, kNaN, kInf, 1e-320, 1e-300, 1e300 })
    {
      for (const double x : { nimbus::ExtinctionFromLiquidWaterContent(a, b),
             nimbus::ExtinctionFromIceWaterContent(a, b),
             nimbus::EffectiveRadiusFromNumberConcentration(a, b),
             nimbus::ExtinctionFromLiquidWaterContentAndNumber(a, b),
             nimbus::LiquidWaterContentFromMixingRatio(a, b) })
      {
        EXPECT_TRUE(std::isfinite(x) && x >= 0.0) << a << " " << b << " " << x;
      }
    }
  }
}

} // namespace
