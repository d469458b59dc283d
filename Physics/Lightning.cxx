#include "Lightning.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <random>
#include <sstream>
#include <stdexcept>

namespace nimbus
{
namespace
{
constexpr double kMaxSegments = 1e6; // main channel length / segment length
constexpr std::size_t kMaxTotalSegments = 1000000;
constexpr double kMaxNodes = 1e7;

/// Portable draws from a 64-bit Mersenne twister (the standard distributions differ
/// between library implementations; these do not).
class Draws
{
public:
  explicit Draws(std::uint64_t seed)
    : Engine(seed)
  {
  }
  /// Uniform in [0, 1).
  double Uniform() { return static_cast<double>(this->Engine() >> 11) * 0x1.0p-53; }
  /// Standard normal (Box-Muller, one of the pair).
  double Normal()
  {
    const double u = 1.0 - this->Uniform(); // (0, 1]
    const double v = this->Uniform();
    return std::sqrt(-2.0 * std::log(u)) * std::cos(2.0 * kPi * v);
  }

private:
  std::mt19937_64 Engine;
};

/// Two unit vectors completing d (unit) to an orthonormal frame.
void Perpendiculars(const Vector3& d, Vector3& u, Vector3& v)
{
  const Vector3 helper =
    std::abs(d[2]) < 0.9 ? Vector3{ { 0.0, 0.0, 1.0 } } : Vector3{ { 1.0, 0.0, 0.0 } };
  u = Normalized(Cross(d, helper));
  v = Cross(d, u);
}

/// d turned by `angle` (radians) about a uniformly random axis perpendicular to it.
Vector3 Turn(const Vector3& d, double angle, Draws& draws)
{
  Vector3 u, v;
  Perpendiculars(d, u, v);
  const double phi = 2.0 * kPi * draws.Uniform();
  const double c = std::cos(angle), s = std::sin(angle);
  Vector3 out;
  for (int i = 0; i < 3; ++i)
  {
    out[i] = c * d[i] + s * (std::cos(phi) * u[i] + std::sin(phi) * v[i]);
  }
  return Normalized(out);
}

bool Finite(double x)
{
  return std::isfinite(x);
}

/// A parameter that must lie in [Low, High] ((Low, High] when OpenLow), finite.
struct RangeCheck
{
  const char* Name;
  double Value, Low, High;
  bool OpenLow = false;
  const char* Unit = "";

  bool Holds() const
  {
    return Finite(this->Value) &&
      (this->OpenLow ? this->Value > this->Low : this->Value >= this->Low) &&
      this->Value <= this->High;
  }
  std::string Message() const
  {
    std::ostringstream why;
    why << this->Name << " must be in " << (this->OpenLow ? "(" : "[") << this->Low << ", "
        << this->High << "]" << this->Unit << ", got " << this->Value;
    return why.str();
  }
};

struct Channel
{
  Vector3 Start, Heading, Overall;
  double Length, Intensity;
  int Depth;
  double PathStart;
};
} // namespace

std::string CheckLightningParameters(const LightningParameters& p)
{
  if (!IsFinite(p.Start))
  {
    return "Start is not finite";
  }
  if (!IsFinite(p.Direction) || Length(p.Direction) == 0.0)
  {
    return "Direction must be finite and non-zero";
  }
  if (!(Finite(p.Length) && p.Length > 0.0))
  {
    return "Length must be > 0 (metres), got " + std::to_string(p.Length);
  }
  if (!(Finite(p.SegmentLength) && p.SegmentLength > 0.0))
  {
    return "SegmentLength must be > 0 (metres), got " + std::to_string(p.SegmentLength);
  }
  if (p.Length / p.SegmentLength > kMaxSegments)
  {
    return "Length / SegmentLength = " + std::to_string(p.Length / p.SegmentLength) +
      " segments; at most " + std::to_string(kMaxSegments);
  }
  for (const RangeCheck& c : { RangeCheck{ "MeanAngleDegrees", p.MeanAngleDegrees, 0.0, 180.0 },
         RangeCheck{ "AngleSpreadDegrees", p.AngleSpreadDegrees, 0.0, 180.0 },
         RangeCheck{ "Straightness", p.Straightness, 0.0, 1.0 },
         RangeCheck{ "BranchProbability", p.BranchProbability, 0.0, 1.0 },
         RangeCheck{ "BranchAngleDegrees", p.BranchAngleDegrees, 0.0, 180.0 },
         RangeCheck{ "BranchLengthFactor", p.BranchLengthFactor, 0.0, 1.0, true },
         RangeCheck{ "BranchIntensityFactor", p.BranchIntensityFactor, 0.0, 1.0, true },
         RangeCheck{ "MaxBranchDepth", static_cast<double>(p.MaxBranchDepth), 0.0, 16.0 } })
  {
    if (!c.Holds())
    {
      return c.Message();
    }
  }
  if (!(Finite(p.Intensity) && p.Intensity >= 0.0))
  {
    return "Intensity must be finite and >= 0, got " + std::to_string(p.Intensity);
  }
  if (std::isnan(p.StopBelowHeight))
  {
    return "StopBelowHeight is NaN";
  }
  return "";
}

std::vector<LightningSegment> GenerateLightning(const LightningParameters& p)
{
  const std::string why = CheckLightningParameters(p);
  if (!why.empty())
  {
    throw std::invalid_argument("nimbus::GenerateLightning: " + why);
  }
  Draws draws(p.Seed);
  const Vector3 overall = Normalized(p.Direction);
  std::vector<LightningSegment> segments;
  std::deque<Channel> channels;
  channels.push_back({ p.Start, overall, overall, p.Length, p.Intensity, 0, 0.0 });
  const double k = p.Straightness;
  while (!channels.empty())
  {
    const Channel channel = channels.front();
    channels.pop_front();
    Vector3 position = channel.Start;
    Vector3 heading = channel.Heading;
    double remaining = channel.Length;
    double path = channel.PathStart;
    if (position[2] < p.StopBelowHeight)
    {
      continue;
    }
    while (remaining > 1e-9 * p.SegmentLength)
    {
      if (segments.size() >= kMaxTotalSegments)
      {
        throw std::invalid_argument("nimbus::GenerateLightning: the stroke passes " +
          std::to_string(kMaxTotalSegments) +
          " segments; use longer segments, a shorter stroke or fewer branches");
      }
      const double length = std::min(remaining, p.SegmentLength * (0.5 + draws.Uniform()));
      const double angle =
        std::abs(p.MeanAngleDegrees + p.AngleSpreadDegrees * draws.Normal()) * kDegree;
      const Vector3 turned = Turn(heading, angle, draws);
      Vector3 pulled;
      for (int i = 0; i < 3; ++i)
      {
        pulled[i] = (1.0 - k) * turned[i] + k * channel.Overall[i];
      }
      heading = Length(pulled) > 1e-12 ? Normalized(pulled) : turned;
      Vector3 end = Along(position, heading, length);
      bool grounded = false;
      if (end[2] < p.StopBelowHeight)
      {
        // Clip at the ground: heading[2] < 0 here since position is above it.
        const double t = (p.StopBelowHeight - position[2]) / heading[2];
        end = Along(position, heading, std::max(0.0, t));
        end[2] = p.StopBelowHeight;
        grounded = true;
      }
      segments.push_back({ position, end, channel.Intensity, channel.Depth, path });
      remaining -= length;
      path += segments.back().Length();
      if (grounded)
      {
        break;
      }
      const bool branches =
        channel.Depth < p.MaxBranchDepth && draws.Uniform() < p.BranchProbability;
      if (branches)
      {
        const double branchLength = p.BranchLengthFactor * remaining;
        const double branchAngle =
          std::abs(p.BranchAngleDegrees + p.AngleSpreadDegrees * draws.Normal()) * kDegree;
        const Vector3 branchHeading = Turn(heading, branchAngle, draws);
        if (branchLength >= 0.5 * p.SegmentLength)
        {
          channels.push_back({ end, branchHeading, branchHeading, branchLength,
            channel.Intensity * p.BranchIntensityFactor, channel.Depth + 1, path });
        }
      }
      position = end;
    }
  }
  return segments;
}

std::string CheckLightningFlashTimeline(const LightningFlashTimeline& t)
{
  // No strings unless something is wrong: LightningFlashBrightness checks on every call.
  for (const RangeCheck& c :
    { RangeCheck{ "LeaderDuration", t.LeaderDuration, 0.0, 1e3, false, " seconds" },
      RangeCheck{ "LeaderBrightness", t.LeaderBrightness, 0.0, 1.0 },
      RangeCheck{ "NumberOfStrokes", static_cast<double>(t.NumberOfStrokes), 1.0, 100.0 },
      RangeCheck{ "InterstrokeInterval", t.InterstrokeInterval, 0.0, 1e3, true, " seconds" },
      RangeCheck{ "SubsequentStrokeFactor", t.SubsequentStrokeFactor, 0.0, 1.0, true },
      RangeCheck{ "StrokeDecaySeconds", t.StrokeDecaySeconds, 0.0, 1e3, true, " seconds" } })
  {
    if (!c.Holds())
    {
      return c.Message();
    }
  }
  return "";
}

double LightningFlashBrightness(const LightningFlashTimeline& timeline,
  const LightningSegment& segment, double farthestPath, double seconds)
{
  const std::string why = CheckLightningFlashTimeline(timeline);
  if (!why.empty())
  {
    throw std::invalid_argument("nimbus::LightningFlashBrightness: " + why);
  }
  if (!(seconds >= 0.0) || !std::isfinite(seconds))
  {
    return 0.0; // before the flash (or no time at all)
  }
  double brightness = 0.0;
  // The leader reaches the segment's start at this time.
  const double reach = farthestPath > 0.0 && std::isfinite(farthestPath)
    ? timeline.LeaderDuration * std::clamp(segment.PathStart / farthestPath, 0.0, 1.0)
    : 0.0;
  if (seconds >= reach && seconds < timeline.LeaderDuration)
  {
    brightness += timeline.LeaderBrightness;
  }
  double strength = 1.0;
  for (int k = 0; k < timeline.NumberOfStrokes; ++k)
  {
    const double start = timeline.LeaderDuration + k * timeline.InterstrokeInterval;
    if (seconds >= start && (k == 0 || segment.Depth == 0))
    {
      brightness += strength * std::exp(-(seconds - start) / timeline.StrokeDecaySeconds);
    }
    strength *= timeline.SubsequentStrokeFactor;
  }
  return brightness;
}

double LightningFlashDuration(const LightningFlashTimeline& timeline)
{
  const std::string why = CheckLightningFlashTimeline(timeline);
  if (!why.empty())
  {
    throw std::invalid_argument("nimbus::LightningFlashDuration: " + why);
  }
  return timeline.LeaderDuration + (timeline.NumberOfStrokes - 1) * timeline.InterstrokeInterval +
    timeline.StrokeDecaySeconds * std::log(100.0);
}

std::vector<PointLight> LightningPointSources(
  const std::vector<LightningSegment>& segments, double spacing)
{
  if (!(std::isfinite(spacing) && spacing > 0.0))
  {
    throw std::invalid_argument("nimbus::LightningPointSources: spacing must be > 0 (metres)");
  }
  std::vector<PointLight> sources;
  for (const LightningSegment& s : segments)
  {
    if (!IsFinite(s.A) || !IsFinite(s.B) || !std::isfinite(s.Intensity))
    {
      throw std::invalid_argument("nimbus::LightningPointSources: a segment is not finite");
    }
    const Vector3 d{ { s.B[0] - s.A[0], s.B[1] - s.A[1], s.B[2] - s.A[2] } };
    const double length = Length(d);
    if (length == 0.0 || s.Intensity == 0.0)
    {
      continue;
    }
    const double pieces = std::ceil(length / spacing);
    if (pieces > 1e7)
    {
      throw std::invalid_argument(
        "nimbus::LightningPointSources: more than 1e7 sources on one segment");
    }
    const int n = static_cast<int>(pieces);
    const double each = s.Intensity * length / n; // 003 Eq. 3: the segment's share
    for (int i = 0; i < n; ++i)
    {
      PointLight light;
      light.Position = Along(s.A, d, (i + 0.5) / n);
      light.Intensity = { { each, each, each } };
      sources.push_back(light);
    }
  }
  return sources;
}

VirtualLightGrid MakeVirtualLightGrid(const VirtualLightGridParameters& p)
{
  const auto fail = [](const std::string& why)
  { throw std::invalid_argument("nimbus::MakeVirtualLightGrid: " + why); };
  if (!IsFinite(p.Low) || !IsFinite(p.High))
  {
    fail("the box is not finite");
  }
  for (int a = 0; a < 3; ++a)
  {
    if (!(p.High[a] > p.Low[a]))
    {
      fail("the box is empty (High must exceed Low on every axis)");
    }
  }
  if (!(std::isfinite(p.CloudBottom) && p.CloudBottom >= p.Low[2] && p.CloudBottom <= p.High[2]))
  {
    fail("the cloud bottom must lie within the box's z range");
  }
  if (!(std::isfinite(p.BaseInterval) && p.BaseInterval > 0.0))
  {
    fail("the base interval must be > 0 (metres)");
  }
  if (!(std::isfinite(p.EpsilonRelative) && p.EpsilonRelative > 0.0 && p.EpsilonRelative < 1.0))
  {
    fail("EpsilonRelative must be in (0, 1)");
  }
  const double h = p.BaseInterval;
  double estimate = 1.0;
  for (int a = 0; a < 3; ++a)
  {
    estimate *= std::ceil((p.High[a] - p.Low[a]) / h) + 1.0;
  }
  if (estimate > kMaxNodes)
  {
    fail("the base interval makes more than 1e7 nodes");
  }
  VirtualLightGrid grid;
  const auto uniform = [h](double low, double high)
  {
    const int n = std::max(1, static_cast<int>(std::ceil((high - low) / h - 1e-9)));
    std::vector<double> nodes;
    for (int i = 0; i <= n; ++i)
    {
      nodes.push_back(i == n ? high : low + (high - low) * i / n);
    }
    return nodes;
  };
  grid.Nodes[0] = uniform(p.Low[0], p.High[0]);
  grid.Nodes[1] = uniform(p.Low[1], p.High[1]);
  // Above the cloud bottom: uniform (a single node if the bottom is the top).
  std::vector<double> z = p.CloudBottom < p.High[2] ? uniform(p.CloudBottom, p.High[2])
                                                    : std::vector<double>{ p.High[2] };
  // Below: 003 Eq. 4 with the minimum step h_usr.
  const double epsilon = p.EpsilonRelative / (h * h);
  const double depth = p.CloudBottom - p.Low[2];
  std::vector<double> below;
  for (double r = h; r <= depth - h;) // a full minimum step left to the floor
  {
    below.push_back(p.CloudBottom - r);
    const double left = 1.0 / (r * r) - epsilon;
    const double next = left > 0.0 ? 1.0 / std::sqrt(left) : depth;
    r = std::max(r + h, next);
  }
  if (depth > 0.0)
  {
    below.push_back(p.Low[2]);
  }
  z.insert(z.begin(), below.rbegin(), below.rend());
  grid.Nodes[2] = z;
  return grid;
}

std::vector<Rgb> DistributeToVirtualLights(
  const VirtualLightGrid& grid, const std::vector<PointLight>& sources)
{
  for (int a = 0; a < 3; ++a)
  {
    if (grid.Nodes[a].size() < 2)
    {
      throw std::invalid_argument(
        "nimbus::DistributeToVirtualLights: the grid needs two nodes per axis");
    }
  }
  std::vector<Rgb> e(grid.NumberOfNodes(), Rgb{ { 0.0, 0.0, 0.0 } });
  for (const PointLight& q : sources)
  {
    if (!IsFinite(q.Position) || !std::isfinite(q.Intensity[0]) || !std::isfinite(q.Intensity[1]) ||
      !std::isfinite(q.Intensity[2]))
    {
      throw std::invalid_argument("nimbus::DistributeToVirtualLights: a source is not finite");
    }
    std::size_t cell[3];
    double f[3];
    for (int a = 0; a < 3; ++a)
    {
      const std::vector<double>& nodes = grid.Nodes[a];
      const double x = std::clamp(q.Position[a], nodes.front(), nodes.back());
      // The cell [nodes[c], nodes[c + 1]] holding x.
      const auto upper = std::upper_bound(nodes.begin(), nodes.end(), x);
      const std::size_t c = std::min<std::size_t>(
        std::max<std::ptrdiff_t>(upper - nodes.begin() - 1, 0), nodes.size() - 2);
      cell[a] = c;
      f[a] = std::clamp((x - nodes[c]) / (nodes[c + 1] - nodes[c]), 0.0, 1.0);
    }
    for (int corner = 0; corner < 8; ++corner)
    {
      double w = 1.0;
      std::size_t index[3];
      for (int a = 0; a < 3; ++a)
      {
        const int bit = (corner >> a) & 1;
        w *= bit ? f[a] : 1.0 - f[a];
        index[a] = cell[a] + bit;
      }
      Rgb& target = e[grid.Index(index[0], index[1], index[2])];
      for (int c = 0; c < 3; ++c)
      {
        target[c] += w * q.Intensity[c]; // 003 Eq. 6
      }
    }
  }
  return e;
}

double LightningGlowRadiance(double sigmaS, double intensity, double b)
{
  if (!(b > 0.0) || !std::isfinite(b) || !std::isfinite(sigmaS) || !std::isfinite(intensity))
  {
    return 0.0;
  }
  return sigmaS * intensity / (4.0 * b); // integral of 1/(b^2 + s^2) over s: pi / b
}

} // namespace nimbus
