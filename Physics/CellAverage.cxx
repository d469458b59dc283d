#include "CellAverage.h"

#include "MultipleScattering.h" // FibonacciDirections

#include <cmath>
#include <limits>
#include <utility>
#include <vector>

namespace nimbus
{
namespace
{
// Directions of the average (enough for 1 % on the source's own cell: CellAverage.h).
constexpr int kDirections = 1024;

const std::vector<Vector3>& AverageDirections()
{
  static const std::vector<Vector3> directions = FibonacciDirections(kDirections);
  return directions;
}

// integral over [t0, t1] of exp(-sigma r) dr (the chord itself when sigma r << 1).
double ChordIntegral(double sigma, double t0, double t1)
{
  if (!(t1 > t0))
  {
    return 0.0;
  }
  return sigma * (t1 - t0) > 1e-6 ? (std::exp(-sigma * t0) - std::exp(-sigma * t1)) / sigma
                                  : (t1 - t0) * std::exp(-sigma * t0);
}

// The parameters [tNear, tFar] of the ray from `origin` along w inside the box
// |x_a| <= half_a (tNear >= tFar: it misses).
std::pair<double, double> ChordThroughBox(
  const Vector3& origin, const Vector3& half, const Vector3& w)
{
  double tNear = 0.0, tFar = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3 && tNear < tFar; ++a)
  {
    if (w[a] == 0.0)
    {
      tFar = std::abs(origin[a]) <= half[a] ? tFar : -1.0;
      continue;
    }
    double t0 = (-half[a] - origin[a]) / w[a], t1 = (half[a] - origin[a]) / w[a];
    if (t0 > t1)
    {
      std::swap(t0, t1);
    }
    tNear = std::max(tNear, t0);
    tFar = std::min(tFar, t1);
  }
  return { tNear, tFar };
}
} // namespace

CellAverageOfSource AverageSourceOverCell(
  const Vector3& source, const Vector3& halfWidths, const BeamTransmittance& transmittance)
{
  const double f = transmittance.PeakFraction;
  const double sigma = transmittance.Sigma;
  const double reduced = transmittance.Reduced * sigma;
  double chords = 0.0;
  Vector3 flux{ { 0, 0, 0 } };
  for (const Vector3& w : AverageDirections())
  {
    const auto [tNear, tFar] = ChordThroughBox(source, halfWidths, w);
    const double chord = f > 0.0
      ? f * ChordIntegral(sigma, tNear, tFar) + (1.0 - f) * ChordIntegral(reduced, tNear, tFar)
      : ChordIntegral(sigma, tNear, tFar);
    chords += chord;
    for (int a = 0; a < 3; ++a)
    {
      flux[a] += chord * w[a];
    }
  }
  const double scale =
    4.0 * kPi / kDirections / (8.0 * halfWidths[0] * halfWidths[1] * halfWidths[2]);
  CellAverageOfSource average;
  average.InverseSquare = chords * scale;
  for (int a = 0; a < 3; ++a)
  {
    average.Flux[a] = flux[a] * scale;
  }
  return average;
}

} // namespace nimbus
