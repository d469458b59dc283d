// MajorantGrid (Reference/Core/MajorantGrid.h): block counts and geometry, block maxima
// equal to the largest grid value over the block's (dilated) points, the maximum
// bounds the trilinear density over the block (dilation 0) and one voxel around it
// (dilation 1), exact empty flags (the flags the single-scattering renderer computed
// point by point before), one-point axes, one-voxel, all-zero and constant grids.
#include "DensityGrid.h"
#include "MajorantGrid.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdio>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

namespace
{
using nimbus::DensityGrid;
using nimbus::MajorantGrid;
using nimbus::Vector3;

constexpr int kB = MajorantGrid::BlockVoxels;

/// A grid with non-zero values only in a few random boxes (so that some blocks are
/// empty, some partly filled), random values in [0, 2) there, some of them 0.
DensityGrid RandomGrid(const std::array<int, 3>& dims, std::mt19937& rng)
{
  std::uniform_real_distribution<float> value(0.0f, 2.0f);
  std::vector<float> values(static_cast<std::size_t>(dims[0]) * dims[1] * dims[2], 0.0f);
  const int boxes = std::uniform_int_distribution<int>(0, 4)(rng);
  for (int b = 0; b < boxes; ++b)
  {
    int lo[3], hi[3];
    for (int a = 0; a < 3; ++a)
    {
      std::uniform_int_distribution<int> point(0, dims[a] - 1);
      lo[a] = point(rng);
      hi[a] = std::min(dims[a] - 1, lo[a] + std::uniform_int_distribution<int>(0, 3)(rng));
    }
    for (int k = lo[2]; k <= hi[2]; ++k)
      for (int j = lo[1]; j <= hi[1]; ++j)
        for (int i = lo[0]; i <= hi[0]; ++i)
        {
          const float v = value(rng);
          values[i +
            static_cast<std::size_t>(dims[0]) * (j + static_cast<std::size_t>(dims[1]) * k)] =
            v < 0.3f ? 0.0f : v;
        }
  }
  const Vector3 origin{ { -3.0, 10.0, 1000.0 } };
  const Vector3 spacing{ { 0.5, 1.25, 3.0 } };
  return DensityGrid(dims, origin, spacing, values);
}

/// Points [first, last] of block b along an axis of n points, widened by d.
std::array<int, 2> PointRange(int n, int b, int d)
{
  if (n == 1)
  {
    return { { 0, 0 } };
  }
  return { { std::max(0, kB * b - d), std::min(n - 1, kB * b + kB + d) } };
}

/// Largest grid value over the points of block (i, j, k) widened by d (brute force).
float BruteMaximum(const DensityGrid& grid, const std::array<int, 3>& block, int d)
{
  const std::array<int, 3>& n = grid.GetDimensions();
  std::array<std::array<int, 2>, 3> r;
  for (int a = 0; a < 3; ++a)
  {
    r[a] = PointRange(n[a], block[a], d);
  }
  float m = 0.0f;
  for (int k = r[2][0]; k <= r[2][1]; ++k)
    for (int j = r[1][0]; j <= r[1][1]; ++j)
      for (int i = r[0][0]; i <= r[0][1]; ++i)
      {
        m = std::max(m,
          grid.GetValues()[i +
            static_cast<std::size_t>(n[0]) * (j + static_cast<std::size_t>(n[1]) * k)]);
      }
  return m;
}

/// The empty flags as the single-scattering renderer computed them before
/// MajorantGrid: every non-zero point clears the blocks it belongs to (a point on a
/// block face belongs to both).
std::vector<unsigned char> PointByPointEmptyFlags(const DensityGrid& grid)
{
  const std::array<int, 3>& dims = grid.GetDimensions();
  int blocks[3];
  for (int a = 0; a < 3; ++a)
  {
    blocks[a] = (std::max(1, dims[a] - 1) + kB - 1) / kB;
  }
  std::vector<unsigned char> empty(static_cast<std::size_t>(blocks[0]) * blocks[1] * blocks[2], 1);
  const std::size_t nx = dims[0], nxy = nx * dims[1];
  for (int k = 0; k < dims[2]; ++k)
    for (int j = 0; j < dims[1]; ++j)
      for (int i = 0; i < dims[0]; ++i)
      {
        if (grid.GetValues()[i + j * nx + k * nxy] == 0.0f)
        {
          continue;
        }
        const int p[3] = { i, j, k };
        int lo[3], hi[3];
        for (int a = 0; a < 3; ++a)
        {
          const int last = blocks[a] - 1;
          lo[a] = std::min(last, std::max(0, (p[a] - 1) / kB));
          hi[a] = std::min(last, p[a] / kB);
          if (p[a] > 0 && p[a] % kB != 0)
          {
            lo[a] = hi[a];
          }
        }
        for (int c = lo[2]; c <= hi[2]; ++c)
          for (int b = lo[1]; b <= hi[1]; ++b)
            for (int a = lo[0]; a <= hi[0]; ++a)
            {
              empty[(static_cast<std::size_t>(c) * blocks[1] + b) * blocks[0] + a] = 0;
            }
      }
  return empty;
}

/// A random point of the box of points [first, last] per axis (the grid's box along
/// an axis with one point).
Vector3 RandomPointIn(
  const DensityGrid& grid, const std::array<std::array<int, 2>, 3>& range, std::mt19937& rng)
{
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Vector3 p;
  for (int a = 0; a < 3; ++a)
  {
    if (grid.GetDimensions()[a] == 1)
    {
      p[a] = grid.GetLower()[a] + u(rng) * (grid.GetUpper()[a] - grid.GetLower()[a]);
      continue;
    }
    // Now and then exactly on a face or a grid plane.
    const int pick = std::uniform_int_distribution<int>(0, 9)(rng);
    double x = range[a][0] + u(rng) * (range[a][1] - range[a][0]);
    if (pick == 0)
    {
      x = range[a][0];
    }
    else if (pick == 1)
    {
      x = range[a][1];
    }
    else if (pick == 2)
    {
      x = std::uniform_int_distribution<int>(range[a][0], range[a][1])(rng);
    }
    p[a] = grid.GetOrigin()[a] + x * grid.GetSpacing()[a];
  }
  return p;
}

/// Blocks (dilation 0) seen empty and not empty, and samples with density > 0, over
/// all CheckGrid calls: the random grids must exercise both kinds of block.
struct Tally
{
  int Empty = 0, NonEmpty = 0, PositiveSamples = 0;
};
Tally tally;

void CheckGrid(const DensityGrid& grid, std::mt19937& rng, int samplesPerBlock)
{
  const std::array<int, 3>& n = grid.GetDimensions();
  const std::vector<unsigned char> oldFlags = PointByPointEmptyFlags(grid);
  for (const int dilation : { 0, 1, 2 })
  {
    const MajorantGrid majorants(grid, dilation);
    const std::array<int, 3>& blocks = majorants.GetBlocks();
    for (int a = 0; a < 3; ++a)
    {
      ASSERT_EQ(blocks[a], n[a] == 1 ? 1 : (n[a] - 1 + kB - 1) / kB);
      EXPECT_EQ(majorants.GetLower()[a], grid.GetLower()[a]);
      EXPECT_EQ(majorants.GetBlockSize()[a],
        n[a] == 1 ? grid.GetUpper()[a] - grid.GetLower()[a] : kB * grid.GetSpacing()[a]);
    }
    for (int k = 0; k < blocks[2]; ++k)
      for (int j = 0; j < blocks[1]; ++j)
        for (int i = 0; i < blocks[0]; ++i)
        {
          const std::size_t index = majorants.GetIndex(i, j, k);
          ASSERT_EQ(index,
            static_cast<std::size_t>(i) +
              static_cast<std::size_t>(blocks[0]) * (j + static_cast<std::size_t>(blocks[1]) * k));
          const std::string where = "block (" + std::to_string(i) + ", " + std::to_string(j) +
            ", " + std::to_string(k) + "), dilation " + std::to_string(dilation);
          const double maximum = majorants.GetMaximum(index);
          EXPECT_EQ(maximum, static_cast<double>(BruteMaximum(grid, { { i, j, k } }, dilation)))
            << where;
          EXPECT_EQ(majorants.IsEmpty(index), maximum == 0.0) << where;
          if (dilation == 0)
          {
            EXPECT_EQ(majorants.IsEmpty(index), oldFlags[index] != 0) << where;
            ++(majorants.IsEmpty(index) ? tally.Empty : tally.NonEmpty);
          }
          // The maximum bounds the trilinear density over the block widened by
          // `dilation` voxels (clipped to the grid).
          std::array<std::array<int, 2>, 3> range;
          for (int a = 0; a < 3; ++a)
          {
            range[a] = PointRange(n[a], std::array<int, 3>{ { i, j, k } }[a], dilation);
          }
          for (int s = 0; s < samplesPerBlock; ++s)
          {
            const Vector3 p = RandomPointIn(grid, range, rng);
            const double density = grid.Sample(p);
            ASSERT_LE(density, maximum) << where;
            tally.PositiveSamples += density > 0.0 ? 1 : 0;
            if (majorants.IsEmpty(index))
            {
              ASSERT_EQ(density, 0.0) << where;
            }
          }
        }
  }
}
} // namespace

TEST(MajorantGrid, BlockCounts)
{
  // Voxels n - 1 in blocks of 4, the last one shorter; one block for one point.
  const std::array<std::array<int, 2>, 10> expected{ { { { 1, 1 } }, { { 2, 1 } }, { { 4, 1 } },
    { { 5, 1 } }, { { 6, 2 } }, { { 8, 2 } }, { { 9, 2 } }, { { 10, 3 } }, { { 13, 3 } },
    { { 14, 4 } } } };
  for (const auto& e : expected)
  {
    const DensityGrid grid({ { e[0], 3, 1 } }, { { 0.0, 0.0, 0.0 } }, { { 1.0, 1.0, 1.0 } },
      std::vector<float>(static_cast<std::size_t>(e[0]) * 3, 1.0f));
    for (const int dilation : { 0, 1 })
    {
      const MajorantGrid majorants(grid, dilation);
      EXPECT_EQ(majorants.GetBlocks()[0], e[1]) << e[0] << " points";
      EXPECT_EQ(majorants.GetBlocks()[1], 1);
      EXPECT_EQ(majorants.GetBlocks()[2], 1);
    }
  }
}

TEST(MajorantGrid, EmptyGridAndBadDilation)
{
  const MajorantGrid none(DensityGrid(), 1);
  EXPECT_EQ(none.GetBlocks()[0] * none.GetBlocks()[1] * none.GetBlocks()[2], 0);
  const DensityGrid grid = DensityGrid::Constant({ { 0, 0, 0 } }, { { 1, 1, 1 } }, 1.0f);
  EXPECT_THROW(MajorantGrid(grid, -1), std::invalid_argument);
}

TEST(MajorantGrid, RandomGrids)
{
  std::mt19937 rng(12345);
  const std::array<int, 3> sizes[] = { { { 2, 2, 2 } }, { { 5, 5, 5 } }, { { 9, 6, 7 } },
    { { 13, 10, 3 } }, { { 17, 4, 11 } }, { { 1, 7, 9 } }, { { 6, 1, 5 } }, { { 10, 9, 1 } },
    { { 1, 1, 12 } }, { { 1, 1, 1 } } };
  for (const auto& dims : sizes)
  {
    for (int trial = 0; trial < 6; ++trial)
    {
      SCOPED_TRACE(std::to_string(dims[0]) + "x" + std::to_string(dims[1]) + "x" +
        std::to_string(dims[2]) + " trial " + std::to_string(trial));
      CheckGrid(RandomGrid(dims, rng), rng, 40);
    }
  }
  EXPECT_GT(tally.Empty, 100);
  EXPECT_GT(tally.NonEmpty, 100);
  EXPECT_GT(tally.PositiveSamples, 1000);
  std::printf("blocks: %d empty, %d not empty; %d samples with density > 0\n", tally.Empty,
    tally.NonEmpty, tally.PositiveSamples);
}

TEST(MajorantGrid, OneNonZeroPointClearsExactlyTheBlocksItTouches)
{
  // 9 x 9 x 9 points: 2 x 2 x 2 blocks. A single point inside block 0, on the face
  // between blocks 0 and 1, and at the far corner.
  const std::array<int, 3> dims{ { 9, 9, 9 } };
  struct Case
  {
    std::array<int, 3> Point;
    std::vector<std::array<int, 3>> NonEmpty;
  };
  const std::vector<Case> cases = {
    { { { 1, 2, 3 } }, { { { 0, 0, 0 } } } },
    { { { 4, 1, 1 } }, { { { 0, 0, 0 } }, { { 1, 0, 0 } } } },
    { { { 4, 4, 0 } }, { { { 0, 0, 0 } }, { { 1, 0, 0 } }, { { 0, 1, 0 } }, { { 1, 1, 0 } } } },
    { { { 8, 8, 8 } }, { { { 1, 1, 1 } } } },
    { { { 0, 0, 0 } }, { { { 0, 0, 0 } } } },
  };
  for (const Case& c : cases)
  {
    std::vector<float> values(9 * 9 * 9, 0.0f);
    values[c.Point[0] + 9 * (c.Point[1] + 9 * c.Point[2])] = 0.75f;
    const DensityGrid grid(dims, { { 0, 0, 0 } }, { { 1, 1, 1 } }, values);
    const MajorantGrid majorants(grid, 0);
    for (int k = 0; k < 2; ++k)
      for (int j = 0; j < 2; ++j)
        for (int i = 0; i < 2; ++i)
        {
          const bool touched = std::find(c.NonEmpty.begin(), c.NonEmpty.end(),
                                 std::array<int, 3>{ { i, j, k } }) != c.NonEmpty.end();
          const std::size_t index = majorants.GetIndex(i, j, k);
          EXPECT_EQ(majorants.IsEmpty(index), !touched)
            << "point " << c.Point[0] << "," << c.Point[1] << "," << c.Point[2] << " block " << i
            << "," << j << "," << k;
          EXPECT_EQ(majorants.GetMaximum(index), touched ? 0.75 : 0.0);
        }
    // With dilation 1 every block sees the point if it is within one point of it.
    const MajorantGrid dilated(grid, 1);
    for (int k = 0; k < 2; ++k)
      for (int j = 0; j < 2; ++j)
        for (int i = 0; i < 2; ++i)
        {
          bool near = true;
          const int b[3] = { i, j, k };
          for (int a = 0; a < 3; ++a)
          {
            near = near && c.Point[a] >= kB * b[a] - 1 && c.Point[a] <= kB * b[a] + kB + 1;
          }
          EXPECT_EQ(dilated.GetMaximum(dilated.GetIndex(i, j, k)), near ? 0.75 : 0.0);
        }
  }
}

TEST(MajorantGrid, AllZeroAndConstantGrids)
{
  std::mt19937 rng(7);
  for (const auto& dims : { std::array<int, 3>{ { 7, 5, 10 } }, std::array<int, 3>{ { 1, 1, 1 } },
         std::array<int, 3>{ { 2, 2, 2 } }, std::array<int, 3>{ { 1, 6, 1 } } })
  {
    const std::size_t count = static_cast<std::size_t>(dims[0]) * dims[1] * dims[2];
    for (const float value : { 0.0f, 1.5f })
    {
      const DensityGrid grid(
        dims, { { 5, 6, 7 } }, { { 2, 3, 4 } }, std::vector<float>(count, value));
      for (const int dilation : { 0, 1 })
      {
        const MajorantGrid majorants(grid, dilation);
        const std::array<int, 3>& blocks = majorants.GetBlocks();
        for (std::size_t index = 0;
             index < static_cast<std::size_t>(blocks[0]) * blocks[1] * blocks[2]; ++index)
        {
          EXPECT_EQ(majorants.GetMaximum(index), static_cast<double>(value));
          EXPECT_EQ(majorants.IsEmpty(index), value == 0.0f);
        }
      }
      CheckGrid(grid, rng, 20);
    }
  }
}

TEST(MajorantGrid, OneVoxelGrid)
{
  // DensityGrid::Constant: 2 points per axis, one voxel, one block of that size.
  const DensityGrid grid =
    DensityGrid::Constant({ { -100, -200, 1000 } }, { { 300, 200, 1500 } }, 0.25f);
  const MajorantGrid majorants(grid, 1);
  EXPECT_EQ(majorants.GetBlocks(), (std::array<int, 3>{ { 1, 1, 1 } }));
  EXPECT_EQ(majorants.GetMaximum(0), 0.25);
  EXPECT_FALSE(majorants.IsEmpty(0));
  EXPECT_EQ(majorants.GetBlockSize()[0], 4 * 400.0);
  EXPECT_EQ(majorants.GetLower()[2], 1000.0);
}

// Other block sizes (the path tracer measured 2, 4 and 8): counts ceil((n - 1) / B), the
// maximum over each block's points [B c, min(n - 1, B c + B)] per axis, which bounds the
// trilinear density anywhere in the block; B < 1 is refused.
TEST(MajorantGrid, OtherBlockSizes)
{
  std::mt19937 rng(777);
  const std::array<int, 3> dims{ { 11, 7, 9 } };
  const DensityGrid grid = RandomGrid(dims, rng);
  const std::vector<float>& values = grid.GetValues();
  for (const int b : { 1, 2, 3, 5, 8, 20 })
  {
    SCOPED_TRACE("block size " + std::to_string(b));
    const MajorantGrid majorants(grid, 0, b);
    const std::array<int, 3>& blocks = majorants.GetBlocks();
    for (int a = 0; a < 3; ++a)
    {
      ASSERT_EQ(blocks[a], (dims[a] - 1 + b - 1) / b);
      EXPECT_DOUBLE_EQ(majorants.GetBlockSize()[a], b * grid.GetSpacing()[a]);
    }
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    for (int k = 0; k < blocks[2]; ++k)
      for (int j = 0; j < blocks[1]; ++j)
        for (int i = 0; i < blocks[0]; ++i)
        {
          const int c[3] = { i, j, k };
          float brute = 0.0f;
          for (int z = b * k; z <= std::min(dims[2] - 1, b * k + b); ++z)
            for (int y = b * j; y <= std::min(dims[1] - 1, b * j + b); ++y)
              for (int x = b * i; x <= std::min(dims[0] - 1, b * i + b); ++x)
                brute = std::max(brute, values[x + dims[0] * (y + dims[1] * z)]);
          const double maximum = majorants.GetMaximum(majorants.GetIndex(i, j, k));
          EXPECT_EQ(maximum, static_cast<double>(brute));
          for (int s = 0; s < 20; ++s)
          {
            Vector3 p;
            for (int a = 0; a < 3; ++a)
            {
              const double lo = b * c[a], hi = std::min(dims[a] - 1, b * c[a] + b);
              p[a] = grid.GetOrigin()[a] + (lo + unit(rng) * (hi - lo)) * grid.GetSpacing()[a];
            }
            ASSERT_LE(grid.Sample(p), maximum);
          }
        }
  }
  EXPECT_THROW(MajorantGrid(grid, 0, 0), std::invalid_argument);
  EXPECT_THROW(MajorantGrid(grid, 0, -3), std::invalid_argument);
}
