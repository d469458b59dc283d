// The first scattering of a flash, grouped by brightness and kept (see the header).
#include "LightningFirstScattering.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>

namespace nimbus
{
namespace
{
constexpr std::uint64_t kFnvOffset = 1469598103934665603ull;
constexpr std::uint64_t kFnvPrime = 1099511628211ull;

void HashBytes(std::uint64_t& h, const void* data, std::size_t bytes)
{
  const unsigned char* p = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < bytes; ++i)
  {
    h = (h ^ p[i]) * kFnvPrime;
  }
}

// Relative intensities (the largest 1) and that largest as the scale.
LightningSourceGroup Normalised(std::vector<ScalarPointSource> sources, double scale)
{
  double largest = 0.0;
  for (const ScalarPointSource& s : sources)
  {
    largest = std::max(largest, s.Intensity);
  }
  LightningSourceGroup group;
  if (!(largest > 0.0))
  {
    return group;
  }
  for (ScalarPointSource& s : sources)
  {
    s.Intensity /= largest;
  }
  group.Sources = std::move(sources);
  group.Scale = scale * largest;
  return group;
}

// Brightness classes: one class's brightness is computed alike for all of its segments,
// but float arrays round intensity and peak apart, so classes are told apart at 1e-5.
long long BrightnessClass(double brightness)
{
  return std::llround(std::log(brightness) * 1e5);
}

// Sources at their peak, each shining at `brightness` times it -> one group per class of
// brightness, its scale the class's mean brightness.
std::vector<LightningSourceGroup> GroupByBrightness(
  std::vector<ScalarPointSource> atPeak, const std::vector<double>& brightness)
{
  std::map<long long, std::pair<double, std::vector<ScalarPointSource>>> classes;
  for (std::size_t k = 0; k < atPeak.size(); ++k)
  {
    auto& c = classes[BrightnessClass(brightness[k])];
    c.first += brightness[k];
    c.second.push_back(atPeak[k]);
  }
  std::vector<LightningSourceGroup> groups;
  for (auto& entry : classes)
  {
    const double mean = entry.second.first / entry.second.second.size();
    LightningSourceGroup group = Normalised(std::move(entry.second.second), mean);
    if (group.Scale > 0.0)
    {
      groups.push_back(std::move(group));
    }
  }
  return groups;
}

// The group's positions and relative intensities, the latter to 1e-6 (float rounding of
// an intensity scaled by the same factor must not make a new group).
std::uint64_t GroupKey(std::uint64_t gridHash, const LightningSourceGroup& group)
{
  std::uint64_t h = gridHash;
  for (const ScalarPointSource& s : group.Sources)
  {
    HashBytes(h, s.Position.data(), sizeof(double) * 3);
    const long long relative = std::llround(s.Intensity * 1e6);
    HashBytes(h, &relative, sizeof(relative));
  }
  return h;
}

// The sources of `kept` found in `group` (same positions), all at one ratio of relative
// intensity: that ratio and the group's other sources; ratio 0 when they do not fit.
std::pair<double, std::vector<ScalarPointSource>> SplitByKept(
  const std::vector<ScalarPointSource>& kept, const std::vector<ScalarPointSource>& group)
{
  std::pair<double, std::vector<ScalarPointSource>> none{ 0.0, {} };
  if (kept.empty() || kept.size() >= group.size())
  {
    return none;
  }
  std::map<Vector3, std::vector<std::size_t>> where;
  for (std::size_t k = 0; k < group.size(); ++k)
  {
    where[group[k].Position].push_back(k);
  }
  std::vector<bool> used(group.size(), false);
  double ratio = 0.0;
  for (const ScalarPointSource& source : kept)
  {
    auto found = where.find(source.Position);
    if (found == where.end() || found->second.empty() || !(source.Intensity > 0.0))
    {
      return none;
    }
    const std::size_t k = found->second.back();
    found->second.pop_back();
    used[k] = true;
    const double r = group[k].Intensity / source.Intensity;
    if (ratio == 0.0)
    {
      ratio = r;
    }
    else if (std::abs(r - ratio) > 1e-6 * ratio)
    {
      return none;
    }
  }
  std::vector<ScalarPointSource> rest;
  for (std::size_t k = 0; k < group.size(); ++k)
  {
    if (!used[k])
    {
      rest.push_back(group[k]);
    }
  }
  return { ratio, std::move(rest) };
}
} // namespace

std::uint64_t HashExtinctionGrid(const ExtinctionGrid& grid)
{
  std::uint64_t h = kFnvOffset;
  HashBytes(h, grid.Dimensions.data(), sizeof(int) * 3);
  HashBytes(h, grid.Origin.data(), sizeof(double) * 3);
  HashBytes(h, grid.Spacing.data(), sizeof(double) * 3);
  for (const Vector3& axis : grid.Axes)
  {
    HashBytes(h, axis.data(), sizeof(double) * 3);
  }
  HashBytes(h, grid.Extinction.data(), sizeof(float) * grid.Extinction.size());
  return h;
}

std::vector<LightningSourceGroup> GroupLightningSegments(
  const std::vector<LightningSegment>& segments, const std::vector<double>& peaks, double spacing)
{
  // Each lit segment's point sources at its peak, with the segment's brightness.
  std::vector<ScalarPointSource> atPeak;
  std::vector<double> brightness;
  for (std::size_t s = 0; s < segments.size(); ++s)
  {
    if (!(segments[s].Intensity > 0.0))
    {
      continue;
    }
    const bool peaked = s < peaks.size() && peaks[s] > 0.0;
    LightningSegment segment = segments[s];
    segment.Intensity = peaked ? peaks[s] : segments[s].Intensity;
    for (const PointLight& light : LightningPointSources({ segment }, spacing))
    {
      atPeak.push_back({ light.Position, light.Intensity[0] });
      brightness.push_back(peaked ? segments[s].Intensity / peaks[s] : 1.0);
    }
  }
  return GroupByBrightness(std::move(atPeak), brightness);
}

std::vector<LightningSourceGroup> GroupPointSources(
  const std::vector<ScalarPointSource>& sources, const std::vector<double>& peaks)
{
  std::vector<ScalarPointSource> atPeak;
  std::vector<double> brightness;
  for (std::size_t k = 0; k < sources.size(); ++k)
  {
    if (!(sources[k].Intensity > 0.0))
    {
      continue;
    }
    const bool peaked = k < peaks.size() && peaks[k] > 0.0;
    atPeak.push_back({ sources[k].Position, peaked ? peaks[k] : sources[k].Intensity });
    brightness.push_back(peaked ? sources[k].Intensity / peaks[k] : 1.0);
  }
  return GroupByBrightness(std::move(atPeak), brightness);
}

FirstScatteringField LightningFirstScatteringCache::Extend(const ExtinctionGrid& grid,
  std::uint64_t gridKey, const LightningSourceGroup& group, const FirstScatteringForwardPeak& peak,
  int threads, const std::function<void(double)>& progress)
{
  const Entry* base = nullptr;
  std::pair<double, std::vector<ScalarPointSource>> split{ 0.0, {} };
  for (const Entry& e : this->Entries)
  {
    if (e.GridKey != gridKey || (base && e.Sources.size() <= base->Sources.size()))
    {
      continue;
    }
    auto candidate = SplitByKept(e.Sources, group.Sources);
    if (candidate.first > 0.0)
    {
      base = &e;
      split = std::move(candidate);
    }
  }
  if (!base)
  {
    return {};
  }
  // Linear in the intensities: the kept field times the ratio, plus the rest's.
  const FirstScatteringField rest =
    ComputeFirstScattering(grid, split.second, threads, progress, peak);
  FirstScatteringField field =
    CombineFirstScattering({ &base->Field, &rest }, { split.first, 1.0 });
  field.Seconds = rest.Seconds;
  ++this->Extensions;
  return field;
}

FirstScatteringField LightningFirstScatteringCache::Evaluate(const ExtinctionGrid& grid,
  const std::vector<LightningSourceGroup>& groups, const FirstScatteringForwardPeak& peak,
  int threads, const std::function<void(double)>& progress)
{
  this->LastComputeSeconds = 0.0;
  std::uint64_t gridHash = HashExtinctionGrid(grid);
  HashBytes(gridHash, &peak.Fraction, sizeof(double));
  HashBytes(gridHash, &peak.Albedo, sizeof(double));
  std::vector<const FirstScatteringField*> fields;
  std::vector<double> scales;
  std::vector<std::uint64_t> keys;
  for (const LightningSourceGroup& group : groups)
  {
    keys.push_back(GroupKey(gridHash, group));
  }
  // Keep the fields of this frame's groups at the front, so that computing one does not
  // push out another.
  std::size_t done = 0;
  for (std::size_t g = 0; g < groups.size(); ++g)
  {
    auto found = std::find_if(
      this->Entries.begin(), this->Entries.end(), [&](const Entry& e) { return e.Key == keys[g]; });
    if (found != this->Entries.end())
    {
      ++this->Hits;
      Entry entry = std::move(*found);
      this->Entries.erase(found);
      this->Entries.push_front(std::move(entry));
      continue;
    }
    ++this->Misses;
    Entry entry;
    entry.Key = keys[g];
    entry.GridKey = gridHash;
    entry.Sources = groups[g].Sources;
    const auto groupProgress = [&](double fraction)
    {
      if (progress)
      {
        progress((done + fraction) / groups.size());
      }
    };
    entry.Field = this->Extend(grid, gridHash, groups[g], peak, threads, groupProgress);
    if (entry.Field.Values.empty())
    {
      entry.Field = ComputeFirstScattering(grid, groups[g].Sources, threads, groupProgress, peak);
    }
    this->LastComputeSeconds += entry.Field.Seconds;
    this->Entries.push_front(std::move(entry));
    ++done;
  }
  for (std::size_t g = 0; g < groups.size(); ++g)
  {
    for (const Entry& e : this->Entries)
    {
      if (e.Key == keys[g])
      {
        fields.push_back(&e.Field);
        scales.push_back(groups[g].Scale);
        break;
      }
    }
  }
  FirstScatteringField sum;
  if (fields.empty())
  {
    sum.Dimensions = grid.Dimensions;
    sum.Values.assign(4 * grid.NumberOfPoints(), 0.0f);
  }
  else
  {
    sum = CombineFirstScattering(fields, scales);
  }
  while (this->Entries.size() > std::max(Capacity, groups.size()))
  {
    this->Entries.pop_back();
  }
  return sum;
}

} // namespace nimbus
