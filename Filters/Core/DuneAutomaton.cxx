#include "DuneAutomaton.h"

#include "ParallelFor.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace nimbus
{

namespace
{
constexpr double Pi = 3.14159265358979323846;
constexpr double MaximumLength = 1.0e8; // m, as the other sources
constexpr int MaximumHops = 16;         // the rest of the flight lands at the 16th

double Tangent(double degrees)
{
  return std::tan(degrees * Pi / 180.0);
}

bool Finite(double value)
{
  return std::isfinite(value);
}

std::uint64_t SplitMix(std::uint64_t z)
{
  z += 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}
}

SandParameters RippleParameters()
{
  SandParameters p;
  p.CellSizeMetres = 0.01;
  p.SaltationLengthMetres = 0.06;
  p.SaltationHeightGain = 1.0;
  p.SaltationDepthMetres = 0.003;
  p.CreepRate = 0.2;
  p.Bedrock = false;
  p.ReposeAngleDegrees = 30.0;
  return p;
}

SandParameters DuneParameters()
{
  SandParameters p;
  p.CellSizeMetres = 2.0;
  p.SaltationLengthMetres = 8.0;
  p.SaltationHeightGain = 0.02;
  p.SaltationDepthMetres = 0.2;
  p.CreepRate = 0.2;
  p.Bedrock = true;
  p.ShadowAngleDegrees = 15.0;
  p.ReposeAngleDegrees = 34.0;
  p.AvalancheSweeps = 4;
  return p;
}

std::string CheckSandParameters(const SandParameters& p)
{
  std::ostringstream message;
  if (p.Dimensions[0] < 1 || p.Dimensions[1] < 1 || p.Dimensions[0] > 65536 ||
    p.Dimensions[1] > 65536)
  {
    message << "the grid must have 1 to 65536 cells a side, got " << p.Dimensions[0] << " x "
            << p.Dimensions[1];
  }
  else if (!Finite(p.CellSizeMetres) || !(p.CellSizeMetres > 0.0) ||
    p.CellSizeMetres > MaximumLength)
  {
    message << "the cell size must be a finite length in (0, 1e8] m, got " << p.CellSizeMetres;
  }
  else if (!Finite(p.SaltationLengthMetres) || p.SaltationLengthMetres < 0.0 ||
    p.SaltationLengthMetres > 0.25 * p.CellSizeMetres * p.Dimensions[0])
  {
    message << "the saltation length must be finite, >= 0 m and at most a quarter of the grid ("
            << 0.25 * p.CellSizeMetres * p.Dimensions[0] << " m), got " << p.SaltationLengthMetres;
  }
  else if (!Finite(p.SaltationHeightGain) || p.SaltationHeightGain < 0.0 ||
    p.SaltationHeightGain > 100.0)
  {
    message << "the saltation height gain must be in [0, 100] m per m, got "
            << p.SaltationHeightGain;
  }
  else if (!Finite(p.SaltationDepthMetres) || p.SaltationDepthMetres < 0.0 ||
    p.SaltationDepthMetres > MaximumLength)
  {
    message << "the saltation depth must be a finite height >= 0 m, got " << p.SaltationDepthMetres;
  }
  else if (!Finite(p.CreepRate) || p.CreepRate < 0.0 || p.CreepRate > 1.0)
  {
    message << "the creep rate must be in [0, 1], got " << p.CreepRate;
  }
  else if (!Finite(p.ShadowAngleDegrees) || p.ShadowAngleDegrees < 0.0 ||
    p.ShadowAngleDegrees >= 90.0)
  {
    message << "the wind-shadow angle must be in [0, 90) degrees, got " << p.ShadowAngleDegrees;
  }
  else if (!Finite(p.ReposeAngleDegrees) || p.ReposeAngleDegrees < 0.0 ||
    p.ReposeAngleDegrees >= 90.0)
  {
    message << "the angle of repose must be in [0, 90) degrees, got " << p.ReposeAngleDegrees;
  }
  else if (!Finite(p.SaturationDepthMetres) || p.SaturationDepthMetres < 0.0 ||
    p.SaturationDepthMetres > MaximumLength)
  {
    message << "the saturation depth must be a finite height >= 0 m, got "
            << p.SaturationDepthMetres;
  }
  else if (!(p.DepositionOnSand >= 0.01 && p.DepositionOnSand <= 1.0) ||
    !(p.DepositionOnRock >= 0.01 && p.DepositionOnRock <= 1.0))
  {
    message << "the deposition fractions must be in [0.01, 1], got " << p.DepositionOnSand
            << " on sand and " << p.DepositionOnRock << " on rock";
  }
  else if (p.AvalancheSweeps < 0 || p.AvalancheSweeps > 1000)
  {
    message << "the avalanche sweeps must be in [0, 1000], got " << p.AvalancheSweeps;
  }
  return message.str();
}

double HashUniform(std::uint64_t seed, std::uint64_t a, std::uint64_t b)
{
  const std::uint64_t h = SplitMix(SplitMix(SplitMix(seed) ^ a) ^ (b * 0x632be59bd9b4e019ULL));
  return static_cast<double>(h >> 11) * 0x1.0p-53;
}

std::vector<double> RandomSandBed(
  int nx, int ny, double meanMetres, double amplitudeMetres, std::uint64_t seed)
{
  std::vector<double> heights(static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny));
  for (int y = 0; y < ny; ++y)
  {
    for (int x = 0; x < nx; ++x)
    {
      heights[static_cast<std::size_t>(x) + static_cast<std::size_t>(nx) * y] =
        meanMetres + amplitudeMetres * (HashUniform(seed, x, y) - 0.5);
    }
  }
  return heights;
}

SandAutomaton::SandAutomaton(const SandParameters& parameters, std::vector<double> heights)
  : P(parameters)
  , H(std::move(heights))
{
  const std::string problem = CheckSandParameters(parameters);
  if (!problem.empty())
  {
    throw std::invalid_argument("sand automaton: " + problem + ".");
  }
  const std::size_t cells =
    static_cast<std::size_t>(P.Dimensions[0]) * static_cast<std::size_t>(P.Dimensions[1]);
  if (this->H.size() != cells)
  {
    throw std::invalid_argument("sand automaton: the height field has the wrong size.");
  }
  for (double& h : this->H)
  {
    if (!std::isfinite(h) || std::abs(h) > MaximumLength)
    {
      throw std::invalid_argument("sand automaton: heights must be finite, within +-1e8 m.");
    }
    if (P.Bedrock && h < 0.0)
    {
      h = 0.0;
    }
  }
  this->Scratch.resize(cells);
}

double SandAutomaton::Volume() const
{
  double sum = 0.0;
  for (double h : this->H)
  {
    sum += h;
  }
  return sum * P.CellSizeMetres * P.CellSizeMetres;
}

void SandAutomaton::Run(
  long long steps, int threads, const std::function<bool(long long stepsDone)>& progress)
{
  for (long long s = 0; s < steps; ++s)
  {
    this->Saltation(threads);
    if (P.CreepRate > 0.0)
    {
      this->Creep(threads);
    }
    if (P.ReposeAngleDegrees > 0.0)
    {
      for (int sweep = 0; sweep < P.AvalancheSweeps; ++sweep)
      {
        this->Avalanche(threads);
      }
    }
    ++this->Steps;
    if (progress && !progress(s + 1))
    {
      return;
    }
  }
}

// N&O Eq. 1 with the wind shadow: rows are independent (the wind is along x).
void SandAutomaton::Saltation(int threads)
{
  const int nx = P.Dimensions[0];
  const int ny = P.Dimensions[1];
  const double dx = P.CellSizeMetres;
  const double shadowDrop = P.ShadowAngleDegrees > 0.0 ? dx * Tangent(P.ShadowAngleDegrees) : 0.0;
  ParallelFor(static_cast<std::size_t>(ny), 1, threads,
    [&](std::size_t begin, std::size_t end)
    {
      std::vector<char> shadow(static_cast<std::size_t>(nx), 0);
      for (std::size_t y = begin; y < end; ++y)
      {
        const double* h = this->H.data() + y * nx;
        double* out = this->Scratch.data() + y * nx;
        std::copy(h, h + nx, out);
        if (shadowDrop > 0.0)
        {
          // The shadow line: the highest upwind crest lowered by tan(angle) per metre;
          // two turns around the periodic row reach every upwind cell.
          double line = -std::numeric_limits<double>::infinity();
          for (int i = 0; i < 2 * nx; ++i)
          {
            const int x = i % nx;
            line -= shadowDrop;
            if (i >= nx)
            {
              // Below the shadow line, or on a face turned away from the wind (lower than
              // its upwind neighbour): the flow separates there and no grain is lifted.
              shadow[x] = (h[x] < line || h[x] < h[(x + nx - 1) % nx]) ? 1 : 0;
            }
            line = std::max(line, h[x]);
          }
        }
        for (int x = 0; x < nx; ++x)
        {
          if (shadow[x])
          {
            continue;
          }
          // With a bedrock, q tanh(h / h_s) (Nishimori, Yamasaki and Andersen 1998: the
          // lifted amount saturates with the sand's depth), never more than the sand there.
          double lift = P.SaltationDepthMetres;
          if (P.Bedrock)
          {
            const double sand = std::max(h[x], 0.0);
            lift = std::min(sand,
              P.SaturationDepthMetres > 0.0 ? lift * std::tanh(sand / P.SaturationDepthMetres)
                                            : lift);
          }
          if (!(lift > 0.0))
          {
            continue;
          }
          // L = L0 + b h (N&O Eq. 1), in cells.
          double length =
            std::max(0.0, P.SaltationLengthMetres + P.SaltationHeightGain * h[x]) / dx;
          out[x] -= lift;
          // The grain hops on until it stays: a fraction of what lands stays (all of it in a
          // wind shadow; DepositionOnSand on sand, DepositionOnRock on bare rock: Werner
          // 1995's probabilities, here as fractions of the flux), the rest jumps again from
          // where it landed, L from that cell's height. Ripples (no bedrock): one hop.
          double flying = lift;
          double from = x;
          for (int hop = 0; hop < MaximumHops && flying > 0.0; ++hop)
          {
            const double target = from + std::min(length, 1.0e6);
            const double whole = std::floor(target);
            const double f = target - whole;
            const int x0 = static_cast<int>(static_cast<long long>(whole) % nx);
            const int x1 = (x0 + 1) % nx;
            double stay = 1.0;
            if (P.Bedrock && hop + 1 < MaximumHops && !shadow[x0])
            {
              stay = h[x0] > 0.0 ? P.DepositionOnSand : P.DepositionOnRock;
            }
            const double landed = flying * stay;
            const double far = landed * f;
            out[x0] += landed - far;
            out[x1] += far;
            flying -= landed;
            from = target;
            length = std::max(0.0, P.SaltationLengthMetres + P.SaltationHeightGain * h[x0]) / dx;
          }
        }
      }
    });
  this->H.swap(this->Scratch);
}

// N&O Eq. 2: relaxation toward the weighted mean of the 8 neighbours.
void SandAutomaton::Creep(int threads)
{
  const int nx = P.Dimensions[0];
  const int ny = P.Dimensions[1];
  const double d = P.CreepRate;
  ParallelFor(static_cast<std::size_t>(ny), 8, threads,
    [&](std::size_t begin, std::size_t end)
    {
      for (std::size_t yy = begin; yy < end; ++yy)
      {
        const int y = static_cast<int>(yy);
        const double* row = this->H.data() + static_cast<std::size_t>(y) * nx;
        const double* up = this->H.data() + static_cast<std::size_t>((y + 1) % ny) * nx;
        const double* down = this->H.data() + static_cast<std::size_t>((y + ny - 1) % ny) * nx;
        double* out = this->Scratch.data() + static_cast<std::size_t>(y) * nx;
        for (int x = 0; x < nx; ++x)
        {
          const int xl = (x + nx - 1) % nx;
          const int xr = (x + 1) % nx;
          const double nearest = row[xl] + row[xr] + up[x] + down[x];
          const double diagonal = up[xl] + up[xr] + down[xl] + down[xr];
          out[x] = row[x] + d * (nearest / 6.0 + diagonal / 12.0 - row[x]);
        }
      }
    });
  this->H.swap(this->Scratch);
}

// Avalanches: a fifth of the height above the angle of repose flows across each of the four
// edges of a cell; the flux of an edge is computed the same way from both of its cells, so
// what one cell loses the other gains exactly.
void SandAutomaton::Avalanche(int threads)
{
  const int nx = P.Dimensions[0];
  const int ny = P.Dimensions[1];
  const double limit = P.CellSizeMetres * Tangent(P.ReposeAngleDegrees);
  ParallelFor(static_cast<std::size_t>(ny), 8, threads,
    [&](std::size_t begin, std::size_t end)
    {
      for (std::size_t yy = begin; yy < end; ++yy)
      {
        const int y = static_cast<int>(yy);
        const double* row = this->H.data() + static_cast<std::size_t>(y) * nx;
        const double* up = this->H.data() + static_cast<std::size_t>((y + 1) % ny) * nx;
        const double* down = this->H.data() + static_cast<std::size_t>((y + ny - 1) % ny) * nx;
        double* out = this->Scratch.data() + static_cast<std::size_t>(y) * nx;
        for (int x = 0; x < nx; ++x)
        {
          const double h = row[x];
          const double neighbours[4] = { row[(x + nx - 1) % nx], row[(x + 1) % nx], up[x],
            down[x] };
          double change = 0.0;
          for (double n : neighbours)
          {
            const double difference = h - n;
            const double excess = std::abs(difference) - limit;
            if (excess > 0.0)
            {
              change -= std::copysign(0.2 * excess, difference);
            }
          }
          out[x] = h + change;
        }
      }
    });
  this->H.swap(this->Scratch);
}

std::vector<RippleNormalLevel> RippleNormalPyramid(
  const std::vector<double>& heights, int size, double cellMetres, int levels)
{
  if (size < 1 || levels < 1 || heights.size() != static_cast<std::size_t>(size) * size ||
    (size % (1 << (levels - 1))) != 0 || !(cellMetres > 0.0) || !std::isfinite(cellMetres))
  {
    throw std::invalid_argument("ripple normal pyramid: the size must be a multiple of "
                                "2^(levels - 1) and match the heights; cells > 0 m.");
  }
  std::vector<RippleNormalLevel> pyramid(static_cast<std::size_t>(levels));
  for (int k = 0; k < levels; ++k)
  {
    RippleNormalLevel& level = pyramid[k];
    const int factor = 1 << k;
    const int n = size / factor;
    level.Size = n;
    level.TexelMetres = cellMetres * factor;
    level.Heights.assign(static_cast<std::size_t>(n) * n, 0.0f);
    level.Normals.assign(static_cast<std::size_t>(n) * n * 3, 0.0f);
    std::vector<double> box(static_cast<std::size_t>(n) * n, 0.0);
    for (int y = 0; y < size; ++y)
    {
      for (int x = 0; x < size; ++x)
      {
        box[static_cast<std::size_t>(x / factor) + static_cast<std::size_t>(n) * (y / factor)] +=
          heights[static_cast<std::size_t>(x) + static_cast<std::size_t>(size) * y];
      }
    }
    const double area = static_cast<double>(factor) * factor;
    for (double& value : box)
    {
      value /= area;
    }
    for (int y = 0; y < n; ++y)
    {
      for (int x = 0; x < n; ++x)
      {
        auto at = [&](int i, int j)
        {
          return box[static_cast<std::size_t>((i + n) % n) +
            static_cast<std::size_t>(n) * ((j + n) % n)];
        };
        const double gx = (at(x + 1, y) - at(x - 1, y)) / (2.0 * level.TexelMetres);
        const double gy = (at(x, y + 1) - at(x, y - 1)) / (2.0 * level.TexelMetres);
        const double norm = std::sqrt(gx * gx + gy * gy + 1.0);
        const std::size_t t = static_cast<std::size_t>(x) + static_cast<std::size_t>(n) * y;
        level.Heights[t] = static_cast<float>(box[t]);
        level.Normals[3 * t + 0] = static_cast<float>(-gx / norm);
        level.Normals[3 * t + 1] = static_cast<float>(-gy / norm);
        level.Normals[3 * t + 2] = static_cast<float>(1.0 / norm);
      }
    }
  }
  return pyramid;
}

int RippleLevelOfDetail(double distance, double nearDistance, int levels)
{
  if (!(distance > nearDistance) || !(nearDistance > 0.0) || levels <= 1)
  {
    return 0;
  }
  const double level = std::floor(std::log2(distance / nearDistance)) + 1.0;
  return static_cast<int>(std::min(level, static_cast<double>(levels - 1)));
}

} // namespace nimbus
