// Do two Monte Carlo images agree within their standard errors? Pixel by pixel (z of
// each pixel channel's difference) and as a whole (z of the image sums' difference,
// where a bias too small to see in one pixel adds up). For tests of the path tracer.
#ifndef NimbusMonteCarloAgreement_h
#define NimbusMonteCarloAgreement_h

#include "PathTracer.h"

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace nimbus_test
{

struct ImageAgreement
{
  double RmsZ = 0.0;                  // RMS of the per-channel z over the channels counted
  double ImageSumZ = 0.0;             // z of sum(a) - sum(b)
  double ImageSumRelativeError = 0.0; // the image sums' difference's se / sum(b)
  int Count = 0;                      // pixel channels with a non-zero combined se
  int Outliers = 0;                   // of those, |z| > 4
  bool Finite = true;                 // every pixel of both images finite
};

inline ImageAgreement CompareMonteCarloImages(
  const nimbus::PathTracingResult& a, const nimbus::PathTracingResult& b)
{
  ImageAgreement result;
  double sumZ2 = 0.0, sumDifference = 0.0, sumVariance = 0.0, sumB = 0.0;
  for (std::size_t i = 0; i < a.Image.Pixels.size(); ++i)
  {
    result.Finite =
      result.Finite && std::isfinite(a.Image.Pixels[i]) && std::isfinite(b.Image.Pixels[i]);
    sumB += b.Image.Pixels[i];
    const double sigma = std::hypot(static_cast<double>(a.StandardError.Pixels[i]),
      static_cast<double>(b.StandardError.Pixels[i]));
    if (!(sigma > 0.0))
    {
      continue;
    }
    const double difference = static_cast<double>(a.Image.Pixels[i]) - b.Image.Pixels[i];
    sumDifference += difference;
    sumVariance += sigma * sigma;
    const double z = difference / sigma;
    sumZ2 += z * z;
    result.Outliers += std::abs(z) > 4.0 ? 1 : 0;
    ++result.Count;
  }
  result.RmsZ = std::sqrt(sumZ2 / std::max(1, result.Count));
  result.ImageSumZ = sumVariance > 0.0 ? sumDifference / std::sqrt(sumVariance) : 0.0;
  result.ImageSumRelativeError = sumB != 0.0 ? std::sqrt(sumVariance) / std::abs(sumB) : 0.0;
  return result;
}

} // namespace nimbus_test

#endif
