#include "DensityGrid.h"
#include "MemoryBudget.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace nimbus
{

DensityGrid::DensityGrid(const std::array<int, 3>& dims, const Vector3& origin,
  const Vector3& spacing, std::vector<float> values)
  : Dimensions(dims)
  , Origin(origin)
  , Spacing(spacing)
  , Values(std::move(values))
{
  for (int a = 0; a < 3; ++a)
  {
    if (dims[a] < 1 || !(spacing[a] > 0.0) || !std::isfinite(spacing[a]) ||
      !std::isfinite(origin[a]))
    {
      throw std::invalid_argument("nimbus::DensityGrid: dimensions must be >= 1 and spacing > 0 "
                                  "and finite on every axis");
    }
  }
  const std::size_t expected = static_cast<std::size_t>(dims[0]) * dims[1] * dims[2];
  if (this->Values.size() != expected)
  {
    throw std::invalid_argument("nimbus::DensityGrid: " + std::to_string(this->Values.size()) +
      " values for " + std::to_string(expected) + " grid points");
  }
  for (std::size_t i = 0; i < this->Values.size(); ++i)
  {
    const float v = this->Values[i];
    if (!std::isfinite(v) || v < 0.0f)
    {
      // How many, not only the first: one bad value is a glitch, a million a bad file.
      const ValueCensus census = TakeCensus(this->Values.data(), this->Values.size());
      throw std::invalid_argument("nimbus::DensityGrid: " + DescribeCensus(census) + " among " +
        std::to_string(this->Values.size()) + " densities (the first at point " +
        std::to_string(i) + ": " + std::to_string(v) + "); densities must be finite and >= 0");
    }
    this->Maximum = std::max(this->Maximum, static_cast<double>(v));
  }
  for (int a = 0; a < 3; ++a)
  {
    if (dims[a] > 1)
    {
      this->Lower[a] = origin[a];
      this->Upper[a] = origin[a] + (dims[a] - 1) * spacing[a];
    }
    else
    {
      this->Lower[a] = origin[a] - 0.5 * spacing[a];
      this->Upper[a] = origin[a] + 0.5 * spacing[a];
    }
  }
}

DensityGrid DensityGrid::Constant(const Vector3& lo, const Vector3& hi, float density)
{
  const Vector3 spacing{ { hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2] } };
  return DensityGrid({ { 2, 2, 2 } }, lo, spacing, std::vector<float>(8, density));
}

double DensityGrid::GetMinimumSpacing() const
{
  return std::min({ this->Spacing[0], this->Spacing[1], this->Spacing[2] });
}

double DensityGrid::Sample(const Vector3& p) const
{
  if (this->Values.empty())
  {
    return 0.0;
  }
  int i0[3];
  double f[3];
  for (int a = 0; a < 3; ++a)
  {
    if (p[a] < this->Lower[a] || p[a] > this->Upper[a])
    {
      return 0.0;
    }
    if (this->Dimensions[a] == 1)
    {
      i0[a] = 0;
      f[a] = 0.0;
      continue;
    }
    const double x = (p[a] - this->Origin[a]) / this->Spacing[a];
    const int last = this->Dimensions[a] - 2;
    i0[a] = std::min(last, std::max(0, static_cast<int>(std::floor(x))));
    f[a] = std::min(1.0, std::max(0.0, x - i0[a]));
  }
  const std::size_t nx = static_cast<std::size_t>(this->Dimensions[0]);
  const std::size_t nxy = nx * static_cast<std::size_t>(this->Dimensions[1]);
  const std::size_t dx = this->Dimensions[0] > 1 ? 1 : 0;
  const std::size_t dy = this->Dimensions[1] > 1 ? nx : 0;
  const std::size_t dz = this->Dimensions[2] > 1 ? nxy : 0;
  const float* v = this->Values.data() + i0[0] + i0[1] * nx + i0[2] * nxy;
  const double c00 = v[0] + f[0] * (v[dx] - v[0]);
  const double c10 = v[dy] + f[0] * (v[dy + dx] - v[dy]);
  const double c01 = v[dz] + f[0] * (v[dz + dx] - v[dz]);
  const double c11 = v[dz + dy] + f[0] * (v[dz + dy + dx] - v[dz + dy]);
  const double c0 = c00 + f[1] * (c10 - c00);
  const double c1 = c01 + f[1] * (c11 - c01);
  return c0 + f[2] * (c1 - c0);
}

bool DensityGrid::IntersectRay(
  const Vector3& origin, const Vector3& direction, double tMin, double& tNear, double& tFar) const
{
  if (this->Values.empty())
  {
    return false;
  }
  double t0 = tMin;
  double t1 = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a)
  {
    if (direction[a] == 0.0)
    {
      if (origin[a] < this->Lower[a] || origin[a] > this->Upper[a])
      {
        return false;
      }
      continue;
    }
    const double inv = 1.0 / direction[a];
    double tA = (this->Lower[a] - origin[a]) * inv;
    double tB = (this->Upper[a] - origin[a]) * inv;
    if (tA > tB)
    {
      std::swap(tA, tB);
    }
    t0 = std::max(t0, tA);
    t1 = std::min(t1, tB);
    if (t0 > t1)
    {
      return false;
    }
  }
  tNear = t0;
  tFar = t1;
  return true;
}

} // namespace nimbus
