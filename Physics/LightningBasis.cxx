#include "LightningBasis.h"

#include "ParallelFor.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>
#include <thread>

namespace nimbus
{
namespace
{
constexpr int kShPerChannel = 4;  // c_00, c_1-1, c_10, c_11
constexpr int kCoefficients = 12; // per point: 4 SH x RGB

MultipleScatteringOptions SolverOptions(const LightningBasisOptions& options)
{
  MultipleScatteringOptions solver;
  solver.Method = MultipleScatteringMethod::DiscreteDirections;
  solver.NumberOfDirections = options.NumberOfDirections;
  solver.Orders = options.Orders;
  solver.SkyLight = false;
  solver.PointLightFirstScattering = options.IncludeFirstScattering;
  solver.Threads = 1; // the lights run in parallel
  return solver;
}

int ThreadCount(int requested)
{
  if (requested > 0)
  {
    return requested;
  }
  return std::max(1u, std::thread::hardware_concurrency());
}
} // namespace

double LightningBasis::CompressedBytes() const
{
  double bytes = 0.0;
  for (const SparseHaarField& f : this->Fields)
  {
    bytes += static_cast<double>(f.Bytes());
  }
  return bytes;
}

double EstimateLightningBasisBytes(
  const ExtinctionGrid& cloud, const VirtualLightGrid& lights, const LightningBasisOptions& options)
{
  const double n = static_cast<double>(cloud.NumberOfPoints());
  const std::array<int, 3> padded = HaarPaddedDimensions(cloud.Dimensions);
  const double paddedSize = static_cast<double>(padded[0]) * padded[1] * padded[2];
  // Worst case: every coefficient kept (index + value), plus per thread one solve's
  // scratch and the transform's doubles.
  const double basis = 4.0 * paddedSize * 8.0 * lights.NumberOfNodes();
  const double perThread =
    EstimateMultipleScatteringBytes(cloud, SolverOptions(options)) + 8.0 * paddedSize + 48.0 * n;
  return basis + ThreadCount(options.Threads) * perThread;
}

LightningBasis PrecomputeLightningBasis(const ExtinctionGrid& cloud, const CloudOptics& optics,
  const VirtualLightGrid& lights, const LightningBasisOptions& options,
  const std::function<void(double)>& progress)
{
  const auto start = std::chrono::steady_clock::now();
  if (!(options.Threshold >= 0.0) || !std::isfinite(options.Threshold))
  {
    throw std::invalid_argument(
      "nimbus::PrecomputeLightningBasis: the threshold must be finite and >= 0");
  }
  if (lights.NumberOfNodes() == 0)
  {
    throw std::invalid_argument("nimbus::PrecomputeLightningBasis: the light grid has no nodes");
  }
  const MultipleScatteringOptions solver = SolverOptions(options);
  CloudLighting probe;
  probe.HasSun = false;
  probe.PointLights = { PointLight{ lights.Position(0, 0, 0), { { 1.0, 1.0, 1.0 } } } };
  const std::string why = CheckMultipleScatteringInput(cloud, optics, probe, solver);
  if (!why.empty())
  {
    throw std::invalid_argument("nimbus::PrecomputeLightningBasis: " + why);
  }
  if (options.MemoryBudgetBytes > 0.0)
  {
    const double need = EstimateLightningBasisBytes(cloud, lights, options);
    if (need > options.MemoryBudgetBytes)
    {
      throw std::length_error("nimbus::PrecomputeLightningBasis: the basis may need " +
        std::to_string(need / 1048576.0) + " MiB, more than the budget of " +
        std::to_string(options.MemoryBudgetBytes / 1048576.0) +
        " MiB; use fewer virtual lights, a coarser cloud grid or a larger threshold");
    }
  }

  LightningBasis basis;
  basis.Dimensions = cloud.Dimensions;
  basis.Lights = lights;
  const std::size_t count = lights.NumberOfNodes();
  basis.Fields.resize(kShPerChannel * count);
  const std::size_t n = cloud.NumberOfPoints();
  const std::size_t nx = lights.Nodes[0].size(), ny = lights.Nodes[1].size();
  // The lights over threads, one solve each (results independent of the split), in
  // batches so that progress is reported (and a stop honoured) on this thread.
  const int threads = ThreadCount(options.Threads);
  const std::size_t batch = static_cast<std::size_t>(4 * threads);
  for (std::size_t first = 0; first < count; first += batch)
  {
    const std::size_t last = std::min(count, first + batch);
    ParallelFor(last - first, 1, threads,
      [&](std::size_t begin, std::size_t end)
      {
        begin += first;
        end += first;
        std::vector<float> values(n);
        for (std::size_t l = begin; l < end; ++l)
        {
          CloudLighting lighting;
          lighting.HasSun = false;
          lighting.PointLights = { PointLight{
            lights.Position(l % nx, (l / nx) % ny, l / (nx * ny)), { { 1.0, 1.0, 1.0 } } } };
          const MultipleScatteringField field =
            SolveMultipleScattering(cloud, optics, lighting, solver);
          for (int b = 0; b < kShPerChannel; ++b)
          {
            double largest = 0.0;
            for (std::size_t i = 0; i < n; ++i)
            {
              values[i] = field.Coefficients[i * kCoefficients + b]; // red = grey
            }
            // The threshold relative to this field's largest Haar coefficient.
            SparseHaarField field = CompressHaar(values, cloud.Dimensions, 0.0);
            for (float v : field.Value)
            {
              largest = std::max(largest, static_cast<double>(std::abs(v)));
            }
            if (options.Threshold > 0.0)
            {
              DropHaarCoefficients(field, options.Threshold * largest);
            }
            basis.Fields[kShPerChannel * l + b] = std::move(field);
          }
        }
      });
    if (progress)
    {
      progress(static_cast<double>(last) / count);
    }
  }
  basis.Seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return basis;
}

MultipleScatteringField RelightLightning(const LightningBasis& basis, const std::vector<Rgb>& e)
{
  const std::size_t count = basis.Lights.NumberOfNodes();
  if (e.size() != count || basis.Fields.size() != kShPerChannel * count)
  {
    throw std::invalid_argument(
      "nimbus::RelightLightning: one intensity per virtual light is needed");
  }
  for (const Rgb& v : e)
  {
    if (!std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2]))
    {
      throw std::invalid_argument("nimbus::RelightLightning: an intensity is not finite");
    }
  }
  const std::size_t n = basis.NumberOfPoints();
  MultipleScatteringField out;
  out.Dimensions = basis.Dimensions;
  out.Coefficients.assign(n * kCoefficients, 0.0f);
  if (count == 0 || n == 0)
  {
    return out;
  }
  const std::array<int, 3> padded = basis.Fields[0].Padded;
  for (int b = 0; b < kShPerChannel; ++b)
  {
    for (int c = 0; c < 3; ++c)
    {
      std::vector<double> h; // H of 003 Eq. 9
      double ambient = 0.0;  // 003 Eq. 10
      for (std::size_t l = 0; l < count; ++l)
      {
        if (e[l][c] == 0.0)
        {
          continue;
        }
        const SparseHaarField& field = basis.Fields[kShPerChannel * l + b];
        AccumulateHaar(field, e[l][c], h);
        ambient += e[l][c] * field.AmbientPerPoint();
      }
      if (h.empty())
      {
        continue;
      }
      const std::vector<double> values = ReconstructHaar(h, basis.Dimensions, padded); // Eq. 8
      const double constant = b == 0 ? ambient : 0.0;
      for (std::size_t i = 0; i < n; ++i)
      {
        out.Coefficients[i * kCoefficients + 4 * c + b] = static_cast<float>(values[i] + constant);
      }
    }
  }
  return out;
}

} // namespace nimbus
