#include "CloudSplats.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

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
} // namespace nimbus
