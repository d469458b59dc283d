// Lightning strokes, their point sources, the virtual-light grid and the distribution of
// the sources onto it (Physics/Lightning.h, 003 §3, §5, §7 Eqs. 3, 4, 6), and the Haar
// wavelet compression of 003 §6-7 (Physics/HaarWavelet.h, Eqs. 5, 8, 9).
// Every bound below is either exact (conservation, round trips: rounding only) or set
// from the measured value printed by the test.
#include "HaarWavelet.h"
#include "Lightning.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

namespace
{
using nimbus::LightningParameters;
using nimbus::LightningSegment;
using nimbus::PointLight;
using nimbus::Vector3;

double Distance(const Vector3& a, const Vector3& b)
{
  return nimbus::Length({ { a[0] - b[0], a[1] - b[1], a[2] - b[2] } });
}

Vector3 Unit(const LightningSegment& s)
{
  return nimbus::Normalized({ { s.B[0] - s.A[0], s.B[1] - s.A[1], s.B[2] - s.A[2] } });
}

double TotalEmission(const std::vector<LightningSegment>& segments)
{
  double sum = 0.0;
  for (const LightningSegment& s : segments)
  {
    sum += s.Intensity * Distance(s.A, s.B);
  }
  return sum;
}
} // namespace

// The same parameters give the same stroke bit for bit; another seed another stroke.
TEST(Lightning, DeterministicForASeed)
{
  LightningParameters p;
  p.Seed = 42;
  const auto a = nimbus::GenerateLightning(p);
  const auto b = nimbus::GenerateLightning(p);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i)
  {
    EXPECT_EQ(a[i].A, b[i].A);
    EXPECT_EQ(a[i].B, b[i].B);
    EXPECT_EQ(a[i].Intensity, b[i].Intensity);
  }
  p.Seed = 43;
  const auto c = nimbus::GenerateLightning(p);
  EXPECT_TRUE(c.size() != a.size() || c.back().B != a.back().B);
}

// The main channel is connected, as long as asked, and turns by Hill's 16 degrees on
// average (Straightness 0: the turns are exactly the drawn angles).
TEST(Lightning, MainChannelShape)
{
  LightningParameters p;
  p.Straightness = 0.0;
  p.BranchProbability = 0.0;
  p.Length = 20000.0;
  p.SegmentLength = 10.0;
  const auto segments = nimbus::GenerateLightning(p);
  ASSERT_GT(segments.size(), 1000u);
  double length = 0.0, turn = 0.0;
  for (std::size_t i = 0; i < segments.size(); ++i)
  {
    length += Distance(segments[i].A, segments[i].B);
    EXPECT_EQ(segments[i].Depth, 0);
    if (i > 0)
    {
      EXPECT_EQ(segments[i].A, segments[i - 1].B);
      turn +=
        std::acos(std::clamp(nimbus::Dot(Unit(segments[i]), Unit(segments[i - 1])), -1.0, 1.0));
    }
  }
  const double meanTurn = turn / (segments.size() - 1) / nimbus::kDegree;
  std::printf(
    "  %zu segments, length %.1f m, mean turn %.2f deg\n", segments.size(), length, meanTurn);
  EXPECT_NEAR(length, p.Length, 1e-6 * p.Length);
  // E|N(16, 8)| = 16.37 deg; measured on this seed: within 0.5 deg of it.
  EXPECT_NEAR(meanTurn, 16.37, 0.5);
  // With the default pull the channel keeps its overall direction (down).
  p.Straightness = 0.1;
  const auto pulled = nimbus::GenerateLightning(p);
  const Vector3 end = pulled.back().B;
  EXPECT_LT(end[2], -0.5 * p.Length) << "the channel should head down";
}

// Branches: deeper ones dimmer by BranchIntensityFactor per level, each starts on a
// segment end of a shallower channel, none deeper than MaxBranchDepth.
TEST(Lightning, BranchesDimWithDepth)
{
  LightningParameters p;
  p.BranchProbability = 0.2;
  p.MaxBranchDepth = 3;
  p.Seed = 7;
  const auto segments = nimbus::GenerateLightning(p);
  int deepest = 0;
  for (const LightningSegment& s : segments)
  {
    deepest = std::max(deepest, s.Depth);
    EXPECT_LE(s.Depth, p.MaxBranchDepth);
    EXPECT_DOUBLE_EQ(s.Intensity, p.Intensity * std::pow(p.BranchIntensityFactor, s.Depth));
  }
  EXPECT_GE(deepest, 2) << "with probability 0.2 per segment the stroke should branch twice";
  // Every branch's first segment starts where a shallower segment ends.
  for (std::size_t i = 1; i < segments.size(); ++i)
  {
    if (segments[i].A == segments[i - 1].B)
    {
      continue;
    }
    const bool attached = std::any_of(segments.begin(), segments.begin() + i,
      [&](const LightningSegment& s)
      { return s.B == segments[i].A && s.Depth < segments[i].Depth; });
    EXPECT_TRUE(attached) << "segment " << i << " (depth " << segments[i].Depth << ")";
  }
}

// Channels end at the ground, the main channel on it.
TEST(Lightning, StopsAtTheGround)
{
  LightningParameters p;
  p.Start = { { 0.0, 0.0, 1500.0 } };
  p.Length = 10000.0;
  p.StopBelowHeight = 0.0;
  p.BranchProbability = 0.1;
  const auto segments = nimbus::GenerateLightning(p);
  double lowest = 1e300;
  for (const LightningSegment& s : segments)
  {
    EXPECT_GE(s.A[2], 0.0);
    EXPECT_GE(s.B[2], 0.0);
    lowest = std::min(lowest, s.B[2]);
  }
  EXPECT_EQ(lowest, 0.0);
}

// 003 Eq. 3: the point sources carry the stroke's emission exactly and lie at most a
// spacing apart along each segment.
TEST(Lightning, PointSourcesCarryTheStroke)
{
  LightningParameters p;
  p.BranchProbability = 0.1;
  const auto segments = nimbus::GenerateLightning(p);
  for (double spacing : { 1.0, 7.0, 100.0 })
  {
    const auto sources = nimbus::LightningPointSources(segments, spacing);
    double sum = 0.0;
    for (const PointLight& q : sources)
    {
      sum += q.Intensity[0];
      EXPECT_EQ(q.Intensity[0], q.Intensity[1]);
    }
    EXPECT_NEAR(sum, TotalEmission(segments), 1e-12 * sum) << spacing;
  }
  const auto one =
    nimbus::LightningPointSources({ { { { 0, 0, 0 } }, { { 10, 0, 0 } }, 2.0, 0 } }, 3.0);
  ASSERT_EQ(one.size(), 4u); // ceil(10 / 3)
  EXPECT_DOUBLE_EQ(one[0].Position[0], 1.25);
  EXPECT_DOUBLE_EQ(one[3].Position[0], 8.75);
  EXPECT_DOUBLE_EQ(one[0].Intensity[0], 5.0);
  EXPECT_THROW(nimbus::LightningPointSources(segments, 0.0), std::invalid_argument);
  EXPECT_THROW(nimbus::LightningPointSources(segments, std::nan("")), std::invalid_argument);
}

// Extremes: zero intensity, one segment, a very long stroke: finite, sensible.
TEST(Lightning, Extremes)
{
  LightningParameters p;
  p.Intensity = 0.0;
  const auto dark = nimbus::GenerateLightning(p);
  EXPECT_FALSE(dark.empty());
  EXPECT_TRUE(nimbus::LightningPointSources(dark, 5.0).empty());
  p = LightningParameters();
  p.Length = 1.0;
  p.SegmentLength = 50.0;
  const auto single = nimbus::GenerateLightning(p);
  ASSERT_EQ(single.size(), 1u);
  EXPECT_NEAR(Distance(single[0].A, single[0].B), 1.0, 1e-12);
  p = LightningParameters();
  p.Length = 2.0e5;
  p.SegmentLength = 1.0;
  p.BranchProbability = 0.0;
  const auto along = nimbus::GenerateLightning(p);
  std::printf("  a 200 km stroke of 1 m segments: %zu segments\n", along.size());
  for (const LightningSegment& s : along)
  {
    ASSERT_TRUE(nimbus::IsFinite(s.A) && nimbus::IsFinite(s.B));
  }
  // With branches it would pass a million segments: refused with a message.
  p.BranchProbability = 0.05;
  try
  {
    nimbus::GenerateLightning(p);
    ADD_FAILURE() << "a stroke of more than 1e6 segments was not refused";
  }
  catch (const std::invalid_argument& e)
  {
    EXPECT_NE(std::string(e.what()).find("segments"), std::string::npos) << e.what();
  }
}

// Every kind of bad parameter is refused with a message naming it.
TEST(Lightning, BadParametersRefused)
{
  const double nan = std::nan(""), inf = std::numeric_limits<double>::infinity();
  const std::vector<std::pair<std::string, std::function<void(LightningParameters&)>>> bad = {
    { "Start", [&](LightningParameters& p) { p.Start[1] = nan; } },
    { "Direction",
      [&](LightningParameters& p) {
        p.Direction = { { 0, 0, 0 } };
      } },
    { "Direction", [&](LightningParameters& p) { p.Direction[0] = inf; } },
    { "Length", [&](LightningParameters& p) { p.Length = 0.0; } },
    { "Length", [&](LightningParameters& p) { p.Length = -5.0; } },
    { "SegmentLength", [&](LightningParameters& p) { p.SegmentLength = nan; } },
    { "segments",
      [&](LightningParameters& p)
      {
        p.SegmentLength = 1e-3;
        p.Length = 1e4;
      } },
    { "MeanAngleDegrees", [&](LightningParameters& p) { p.MeanAngleDegrees = 200.0; } },
    { "AngleSpreadDegrees", [&](LightningParameters& p) { p.AngleSpreadDegrees = -1.0; } },
    { "Straightness", [&](LightningParameters& p) { p.Straightness = 1.5; } },
    { "BranchProbability", [&](LightningParameters& p) { p.BranchProbability = nan; } },
    { "BranchAngleDegrees", [&](LightningParameters& p) { p.BranchAngleDegrees = inf; } },
    { "BranchLengthFactor", [&](LightningParameters& p) { p.BranchLengthFactor = 0.0; } },
    { "BranchIntensityFactor", [&](LightningParameters& p) { p.BranchIntensityFactor = 2.0; } },
    { "MaxBranchDepth", [&](LightningParameters& p) { p.MaxBranchDepth = -1; } },
    { "Intensity", [&](LightningParameters& p) { p.Intensity = -1.0; } },
    { "Intensity", [&](LightningParameters& p) { p.Intensity = inf; } },
    { "StopBelowHeight", [&](LightningParameters& p) { p.StopBelowHeight = nan; } },
  };
  for (const auto& [field, spoil] : bad)
  {
    LightningParameters p;
    spoil(p);
    const std::string why = nimbus::CheckLightningParameters(p);
    EXPECT_NE(why.find(field), std::string::npos) << field << ": '" << why << "'";
    EXPECT_THROW(nimbus::GenerateLightning(p), std::invalid_argument) << field;
  }
  EXPECT_EQ(nimbus::CheckLightningParameters(LightningParameters()), "");
}

// 003 §5 Eq. 4: uniform above the cloud bottom and horizontally; below it, each layer
// either the minimum step h_usr or the step that adds epsilon to 1/r^2.
TEST(VirtualLightGrid, Equation4)
{
  nimbus::VirtualLightGridParameters p;
  p.Low = { { 0.0, 0.0, 0.0 } };
  p.High = { { 4000.0, 3000.0, 3000.0 } };
  p.CloudBottom = 2000.0;
  p.BaseInterval = 200.0;
  p.EpsilonRelative = 0.05;
  const nimbus::VirtualLightGrid grid = nimbus::MakeVirtualLightGrid(p);
  EXPECT_EQ(grid.Nodes[0].size(), 21u);
  EXPECT_EQ(grid.Nodes[1].size(), 16u);
  EXPECT_EQ(grid.Nodes[0].front(), 0.0);
  EXPECT_EQ(grid.Nodes[0].back(), 4000.0);
  const std::vector<double>& z = grid.Nodes[2];
  std::printf("  z nodes:");
  for (double v : z)
  {
    std::printf(" %.0f", v);
  }
  std::printf("\n");
  EXPECT_TRUE(std::is_sorted(z.begin(), z.end()));
  EXPECT_EQ(z.front(), 0.0);
  EXPECT_EQ(z.back(), 3000.0);
  const double h = p.BaseInterval, epsilon = p.EpsilonRelative / (h * h);
  std::vector<double> r;
  for (double v : z)
  {
    if (v < p.CloudBottom)
    {
      r.insert(r.begin(), p.CloudBottom - v);
    }
    else if (v > p.CloudBottom)
    {
      EXPECT_NEAR(v - *(std::find(z.begin(), z.end(), v) - 1), 200.0, 1e-9);
    }
  }
  ASSERT_GE(r.size(), 3u);
  EXPECT_NEAR(r[0], h, 1e-9);
  for (std::size_t l = 0; l + 2 < r.size(); ++l) // the last node closes the grid
  {
    const double step = r[l + 1] - r[l];
    const double energy = 1.0 / (r[l] * r[l]) - 1.0 / (r[l + 1] * r[l + 1]);
    EXPECT_GE(step, h - 1e-9);
    EXPECT_TRUE(std::abs(step - h) < 1e-9 || std::abs(energy - epsilon) < 1e-9 * epsilon)
      << "layer " << l << ": step " << step << ", 1/r^2 step " << energy;
  }
  // Coarser below than above: fewer nodes than a uniform grid.
  EXPECT_LT(z.size(), 16u);
}

TEST(VirtualLightGrid, BadParametersRefused)
{
  const double nan = std::nan("");
  const std::vector<std::function<void(nimbus::VirtualLightGridParameters&)>> bad = {
    [&](auto& p) { p.Low[0] = nan; },
    [&](auto& p) { p.High[1] = p.Low[1]; },
    [&](auto& p) { p.CloudBottom = 2.0; },
    [&](auto& p) { p.CloudBottom = nan; },
    [&](auto& p) { p.BaseInterval = 0.0; },
    [&](auto& p) { p.BaseInterval = 1e-5; },
    [&](auto& p) { p.EpsilonRelative = 0.0; },
    [&](auto& p) { p.EpsilonRelative = 1.0; },
  };
  for (std::size_t i = 0; i < bad.size(); ++i)
  {
    nimbus::VirtualLightGridParameters p;
    bad[i](p);
    EXPECT_THROW(nimbus::MakeVirtualLightGrid(p), std::invalid_argument) << "case " << i;
  }
  // The cloud bottom at the box's floor or top: no layers below / one node above.
  nimbus::VirtualLightGridParameters p;
  p.CloudBottom = 0.0;
  EXPECT_EQ(nimbus::MakeVirtualLightGrid(p).Nodes[2].size(), 11u);
  p.CloudBottom = 1.0;
  EXPECT_GE(nimbus::MakeVirtualLightGrid(p).Nodes[2].size(), 3u);
}

// 003 Eq. 6: the trilinear distribution conserves the sources' total (no energy lost,
// sources outside the grid included) and, for sources inside, their first moment.
TEST(VirtualLightGrid, DistributionConservesEnergy)
{
  nimbus::VirtualLightGridParameters p;
  p.Low = { { -1000.0, -1000.0, 0.0 } };
  p.High = { { 1000.0, 1000.0, 2500.0 } };
  p.CloudBottom = 1500.0;
  p.BaseInterval = 250.0;
  const nimbus::VirtualLightGrid grid = nimbus::MakeVirtualLightGrid(p);
  std::mt19937_64 engine(3);
  std::uniform_real_distribution<double> coordinate(-1500.0, 3000.0), intensity(0.0, 5.0);
  for (int trial = 0; trial < 50; ++trial)
  {
    std::vector<PointLight> sources(1 + trial * 7);
    Vector3 moment{ { 0, 0, 0 } };
    double total = 0.0;
    bool inside = true;
    for (PointLight& q : sources)
    {
      q.Position = { { coordinate(engine), coordinate(engine), coordinate(engine) } };
      if (trial % 2 == 0) // even trials: inside the box only
      {
        for (int a = 0; a < 3; ++a)
        {
          q.Position[a] = std::clamp(q.Position[a], p.Low[a], p.High[a]);
        }
      }
      const double w = intensity(engine);
      q.Intensity = { { w, 2.0 * w, 0.5 * w } };
      total += w;
      for (int a = 0; a < 3; ++a)
      {
        moment[a] += w * q.Position[a];
        inside = inside && q.Position[a] >= p.Low[a] && q.Position[a] <= p.High[a];
      }
    }
    const std::vector<nimbus::Rgb> e = nimbus::DistributeToVirtualLights(grid, sources);
    nimbus::Rgb sum{ { 0, 0, 0 } };
    Vector3 distributedMoment{ { 0, 0, 0 } };
    for (std::size_t k = 0; k < grid.Nodes[2].size(); ++k)
      for (std::size_t j = 0; j < grid.Nodes[1].size(); ++j)
        for (std::size_t i = 0; i < grid.Nodes[0].size(); ++i)
        {
          const nimbus::Rgb& v = e[grid.Index(i, j, k)];
          EXPECT_GE(v[0], 0.0);
          for (int c = 0; c < 3; ++c)
          {
            sum[c] += v[c];
          }
          const Vector3 x = grid.Position(i, j, k);
          for (int a = 0; a < 3; ++a)
          {
            distributedMoment[a] += v[0] * x[a];
          }
        }
    EXPECT_NEAR(sum[0], total, 1e-12 * total + 1e-300);
    EXPECT_NEAR(sum[1], 2.0 * total, 2e-12 * total + 1e-300);
    EXPECT_NEAR(sum[2], 0.5 * total, 1e-12 * total + 1e-300);
    if (inside)
    {
      for (int a = 0; a < 3; ++a)
      {
        EXPECT_NEAR(distributedMoment[a], moment[a], 1e-9 * (std::abs(moment[a]) + total * 3000.0));
      }
    }
  }
  // A source on a node lights that node alone.
  const Vector3 node = grid.Position(2, 3, 4);
  const auto e = nimbus::DistributeToVirtualLights(grid, { { node, { { 1.0, 1.0, 1.0 } } } });
  EXPECT_DOUBLE_EQ(e[grid.Index(2, 3, 4)][0], 1.0);
  PointLight broken;
  broken.Position[2] = std::nan("");
  EXPECT_THROW(nimbus::DistributeToVirtualLights(grid, { broken }), std::invalid_argument);
}

// The Haar transform is orthonormal (Parseval), its inverse undoes it, and the codec
// reproduces any field (odd sizes, padding) at xi = 0.
TEST(HaarWavelet, OrthonormalAndInvertible)
{
  std::mt19937_64 engine(11);
  std::normal_distribution<double> normal;
  const std::array<int, 3> padded{ { 8, 4, 16 } };
  std::vector<double> data(8 * 4 * 16);
  for (double& v : data)
  {
    v = normal(engine);
  }
  const std::vector<double> original = data;
  double energy = 0.0, transformed = 0.0;
  for (double v : data)
  {
    energy += v * v;
  }
  nimbus::HaarForward(data, padded);
  for (double v : data)
  {
    transformed += v * v;
  }
  EXPECT_NEAR(transformed, energy, 1e-12 * energy);
  nimbus::HaarInverse(data, padded);
  for (std::size_t i = 0; i < data.size(); ++i)
  {
    EXPECT_NEAR(data[i], original[i], 1e-12);
  }
  for (const std::array<int, 3>& dims : { std::array<int, 3>{ { 5, 3, 7 } },
         std::array<int, 3>{ { 1, 1, 1 } }, std::array<int, 3>{ { 32, 1, 4 } } })
  {
    std::vector<float> values(static_cast<std::size_t>(dims[0]) * dims[1] * dims[2]);
    for (float& v : values)
    {
      v = static_cast<float>(normal(engine));
    }
    const nimbus::SparseHaarField field = nimbus::CompressHaar(values, dims, 0.0);
    std::vector<double> h;
    nimbus::AccumulateHaar(field, 1.0, h);
    const std::vector<double> back = nimbus::ReconstructHaar(h, dims, field.Padded);
    ASSERT_EQ(back.size(), values.size());
    for (std::size_t i = 0; i < back.size(); ++i)
    {
      EXPECT_NEAR(back[i], values[i], 1e-5) << i; // float coefficients
    }
  }
}

// Dropping coefficients below xi changes the (padded) field by exactly the dropped
// norm gamma; the weighted sum in the wavelet domain (Eq. 9) equals the weighted sum
// of the fields; a smooth field (1/r^2 of a light below a cloud grid, 003 §6)
// compresses well. Measured ratios and errors printed.
TEST(HaarWavelet, ThresholdAndWeightedSums)
{
  const std::array<int, 3> dims{ { 32, 32, 4 } };
  const auto field = [&](double lx, double ly, double lz)
  {
    std::vector<float> v(32 * 32 * 4);
    for (int k = 0; k < 4; ++k)
      for (int j = 0; j < 32; ++j)
        for (int i = 0; i < 32; ++i)
        {
          const double r2 = (i - lx) * (i - lx) + (j - ly) * (j - ly) + (k - lz) * (k - lz);
          v[i + 32 * (j + 32 * k)] = static_cast<float>(1.0 / r2);
        }
    return v;
  };
  const std::vector<float> a = field(10.3, 20.7, -3.0), b = field(25.0, 4.5, -6.0);
  double norm = 0.0;
  for (float v : a)
  {
    norm += double(v) * v;
  }
  norm = std::sqrt(norm);
  std::printf("  xi / max   kept    ratio   L2 error / L2 norm   gamma / L2 norm\n");
  for (double xi : { 0.0, 1e-5, 1e-4, 1e-3, 1e-2 })
  {
    const nimbus::SparseHaarField c = nimbus::CompressHaar(a, dims, xi * 0.111);
    std::vector<double> h;
    nimbus::AccumulateHaar(c, 1.0, h);
    const std::vector<double> back = nimbus::ReconstructHaar(h, dims, c.Padded);
    double error = 0.0;
    for (std::size_t i = 0; i < back.size(); ++i)
    {
      error += (back[i] - a[i]) * (back[i] - a[i]);
    }
    error = std::sqrt(error);
    std::printf("  %-8g %6zu  %6.1f  %.3e            %.3e\n", xi, c.Index.size(),
      double(a.size()) / std::max<std::size_t>(c.Index.size(), 1), error / norm,
      c.DroppedNorm / norm);
    // The dims are powers of two: no padding, so the error is the dropped norm
    // (float storage adds ~1e-7 relative).
    EXPECT_NEAR(error, c.DroppedNorm, 1e-6 * norm) << xi;
    EXPECT_NEAR(c.AmbientPerPoint(), c.DroppedNorm / std::sqrt(32.0 * 32.0 * 4.0), 1e-15);
  }
  // Eq. 9 then Eq. 8 = the weighted sum of the fields (xi = 0).
  const nimbus::SparseHaarField ca = nimbus::CompressHaar(a, dims, 0.0);
  const nimbus::SparseHaarField cb = nimbus::CompressHaar(b, dims, 0.0);
  std::vector<double> h;
  nimbus::AccumulateHaar(ca, 0.25, h);
  nimbus::AccumulateHaar(cb, 3.0, h);
  const std::vector<double> sum = nimbus::ReconstructHaar(h, dims, ca.Padded);
  for (std::size_t i = 0; i < sum.size(); ++i)
  {
    EXPECT_NEAR(sum[i], 0.25 * a[i] + 3.0 * b[i], 1e-6 * (0.25 * a[i] + 3.0 * b[i]));
  }
  // Measured at xi = 1e-3 of the largest value: 1731 of 4096 kept (2.4x) for an L2
  // error of 0.21 %; bound: fewer than half kept.
  const nimbus::SparseHaarField smooth = nimbus::CompressHaar(a, dims, 1e-3 * 0.111);
  EXPECT_LT(smooth.Index.size(), a.size() / 2);
}

TEST(HaarWavelet, BadInputRefused)
{
  EXPECT_THROW(nimbus::HaarPaddedDimensions({ { 0, 4, 4 } }), std::invalid_argument);
  EXPECT_THROW(
    nimbus::HaarPaddedDimensions({ { 1 << 12, 1 << 12, 1 << 12 } }), std::invalid_argument);
  std::vector<double> d(12);
  EXPECT_THROW(nimbus::HaarForward(d, { { 3, 2, 2 } }), std::invalid_argument);
  EXPECT_THROW(nimbus::HaarForward(d, { { 4, 4, 1 } }), std::invalid_argument);
  std::vector<float> v(8, 1.0f);
  EXPECT_THROW(nimbus::CompressHaar(v, { { 2, 2, 3 } }, 0.0), std::invalid_argument);
  EXPECT_THROW(nimbus::CompressHaar(v, { { 2, 2, 2 } }, -1.0), std::invalid_argument);
  EXPECT_THROW(nimbus::CompressHaar(v, { { 2, 2, 2 } }, std::nan("")), std::invalid_argument);
  v[3] = std::numeric_limits<float>::infinity();
  EXPECT_THROW(nimbus::CompressHaar(v, { { 2, 2, 2 } }, 0.0), std::invalid_argument);
  // xi huge: nothing kept, all of it in gamma.
  std::vector<float> ones(8, 1.0f);
  const nimbus::SparseHaarField none = nimbus::CompressHaar(ones, { { 2, 2, 2 } }, 1e30);
  EXPECT_TRUE(none.Index.empty());
  EXPECT_NEAR(none.DroppedNorm, std::sqrt(8.0), 1e-12);
  EXPECT_NEAR(none.AmbientPerPoint(), 1.0, 1e-12); // the constant 1 back as the ambient
}

// The flash over time: nothing before it, the leader's glow reaching the far end at
// LeaderDuration, the return stroke on every channel, the subsequent strokes on the
// main channel only, each weaker, all decayed by the flash's duration.
TEST(Lightning, FlashTimeline)
{
  LightningParameters p;
  p.BranchProbability = 0.15;
  p.Seed = 5;
  const auto segments = nimbus::GenerateLightning(p);
  double farthest = 0.0;
  const LightningSegment* branch = nullptr;
  for (const LightningSegment& s : segments)
  {
    farthest = std::max(farthest, s.PathStart);
    if (s.Depth > 0 && !branch)
    {
      branch = &s;
    }
  }
  ASSERT_NE(branch, nullptr);
  // Path lengths: the main channel's grow by each segment's length from 0.
  EXPECT_EQ(segments[0].PathStart, 0.0);
  EXPECT_NEAR(segments[1].PathStart, Distance(segments[0].A, segments[0].B), 1e-9);
  const nimbus::LightningFlashTimeline t;
  const LightningSegment& first = segments.front();
  const LightningSegment& last = *std::max_element(segments.begin(), segments.end(),
    [](const LightningSegment& a, const LightningSegment& b) { return a.PathStart < b.PathStart; });
  EXPECT_EQ(nimbus::LightningFlashBrightness(t, first, farthest, -0.01), 0.0);
  EXPECT_DOUBLE_EQ(nimbus::LightningFlashBrightness(t, first, farthest, 0.001), t.LeaderBrightness);
  EXPECT_EQ(nimbus::LightningFlashBrightness(t, last, farthest, 0.5 * t.LeaderDuration), 0.0);
  const double stroke = t.LeaderDuration;
  EXPECT_DOUBLE_EQ(nimbus::LightningFlashBrightness(t, first, farthest, stroke), 1.0);
  EXPECT_DOUBLE_EQ(nimbus::LightningFlashBrightness(t, *branch, farthest, stroke), 1.0);
  const double second = stroke + t.InterstrokeInterval;
  const double decayed = std::exp(-t.InterstrokeInterval / t.StrokeDecaySeconds);
  EXPECT_NEAR(nimbus::LightningFlashBrightness(t, first, farthest, second),
    decayed + t.SubsequentStrokeFactor, 1e-12);
  EXPECT_NEAR(nimbus::LightningFlashBrightness(t, *branch, farthest, second), decayed, 1e-12);
  const double end = nimbus::LightningFlashDuration(t);
  const double lastStrength = std::pow(t.SubsequentStrokeFactor, t.NumberOfStrokes - 1);
  EXPECT_LE(
    nimbus::LightningFlashBrightness(t, first, farthest, end), 0.0101 * lastStrength + 1e-3);
  nimbus::LightningFlashTimeline bad;
  bad.NumberOfStrokes = 0;
  EXPECT_THROW(nimbus::LightningFlashBrightness(bad, first, farthest, 0.1), std::invalid_argument);
  bad = nimbus::LightningFlashTimeline();
  bad.StrokeDecaySeconds = std::nan("");
  EXPECT_NE(nimbus::CheckLightningFlashTimeline(bad).find("StrokeDecaySeconds"), std::string::npos);
}

// The glow (003 §8): a point source's single-scattered radiance against the integral
// along the ray, and a straight channel of point sources against the line source's
// closed form (sigma_s I' / 2) acosh(R / d) with every glow cut at radius R.
TEST(Lightning, GlowOfPointAndLine)
{
  const double sigma = 1e-3, intensity = 50.0;
  for (double b : { 1.0, 10.0, 100.0 })
  {
    // sigma / (4 pi) I / (b^2 + s^2) over s in [-1e7 b, 1e7 b], midpoint rule in atan.
    double sum = 0.0;
    const int n = 20000;
    const double limit = std::atan(1e7);
    for (int i = 0; i < n; ++i)
    {
      const double theta = -limit + (i + 0.5) * 2.0 * limit / n; // s = b tan(theta)
      const double s = b * std::tan(theta);
      const double ds = b / (std::cos(theta) * std::cos(theta)) * 2.0 * limit / n;
      sum += sigma / (4.0 * M_PI) * intensity / (b * b + s * s) * ds;
    }
    EXPECT_NEAR(nimbus::LightningGlowRadiance(sigma, intensity, b), sum, 1e-6 * sum) << b;
  }
  EXPECT_EQ(nimbus::LightningGlowRadiance(sigma, intensity, 0.0), 0.0);
  EXPECT_EQ(nimbus::LightningGlowRadiance(sigma, intensity, std::nan("")), 0.0);
  EXPECT_EQ(nimbus::LightningGlowRadiance(std::nan(""), intensity, 1.0), 0.0);

  // A channel along x of I' = 100 per metre as sources 0.5 m apart, each glow cut at
  // R = 300 m, seen by a ray passing at distance d (the ray along y through (0, d, 0)
  // reaches each source at b = sqrt(x^2 + d^2)).
  const double perMetre = 100.0, spacing = 0.5, radius = 300.0;
  for (double d : { 5.0, 30.0, 150.0 })
  {
    double glow = 0.0;
    for (double x = -radius; x <= radius; x += spacing)
    {
      const double b = std::hypot(x, d);
      if (b <= radius)
      {
        glow += nimbus::LightningGlowRadiance(sigma, perMetre * spacing, b);
      }
    }
    const double line = 0.5 * sigma * perMetre * std::acosh(radius / d);
    EXPECT_NEAR(glow, line, 0.01 * line) << d; // the sum's rule: < 1 % at these spacings
  }
}
