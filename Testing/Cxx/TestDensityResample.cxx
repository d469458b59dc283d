// The density texture's resampling (Representations/Cloud/DensityResample.h) and its
// typed VTK access (nimbus::CloudDensityTexture::Resample): box averages against a
// naive reference and against the mapper's former loop (bit for bit), NaN, infinity
// and negative samples, every VTK numeric type and multi-component arrays through
// vtkArrayDispatch, and the path that borrows the array instead of copying it.
#include "CloudDensityTexture.h"
#include "DensityResample.h"
#include "EmissionTexture.h"

#include "BlackbodyEmission.h"

#include "vtkAOSDataArrayTemplate.h"
#include "vtkBitArray.h"
#include "vtkDataArray.h"
#include "vtkDoubleArray.h"
#include "vtkFloatArray.h"
#include "vtkNew.h"
#include "vtkSOADataArrayTemplate.h"
#include "vtkSmartPointer.h"
#include "vtkType.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <random>
#include <string>
#include <vector>

namespace
{
using nimbus::DensityResamplePlan;
using nimbus::PlanDensityResample;
using nimbus::ResampledDensity;

using Dims = std::array<int, 3>;

// The loop vtkNimbusCloudVolumeMapper::Render ran before the resampling moved to
// DensityResample.h, as it was (values read as doubles): the texture must not change.
std::vector<float> FormerMapperLoop(
  const std::function<double(std::size_t)>& get, const Dims& dims, int maxSize, std::size_t& bad)
{
  int factor[3], texDims[3];
  for (int k = 0; k < 3; ++k)
  {
    factor[k] = (dims[k] + maxSize - 1) / maxSize;
    texDims[k] = (dims[k] + factor[k] - 1) / factor[k];
  }
  std::vector<float> values(static_cast<size_t>(texDims[0]) * texDims[1] * texDims[2], 0.0f);
  std::vector<float> counts(values.size(), 0.0f);
  bad = 0;
  for (int z = 0; z < dims[2]; ++z)
  {
    for (int y = 0; y < dims[1]; ++y)
    {
      for (int x = 0; x < dims[0]; ++x)
      {
        const std::size_t id = x + static_cast<std::size_t>(dims[0]) * (y + dims[1] * z);
        double v = get(id);
        if (!std::isfinite(v))
        {
          ++bad;
          v = 0.0;
        }
        const size_t t = (x / factor[0]) +
          static_cast<size_t>(texDims[0]) *
            ((y / factor[1]) + static_cast<size_t>(texDims[1]) * (z / factor[2]));
        values[t] += static_cast<float>(std::max(v, 0.0));
        counts[t] += 1.0f;
      }
    }
  }
  for (size_t i = 0; i < values.size(); ++i)
  {
    values[i] = counts[i] > 0.0f ? values[i] / counts[i] : 0.0f;
  }
  return values;
}

// Naive reference in double: for every texel, the mean over its block of the
// samples with NaN/infinity as 0 and negatives as 0.
std::vector<double> NaiveBlockMean(const std::vector<double>& samples, const Dims& n, const Dims& f)
{
  Dims m;
  for (int k = 0; k < 3; ++k)
  {
    m[k] = (n[k] + f[k] - 1) / f[k];
  }
  std::vector<double> out;
  for (int tz = 0; tz < m[2]; ++tz)
    for (int ty = 0; ty < m[1]; ++ty)
      for (int tx = 0; tx < m[0]; ++tx)
      {
        double sum = 0.0;
        int count = 0;
        for (int z = tz * f[2]; z < std::min(n[2], (tz + 1) * f[2]); ++z)
          for (int y = ty * f[1]; y < std::min(n[1], (ty + 1) * f[1]); ++y)
            for (int x = tx * f[0]; x < std::min(n[0], (tx + 1) * f[0]); ++x)
            {
              const double v = samples[x + n[0] * (y + n[1] * static_cast<size_t>(z))];
              sum += std::isfinite(v) ? std::max(v, 0.0) : 0.0;
              ++count;
            }
        out.push_back(sum / count);
      }
  return out;
}

std::vector<double> RandomSamples(std::size_t count, unsigned seed, bool withBadValues)
{
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> value(-0.3, 2.0);
  std::uniform_int_distribution<int> special(0, 40);
  std::vector<double> samples(count);
  for (double& v : samples)
  {
    v = value(random);
    if (withBadValues)
    {
      switch (special(random))
      {
        case 0:
          v = std::numeric_limits<double>::quiet_NaN();
          break;
        case 1:
          v = std::numeric_limits<double>::infinity();
          break;
        case 2:
          v = -std::numeric_limits<double>::infinity();
          break;
        default:
          break;
      }
    }
  }
  return samples;
}

bool SameBits(const float* a, const std::vector<float>& b)
{
  return std::memcmp(a, b.data(), b.size() * sizeof(float)) == 0;
}
}

TEST(DensityResample, PlanFactorsAndSizes)
{
  // The mapper test's cloud under a 16-texel limit.
  DensityResamplePlan plan = PlanDensityResample({ 48, 48, 32 }, 16);
  EXPECT_EQ(plan.Factors, (Dims{ 3, 3, 2 }));
  EXPECT_EQ(plan.OutputDimensions, (Dims{ 16, 16, 16 }));
  EXPECT_TRUE(plan.Downsamples());
  // Sizes not divisible by the factor: partial blocks at the upper edge.
  plan = PlanDensityResample({ 10, 7, 4 }, 4);
  EXPECT_EQ(plan.Factors, (Dims{ 3, 2, 1 }));
  EXPECT_EQ(plan.OutputDimensions, (Dims{ 4, 4, 4 }));
  EXPECT_EQ(plan.InputSize(), 280u);
  EXPECT_EQ(plan.OutputSize(), 64u);
  plan = PlanDensityResample({ 5, 5, 5 }, 5);
  EXPECT_FALSE(plan.Downsamples());
  EXPECT_EQ(plan.OutputDimensions, (Dims{ 5, 5, 5 }));
}

// Factors 1..3 on every axis (sizes 3, 7 and 10 under a 4-texel limit, the last
// two not divisible by their factor), random samples with NaN, infinities and
// negatives: the naive mean within float rounding, the former loop bit for bit.
TEST(DensityResample, BoxAverageMatchesReferences)
{
  const int sizes[3] = { 3, 7, 10 }; // factors 1, 2, 3 under the limit 4
  unsigned seed = 1;
  for (int sx : sizes)
    for (int sy : sizes)
      for (int sz : sizes)
      {
        const Dims n = { sx, sy, sz };
        const DensityResamplePlan plan = PlanDensityResample(n, 4);
        const std::vector<double> samples = RandomSamples(plan.InputSize(), seed++, true);
        const auto get = [&samples](std::size_t i) { return samples[i]; };
        const ResampledDensity result = nimbus::ResampleDensityWith(get, plan);
        ASSERT_TRUE(result.IsCopy());
        const std::vector<double> naive = NaiveBlockMean(samples, n, plan.Factors);
        ASSERT_EQ(naive.size(), plan.OutputSize());
        for (std::size_t t = 0; t < naive.size(); ++t)
        {
          EXPECT_NEAR(result.Data()[t], naive[t], 1e-6 * (1.0 + naive[t]))
            << "texel " << t << " of " << sx << "x" << sy << "x" << sz;
        }
        std::size_t formerBad = 0;
        const std::vector<float> former = FormerMapperLoop(get, n, 4, formerBad);
        EXPECT_TRUE(SameBits(result.Data(), former)) << sx << "x" << sy << "x" << sz;
        EXPECT_EQ(result.NonFiniteCount, formerBad);
      }
}

TEST(DensityResample, NonFiniteAndNegativeSamples)
{
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  // No downsampling: each sample on its own.
  const std::vector<double> samples = { 1.5, nan, -2.0, inf, -inf, 0.25, -0.0, 3.0 };
  const DensityResamplePlan same = PlanDensityResample({ 2, 2, 2 }, 2);
  const ResampledDensity out =
    nimbus::ResampleDensityWith([&](std::size_t i) { return samples[i]; }, same);
  const std::vector<float> expected = { 1.5f, 0.0f, 0.0f, 0.0f, 0.0f, 0.25f, 0.0f, 3.0f };
  EXPECT_EQ(out.NonFiniteCount, 3u);
  for (std::size_t i = 0; i < expected.size(); ++i)
  {
    EXPECT_EQ(out.Data()[i], expected[i]) << i;
    EXPECT_FALSE(std::signbit(out.Data()[i])) << i; // no -0 in the texture
  }
  // Downsampled to one texel: the mean of 1.5, 0, 0, 0, 0, 0.25, 0, 3 over all 8.
  const DensityResamplePlan one = PlanDensityResample({ 2, 2, 2 }, 1);
  const ResampledDensity mean =
    nimbus::ResampleDensityWith([&](std::size_t i) { return samples[i]; }, one);
  ASSERT_EQ(one.OutputSize(), 1u);
  EXPECT_FLOAT_EQ(mean.Data()[0], (1.5f + 0.25f + 3.0f) / 8.0f);
  EXPECT_EQ(mean.NonFiniteCount, 3u);
}

// Every numeric VTK type (typed access through vtkArrayDispatch), with and without
// downsampling: the same texels as reading the array with GetComponent in the
// former loop.
TEST(DensityResample, EveryNumericTypeThroughDispatch)
{
  const int types[] = { VTK_CHAR, VTK_SIGNED_CHAR, VTK_UNSIGNED_CHAR, VTK_SHORT, VTK_UNSIGNED_SHORT,
    VTK_INT, VTK_UNSIGNED_INT, VTK_LONG, VTK_UNSIGNED_LONG, VTK_LONG_LONG, VTK_UNSIGNED_LONG_LONG,
    VTK_FLOAT, VTK_DOUBLE, VTK_ID_TYPE };
  const Dims n = { 7, 5, 10 };
  for (int type : types)
  {
    vtkSmartPointer<vtkDataArray> array =
      vtkSmartPointer<vtkDataArray>::Take(vtkDataArray::CreateDataArray(type));
    ASSERT_NE(array, nullptr);
    array->SetNumberOfComponents(1);
    array->SetNumberOfTuples(n[0] * n[1] * n[2]);
    const bool isSigned = array->GetDataTypeMin() < 0;
    std::mt19937 random(type);
    std::uniform_int_distribution<int> value(isSigned ? -20 : 0, 120);
    for (vtkIdType i = 0; i < array->GetNumberOfTuples(); ++i)
    {
      array->SetComponent(i, 0, value(random));
    }
    for (int limit : { 16, 3 })
    {
      const DensityResamplePlan plan = PlanDensityResample(n, limit);
      const ResampledDensity result = nimbus::CloudDensityTexture::Resample(array, plan);
      std::size_t bad = 0;
      const std::vector<float> former = FormerMapperLoop([&](std::size_t i)
        { return array->GetComponent(static_cast<vtkIdType>(i), 0); },
        n, limit, bad);
      EXPECT_EQ(former.size(), plan.OutputSize());
      EXPECT_TRUE(SameBits(result.Data(), former))
        << array->GetDataTypeAsString() << ", limit " << limit;
      // Not one-component floats >= 0 that fit: converted, not borrowed.
      EXPECT_TRUE(result.IsCopy());
    }
  }
}

// Multi-component arrays (contiguous, structure-of-arrays, and a type outside the
// dispatch list): the first component is the density.
TEST(DensityResample, FirstComponentOfMultiComponentArrays)
{
  const Dims n = { 6, 4, 5 };
  const vtkIdType count = n[0] * n[1] * n[2];
  vtkNew<vtkFloatArray> density;
  density->SetNumberOfValues(count);
  vtkNew<vtkDoubleArray> aos;
  aos->SetNumberOfComponents(3);
  aos->SetNumberOfTuples(count);
  vtkNew<vtkSOADataArrayTemplate<short>> soa;
  soa->SetNumberOfComponents(2);
  soa->SetNumberOfTuples(count);
  for (vtkIdType i = 0; i < count; ++i)
  {
    const float v = static_cast<float>((i * 7) % 23);
    density->SetValue(i, v);
    aos->SetTuple3(i, v, -1.0, 1e6);
    soa->SetTypedComponent(i, 0, static_cast<short>(v));
    soa->SetTypedComponent(i, 1, 999);
  }
  for (int limit : { 8, 2 })
  {
    const DensityResamplePlan plan = PlanDensityResample(n, limit);
    const ResampledDensity expected = nimbus::CloudDensityTexture::Resample(density, plan);
    const std::vector<float> reference(
      expected.Data(), expected.Data() + plan.OutputSize()); // one component
    for (vtkDataArray* array : { static_cast<vtkDataArray*>(aos.GetPointer()),
           static_cast<vtkDataArray*>(soa.GetPointer()) })
    {
      const ResampledDensity result = nimbus::CloudDensityTexture::Resample(array, plan);
      EXPECT_TRUE(result.IsCopy());
      EXPECT_TRUE(SameBits(result.Data(), reference))
        << array->GetClassName() << ", limit " << limit;
    }
  }
  // vtkBitArray is not in the dispatch list: generic access, the same result.
  vtkNew<vtkBitArray> bits;
  bits->SetNumberOfComponents(2);
  bits->SetNumberOfTuples(count);
  vtkNew<vtkFloatArray> bitValues;
  bitValues->SetNumberOfValues(count);
  for (vtkIdType i = 0; i < count; ++i)
  {
    bits->SetComponent(i, 0, i % 3 == 0 ? 1 : 0);
    bits->SetComponent(i, 1, 1);
    bitValues->SetValue(i, i % 3 == 0 ? 1.0f : 0.0f);
  }
  const DensityResamplePlan plan = PlanDensityResample(n, 3);
  const ResampledDensity fromBits = nimbus::CloudDensityTexture::Resample(bits, plan);
  const ResampledDensity fromFloats = nimbus::CloudDensityTexture::Resample(bitValues, plan);
  const std::vector<float> reference(fromFloats.Data(), fromFloats.Data() + plan.OutputSize());
  EXPECT_TRUE(SameBits(fromBits.Data(), reference));
}

// A one-component float array that fits and holds only finite values >= 0 is the
// texture as it is: borrowed, not copied. Everything else is converted.
TEST(DensityResample, NoCopyOnlyWhenTheArrayIsTheTexture)
{
  const Dims n = { 8, 6, 5 };
  const vtkIdType count = n[0] * n[1] * n[2];
  const DensityResamplePlan fits = PlanDensityResample(n, 8);
  ASSERT_FALSE(fits.Downsamples());
  auto makeFloats = [&]()
  {
    vtkSmartPointer<vtkFloatArray> array = vtkSmartPointer<vtkFloatArray>::New();
    array->SetNumberOfValues(count);
    for (vtkIdType i = 0; i < count; ++i)
    {
      array->SetValue(i, 0.01f * static_cast<float>(i % 97));
    }
    return array;
  };

  vtkSmartPointer<vtkFloatArray> clean = makeFloats();
  const ResampledDensity borrowed = nimbus::CloudDensityTexture::Resample(clean, fits);
  EXPECT_FALSE(borrowed.IsCopy());
  EXPECT_EQ(borrowed.Data(), clean->GetPointer(0)); // the array's own memory
  EXPECT_TRUE(borrowed.Storage.empty());            // nothing allocated
  EXPECT_EQ(borrowed.NonFiniteCount, 0u);
  // The plain-C++ entry point borrows the same way.
  EXPECT_EQ(nimbus::ResampleDensity(clean->GetPointer(0), 1, fits).Data(), clean->GetPointer(0));

  // Downsampling: converted (averaged) into new storage.
  const ResampledDensity averaged =
    nimbus::CloudDensityTexture::Resample(clean, PlanDensityResample(n, 4));
  EXPECT_TRUE(averaged.IsCopy());
  EXPECT_NE(averaged.Data(), clean->GetPointer(0));

  // A NaN, a negative value, a -0: converted once, the array left as it is.
  const float bad[] = { std::numeric_limits<float>::quiet_NaN(), -0.5f, -0.0f,
    std::numeric_limits<float>::infinity() };
  for (float value : bad)
  {
    vtkSmartPointer<vtkFloatArray> array = makeFloats();
    array->SetValue(17, value);
    const ResampledDensity converted = nimbus::CloudDensityTexture::Resample(array, fits);
    EXPECT_TRUE(converted.IsCopy()) << value;
    EXPECT_NE(converted.Data(), array->GetPointer(0));
    EXPECT_EQ(converted.Data()[17], 0.0f);
    EXPECT_FALSE(std::signbit(converted.Data()[17]));
    EXPECT_EQ(converted.Data()[18], array->GetValue(18));
    EXPECT_EQ(converted.NonFiniteCount, std::isfinite(value) ? 0u : 1u);
    EXPECT_TRUE(std::isnan(value) || array->GetValue(17) == value); // input untouched
  }

  // Other layouts: another type, several components.
  vtkNew<vtkDoubleArray> doubles;
  doubles->DeepCopy(clean);
  EXPECT_TRUE(nimbus::CloudDensityTexture::Resample(doubles, fits).IsCopy());
  vtkNew<vtkFloatArray> pairs;
  pairs->SetNumberOfComponents(2);
  pairs->SetNumberOfTuples(count);
  pairs->Fill(1.0);
  EXPECT_TRUE(nimbus::CloudDensityTexture::Resample(pairs, fits).IsCopy());
}

// The census the mapper's warning reports (NaN, infinite, negative, too large), with
// and without downsampling, and the clamp that keeps block sums and k_cl rho finite.
TEST(DensityResample, CensusAndTooLargeValues)
{
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  const std::vector<double> values = { 1.0, nan, nan, inf, -inf, -2.0, -0.0, 1e300, 1e31, 3.0 };
  const Dims n = { 10, 1, 1 };
  for (const int limit : { 16, 2 })
  {
    const ResampledDensity out =
      nimbus::ResampleDensity(values.data(), 1, PlanDensityResample(n, limit));
    EXPECT_EQ(out.Census.NaN, 2u) << limit;
    EXPECT_EQ(out.Census.Infinite, 2u) << limit;
    EXPECT_EQ(out.Census.Negative, 1u) << limit; // -0 is not negative
    EXPECT_EQ(out.NonFiniteCount, 4u) << limit;
    EXPECT_EQ(out.TooLargeCount, 2u) << limit;
    for (std::size_t i = 0; i < PlanDensityResample(n, limit).OutputSize(); ++i)
    {
      EXPECT_TRUE(std::isfinite(out.Data()[i]) && out.Data()[i] >= 0.0f) << limit << " " << i;
      EXPECT_LE(out.Data()[i], nimbus::kMaximumDensity * (1 + 1e-6)) << limit << " " << i;
    }
  }
  // Floats above the limit are not borrowed (they would reach the texture).
  const std::vector<float> large = { 1.0f, 2e38f };
  EXPECT_FALSE(nimbus::IsTextureReadyDensity(large.data(), large.size()));
  const ResampledDensity clamped =
    nimbus::ResampleDensity(large.data(), 1, PlanDensityResample({ 2, 1, 1 }, 16));
  EXPECT_TRUE(clamped.IsCopy());
  EXPECT_FLOAT_EQ(clamped.Data()[1], static_cast<float>(nimbus::kMaximumDensity));
}

// The emission texels (hot smoke): per texel the mean over its block of rho B(T) / Y[B(T_ref)],
// blocks at the upper edges partial; NaN or negative densities and NaN temperatures emit
// nothing.
TEST(EmissionTexels, BlockMeansOfDensityTimesBlackbody)
{
  const nimbus::SpectralSamples spectrum;
  const nimbus::BlackbodyEmission blackbody(spectrum, 1500.0);
  const std::array<int, 3> dims{ { 3, 2, 1 } };
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const std::vector<float> rho = { 1.0f, 2.0f, 4.0f, nan, -1.0f, 0.5f };
  const std::vector<float> kelvin = { 1500.0f, 2000.0f, 1800.0f, 1500.0f, 1500.0f, nan };
  const std::vector<float> texels = nimbus::ComputeEmissionTexels(
    rho.data(), kelvin.data(), dims, { { 2, 2, 1 } }, { { 2, 1, 1 } }, blackbody);
  ASSERT_EQ(texels.size(), 6u);
  for (int c = 0; c < 3; ++c)
  {
    // Texel 0: samples 0, 1, 3, 4 (two of them emit nothing); texel 1: samples 2 and 5.
    const double first =
      (1.0 * blackbody.RelativeRgb(1500.0)[c] + 2.0 * blackbody.RelativeRgb(2000.0)[c]) / 4.0;
    const double second = 4.0 * blackbody.RelativeRgb(1800.0)[c] / 2.0;
    EXPECT_NEAR(texels[c], first, 1e-6 * std::abs(first)) << c;
    EXPECT_NEAR(texels[3 + c], second, 1e-6 * std::abs(second)) << c;
  }
}
