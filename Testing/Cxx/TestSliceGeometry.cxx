// Shadow-view-slice geometry (000 §4.2) and the atmosphere texture (000 §3), plain C++.
#include "AtmosphereTable.h"
#include "Sky.h"
#include "SliceGeometry.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

using nimbus::Vector3;

namespace
{
double Angle(const Vector3& a, const Vector3& b)
{
  return std::acos(
    std::clamp(nimbus::Dot(nimbus::Normalized(a), nimbus::Normalized(b)), -1.0, 1.0));
}
Vector3 Neg(const Vector3& v)
{
  return { { -v[0], -v[1], -v[2] } };
}
}

TEST(SliceGeometry, AngleRatioAndOrder)
{
  std::mt19937 rng(5);
  std::normal_distribution<double> n01;
  for (int i = 0; i < 2000; ++i)
  {
    const Vector3 v = nimbus::Normalized({ { n01(rng), n01(rng), n01(rng) } });
    const Vector3 l = nimbus::Normalized({ { n01(rng), n01(rng), n01(rng) } });
    for (double a : { 1.0, 1.5, 2.0 })
    {
      const nimbus::SliceAxis axis = nimbus::ComputeSliceAxis(v, l, a);
      ASSERT_NEAR(nimbus::Dot(axis.Normal, axis.Normal), 1.0, 1e-12);
      // Always moving away from the sun, so the shadow accumulates in order.
      ASSERT_GT(nimbus::Dot(axis.Normal, Neg(l)), 0.0);
      ASSERT_EQ(axis.BackToFront, nimbus::Dot(v, l) >= 0.0);
      const Vector3 e = axis.BackToFront ? Neg(v) : v;
      const double thetaE = Angle(axis.Normal, e), thetaS = Angle(axis.Normal, Neg(l));
      // theta_e : theta_s = 1 : a, and the normal lies between the two.
      ASSERT_NEAR(thetaS, a * thetaE, 1e-9);
      ASSERT_NEAR(thetaE + thetaS, Angle(e, Neg(l)), 1e-9);
      ASSERT_NEAR(axis.SunCosine, std::cos(thetaS), 1e-12);
      // Half-angle bound: theta_s <= 90 deg * a / (1 + a), so Delta s stays finite.
      ASSERT_LE(thetaS, M_PI / 2 * a / (1 + a) + 1e-12);
    }
  }
}

TEST(SliceGeometry, DegenerateViewAlongAndAgainstSun)
{
  const Vector3 l = nimbus::Normalized({ { 0.3, 0.4, 0.5 } });
  for (const Vector3& v : { l, Neg(l) })
  {
    for (double a : { 1.0, 2.0 })
    {
      const nimbus::SliceAxis axis = nimbus::ComputeSliceAxis(v, l, a);
      for (double c : axis.Normal)
      {
        ASSERT_TRUE(std::isfinite(c));
      }
      EXPECT_NEAR(nimbus::Dot(axis.Normal, Neg(l)), 1.0, 1e-12);
      EXPECT_NEAR(axis.SunCosine, 1.0, 1e-12);
    }
  }
  // View exactly perpendicular to the sun: 90 deg split 1:a.
  const nimbus::SliceAxis side = nimbus::ComputeSliceAxis({ { 1, 0, 0 } }, { { 0, 0, 1 } }, 1.0);
  EXPECT_NEAR(Angle(side.Normal, { { 0, 0, -1 } }), M_PI / 4, 1e-12);
  EXPECT_THROW(nimbus::ComputeSliceAxis({ { 0, 0, 0 } }, l, 1.0), std::invalid_argument);
  EXPECT_THROW(nimbus::ComputeSliceAxis(l, { { NAN, 0, 1 } }, 1.0), std::invalid_argument);
}

TEST(SliceGeometry, PlanesAndShadowFrame)
{
  std::vector<Vector3> corners;
  for (int c = 0; c < 8; ++c)
  {
    corners.push_back(
      { { (c & 1) ? 100.0 : -100.0, (c & 2) ? 50.0 : -50.0, (c & 4) ? 30.0 : 10.0 } });
  }
  const Vector3 n = nimbus::Normalized({ { 0, 0, 1 } });
  const auto range = nimbus::ProjectedRange(corners, n);
  EXPECT_DOUBLE_EQ(range[0], 10.0);
  EXPECT_DOUBLE_EQ(range[1], 30.0);
  const nimbus::SlicePlanes planes = nimbus::MakeSlicePlanes(range[0], range[1], 4);
  EXPECT_DOUBLE_EQ(planes.Spacing, 5.0);
  EXPECT_DOUBLE_EQ(planes.Offsets.front(), 12.5);
  EXPECT_DOUBLE_EQ(planes.Offsets.back(), 27.5);
  EXPECT_THROW(nimbus::MakeSlicePlanes(0, 1, 0), std::invalid_argument);

  const Vector3 l = nimbus::Normalized({ { 0.2, -0.5, 0.8 } });
  const nimbus::ShadowFrame frame = nimbus::ComputeShadowFrame(corners, l, 0.02);
  EXPECT_NEAR(nimbus::Dot(frame.U, frame.U), 1.0, 1e-12);
  EXPECT_NEAR(nimbus::Dot(frame.W, frame.W), 1.0, 1e-12);
  EXPECT_NEAR(nimbus::Dot(frame.U, frame.W), 0.0, 1e-12);
  EXPECT_NEAR(nimbus::Dot(frame.U, l), 0.0, 1e-12);
  EXPECT_NEAR(nimbus::Dot(frame.W, l), 0.0, 1e-12);
  for (const Vector3& corner : corners)
  {
    const Vector3 q = { { corner[0] - frame.Origin[0], corner[1] - frame.Origin[1],
      corner[2] - frame.Origin[2] } };
    const double s = nimbus::Dot(q, frame.U) / frame.Width,
                 t = nimbus::Dot(q, frame.W) / frame.Height;
    EXPECT_GT(s, 0.0);
    EXPECT_LT(s, 1.0);
    EXPECT_GT(t, 0.0);
    EXPECT_LT(t, 1.0);
  }
}

TEST(AtmosphereTable, WithoutAtmosphereOnlyTheSun)
{
  nimbus::SceneAtmosphere air;
  air.Enabled = false;
  const nimbus::SunAndAir sunAndAir(nimbus::SunParameters(), air, 16);
  const nimbus::AtmosphereTable table = nimbus::BuildAtmosphereTable(sunAndAir, 0.0, 1000.0, 16);
  EXPECT_FALSE(table.HasAtmosphere);
  EXPECT_EQ(table.Samples, 0);
  // Luminance of the sun's linear sRGB = the scene's illuminance (1).
  const auto& e = table.SunIrradianceTop;
  EXPECT_NEAR(0.2126 * e[0] + 0.7152 * e[1] + 0.0722 * e[2], 1.0, 1e-3);
}

TEST(AtmosphereTable, RowsFollowTheAtmosphere)
{
  nimbus::SunParameters sun;
  sun.ElevationDegrees = 5.0;
  const nimbus::SceneAtmosphere air;
  const nimbus::SunAndAir sunAndAir(sun, air, 16);
  const double top = air.TopRadiusMetres - air.EarthRadiusMetres;
  const nimbus::AtmosphereTable table = nimbus::BuildAtmosphereTable(sunAndAir, 0.0, top, 1024);
  ASSERT_TRUE(table.HasAtmosphere);
  // Low sun: reddened at the ground, nearly unattenuated at the top.
  const auto ground = table.Lookup(0, 0.0), high = table.Lookup(0, top);
  EXPECT_GT(ground[0] / ground[2], 2.0 * table.SunIrradianceTop[0] / table.SunIrradianceTop[2]);
  for (int c = 0; c < 3; ++c)
  {
    EXPECT_NEAR(high[c], table.SunIrradianceTop[c], 1e-3 * table.SunIrradianceTop[c]);
  }
  // Extinction row: beta_R,eff rho_R + beta_M,ext rho_M with rho = exp(-h/H).
  for (double z : { 0.0, 1200.0, 8000.0 })
  {
    const auto k = table.Lookup(3, z);
    for (int c = 0; c < 3; ++c)
    {
      const double expected = table.RayleighExtinctionSeaLevel[c] * std::exp(-z / 8000.0) +
        table.MieExtinctionSeaLevel * std::exp(-z / 1200.0);
      EXPECT_NEAR(k[c], expected, 2e-3 * expected) << "z " << z;
    }
  }
  // Rayleigh extinction is bluer than red (lambda^-4), Mie grey.
  EXPECT_GT(table.RayleighExtinctionSeaLevel[2], 2.0 * table.RayleighExtinctionSeaLevel[0]);
  // Interpolation error of the 1024-sample table against an exact build at mid-sample heights.
  double worst = 0.0;
  for (int i = 0; i < 20; ++i)
  {
    const double z = (i + 0.37) * top / 1023.0 * 3.0;
    const nimbus::AtmosphereTable exact = nimbus::BuildAtmosphereTable(sunAndAir, z, z + 1.0, 2);
    for (int row = 0; row < 4; ++row)
    {
      const auto a = table.Lookup(row, z), b = exact.Lookup(row, z);
      for (int c = 0; c < 3; ++c)
      {
        if (std::abs(b[c]) > 1e-12)
        {
          worst = std::max(worst, std::abs(a[c] - b[c]) / std::abs(b[c]));
        }
      }
    }
  }
  std::cout << "worst relative interpolation error of the atmosphere texture: " << worst << "\n";
  EXPECT_LT(worst, 2e-4); // measured 9.6e-5
  EXPECT_THROW(nimbus::BuildAtmosphereTable(sunAndAir, 10.0, 0.0, 16), std::invalid_argument);
}

// The air's multiple scattering (rows 4 and 5, AirMultipleScattering): a sky model
// of the same air, small tables (the rows only look it up).
namespace
{
nimbus::SkyParameters SmallSky(const nimbus::AtmosphereParameters& air, double groundAlbedo)
{
  nimbus::SkyParameters p;
  p.Atmosphere = air;
  p.GroundAlbedo = groundAlbedo;
  p.Wavelengths = 16;
  p.ScatteringMuSSize = 16;
  p.ScatteringRSize = 8;
  p.ScatteringZenithDirections = 8;
  p.ScatteringAzimuthDirections = 4;
  p.ScatteringSteps = 16;
  p.TransmittanceMuSize = 64;
  p.TransmittanceRSize = 16;
  return p;
}
}

// Radiance is never negative: a sun at (or just below) the horizon, or a 1000 K sun,
// has a spectrum outside the sRGB gamut, whose linear-sRGB channels are partly
// negative; the table clips them at 0 (before: the mapper's radiance reached
// -4e-5 at 0 deg and -6e-3 for 1000 K, measured with TestCloudMapperStability).
// With and without the sky model's multiple-scattering rows.
TEST(AtmosphereTable, NonNegativeOutOfGamutSuns)
{
  const nimbus::SceneAtmosphere air;
  const double top = air.TopRadiusMetres - air.EarthRadiusMetres;
  for (const double elevation : { 0.0, -0.5, 2.0, 90.0 })
  {
    for (const double kelvin : { 1000.0, 5778.0, 40000.0 })
    {
      nimbus::SunParameters sun;
      sun.ElevationDegrees = elevation;
      sun.TemperatureKelvin = kelvin;
      const nimbus::SunAndAir sunAndAir(sun, air, 16);
      nimbus::SkyParameters skyParameters = SmallSky(air, 0.3);
      skyParameters.SunTemperatureKelvin = kelvin;
      const nimbus::SkyModel sky(skyParameters);
      for (const nimbus::SkyModel* multiple :
        { static_cast<const nimbus::SkyModel*>(nullptr), &sky })
      {
        const nimbus::AtmosphereTable table =
          nimbus::BuildAtmosphereTable(sunAndAir, -100.0, top, 256, multiple);
        for (const float value : table.Data)
        {
          ASSERT_TRUE(std::isfinite(value) && value >= 0.0f)
            << elevation << " deg, " << kelvin << " K: " << value;
        }
        for (const double value : table.GroundSkyIrradiance)
        {
          ASSERT_TRUE(std::isfinite(value) && value >= 0.0) << elevation << " deg, " << kelvin;
        }
        for (const double value : table.SunIrradianceTop)
        {
          EXPECT_GE(value, 0.0) << elevation << " deg, " << kelvin << " K";
        }
      }
    }
  }
}

TEST(AtmosphereTable, MultipleScatteringRowsZeroWithoutSkyModelOrAir)
{
  nimbus::SunParameters sun;
  sun.ElevationDegrees = 40.0;
  const nimbus::SceneAtmosphere air;
  const nimbus::SunAndAir sunAndAir(sun, air, 16);
  const nimbus::AtmosphereTable table = nimbus::BuildAtmosphereTable(sunAndAir, 0.0, 1.0e5, 64);
  EXPECT_FALSE(table.HasMultipleScattering);
  for (double z : { 0.0, 3000.0, 9.0e4 })
  {
    for (int row : { 4, 5 })
    {
      const auto v = table.Lookup(row, z);
      EXPECT_EQ(v[0] + v[1] + v[2], 0.0) << "row " << row << " z " << z;
    }
  }
  // No atmosphere: nothing, even with a sky model.
  const nimbus::SkyModel sky(SmallSky(air, 0.2));
  nimbus::SceneAtmosphere none;
  none.Enabled = false;
  const nimbus::SunAndAir vacuum(sun, none, 16);
  const nimbus::AtmosphereTable empty = nimbus::BuildAtmosphereTable(vacuum, 0.0, 1.0e5, 64, &sky);
  EXPECT_FALSE(empty.HasAtmosphere);
  EXPECT_FALSE(empty.HasMultipleScattering);
  EXPECT_EQ(empty.Samples, 0);
  EXPECT_EQ(
    empty.GroundSkyIrradiance[0] + empty.GroundSkyIrradiance[1] + empty.GroundSkyIrradiance[2],
    0.0);
  // A sky model of another wavelength count is refused.
  nimbus::SkyParameters other = SmallSky(air, 0.2);
  other.Wavelengths = 12;
  const nimbus::SkyModel otherSky(other);
  EXPECT_THROW(
    nimbus::BuildAtmosphereTable(sunAndAir, 0.0, 1.0e5, 64, &otherSky), std::invalid_argument);
}

TEST(AtmosphereTable, MultipleScatteringMatchesTheSkyModel)
{
  nimbus::SunParameters sun;
  sun.ElevationDegrees = 40.0;
  sun.Illuminance = 2.5; // the table is relative to this sun, the sky model to luminance 1
  nimbus::SceneAtmosphere air;
  air.SceneAltitudeMetres = 300.0;
  const nimbus::SunAndAir sunAndAir(sun, air, 16);
  const nimbus::SkyModel sky(SmallSky(air, 0.2));
  const double top = air.TopRadiusMetres - air.EarthRadiusMetres - air.SceneAltitudeMetres;
  const nimbus::AtmosphereTable table =
    nimbus::BuildAtmosphereTable(sunAndAir, -300.0, top, 1024, &sky);
  ASSERT_TRUE(table.HasMultipleScattering);
  // Positive and finite where there is air, and a fraction of the single scattering.
  for (double z : { -300.0, 0.0, 1000.0, 5000.0, 20000.0 })
  {
    const auto m = table.Lookup(4, z);
    const auto rayleigh = table.Lookup(1, z), mie = table.Lookup(2, z);
    for (int c = 0; c < 3; ++c)
    {
      EXPECT_TRUE(std::isfinite(m[c]) && m[c] > 0.0) << "z " << z << " c " << c;
    }
    // Rows 1 and 2 times the mean phase 1/(4 pi): the isotropic single scattering.
    const double single = nimbus::LinearSrgbLuminance(rayleigh) / (4.0 * nimbus::kPi) +
      nimbus::LinearSrgbLuminance(mie) / (4.0 * nimbus::kPi);
    const double ratio = nimbus::LinearSrgbLuminance(m) / single;
    std::cout << "z " << z << ": multiple / isotropic single scattering " << ratio << "\n";
    EXPECT_GT(ratio, 0.05);
    EXPECT_LT(ratio, 2.0);
  }
  // Independently at h = 1300 m: sigma_s(l) M_ms(l) from the sky model's own air,
  // times the illuminance, through the sky model's spectrum -> sRGB map.
  const double z = 1000.0, h = air.SceneAltitudeMetres + z;
  const nimbus::Atmosphere& atmosphere = sky.GetAtmosphere();
  const std::vector<double>& wavelengths = sky.GetSpectrum().GetWavelengths();
  const double muS = std::sin(40.0 * nimbus::kPi / 180.0);
  std::vector<double> mean(wavelengths.size()), source(wavelengths.size()),
    ground(wavelengths.size());
  sky.LookupMultipleScattering(air.EarthRadiusMetres + h, muS, mean.data());
  sky.LookupGroundSkyIrradiance(muS, ground.data());
  const double rhoR = atmosphere.Density(h, air.RayleighScaleHeightMetres);
  const double rhoM = atmosphere.Density(h, air.MieScaleHeightMetres);
  for (std::size_t l = 0; l < wavelengths.size(); ++l)
  {
    source[l] = sun.Illuminance * mean[l] *
      (atmosphere.RayleighScattering(wavelengths[l]) * rhoR +
        atmosphere.MieScattering(550.0) * rhoM);
    ground[l] *= sun.Illuminance;
  }
  const auto expected = sky.GetSpectrum().ToLinearSrgb(source);
  const auto expectedGround = sky.GetSpectrum().ToLinearSrgb(ground);
  const auto m = table.Lookup(4, z), g = table.Lookup(5, z);
  for (int c = 0; c < 3; ++c)
  {
    EXPECT_NEAR(m[c], expected[c], 2e-3 * expected[c]) << "c " << c;
    EXPECT_NEAR(g[c], expectedGround[c], 1e-5 * expectedGround[c]) << "c " << c;
    EXPECT_NEAR(table.GroundSkyIrradiance[c], expectedGround[c], 1e-5 * expectedGround[c]);
  }
  // The sky lights a horizontal ground with a fraction of the sun's irradiance on it.
  const double sunOnGround = nimbus::LinearSrgbLuminance(table.Lookup(0, -300.0)) * muS;
  const double skyOnGround = nimbus::LinearSrgbLuminance(table.GroundSkyIrradiance);
  std::cout << "sky / sun irradiance of the ground at 40 deg: " << skyOnGround / sunOnGround
            << "\n";
  EXPECT_GT(skyOnGround / sunOnGround, 0.05);
  EXPECT_LT(skyOnGround / sunOnGround, 0.6);
}

TEST(AtmosphereTable, MultipleScatteringGrowsWithHaze)
{
  nimbus::SunParameters sun;
  sun.ElevationDegrees = 30.0;
  nimbus::SceneAtmosphere clear, hazy;
  hazy.MieScatteringPerMetre = 4.0 * clear.MieScatteringPerMetre;
  double previous = 0.0;
  for (const nimbus::SceneAtmosphere* air : { &clear, &hazy })
  {
    const nimbus::SunAndAir sunAndAir(sun, *air, 16);
    const nimbus::SkyModel sky(SmallSky(*air, 0.2));
    const nimbus::AtmosphereTable table =
      nimbus::BuildAtmosphereTable(sunAndAir, 0.0, 1.0e5, 512, &sky);
    const double value = nimbus::LinearSrgbLuminance(table.Lookup(4, 500.0));
    EXPECT_GT(value, 1.5 * previous);
    previous = value;
  }
}

TEST(SliceGeometry, SlicePolygonCutsTheBox)
{
  std::vector<Vector3> cube;
  for (int c = 0; c < 8; ++c)
  {
    cube.push_back({ { (c & 1) ? 1.0 : 0.0, (c & 2) ? 1.0 : 0.0, (c & 4) ? 1.0 : 0.0 } });
  }
  const auto square = nimbus::SlicePolygon(cube, { { 0, 0, 1 } }, 0.25);
  ASSERT_EQ(square.size(), 4u);
  for (const Vector3& p : square)
  {
    EXPECT_DOUBLE_EQ(p[2], 0.25);
  }
  // The plane through the centre with normal (1,1,1) cuts a regular hexagon.
  const Vector3 diagonal = nimbus::Normalized({ { 1, 1, 1 } });
  const auto hexagon =
    nimbus::SlicePolygon(cube, diagonal, nimbus::Dot(diagonal, { { 0.5, 0.5, 0.5 } }));
  ASSERT_EQ(hexagon.size(), 6u);
  for (const Vector3& p : hexagon)
  {
    EXPECT_NEAR(p[0] + p[1] + p[2], 1.5, 1e-12);
    EXPECT_NEAR(std::sqrt((p[0] - 0.5) * (p[0] - 0.5) + (p[1] - 0.5) * (p[1] - 0.5) +
                  (p[2] - 0.5) * (p[2] - 0.5)),
      std::sqrt(0.5), 1e-12);
  }
  EXPECT_TRUE(nimbus::SlicePolygon(cube, { { 0, 0, 1 } }, 2.0).empty());
  EXPECT_THROW(
    nimbus::SlicePolygon({ { { 0, 0, 0 } } }, { { 0, 0, 1 } }, 0.0), std::invalid_argument);
}

// The slab's points bound every plane's polygon between its two planes (the
// jittered slices' scissor), over random tilted planes through a cube.
TEST(SliceGeometry, SlabPointsBoundTheJitteredPolygons)
{
  std::vector<Vector3> cube;
  for (int c = 0; c < 8; ++c)
  {
    cube.push_back({ { (c & 1) ? 1.0 : 0.0, (c & 2) ? 1.0 : 0.0, (c & 4) ? 1.0 : 0.0 } });
  }
  std::mt19937 random(3);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  int checked = 0;
  for (int trial = 0; trial < 200; ++trial)
  {
    const Vector3 n = nimbus::Normalized({ { unit(random), unit(random), unit(random) } });
    const double d = nimbus::Dot(n, { { 0.5, 0.5, 0.5 } }) + 0.9 * unit(random);
    const double half = 0.1 * (1.0 + unit(random));
    const auto slab = nimbus::SlabPoints(cube, n, d, half);
    for (int k = 0; k <= 10; ++k)
    {
      const auto polygon = nimbus::SlicePolygon(cube, n, d - half + 0.2 * half * k);
      for (const Vector3& p : polygon)
      {
        ASSERT_FALSE(slab.empty());
        for (int axis = 0; axis < 3; ++axis)
        {
          double lo = 1e30, hi = -1e30;
          for (const Vector3& q : slab)
          {
            lo = std::min(lo, q[axis]);
            hi = std::max(hi, q[axis]);
          }
          EXPECT_GE(p[axis], lo - 1e-12);
          EXPECT_LE(p[axis], hi + 1e-12);
        }
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, 1000);
  EXPECT_TRUE(nimbus::SlabPoints(cube, { { 0, 0, 1 } }, 3.0, 0.5).empty());
}

// The scissor rectangles cover the projected polygon with one pixel (texel) of
// margin, stay inside the target, and refuse a polygon behind the eye.
TEST(SliceGeometry, ScissorRectanglesCoverTheSlice)
{
  const std::vector<Vector3> square = { { { -0.5, -0.5, 0.0 } }, { { 0.5, -0.5, 0.0 } },
    { { 0.5, 0.5, 0.0 } }, { { -0.5, 0.5, 0.0 } } };
  // An orthographic "camera": NDC = world / 2 (x, y), w = 1.
  const double half[16] = { 0.5, 0, 0, 0, 0, 0.5, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1 };
  int rect[4];
  ASSERT_TRUE(nimbus::ScreenRectangle(square, half, 100, 80, rect));
  // NDC x in [-0.25, 0.25] -> pixels [37.5, 62.5] -> [36, 64) with the margin.
  EXPECT_EQ(rect[0], 36);
  EXPECT_EQ(rect[2], 64 - 36);
  EXPECT_EQ(rect[1], 29); // NDC y in [-0.25, 0.25] over 80 rows: [30, 50] -> [29, 51)
  EXPECT_EQ(rect[3], 51 - 29);
  // A polygon larger than the view is clamped to it.
  const double big[16] = { 10, 0, 0, 0, 0, 10, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1 };
  ASSERT_TRUE(nimbus::ScreenRectangle(square, big, 100, 80, rect));
  EXPECT_EQ(rect[0], 0);
  EXPECT_EQ(rect[1], 0);
  EXPECT_EQ(rect[2], 100);
  EXPECT_EQ(rect[3], 80);
  // w <= 0: a vertex behind the eye.
  const double behind[16] = { 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, -1, 0 };
  EXPECT_FALSE(nimbus::ScreenRectangle(square, behind, 100, 80, rect));

  // The shadow surface seen straight down onto the unit square at the origin.
  nimbus::ShadowFrame frame;
  frame.Origin = { { -1.0, -1.0, 0.0 } };
  frame.Width = frame.Height = 2.0;
  nimbus::ShadowRectangle(square, frame, 64, rect);
  EXPECT_EQ(rect[0], 15); // s in [0.25, 0.75] of 64 texels: [16, 48] -> [15, 49)
  EXPECT_EQ(rect[2], 49 - 15);
  EXPECT_EQ(rect[1], 15);
  EXPECT_EQ(rect[3], 49 - 15);
  nimbus::ShadowRectangle(square, frame, 2, rect); // clamped to the surface
  EXPECT_EQ(rect[0], 0);
  EXPECT_EQ(rect[2], 2);
}
