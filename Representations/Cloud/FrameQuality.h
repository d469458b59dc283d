// The cloud mapper's automatic quality (plain C++, no GL): what a quality level
// means for a frame, and the measured cost model that picks the level that fits a
// frame budget while the user interacts.
//
// Quality q in (0, 1] is the fraction of a full frame's fragment work: the slices
// (eye and shadow passes) cost about N_slices x (pixels + shadow texels), so a
// level renders N = f N_0 slices into an image r W x r H with a shadow surface of
// r S_0 texels per side, f r^2 = q. Slices go first (down to a quarter; fewer
// slices band, a smaller image only blurs), then the image (down to 1/16 per side).
#ifndef nimbus_FrameQuality_h
#define nimbus_FrameQuality_h

#include "NimbusRepresentationsModule.h"

#include <deque>

namespace nimbus
{
struct NIMBUSREPRESENTATIONS_EXPORT FrameLevel
{
  double Quality = 1.0;       // f r^2 after rounding
  double ImageScale = 1.0;    // r: rendered pixels per viewport pixel, per side
  double SliceFraction = 1.0; // f
  int Slices = 1;
  int ShadowSurfaceSize = 1;
  int Width = 1, Height = 1; // the rendered image
};

/// The lowest quality a level can have (slices / 4, image / 16 per side).
constexpr double kMinimumFrameQuality = 0.25 / 256.0;

/// The level for `quality` (clamped to [kMinimumFrameQuality, 1]) of a frame whose
/// full quality has `slices`, `shadowSurfaceSize` and a `width` x `height` viewport.
NIMBUSREPRESENTATIONS_EXPORT FrameLevel ComputeFrameLevel(
  double quality, int slices, int shadowSurfaceSize, int width, int height);

/// Frame time t [s] against quality q, fitted as t = a + b q (a >= 0, b > 0) to the
/// newest frame of each level measured (at most 12 levels; the newest weigh most:
/// the machine's load changes).
class NIMBUSREPRESENTATIONS_EXPORT FrameCostModel
{
public:
  /// A measured frame: its quality and seconds (ignored unless both are finite
  /// and positive).
  void AddSample(double quality, double seconds);
  bool HasSamples() const { return !this->Samples.empty(); }
  /// Predicted seconds at `quality` (0 without samples).
  double PredictSeconds(double quality) const;
  /// The highest quality in [kMinimumFrameQuality, maximumQuality] predicted to
  /// take at most `budgetSeconds` (maximumQuality without samples: the first frame
  /// measures).
  double QualityFor(double budgetSeconds, double maximumQuality) const;
  void Clear() { this->Samples.clear(); }

private:
  struct Sample
  {
    double Quality, Seconds;
  };
  void Fit(double& fixed, double& perQuality) const;
  std::deque<Sample> Samples; // newest first, one per level (within 10 %), at most 12
};
} // namespace nimbus

#endif
