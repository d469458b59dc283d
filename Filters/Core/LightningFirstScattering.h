// The first scattering of a flash's point sources on the cloud's own grid, frame after
// frame (nimbus::ComputeFirstScattering, Physics/FirstScattering.h), without redoing it
// for every time step. Plain C++, no VTK.
//
// The first scattering is linear in the sources' intensities. A flash changes its
// segments' brightness in a few classes (LightningFlashBrightness, Physics/Lightning.h):
// every segment by the same factor during a stroke's decay, the main channel and the
// branches by two factors during subsequent strokes, the segments the leader has reached
// by one. So the sources are grouped by their brightness relative to their peak; a
// group's field at unit scale is computed once and kept (the last few, keyed by the
// grid and the group's positions and relative intensities), and a frame is the sum of its
// groups' fields times their scales: a frame of a decaying stroke costs a weighted sum. A
// group that holds a kept group's sources, all at one ratio of intensity (the leader's
// reached set, which grows step by step), is that group's field times the ratio plus the
// field of its other sources alone: a leader's step costs its new segments.
#ifndef nimbus_LightningFirstScattering_h
#define nimbus_LightningFirstScattering_h

#include "FirstScattering.h"
#include "Lightning.h"

#include <cstdint>
#include <deque>
#include <functional>
#include <string>
#include <vector>

namespace nimbus
{

/// Sources whose intensities change together: Sources at relative intensity (the largest
/// 1), each lit by Scale times that.
struct LightningSourceGroup
{
  std::vector<ScalarPointSource> Sources;
  double Scale = 0.0;
};

/// Groups of a flash's segments by brightness: segment s shines at segments[s].Intensity,
/// its peak is peaks[s] (empty: one group of all). Point sources every `spacing` metres
/// (LightningPointSources). Segments with zero intensity are left out.
std::vector<LightningSourceGroup> GroupLightningSegments(
  const std::vector<LightningSegment>& segments, const std::vector<double>& peaks, double spacing);

/// Groups of point sources by brightness: source k shines at sources[k].Intensity, its
/// peak is peaks[k] (empty: one group of all, its intensities relative to the largest).
std::vector<LightningSourceGroup> GroupPointSources(
  const std::vector<ScalarPointSource>& sources, const std::vector<double>& peaks);

/// The groups' fields, computed once per grid and group and kept (see the file comment).
class LightningFirstScatteringCache
{
public:
  /// The sum over the groups of Scale x the group's field on `grid` (with the solver's
  /// forward peak, ComputeFirstScattering). `progress` as for ComputeFirstScattering
  /// (fractions of the groups computed anew).
  FirstScatteringField Evaluate(const ExtinctionGrid& grid,
    const std::vector<LightningSourceGroup>& groups, const FirstScatteringForwardPeak& peak,
    int threads, const std::function<void(double)>& progress = nullptr);

  /// Groups found in the cache and computed, since construction; of those computed, the
  /// ones computed by extending a kept group (only their other sources computed).
  int GetHits() const { return this->Hits; }
  int GetMisses() const { return this->Misses; }
  int GetExtensions() const { return this->Extensions; }
  /// Seconds spent computing in the last Evaluate (0 when every group was kept).
  double GetLastComputeSeconds() const { return this->LastComputeSeconds; }
  void Clear() { this->Entries.clear(); }

  /// Fields kept at most.
  static constexpr std::size_t Capacity = 6;

private:
  struct Entry
  {
    std::uint64_t Key = 0;
    std::uint64_t GridKey = 0;              // the grid and the forward peak
    std::vector<ScalarPointSource> Sources; // the group's, at relative intensity
    FirstScatteringField Field;
  };
  /// The field of `group` from the kept group with the most of its sources (all of them
  /// in `group` at one ratio of intensity) and the rest computed, or an empty field when
  /// no kept group fits.
  FirstScatteringField Extend(const ExtinctionGrid& grid, std::uint64_t gridKey,
    const LightningSourceGroup& group, const FirstScatteringForwardPeak& peak, int threads,
    const std::function<void(double)>& progress);

  std::deque<Entry> Entries; // most recently used first
  int Hits = 0;
  int Misses = 0;
  int Extensions = 0;
  double LastComputeSeconds = 0.0;
};

/// A 64-bit FNV-1a hash of the grid (dimensions, placement, extinction).
std::uint64_t HashExtinctionGrid(const ExtinctionGrid& grid);

} // namespace nimbus

#endif
