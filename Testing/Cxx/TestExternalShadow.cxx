// The other pieces' shadow of a distributed cloud (Representations/Cloud/ExternalShadow.h,
// under MPI) against closed forms: a uniform slab cut into two pieces, the sun
// overhead and oblique, lines that miss the piece, the trilinear lattice, and bad
// input (NaN, negative, an empty grid) giving finite zeros.
#include "ExternalShadow.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace
{
// A uniform density `value` on a lattice of n^3 points covering [0, side]^3 (world).
nimbus::CoarseDensityGrid UniformCube(int n, double side, float value)
{
  nimbus::CoarseDensityGrid grid;
  grid.Dimensions = { { n, n, n } };
  grid.Spacing = { { side / (n - 1), side / (n - 1), side / (n - 1) } };
  grid.Values.assign(static_cast<std::size_t>(n) * n * n, value);
  return grid;
}

// The texel of `map` whose sun line passes closest to the point (x, y, z).
std::size_t TexelOf(const nimbus::ExternalShadowMap& map, const nimbus::Vector3& p)
{
  const auto& f = map.Frame;
  double u = 0.0, w = 0.0;
  for (int a = 0; a < 3; ++a)
  {
    u += (p[a] - f.Origin[a]) * f.U[a];
    w += (p[a] - f.Origin[a]) * f.W[a];
  }
  const int s = static_cast<int>(u / f.Width * map.Size);
  const int t = static_cast<int>(w / f.Height * map.Size);
  return static_cast<std::size_t>(t) * map.Size + s;
}
}

TEST(ExternalShadow, TrilinearGridIsExactAndZeroOutside)
{
  nimbus::CoarseDensityGrid grid;
  grid.Dimensions = { { 2, 2, 2 } };
  grid.Spacing = { { 2.0, 2.0, 2.0 } };
  grid.Origin = { { -1.0, -1.0, -1.0 } };
  // value = x + 2 y + 3 z + 10 at the corners: trilinear reproduces it inside.
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i)
        grid.Values.push_back(
          static_cast<float>((2 * i - 1) + 2 * (2 * j - 1) + 3 * (2 * k - 1) + 10));
  ASSERT_TRUE(grid.IsValid());
  EXPECT_NEAR(grid.Sample({ { 0.25, -0.5, 0.75 } }), 0.25 - 1.0 + 2.25 + 10.0, 1e-6);
  EXPECT_EQ(grid.Sample({ { 1.5, 0.0, 0.0 } }), 0.0);
  EXPECT_EQ(grid.Sample({ { std::nan(""), 0.0, 0.0 } }), 0.0);
}

TEST(ExternalShadow, SlabCutInTwoSunOverhead)
{
  // 1000 m cube, density 2, k = 0.01 /m: sigma = 0.02 /m. The piece is the lower
  // half (z in [0, 500]): a line through it has 500 m of the other piece above it
  // (Beyond = 10) and 500 m outside the piece in all (Whole = 10).
  const auto grid = UniformCube(21, 1000.0, 2.0f);
  const std::array<double, 6> piece = { { 0.0, 1000.0, 0.0, 1000.0, 0.0, 500.0 } };
  const auto map =
    nimbus::ComputeExternalShadowMap(grid, piece, { { 0.0, 0.0, 1.0 } }, 0.01, 1.0, 64);
  ASSERT_EQ(map.Size, 64);
  const std::size_t centre = TexelOf(map, { { 500.0, 500.0, 0.0 } });
  EXPECT_NEAR(map.Depths[2 * centre], 10.0, 0.05);
  EXPECT_NEAR(map.Depths[2 * centre + 1], 10.0, 0.05);
  // The upper half as the piece: nothing beyond it toward the sun, 10 below it.
  const std::array<double, 6> upper = { { 0.0, 1000.0, 0.0, 1000.0, 500.0, 1000.0 } };
  const auto above =
    nimbus::ComputeExternalShadowMap(grid, upper, { { 0.0, 0.0, 1.0 } }, 0.01, 1.0, 64);
  EXPECT_NEAR(above.Depths[2 * centre], 0.0, 1e-6);
  EXPECT_NEAR(above.Depths[2 * centre + 1], 10.0, 0.05);
  // Metres per unit scale the depth.
  const auto km =
    nimbus::ComputeExternalShadowMap(grid, piece, { { 0.0, 0.0, 1.0 } }, 0.01, 2.0, 64);
  EXPECT_NEAR(km.Depths[2 * centre], 20.0, 0.1);
}

TEST(ExternalShadow, ObliqueSunAndLinesMissingThePiece)
{
  // Sun at 45 degrees toward +x: the line from (50, 500, 100) in the piece (lower
  // half) leaves it at (450, 500, 500) and the cube at (950, 500, 1000): 500 sqrt(2) m
  // of path in the upper half.
  const auto grid = UniformCube(41, 1000.0, 1.0f);
  const std::array<double, 6> piece = { { 0.0, 1000.0, 0.0, 1000.0, 0.0, 500.0 } };
  const double c = std::sqrt(0.5);
  const auto map = nimbus::ComputeExternalShadowMap(grid, piece, { { c, 0.0, c } }, 0.01, 1.0, 128);
  const std::size_t inside = TexelOf(map, { { 50.0, 500.0, 100.0 } });
  EXPECT_NEAR(map.Depths[2 * inside], 0.01 * 500.0 * std::sqrt(2.0), 0.1);
  // A line through the upper half only (it enters the cube at x = 0, z = 600 and
  // never meets the lower half): Beyond 0, Whole its whole path in the cube.
  const auto missing = nimbus::ComputeExternalShadowMap(
    grid, { { 0.0, 1000.0, 0.0, 1000.0, 0.0, 500.0 } }, { { c, 0.0, c } }, 0.01, 1.0, 128);
  const std::size_t high = TexelOf(missing, { { 0.0, 500.0, 600.0 } });
  EXPECT_NEAR(missing.Depths[2 * high], 0.0, 1e-6);
  EXPECT_NEAR(missing.Depths[2 * high + 1], 0.01 * 400.0 * std::sqrt(2.0), 0.15);
}

TEST(ExternalShadow, BadInputGivesFiniteZeros)
{
  auto grid = UniformCube(5, 10.0, std::numeric_limits<float>::quiet_NaN());
  grid.Values[3] = -5.0f;
  grid.Values[7] = std::numeric_limits<float>::infinity();
  const std::array<double, 6> piece = { { 0.0, 10.0, 0.0, 10.0, 0.0, 5.0 } };
  const auto map =
    nimbus::ComputeExternalShadowMap(grid, piece, { { 0.0, 0.0, 1.0 } }, 1.0, 1.0, 16);
  for (const float depth : map.Depths)
  {
    EXPECT_TRUE(std::isfinite(depth));
    EXPECT_GE(depth, 0.0f);
  }
  nimbus::CoarseDensityGrid empty;
  EXPECT_FALSE(empty.IsValid());
  EXPECT_EQ(
    nimbus::ComputeExternalShadowMap(empty, piece, { { 0.0, 0.0, 1.0 } }, 1.0, 1.0, 16).Size, 0);
}
