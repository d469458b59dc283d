// The ray-marched Cloud method's sun-depth volume without a render window
// (Representations/Cloud/SunDepthVolume.h): closed forms for homogeneous boxes and
// slabs, any sun direction, spacing and metres per unit; bad texels; the same result
// on any number of threads; the blur of a shadow edge; the block maxima.
#include "SunDepthVolume.h"

#include <gtest/gtest.h>

#include <algorithm>
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
  const int n = 24;
  const std::vector<float> density(n * n * n, 1.0f);
  for (const Vector3& L : { Unit(1, 0, 2), Unit(-1, 2, 3), Unit(0.3, -0.2, -1), Unit(1, 1, 1) })
  {
    const auto tau = ComputeSunDepthVolume(density.data(), PointGrid(n), L, 1.0, 1.0);
    double worst = 0.0, sum = 0.0;
    for (int k = 0; k < n; ++k)
    {
      for (int j = 0; j < n; ++j)
      {
        for (int i = 0; i < n; ++i)
        {
          const double exact =
            DistanceToExit({ { double(i), double(j), double(k) } }, L, 0.0, n - 1.0);
          const double error = std::abs(tau[Index(n, i, j, k)] - exact);
          worst = std::max(worst, error);
          sum += error;
        }
      }
    }
    // Bilinear interpolation is exact where the depth is linear in position. Where
    // lines that leave through a side face meet lines that leave through the face
    // the sweep ends on, the depth has a kink; the kink's plane contains L, so the
    // sweep follows it and its interpolation error adds up along it (measured:
    // mean 0.31, worst 5.4 texels' optical depth for L = (0.28, -0.19, -0.94), n = 24;
    // docs/ray-march.md). A cloud that does not touch its box's sides never sees it.
    const double mean = sum / (n * n * n);
    std::printf("L = (%.2f, %.2f, %.2f): mean error %.3f, worst %.3f (texel optical depths)\n",
      L[0], L[1], L[2], mean, worst);
    EXPECT_LT(mean, 0.4);
    EXPECT_LT(worst, 0.25 * n);
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
