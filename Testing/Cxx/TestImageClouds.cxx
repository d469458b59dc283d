// Tests of clouds from a 2-D image (002 §3): the intensity -> optical depth mappings, and
// metaball clouds whose column optical depth matches a synthetic image of discs.
#include "ImageClouds.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <stdexcept>
#include <vector>

using nimbus::OpticalDepthMapping;

TEST(ImageCloudMapping, LinearAndTwoStream)
{
  OpticalDepthMapping linear;
  linear.ClearIntensity = 0.2;
  linear.WhiteIntensity = 0.9;
  linear.MaximumOpticalDepth = 40.0;
  EXPECT_EQ(nimbus::IntensityToOpticalDepth(0.1, linear), 0.0); // darker than clear sky
  EXPECT_EQ(nimbus::IntensityToOpticalDepth(0.2, linear), 0.0);
  EXPECT_NEAR(nimbus::IntensityToOpticalDepth(0.55, linear), 20.0, 1e-12); // halfway
  EXPECT_NEAR(nimbus::IntensityToOpticalDepth(0.9, linear), 40.0, 1e-12);
  EXPECT_NEAR(nimbus::IntensityToOpticalDepth(1.0, linear), 40.0, 1e-12); // clamped
  linear.Gamma = 2.0;
  EXPECT_NEAR(nimbus::IntensityToOpticalDepth(0.55, linear), 10.0, 1e-12);
  EXPECT_EQ(nimbus::IntensityToOpticalDepth(std::nan(""), linear), 0.0);

  OpticalDepthMapping twoStream;
  twoStream.Type = OpticalDepthMapping::Kind::TwoStream;
  twoStream.ClearIntensity = 0.0;
  twoStream.WhiteIntensity = 1.0;
  twoStream.AsymmetryParameter = 0.85;
  twoStream.MaximumOpticalDepth = 100.0;
  // Hand-worked: u = 0.5 -> tau = 2 * 0.5 / (0.15 * 0.5) = 13.333...
  EXPECT_NEAR(nimbus::IntensityToOpticalDepth(0.5, twoStream), 40.0 / 3.0, 1e-12);
  // Round trip through the two-stream reflectance R = (1-g) tau / (2 + (1-g) tau).
  for (const double u : { 0.01, 0.2, 0.6, 0.85 })
  {
    const double tau = nimbus::IntensityToOpticalDepth(u, twoStream);
    EXPECT_NEAR(0.15 * tau / (2.0 + 0.15 * tau), u, 1e-12);
  }
  EXPECT_EQ(nimbus::IntensityToOpticalDepth(1.0, twoStream), 100.0); // capped, finite
  EXPECT_EQ(nimbus::IntensityToOpticalDepth(0.999999, twoStream), 100.0);

  OpticalDepthMapping bad;
  bad.WhiteIntensity = bad.ClearIntensity;
  EXPECT_THROW(nimbus::IntensityToOpticalDepth(0.5, bad), std::invalid_argument);
}

namespace
{
struct Disc
{
  double X, Y, Radius, Tau; // pixels, pixels, pixels, optical depth
};

// The synthetic "satellite" image: discs of known optical depth on clear sky, given as
// intensities through the linear mapping, then mapped back, as the filter does.
std::vector<double> DiscOpticalDepths(
  int nx, int ny, const std::vector<Disc>& discs, const OpticalDepthMapping& mapping)
{
  std::vector<double> tau(static_cast<std::size_t>(nx) * ny);
  for (int y = 0; y < ny; ++y)
  {
    for (int x = 0; x < nx; ++x)
    {
      double intensity = 0.05; // sea
      for (const Disc& d : discs)
      {
        if (std::hypot(x - d.X, y - d.Y) < d.Radius)
        {
          intensity = mapping.ClearIntensity +
            d.Tau / mapping.MaximumOpticalDepth * (mapping.WhiteIntensity - mapping.ClearIntensity);
        }
      }
      tau[x + nx * y] = nimbus::IntensityToOpticalDepth(intensity, mapping);
    }
  }
  return tau;
}
}

TEST(ImageCloud, ColumnOpticalDepthMatchesTheDiscs)
{
  const int nx = 100, ny = 80;
  const std::vector<Disc> discs = { { 24, 24, 18, 4.0 }, { 70, 26, 20, 15.0 },
    { 45, 60, 17, 30.0 } };
  OpticalDepthMapping mapping; // linear, clear 0.1, white 1, tau_max 30
  const std::vector<double> target = DiscOpticalDepths(nx, ny, discs, mapping);
  nimbus::ImageCloudParameters parameters; // 100 m pixels, balls every 2 px, R = 600 m
  const nimbus::ImageCloud cloud = nimbus::BuildImageCloud(target, nx, ny, parameters);
  const auto& grid = cloud.Grid;
  const int nz = grid.Dimensions[2];
  ASSERT_EQ(cloud.Density.size(), static_cast<std::size_t>(nx) * ny * nz);
  // Recompute the column optical depth from the density itself (do not trust the struct).
  const std::vector<double> tau =
    nimbus::ColumnOpticalDepth(grid, cloud.Density, parameters.ExtinctionCoefficient);
  // Interior of each disc: farther than one ball radius plus one block (6 + 2 px) from the
  // edge, where the image is uniform over every ball's reach.
  const double reach =
    parameters.BallRadiusFactor * parameters.BallSpacing + parameters.BallSpacing;
  std::vector<double> topHeights(discs.size());
  for (std::size_t n = 0; n < discs.size(); ++n)
  {
    const Disc& d = discs[n];
    double worst = 0.0, sumSquares = 0.0, topSum = 0.0, topSquares = 0.0;
    int count = 0, baseLayer = -1;
    bool flatBase = true;
    for (int y = 0; y < ny; ++y)
      for (int x = 0; x < nx; ++x)
        if (std::hypot(x - d.X, y - d.Y) < d.Radius - reach)
        {
          const double error = tau[x + nx * y] / d.Tau - 1.0;
          worst = std::max(worst, std::abs(error));
          sumSquares += error * error;
          ++count;
          // Lowest layer with density, and the top: highest layer above half the column's peak.
          int lowest = -1, highest = -1;
          float peak = 0.0f;
          for (int z = 0; z < nz; ++z)
            peak = std::max(peak, cloud.Density[x + nx * (y + ny * z)]);
          for (int z = 0; z < nz; ++z)
          {
            const float v = cloud.Density[x + nx * (y + ny * z)];
            if (v > 0.0f && lowest < 0)
              lowest = z;
            if (v > 0.5f * peak)
              highest = z;
          }
          flatBase = flatBase && (baseLayer < 0 || lowest == baseLayer);
          baseLayer = lowest;
          const double top = grid.Origin[2] + highest * grid.Spacing[2];
          topSum += top;
          topSquares += top * top;
        }
    ASSERT_GT(count, 100);
    const double rms = std::sqrt(sumSquares / count);
    const double topMean = topSum / count;
    const double topSpread = std::sqrt(std::max(0.0, topSquares / count - topMean * topMean));
    std::cout << "disc tau " << d.Tau << ": " << count << " interior columns, relative error of "
              << "the column optical depth: max " << worst << ", rms " << rms << "; top " << topMean
              << " m +- " << topSpread << " m\n";
    // Measured with the defaults: max 0.035 / 0.047 / 0.034, rms 0.013 / 0.015 / 0.011
    // (tau 4 / 15 / 30); the ripple comes from the discrete, jittered ball columns.
    EXPECT_LT(worst, 0.06) << "tau " << d.Tau;
    EXPECT_LT(rms, 0.02) << "tau " << d.Tau;
    // Flat base: every interior column starts in the same layer, just above the base.
    EXPECT_TRUE(flatBase) << "tau " << d.Tau;
    EXPECT_EQ(grid.Origin[2] + baseLayer * grid.Spacing[2] > parameters.BaseHeight, true);
    EXPECT_LE(
      grid.Origin[2] + baseLayer * grid.Spacing[2], parameters.BaseHeight + grid.Spacing[2]);
    topHeights[n] = topMean;
    if (d.Tau >= 15.0)
    {
      // Bumpy top (the base above is flat, spread 0). Measured: 25.6 m (tau 15), 49.6 m (30).
      EXPECT_GT(topSpread, 15.0) << "a bumpy top, tau " << d.Tau;
    }
  }
  // Thicker clouds rise higher (thickness ~ tau / (sigma rho): 200, 750, 1500 m).
  EXPECT_LT(topHeights[0], topHeights[1]);
  EXPECT_LT(topHeights[1], topHeights[2]);
  // Clear sky beyond every disc's reach: exactly no cloud.
  for (int y = 0; y < ny; ++y)
    for (int x = 0; x < nx; ++x)
    {
      bool far = true;
      for (const Disc& d : discs)
        far = far && std::hypot(x - d.X, y - d.Y) > d.Radius + reach + 1;
      if (far)
      {
        ASSERT_EQ(tau[x + nx * y], 0.0) << x << " " << y;
      }
    }
  // Nothing below the base.
  for (int z = 0; z < nz; ++z)
  {
    if (grid.Origin[2] + z * grid.Spacing[2] <= parameters.BaseHeight)
    {
      for (int i = 0; i < nx * ny; ++i)
      {
        ASSERT_EQ(cloud.Density[i + static_cast<std::size_t>(nx) * ny * z], 0.0f);
      }
    }
  }
}

TEST(ImageCloud, ExtremesAndErrors)
{
  nimbus::ImageCloudParameters parameters;
  // All clear: an empty (all-zero) cloud, no balls.
  const nimbus::ImageCloud clear =
    nimbus::BuildImageCloud(std::vector<double>(12, 0.0), 4, 3, parameters);
  EXPECT_TRUE(clear.Balls.empty());
  for (float v : clear.Density)
    ASSERT_EQ(v, 0.0f);
  // One pixel.
  const nimbus::ImageCloud one = nimbus::BuildImageCloud({ 10.0 }, 1, 1, parameters);
  EXPECT_FALSE(one.Balls.empty());
  EXPECT_GT(one.ColumnOpticalDepth[0], 0.0);
  EXPECT_TRUE(std::isfinite(one.ColumnOpticalDepth[0]));
  // Bad input.
  EXPECT_THROW(nimbus::BuildImageCloud({ 1.0, -1.0 }, 2, 1, parameters), std::invalid_argument);
  EXPECT_THROW(nimbus::BuildImageCloud({ 1.0 }, 2, 1, parameters), std::invalid_argument);
  EXPECT_THROW(nimbus::BuildImageCloud({ std::nan("") }, 1, 1, parameters), std::invalid_argument);
  auto p = parameters;
  p.PixelSize = 0.0;
  EXPECT_THROW(nimbus::BuildImageCloud({ 1.0 }, 1, 1, p), std::invalid_argument);
  // An absurd thickness is refused, not allocated: tau 1e6 at sigma 0.02 is 5e7 m.
  EXPECT_THROW(nimbus::BuildImageCloud({ 1.0e6 }, 1, 1, parameters), std::invalid_argument);
}

TEST(ImageCloud, GridMessagesNameTheRealCause)
{
  nimbus::ImageCloudParameters parameters;
  auto message = [&](int nx, int ny, double tau)
  {
    try
    {
      nimbus::ImageCloudGrid(nx, ny, tau, parameters);
    }
    catch (const std::invalid_argument& error)
    {
      return std::string(error.what());
    }
    return std::string();
  };
  // A 40000 x 40000 image of a thin cloud: few layers, too many points. This said "would
  // need 52 layers ... raise VerticalSpacing" before.
  const std::string large = message(40000, 40000, 30.0);
  EXPECT_NE(large.find("40000 x 40000"), std::string::npos) << large;
  EXPECT_NE(large.find("too large"), std::string::npos) << large;
  EXPECT_EQ(large.find("layers, more than"), std::string::npos) << large;
  // A thick cloud on a small image: the layers are the problem.
  const std::string thick = message(8, 8, 1.0e6);
  EXPECT_NE(thick.find("layers, more than 4096"), std::string::npos) << thick;
  // Values beyond the ranges, NaN and infinities name the parameter.
  for (const double bad : { 0.0, -1.0, 1e-300, 1e308, HUGE_VAL, std::nan("") })
  {
    parameters = nimbus::ImageCloudParameters();
    parameters.PixelSize = bad;
    EXPECT_NE(message(8, 8, 1.0).find("PixelSize"), std::string::npos) << bad;
    parameters = nimbus::ImageCloudParameters();
    parameters.VerticalSpacing = bad;
    EXPECT_NE(message(8, 8, 1.0).find("VerticalSpacing"), std::string::npos) << bad;
  }
  parameters = nimbus::ImageCloudParameters();
  parameters.BaseHeight = 1e308;
  EXPECT_NE(message(8, 8, 1.0).find("BaseHeight"), std::string::npos);
}

TEST(ImageCloud, ColumnsThatAchieveNothingStayFinite)
{
  // The base transition covers the whole cloud (weights near 0): the fit multiplied the
  // densities by 10 per iteration without bound; they are capped at 1e6 NominalDensity.
  nimbus::ImageCloudParameters parameters;
  parameters.BaseTransitionThickness = 1.0e8;
  parameters.Iterations = 100;
  const nimbus::ImageCloud cloud =
    nimbus::BuildImageCloud(std::vector<double>(16, 20.0), 4, 4, parameters);
  for (const nimbus::Metaball& ball : cloud.Balls)
  {
    ASSERT_LE(ball.Density, 1.0e6 * parameters.NominalDensity);
  }
  for (const float v : cloud.Density)
  {
    ASSERT_TRUE(std::isfinite(v) && v >= 0.0f) << v;
  }
}
