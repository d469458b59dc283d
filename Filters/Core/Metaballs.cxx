#include "Metaballs.h"

#include "Random.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace nimbus
{

double WyvillFalloff(double distanceSquared, double radiusSquared)
{
  if (!(distanceSquared < radiusSquared))
  {
    return 0.0;
  }
  const double q = distanceSquared / radiusSquared; // (r/R)^2
  // 1 - 22/9 q + 17/9 q^2 - 4/9 q^3, in Horner form. f(1) = 0 exactly only in real
  // arithmetic: just inside the radius rounding can give about -1e-17, so clamp at 0 (no
  // negative density anywhere, as documented).
  return std::max(0.0, 1.0 + q * (-22.0 / 9.0 + q * (17.0 / 9.0 - q * (4.0 / 9.0))));
}

namespace
{
double SquaredDistance(const std::array<double, 3>& a, const std::array<double, 3>& b)
{
  const double dx = a[0] - b[0], dy = a[1] - b[1], dz = a[2] - b[2];
  return dx * dx + dy * dy + dz * dz;
}
}

double MetaballDensity(const std::vector<Metaball>& balls, const std::array<double, 3>& point)
{
  double density = 0.0;
  for (const Metaball& ball : balls)
  {
    density +=
      ball.Density * WyvillFalloff(SquaredDistance(point, ball.Center), ball.Radius * ball.Radius);
  }
  return density;
}

std::array<double, 3> MetaballDensityGradient(
  const std::vector<Metaball>& balls, const std::array<double, 3>& point)
{
  std::array<double, 3> gradient{ { 0.0, 0.0, 0.0 } };
  for (const Metaball& ball : balls)
  {
    const double r2 = ball.Radius * ball.Radius;
    const double d2 = SquaredDistance(point, ball.Center);
    if (!(d2 < r2))
    {
      continue;
    }
    // d f / d q = -22/9 + 34/9 q - 12/9 q^2 and grad q = 2 (p - c) / R^2
    const double q = d2 / r2;
    const double dfdq = -22.0 / 9.0 + q * (34.0 / 9.0 - q * (12.0 / 9.0));
    const double scale = ball.Density * dfdq * 2.0 / r2;
    for (int a = 0; a < 3; ++a)
    {
      gradient[a] += scale * (point[a] - ball.Center[a]);
    }
  }
  return gradient;
}

namespace
{
// Grid-point updates (or ball evaluations) between two progress calls.
constexpr double ProgressInterval = 4194304.0;

// Index range [lo, hi] of the grid points along one axis within `radius` of `centre`,
// clipped to [0, n - 1] in floating point (no out-of-range conversion); empty (lo > hi)
// when the ball misses the grid or anything is NaN.
void AxisRange(double centre, double radius, double origin, double spacing, int n, int& lo, int& hi)
{
  const double first = std::ceil((centre - radius - origin) / spacing);
  const double last = std::floor((centre + radius - origin) / spacing);
  if (!(first <= last) || !(last >= 0.0) || !(first <= n - 1.0))
  {
    lo = 0;
    hi = -1;
    return;
  }
  lo = static_cast<int>(std::max(0.0, first));
  hi = static_cast<int>(std::min(n - 1.0, last));
}
}

double MetaballBoxPoints(double radius, const GridGeometry& grid)
{
  double points = 1.0;
  for (int a = 0; a < 3; ++a)
  {
    const double across = 2.0 * radius / grid.Spacing[a] + 1.0;
    points *= std::min(static_cast<double>(grid.Dimensions[a]), std::isnan(across) ? 1.0 : across);
  }
  return points;
}

GridExtent WholeExtent(const GridGeometry& grid)
{
  return { { 0, grid.Dimensions[0] - 1, 0, grid.Dimensions[1] - 1, 0, grid.Dimensions[2] - 1 } };
}

namespace
{
// Number of points of an extent within the grid; throws for one outside it.
std::size_t CheckedExtentPoints(const GridGeometry& grid, const GridExtent& extent)
{
  std::size_t points = 1;
  for (int a = 0; a < 3; ++a)
  {
    if (extent[2 * a] < 0 || extent[2 * a + 1] >= grid.Dimensions[a] ||
      extent[2 * a] > extent[2 * a + 1])
    {
      throw std::invalid_argument("metaball sampling: the extent is empty or outside the grid");
    }
    points *= static_cast<std::size_t>(extent[2 * a + 1] - extent[2 * a] + 1);
  }
  return points;
}
}

bool SampleMetaballs(const std::vector<Metaball>& balls, const GridGeometry& grid,
  std::vector<float>& density, const ProgressCallback& progress)
{
  return SampleMetaballs(balls, grid, WholeExtent(grid), density, progress);
}

bool SampleMetaballs(const std::vector<Metaball>& balls, const GridGeometry& grid,
  const GridExtent& extent, std::vector<float>& density, const ProgressCallback& progress)
{
  density.assign(CheckedExtentPoints(grid, extent), 0.0f);
  const int nx = extent[1] - extent[0] + 1;
  const int ny = extent[3] - extent[2] + 1;
  double sinceReport = 0.0;
  for (std::size_t b = 0; b < balls.size(); ++b)
  {
    const Metaball& ball = balls[b];
    // Index range of the ball's bounding box, clipped to the grid, then to the extent.
    int lo[3], hi[3];
    for (int a = 0; a < 3; ++a)
    {
      AxisRange(ball.Center[a], ball.Radius, grid.Origin[a], grid.Spacing[a], grid.Dimensions[a],
        lo[a], hi[a]);
      lo[a] = std::max(lo[a], extent[2 * a]);
      hi[a] = std::min(hi[a], extent[2 * a + 1]);
    }
    const double r2 = ball.Radius * ball.Radius;
    for (int k = lo[2]; k <= hi[2]; ++k)
    {
      // Positions from the whole grid's indices: the same numbers in every piece.
      const double dz = grid.Origin[2] + k * grid.Spacing[2] - ball.Center[2];
      for (int j = lo[1]; j <= hi[1]; ++j)
      {
        const double dy = grid.Origin[1] + j * grid.Spacing[1] - ball.Center[1];
        const double dyz2 = dy * dy + dz * dz;
        if (!(dyz2 < r2))
        {
          continue;
        }
        float* row =
          density.data() + (static_cast<std::size_t>(k - extent[4]) * ny + (j - extent[2])) * nx;
        for (int i = lo[0]; i <= hi[0]; ++i)
        {
          const double dx = grid.Origin[0] + i * grid.Spacing[0] - ball.Center[0];
          row[i - extent[0]] +=
            static_cast<float>(ball.Density * WyvillFalloff(dx * dx + dyz2, r2));
        }
      }
      if (progress && hi[0] >= lo[0] && hi[1] >= lo[1])
      {
        sinceReport += static_cast<double>(hi[0] - lo[0] + 1) * (hi[1] - lo[1] + 1);
        if (sinceReport >= ProgressInterval)
        {
          sinceReport = 0.0;
          const double withinBall = static_cast<double>(k - lo[2] + 1) / (hi[2] - lo[2] + 1);
          if (!progress((static_cast<double>(b) + withinBall) / static_cast<double>(balls.size())))
          {
            return false;
          }
        }
      }
    }
  }
  return true;
}

void ApplyCloudBase(const GridGeometry& grid, double baseHeight, double transitionThickness,
  std::vector<float>& density)
{
  ApplyCloudBase(grid, WholeExtent(grid), baseHeight, transitionThickness, density);
}

void ApplyCloudBase(const GridGeometry& grid, const GridExtent& extent, double baseHeight,
  double transitionThickness, std::vector<float>& density)
{
  const std::size_t points = CheckedExtentPoints(grid, extent);
  if (density.size() != points)
  {
    throw std::invalid_argument("ApplyCloudBase: the density does not match the extent");
  }
  const std::size_t sliceSize =
    static_cast<std::size_t>(extent[1] - extent[0] + 1) * (extent[3] - extent[2] + 1);
  for (int k = extent[4]; k <= extent[5]; ++k)
  {
    const double z = grid.Origin[2] + k * grid.Spacing[2];
    double weight;
    if (z <= baseHeight)
    {
      weight = 0.0;
    }
    else if (transitionThickness <= 0.0 || z >= baseHeight + transitionThickness)
    {
      weight = 1.0;
    }
    else
    {
      const double t = (z - baseHeight) / transitionThickness;
      weight = t * t * (3.0 - 2.0 * t); // smoothstep
    }
    if (weight == 1.0)
    {
      continue;
    }
    float* slice = density.data() + static_cast<std::size_t>(k - extent[4]) * sliceSize;
    for (std::size_t idx = 0; idx < sliceSize; ++idx)
    {
      slice[idx] = static_cast<float>(slice[idx] * weight);
    }
  }
}

std::vector<Metaball> MakeBasicShape(const BasicShapeParameters& parameters, Random& random)
{
  std::vector<Metaball> balls;
  balls.reserve(static_cast<std::size_t>(std::max(0, parameters.NumberOfBalls)));
  const double twoPi = 6.283185307179586;
  for (int n = 0; n < parameters.NumberOfBalls; ++n)
  {
    Metaball ball;
    ball.Radius = random.Uniform(parameters.RadiusMin, parameters.RadiusMax);
    // Uniform in the disc: radius ~ sqrt(U).
    const double rho = parameters.FootprintRadius * std::sqrt(random.Uniform());
    const double phi = twoPi * random.Uniform();
    ball.Center[0] = parameters.Center[0] + rho * std::cos(phi);
    ball.Center[1] = parameters.Center[1] + rho * std::sin(phi);
    ball.Center[2] =
      parameters.BaseHeight + 0.5 * ball.Radius + parameters.TowerHeight * random.Uniform();
    ball.Density = parameters.Density;
    ball.Level = 0;
    balls.push_back(ball);
  }
  return balls;
}

std::vector<Metaball> GrowOnSurface(const std::vector<Metaball>& balls,
  const std::vector<double>& points, const std::vector<std::int64_t>& triangles,
  const GrowthParameters& parameters, Random& random, const ProgressCallback& progress)
{
  const std::size_t numberOfTriangles = triangles.size() / 3;
  // Cumulative area of the triangles allowed to grow (outward normal not downward).
  std::vector<double> cumulativeArea;
  std::vector<std::size_t> eligible;
  cumulativeArea.reserve(numberOfTriangles);
  eligible.reserve(numberOfTriangles);
  double totalArea = 0.0;
  double sinceReport = 0.0;
  for (std::size_t t = 0; t < numberOfTriangles; ++t)
  {
    if (progress)
    {
      sinceReport += static_cast<double>(balls.size()) + 1.0;
      if (sinceReport >= ProgressInterval)
      {
        sinceReport = 0.0;
        if (!progress(static_cast<double>(t) / static_cast<double>(numberOfTriangles)))
        {
          return {};
        }
      }
    }
    const double* a = &points[3 * triangles[3 * t]];
    const double* b = &points[3 * triangles[3 * t + 1]];
    const double* c = &points[3 * triangles[3 * t + 2]];
    const double u[3] = { b[0] - a[0], b[1] - a[1], b[2] - a[2] };
    const double v[3] = { c[0] - a[0], c[1] - a[1], c[2] - a[2] };
    const double cross[3] = { u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2],
      u[0] * v[1] - u[1] * v[0] };
    const double area =
      0.5 * std::sqrt(cross[0] * cross[0] + cross[1] * cross[1] + cross[2] * cross[2]);
    if (!(area > 0.0))
    {
      continue;
    }
    const std::array<double, 3> centroid{ { (a[0] + b[0] + c[0]) / 3.0, (a[1] + b[1] + c[1]) / 3.0,
      (a[2] + b[2] + c[2]) / 3.0 } };
    const std::array<double, 3> gradient = MetaballDensityGradient(balls, centroid);
    const double gradientNorm =
      std::sqrt(gradient[0] * gradient[0] + gradient[1] * gradient[1] + gradient[2] * gradient[2]);
    // Outward normal = -gradient / |gradient| (density decreases outwards).
    const double normalZ = gradientNorm > 0.0 ? -gradient[2] / gradientNorm : 0.0;
    if (normalZ < parameters.MinimumNormalZ)
    {
      continue;
    }
    totalArea += area;
    cumulativeArea.push_back(totalArea);
    eligible.push_back(t);
  }

  std::vector<Metaball> grown;
  if (eligible.empty())
  {
    return grown;
  }
  grown.reserve(static_cast<std::size_t>(std::max(0, parameters.NumberOfBalls)));
  for (int n = 0; n < parameters.NumberOfBalls; ++n)
  {
    // Triangle with probability proportional to its area.
    const double target = random.Uniform() * totalArea;
    const std::size_t pick = static_cast<std::size_t>(
      std::upper_bound(cumulativeArea.begin(), cumulativeArea.end(), target) -
      cumulativeArea.begin());
    const std::size_t t = eligible[std::min(pick, eligible.size() - 1)];
    const double* a = &points[3 * triangles[3 * t]];
    const double* b = &points[3 * triangles[3 * t + 1]];
    const double* c = &points[3 * triangles[3 * t + 2]];
    // Uniform point in the triangle (square-root parametrisation).
    const double s = std::sqrt(random.Uniform());
    const double r = random.Uniform();
    const double wa = 1.0 - s, wb = s * (1.0 - r), wc = s * r;
    Metaball ball;
    for (int axis = 0; axis < 3; ++axis)
    {
      ball.Center[axis] = wa * a[axis] + wb * b[axis] + wc * c[axis];
    }
    ball.Radius = random.Uniform(parameters.RadiusMin, parameters.RadiusMax);
    ball.Density = parameters.Density;
    ball.Level = parameters.Level;
    grown.push_back(ball);
  }
  return grown;
}

} // namespace nimbus
