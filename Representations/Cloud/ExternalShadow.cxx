#include "ExternalShadow.h"

#include "Math.h"
#include "ParallelFor.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace nimbus
{
namespace
{
// The parameter interval [t0, t1] of the line p + t d inside the box (slab method);
// false when it misses the box.
bool LineBoxInterval(
  const Vector3& p, const Vector3& d, const std::array<double, 6>& box, double& t0, double& t1)
{
  t0 = -std::numeric_limits<double>::infinity();
  t1 = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a)
  {
    const double lo = box[2 * a], hi = box[2 * a + 1];
    if (std::abs(d[a]) < 1e-15)
    {
      if (p[a] < lo || p[a] > hi)
      {
        return false;
      }
      continue;
    }
    double ta = (lo - p[a]) / d[a], tb = (hi - p[a]) / d[a];
    if (ta > tb)
    {
      std::swap(ta, tb);
    }
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
  }
  return t0 <= t1;
}
}

bool CoarseDensityGrid::IsValid() const
{
  const std::size_t count = static_cast<std::size_t>(std::max(this->Dimensions[0], 0)) *
    static_cast<std::size_t>(std::max(this->Dimensions[1], 0)) *
    static_cast<std::size_t>(std::max(this->Dimensions[2], 0));
  return count > 0 && this->Values.size() == count && this->Spacing[0] > 0.0 &&
    this->Spacing[1] > 0.0 && this->Spacing[2] > 0.0;
}

double CoarseDensityGrid::Sample(const Vector3& p) const
{
  int base[3];
  double weight[3];
  for (int a = 0; a < 3; ++a)
  {
    const double x = (p[a] - this->Origin[a]) / this->Spacing[a];
    const int last = this->Dimensions[a] - 1;
    if (!(x >= 0.0 && x <= static_cast<double>(last)))
    {
      return 0.0; // outside (or NaN)
    }
    base[a] = std::min(static_cast<int>(x), std::max(last - 1, 0));
    weight[a] = last > 0 ? x - base[a] : 0.0;
  }
  const auto at = [this](int i, int j, int k)
  {
    i = std::min(i, this->Dimensions[0] - 1);
    j = std::min(j, this->Dimensions[1] - 1);
    k = std::min(k, this->Dimensions[2] - 1);
    return static_cast<double>(
      this->Values[(static_cast<std::size_t>(k) * this->Dimensions[1] + j) * this->Dimensions[0] +
        i]);
  };
  double value = 0.0;
  for (int c = 0; c < 8; ++c)
  {
    const int di = c & 1, dj = (c >> 1) & 1, dk = (c >> 2) & 1;
    const double w = (di ? weight[0] : 1.0 - weight[0]) * (dj ? weight[1] : 1.0 - weight[1]) *
      (dk ? weight[2] : 1.0 - weight[2]);
    const double v = w > 0.0 ? at(base[0] + di, base[1] + dj, base[2] + dk) : 0.0;
    if (std::isfinite(v) && v > 0.0) // NaN, infinite and negative densities are empty
    {
      value += w * v;
    }
  }
  return value;
}

ExternalShadowMap ComputeExternalShadowMap(const CoarseDensityGrid& grid,
  const std::array<double, 6>& pieceBounds, const Vector3& toSun, double extinctionPerDensity,
  double metresPerUnit, int size, int threads)
{
  ExternalShadowMap map;
  if (!grid.IsValid() || size < 1)
  {
    return map;
  }
  std::array<double, 6> gridBox;
  std::vector<Vector3> corners;
  for (int a = 0; a < 3; ++a)
  {
    gridBox[2 * a] = grid.Origin[a];
    gridBox[2 * a + 1] = grid.Origin[a] + (grid.Dimensions[a] - 1) * grid.Spacing[a];
  }
  for (int c = 0; c < 8; ++c)
  {
    corners.push_back(
      { { gridBox[(c & 1) ? 1 : 0], gridBox[(c & 2) ? 3 : 2], gridBox[(c & 4) ? 5 : 4] } });
  }
  const Vector3 l = Normalized(toSun);
  map.Frame = ComputeShadowFrame(corners, l, 0.02);
  map.Size = size;
  map.Depths.assign(static_cast<std::size_t>(size) * size * 2, 0.0f);
  // Half the finest coarse spacing: the midpoint rule resolves the trilinear grid.
  const double step =
    0.5 * std::min({ grid.Spacing[0], grid.Spacing[1], grid.Spacing[2] }); // world units
  const double sigmaStep = extinctionPerDensity * step * metresPerUnit;    // [m / m]
  ParallelFor(static_cast<std::size_t>(size) * size, static_cast<std::size_t>(size), threads,
    [&](std::size_t begin, std::size_t end)
    {
      for (std::size_t texel = begin; texel < end; ++texel)
      {
        const double s = (static_cast<double>(texel % size) + 0.5) / size;
        const double t = (static_cast<double>(texel / size) + 0.5) / size;
        Vector3 base;
        for (int a = 0; a < 3; ++a)
        {
          base[a] = map.Frame.Origin[a] + s * map.Frame.Width * map.Frame.U[a] +
            t * map.Frame.Height * map.Frame.W[a];
        }
        double g0, g1;
        if (!LineBoxInterval(base, l, gridBox, g0, g1))
        {
          continue;
        }
        double p0 = 0.0, p1 = 0.0;
        const bool hitsPiece = LineBoxInterval(base, l, pieceBounds, p0, p1);
        double beyond = 0.0, whole = 0.0;
        const int steps = std::max(1, static_cast<int>(std::ceil((g1 - g0) / step)));
        const double h = (g1 - g0) / steps;
        for (int i = 0; i < steps; ++i)
        {
          const double u = g0 + (i + 0.5) * h;
          if (hitsPiece && u >= p0 && u <= p1)
          {
            continue; // the piece's own density: its shadow surface has it at full resolution
          }
          const Vector3 p = { { base[0] + u * l[0], base[1] + u * l[1], base[2] + u * l[2] } };
          const double depth = grid.Sample(p) * sigmaStep * (h / step);
          whole += depth;
          if (hitsPiece && u > p1)
          {
            beyond += depth;
          }
        }
        map.Depths[2 * texel] = static_cast<float>(beyond);
        map.Depths[2 * texel + 1] = static_cast<float>(whole);
      }
    });
  return map;
}

} // namespace nimbus
