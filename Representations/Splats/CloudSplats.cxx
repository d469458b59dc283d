#include "CloudSplats.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <utility>

namespace nimbus
{
namespace
{
// F(t) = integral from 0 to t of f(a + t'^2) dt' with a = u^2: f expanded in powers of t',
//   (a + t^2)^2 = a^2 + 2 a t^2 + t^4, (a + t^2)^3 = a^3 + 3 a^2 t^2 + 3 a t^4 + t^6.
double ColumnAntiderivative(double a, double t)
{
  const double c0 = 1.0 - 22.0 / 9.0 * a + 17.0 / 9.0 * a * a - 4.0 / 9.0 * a * a * a;
  const double c2 = -22.0 / 9.0 + 34.0 / 9.0 * a - 12.0 / 9.0 * a * a;
  const double c4 = 17.0 / 9.0 - 12.0 / 9.0 * a;
  const double c6 = -4.0 / 9.0;
  const double t2 = t * t;
  return t * (c0 + t2 * (c2 / 3.0 + t2 * (c4 / 5.0 + t2 * c6 / 7.0)));
}
} // namespace

// 004 §4 (Wyvill's soft-object kernel, as Filters/Core/Metaballs.cxx).
double SplatKernel(double q)
{
  if (!(q < 1.0))
  {
    return 0.0;
  }
  q = std::max(q, 0.0);
  return 1.0 + q * (-22.0 / 9.0 + q * (17.0 / 9.0 - q * 4.0 / 9.0));
}

// 002 §3.3: the cumulative density through one metaball, in closed form.
double SplatPartialColumn(double u, double h)
{
  u = std::abs(u);
  if (!(u < 1.0) || std::isnan(h))
  {
    return 0.0;
  }
  const double a = u * u;
  const double s = std::sqrt(1.0 - a);
  const double t = std::clamp(h, -s, s);
  return ColumnAntiderivative(a, t) + ColumnAntiderivative(a, s);
}

double SplatColumn(double u)
{
  return SplatPartialColumn(u, 1.0);
}

std::vector<float> SplatColumnTexture(int size, int supersample)
{
  if (size < 1 || supersample < 1)
  {
    throw std::invalid_argument("SplatColumnTexture: size and supersample must be >= 1");
  }
  std::vector<float> texels(static_cast<std::size_t>(size) * size);
  const double texel = 2.0 / size;
  const double sub = texel / supersample;
  for (int j = 0; j < size; ++j)
  {
    for (int i = 0; i < size; ++i)
    {
      double sum = 0.0;
      for (int b = 0; b < supersample; ++b)
      {
        const double y = -1.0 + j * texel + (b + 0.5) * sub;
        for (int a = 0; a < supersample; ++a)
        {
          const double x = -1.0 + i * texel + (a + 0.5) * sub;
          sum += SplatColumn(std::sqrt(x * x + y * y));
        }
      }
      texels[static_cast<std::size_t>(j) * size + i] =
        static_cast<float>(sum / (supersample * supersample));
    }
  }
  return texels;
}

std::vector<float> SplatPartialColumnTable(int uSize, int hSize)
{
  if (uSize < 2 || hSize < 2)
  {
    throw std::invalid_argument("SplatPartialColumnTable: sizes must be >= 2");
  }
  std::vector<float> table(static_cast<std::size_t>(uSize) * hSize);
  for (int j = 0; j < hSize; ++j)
  {
    const double h = -1.0 + 2.0 * j / (hSize - 1);
    for (int i = 0; i < uSize; ++i)
    {
      const double u = static_cast<double>(i) / (uSize - 1);
      table[static_cast<std::size_t>(j) * uSize + i] = static_cast<float>(SplatPartialColumn(u, h));
    }
  }
  return table;
}

std::vector<std::uint32_t> SplatOrder(const std::vector<float>& centres,
  const std::array<double, 3>& direction, const std::vector<float>& offsets)
{
  const std::size_t n = centres.size() / 3;
  if (!offsets.empty() && offsets.size() != n)
  {
    throw std::invalid_argument("SplatOrder: one offset per centre, or none");
  }
  std::vector<double> keys(n);
  for (std::size_t i = 0; i < n; ++i)
  {
    keys[i] = direction[0] * centres[3 * i] + direction[1] * centres[3 * i + 1] +
      direction[2] * centres[3 * i + 2] + (offsets.empty() ? 0.0 : offsets[i]);
  }
  std::vector<std::uint32_t> order(n);
  std::iota(order.begin(), order.end(), 0u);
  std::stable_sort(order.begin(), order.end(),
    [&keys](std::uint32_t a, std::uint32_t b) { return keys[a] < keys[b]; });
  return order;
}

std::vector<std::uint32_t> SplatOrderBackToFront(
  const std::vector<float>& centres, const std::array<double, 3>& eye)
{
  const std::size_t n = centres.size() / 3;
  std::vector<double> keys(n);
  for (std::size_t i = 0; i < n; ++i)
  {
    const double dx = centres[3 * i] - eye[0];
    const double dy = centres[3 * i + 1] - eye[1];
    const double dz = centres[3 * i + 2] - eye[2];
    keys[i] = -(dx * dx + dy * dy + dz * dz);
  }
  std::vector<std::uint32_t> order(n);
  std::iota(order.begin(), order.end(), 0u);
  std::stable_sort(order.begin(), order.end(),
    [&keys](std::uint32_t a, std::uint32_t b) { return keys[a] < keys[b]; });
  return order;
}

std::array<std::array<double, 3>, 3> SplatFrame(const std::array<double, 3>& axis)
{
  // The world axis least aligned with `axis` seeds the first vector.
  std::array<double, 3> seed{ 0.0, 0.0, 0.0 };
  const double ax = std::abs(axis[0]), ay = std::abs(axis[1]), az = std::abs(axis[2]);
  seed[ax <= ay && ax <= az ? 0 : (ay <= az ? 1 : 2)] = 1.0;
  const double d = seed[0] * axis[0] + seed[1] * axis[1] + seed[2] * axis[2];
  std::array<double, 3> e1{ seed[0] - d * axis[0], seed[1] - d * axis[1], seed[2] - d * axis[2] };
  const double l = std::sqrt(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]);
  for (double& c : e1)
  {
    c /= l;
  }
  const std::array<double, 3> e2{ axis[1] * e1[2] - axis[2] * e1[1],
    axis[2] * e1[0] - axis[0] * e1[2], axis[0] * e1[1] - axis[1] * e1[0] };
  return { e1, e2, axis };
}

std::vector<std::array<std::size_t, 2>> SplatLayerRanges(
  const std::vector<float>& sortedFronts, double zMin, double zMax, int layers, double maxDiameter)
{
  if (layers < 2 || !(zMax >= zMin) || !(maxDiameter >= 0.0))
  {
    throw std::invalid_argument(
      "SplatLayerRanges: needs layers >= 2, zMax >= zMin and maxDiameter >= 0");
  }
  auto before = [&sortedFronts](double z)
  {
    return static_cast<std::size_t>(std::lower_bound(sortedFronts.begin(), sortedFronts.end(), z,
                                      [](float front, double plane) { return front < plane; }) -
      sortedFronts.begin());
  };
  std::vector<std::array<std::size_t, 2>> ranges(layers, { 0, 0 });
  for (int k = 1; k < layers; ++k)
  {
    const double z = zMin + (zMax - zMin) * k / (layers - 1);
    const double previous = zMin + (zMax - zMin) * (k - 1) / (layers - 1);
    const std::size_t end = before(z);
    ranges[k] = { std::min(before(previous - maxDiameter), end), end };
  }
  return ranges;
}
double SplatBallVolume()
{
  // 4 pi integral_0^1 f(r^2) r^2 dr, f the metaball kernel (004 §4).
  return 4.0 * M_PI * (1.0 / 3.0 - 22.0 / 45.0 + 17.0 / 63.0 - 4.0 / 81.0);
}

namespace
{
// The ball's mass on the 8 grid points around `x` (grid coordinates), trilinearly.
void DepositCloudInCell(SplatDensityGrid& grid, const double x[3], double mass)
{
  int i0[3];
  double w[3];
  for (int a = 0; a < 3; ++a)
  {
    const double u = std::min(std::max(x[a], 0.0), grid.Dimensions[a] - 1.000001);
    i0[a] = static_cast<int>(u);
    w[a] = u - i0[a];
  }
  const double perPoint = mass / (grid.Spacing * grid.Spacing * grid.Spacing);
  for (int corner = 0; corner < 8; ++corner)
  {
    double weight = 1.0;
    int idx[3];
    for (int a = 0; a < 3; ++a)
    {
      const int bit = (corner >> a) & 1;
      weight *= bit ? w[a] : 1.0 - w[a];
      idx[a] = i0[a] + bit;
    }
    const std::size_t n =
      (static_cast<std::size_t>(idx[2]) * grid.Dimensions[1] + idx[1]) * grid.Dimensions[0] +
      idx[0];
    grid.Density[n] += static_cast<float>(weight * perPoint);
  }
}
} // namespace

// The balls' density on a grid for the multiple-scattering solve (docs/splats.md).
SplatDensityGrid SplatBallsOntoGrid(const std::vector<float>& centres,
  const std::vector<float>& radii, const std::vector<float>& densities, int longestSide)
{
  const std::size_t balls = radii.size();
  if (longestSide < 4 || centres.size() != 3 * balls || densities.size() != balls)
  {
    throw std::invalid_argument("SplatBallsOntoGrid: needs longestSide >= 4 and 3 centre "
                                "coordinates and one density per radius");
  }
  SplatDensityGrid grid;
  if (balls == 0)
  {
    return grid;
  }
  double lo[3] = { 1e300, 1e300, 1e300 }, hi[3] = { -1e300, -1e300, -1e300 };
  for (std::size_t b = 0; b < balls; ++b)
  {
    for (int a = 0; a < 3; ++a)
    {
      lo[a] = std::min(lo[a], static_cast<double>(centres[3 * b + a]) - radii[b]);
      hi[a] = std::max(hi[a], static_cast<double>(centres[3 * b + a]) + radii[b]);
    }
  }
  const double longest = std::max({ hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2], 1e-30 });
  // longestSide points including one padding point at each end.
  grid.Spacing = longest / (longestSide - 3);
  for (int a = 0; a < 3; ++a)
  {
    grid.Dimensions[a] =
      std::max(static_cast<int>(std::ceil((hi[a] - lo[a]) / grid.Spacing - 1e-9)) + 3, 4);
    const double extent = (grid.Dimensions[a] - 1) * grid.Spacing;
    grid.Origin[a] = 0.5 * (lo[a] + hi[a]) - 0.5 * extent;
  }
  grid.Density.assign(
    static_cast<std::size_t>(grid.Dimensions[0]) * grid.Dimensions[1] * grid.Dimensions[2], 0.0f);
  const double h = grid.Spacing;
  const double cell = h * h * h;
  std::vector<std::pair<std::size_t, float>> samples;
  for (std::size_t b = 0; b < balls; ++b)
  {
    const double radius = radii[b];
    const double mass =
      static_cast<double>(densities[b]) * radius * radius * radius * SplatBallVolume();
    const double x[3] = { (centres[3 * b] - grid.Origin[0]) / h,
      (centres[3 * b + 1] - grid.Origin[1]) / h, (centres[3 * b + 2] - grid.Origin[2]) / h };
    if (!(mass > 0.0) || !std::isfinite(mass))
    {
      continue;
    }
    samples.clear();
    double sum = 0.0;
    if (radius >= h)
    {
      const double r = radius / h;
      int first[3], last[3];
      for (int a = 0; a < 3; ++a)
      {
        first[a] = std::max(static_cast<int>(std::ceil(x[a] - r)), 0);
        last[a] = std::min(static_cast<int>(std::floor(x[a] + r)), grid.Dimensions[a] - 1);
      }
      for (int k = first[2]; k <= last[2]; ++k)
      {
        for (int j = first[1]; j <= last[1]; ++j)
        {
          for (int i = first[0]; i <= last[0]; ++i)
          {
            const double q =
              ((i - x[0]) * (i - x[0]) + (j - x[1]) * (j - x[1]) + (k - x[2]) * (k - x[2])) /
              (r * r);
            const double f = SplatKernel(q);
            if (f > 0.0)
            {
              const std::size_t n =
                (static_cast<std::size_t>(k) * grid.Dimensions[1] + j) * grid.Dimensions[0] + i;
              samples.emplace_back(n, static_cast<float>(f));
              sum += f;
            }
          }
        }
      }
    }
    if (sum <= 0.0)
    {
      DepositCloudInCell(grid, x, mass);
      continue;
    }
    // Each point's share of the mass: d f(q) rescaled to the ball's exact mass.
    const double scale = mass / (sum * cell);
    for (const auto& sample : samples)
    {
      grid.Density[sample.first] += static_cast<float>(scale * sample.second);
    }
  }
  return grid;
}
} // namespace nimbus
