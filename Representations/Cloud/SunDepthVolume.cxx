#include "SunDepthVolume.h"

#include "ParallelFor.h"

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace nimbus
{
namespace
{
constexpr double kMaximumDepth = 1e30;

double CleanDensity(float value)
{
  return std::isfinite(value) && value > 0.0f ? static_cast<double>(value) : 0.0;
}

// The sweep's geometry: the axis it runs along, the index step toward the sun from
// one slice to the next (its component on that axis is +-1) and that step's length.
struct SweepStep
{
  int Axis = 2;
  std::array<double, 3> Step{ { 0, 0, 1 } };
  double LengthMetres = 0.0;
};

SweepStep SweepStepOf(const SunDepthGrid& grid, const Vector3& toSun, double metresPerUnit)
{
  std::array<double, 3> u{};
  for (int r = 0; r < 3; ++r)
  {
    u[r] = grid.Linear[3 * r] * toSun[0] + grid.Linear[3 * r + 1] * toSun[1] +
      grid.Linear[3 * r + 2] * toSun[2];
  }
  SweepStep step;
  for (int a = 0; a < 3; ++a)
  {
    if (std::abs(u[a]) > std::abs(u[step.Axis]))
    {
      step.Axis = a;
    }
  }
  const double along = std::abs(u[step.Axis]); // index units per world unit
  for (int a = 0; a < 3; ++a)
  {
    step.Step[a] = along > 0.0 ? u[a] / along : 0.0;
  }
  step.LengthMetres = along > 0.0 ? metresPerUnit / along : 0.0;
  return step;
}

// How far (in steps) from index point x along the step the line stays in the box.
double StepsToBoxExit(
  const SunDepthGrid& grid, const std::array<double, 3>& x, const std::array<double, 3>& step)
{
  double exit = kMaximumDepth;
  for (int a = 0; a < 3; ++a)
  {
    if (step[a] > 1e-12)
    {
      exit = std::min(exit, (grid.BoxHigh[a] - x[a]) / step[a]);
    }
    else if (step[a] < -1e-12)
    {
      exit = std::min(exit, (grid.BoxLow[a] - x[a]) / step[a]);
    }
  }
  return std::max(exit, 0.0);
}

// Bilinear look-up in slice `slice` (along `axis`) at the other two index coordinates
// of y, clamped to the texel centres (as clamp-to-edge texturing does); read(n) gives
// the value of texel n.
template <typename Read>
double SliceBilinear(
  Read read, const std::array<int, 3>& dims, int axis, int slice, const std::array<double, 3>& y)
{
  const int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
  const double c1 = std::min(std::max(y[a1], 0.0), static_cast<double>(dims[a1] - 1));
  const double c2 = std::min(std::max(y[a2], 0.0), static_cast<double>(dims[a2] - 1));
  const int i1 = std::min(static_cast<int>(c1), std::max(dims[a1] - 2, 0));
  const int i2 = std::min(static_cast<int>(c2), std::max(dims[a2] - 2, 0));
  const double f1 = dims[a1] > 1 ? c1 - i1 : 0.0, f2 = dims[a2] > 1 ? c2 - i2 : 0.0;
  const auto at = [&](int d1, int d2)
  {
    std::array<int, 3> i{};
    i[axis] = slice;
    i[a1] = std::min(i1 + d1, dims[a1] - 1);
    i[a2] = std::min(i2 + d2, dims[a2] - 1);
    return read(static_cast<std::size_t>(i[0]) +
      static_cast<std::size_t>(dims[0]) *
        (static_cast<std::size_t>(i[1]) + static_cast<std::size_t>(dims[1]) * i[2]));
  };
  return (1.0 - f2) * ((1.0 - f1) * at(0, 0) + f1 * at(1, 0)) +
    f2 * ((1.0 - f1) * at(0, 1) + f1 * at(1, 1));
}
} // namespace

std::vector<float> ComputeSunDepthVolume(const float* density, const SunDepthGrid& grid,
  const Vector3& toSun, double extinctionPerDensity, double metresPerUnit, int threads,
  SunDepthInterpolation interpolation)
{
  // The values swept: tau, or T = exp(-tau) (then tau = -log T at the end).
  const bool transmittance = interpolation == SunDepthInterpolation::Transmittance;
  const std::array<int, 3>& dims = grid.Dimensions;
  const std::size_t count = static_cast<std::size_t>(std::max(dims[0], 0)) *
    static_cast<std::size_t>(std::max(dims[1], 0)) * static_cast<std::size_t>(std::max(dims[2], 0));
  std::vector<float> depth(count, transmittance ? 1.0f : 0.0f);
  if (count == 0 || !density)
  {
    std::fill(depth.begin(), depth.end(), 0.0f);
    return depth;
  }
  const SweepStep sweep = SweepStepOf(grid, toSun, metresPerUnit);
  const int axis = sweep.Axis, a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
  const int towardSun = sweep.Step[axis] > 0.0 ? 1 : -1;
  const double k = extinctionPerDensity;
  const std::size_t sliceTexels = static_cast<std::size_t>(dims[a1]) * dims[a2];
  // Slices in order from the sun's side: each reads only the one before it.
  for (int n = 0; n < dims[axis]; ++n)
  {
    const int slice = towardSun > 0 ? dims[axis] - 1 - n : n;
    const int upstream = slice + towardSun;
    ParallelFor(sliceTexels, 4096, threads,
      [&](std::size_t begin, std::size_t end)
      {
        for (std::size_t t = begin; t < end; ++t)
        {
          std::array<int, 3> i{};
          i[axis] = slice;
          i[a1] = static_cast<int>(t % dims[a1]);
          i[a2] = static_cast<int>(t / dims[a1]);
          const std::size_t at = static_cast<std::size_t>(i[0]) +
            static_cast<std::size_t>(dims[0]) *
              (static_cast<std::size_t>(i[1]) + static_cast<std::size_t>(dims[1]) * i[2]);
          const std::array<double, 3> x{ { static_cast<double>(i[0]), static_cast<double>(i[1]),
            static_cast<double>(i[2]) } };
          const double sigma = k * CleanDensity(density[at]);
          const double exit = StepsToBoxExit(grid, x, sweep.Step);
          double value; // tau or T
          if (exit <= 1.0 || upstream < 0 || upstream >= dims[axis])
          {
            const double tau = sigma * std::min(exit, 1.0) * sweep.LengthMetres;
            value = transmittance ? std::exp(-tau) : tau;
          }
          else
          {
            std::array<double, 3> y{};
            for (int a = 0; a < 3; ++a)
            {
              y[a] = x[a] + sweep.Step[a];
            }
            // Texel by texel through CleanDensity: a NaN neighbour counts as 0.
            const double sigmaY = k *
              SliceBilinear([density](std::size_t m) { return CleanDensity(density[m]); }, dims,
                axis, upstream, y);
            const float* previous = depth.data();
            const double before =
              SliceBilinear([previous](std::size_t m) { return static_cast<double>(previous[m]); },
                dims, axis, upstream, y);
            const double segment = 0.5 * (sigma + sigmaY) * sweep.LengthMetres;
            value = transmittance ? before * std::exp(-segment) : before + segment;
          }
          depth[at] = static_cast<float>(transmittance
              ? (std::isfinite(value) ? std::max(value, 0.0) : 0.0)
              : std::min(std::isfinite(value) ? value : kMaximumDepth, kMaximumDepth));
        }
      });
  }
  if (transmittance)
  {
    for (float& value : depth)
    {
      value = value > 0.0f ? std::min(-std::log(value), static_cast<float>(kMaximumDepth))
                           : static_cast<float>(kMaximumDepth);
    }
  }
  return depth;
}

std::vector<float> ComputeBlockMaxima(const float* density, const std::array<int, 3>& dimensions,
  int blockSize, std::array<int, 3>& blocks)
{
  const int b = std::max(blockSize, 1);
  for (int a = 0; a < 3; ++a)
  {
    blocks[a] = std::max((dimensions[a] + b - 1) / b, 1);
  }
  std::vector<float> maxima(
    static_cast<std::size_t>(blocks[0]) * blocks[1] * static_cast<std::size_t>(blocks[2]), 0.0f);
  if (!density || dimensions[0] <= 0 || dimensions[1] <= 0 || dimensions[2] <= 0)
  {
    return maxima;
  }
  for (int k = 0; k < dimensions[2]; ++k)
  {
    for (int j = 0; j < dimensions[1]; ++j)
    {
      for (int i = 0; i < dimensions[0]; ++i)
      {
        const double value = CleanDensity(density[static_cast<std::size_t>(i) +
          static_cast<std::size_t>(dimensions[0]) *
            (static_cast<std::size_t>(j) + static_cast<std::size_t>(dimensions[1]) * k)]);
        if (value <= 0.0)
        {
          continue;
        }
        // Every block whose grown range [B b - 1, (B + 1) b] holds this texel.
        const int lo[3] = { std::max((i - 1) / b, 0), std::max((j - 1) / b, 0),
          std::max((k - 1) / b, 0) };
        const int hi[3] = { std::min((i + 1) / b, blocks[0] - 1),
          std::min((j + 1) / b, blocks[1] - 1), std::min((k + 1) / b, blocks[2] - 1) };
        for (int K = lo[2]; K <= hi[2]; ++K)
        {
          for (int J = lo[1]; J <= hi[1]; ++J)
          {
            for (int I = lo[0]; I <= hi[0]; ++I)
            {
              float& m = maxima[static_cast<std::size_t>(I) +
                static_cast<std::size_t>(blocks[0]) *
                  (static_cast<std::size_t>(J) + static_cast<std::size_t>(blocks[1]) * K)];
              m = std::max(m, static_cast<float>(value));
            }
          }
        }
      }
    }
  }
  return maxima;
}
}
