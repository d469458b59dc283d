// Lightning for clouds lit from inside (paper 003, Dobashi, Enjyo, Yamamoto & Nishita):
// the strokes, the point sources along them, the adaptive grid of virtual point lights
// and the energy-conserving distribution of the sources onto it. Plain C++, no VTK.
//
// Strokes (003 §3, after Reed & Wyvill 1994, "Visual Simulation of Lightning",
// SIGGRAPH 94): a main channel grown segment by segment from a seed point; each
// segment turns away from the previous one by an angle drawn from a normal distribution
// of mean 16 deg (the mean tortuosity that Hill 1968, "Analysis of irregular paths of
// lightning channels", J. Geophys. Res. 73, measured on photographs and Reed & Wyvill
// use) about a uniformly random axis; a pull toward the channel's overall direction
// (Straightness, our addition: a free random walk of directions wanders off) keeps the
// channel heading where it is going. A segment starts a branch with a probability; a
// branch leaves its parent at BranchAngleDegrees (Reed & Wyvill: a wider turn than the
// channel's), grows BranchLengthFactor times its parent's remaining length, carries
// BranchIntensityFactor times its parent's intensity (003: "the intensities of the
// lightning strokes are decreased as they branch") and branches again up to
// MaxBranchDepth. Everything is drawn from one 64-bit seed: the same parameters give
// the same stroke, bit for bit, on every run.
//
// Point sources (003 §3, Eq. 3): each segment of intensity I (radiant intensity per
// metre of channel [radiance x m^2 / m]) and length l is split into n = ceil(l / spacing)
// equal pieces, and a point light of intensity I l / n sits at the middle of each, so
// the sources carry the stroke's total I l exactly.
//
// The grid of virtual point lights (003 §5, Eq. 4): uniform at interval h_usr
// horizontally and above the cloud bottom z_cld; below it the distances r_l from the
// cloud bottom grow so that every layer adds about the same 1/r^2:
//   1/r_l^2 - 1/r_{l+1}^2 <= epsilon,  r_{l+1} - r_l >= h_usr  (003 Eq. 4 and its bound),
// i.e. r_1 = h_usr, r_{l+1} = max(r_l + h_usr, (1/r_l^2 - epsilon)^(-1/2)), until the
// bottom of the simulation space (a node there closes the grid; a layer closer to it
// than h_usr is left out). epsilon is given
// relative to the first layer, epsilon = EpsilonRelative / h_usr^2.
//
// Distribution (003 §7, Eq. 6): each point source's intensity goes to the eight nodes
// of its grid cell with the trilinear weights of its position in the (non-uniform) cell;
// the weights sum to 1, so the virtual lights carry the sources' total exactly. A source
// outside the grid is moved to the nearest point of the grid's box first (its light is
// kept, not lost).
#ifndef nimbus_Lightning_h
#define nimbus_Lightning_h

#include "NimbusPhysicsExport.h" // for export macro

#include "Math.h"
#include "MultipleScattering.h" // PointLight

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace nimbus
{

/// Everything that shapes one flash's strokes. Lengths in metres (world units of the
/// cloud's grid), angles in degrees.
struct NIMBUSPHYSICS_EXPORT LightningParameters
{
  Vector3 Start{ { 0, 0, 0 } };       // seed point (inside the cloud)
  Vector3 Direction{ { 0, 0, -1 } };  // overall direction of the main channel
  double Length = 3000.0;             // main channel, metres
  double SegmentLength = 30.0;        // mean segment length, metres (+-50 % uniform)
  double MeanAngleDegrees = 16.0;     // mean turn between segments (Hill 1968)
  double AngleSpreadDegrees = 8.0;    // its standard deviation
  double Straightness = 0.1;          // pull toward Direction per segment, [0, 1]
  double BranchProbability = 0.06;    // per segment, [0, 1]
  double BranchAngleDegrees = 35.0;   // mean turn of a branch from its parent
  double BranchLengthFactor = 0.35;   // branch length / parent's remaining length
  double BranchIntensityFactor = 0.4; // branch intensity / parent's, (0, 1]
  int MaxBranchDepth = 3;             // 0: the main channel only
  double Intensity = 1.0;             // main channel, radiant intensity per metre
  double StopBelowHeight = -1e300;    // z at which channels end (the ground)
  std::uint64_t Seed = 1;
};

/// One straight piece of a stroke.
struct NIMBUSPHYSICS_EXPORT LightningSegment
{
  Vector3 A, B;           // from A to B (metres)
  double Intensity = 0.0; // radiant intensity per metre of channel
  int Depth = 0;          // 0 main channel, 1 its branches, ...
  double PathStart = 0.0; // distance from the seed along the channels to A, metres

  /// |B - A|, metres.
  double Length() const
  {
    return nimbus::Length(
      { { this->B[0] - this->A[0], this->B[1] - this->A[1], this->B[2] - this->A[2] } });
  }
};

/// The first message describing what is wrong with the parameters, or "" (NaN or
/// infinite values, zero direction, lengths <= 0 or absurd (more than 1e6 segments),
/// probabilities or factors out of range, negative intensity).
NIMBUSPHYSICS_EXPORT std::string CheckLightningParameters(const LightningParameters& p);

/// The strokes of one flash (003 §3 after Reed & Wyvill 1994; see the file comment),
/// main channel first, then each branch's segments in the order they were made.
/// Throws std::invalid_argument with CheckLightningParameters's message, or when the
/// stroke with its branches would pass a million segments.
NIMBUSPHYSICS_EXPORT std::vector<LightningSegment> GenerateLightning(const LightningParameters& p);

/// One flash over time (seconds from its start), after the measured sequence of a
/// cloud-to-ground flash (Rakov & Uman 2003, "Lightning: Physics and Effects", ch. 4):
/// a stepped leader grows from the seed along the channels at constant speed, faint,
/// reaching the farthest point at LeaderDuration; then the return stroke lights every
/// channel; NumberOfStrokes - 1 subsequent strokes follow every InterstrokeInterval
/// along the main channel only (dart leaders retrace the first channel), each
/// SubsequentStrokeFactor times the one before. Every stroke decays as exp(-dt /
/// StrokeDecaySeconds) (its continuing current). Measured medians: 3-5 strokes per flash,
/// 60 ms between strokes, leaders of tens of milliseconds.
struct NIMBUSPHYSICS_EXPORT LightningFlashTimeline
{
  double LeaderDuration = 0.03;        // seconds
  double LeaderBrightness = 0.02;      // of the return stroke's
  int NumberOfStrokes = 4;             // >= 1
  double InterstrokeInterval = 0.06;   // seconds
  double SubsequentStrokeFactor = 0.6; // (0, 1]
  double StrokeDecaySeconds = 0.015;   // > 0
};

/// "" or what is wrong (non-finite or out-of-range fields).
NIMBUSPHYSICS_EXPORT std::string CheckLightningFlashTimeline(const LightningFlashTimeline& t);

/// The factor on a segment's intensity at time `seconds` (0 before the flash): the
/// leader's faint glow once the leader has reached the segment (at PathStart /
/// farthestPath of LeaderDuration), then the strokes. Deterministic, >= 0. Throws
/// std::invalid_argument with CheckLightningFlashTimeline's message.
NIMBUSPHYSICS_EXPORT double LightningFlashBrightness(const LightningFlashTimeline& timeline,
  const LightningSegment& segment, double farthestPath, double seconds);

/// The time the whole flash takes until its last stroke has decayed to 1 % (seconds).
NIMBUSPHYSICS_EXPORT double LightningFlashDuration(const LightningFlashTimeline& timeline);

/// Point sources along the segments (003 Eq. 3), at most `spacing` metres apart, with
/// intensity = segment intensity x piece length, one colour for all (grey: rgb equal).
/// Throws std::invalid_argument for spacing <= 0 or non-finite.
NIMBUSPHYSICS_EXPORT std::vector<PointLight> LightningPointSources(
  const std::vector<LightningSegment>& segments, double spacing);

/// The glow of the air around a point source (003 §8, after its [2]): the radiance that a
/// ray passing at distance b [m] from a point source of radiant intensity I sees
/// scattered once by air of scattering coefficient sigma_s [1/m], isotropic scattering,
/// extinction along the way neglected: L = integral over the ray of sigma_s / (4 pi) x
/// I / (b^2 + s^2) ds = sigma_s I / (4 b). Along a straight channel of I' per metre the
/// sources sum to (sigma_s I' / 2) acosh(R / d) at distance d < R when each glow is cut
/// at radius R (about ln(2R / d): a line source's log profile). 0 for b <= 0 or non-finite input.
NIMBUSPHYSICS_EXPORT double LightningGlowRadiance(double sigmaS, double intensity, double b);

/// The grid of virtual point lights (003 §5): node coordinates per axis, ascending,
/// metres. x and y uniform, z per Eq. 4 below the cloud bottom.
struct NIMBUSPHYSICS_EXPORT VirtualLightGrid
{
  std::array<std::vector<double>, 3> Nodes;

  std::size_t NumberOfNodes() const
  {
    return this->Nodes[0].size() * this->Nodes[1].size() * this->Nodes[2].size();
  }
  /// Node (i, j, k) at index i + nx (j + ny k).
  std::size_t Index(std::size_t i, std::size_t j, std::size_t k) const
  {
    return i + this->Nodes[0].size() * (j + this->Nodes[1].size() * k);
  }
  Vector3 Position(std::size_t i, std::size_t j, std::size_t k) const
  {
    return { { this->Nodes[0][i], this->Nodes[1][j], this->Nodes[2][k] } };
  }
};

/// The simulation space: an axis-aligned box [Low, High] (metres), the cloud bottom
/// z_cld inside it, the base interval h_usr and Eq. 4's epsilon relative to 1/h_usr^2.
struct NIMBUSPHYSICS_EXPORT VirtualLightGridParameters
{
  Vector3 Low{ { 0, 0, 0 } };
  Vector3 High{ { 1, 1, 1 } };
  double CloudBottom = 0.5;
  double BaseInterval = 0.1;
  double EpsilonRelative = 0.05;
};

/// Throws std::invalid_argument for a box that is empty or not finite, a cloud bottom
/// outside it, an interval <= 0 or one that would make more than 1e7 nodes, or
/// epsilon outside (0, 1).
NIMBUSPHYSICS_EXPORT VirtualLightGrid MakeVirtualLightGrid(const VirtualLightGridParameters& p);

/// The intensities e_l of the virtual lights (003 Eq. 6): every source's intensity
/// spread over the eight nodes of its cell with trilinear weights (sources outside the
/// grid's box moved onto it first). The sum over the result equals the sum over the
/// sources, per channel. Throws std::invalid_argument for non-finite sources.
NIMBUSPHYSICS_EXPORT std::vector<Rgb> DistributeToVirtualLights(
  const VirtualLightGrid& grid, const std::vector<PointLight>& sources);

} // namespace nimbus

#endif
