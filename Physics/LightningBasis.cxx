#include "LightningBasis.h"

#include "ParallelFor.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
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
// FNV-1a over bytes, 64 bits; two different offset bases make the 128-bit fingerprint.
class Fnv1a
{
public:
  explicit Fnv1a(std::uint64_t basis)
    : Hash(basis)
  {
  }
  void Bytes(const void* data, std::size_t size)
  {
    const unsigned char* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < size; ++i)
    {
      this->Hash = (this->Hash ^ p[i]) * 1099511628211ull;
    }
  }
  template <typename T>
  void Value(const T& value)
  {
    this->Bytes(&value, sizeof(T));
  }
  std::uint64_t Hash;
};

constexpr char kMagic[8] = { 'N', 'I', 'M', 'B', 'L', 'B', 'A', 'S' };
constexpr std::uint32_t kFormatVersion = 1;
// The solver's revision, in the fingerprint so that a basis the solver would now compute
// differently is not taken from the disk cache (2: point lights' first source averaged
// over the cells next to them, MultipleScattering.cxx ArrivalAt).
constexpr std::uint32_t kSolverRevision = 3;

template <typename T>
void Put(std::ostream& out, const T& value)
{
  out.write(reinterpret_cast<const char*>(&value), sizeof(T));
}

template <typename T>
bool Get(std::istream& in, T& value)
{
  return static_cast<bool>(in.read(reinterpret_cast<char*>(&value), sizeof(T)));
}
} // namespace

std::string LightningBasisFingerprint(const ExtinctionGrid& cloud, const CloudOptics& optics,
  const VirtualLightGrid& lights, const LightningBasisOptions& options)
{
  std::uint64_t hashes[2] = { 0, 0 };
  const std::uint64_t bases[2] = { 14695981039346656037ull, 0x84222325cbf29ce4ull };
  for (int h = 0; h < 2; ++h)
  {
    Fnv1a f(bases[h]);
    f.Value(kFormatVersion);
    f.Value(kSolverRevision);
    f.Value(cloud.Dimensions);
    f.Value(cloud.Origin);
    f.Value(cloud.Spacing);
    f.Value(cloud.Axes);
    f.Bytes(cloud.Extinction.data(), cloud.Extinction.size() * sizeof(float));
    f.Value(optics.Albedo);
    f.Value(static_cast<int>(optics.Phase));
    f.Value(optics.G);
    for (const std::vector<double>& axis : lights.Nodes)
    {
      f.Value(axis.size());
      f.Bytes(axis.data(), axis.size() * sizeof(double));
    }
    f.Value(options.NumberOfDirections);
    f.Value(options.Orders);
    f.Value(options.Threshold);
    f.Value(options.IncludeFirstScattering);
    hashes[h] = f.Hash;
  }
  char text[33];
  std::snprintf(text, sizeof(text), "%016llx%016llx", static_cast<unsigned long long>(hashes[0]),
    static_cast<unsigned long long>(hashes[1]));
  return text;
}

void WriteLightningBasis(
  const LightningBasis& basis, const std::string& fingerprint, const std::string& path)
{
  const std::string partial = path + ".partial";
  {
    std::ofstream out(partial, std::ios::binary | std::ios::trunc);
    if (!out)
    {
      throw std::runtime_error("nimbus::WriteLightningBasis: cannot write " + partial);
    }
    out.write(kMagic, sizeof(kMagic));
    Put(out, kFormatVersion);
    const std::uint32_t length = static_cast<std::uint32_t>(fingerprint.size());
    Put(out, length);
    out.write(fingerprint.data(), length);
    Put(out, basis.Dimensions);
    Put(out, basis.Seconds);
    for (const std::vector<double>& axis : basis.Lights.Nodes)
    {
      Put(out, static_cast<std::uint64_t>(axis.size()));
      out.write(reinterpret_cast<const char*>(axis.data()),
        static_cast<std::streamsize>(axis.size() * sizeof(double)));
    }
    Put(out, static_cast<std::uint64_t>(basis.Fields.size()));
    for (const SparseHaarField& field : basis.Fields)
    {
      Put(out, field.Dimensions);
      Put(out, field.Padded);
      Put(out, field.DroppedNorm);
      Put(out, static_cast<std::uint64_t>(field.Index.size()));
      out.write(reinterpret_cast<const char*>(field.Index.data()),
        static_cast<std::streamsize>(field.Index.size() * sizeof(std::uint32_t)));
      out.write(reinterpret_cast<const char*>(field.Value.data()),
        static_cast<std::streamsize>(field.Value.size() * sizeof(float)));
    }
    out.flush();
    if (!out)
    {
      out.close();
      std::remove(partial.c_str());
      throw std::runtime_error("nimbus::WriteLightningBasis: writing " + partial + " failed");
    }
  }
  if (std::rename(partial.c_str(), path.c_str()) != 0)
  {
    std::remove(partial.c_str());
    throw std::runtime_error(
      "nimbus::WriteLightningBasis: cannot rename " + partial + " to " + path);
  }
}

bool ReadLightningBasis(
  const std::string& path, const std::string& fingerprint, LightningBasis& basis, std::string& why)
{
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in)
  {
    why = "no file " + path;
    return false;
  }
  // Sizes read from the file are checked against what is left of it before anything
  // is allocated, so a damaged count cannot ask for gigabytes.
  const std::streamoff fileSize = in.tellg();
  in.seekg(0);
  const auto left = [&]() { return static_cast<std::uint64_t>(fileSize - in.tellg()); };
  char magic[sizeof(kMagic)];
  std::uint32_t version = 0, length = 0;
  if (!in.read(magic, sizeof(magic)) || std::memcmp(magic, kMagic, sizeof(kMagic)) != 0 ||
    !Get(in, version) || !Get(in, length) || length > 256)
  {
    why = path + " is not a Nimbus lightning basis";
    return false;
  }
  if (version != kFormatVersion)
  {
    why = path + " has format version " + std::to_string(version) + ", not " +
      std::to_string(kFormatVersion);
    return false;
  }
  std::string stored(length, '\0');
  if (!in.read(&stored[0], length) || stored != fingerprint)
  {
    why = path + " holds another basis (fingerprint " + stored + ")";
    return false;
  }
  const auto damaged = [&](const char* what)
  {
    why = path + " is damaged: " + what;
    return false;
  };
  LightningBasis read;
  if (!Get(in, read.Dimensions) || !Get(in, read.Seconds))
  {
    return damaged("truncated header");
  }
  for (int k = 0; k < 3; ++k)
  {
    if (read.Dimensions[k] < 1 || read.Dimensions[k] > (1 << 20))
    {
      return damaged("bad grid dimensions");
    }
  }
  std::array<int, 3> padded;
  try
  {
    padded = HaarPaddedDimensions(read.Dimensions);
  }
  catch (const std::exception&)
  {
    return damaged("bad grid dimensions");
  }
  const std::uint64_t paddedSize = static_cast<std::uint64_t>(padded[0]) * padded[1] * padded[2];
  for (std::vector<double>& axis : read.Lights.Nodes)
  {
    std::uint64_t count = 0;
    if (!Get(in, count) || count < 1 || count > left() / sizeof(double))
    {
      return damaged("bad light grid");
    }
    axis.resize(count);
    if (!in.read(reinterpret_cast<char*>(axis.data()),
          static_cast<std::streamsize>(count * sizeof(double))))
    {
      return damaged("truncated light grid");
    }
  }
  std::uint64_t fields = 0;
  if (!Get(in, fields) || fields > left() || fields != kShPerChannel * read.Lights.NumberOfNodes())
  {
    return damaged("the number of fields does not match the lights");
  }
  read.Fields.resize(fields);
  for (SparseHaarField& field : read.Fields)
  {
    std::uint64_t kept = 0;
    if (!Get(in, field.Dimensions) || !Get(in, field.Padded) || !Get(in, field.DroppedNorm) ||
      !Get(in, kept))
    {
      return damaged("truncated field");
    }
    if (field.Dimensions != read.Dimensions || field.Padded != padded || kept > paddedSize ||
      kept > left() / (sizeof(std::uint32_t) + sizeof(float)) || !(field.DroppedNorm >= 0.0) ||
      !std::isfinite(field.DroppedNorm))
    {
      return damaged("a field's header does not match the grid");
    }
    field.Index.resize(kept);
    field.Value.resize(kept);
    if (!in.read(reinterpret_cast<char*>(field.Index.data()),
          static_cast<std::streamsize>(kept * sizeof(std::uint32_t))) ||
      !in.read(reinterpret_cast<char*>(field.Value.data()),
        static_cast<std::streamsize>(kept * sizeof(float))))
    {
      return damaged("truncated field");
    }
    for (std::size_t i = 0; i < kept; ++i)
    {
      if (field.Index[i] >= paddedSize || (i > 0 && field.Index[i] <= field.Index[i - 1]) ||
        !std::isfinite(field.Value[i]))
      {
        return damaged("a field's coefficients are out of range");
      }
    }
  }
  char extra;
  if (in.read(&extra, 1))
  {
    return damaged("bytes after the last field");
  }
  basis = std::move(read);
  return true;
}

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
  // Three lights per solve: the solver carries red, green and blue through the same
  // sweeps independently (the cloud's optics are grey), so light 3t + c goes in channel
  // c of solve t, and one solve gives three basis fields for the cost of one. The
  // solves over threads (results independent of the split), in batches so that
  // progress is reported (and a stop honoured) on this thread.
  const std::size_t solves = (count + 2) / 3;
  const int threads = ThreadCount(options.Threads);
  const std::size_t batch = static_cast<std::size_t>(4 * threads);
  for (std::size_t first = 0; first < solves; first += batch)
  {
    const std::size_t last = std::min(solves, first + batch);
    ParallelFor(last - first, 1, threads,
      [&](std::size_t begin, std::size_t end)
      {
        begin += first;
        end += first;
        std::vector<float> values(n);
        for (std::size_t t = begin; t < end; ++t)
        {
          CloudLighting lighting;
          lighting.HasSun = false;
          for (std::size_t c = 0; c < 3 && 3 * t + c < count; ++c)
          {
            const std::size_t l = 3 * t + c;
            Rgb unit{ { 0.0, 0.0, 0.0 } };
            unit[c] = 1.0;
            lighting.PointLights.push_back(
              PointLight{ lights.Position(l % nx, (l / nx) % ny, l / (nx * ny)), unit });
          }
          const MultipleScatteringField solved =
            SolveMultipleScattering(cloud, optics, lighting, solver);
          for (std::size_t c = 0; c < lighting.PointLights.size(); ++c)
          {
            const std::size_t l = 3 * t + c;
            for (int b = 0; b < kShPerChannel; ++b)
            {
              for (std::size_t i = 0; i < n; ++i)
              {
                values[i] = solved.Coefficients[i * kCoefficients + kShPerChannel * c + b];
              }
              basis.Fields[kShPerChannel * l + b] = CompressHaar(values, cloud.Dimensions, 0.0);
            }
          }
        }
      });
    if (progress)
    {
      progress(static_cast<double>(last) / solves);
    }
  }
  // 003 Eq. 5: the coefficients of magnitude <= xi dropped, xi relative to the largest
  // coefficient of the whole basis (one absolute threshold for every light: what a
  // light far from the cloud contributes is small in every coefficient, and the
  // relight's error is the weighted sum of what was dropped).
  if (options.Threshold > 0.0)
  {
    double largest = 0.0;
    for (const SparseHaarField& field : basis.Fields)
    {
      for (float v : field.Value)
      {
        largest = std::max(largest, static_cast<double>(std::abs(v)));
      }
    }
    ParallelFor(basis.Fields.size(), 16, threads,
      [&](std::size_t begin, std::size_t end)
      {
        for (std::size_t f = begin; f < end; ++f)
        {
          DropHaarCoefficients(basis.Fields[f], options.Threshold * largest);
        }
      });
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
  // Sources of one colour (a flash has one spectrum): e_l = s_l k for a common k, so the
  // sums of Eq. 9 are made once, for s, and scaled by k per channel (a third of the work;
  // the same result to about 1e-9). Otherwise one sum per channel.
  Rgb colour{ { 0, 0, 0 } };
  std::size_t strongest = count;
  double largest = 0.0;
  for (std::size_t l = 0; l < count; ++l)
  {
    const double size = std::max({ std::abs(e[l][0]), std::abs(e[l][1]), std::abs(e[l][2]) });
    if (size > largest)
    {
      largest = size;
      strongest = l;
    }
  }
  bool oneColour = strongest < count;
  std::vector<double> scale(count, 0.0);
  if (oneColour)
  {
    colour = e[strongest];
    int main = 0;
    for (int c = 1; c < 3; ++c)
    {
      main = std::abs(colour[c]) > std::abs(colour[main]) ? c : main;
    }
    for (std::size_t l = 0; l < count && oneColour; ++l)
    {
      scale[l] = e[l][main] / colour[main];
      for (int c = 0; c < 3; ++c)
      {
        oneColour = oneColour && std::abs(e[l][c] - scale[l] * colour[c]) <= 1e-12 * largest;
      }
    }
  }
  const int sums = oneColour ? 1 : 3;
  for (int b = 0; b < kShPerChannel; ++b)
  {
    for (int c = 0; c < sums; ++c)
    {
      std::vector<double> h; // H of 003 Eq. 9
      double ambient = 0.0;  // 003 Eq. 10
      for (std::size_t l = 0; l < count; ++l)
      {
        const double weight = oneColour ? scale[l] : e[l][c];
        if (weight == 0.0)
        {
          continue;
        }
        const SparseHaarField& field = basis.Fields[kShPerChannel * l + b];
        AccumulateHaar(field, weight, h);
        ambient += weight * field.AmbientPerPoint();
      }
      if (h.empty())
      {
        continue;
      }
      const std::vector<double> values = ReconstructHaar(h, basis.Dimensions, padded); // Eq. 8
      const double constant = b == 0 ? ambient : 0.0;
      for (int channel = oneColour ? 0 : c; channel < (oneColour ? 3 : c + 1); ++channel)
      {
        const double k = oneColour ? colour[channel] : 1.0;
        for (std::size_t i = 0; i < n; ++i)
        {
          out.Coefficients[i * kCoefficients + 4 * channel + b] =
            static_cast<float>(k * (values[i] + constant));
        }
      }
    }
  }
  return out;
}

} // namespace nimbus
