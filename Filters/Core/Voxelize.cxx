#include "Voxelize.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace nimbus
{

bool VoxelizeClosedSurface(const std::vector<Vector3>& points,
  const std::vector<std::array<std::int64_t, 3>>& triangles, const std::array<int, 3>& dims,
  const Vector3& origin, double h, std::vector<std::uint8_t>& solid, std::string& error)
{
  solid.clear();
  error.clear();
  if (!(h > 0.0) || !std::isfinite(h) || !IsFinite(origin) || dims[0] < 1 || dims[1] < 1 ||
    dims[2] < 1)
  {
    error = "the grid must have at least one cell per axis and a finite cell size > 0";
    return false;
  }
  for (const Vector3& p : points)
  {
    if (!IsFinite(p))
    {
      error = "the surface has a point with a non-finite coordinate";
      return false;
    }
  }
  // Closed: every edge is shared by an even number of triangles (a hole leaves an edge
  // with one; a hole in a vertical face no vertical line would notice).
  std::vector<std::pair<std::int64_t, std::int64_t>> edges;
  edges.reserve(3 * triangles.size());
  for (const auto& t : triangles)
  {
    for (int e = 0; e < 3; ++e)
    {
      const std::int64_t a = t[e];
      const std::int64_t b = t[(e + 1) % 3];
      if (a < 0 || b < 0 || static_cast<std::size_t>(std::max(a, b)) >= points.size())
      {
        std::ostringstream message;
        message << "the surface has a triangle with point index "
                << (a < 0 || static_cast<std::size_t>(a) >= points.size() ? a : b) << " (it has "
                << points.size() << " points)";
        error = message.str();
        return false;
      }
      edges.emplace_back(std::min(a, b), std::max(a, b));
    }
  }
  std::sort(edges.begin(), edges.end());
  for (std::size_t e = 0; e < edges.size();)
  {
    std::size_t run = e;
    while (run < edges.size() && edges[run] == edges[e])
    {
      ++run;
    }
    if ((run - e) % 2 != 0)
    {
      std::ostringstream message;
      message << "the surface is not closed: the edge between its points " << edges[e].first
              << " and " << edges[e].second << " belongs to " << run - e
              << " triangle(s) (a closed surface has two per edge)";
      error = message.str();
      return false;
    }
    e = run;
  }

  const std::size_t nx = static_cast<std::size_t>(dims[0]);
  const std::size_t ny = static_cast<std::size_t>(dims[1]);
  const std::size_t nz = static_cast<std::size_t>(dims[2]);
  // The column centres' offset: small against h, and not a rational multiple of the grid
  // step, so no column passes exactly through a vertex or along an edge of a surface whose
  // vertices sit on grid lines or cell centres.
  const double offsetX = 1.0e-7 * std::sqrt(2.0) * h;
  const double offsetY = 1.0e-7 * std::sqrt(3.0) * h;
  std::vector<std::vector<double>> crossings(nx * ny);
  for (const auto& t : triangles)
  {
    const Vector3& a = points[static_cast<std::size_t>(t[0])];
    const Vector3& b = points[static_cast<std::size_t>(t[1])];
    const Vector3& c = points[static_cast<std::size_t>(t[2])];
    // Twice the signed area of the projection; a vertical triangle is crossed by no
    // column (its neighbours account for the crossing).
    const double area = (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]);
    if (area == 0.0)
    {
      continue;
    }
    const double minX = std::min({ a[0], b[0], c[0] });
    const double maxX = std::max({ a[0], b[0], c[0] });
    const double minY = std::min({ a[1], b[1], c[1] });
    const double maxY = std::max({ a[1], b[1], c[1] });
    // Columns i whose centre x = origin + (i + 1/2) h + offset lies in [minX, maxX].
    auto firstColumn = [&](double low, double o, double offset, std::size_t n)
    {
      const double i = std::ceil((low - o - offset) / h - 0.5);
      return static_cast<long long>(std::clamp(i, 0.0, static_cast<double>(n)));
    };
    auto lastColumn = [&](double high, double o, double offset, std::size_t n)
    {
      const double i = std::floor((high - o - offset) / h - 0.5);
      return static_cast<long long>(std::clamp(i, -1.0, static_cast<double>(n) - 1.0));
    };
    const long long i0 = firstColumn(minX, origin[0], offsetX, nx);
    const long long i1 = lastColumn(maxX, origin[0], offsetX, nx);
    const long long j0 = firstColumn(minY, origin[1], offsetY, ny);
    const long long j1 = lastColumn(maxY, origin[1], offsetY, ny);
    for (long long j = j0; j <= j1; ++j)
    {
      const double y = origin[1] + (static_cast<double>(j) + 0.5) * h + offsetY;
      for (long long i = i0; i <= i1; ++i)
      {
        const double x = origin[0] + (static_cast<double>(i) + 0.5) * h + offsetX;
        // Barycentric coordinates of (x, y) in the projected triangle.
        const double wa = ((b[0] - x) * (c[1] - y) - (c[0] - x) * (b[1] - y)) / area;
        const double wb = ((c[0] - x) * (a[1] - y) - (a[0] - x) * (c[1] - y)) / area;
        const double wc = 1.0 - wa - wb;
        if (wa < 0.0 || wb < 0.0 || wc < 0.0)
        {
          continue;
        }
        crossings[static_cast<std::size_t>(j) * nx + static_cast<std::size_t>(i)].push_back(
          wa * a[2] + wb * b[2] + wc * c[2]);
      }
    }
  }
  solid.assign(nx * ny * nz, 0);
  for (std::size_t column = 0; column < crossings.size(); ++column)
  {
    std::vector<double>& z = crossings[column];
    if (z.size() % 2 != 0)
    {
      std::ostringstream message;
      message << "the surface is not closed: the vertical line through cell column (" << column % nx
              << ", " << column / nx << ") crosses it " << z.size() << " times (an odd number)";
      error = message.str();
      solid.clear();
      return false;
    }
    std::sort(z.begin(), z.end());
    for (std::size_t pair = 0; pair + 1 < z.size(); pair += 2)
    {
      // Cells k whose centre origin + (k + 1/2) h lies in [z_in, z_out).
      const double k0 = std::ceil((z[pair] - origin[2]) / h - 0.5);
      const double k1 = std::ceil((z[pair + 1] - origin[2]) / h - 0.5) - 1.0;
      for (double k = std::max(k0, 0.0); k <= std::min(k1, static_cast<double>(nz) - 1.0); ++k)
      {
        solid[static_cast<std::size_t>(k) * nx * ny + column] = 1;
      }
    }
  }
  return true;
}

} // namespace nimbus
