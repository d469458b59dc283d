// The ray-marched Cloud method's sun-depth volume without a render window
// (Representations/Cloud/SunDepthVolume.h): closed forms for homogeneous boxes and
// slabs, any sun direction, spacing and metres per unit; bad texels; the same result
// on any number of threads; the blur of a shadow edge; the block maxima.
#include "SunDepthVolume.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

using nimbus::ComputeBlockMaxima;
using nimbus::ComputeSunDepthVolume;
using nimbus::SunDepthGrid;
using nimbus::Vector3;

namespace
{
SunDepthGrid PointGrid(int n, double spacing = 1.0)
{
  SunDepthGrid grid;
  grid.Dimensions = { { n, n, n } };
  grid.Linear = { { 1.0 / spacing, 0, 0, 0, 1.0 / spacing, 0, 0, 0, 1.0 / spacing } };
  grid.BoxLow = { { 0, 0, 0 } };
  grid.BoxHigh = { { n - 1.0, n - 1.0, n - 1.0 } };
  return grid;
}

std::size_t Index(int n, int i, int j, int k)
{
  return static_cast<std::size_t>(i) +
    static_cast<std::size_t>(n) * (j + static_cast<std::size_t>(n) * k);
}

Vector3 Unit(double x, double y, double z)
{
  const double l = std::sqrt(x * x + y * y + z * z);
  return { { x / l, y / l, z / l } };
}

// Distance (world units) from x along L to the box [lo, hi]^3.
double DistanceToExit(const Vector3& x, const Vector3& L, double lo, double hi)
{
  double t = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a)
  {
    if (L[a] > 1e-12)
    {
      t = std::min(t, (hi - x[a]) / L[a]);
    }
    else if (L[a] < -1e-12)
    {
      t = std::min(t, (lo - x[a]) / L[a]);
    }
  }
  return t;
}
}

TEST(SunDepthVolume, HomogeneousBoxSunOverhead)
{
  const int n = 16;
  const std::vector<float> density(n * n * n, 2.0f);
  // Spacing 3 world units, 10 m per unit, k = 0.01 / m: tau = 0.02 * 30 m * (n-1-k).
  const auto tau =
    ComputeSunDepthVolume(density.data(), PointGrid(n, 3.0), Unit(0, 0, 1), 0.01, 10.0);
  for (int k = 0; k < n; ++k)
  {
    EXPECT_NEAR(tau[Index(n, 5, 7, k)], 0.02 * 30.0 * (n - 1 - k), 1e-4) << k;
  }
  // Sun toward -y: the sweep runs the other way along another axis.
  const auto side = ComputeSunDepthVolume(density.data(), PointGrid(n), Unit(0, -1, 0), 1.0, 1.0);
  for (int j = 0; j < n; ++j)
  {
    EXPECT_NEAR(side[Index(n, 3, j, 9)], 2.0 * j, 1e-4) << j;
  }
}

TEST(SunDepthVolume, HomogeneousBoxObliqueSun)
{
  // k = 0.1 per texel length: optical depths 0 to about 4, where the light shows.
  const int n = 24;
  const std::vector<float> density(n * n * n, 1.0f);
  for (const auto interpolation :
    { nimbus::SunDepthInterpolation::Transmittance, nimbus::SunDepthInterpolation::OpticalDepth })
  {
    for (const Vector3& L : { Unit(1, 0, 2), Unit(-1, 2, 3), Unit(0.3, -0.2, -1), Unit(1, 1, 1) })
    {
      const auto tau =
        ComputeSunDepthVolume(density.data(), PointGrid(n), L, 0.1, 1.0, 0, interpolation);
      double worst = 0.0, sum = 0.0;
      for (int k = 0; k < n; ++k)
      {
        for (int j = 0; j < n; ++j)
        {
          for (int i = 0; i < n; ++i)
          {
            const double exact =
              0.1 * DistanceToExit({ { double(i), double(j), double(k) } }, L, 0.0, n - 1.0);
            const double error = std::abs(std::exp(-tau[Index(n, i, j, k)]) - std::exp(-exact));
            worst = std::max(worst, error);
            sum += error;
          }
        }
      }
      // Interpolation is exact where the interpolated quantity is linear in position.
      // Where lines that leave through a side face meet lines that leave through the
      // face the sweep ends on, the depth has a kink; its plane contains L, so the sweep
      // follows it and the interpolation error adds up along it (docs/ray-march.md). A
      // cloud that does not touch its box's sides never sees it. Measured (the sun's
      // transmittance): mean 0.003 to 0.015, worst 0.06 to 0.17.
      const double mean = sum / (n * n * n);
      std::printf("%s, L = (%.2f, %.2f, %.2f): transmittance error mean %.4f, worst %.4f\n",
        interpolation == nimbus::SunDepthInterpolation::Transmittance ? "transmittance"
                                                                      : "optical depth",
        L[0], L[1], L[2], mean, worst);
      EXPECT_LT(mean, 0.02);
      EXPECT_LT(worst, 0.2);
    }
  }
}

TEST(SunDepthVolume, SlabShadowIsItsOpticalThickness)
{
  const int n = 32;
  std::vector<float> density(n * n * n, 0.0f);
  for (int k = 20; k <= 22; ++k)
  {
    for (int j = 0; j < n; ++j)
    {
      for (int i = 0; i < n; ++i)
      {
        density[Index(n, i, j, k)] = 1.0f;
      }
    }
  }
  const auto tau = ComputeSunDepthVolume(density.data(), PointGrid(n), Unit(0, 0, 1), 0.5, 1.0);
  // The trapezoid integrates the linear interpolant: ramps of 1/2 on both sides.
  EXPECT_NEAR(tau[Index(n, 10, 10, 5)], 0.5 * 3.0, 1e-5);
  EXPECT_NEAR(tau[Index(n, 10, 10, 30)], 0.0, 1e-7);
  // An oblique sun through an infinite slab: thickness / cos(zenith), away from the sides.
  const Vector3 L = Unit(0.5, 0.0, 1.0);
  const auto oblique = ComputeSunDepthVolume(density.data(), PointGrid(n), L, 0.5, 1.0);
  EXPECT_NEAR(oblique[Index(n, 4, 10, 10)], 0.5 * 3.0 / L[2], 1e-4);
}

// Trilinear density at index point x (clamped to the texel centres), as the sweep and
// the GPU read it.
double Trilinear(const std::vector<float>& density, int n, const std::array<double, 3>& x)
{
  int i0[3];
  double f[3];
  for (int a = 0; a < 3; ++a)
  {
    const double c = std::min(std::max(x[a], 0.0), n - 1.0);
    i0[a] = std::min(static_cast<int>(c), n - 2);
    f[a] = c - i0[a];
  }
  double value = 0.0;
  for (int corner = 0; corner < 8; ++corner)
  {
    double w = 1.0;
    int i[3];
    for (int a = 0; a < 3; ++a)
    {
      const int bit = (corner >> a) & 1;
      i[a] = i0[a] + bit;
      w *= bit ? f[a] : 1.0 - f[a];
    }
    value += w * density[Index(n, i[0], i[1], i[2])];
  }
  return value;
}

TEST(SunDepthVolume, GapsBetweenCloudsPassTheirShareOfTheSun)
{
  // A thin opaque layer with a four-texel gap every eight texels, the sun oblique so each
  // slice's line falls between texels. Below the layer the mean transmittance over a
  // row must match a fine march through the same trilinear density: interpolating the
  // transmittance keeps the mean light of the neighbouring lines (an average of
  // averages); interpolating the optical depth darkens every gap (the mean of exp is
  // above exp of the mean).
  const int n = 64;
  std::vector<float> density(n * n * n, 0.0f);
  for (int k = n - 4; k < n - 2; ++k)
  {
    for (int j = 0; j < n; ++j)
    {
      for (int i = 0; i < n; ++i)
      {
        density[Index(n, i, j, k)] = i % 8 < 4 ? 50.0f : 0.0f;
      }
    }
  }
  const Vector3 L = Unit(0.37, 0.0, 1.0);
  const int row[2] = { 24, 40 }; // away from the sides
  double exact = 0.0;
  for (int i = row[0]; i < row[1]; ++i)
  {
    // The line from texel (i, 10, 20) toward the sun, in steps of 1/50 texel.
    double tau = 0.0;
    const double ds = 0.02;
    for (double s = 0.5 * ds;; s += ds)
    {
      const std::array<double, 3> x{ { i + s * L[0], 10.0, 20.0 + s * L[2] } };
      if (x[2] > n - 1.0 || x[0] > n - 1.0)
      {
        break;
      }
      tau += Trilinear(density, n, x) * ds;
    }
    exact += std::exp(-tau) / (row[1] - row[0]);
  }
  const auto meanBelow = [&](nimbus::SunDepthInterpolation interpolation)
  {
    const auto tau =
      ComputeSunDepthVolume(density.data(), PointGrid(n), L, 1.0, 1.0, 0, interpolation);
    double sum = 0.0;
    for (int i = row[0]; i < row[1]; ++i)
    {
      sum += std::exp(-tau[Index(n, i, 10, 20)]) / (row[1] - row[0]);
    }
    return sum;
  };
  const double light = meanBelow(nimbus::SunDepthInterpolation::Transmittance);
  const double depth = meanBelow(nimbus::SunDepthInterpolation::OpticalDepth);
  std::printf("mean transmittance below the gaps: fine march %.4f, transmittance interpolated "
              "%.4f, optical depth interpolated %.4f\n",
    exact, light, depth);
  // Measured: fine march 0.250, transmittance 0.329 (the trapezoid steps across the
  // layer let a little more through), optical depth 0.000 (every gap closed).
  EXPECT_NEAR(light, exact, 0.4 * exact);
  EXPECT_LT(depth, 0.5 * exact);
}

TEST(SunDepthVolume, CellDataBoxReachesHalfATexelFurther)
{
  const int n = 8;
  SunDepthGrid grid = PointGrid(n);
  grid.BoxLow = { { -0.5, -0.5, -0.5 } };
  grid.BoxHigh = { { n - 0.5, n - 0.5, n - 0.5 } };
  const std::vector<float> density(n * n * n, 1.0f);
  const auto tau = ComputeSunDepthVolume(density.data(), grid, Unit(0, 0, 1), 1.0, 1.0);
  EXPECT_NEAR(tau[Index(n, 2, 2, n - 1)], 0.5, 1e-6);
  EXPECT_NEAR(tau[Index(n, 2, 2, 0)], n - 0.5, 1e-5);
}

TEST(SunDepthVolume, BadTexelsCountAsEmptyAndHugeOnesStayFinite)
{
  const int n = 8;
  std::vector<float> density(n * n * n, 1.0f);
  density[Index(n, 4, 4, 6)] = std::numeric_limits<float>::quiet_NaN();
  density[Index(n, 2, 2, 6)] = std::numeric_limits<float>::infinity();
  density[Index(n, 6, 6, 6)] = -5.0f;
  density[Index(n, 1, 1, 6)] = 3e38f;
  const auto tau = ComputeSunDepthVolume(density.data(), PointGrid(n), Unit(0.2, 0.1, 1), 1e6, 1e9);
  for (const float t : tau)
  {
    ASSERT_TRUE(std::isfinite(t));
    ASSERT_GE(t, 0.0f);
  }
  // A NaN texel lowers the depth below it as an empty texel would.
  std::vector<float> hole(n * n * n, 1.0f);
  hole[Index(n, 4, 4, 6)] = 0.0f;
  std::vector<float> nan = hole;
  nan[Index(n, 4, 4, 6)] = std::numeric_limits<float>::quiet_NaN();
  EXPECT_EQ(ComputeSunDepthVolume(hole.data(), PointGrid(n), Unit(0, 0, 1), 1.0, 1.0),
    ComputeSunDepthVolume(nan.data(), PointGrid(n), Unit(0, 0, 1), 1.0, 1.0));
  // One texel, one-texel-thick axes.
  SunDepthGrid one;
  one.Dimensions = { { 1, 1, 1 } };
  one.BoxLow = { { -0.5, -0.5, -0.5 } };
  one.BoxHigh = { { 0.5, 0.5, 0.5 } };
  const float single = 4.0f;
  const auto t1 = ComputeSunDepthVolume(&single, one, Unit(0, 0, 1), 1.0, 1.0);
  ASSERT_EQ(t1.size(), 1u);
  EXPECT_NEAR(t1[0], 2.0, 1e-6);
}

TEST(SunDepthVolume, SameOnAnyNumberOfThreads)
{
  const int n = 40;
  std::vector<float> density(n * n * n);
  for (std::size_t m = 0; m < density.size(); ++m)
  {
    density[m] = static_cast<float>((m * 2654435761u % 1000) / 1000.0);
  }
  const Vector3 L = Unit(0.3, -0.6, 0.7);
  EXPECT_EQ(ComputeSunDepthVolume(density.data(), PointGrid(n), L, 1.0, 1.0, 1),
    ComputeSunDepthVolume(density.data(), PointGrid(n), L, 1.0, 1.0, 4));
}

TEST(SunDepthVolume, ShadowEdgeBlur)
{
  // A thick occluder over half of the top (x < n/2), the sun 30 degrees from the
  // zenith in x: below, the shadow's edge is a step in x; the sweep's bilinear
  // steps widen it. Measured: the 10-90 % width at the bottom in texels.
  const int n = 64;
  std::vector<float> density(n * n * n, 0.0f);
  for (int k = n - 4; k < n; ++k)
  {
    for (int j = 0; j < n; ++j)
    {
      for (int i = 0; i < n / 2; ++i)
      {
        density[Index(n, i, j, k)] = 10.0f;
      }
    }
  }
  const Vector3 L = Unit(std::sin(30.0 * nimbus::kDegree), 0.0, std::cos(30.0 * nimbus::kDegree));
  const auto tau = ComputeSunDepthVolume(density.data(), PointGrid(n), L, 1.0, 1.0);
  const double full = tau[Index(n, 2, 5, 0)];
  int first = -1, last = -1;
  for (int i = 0; i < n; ++i)
  {
    const double f = tau[Index(n, i, 5, 0)] / full;
    if (f < 0.9 && first < 0)
    {
      first = i;
    }
    if (f < 0.1 && last < 0)
    {
      last = i;
    }
  }
  const int width = last - first;
  std::printf("shadow edge 10-90 %% width after %d slices: %d texels\n", n - 4, width);
  ::testing::Test::RecordProperty("edge_width_texels", width);
  EXPECT_GT(width, 0);
  EXPECT_LE(width, 12); // about sqrt(60 * 0.58 * 0.42)*2.5 for the diffusion of a binomial
}

TEST(SunDepthVolume, BlockMaximaCoverEveryTrilinearReach)
{
  const std::array<int, 3> dims{ { 10, 9, 8 } };
  std::vector<float> density(10 * 9 * 8, 0.0f);
  density[5 + 10 * (4 + 9 * 3)] = 7.0f; // texel (5, 4, 3)
  std::array<int, 3> blocks{};
  const auto maxima = ComputeBlockMaxima(density.data(), dims, 4, blocks);
  EXPECT_EQ(blocks, (std::array<int, 3>{ { 3, 3, 2 } }));
  // Every sample position x (index coordinates, clamp-to-edge) whose trilinear
  // look-up reads texel (5, 4, 3) lies in a block B = floor(x / 4) that is non-zero.
  const int texel[3] = { 5, 4, 3 };
  const auto reads = [](double x, int t, int n)
  {
    const double c = std::min(std::max(x, 0.0), n - 1.0);
    const int lo = static_cast<int>(std::floor(c));
    return lo == t || std::min(lo + 1, n - 1) == t;
  };
  int checked = 0;
  for (double z = -0.5; z <= 7.5; z += 0.25)
  {
    for (double y = -0.5; y <= 8.5; y += 0.25)
    {
      for (double x = -0.5; x <= 9.5; x += 0.25)
      {
        if (reads(x, texel[0], 10) && reads(y, texel[1], 9) && reads(z, texel[2], 8))
        {
          const int B[3] = { std::min(std::max(int(std::floor(x / 4)), 0), 2),
            std::min(std::max(int(std::floor(y / 4)), 0), 2),
            std::min(std::max(int(std::floor(z / 4)), 0), 1) };
          EXPECT_EQ(maxima[B[0] + 3 * (B[1] + 3 * B[2])], 7.0f) << x << " " << y << " " << z;
          ++checked;
        }
      }
    }
  }
  EXPECT_GT(checked, 0);
  EXPECT_EQ(maxima[2 + 3 * (2 + 3 * 1)], 0.0f); // far from the texel
}
