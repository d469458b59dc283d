// Monte Carlo volumetric path tracer: the full-multiple-scattering ground truth
// for the scenes of RenderContext (cloud + Rayleigh/Mie atmosphere + Lambertian
// ground + background + directional sun; since scene format version 3 also point and
// polyline lights, emitting media and several media; since version 4 spot lights with light
// maps and opaque Lambertian occluders). Everything physical comes from the
// RenderContext; this file only integrates the radiative transfer equation
//     L(x, w) = int_0^d T(x, x_t) [eta(x_t) + sigma_s(x_t) int p(w', w) L(x_t, w') dw'] dt
//               + T(x, x_d) L_d
// with T = exp(-int sigma_t) and eta the media's emission (Y/(sr m)), by unbiased
// estimators:
//
//  - Version 3 (docs/ground-truth.md, "Lights, emission and several media"): lights by
//    next-event estimation at every vertex (one element chosen by intensity; a polyline
//    segment among the segments by its estimated contribution at the vertex and a point
//    on it uniform in the angle it subtends there, SampleSegmentByAngle; ratio tracking to
//    a finite distance, the air's exact transmittance); emission by the collision estimator w eta /
//    sigma_bar_c at each tentative collision charged to the cloud (blocks that emit get a majorant
//    of at least 1 / block edge); several media through the summed extinction grid, the scattering
//    medium chosen with probability a_i sigma_t,i / sigma_s and its phase used at that vertex. None
//    of it runs, or draws a random number, in scenes without it.
//
//  - Version 4 (docs/ground-truth.md, "Spot lights and occluders"): a spot is a light
//    element whose estimate is multiplied by SpotFactor x its light map toward the vertex
//    (Physics/SpotLight.h); occluders (RenderContext::GetOccluders, a bounding volume
//    hierarchy) end a segment where a ray meets one (a surface vertex: NEE of the sun and
//    the lights with f = albedo/pi cos, the next direction cosine-weighted about the
//    normal, weight x albedo; albedo 0 ends the path) and block the shadow rays of the sun
//    and of every light. Neither runs, or draws a random number, in scenes without it.
//
//  - Light tracing (PathTracingSettings::LightTracing; docs/ground-truth.md, "Light
//    tracing"): for scenes lit only by point, spot and polyline lights, paths start at the
//    lights and connect to the pinhole camera at every scattering vertex (RenderLightTraced);
//    the standard error comes from batches of light paths.
//
//  - Free flights: delta tracking against a piecewise-constant majorant
//    sigma_bar(t) = cloud block majorant (max density of a 4^3-voxel block of the
//    MajorantGrid x ExtinctionPerDensity, the blocks visited by an incremental 3-D DDA,
//    Amanatides & Woo 1987, so no dilation is needed; BlockTraversal) + atmosphere
//    majorant (max over wavelengths of beta_R(lambda) rho_R(h_min) + beta_M,ext
//    rho_M(h_min), h_min the lowest altitude on the piece: pieces of <= 50 km outside
//    the cloud box, the box's lowest altitude inside it). Majorants bound sigma_t: no
//    bias. A tentative collision is charged to the cloud or to the atmosphere in
//    proportion to their majorants, so only one of the two is evaluated.
//  - Spectral: one path carries a throughput vector over all wavelength samples
//    of the context (spectral tracking with history-aware collision
//    probabilities, Kutz et al., "Spectral and Decomposition Tracking for
//    Rendering Heterogeneous Volumes", SIGGRAPH 2017, Eqs. 14-17). The cloud is
//    grey, so cloud-only paths have identical weights at all wavelengths (no
//    colour noise); the atmosphere's lambda^-4 extinction makes the weights
//    differ. Cost: O(N_lambda) per tentative collision.
//  - Next-event estimation to the sun at every real scattering event and ground
//    hit: cloud transmittance by ratio tracking (with Russian roulette below
//    0.1) x the atmosphere's sun transmittance: inside the cloud box from a (r, mu_s)
//    table of the exact optical lengths whose interpolation error is verified < 1e-6
//    in ln T; elsewhere from a whole-atmosphere table of ln L_R, ln L_M checked cell
//    by cell (< 1e-4 in ln T where used; TabulatedAirTransmittance), else exact
//    (RenderContext::SunAtmosphereTransmittance; 0 where the earth hides the sun) x 0
//    if the sun is below the horizon of the enabled ground plane without atmosphere.
//    Inside the cloud the estimate runs with probability min(1, T_est / 0.02) (at
//    least 0.01), weighted by its inverse, T_est from a short-characteristics lattice
//    of the cloud's optical depth toward the sun (SunDepthRoulette).
//  - Sun-peak sampling (SunPeakSampling, Veach's balance heuristic): at each cloud or
//    ground vertex a second direction is drawn from the cloud's phase function about
//    the sun and followed to its next event; if that is a cloud scattering event, the
//    sun's contribution there is added with weight p_B / (p_A + p_B), and the usual
//    path's contribution at a cloud event with p_A / (p_A + p_B) (p_A the pdf of the
//    direction the previous vertex drew, p_B = p_c(s . d)). The sun is a delta light,
//    so phase sampling never hits it: the two strategies are two ways of reaching the
//    vertex whose sun estimate p_c(s . d) T_sun E is spiky when d is near s.
//  - New directions: phase-function sampling of the component that scattered
//    (cloud mixture, Rayleigh, Cornette-Shanks g = mie_g); cosine-weighted at the
//    ground (weight *= albedo).
//  - Russian roulette from RussianRouletteOrder bounces on: survive with
//    probability min(1, max_lambda weight).
//  - Adaptive sampling (AdaptiveSampling, off by default): a pilot whose samples are
//    not part of the image sets each pixel's share of the samples.
//
// Phase-function convention (PhaseFunctions.h): mu = dot(propagation direction
// of the incident light, scattered direction). For NEE the light propagates
// along -sunDirection and leaves toward the camera along -d (d: path direction
// away from the camera), so mu = dot(sunDirection, d): looking toward the sun
// through the cloud is forward scattering.
//
// Termination of a path: it leaves the scene or passes the top of the
// atmosphere (background radiance), hits the ground plane or an occluder (reflects;
// a black occluder ends it), hits the
// earth sphere of an enabled atmosphere (reached only with the ground plane
// disabled: black, no radiance), or is killed by Russian roulette /
// MaxScatteringOrder. Sun occlusion: without atmosphere the enabled ground plane
// hides a sun below the horizon; with the atmosphere the spherical earth does
// (twilight reaches the upper air). Both as in SingleScatteringRenderer. A path
// that exceeds kMaxTrackingStepsPerPath tentative collisions (free-flight +
// ratio-tracking steps + ground hits together) is truncated (contribution so far
// kept, slightly biased low) and counted in PathTracingResult::TruncatedPaths.
//
// Measured (g++ 12 -O2, 2 shared cores, BenchPathTracer at 80 x 60): 4-30 us per
// path on the five harness scenes; per-path relative standard deviation ~1.5-2.5 (a
// lit cloud pixel: 2.1; 1 % of its paths carry 61 % of the second moment, each with
// one sun estimate at the lit surface while heading sunward, phase 1.2-6.3 against a
// median of 0.06). The time to 1 % image-wide is in docs/ground-truth.md.
//
// Determinism: sample k of pixel (i, j) draws from a counter-based generator
// seeded by (Seed, pixel index, k) and each pixel's running statistics are
// updated in sample order by one thread, so results are bit-identical for any
// thread count.
#ifndef NimbusPathTracer_h
#define NimbusPathTracer_h

#include "NimbusReferenceModule.h"

#include "FloatImage.h"
#include "RenderContext.h"

#include <cstdint>
#include <functional>
#include <string>

namespace nimbus
{

/// Free-flight + ratio-tracking steps (tentative collisions) allowed per path.
/// Reached only in near-conservative media of optical thickness >~ 1e3, where
/// a diffusing path needs ~tau^2 steps; the path is then cut (see above).
constexpr std::uint64_t kMaxTrackingStepsPerPath = std::uint64_t(1) << 20;

struct PathTracingRound;

struct NIMBUSREFERENCE_EXPORT PathTracingSettings
{
  int MinSamplesPerPixel = 16;
  int MaxSamplesPerPixel = 1024;
  /// Stop a pixel when its standard error / mean < target (0 = run to Max).
  /// Measured on the mean of the three linear sRGB channels; a pixel whose
  /// samples are all exactly 0 counts as converged after MinSamplesPerPixel.
  double TargetRelativeError = 0.0;
  /// 0 = unlimited; 1 = single scattering only (NEE at the first scattering event
  /// or ground hit; the background seen directly, attenuated, is order 0).
  int MaxScatteringOrder = 0;
  std::uint64_t Seed = 1;
  /// 0 = std::thread::hardware_concurrency().
  int Threads = 0;
  /// Russian roulette at scattering orders >= this (negative: never).
  int RussianRouletteOrder = 5;
  /// Extension: true = uniform jitter over the pixel (box filter); false = every
  /// path through the pixel centre, like the deterministic renderers.
  bool PixelJitter = true;
  /// Sun-peak sampling: at each cloud or ground vertex, also a direction from the
  /// cloud's phase function about the sun, combined with the usual direction by the
  /// balance heuristic (see PathTracer.cxx). Unbiased either way; false = off. Runs only
  /// when the cloud's phase function peaks at >= 2x its mean (not for isotropic or
  /// Rayleigh scattering, where it would only cost time).
  bool SunPeakSampling = true;
  /// Sun-depth roulette: inside the cloud, estimate the sun's contribution only with
  /// probability min(1, T_est / 0.05) (weighted by its inverse), T_est from a lattice of
  /// the cloud's optical depth toward the sun. Unbiased either way; false = always.
  bool SunDepthRoulette = true;
  /// Equi-angular sampling of the lights (Kulla & Fajardo 2012): on every segment of a
  /// path through a medium, a point drawn with density proportional to 1/d^2 about a light
  /// (within a spot's cone), its single scattering of that light added, combined with the
  /// lights' estimate at the segment's collisions by the balance heuristic. Unbiased either
  /// way; without it a point light's estimate near the light has infinite variance (the
  /// second moment of 1/d^2 over a volume diverges). Runs only in scenes with lights.
  bool EquiAngularLightSampling = true;
  /// Next-event estimation to polyline segments (lightning channels): true = the segment
  /// chosen by an estimate of its unoccluded contribution at the vertex and the point on it
  /// uniform in the angle it subtends there (the estimate is bounded by pi I_l / h, h the
  /// vertex's distance to the segment's line, I_l the intensity per metre); false = the
  /// segment chosen in proportion to its intensity and the point uniform in length (the
  /// estimate ~ 1/|x - y|^2, whose second moment diverges at vertices near a segment).
  /// Both are unbiased; points and spots are sampled alike either way.
  bool AngularLineLightSampling = true;
  /// The atmosphere's transmittance toward the sun at air and ground points from a
  /// table checked cell by cell against the exact integral (error in ln T <= 1e-4 where
  /// used, exact elsewhere); false = the exact integral at every point. The table
  /// (~0.3 s) is built only for renders of >= 65536 planned paths (pixels x
  /// MaxSamplesPerPixel) or with a time limit or image target.
  bool TabulatedAirTransmittance = true;
  /// Incremental DDA over the cloud's majorant blocks of MajorantBlockVoxels^3 voxels
  /// (no dilation: the traversal keeps every point in its block); false = 4^3 blocks
  /// dilated by one point, the block located from the position at every piece.
  bool BlockTraversal = true;
  int MajorantBlockVoxels = 4;
  /// Adaptive sampling: a pilot of MinSamplesPerPixel paths per pixel (not part of the
  /// image) gives each pixel a share s_i of the samples, s_i ~ sqrt(variance / cost)
  /// (mean 1, within [1/8, 8]); round targets and MaxSamplesPerPixel are then means
  /// over the image and pixel i gets s_i times them. Cuts the image-wide error at a
  /// given time; unbiased (the shares do not depend on the image's samples).
  bool AdaptiveSampling = false;
  /// Bytes the per-pixel buffers may take (about 104 bytes per pixel); 0 =
  /// nimbus::DefaultMemoryBudgetBytes() (Physics/MemoryBudget.h).
  double MemoryBudgetBytes = 0.0;
  /// Stop after the first round that ends past this many seconds (0 = no limit). The
  /// image is then unbiased with fewer samples; PathTracingResult says so. Rounds double
  /// the samples per pixel, but with a limit a round is cut to what the time left allows
  /// at the last round's cost (NextRoundTarget), so the render ends near the limit, not
  /// up to twice past it.
  double TimeLimitSeconds = 0.0;
  /// Stop after the first round whose image-wide relative error (ImageRelativeError)
  /// is at or below this (0 = no such target; the per-pixel target still applies).
  double TargetImageRelativeError = 0.0;
  /// Called on the calling thread after each round (for a progress display).
  std::function<void(const PathTracingRound&)> OnRound;
  /// Light tracing instead of camera paths (docs/ground-truth.md, "Light tracing"): paths
  /// start at the lights (an element chosen by intensity, a point uniform on a segment, a
  /// direction uniform on the sphere or in a spot's cone) and at every scattering vertex
  /// connect to the pinhole camera (ratio tracking to it, with its Russian roulette below
  /// a transmittance of 0.1), adding to the pixel the connection passes through. The
  /// camera's importance is normalised so that the image is the box-filtered radiance of
  /// the camera path tracer with PixelJitter. Paths come in batches of LightPathsPerBatch;
  /// each batch is one sample of the whole image, and a pixel's standard error is that of
  /// the mean over the batches. MinSamplesPerPixel and MaxSamplesPerPixel then count light
  /// paths per pixel (at least 2 batches); TargetRelativeError and AdaptiveSampling do not
  /// apply. Only for scenes lit by point, spot and polyline lights in the cloud's media:
  /// RenderPathTraced throws std::invalid_argument (LightTracingUnsupported's message) for a
  /// sun of illuminance > 0, a background radiance > 0, the atmosphere, the ground,
  /// occluders, emitting media or no light. Deterministic for a Seed and any thread count
  /// (each batch is traced by one thread; batches are summed in order).
  bool LightTracing = false;
  /// Light tracing: light paths per batch (0 = max(1024, pixels)).
  std::uint64_t LightPathsPerBatch = 0;
};

/// The state after one round of samples.
struct NIMBUSREFERENCE_EXPORT PathTracingRound
{
  int Round = 0;                    // 1 for the first
  double MeanSamplesPerPixel = 0.0; // so far
  double Seconds = 0.0;             // since the render started
  double ImageRelativeError = 0.0;  // as PathTracingResult::ImageRelativeError, so far
  std::size_t ActivePixels = 0;     // pixels that will get more samples
  std::size_t Pixels = 0;
};

/// Image-wide relative error of a radiance image with its per-pixel standard error:
/// the RMS standard error over the RMS radiance, all pixels and channels (0 for a
/// black image).
NIMBUSREFERENCE_EXPORT double ImageRelativeError(
  const FloatImage& image, const FloatImage& standardError);

/// The samples per pixel (mean over the image) the next round brings every active pixel
/// to, after a round that brought them to `target`: 2 * target, at most maxSamples; with a
/// time limit (secondsLeft finite) at most target + secondsLeft / secondsPerSample, the
/// samples that fit in the time left at the cost of one more sample per active pixel
/// (measured on the last round), and always at least target + 1.
NIMBUSREFERENCE_EXPORT std::uint64_t NextRoundTarget(
  std::uint64_t target, std::uint64_t maxSamples, double secondsLeft, double secondsPerSample);

struct NIMBUSREFERENCE_EXPORT PathTracingResult
{
  FloatImage Image;         // linear sRGB radiance, the scene's relative units
  FloatImage StandardError; // per pixel and channel, same units
  double MeanSamplesPerPixel = 0.0;
  double Seconds = 0.0;
  // Extensions.
  std::uint64_t Paths = 0;          // paths traced in total
  std::uint64_t TruncatedPaths = 0; // paths cut at kMaxTrackingStepsPerPath
  double ImageRelativeError = 0.0;  // ImageRelativeError(Image, StandardError)
  bool StoppedAtTimeLimit = false;  // TimeLimitSeconds ended the render
  bool ReachedImageTarget = false;  // TargetImageRelativeError ended the render
  int Rounds = 0;
};

/// A pilot's forecast of a render's time to an image-wide error target.
struct NIMBUSREFERENCE_EXPORT PathTracingEstimate
{
  double SecondsToTarget = 0.0;    // forecast for the whole image, settings' threads
  double PilotSeconds = 0.0;       // what the pilot took
  double PilotRelativeError = 0.0; // its image-wide relative error
  std::size_t PilotPixels = 0;     // pixels it traced
  int PilotSamplesPerPixel = 0;
};

/// Before a long render: traces every `stride`-th pixel along x and y (at least one)
/// with `pilotSamples` paths each (a stream of their own; about pilotSamples / stride^2
/// samples per pixel of the whole image's cost) and forecasts the time for the whole
/// image to reach `targetImageRelativeError` with settings' threads, from the N^-1/2
/// law: t = t_pilot (pixels / pilot pixels) (e_pilot / target)^2. A pilot of a few
/// dozen samples sees few of the rare large samples, so it errs short (measured in
/// docs/ground-truth.md). Throws std::invalid_argument for a target <= 0, pilotSamples
/// < 2 or stride < 1.
NIMBUSREFERENCE_EXPORT PathTracingEstimate EstimatePathTracingTime(const RenderContext& context,
  const PathTracingSettings& settings, double targetImageRelativeError, int pilotSamples = 32,
  int stride = 4);

/// Renders the context's camera view progressively: rounds of samples (first
/// MinSamplesPerPixel, then doubling up to MaxSamplesPerPixel), per-pixel
/// running mean and variance (Welford), per-pixel stop on TargetRelativeError.
/// progress(fraction in [0, 1]) is called from the calling thread during and
/// after each round; it may throw to stop the render (e.g. on a user's abort): the
/// exception propagates once the pixels being traced are done. Throws
/// std::invalid_argument for MinSamplesPerPixel < 1 or MaxSamplesPerPixel <
/// MinSamplesPerPixel or a negative / NaN target or time limit, and std::length_error, before
/// allocating, when the per-pixel buffers would need more than MemoryBudgetBytes,
/// and std::range_error when the image has a NaN or infinite pixel component.
NIMBUSREFERENCE_EXPORT PathTracingResult RenderPathTraced(const RenderContext& context,
  const PathTracingSettings& settings, const std::function<void(double)>& progress = {});

/// Why light tracing (PathTracingSettings::LightTracing) cannot render the context's scene,
/// or "" when it can.
NIMBUSREFERENCE_EXPORT std::string LightTracingUnsupported(const RenderContext& context);

/// Line lights (AngularLineLightSampling). A point y(s) = a + s axis of the segment from a
/// along the unit axis, s in [0, length] (m), seen from p: drawn uniformly in the angle
/// theta the segment subtends at p (u in [0, 1)), so with the density in s
///   pdf(s) = h / (Delta theta r(s)^2),  1/m,
/// h the distance from p to the segment's line, r(s) = |y(s) - p| (Kulla & Fajardo,
/// "Importance Sampling Techniques for Path Tracing in Participating Media", EGSR 2012:
/// their equi-angular density with the light and the path's line swapped). An estimate
/// I_l f T / r^2 / pdf of the line's light at p is then I_l f T Delta theta / h.
struct NIMBUSREFERENCE_EXPORT SegmentAngleSample
{
  Vector3 Point{ { 0.0, 0.0, 0.0 } }; // y, m
  double Along = 0.0;                 // s, m
  /// Delta theta / h = 1 / (r(s)^2 pdf(s)) for every s, 1/m.
  double AngleOverDistance = 0.0;
};
/// False where p lies on the segment's line (a set of zero measure) or the segment is
/// degenerate. Exact also near the line's extension (Delta theta = atan2(L h, a.b)).
NIMBUSREFERENCE_EXPORT bool SampleSegmentByAngle(const Vector3& p, const Vector3& a,
  const Vector3& axis, double length, double u, SegmentAngleSample& sample);
/// The density pdf(s) of SampleSegmentByAngle, 1/m (0 outside [0, length]).
NIMBUSREFERENCE_EXPORT double SegmentAngleDensity(
  const Vector3& p, const Vector3& a, const Vector3& axis, double length, double s);
/// The weight by which the path tracer chooses among the line segments of a cluster (after
/// choosing the cluster by its intensity over its squared distance) at a vertex p: the
/// segment [a, b] of total intensity I (Y/sr, I_l = I / L per metre) gets
///   w = I_l 2 sin(Delta theta / 2) / h = sqrt(2) I / sqrt(q (q + (a - p).(b - p))),
/// q = |a - p| |b - p|, Y/(sr m^2): the chord of the subtended angle in place of the angle
/// in the segment's unoccluded I_l Delta theta / h, so that
/// 1 <= (I_l Delta theta / h) / w <= pi / 2. Two square roots, no trigonometry; finite
/// off the segment's own points.
NIMBUSREFERENCE_EXPORT double LineLightWeight(
  const Vector3& p, const Vector3& a, const Vector3& b, double intensity);

} // namespace nimbus

#endif
