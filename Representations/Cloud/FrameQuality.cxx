#include "FrameQuality.h"

#include <algorithm>
#include <cmath>

namespace nimbus
{
FrameLevel ComputeFrameLevel(
  double quality, int slices, int shadowSurfaceSize, int width, int height)
{
  FrameLevel level;
  const double q =
    std::isfinite(quality) ? std::min(1.0, std::max(kMinimumFrameQuality, quality)) : 1.0;
  // Slices first (f = sqrt q down to 1/4), the image takes the rest (r^2 = q / f).
  level.SliceFraction = std::min(1.0, std::max(0.25, std::sqrt(q)));
  level.ImageScale = std::min(1.0, std::max(1.0 / 16.0, std::sqrt(q / level.SliceFraction)));
  const auto atLeastOne = [](double v) { return std::max(1, static_cast<int>(std::lround(v))); };
  level.Slices = atLeastOne(std::max(1, slices) * level.SliceFraction);
  level.ShadowSurfaceSize = atLeastOne(std::max(1, shadowSurfaceSize) * level.ImageScale);
  level.Width = atLeastOne(std::max(1, width) * level.ImageScale);
  level.Height = atLeastOne(std::max(1, height) * level.ImageScale);
  level.Quality = level.SliceFraction * level.ImageScale * level.ImageScale;
  return level;
}

void FrameCostModel::AddSample(double quality, double seconds)
{
  if (!(std::isfinite(quality) && quality > 0.0 && std::isfinite(seconds) && seconds > 0.0))
  {
    return;
  }
  // One sample per level (the newest): a frame slowed by something else (a
  // reallocation, a busy machine) is replaced by the next at its level.
  this->Samples.erase(
    std::remove_if(this->Samples.begin(), this->Samples.end(),
      [quality](const Sample& s) { return std::abs(s.Quality - quality) <= 0.1 * quality; }),
    this->Samples.end());
  this->Samples.push_front({ quality, seconds });
  if (this->Samples.size() > 12)
  {
    this->Samples.pop_back();
  }
}

// Weighted least squares of t = a + b q, weights 0.7^age; through the origin (a = 0)
// when the qualities measured are too close to separate a from b, or when the fit
// gives a < 0 or b <= 0 (noise).
void FrameCostModel::Fit(double& fixed, double& perQuality) const
{
  double sw = 0, sq = 0, st = 0, sqq = 0, sqt = 0, qMin = 1e300, qMax = 0;
  double weight = 1.0;
  for (const Sample& s : this->Samples)
  {
    sw += weight;
    sq += weight * s.Quality;
    st += weight * s.Seconds;
    sqq += weight * s.Quality * s.Quality;
    sqt += weight * s.Quality * s.Seconds;
    qMin = std::min(qMin, s.Quality);
    qMax = std::max(qMax, s.Quality);
    weight *= 0.7;
  }
  fixed = 0.0;
  perQuality = sqq > 0.0 ? sqt / sqq : 0.0;
  if (qMax > 1.25 * qMin)
  {
    const double determinant = sw * sqq - sq * sq;
    if (determinant > 0.0)
    {
      const double b = (sw * sqt - sq * st) / determinant;
      const double a = (st - b * sq) / sw;
      if (a >= 0.0 && b > 0.0)
      {
        fixed = a;
        perQuality = b;
      }
    }
  }
}

double FrameCostModel::PredictSeconds(double quality) const
{
  if (this->Samples.empty())
  {
    return 0.0;
  }
  double a, b;
  this->Fit(a, b);
  return a + b * quality;
}

double FrameCostModel::QualityFor(double budgetSeconds, double maximumQuality) const
{
  const double top = std::min(1.0, std::max(kMinimumFrameQuality, maximumQuality));
  if (this->Samples.empty() || !(budgetSeconds > 0.0))
  {
    return top;
  }
  double a, b;
  this->Fit(a, b);
  if (!(b > 0.0))
  {
    return top;
  }
  const double q = (budgetSeconds - a) / b;
  return std::min(top, std::max(kMinimumFrameQuality, q));
}
} // namespace nimbus
