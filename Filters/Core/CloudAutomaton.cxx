#include "CloudAutomaton.h"

#include "Metaballs.h" // WyvillFalloff
#include "ParallelFor.h"
#include "Random.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>

namespace nimbus
{

ProbabilityField ProbabilityField::Uniform(double value)
{
  ProbabilityField field;
  field.Type = Kind::Uniform;
  field.Value = value;
  return field;
}

ProbabilityField ProbabilityField::Plane(std::vector<float> values)
{
  ProbabilityField field;
  field.Type = Kind::Plane;
  field.Values = std::move(values);
  return field;
}

ProbabilityField ProbabilityField::Volume(std::vector<float> values)
{
  ProbabilityField field;
  field.Type = Kind::Volume;
  field.Values = std::move(values);
  return field;
}

std::int64_t WindShift(double cellsPerStep, std::int64_t step)
{
  // The shifts of steps 0..n-1 telescope to floor(v n) - floor(0) = floor(v n).
  const double v = cellsPerStep;
  return static_cast<std::int64_t>(std::floor(v * static_cast<double>(step + 1))) -
    static_cast<std::int64_t>(std::floor(v * static_cast<double>(step)));
}

namespace
{
using Word = std::uint64_t;
constexpr int Bits = 64;
constexpr std::uint32_t ThresholdOne = 1u << 24; // probability 1 on the 24-bit scale

// Random streams: one per use, so that no two uses share numbers.
enum Stream : std::uint64_t
{
  StreamHumidity = 1,
  StreamActivation = 2,
  StreamExtinction = 3,
  StreamInitialHumidity = 4,
  StreamInitialActivation = 5
};

// SplitMix64's finaliser (Steele, Lea, Flood 2014): a bijective 64-bit mix.
inline Word Mix(Word z)
{
  z += 0x9E3779B97F4A7C15ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

// Counter-based random numbers: key(seed, step, stream), then hash(key, counter).
inline Word StreamKey(std::uint64_t seed, std::int64_t step, Stream stream)
{
  return Mix(Mix(Mix(seed) + static_cast<Word>(step)) + static_cast<Word>(stream));
}

inline Word Hash(Word key, Word counter)
{
  return Mix(key ^ (counter * 0xD6E8FEB86659FD93ull));
}

std::uint32_t ToThreshold(double p)
{
  return static_cast<std::uint32_t>(std::llround(std::clamp(p, 0.0, 1.0) * ThresholdOne));
}

// 64 independent Bernoulli bits of probability threshold / 2^24 from
// 24 - ctz(threshold) random words: processing the binary digits of the
// probability from the least significant, OR where the digit is 1 and AND where it
// is 0 gives P(bit) = sum_j digit_j 2^(j-24) exactly.
inline Word BernoulliWord(Word key, Word wordIndex, std::uint32_t threshold)
{
  if (threshold == 0)
  {
    return 0;
  }
  if (threshold >= ThresholdOne)
  {
    return ~Word(0);
  }
  Word mask = 0;
  int j = 0;
  while (((threshold >> j) & 1u) == 0)
  {
    ++j;
  }
  for (; j < 24; ++j)
  {
    const Word random = Hash(key, wordIndex * 24 + static_cast<Word>(j));
    mask = ((threshold >> j) & 1u) ? (mask | random) : (mask & random);
  }
  return mask;
}

// Runs body(begin, end) over [0, count) split into contiguous slabs, one per thread
// (ParallelFor with grain 0).
template <typename Body>
void ForEachSlab(int count, int threads, const Body& body)
{
  ParallelFor(static_cast<std::size_t>(std::max(0, count)), 0, threads,
    [&body](std::size_t begin, std::size_t end)
    { body(static_cast<int>(begin), static_cast<int>(end)); });
}

inline int Wrap(long long i, int n)
{
  long long r = i % n;
  return static_cast<int>(r < 0 ? r + n : r);
}

inline bool GetBit(const Word* row, int x)
{
  return (row[x / Bits] >> (x % Bits)) & 1u;
}

// Word w of the row shifted by s >= 0 cells towards +x (cells leave at the top).
inline Word ShiftedUp(const Word* row, int words, int w, long long s)
{
  const long long ws = s / Bits;
  const int bs = static_cast<int>(s % Bits);
  const long long i = w - ws;
  Word v = 0;
  if (i >= 0 && i < words)
  {
    v = row[i] << bs;
  }
  if (bs != 0 && i - 1 >= 0 && i - 1 < words)
  {
    v |= row[i - 1] >> (Bits - bs);
  }
  return v;
}

// Word w of the row shifted by s >= 0 cells towards -x.
inline Word ShiftedDown(const Word* row, int words, int w, long long s)
{
  const long long ws = s / Bits;
  const int bs = static_cast<int>(s % Bits);
  const long long i = w + ws;
  Word v = 0;
  if (i >= 0 && i < words)
  {
    v = row[i] >> bs;
  }
  if (bs != 0 && i + 1 < words)
  {
    v |= row[i + 1] << (Bits - bs);
  }
  return v;
}

void CheckProbability(double p, const char* name)
{
  if (!(p >= 0.0 && p <= 1.0))
  {
    std::ostringstream message;
    message << name << " must be a probability in [0, 1], got " << p << ".";
    throw std::invalid_argument(message.str());
  }
}

std::vector<std::uint32_t> MakeThresholds(
  const ProbabilityField& field, std::size_t planeSize, std::size_t volumeSize, const char* name)
{
  std::size_t expected = 0;
  switch (field.Type)
  {
    case ProbabilityField::Kind::Uniform:
      CheckProbability(field.Value, name);
      return { ToThreshold(field.Value) };
    case ProbabilityField::Kind::Plane:
      expected = planeSize;
      break;
    case ProbabilityField::Kind::Volume:
      expected = volumeSize;
      break;
  }
  if (field.Values.size() != expected)
  {
    std::ostringstream message;
    message << name << ": a " << (field.Type == ProbabilityField::Kind::Plane ? "2-D" : "3-D")
            << " probability field needs " << expected << " values (the grid's "
            << (field.Type == ProbabilityField::Kind::Plane ? "nx*ny" : "nx*ny*nz") << "), got "
            << field.Values.size() << ".";
    throw std::invalid_argument(message.str());
  }
  std::vector<std::uint32_t> thresholds(expected);
  for (std::size_t i = 0; i < expected; ++i)
  {
    const double p = field.Values[i];
    if (!(p >= 0.0 && p <= 1.0))
    {
      std::ostringstream message;
      message << name << ": value " << p << " at index " << i << " is not a probability in [0, 1].";
      throw std::invalid_argument(message.str());
    }
    thresholds[i] = ToThreshold(p);
  }
  return thresholds;
}

// The random event mask of one word: bits of `candidates` whose cell draws r < p.
// Uniform fields use the word-at-a-time Bernoulli bits; spatial fields draw one
// 24-bit number per candidate cell keyed by the cell's linear index.
struct EventSampler
{
  const ProbabilityField* Field;
  const std::vector<std::uint32_t>* Thresholds;
  Word Key;
  int Nx, Ny;
  int ZOffset; // global layer of held layer 0: random numbers are keyed by the global cell
  int Owned0;  // held layer of the first stepped layer, the first of a Volume field's values

  Word operator()(Word candidates, Word wordIndex, int w, int y, int z) const
  {
    if (candidates == 0)
    {
      return 0;
    }
    const auto& t = *this->Thresholds;
    if (this->Field->Type == ProbabilityField::Kind::Uniform)
    {
      return BernoulliWord(this->Key, wordIndex, t[0]) & candidates;
    }
    const std::size_t planeIndex = static_cast<std::size_t>(y) * this->Nx;
    const std::size_t base = this->Field->Type == ProbabilityField::Kind::Plane
      ? planeIndex
      : planeIndex + static_cast<std::size_t>(z - this->Owned0) * this->Nx * this->Ny;
    const std::size_t cellBase =
      planeIndex + static_cast<std::size_t>(z + this->ZOffset) * this->Nx * this->Ny;
    Word events = 0;
    Word remaining = candidates;
    while (remaining)
    {
      const int b = __builtin_ctzll(remaining);
      remaining &= remaining - 1;
      const std::size_t x = static_cast<std::size_t>(w) * Bits + b;
      const std::uint32_t threshold = t[base + x];
      if (threshold == 0)
      {
        continue;
      }
      const std::uint32_t r = static_cast<std::uint32_t>(Hash(this->Key, cellBase + x) >> 40);
      if (r < threshold)
      {
        events |= Word(1) << b;
      }
    }
    return events;
  }
};
} // namespace

namespace
{
/// Whether the wind moves any of the layers [layer0, layer0 + nz) at step n.
bool AnyLayerMoves(const CloudAutomatonParameters& p, int layer0, int nz, std::int64_t n)
{
  for (int z = layer0; z < layer0 + nz; ++z)
  {
    if (WindShift(p.Wind[0] + z * p.Shear[0], n) != 0 ||
      WindShift(p.Wind[1] + z * p.Shear[1], n) != 0)
    {
      return true;
    }
  }
  return false;
}
}

CloudAutomaton::CloudAutomaton(const CloudAutomatonParameters& parameters)
  : Parameters(parameters)
{
  this->ValidateAndPrepare();
  this->InitialState();
}

CloudAutomaton::CloudAutomaton(CloudAutomatonParameters&& parameters)
  : Parameters(std::move(parameters))
{
  this->ValidateAndPrepare();
  this->InitialState();
}

void CloudAutomaton::ValidateAndPrepare()
{
  const auto& p = this->Parameters;
  for (int a = 0; a < 3; ++a)
  {
    if (p.Dimensions[a] < 1)
    {
      std::ostringstream message;
      message << "Dimensions must be >= 1 cell along every axis, got (" << p.Dimensions[0] << ", "
              << p.Dimensions[1] << ", " << p.Dimensions[2] << ").";
      throw std::invalid_argument(message.str());
    }
  }
  const std::size_t nx = p.Dimensions[0], ny = p.Dimensions[1], nz = p.Dimensions[2];
  const double cells = static_cast<double>(nx) * ny * nz;
  if (cells > 4.0e9)
  {
    std::ostringstream message;
    message << "Dimensions: " << cells << " cells is more than the limit of 4e9.";
    throw std::invalid_argument(message.str());
  }
  for (int a = 0; a < 2; ++a)
  {
    if (!std::isfinite(p.Wind[a]) || !std::isfinite(p.Shear[a]) || std::abs(p.Wind[a]) > 1.0e6 ||
      std::abs(p.Shear[a]) > 1.0e6)
    {
      throw std::invalid_argument(
        "Wind and Shear must be finite and at most 1e6 cells per step in magnitude.");
    }
  }
  if (p.NumberOfThreads < 0)
  {
    throw std::invalid_argument("NumberOfThreads must be >= 0 (0: one per hardware thread).");
  }
  CheckProbability(p.InitialHumidity, "InitialHumidity");
  CheckProbability(p.InitialActivation, "InitialActivation");
  const int layerEnd = p.Layers[1] < 0 ? static_cast<int>(nz) : p.Layers[1];
  if (p.Layers[0] < 0 || layerEnd > static_cast<int>(nz) || p.Layers[0] >= layerEnd)
  {
    std::ostringstream message;
    message << "Layers must be a non-empty range within [0, " << nz << "), got [" << p.Layers[0]
            << ", " << layerEnd << ").";
    throw std::invalid_argument(message.str());
  }
  this->Z0 = p.Layers[0];
  this->NZ = layerEnd - p.Layers[0];
  const std::size_t held = static_cast<std::size_t>(this->NZ);
  const int ownedBegin = p.Owned[0] < 0 ? p.Layers[0] : p.Owned[0];
  const int ownedEnd = p.Owned[0] < 0 ? layerEnd : p.Owned[1];
  if (ownedBegin < p.Layers[0] || ownedEnd > layerEnd || ownedBegin >= ownedEnd)
  {
    std::ostringstream message;
    message << "Owned must be a non-empty range within the held layers [" << p.Layers[0] << ", "
            << layerEnd << "), got [" << ownedBegin << ", " << ownedEnd << ").";
    throw std::invalid_argument(message.str());
  }
  this->O0 = ownedBegin - this->Z0;
  this->ON = ownedEnd - ownedBegin;
  const std::size_t owned = static_cast<std::size_t>(this->ON);
  // The thresholds replace the values, each field's as soon as they are made (GetParameters).
  auto thresholds = [&](ProbabilityField& field, const char* name)
  {
    std::vector<std::uint32_t> t = MakeThresholds(field, nx * ny, nx * ny * owned, name);
    field.Values = std::vector<float>();
    return t;
  };
  this->ExtinctionThresholds = thresholds(this->Parameters.Extinction, "Extinction");
  this->HumidityThresholds = thresholds(this->Parameters.HumiditySupply, "HumiditySupply");
  this->ActivationThresholds = thresholds(this->Parameters.ActivationSupply, "ActivationSupply");

  this->RowWords = static_cast<int>((nx + Bits - 1) / Bits);
  const int tailBits = static_cast<int>(nx % Bits);
  this->TailMask = tailBits == 0 ? ~Word(0) : ((Word(1) << tailBits) - 1);
  this->Threads = ResolveThreadCount(p.NumberOfThreads);
  const std::size_t words = static_cast<std::size_t>(this->RowWords) * ny * held;
  for (auto* state : { &this->Current, &this->Scratch })
  {
    state->Hum.assign(words, 0);
    state->Act.assign(words, 0);
    state->Cld.assign(words, 0);
  }
}

void CloudAutomaton::InitialState()
{
  const auto& p = this->Parameters;
  const int ny = p.Dimensions[1], nz = this->NZ, W = this->RowWords;
  // Global word index of held word i: random numbers are keyed by the global cell.
  const std::size_t offset = static_cast<std::size_t>(this->Z0) * ny * W;
  const Word humKey = StreamKey(p.Seed, -1, StreamInitialHumidity);
  const Word actKey = StreamKey(p.Seed, -1, StreamInitialActivation);
  const std::uint32_t humThreshold = ToThreshold(p.InitialHumidity);
  const std::uint32_t actThreshold = ToThreshold(p.InitialActivation);
  auto& s = this->Current;
  s.Step = 0;
  ForEachSlab(nz, this->Threads,
    [&](int z0, int z1)
    {
      for (int z = z0; z < z1; ++z)
      {
        for (int y = 0; y < ny; ++y)
        {
          for (int w = 0; w < W; ++w)
          {
            const std::size_t i = (static_cast<std::size_t>(z) * ny + y) * W + w;
            const Word tail = (w == W - 1) ? this->TailMask : ~Word(0);
            s.Hum[i] = BernoulliWord(humKey, i + offset, humThreshold) & tail;
            s.Act[i] = BernoulliWord(actKey, i + offset, actThreshold) & tail;
            s.Cld[i] = 0;
          }
        }
      }
    });
}

void CloudAutomaton::Reset()
{
  this->InitialState();
}

void CloudAutomaton::Clear()
{
  std::fill(this->Current.Hum.begin(), this->Current.Hum.end(), 0);
  std::fill(this->Current.Act.begin(), this->Current.Act.end(), 0);
  std::fill(this->Current.Cld.begin(), this->Current.Cld.end(), 0);
}

void CloudAutomaton::Step()
{
  const auto& p = this->Parameters;
  // nz: the held layers (Parameters.Layers); layer0 + z is held layer z's global index.
  const int nx = p.Dimensions[0], ny = p.Dimensions[1], nz = this->NZ, layer0 = this->Z0;
  const int W = this->RowWords;
  const std::size_t offset = static_cast<std::size_t>(layer0) * ny * W; // global - held word
  const bool periodic = p.Boundary == CloudBoundary::Periodic;
  const std::int64_t n = this->Current.Step;
  const CloudAutomatonState& in = this->Current;
  CloudAutomatonState& out = this->Scratch;

  const EventSampler humidity{ &p.HumiditySupply, &this->HumidityThresholds,
    StreamKey(p.Seed, n, StreamHumidity), nx, ny, layer0, this->O0 };
  const EventSampler activation{ &p.ActivationSupply, &this->ActivationThresholds,
    StreamKey(p.Seed, n, StreamActivation), nx, ny, layer0, this->O0 };
  const EventSampler extinction{ &p.Extinction, &this->ExtinctionThresholds,
    StreamKey(p.Seed, n, StreamExtinction), nx, ny, layer0, this->O0 };

  // Row (y, z) of a field, nullptr outside the grid (open) -- y wraps when periodic.
  auto row = [&](const std::vector<Word>& field, int y, int z) -> const Word*
  {
    if (z < 0 || z >= nz)
    {
      return nullptr;
    }
    if (y < 0 || y >= ny)
    {
      if (!periodic)
      {
        return nullptr;
      }
      y = Wrap(y, ny);
    }
    return field.data() + (static_cast<std::size_t>(z) * ny + y) * W;
  };

  // The cells whose x +-1, +-2 neighbours wrap around (periodic boundary).
  std::vector<int> edges;
  for (const int x : { 0, 1, nx - 2, nx - 1 })
  {
    if (x >= 0 && x < nx && std::find(edges.begin(), edges.end(), x) == edges.end())
    {
      edges.push_back(x);
    }
  }

  // 1. growth and 2. extinction/supply: in -> out.
  ForEachSlab(nz, this->Threads,
    [&](int z0, int z1)
    {
      for (int z = z0; z < z1; ++z)
      {
        if (z < this->O0 || z >= this->O0 + this->ON)
        {
          // A halo layer: its owner steps it (Parameters.Owned); empty until it is replaced.
          const std::size_t first = static_cast<std::size_t>(z) * ny * W,
                            count = std::size_t(ny) * W;
          std::fill_n(out.Hum.begin() + first, count, Word(0));
          std::fill_n(out.Act.begin() + first, count, Word(0));
          std::fill_n(out.Cld.begin() + first, count, Word(0));
          continue;
        }
        for (int y = 0; y < ny; ++y)
        {
          const Word* act = row(in.Act, y, z);
          // f_act's neighbourhood (shared/papers/README.md): y +-1, +-2 and z +1, -1, -2 ...
          const Word* others[7] = { row(in.Act, y - 1, z), row(in.Act, y + 1, z),
            row(in.Act, y - 2, z), row(in.Act, y + 2, z), row(in.Act, y, z + 1),
            row(in.Act, y, z - 1), row(in.Act, y, z - 2) };
          const std::size_t rowStart = (static_cast<std::size_t>(z) * ny + y) * W;
          for (int w = 0; w < W; ++w)
          {
            const std::size_t i = rowStart + w;
            const Word a = act[w];
            const Word prev = w > 0 ? act[w - 1] : 0;
            const Word next = w + 1 < W ? act[w + 1] : 0;
            // ... and x +-1, +-2: bit x of (a << d) is cell x - d, of (a >> d) cell x + d.
            Word f = (a << 1) | (prev >> 63) | (a << 2) | (prev >> 62) | (a >> 1) | (next << 63) |
              (a >> 2) | (next << 62);
            if (periodic)
            {
              // Wrap-around in x: cells x < 2 see x - d from the far end, cells x >= nx - 2
              // see x + d from the start (the shifts above read 0 there).
              for (const int x : edges)
              {
                if (x / Bits != w)
                {
                  continue;
                }
                bool any = false;
                for (int d = 1; d <= 2; ++d)
                {
                  any = any || (x - d < 0 && GetBit(act, Wrap(x - d, nx))) ||
                    (x + d >= nx && GetBit(act, Wrap(x + d, nx)));
                }
                if (any)
                {
                  f |= Word(1) << (x % Bits);
                }
              }
            }
            for (const Word* other : others)
            {
              if (other)
              {
                f |= other[w];
              }
            }
            const Word h = in.Hum[i];
            const Word c = in.Cld[i];
            // 002 §3 (shared/papers/README.md): growth.
            Word hum = h & ~a;
            Word cld = c | a;
            Word newAct = ~a & h & f;
            // Extinction and supply.
            const Word tail = (w == W - 1) ? this->TailMask : ~Word(0);
            cld &= ~extinction(cld & tail, i + offset, w, y, z);
            hum |= humidity(~hum & tail, i + offset, w, y, z);
            newAct |= activation(~newAct & tail, i + offset, w, y, z);
            out.Hum[i] = hum & tail;
            out.Act[i] = newAct & tail;
            out.Cld[i] = cld & tail;
          }
        }
      }
    });

  // 3. wind: out -> in (shifted), or just swap when no layer moves this step.
  this->MoveWithTheWind(n);
  this->Current.Step = n + 1;
}

// Step's third part: the wind moves each held layer of Scratch (the step's result) by its
// whole-cell shift of step n into Current, or Scratch and Current swap when no layer moves.
void CloudAutomaton::MoveWithTheWind(std::int64_t n)
{
  const auto& p = this->Parameters;
  const int nx = p.Dimensions[0], ny = p.Dimensions[1], nz = this->NZ, layer0 = this->Z0;
  const int W = this->RowWords;
  const bool periodic = p.Boundary == CloudBoundary::Periodic;
  if (!AnyLayerMoves(p, layer0, nz, n))
  {
    std::swap(this->Current.Hum, this->Scratch.Hum);
    std::swap(this->Current.Act, this->Scratch.Act);
    std::swap(this->Current.Cld, this->Scratch.Cld);
  }
  else
  {
    CloudAutomatonState& dst = this->Current;
    const CloudAutomatonState& src = this->Scratch;
    ForEachSlab(nz, this->Threads,
      [&](int z0, int z1)
      {
        for (int z = z0; z < z1; ++z)
        {
          const long long sx = WindShift(p.Wind[0] + (layer0 + z) * p.Shear[0], n);
          const long long sy = WindShift(p.Wind[1] + (layer0 + z) * p.Shear[1], n);
          long long up = 0, down = 0; // shifts towards +x and -x combined by OR
          bool useUp = false, useDown = false;
          if (periodic)
          {
            const int s = Wrap(sx, nx);
            up = s;
            down = nx - s;
            useUp = true;
            useDown = s != 0;
          }
          else if (sx >= 0)
          {
            up = sx;
            useUp = true;
          }
          else
          {
            down = -sx;
            useDown = true;
          }
          for (int y = 0; y < ny; ++y)
          {
            long long sourceY = y - sy;
            const bool inside = sourceY >= 0 && sourceY < ny;
            if (!inside && !periodic)
            {
              sourceY = -1;
            }
            else if (!inside)
            {
              sourceY = Wrap(sourceY, ny);
            }
            const std::size_t dstStart = (static_cast<std::size_t>(z) * ny + y) * W;
            for (int f = 0; f < 3; ++f)
            {
              const std::vector<Word>& from = f == 0 ? src.Hum : (f == 1 ? src.Act : src.Cld);
              std::vector<Word>& to = f == 0 ? dst.Hum : (f == 1 ? dst.Act : dst.Cld);
              if (sourceY < 0)
              {
                std::fill_n(to.begin() + static_cast<std::ptrdiff_t>(dstStart), W, Word(0));
                continue;
              }
              const Word* source = from.data() + (static_cast<std::size_t>(z) * ny + sourceY) * W;
              for (int w = 0; w < W; ++w)
              {
                Word v = 0;
                if (useUp)
                {
                  v |= ShiftedUp(source, W, w, up);
                }
                if (useDown)
                {
                  v |= ShiftedDown(source, W, w, down);
                }
                to[dstStart + w] = v & ((w == W - 1) ? this->TailMask : ~Word(0));
              }
            }
          }
        }
      });
  }
}

bool CloudAutomaton::StepTo(std::int64_t step, const std::function<bool(double)>& progress)
{
  if (step < this->Current.Step)
  {
    std::ostringstream message;
    message << "StepTo(" << step << "): the automaton is already at step " << this->Current.Step
            << " and cannot go back; restore an earlier state with SetState or Reset.";
    throw std::invalid_argument(message.str());
  }
  const std::int64_t first = this->Current.Step;
  while (this->Current.Step < step)
  {
    if (progress &&
      !progress(
        static_cast<double>(this->Current.Step - first) / static_cast<double>(step - first)))
    {
      return false;
    }
    this->Step();
  }
  return true;
}

void CloudAutomaton::SetState(const CloudAutomatonState& state)
{
  const std::size_t words = this->Current.Hum.size();
  if (state.Hum.size() != words || state.Act.size() != words || state.Cld.size() != words ||
    state.Step < 0)
  {
    throw std::invalid_argument(
      "SetState: the state comes from an automaton of another size (or has a negative step).");
  }
  this->Current = state;
}

std::vector<std::uint64_t>& CloudAutomaton::Data(Field field)
{
  return field == Field::Hum ? this->Current.Hum
                             : (field == Field::Act ? this->Current.Act : this->Current.Cld);
}

const std::vector<std::uint64_t>& CloudAutomaton::Data(Field field) const
{
  return field == Field::Hum ? this->Current.Hum
                             : (field == Field::Act ? this->Current.Act : this->Current.Cld);
}

bool CloudAutomaton::Get(Field field, int x, int y, int z) const
{
  const int* d = this->Parameters.Dimensions;
  if (x < 0 || y < 0 || z < this->Z0 || x >= d[0] || y >= d[1] || z >= this->Z0 + this->NZ)
  {
    throw std::out_of_range("CloudAutomaton::Get: cell outside the grid (or its held layers).");
  }
  const std::size_t i =
    (static_cast<std::size_t>(z - this->Z0) * d[1] + y) * this->RowWords + x / Bits;
  return (this->Data(field)[i] >> (x % Bits)) & 1u;
}

void CloudAutomaton::Set(Field field, int x, int y, int z, bool value)
{
  const int* d = this->Parameters.Dimensions;
  if (x < 0 || y < 0 || z < this->Z0 || x >= d[0] || y >= d[1] || z >= this->Z0 + this->NZ)
  {
    throw std::out_of_range("CloudAutomaton::Set: cell outside the grid (or its held layers).");
  }
  const std::size_t i =
    (static_cast<std::size_t>(z - this->Z0) * d[1] + y) * this->RowWords + x / Bits;
  const Word bit = Word(1) << (x % Bits);
  auto& data = this->Data(field);
  data[i] = value ? (data[i] | bit) : (data[i] & ~bit);
}

std::uint64_t* CloudAutomaton::Layer(Field field, int z)
{
  if (z < this->Z0 || z >= this->Z0 + this->NZ)
  {
    throw std::out_of_range("CloudAutomaton::Layer: layer outside the held layers.");
  }
  return this->Data(field).data() +
    static_cast<std::size_t>(z - this->Z0) * this->Parameters.Dimensions[1] * this->RowWords;
}

void DistributedLayers(int nz, int rank, int ranks, int owned[2], int held[2])
{
  if (ranks < 1 || rank < 0 || rank >= ranks || nz < 2 * ranks)
  {
    throw std::invalid_argument("DistributedLayers: needs 0 <= rank < ranks and nz >= 2 ranks.");
  }
  owned[0] = static_cast<int>(static_cast<long long>(nz) * rank / ranks);
  owned[1] = static_cast<int>(static_cast<long long>(nz) * (rank + 1) / ranks);
  held[0] = std::max(0, owned[0] - CloudHaloBelow);
  held[1] = std::min(nz, owned[1] + CloudHaloAbove);
}

std::size_t CloudAutomaton::Count(Field field) const
{
  std::size_t count = 0;
  for (const Word word : this->Data(field))
  {
    count += static_cast<std::size_t>(__builtin_popcountll(word));
  }
  return count;
}

void SmoothCloud(const CloudAutomaton& automaton, const CloudSmoothingParameters& smoothing,
  std::vector<float>& density)
{
  SmoothCloud(automaton.GetParameters(), automaton.GetState(), smoothing, density);
}

void SmoothCloud(const CloudAutomatonParameters& parameters, const CloudAutomatonState& state,
  const CloudSmoothingParameters& smoothing, std::vector<float>& density)
{
  const int nx = parameters.Dimensions[0], ny = parameters.Dimensions[1],
            nz = parameters.Dimensions[2];
  const int W = (nx + Bits - 1) / Bits;
  const std::size_t plane = static_cast<std::size_t>(nx) * ny;
  const std::size_t count = plane * nz;
  if (state.Cld.size() != static_cast<std::size_t>(W) * ny * nz)
  {
    throw std::invalid_argument("SmoothCloud: the state does not match the parameters' grid.");
  }
  if (!std::isfinite(smoothing.Radius) || smoothing.Radius < 0.0 || smoothing.Radius > 64.0)
  {
    throw std::invalid_argument("SmoothCloud: Radius must be in [0, 64] cells.");
  }
  const bool periodic = parameters.Boundary == CloudBoundary::Periodic;
  const int threads = ResolveThreadCount(smoothing.NumberOfThreads);

  // Kernel taps d = -K..K with |d| < R, w(d) = Wyvill falloff (004 §4), sum 1.
  const double R = std::max(1.0, smoothing.Radius);
  const int K = static_cast<int>(std::ceil(R)) - 1;
  std::vector<float> weights(static_cast<std::size_t>(2 * K + 1));
  double sum = 0.0;
  for (int d = -K; d <= K; ++d)
  {
    sum += WyvillFalloff(static_cast<double>(d) * d, R * R);
  }
  for (int d = -K; d <= K; ++d)
  {
    weights[d + K] = static_cast<float>(WyvillFalloff(static_cast<double>(d) * d, R * R) / sum);
  }

  density.assign(count, 0.0f);
  std::vector<float> scratch(count);
  // Bits -> 0/1 floats, into `density`.
  ForEachSlab(nz, threads,
    [&](int z0, int z1)
    {
      for (int z = z0; z < z1; ++z)
      {
        for (int y = 0; y < ny; ++y)
        {
          const Word* row = state.Cld.data() + (static_cast<std::size_t>(z) * ny + y) * W;
          float* out = density.data() + plane * z + static_cast<std::size_t>(nx) * y;
          for (int x = 0; x < nx; ++x)
          {
            out[x] = GetBit(row, x) ? 1.0f : 0.0f;
          }
        }
      }
    });
  if (K == 0)
  {
    return;
  }
  // One separable pass along `axis` from `src` into `dst`. Along y and z whole rows are
  // combined (contiguous, vectorisable); along x the interior skips the boundary tests.
  auto pass = [&](const std::vector<float>& src, std::vector<float>& dst, int axis)
  {
    const int n = parameters.Dimensions[axis];
    const bool wraps = periodic && axis < 2;
    ForEachSlab(nz, threads,
      [&](int z0, int z1)
      {
        for (int z = z0; z < z1; ++z)
        {
          for (int y = 0; y < ny; ++y)
          {
            const std::size_t rowStart = plane * z + static_cast<std::size_t>(nx) * y;
            float* out = dst.data() + rowStart;
            if (axis == 0)
            {
              const float* in = src.data() + rowStart;
              for (int x = 0; x < nx; ++x)
              {
                float value = 0.0f;
                if (x >= K && x + K < nx)
                {
                  for (int d = -K; d <= K; ++d)
                  {
                    value += weights[d + K] * in[x + d];
                  }
                }
                else
                {
                  for (int d = -K; d <= K; ++d)
                  {
                    int j = x + d;
                    if (j < 0 || j >= n)
                    {
                      if (!wraps)
                      {
                        continue;
                      }
                      j = Wrap(j, n);
                    }
                    value += weights[d + K] * in[j];
                  }
                }
                out[x] = value;
              }
              continue;
            }
            std::fill(out, out + nx, 0.0f);
            const int c = axis == 1 ? y : z;
            for (int d = -K; d <= K; ++d)
            {
              int j = c + d;
              if (j < 0 || j >= n)
              {
                if (!wraps)
                {
                  continue;
                }
                j = Wrap(j, n);
              }
              const float* in = src.data() +
                (axis == 1 ? plane * z + static_cast<std::size_t>(nx) * j
                           : plane * j + static_cast<std::size_t>(nx) * y);
              const float w = weights[d + K];
              for (int x = 0; x < nx; ++x)
              {
                out[x] += w * in[x];
              }
            }
          }
        }
      });
  };
  pass(density, scratch, 0);
  pass(scratch, density, 1);
  pass(density, scratch, 2);
  density.swap(scratch);
}

int SmoothingHalo(const CloudSmoothingParameters& smoothing)
{
  return static_cast<int>(std::ceil(std::max(1.0, smoothing.Radius))) - 1;
}

void SmoothCloudBox(const CloudAutomatonParameters& parameters,
  const CloudSmoothingParameters& smoothing, const int box[6],
  const std::function<const std::uint64_t*(int y, int z)>& row, std::vector<float>& density)
{
  const int* d = parameters.Dimensions;
  const int nx = d[0], ny = d[1], nz = d[2];
  for (int a = 0; a < 3; ++a)
  {
    if (box[2 * a] < 0 || box[2 * a + 1] >= d[a] || box[2 * a] > box[2 * a + 1])
    {
      throw std::invalid_argument("SmoothCloudBox: the box is empty or outside the grid.");
    }
  }
  if (!std::isfinite(smoothing.Radius) || smoothing.Radius < 0.0 || smoothing.Radius > 64.0)
  {
    throw std::invalid_argument("SmoothCloudBox: Radius must be in [0, 64] cells.");
  }
  const bool periodic = parameters.Boundary == CloudBoundary::Periodic;
  const int threads = ResolveThreadCount(smoothing.NumberOfThreads);
  // The kernel exactly as SmoothCloud makes it.
  const double R = std::max(1.0, smoothing.Radius);
  const int K = SmoothingHalo(smoothing);
  std::vector<float> weights(static_cast<std::size_t>(2 * K + 1));
  double sum = 0.0;
  for (int t = -K; t <= K; ++t)
  {
    sum += WyvillFalloff(static_cast<double>(t) * t, R * R);
  }
  for (int t = -K; t <= K; ++t)
  {
    weights[t + K] = static_cast<float>(WyvillFalloff(static_cast<double>(t) * t, R * R) / sum);
  }
  // Boxes: B (bits as floats) over x0-K..x1+K, y0-K..y1+K, the layers zl..zh; X (after the x
  // pass) over x0..x1 and the same y and z; Y (after y) over y0..y1; the result over z0..z1.
  // Cells outside the grid (open sides) are 0 in B: SmoothCloud skips them, and adding
  // w * 0 to a sum of non-negative terms leaves it bit for bit.
  const int x0 = box[0], y0 = box[2], z0 = box[4];
  const int bx = box[1] - box[0] + 1, by = box[3] - box[2] + 1, bz = box[5] - box[4] + 1;
  const int zl = std::max(0, z0 - K), zh = std::min(nz - 1, box[5] + K);
  const int lz = zh - zl + 1, ey = by + 2 * K, ex = bx + 2 * K;
  std::vector<float> X(static_cast<std::size_t>(bx) * ey * lz);
  ForEachSlab(lz, threads,
    [&](int k0, int k1)
    {
      std::vector<float> bits(static_cast<std::size_t>(ex));
      for (int k = k0; k < k1; ++k)
      {
        for (int j = 0; j < ey; ++j)
        {
          int y = y0 - K + j;
          const bool inside = y >= 0 && y < ny;
          const Word* words = nullptr;
          if (inside || periodic)
          {
            words = row(Wrap(y, ny), zl + k);
          }
          for (int i = 0; i < ex; ++i)
          {
            const int x = x0 - K + i;
            float v = 0.0f;
            if (words && ((x >= 0 && x < nx) || periodic))
            {
              v = GetBit(words, Wrap(x, nx)) ? 1.0f : 0.0f;
            }
            bits[i] = v;
          }
          float* out = X.data() + (static_cast<std::size_t>(k) * ey + j) * bx;
          for (int i = 0; i < bx; ++i)
          {
            if (K == 0)
            {
              out[i] = bits[i];
              continue;
            }
            float value = 0.0f;
            for (int t = -K; t <= K; ++t)
            {
              const int x = x0 + i + t;
              if (!periodic && (x < 0 || x >= nx))
              {
                continue; // as SmoothCloud
              }
              value += weights[t + K] * bits[i + K + t];
            }
            out[i] = value;
          }
        }
      }
    });
  if (K == 0)
  {
    density.assign(static_cast<std::size_t>(bx) * by * bz, 0.0f);
    for (int k = 0; k < bz; ++k)
    {
      for (int j = 0; j < by; ++j)
      {
        const float* in = X.data() + (static_cast<std::size_t>(k + z0 - zl) * ey + j) * bx;
        std::copy(in, in + bx, density.data() + (static_cast<std::size_t>(k) * by + j) * bx);
      }
    }
    return;
  }
  std::vector<float> Y(static_cast<std::size_t>(bx) * by * lz);
  ForEachSlab(lz, threads,
    [&](int k0, int k1)
    {
      for (int k = k0; k < k1; ++k)
      {
        for (int j = 0; j < by; ++j)
        {
          float* out = Y.data() + (static_cast<std::size_t>(k) * by + j) * bx;
          std::fill(out, out + bx, 0.0f);
          for (int t = -K; t <= K; ++t)
          {
            const int y = y0 + j + t;
            if (!periodic && (y < 0 || y >= ny))
            {
              continue;
            }
            const float* in = X.data() + (static_cast<std::size_t>(k) * ey + j + K + t) * bx;
            const float w = weights[t + K];
            for (int i = 0; i < bx; ++i)
            {
              out[i] += w * in[i];
            }
          }
        }
      }
    });
  // X freed before the result is made: two boxes of floats at a time, as SmoothCloud holds.
  X = std::vector<float>();
  density.assign(static_cast<std::size_t>(bx) * by * bz, 0.0f);
  ForEachSlab(bz, threads,
    [&](int k0, int k1)
    {
      for (int k = k0; k < k1; ++k)
      {
        for (int j = 0; j < by; ++j)
        {
          float* out = density.data() + (static_cast<std::size_t>(k) * by + j) * bx;
          for (int t = -K; t <= K; ++t)
          {
            const int z = z0 + k + t;
            if (z < 0 || z >= nz)
            {
              continue;
            }
            const float* in = Y.data() + (static_cast<std::size_t>(z - zl) * by + j) * bx;
            const float w = weights[t + K];
            for (int i = 0; i < bx; ++i)
            {
              out[i] += w * in[i];
            }
          }
        }
      }
    });
}

void InterpolateDensity(
  const std::vector<float>& a, const std::vector<float>& b, double t, std::vector<float>& out)
{
  if (a.size() != b.size())
  {
    throw std::invalid_argument("InterpolateDensity: the two densities differ in size.");
  }
  if (!(t >= 0.0 && t <= 1.0))
  {
    throw std::invalid_argument("InterpolateDensity: t must be in [0, 1].");
  }
  out.resize(a.size());
  const float s = static_cast<float>(t);
  for (std::size_t i = 0; i < a.size(); ++i)
  {
    out[i] = a[i] + s * (b[i] - a[i]);
  }
}

std::vector<float> FormationRegionWeights(const int dimensions[3],
  const std::vector<FormationRegion>& regions, bool periodic, int zBegin, int zEnd)
{
  const int nx = dimensions[0], ny = dimensions[1];
  zBegin = std::clamp(zBegin, 0, dimensions[2]);
  zEnd = zEnd < 0 ? dimensions[2] : std::clamp(zEnd, zBegin, dimensions[2]);
  const int nz = zEnd - zBegin; // the layers computed
  std::vector<float> weights(static_cast<std::size_t>(nx) * ny * nz, 0.0f);
  constexpr double cutoff = 3.0; // semi-axes
  for (const FormationRegion& region : regions)
  {
    // The box of cells within the cutoff (unwrapped indices; wrapped below when periodic).
    int low[3], high[3];
    for (int a = 0; a < 3; ++a)
    {
      const double reach = cutoff * std::max(region.Radius[a], 1e-9);
      low[a] = static_cast<int>(std::floor(region.Center[a] - reach));
      high[a] = static_cast<int>(std::ceil(region.Center[a] + reach));
      const bool wraps = periodic && a < 2;
      const int n = dimensions[a];
      if (wraps && high[a] - low[a] + 1 > n)
      {
        // Wider than the grid: every cell once, at its nearest image.
        low[a] = static_cast<int>(std::floor(region.Center[a] - 0.5 * n));
        high[a] = low[a] + n - 1;
      }
      else if (!wraps)
      {
        low[a] = std::max(low[a], 0);
        high[a] = std::min(high[a], n - 1);
      }
    }
    for (int k = std::max(low[2], zBegin); k <= std::min(high[2], zEnd - 1); ++k)
    {
      const double dz = (k - region.Center[2]) / region.Radius[2];
      for (int j = low[1]; j <= high[1]; ++j)
      {
        const double dy = (j - region.Center[1]) / region.Radius[1];
        const int y = ((j % ny) + ny) % ny;
        for (int i = low[0]; i <= high[0]; ++i)
        {
          const double dx = (i - region.Center[0]) / region.Radius[0];
          const double r2 = dx * dx + dy * dy + dz * dz;
          if (r2 > cutoff * cutoff)
          {
            continue;
          }
          const int x = ((i % nx) + nx) % nx;
          float& w = weights[x +
            static_cast<std::size_t>(nx) * (y + static_cast<std::size_t>(ny) * (k - zBegin))];
          w = std::max(w, static_cast<float>(std::exp(-0.5 * r2)));
        }
      }
    }
  }
  return weights;
}

std::vector<FormationRegion> RandomFormationRegions(const int dimensions[3], int count,
  const double horizontalRadius[2], double aspect, double centerHeight, std::uint64_t seed,
  bool inside)
{
  Random random(seed ^ 0x9E3779B97F4A7C15ull);
  std::vector<FormationRegion> regions;
  const double low = std::min(horizontalRadius[0], horizontalRadius[1]);
  const double high = std::max(horizontalRadius[0], horizontalRadius[1]);
  for (int r = 0; r < count; ++r)
  {
    FormationRegion region;
    const double radius = random.Uniform(low, high);
    region.Radius[0] = region.Radius[1] = radius;
    region.Radius[2] = aspect * radius;
    region.Center[2] = centerHeight;
    // Kept apart while there are few regions (beyond 256 the test would cost too much and
    // there is no room anyway).
    const int attempts = regions.size() < 256 ? 64 : 1;
    for (int attempt = 0; attempt < attempts; ++attempt)
    {
      for (int a = 0; a < 2; ++a)
      {
        const double margin = inside && dimensions[a] > 6.0 * radius ? 3.0 * radius : 0.0;
        region.Center[a] = random.Uniform(margin, dimensions[a] - margin);
      }
      bool apart = true;
      for (const FormationRegion& other : regions)
      {
        double d2 = 0.0;
        for (int a = 0; a < 2; ++a)
        {
          double d = std::abs(region.Center[a] - other.Center[a]);
          d = std::min(d, dimensions[a] - d); // nearest image
          d2 += d * d;
        }
        const double apartDistance = 1.5 * (radius + other.Radius[0]);
        apart = apart && d2 >= apartDistance * apartDistance;
      }
      if (apart)
      {
        break;
      }
    }
    regions.push_back(region);
  }
  return regions;
}

} // namespace nimbus
