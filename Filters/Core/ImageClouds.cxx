#include "ImageClouds.h"

#include "Random.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace nimbus
{

double IntensityToOpticalDepth(double intensity, const OpticalDepthMapping& mapping)
{
  const double span = mapping.WhiteIntensity - mapping.ClearIntensity;
  if (!(span > 0.0))
  {
    throw std::invalid_argument("OpticalDepthMapping: WhiteIntensity must be > ClearIntensity.");
  }
  if (!(mapping.MaximumOpticalDepth >= 0.0) || !std::isfinite(mapping.MaximumOpticalDepth))
  {
    throw std::invalid_argument("OpticalDepthMapping: MaximumOpticalDepth must be finite, >= 0.");
  }
  if (std::isnan(intensity))
  {
    return 0.0; // no data: clear sky
  }
  const double u = std::clamp((intensity - mapping.ClearIntensity) / span, 0.0, 1.0);
  switch (mapping.Type)
  {
    case OpticalDepthMapping::Kind::Linear:
      if (!(mapping.Gamma > 0.0) || !std::isfinite(mapping.Gamma))
      {
        throw std::invalid_argument("OpticalDepthMapping: Gamma must be finite and > 0.");
      }
      return mapping.MaximumOpticalDepth * std::pow(u, mapping.Gamma);
    case OpticalDepthMapping::Kind::TwoStream:
    {
      const double g = mapping.AsymmetryParameter;
      if (!(g >= 0.0 && g < 1.0))
      {
        throw std::invalid_argument("OpticalDepthMapping: AsymmetryParameter must be in [0, 1).");
      }
      // R = (1-g) tau / (2 + (1-g) tau)  <=>  tau = 2 R / ((1-g)(1-R)); u = 1 is infinitely thick.
      if (u >= 1.0)
      {
        return mapping.MaximumOpticalDepth;
      }
      return std::min(mapping.MaximumOpticalDepth, 2.0 * u / ((1.0 - g) * (1.0 - u)));
    }
  }
  return 0.0;
}

std::vector<double> ColumnOpticalDepth(
  const GridGeometry& grid, const std::vector<float>& density, double extinctionCoefficient)
{
  const int nx = grid.Dimensions[0], ny = grid.Dimensions[1], nz = grid.Dimensions[2];
  const std::size_t plane = static_cast<std::size_t>(nx) * ny;
  if (density.size() != plane * nz)
  {
    throw std::invalid_argument("ColumnOpticalDepth: the density does not fit the grid.");
  }
  std::vector<double> tau(plane, 0.0);
  for (int z = 0; z < nz; ++z)
  {
    const float* layer = density.data() + plane * z;
    for (std::size_t i = 0; i < plane; ++i)
    {
      tau[i] += layer[i];
    }
  }
  const double scale = extinctionCoefficient * grid.Spacing[2];
  for (double& t : tau)
  {
    t *= scale;
  }
  return tau;
}

namespace
{
constexpr double HorizontalJitter = 1.0 / 3.0; // of a block, each way
constexpr int MaximumBallsPerColumn = 30;
constexpr double MaximumDensityFactor = 1.0e6; // ball density <= this * NominalDensity
constexpr double MaximumLayers = 4096.0;
constexpr double MaximumGridPoints = 2.0e9;

void Require(bool condition, const char* message)
{
  if (!condition)
  {
    throw std::invalid_argument(message);
  }
}

// A column of balls standing on one site (a BallSpacing x BallSpacing block of pixels).
struct Site
{
  int X0, Y0, X1, Y1; // pixel block [X0, X1) x [Y0, Y1)
  int SiteX, SiteY;   // the block's centre pixel
  double Target;      // mean target optical depth over the block
  std::size_t FirstBall, EndBall;
};

double BlockMean(const std::vector<double>& values, int nx, const Site& site)
{
  double sum = 0.0;
  for (int y = site.Y0; y < site.Y1; ++y)
  {
    for (int x = site.X0; x < site.X1; ++x)
    {
      sum += values[static_cast<std::size_t>(x) + static_cast<std::size_t>(nx) * y];
    }
  }
  return sum / ((site.X1 - site.X0) * (site.Y1 - site.Y0));
}
}

GridGeometry ImageCloudGrid(
  int nx, int ny, double maximumOpticalDepth, const ImageCloudParameters& p)
{
  Require(nx >= 1 && ny >= 1, "BuildImageCloud: the image must have at least 1 x 1 pixels.");
  Require(p.PixelSize >= 1.0e-3 && p.PixelSize <= 1.0e6,
    "PixelSize must be between 1e-3 and 1e6 m (a millimetre to 1000 km per pixel).");
  Require(p.VerticalSpacing >= 1.0e-3 && p.VerticalSpacing <= 1.0e6,
    "VerticalSpacing must be between 1e-3 and 1e6 m.");
  Require(p.ExtinctionCoefficient > 0.0 && p.ExtinctionCoefficient <= 1.0e3,
    "ExtinctionCoefficient must be > 0 and at most 1e3 1/m (clouds: about 0.01 to 0.1 1/m).");
  Require(p.NominalDensity > 0.0 && p.NominalDensity <= 1.0e6,
    "NominalDensity must be > 0 and at most 1e6.");
  Require(std::abs(p.BaseHeight) <= 1.0e8, "BaseHeight must be finite, within +-1e8 m.");
  Require(p.BaseTransitionThickness >= 0.0 && p.BaseTransitionThickness <= 1.0e8,
    "BaseTransitionThickness must be between 0 and 1e8 m.");
  Require(static_cast<double>(std::max(nx, ny)) * p.PixelSize <= 2.0e8,
    "The image is wider than 2e8 m (pixels times PixelSize); lower PixelSize.");
  Require(p.BallSpacing >= 1, "BallSpacing must be >= 1 pixel.");
  Require(p.BallSpacing <= 1 << 20, "BallSpacing must be at most 2^20 pixels.");
  Require(p.BallRadiusFactor > 0.0 && p.BallRadiusFactor <= 1.0e3,
    "BallRadiusFactor must be > 0 and at most 1e3.");
  Require(p.TopRoughness >= 0.0 && p.TopRoughness <= 1.0, "TopRoughness must be in [0, 1].");
  Require(p.MinimumOpticalDepth >= 0.0 && std::isfinite(p.MinimumOpticalDepth),
    "MinimumOpticalDepth must be finite and >= 0.");
  Require(p.Iterations >= 0 && p.Iterations <= 10000, "Iterations must be in [0, 10000].");
  Require(p.GridOpticalDepth >= 0.0 && std::isfinite(p.GridOpticalDepth),
    "GridOpticalDepth must be finite and >= 0.");
  Require(maximumOpticalDepth >= 0.0 && std::isfinite(maximumOpticalDepth),
    "BuildImageCloud: optical depths must be finite, >= 0.");

  const double radius = p.BallRadiusFactor * p.BallSpacing * p.PixelSize; // m
  const double maxThickness = std::max(maximumOpticalDepth, p.GridOpticalDepth) /
    (p.ExtinctionCoefficient * p.NominalDensity); // m
  // x, y: pixels centred on 0; z from one layer below the base to above the highest
  // possible top (thickness + rough top ball).
  GridGeometry grid;
  grid.Dimensions = { { nx, ny, 1 } };
  grid.Spacing = { { p.PixelSize, p.PixelSize, p.VerticalSpacing } };
  grid.Origin = { { -0.5 * (nx - 1) * p.PixelSize, -0.5 * (ny - 1) * p.PixelSize,
    p.BaseHeight - p.VerticalSpacing } };
  const double top =
    p.BaseHeight + std::max(maxThickness, radius) + radius * (1.0 + p.TopRoughness);
  const double layers = std::ceil((top - grid.Origin[2]) / p.VerticalSpacing) + 1.0;
  if (!(layers <= MaximumLayers))
  {
    std::ostringstream message;
    message << "BuildImageCloud: the cloud would need " << layers << " layers, more than "
            << MaximumLayers << " (thickness " << maxThickness << " m and balls of radius "
            << radius << " m at a vertical spacing of " << p.VerticalSpacing
            << " m); raise VerticalSpacing, ExtinctionCoefficient or NominalDensity, or lower "
               "the maximum optical depth or BallRadiusFactor.";
    throw std::invalid_argument(message.str());
  }
  const double points = static_cast<double>(nx) * ny * layers;
  if (!(points <= MaximumGridPoints))
  {
    std::ostringstream message;
    message << "BuildImageCloud: the grid would have " << nx << " x " << ny << " x " << layers
            << " = " << points << " points, more than " << MaximumGridPoints << "; the image ("
            << nx << " x " << ny
            << " pixels) is too large: shrink it first (e.g. ParaView's Resample To Image), or "
               "raise VerticalSpacing if the layers are many.";
    throw std::invalid_argument(message.str());
  }
  grid.Dimensions[2] = static_cast<int>(layers);
  return grid;
}

double MaximumImageCloudBalls(
  int nx, int ny, double maximumOpticalDepth, const ImageCloudParameters& p)
{
  const GridGeometry grid = ImageCloudGrid(nx, ny, maximumOpticalDepth, p); // validates
  (void)grid;
  const double s = p.BallSpacing;
  const double sites = std::ceil(nx / s) * std::ceil(ny / s);
  const double radius = p.BallRadiusFactor * p.BallSpacing * p.PixelSize;
  const double thickness = std::max(maximumOpticalDepth, p.GridOpticalDepth) /
    (p.ExtinctionCoefficient * p.NominalDensity);
  const double perColumn = std::min(static_cast<double>(MaximumBallsPerColumn),
    2.0 + std::ceil(std::max(0.0, thickness - 0.5 * radius) / (0.5 * radius)));
  return sites * perColumn;
}

ImageCloud BuildImageCloud(const std::vector<double>& opticalDepth, int nx, int ny,
  const ImageCloudParameters& p, const ProgressCallback& progress)
{
  Require(opticalDepth.size() == static_cast<std::size_t>(nx < 0 ? 0 : nx) * (ny < 0 ? 0 : ny),
    "BuildImageCloud: the optical-depth map must have nx * ny values.");
  double maxTau = 0.0;
  for (const double t : opticalDepth)
  {
    Require(t >= 0.0 && std::isfinite(t), "BuildImageCloud: optical depths must be finite, >= 0.");
    maxTau = std::max(maxTau, t);
  }
  ImageCloud cloud;
  cloud.Grid = ImageCloudGrid(nx, ny, maxTau, p);
  const GridGeometry& grid = cloud.Grid;
  cloud.Density.assign(grid.NumberOfPoints(), 0.0f);
  const double sigma = p.ExtinctionCoefficient;
  const double rho = p.NominalDensity;
  const double radius = p.BallRadiusFactor * p.BallSpacing * p.PixelSize; // m

  // Ball columns.
  Random random(p.Seed);
  std::vector<Site> sites;
  auto& balls = cloud.Balls;
  const int s = p.BallSpacing;
  for (int y0 = 0; y0 < ny; y0 += s)
  {
    for (int x0 = 0; x0 < nx; x0 += s)
    {
      Site site{ x0, y0, std::min(nx, x0 + s), std::min(ny, y0 + s), 0, 0, 0.0, 0, 0 };
      site.SiteX = (site.X0 + site.X1 - 1) / 2;
      site.SiteY = (site.Y0 + site.Y1 - 1) / 2;
      site.Target = BlockMean(opticalDepth, nx, site);
      // Draw the random numbers of every site, used or not, so a site's balls do not
      // depend on which other sites are cloudy.
      double jitter[64];
      for (double& j : jitter)
      {
        j = random.Uniform(-1.0, 1.0);
      }
      if (!(site.Target > p.MinimumOpticalDepth))
      {
        continue;
      }
      const double thickness = site.Target / (sigma * rho);
      const double zFirst = p.BaseHeight + 0.5 * std::min(radius, thickness);
      const double zLast = std::max(zFirst, p.BaseHeight + thickness - 0.5 * radius);
      const int count = static_cast<int>(std::min(static_cast<double>(MaximumBallsPerColumn),
        1.0 + std::ceil((zLast - zFirst) / (0.5 * radius))));
      const double cx = grid.Origin[0] + (0.5 * (site.X0 + site.X1) - 0.5) * p.PixelSize;
      const double cy = grid.Origin[1] + (0.5 * (site.Y0 + site.Y1) - 0.5) * p.PixelSize;
      site.FirstBall = balls.size();
      for (int k = 0; k < count; ++k)
      {
        Metaball ball;
        const double z = count > 1 ? zFirst + (zLast - zFirst) * k / (count - 1) : zFirst;
        // Sideways jitter of a third of a block; the top ball of a column of two or more
        // also moves up or down and changes size by TopRoughness (the bumpy top). A
        // single-ball column (a thin cloud) stays smooth: its one ball sets the whole
        // column's optical depth, and jittering it would ripple the thin cloud's tau.
        ball.Center = { { cx + HorizontalJitter * s * p.PixelSize * jitter[2 * k],
          cy + HorizontalJitter * s * p.PixelSize * jitter[2 * k + 1], z } };
        ball.Radius = radius;
        if (k == count - 1 && count > 1)
        {
          ball.Center[2] += 0.5 * p.TopRoughness * radius * jitter[62];
          ball.Radius *= 1.0 + p.TopRoughness * jitter[63];
        }
        ball.Density = rho;
        balls.push_back(ball);
      }
      site.EndBall = balls.size();
      sites.push_back(site);
    }
  }

  // Fit: rescale each column's balls by target / achieved optical depth over its block.
  // Progress: each of the Iterations + 1 samplings is an equal part.
  const int passes = (sites.empty() ? 0 : p.Iterations) + 1;
  int pass = 0;
  auto sample = [&]()
  {
    ProgressCallback within;
    if (progress)
    {
      within = [&](double f) { return progress((pass + f) / passes); };
    }
    if (!SampleMetaballs(balls, grid, cloud.Density, within))
    {
      return false;
    }
    ApplyCloudBase(grid, p.BaseHeight, p.BaseTransitionThickness, cloud.Density);
    cloud.ColumnOpticalDepth = ColumnOpticalDepth(grid, cloud.Density, sigma);
    ++pass;
    return !progress || progress(static_cast<double>(pass) / passes);
  };
  const auto stopped = [&cloud]()
  {
    cloud.Complete = false;
    return cloud;
  };
  if (!sample())
  {
    return stopped();
  }
  const double maximumDensity = MaximumDensityFactor * rho;
  for (int iteration = 0; iteration < p.Iterations && !sites.empty(); ++iteration)
  {
    for (const Site& site : sites)
    {
      const double achieved = BlockMean(cloud.ColumnOpticalDepth, nx, site);
      const double factor = achieved > 0.0 ? std::clamp(site.Target / achieved, 0.1, 10.0) : 10.0;
      for (std::size_t b = site.FirstBall; b < site.EndBall; ++b)
      {
        // A column whose balls reach no grid point (or only below the base) never
        // achieves anything; without the cap its density would grow 10x per iteration.
        balls[b].Density = std::min(balls[b].Density * factor, maximumDensity);
      }
    }
    if (!sample())
    {
      return stopped();
    }
  }
  return cloud;
}

} // namespace nimbus
