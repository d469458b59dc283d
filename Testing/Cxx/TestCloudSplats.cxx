// The numerics of billboard splatting (Representations/Splats/CloudSplats.h, 002 §3.3):
// the kernel against the metaball cloud's, the closed-form columns against a numerical
// integral of the kernel, the textures, the sorting and the sun pass's layer counts.
#include "CloudSplats.h"
#include "Metaballs.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <random>
#include <stdexcept>
#include <vector>

namespace
{
// The kernel integrated along the line at impact parameter u from t0 to t1 (units of R),
// composite Simpson's rule on 2000 intervals (the kernel is a smooth polynomial inside).
double NumericalColumn(double u, double t0, double t1)
{
  const int n = 2000;
  const double h = (t1 - t0) / n;
  double sum = 0.0;
  for (int i = 0; i <= n; ++i)
  {
    const double t = t0 + i * h;
    const double w = (i == 0 || i == n) ? 1.0 : (i % 2 ? 4.0 : 2.0);
    sum += w * nimbus::WyvillFalloff(u * u + t * t, 1.0);
  }
  return sum * h / 3.0;
}
}

TEST(CloudSplats, KernelIsTheMetaballCloudsKernel)
{
  for (double q = 0.0; q <= 1.2; q += 0.01)
  {
    EXPECT_NEAR(nimbus::SplatKernel(q), nimbus::WyvillFalloff(q, 1.0), 1e-14) << "q " << q;
  }
}

TEST(CloudSplats, ColumnAgainstNumericalIntegral)
{
  EXPECT_NEAR(nimbus::SplatColumn(0.0), 944.0 / 945.0, 1e-14);
  for (double u = 0.0; u < 1.0; u += 0.037)
  {
    const double s = std::sqrt(1.0 - u * u);
    EXPECT_NEAR(nimbus::SplatColumn(u), NumericalColumn(u, -s, s), 1e-10) << "u " << u;
  }
  EXPECT_EQ(nimbus::SplatColumn(1.0), 0.0);
  EXPECT_EQ(nimbus::SplatColumn(1.5), 0.0);
  EXPECT_NEAR(nimbus::SplatColumn(0.999), 0.0, 1e-6); // continuous at the rim
}

TEST(CloudSplats, PartialColumnAgainstNumericalIntegral)
{
  for (double u = 0.0; u < 1.0; u += 0.11)
  {
    const double s = std::sqrt(1.0 - u * u);
    for (double h = -1.2; h <= 1.2; h += 0.1)
    {
      const double end = std::clamp(h, -s, s);
      EXPECT_NEAR(nimbus::SplatPartialColumn(u, h), NumericalColumn(u, -s, end), 1e-10)
        << "u " << u << " h " << h;
    }
    // Half of the column lies in front of the centre plane.
    EXPECT_NEAR(nimbus::SplatPartialColumn(u, 0.0), 0.5 * nimbus::SplatColumn(u), 1e-14);
  }
}

TEST(CloudSplats, BallMassFromColumns)
{
  // The integral of the column over the billboard's disc is the ball's mass:
  // 4 pi integral_0^1 f(r^2) r^2 dr = 4 pi (1/3 - 22/45 + 17/63 - 4/81) = 4 pi 32/2835 ... x R^3.
  const double exact = 4.0 * M_PI * (1.0 / 3.0 - 22.0 / 45.0 + 17.0 / 63.0 - 4.0 / 81.0);
  const int n = 4000;
  double sum = 0.0;
  for (int i = 0; i < n; ++i)
  {
    const double u = (i + 0.5) / n;
    sum += 2.0 * M_PI * u * nimbus::SplatColumn(u) / n;
  }
  EXPECT_NEAR(sum, exact, 1e-6);
}

TEST(CloudSplats, Textures)
{
  const int size = 32;
  const std::vector<float> texture = nimbus::SplatColumnTexture(size, 4);
  ASSERT_EQ(texture.size(), static_cast<std::size_t>(size * size));
  // The texels' mean x the square's area = the ball's mass (units of R^3), to the
  // texel averages' supersampling.
  double mass = 0.0;
  for (float value : texture)
  {
    mass += value * (2.0 / size) * (2.0 / size);
  }
  const double exact = 4.0 * M_PI * (1.0 / 3.0 - 22.0 / 45.0 + 17.0 / 63.0 - 4.0 / 81.0);
  EXPECT_NEAR(mass, exact, 2e-3 * exact);
  // Symmetric, highest at the centre, 0 in the corners.
  EXPECT_FLOAT_EQ(texture[0], 0.0f);
  EXPECT_FLOAT_EQ(texture[5 * size + 7], texture[7 * size + 5]);
  EXPECT_FLOAT_EQ(texture[5 * size + 7], texture[(size - 1 - 5) * size + (size - 1 - 7)]);
  EXPECT_GT(texture[(size / 2) * size + size / 2], 0.95f);

  const std::vector<float> table = nimbus::SplatPartialColumnTable(9, 5);
  ASSERT_EQ(table.size(), 45u);
  EXPECT_FLOAT_EQ(table[0], 0.0f);                               // u 0, h -1
  EXPECT_NEAR(table[2 * 9], 0.5 * 944.0 / 945.0, 1e-7);          // u 0, h 0
  EXPECT_NEAR(table[4 * 9 + 4], nimbus::SplatColumn(0.5), 1e-7); // u 0.5, h 1
  EXPECT_THROW(nimbus::SplatPartialColumnTable(1, 5), std::invalid_argument);
}

TEST(CloudSplats, Sorting)
{
  std::mt19937 random(7);
  std::uniform_real_distribution<float> uniform(-100.0f, 100.0f);
  std::vector<float> centres(3 * 500);
  for (float& c : centres)
  {
    c = uniform(random);
  }
  const std::array<double, 3> direction = { 0.6, 0.0, -0.8 };
  std::vector<float> offsets(500);
  for (float& o : offsets)
  {
    o = uniform(random);
  }
  const auto order = nimbus::SplatOrder(centres, direction, offsets);
  ASSERT_EQ(order.size(), 500u);
  auto key = [&](std::uint32_t i)
  {
    return direction[0] * centres[3 * i] + direction[1] * centres[3 * i + 1] +
      direction[2] * centres[3 * i + 2] + offsets[i];
  };
  for (std::size_t n = 1; n < order.size(); ++n)
  {
    EXPECT_LE(key(order[n - 1]), key(order[n]));
  }
  const std::array<double, 3> eye = { 10.0, -300.0, 50.0 };
  const auto backToFront = nimbus::SplatOrderBackToFront(centres, eye);
  auto distance = [&](std::uint32_t i)
  {
    const double dx = centres[3 * i] - eye[0], dy = centres[3 * i + 1] - eye[1],
                 dz = centres[3 * i + 2] - eye[2];
    return dx * dx + dy * dy + dz * dz;
  };
  for (std::size_t n = 1; n < backToFront.size(); ++n)
  {
    EXPECT_GE(distance(backToFront[n - 1]), distance(backToFront[n]));
  }
  EXPECT_THROW(nimbus::SplatOrder(centres, direction, { 1.0f }), std::invalid_argument);
}

TEST(CloudSplats, FrameAndLayers)
{
  const std::array<double, 3> axis = { 0.48, -0.6, 0.64 };
  const auto frame = nimbus::SplatFrame(axis);
  for (int a = 0; a < 3; ++a)
  {
    for (int b = 0; b < 3; ++b)
    {
      const double dot =
        frame[a][0] * frame[b][0] + frame[a][1] * frame[b][1] + frame[a][2] * frame[b][2];
      EXPECT_NEAR(dot, a == b ? 1.0 : 0.0, 1e-12);
    }
  }
  // Fronts 0, 1, ..., 9 (diameters at most 2); planes at 0, 3, 6, 9: slab k takes the
  // fronts in [z_{k-1} - 2, z_k).
  std::vector<float> fronts;
  for (int i = 0; i < 10; ++i)
  {
    fronts.push_back(static_cast<float>(i));
  }
  const auto ranges = nimbus::SplatLayerRanges(fronts, 0.0, 9.0, 4, 2.0);
  ASSERT_EQ(ranges.size(), 4u);
  EXPECT_EQ(ranges[0][0], ranges[0][1]); // the first plane: nothing before it
  EXPECT_EQ(ranges[1][0], 0u);
  EXPECT_EQ(ranges[1][1], 3u);
  EXPECT_EQ(ranges[2][0], 1u);
  EXPECT_EQ(ranges[2][1], 6u);
  EXPECT_EQ(ranges[3][0], 4u);
  EXPECT_EQ(ranges[3][1], 9u);
  // Every ball crossing a slab lies in its range (random fronts and diameters).
  std::mt19937 random(3);
  std::uniform_real_distribution<float> uniform(0.0f, 100.0f), diameter(0.0f, 7.0f);
  std::vector<std::pair<float, float>> balls(300);
  for (auto& b : balls)
  {
    b = { uniform(random), diameter(random) };
  }
  std::sort(balls.begin(), balls.end());
  std::vector<float> sorted;
  for (const auto& b : balls)
  {
    sorted.push_back(b.first);
  }
  const int layers = 17;
  const auto r = nimbus::SplatLayerRanges(sorted, 0.0, 110.0, layers, 7.0);
  for (int k = 1; k < layers; ++k)
  {
    const double z = 110.0 * k / (layers - 1), previous = 110.0 * (k - 1) / (layers - 1);
    for (std::size_t n = 0; n < balls.size(); ++n)
    {
      const bool crosses = balls[n].first < z && balls[n].first + balls[n].second > previous;
      if (crosses)
      {
        EXPECT_TRUE(n >= r[k][0] && n < r[k][1]) << "layer " << k << " ball " << n;
      }
    }
  }
}

// The point samples of one ball, d f at the points of a lattice of spacing h, miss its
// mass by the kernel's discretisation error; SplatBallsOntoGrid rescales each ball to its
// exact mass. Measured here (random centres, 200 balls per ratio): the worst relative
// error of the plain point sum is below 2e-2 at R = h, 2e-3 at R = 2 h, 1e-4 at R = 4 h.
TEST(CloudSplats, PointSamplesDiscretisationError)
{
  std::mt19937 random(7);
  std::uniform_real_distribution<double> offset(0.0, 1.0);
  const double exact = nimbus::SplatBallVolume();
  EXPECT_NEAR(exact, 4.0 * M_PI * 0.064903, 1e-5);
  const double ratios[3] = { 1.0, 2.0, 4.0 };
  const double bounds[3] = { 0.6, 0.02, 0.0015 };
  for (int r = 0; r < 3; ++r)
  {
    const double radius = ratios[r]; // in units of the spacing
    double worst = 0.0;
    for (int trial = 0; trial < 200; ++trial)
    {
      const double c[3] = { offset(random), offset(random), offset(random) };
      double sum = 0.0;
      const int n = static_cast<int>(radius) + 2;
      for (int k = -n; k <= n; ++k)
      {
        for (int j = -n; j <= n; ++j)
        {
          for (int i = -n; i <= n; ++i)
          {
            const double q =
              ((i - c[0]) * (i - c[0]) + (j - c[1]) * (j - c[1]) + (k - c[2]) * (k - c[2])) /
              (radius * radius);
            sum += nimbus::SplatKernel(q);
          }
        }
      }
      worst = std::max(worst, std::abs(sum / (radius * radius * radius) / exact - 1.0));
    }
    EXPECT_LT(worst, bounds[r]) << "R / h " << radius;
    std::cout << "R / h " << radius << ": worst relative mass error of the point samples " << worst
              << "\n";
  }
}

// The grid's mass (sum of density x cell volume) is the balls' (d R^3 SplatBallVolume),
// big balls and balls smaller than a cell alike; the grid covers them and a big ball's
// shape is the kernel's.
TEST(CloudSplats, GridConservesMass)
{
  std::mt19937 random(3);
  std::uniform_real_distribution<double> position(-1000.0, 1000.0);
  std::uniform_real_distribution<double> size(5.0, 300.0);
  std::vector<float> centres, radii, densities;
  double mass = 0.0;
  for (int b = 0; b < 500; ++b)
  {
    centres.insert(centres.end(),
      { static_cast<float>(position(random)), static_cast<float>(position(random)),
        static_cast<float>(0.4 * position(random)) });
    radii.push_back(static_cast<float>(size(random)));
    densities.push_back(static_cast<float>(0.1 + 0.001 * b));
    mass += static_cast<double>(densities.back()) * radii.back() * radii.back() * radii.back() *
      nimbus::SplatBallVolume();
  }
  for (int side : { 8, 32, 64 })
  {
    const nimbus::SplatDensityGrid grid =
      nimbus::SplatBallsOntoGrid(centres, radii, densities, side);
    EXPECT_EQ(std::max({ grid.Dimensions[0], grid.Dimensions[1], grid.Dimensions[2] }), side);
    double sum = 0.0;
    for (float d : grid.Density)
    {
      EXPECT_GE(d, 0.0f);
      sum += d;
    }
    const double cell = grid.Spacing * grid.Spacing * grid.Spacing;
    EXPECT_NEAR(sum * cell / mass, 1.0, 1e-5) << "side " << side;
    for (int a = 0; a < 3; ++a)
    {
      EXPECT_LE(grid.Origin[a], -1000.0 * (a == 2 ? 0.4 : 1.0) - 300.0 + 1e-6);
    }
  }
  // One ball of radius 4 spacings: the samples are d f(q) to the rescaling (0.12 %).
  const std::vector<float> one = { 10.0f, 20.0f, 30.0f };
  const nimbus::SplatDensityGrid grid = nimbus::SplatBallsOntoGrid(one, { 100.0f }, { 0.5f }, 11);
  EXPECT_NEAR(grid.Spacing, 25.0, 1e-9);
  double peak = 0.0;
  for (int k = 0; k < grid.Dimensions[2]; ++k)
  {
    for (int j = 0; j < grid.Dimensions[1]; ++j)
    {
      for (int i = 0; i < grid.Dimensions[0]; ++i)
      {
        const double x[3] = { grid.Origin[0] + i * grid.Spacing - 10.0,
          grid.Origin[1] + j * grid.Spacing - 20.0, grid.Origin[2] + k * grid.Spacing - 30.0 };
        const double expected =
          0.5 * nimbus::SplatKernel((x[0] * x[0] + x[1] * x[1] + x[2] * x[2]) / 1e4);
        const float value =
          grid.Density[(static_cast<std::size_t>(k) * grid.Dimensions[1] + j) * grid.Dimensions[0] +
            i];
        EXPECT_NEAR(value, expected, 0.0015 * 0.5);
        peak = std::max(peak, static_cast<double>(value));
      }
    }
  }
  EXPECT_GT(peak, 0.45);
  EXPECT_THROW(nimbus::SplatBallsOntoGrid(one, { 1.0f }, {}, 32), std::invalid_argument);
  EXPECT_TRUE(nimbus::SplatBallsOntoGrid({}, {}, {}, 32).Density.empty());
}
