// The cloud density as the mapper's 3-D texture takes it: one float per texel, x
// fastest, finite and >= 0, at most a given number of texels per side.
//
//  - A volume larger than the limit is reduced by the smallest integer factor per
//    axis that fits, f_k = ceil(n_k / limit); each texel is the mean of its
//    f_x x f_y x f_z block of samples, the blocks at the upper edges partial
//    (ceil(n_k / f_k) texels per axis).
//  - NaN and infinite samples are taken as 0, negative samples are clamped to 0
//    and samples above kMaximumDensity (1e30) to kMaximumDensity, all before
//    averaging and all counted (ResampledDensity::Census, TooLargeCount): the sum
//    of a block then stays finite in float, and so does k_cl rho in the shaders.
//  - A volume that fits and already is such floats (contiguous, one component,
//    finite, no sign bit) is used where it is: ResampledDensity::Data() points into
//    it and nothing is allocated. Anything else is converted once.
//
// Plain C++ (no VTK, no GL). The VTK glue, typed access to any vtkDataArray through
// vtkArrayDispatch, is nimbus::CloudDensityTexture::Resample.
#ifndef nimbus_DensityResample_h
#define nimbus_DensityResample_h

#include "MemoryBudget.h" // for ValueCensus
#include "NimbusRepresentationsModule.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <type_traits>
#include <vector>

namespace nimbus
{
/// The largest density a texel holds; larger samples are clamped to it (and
/// counted), so that a block's float sum stays finite (below 3.4e38 for blocks of
/// up to 3e8 samples) and k_cl rho does too (k_cl <= 1e6).
constexpr double kMaximumDensity = 0x1p100; // 1.27e30, exact in float and double

/// Sizes of one resampling: samples per axis, samples per texel per axis (the
/// block), texels per axis.
struct NIMBUSREPRESENTATIONS_EXPORT DensityResamplePlan
{
  std::array<int, 3> InputDimensions{ { 0, 0, 0 } };
  std::array<int, 3> Factors{ { 1, 1, 1 } };
  std::array<int, 3> OutputDimensions{ { 0, 0, 0 } };

  bool Downsamples() const;
  std::size_t InputSize() const;
  std::size_t OutputSize() const;
};

/// The plan for `dimensions` samples with at most `maximumSize` (>= 1) texels per side.
NIMBUSREPRESENTATIONS_EXPORT DensityResamplePlan PlanDensityResample(
  const std::array<int, 3>& dimensions, int maximumSize);

/// The texels of one resampling: borrowed from the input (no copy) or in Storage.
struct ResampledDensity
{
  /// OutputSize() texels, x fastest.
  const float* Data() const { return this->Borrowed ? this->Borrowed : this->Storage.data(); }
  /// Whether the texels were converted into Storage (false: Data() is the input).
  bool IsCopy() const { return this->Borrowed == nullptr; }

  const float* Borrowed = nullptr;
  std::vector<float> Storage;
  /// Samples that were NaN or infinite (taken as 0): Census.NaN + Census.Infinite.
  std::size_t NonFiniteCount = 0;
  /// NaN, infinite (taken as 0) and negative (clamped to 0) samples.
  ValueCensus Census;
  /// Finite samples above kMaximumDensity (clamped to it).
  std::size_t TooLargeCount = 0;
};

/// Whether `count` floats can be the texture as they are: all finite, without
/// sign bit (a -0 is converted to +0 like every other negative value) and at most
/// kMaximumDensity.
NIMBUSREPRESENTATIONS_EXPORT bool IsTextureReadyDensity(const float* values, std::size_t count);

/// One sample as the texture takes it: NaN and infinity -> 0, negative -> 0, above
/// kMaximumDensity -> kMaximumDensity; each counted.
inline double TextureDensity(double v, ValueCensus& census, std::size_t& tooLarge)
{
  if (std::isnan(v))
  {
    ++census.NaN;
    return 0.0;
  }
  if (std::isinf(v))
  {
    ++census.Infinite;
    return 0.0;
  }
  if (v < 0.0)
  {
    ++census.Negative;
    return 0.0;
  }
  if (v > kMaximumDensity)
  {
    ++tooLarge;
    return kMaximumDensity;
  }
  return v > 0.0 ? v : 0.0; // -0 -> +0
}

/// Resampling of plan.InputSize() samples, `sample(i)` giving sample i (x fastest)
/// as a double; always converts into Storage.
template <typename SampleFunction>
ResampledDensity ResampleDensityWith(const SampleFunction& sample, const DensityResamplePlan& plan)
{
  ResampledDensity result;
  result.Storage.assign(plan.OutputSize(), 0.0f);
  float* texels = result.Storage.data();
  ValueCensus& census = result.Census;
  std::size_t& tooLarge = result.TooLargeCount;
  if (!plan.Downsamples())
  {
    const std::size_t count = plan.InputSize();
    for (std::size_t i = 0; i < count; ++i)
    {
      texels[i] = static_cast<float>(TextureDensity(sample(i), census, tooLarge));
    }
    result.NonFiniteCount = census.NaN + census.Infinite;
    return result;
  }
  // Block sums in float, the samples in memory order, then divided by the block's
  // sample count.
  const std::array<int, 3>& n = plan.InputDimensions;
  const std::array<int, 3>& f = plan.Factors;
  const std::array<int, 3>& m = plan.OutputDimensions;
  std::size_t i = 0;
  for (int z = 0; z < n[2]; ++z)
  {
    for (int y = 0; y < n[1]; ++y)
    {
      float* row = texels +
        static_cast<std::size_t>(m[0]) *
          (static_cast<std::size_t>(y / f[1]) + static_cast<std::size_t>(m[1]) * (z / f[2]));
      for (int x = 0; x < n[0]; ++x)
      {
        row[x / f[0]] += static_cast<float>(TextureDensity(sample(i++), census, tooLarge));
      }
    }
  }
  std::size_t t = 0;
  for (int z = 0; z < m[2]; ++z)
  {
    const std::size_t bz = std::min(f[2], n[2] - z * f[2]);
    for (int y = 0; y < m[1]; ++y)
    {
      const std::size_t by = std::min(f[1], n[1] - y * f[1]);
      for (int x = 0; x < m[0]; ++x)
      {
        const std::size_t bx = std::min(f[0], n[0] - x * f[0]);
        texels[t++] /= static_cast<float>(bx * by * bz);
      }
    }
  }
  result.NonFiniteCount = census.NaN + census.Infinite;
  return result;
}

/// Resampling of typed values, the first of every `components` values being the
/// sample. Floats with one component that need no downsampling and are
/// IsTextureReadyDensity are borrowed, not copied.
template <typename T>
ResampledDensity ResampleDensity(const T* values, int components, const DensityResamplePlan& plan)
{
  if constexpr (std::is_same<T, float>::value)
  {
    if (components == 1 && !plan.Downsamples() && IsTextureReadyDensity(values, plan.InputSize()))
    {
      ResampledDensity result;
      result.Borrowed = values;
      return result;
    }
  }
  const std::size_t stride = static_cast<std::size_t>(std::max(components, 1));
  return ResampleDensityWith(
    [values, stride](std::size_t i) { return static_cast<double>(values[i * stride]); }, plan);
}
} // namespace nimbus

#endif
