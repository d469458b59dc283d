// 004 §3.4's reference patterns: the sun's orders 2..Orders of multiple scattering,
// gathered at every grid point from the grid points a precomputed 3-D filter (the
// reference pattern) names, with the paper's stochastic selection of paths.
//
// The transport (per order, at grid point P, from every source grid point j = P + o):
//   E_j = sigma_s(j) J_n(j, s) T(j -> P) dV / r^2                        [irradiance]
//   J_{n+1}(P, w) = sum_j E_j p(w . s)                                   [radiance]
// with s the unit propagation direction from j to P, r = |P - j| [m], dV the cell
// volume [m^3] and T the transmittance through the real (non-uniform) extinction
// (004 §3.4 step 2). sigma_s J dV is the intensity the source cell emits toward P
// (sigma_s J [radiance/m] is the cloud's emission per unit length), / r^2 makes it
// the irradiance at P, and the phase function p [1/sr] turns it into radiance leaving
// P in w. Stored as degree-1 spherical harmonics (Funk-Hecke):
//   c_lm(P) += k_l E_j Y_lm(s),   k_0 = 1, k_1 = PhaseLegendreCoefficient(optics, 1).
// Order 1 (the mapper's, not added here) is the source of order 2:
//   J_1(j, s) = p(s . -L_sun) E_sun(z_j) exp(-tau_sun(j))   (the sun light travels
// along -ToLight; scattering it into s has mu = s . -ToLight). Orders >= 3 take J_n(j, s)
// from the order-n field stored as SH (EvaluateInScattering, clamped at 0): the
// recursive form of the paper's 3rd-order path pairs P3 P2 P ("the idea can be
// expanded to higher orders", 004 §3.4).
//
// The reference pattern (004 §3.4 step 1). On a uniform sample space at the cloud's
// mean extinction sigma_mean (mean over the grid points with sigma_t > 0), the offset
// o of a source contributes to P
//   w(o) = p(s . -L_sun) exp(-sigma_mean r) dV / r^2        (order 2)
//   w(o) = exp(-sigma_mean r) dV / r^2                      (orders >= 3: the order-n
//                                                            field has no sun peak)
// over the cube of offsets of half-width PatternRadius (clipped to the grid), the self
// offset o = 0 excluded (1/r^2 is singular there).
// The paper's pattern is view-dependent (it multiplies the outgoing phase p(w . s) for
// the viewing direction w); J here is stored for all w, so the outgoing phase is
// averaged over w (its mean over the sphere is 1/(4 pi), a constant) and dropped.
// The offsets are sorted by w(o) and the fewest whose sum reaches PatternContribution
// (the paper's r = 0.8) of the total are kept: n2 offsets covering the share c.
//
// Stochastic selection (004 §3.4). At each point n1 = ceil(PatternSelection n2) of the
// n2 kept offsets are drawn, seeded from Seed, the order and the point index
// (independent of the threads), and the estimate is divided by c. The paper draws the
// n1 uniformly and writes the estimate as "I r n2/n1"; multiplying by r <= 1 would make
// a truncated sum smaller still, so we read it as I (n2 / n1) / r: n2/n1 makes the
// subset's sum an unbiased estimate of the kept offsets' sum (each is drawn with
// probability n1/n2), and 1/c extends the kept share to the whole pattern, exact where
// the real field's share equals the uniform sample space's (the paper's own assumption:
// "the contribution pattern ... is close to the reference pattern of uniform density").
// Drawn uniformly, though, a forward-scattering pattern is noisy: with the defaults
// (Cornette-Shanks g = 0.85, r = 0.8, radius 6) the order-2 pattern keeps ~45 offsets,
// the heaviest holding 30 % of their weight, and a quarter of them drawn uniformly
// misses it 3 times in 4: 42 % rms per point (30 % for order 3; a 32^3 cloud, the
// defaults, against PatternSelection = 1). So we follow the
// paper's remedy, "to use these voxels with high possibility we can improve the
// accuracy": offset i is drawn with probability proportional to its weight w_i, by
// systematic sampling (n1 equally spaced points u0 + m, m < n1, on the cumulative
// weights scaled to n1, u0 uniform in [0, 1)), and counts (W / n1) / w_i per draw
// (W: the kept offsets' total weight). Unbiased for the kept offsets' sum (offset i is
// drawn n1 w_i / W times on average), exact where the field is the uniform sample
// space's, and the heaviest offsets are evaluated at every point (once, with their
// draws counted): 3.4 % rms per point for order 2, 2.9 % for order 3, at the same cost.
// PatternSelection = 1 evaluates every kept offset once.
//
// The self cell. The lattice sum leaves out the light P's own cell scatters into P,
// which in a uniform medium is the share 1 - exp(-sigma R) of an order (R = 0.62 h, the
// radius of the sphere of a cell's volume): 6 % at sigma h = 0.1, 22 % at 0.4, 39 % at
// 0.8, and cloud cells are often thicker. So every order adds the closed form for that
// sphere, with sigma_t, sigma_s and J_n held at their values at P (not a pattern
// offset: always evaluated, exactly, never scaled):
//   integral_sphere sigma_s J_n(P, s) exp(-sigma r) / r^2 dV  over directions
//     = albedo (1 - exp(-sigma_P R)) J_n(P, s) ds,
//   c_lm += albedo (1 - exp(-sigma_P R)) k_l c^(n)_lm(P)          (n >= 2)
//   c_lm += albedo (1 - exp(-sigma_P R)) k_l^2 Y_lm(-L_sun) E_sun T_sun   (n = 1).
// With it, order 2 in a uniform cube is within 1.5 % of the continuous volume integral
// at sigma h = 0.4 (TestMultipleScatteringPatterns, Order2ApproachesTheContinuousIntegral).
//
// Accuracy against a forward Monte Carlo reference (1e6 photons, a 32^3 sphere of
// cloud, 20 m cells, sigma_t <= 0.05 /m, Cornette-Shanks g = 0.85, albedo 0.99, the
// default pattern options), at a lit point 70 m under the top: order 2 within 8 % in
// c_00 and 1 % in c_10, order 3 35 % high in c_00 (the clamp of the degree-1 field and
// the 1/c extension). Many orders compound such biases: orders 2..64 came out 1.6-1.9
// times the Monte Carlo's at three points. Keep Orders near the paper's 3.
//
// Transmittance T = exp(-tau): trapezoid rule along the segment j -> P with one step
// per grid step along the offset's longest axis (the march of OpticalDepthToward);
// the interior samples lie on grid planes of that axis, so each is a bilinear
// interpolation whose weights depend on the offset only: a precomputed stencil per
// offset. Inside the grid's box this is ExtinctionAt's trilinear interpolation.
//
// Cost: points x n1 x (Orders - 1) x (segment samples ~ PatternRadius, 4 grid reads
// each). Points whose 3x3x3 neighbourhood has no extinction are skipped (J there is
// never used: the mapper's trilinear extinction is 0 around them) and sources with no
// extinction are skipped. Measured (2-core machine, shared): a 32^3 grid holding an
// 11.5k-point cloud, radius 6, Orders 3, the other options default: 0.07 s on 1 thread
// (PatternSelection 1: 0.2 s); a 32^3 grid full of cloud: 0.17 s. Memory per point:
// two fields of 12 floats (one when Orders = 2), 3 floats of sun light and 1 byte.
#include "MultipleScatteringPatterns.h"

#include "ParallelFor.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <utility>
#include <vector>

namespace nimbus
{
namespace
{
constexpr double kY00 = 0.28209479177387814; // Y_00 = 1 / (2 sqrt(pi))
constexpr double kY1 = 0.4886025119029199;   // Y_1m / (w_y, w_z, w_x) = sqrt(3 / (4 pi))

/// One offset o of a reference pattern: the source j = P + o of point P.
struct PatternOffset
{
  std::array<int, 3> Step{ { 0, 0, 0 } };            // o [grid steps]
  std::ptrdiff_t Delta = 0;                          // index(P + o) - index(P)
  Vector3 Propagation{ { 0, 0, 0 } };                // s: unit world direction from j to P
  double Distance = 0.0;                             // r [m]
  double Geometry = 0.0;                             // dV / r^2 [m]
  double SunPhase = 0.0;                             // p(s . -L_sun) [1/sr]
  std::array<double, 4> Harmonics{ { 0, 0, 0, 0 } }; // k_l Y_lm(s), the file's order
  double Weight = 0.0;                               // w(o) / max w(o) in the uniform sample space
  int Intervals = 1;                                 // trapezoid steps along the segment
  std::size_t StencilBegin = 0, StencilEnd = 0;      // range in ReferencePattern's stencil
};

/// A grid read of the transmittance stencil: extinction at P + Delta, times Weight.
struct StencilTap
{
  std::ptrdiff_t Delta;
  double Weight;
};

struct ReferencePattern
{
  std::vector<PatternOffset> Kept; // the n2 kept offsets, largest weight first
  std::vector<StencilTap> Stencil;
  std::vector<double> Cumulative; // sum of the kept weights up to and including each
  double CoveredShare = 1.0;      // c: the kept offsets' share of the pattern's total weight
};

/// SplitMix64's finaliser (Steele et al. 2014).
std::uint64_t Mix(std::uint64_t z)
{
  z += 0x9E3779B97F4A7C15ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

/// Builds the reference pattern (see the file comment). sunPhase: weigh the offsets
/// with the order-1 source's phase p(s . -L_sun) (order 2) or not (orders >= 3).
ReferencePattern BuildReferencePattern(const ExtinctionGrid& grid, const CloudOptics& optics,
  const Vector3& toLight, const MultipleScatteringOptions& options, double sigmaMean, bool sunPhase)
{
  const std::array<int, 3>& n = grid.Dimensions;
  const double dV = grid.Spacing[0] * grid.Spacing[1] * grid.Spacing[2]; // [m^3]
  const double k1 = PhaseLegendreCoefficient(optics, 1);
  std::array<int, 3> half;
  for (int a = 0; a < 3; ++a)
  {
    half[a] = std::max(0, std::min(options.PatternRadius, n[a] - 1));
  }

  std::vector<PatternOffset> all;
  std::vector<double> logWeights;
  for (int dk = -half[2]; dk <= half[2]; ++dk)
  {
    for (int dj = -half[1]; dj <= half[1]; ++dj)
    {
      for (int di = -half[0]; di <= half[0]; ++di)
      {
        if (di == 0 && dj == 0 && dk == 0)
        {
          continue;
        }
        PatternOffset offset;
        offset.Step = { { di, dj, dk } };
        offset.Delta = (static_cast<std::ptrdiff_t>(dk) * n[1] + dj) * n[0] + di;
        // World vector from P to the source j.
        Vector3 toSource{ { 0, 0, 0 } };
        for (int a = 0; a < 3; ++a)
        {
          const double length = offset.Step[a] * grid.Spacing[a];
          for (int c = 0; c < 3; ++c)
          {
            toSource[c] += length * grid.Axes[a][c];
          }
        }
        offset.Distance = Length(toSource);
        offset.Propagation = { { -toSource[0] / offset.Distance, -toSource[1] / offset.Distance,
          -toSource[2] / offset.Distance } };
        offset.Geometry = dV / (offset.Distance * offset.Distance);
        const Vector3& s = offset.Propagation;
        offset.SunPhase =
          EvaluatePhaseFunction(optics.Phase, -Dot(s, toLight), optics.G); // 004 Eq. 5
        offset.Harmonics = { { kY00, k1 * kY1 * s[1], k1 * kY1 * s[2], k1 * kY1 * s[0] } };
        offset.Intervals = std::max({ std::abs(di), std::abs(dj), std::abs(dk) });
        // Logarithms: at sigma_mean r >> 700 the weights underflow but still rank.
        double logWeight = -sigmaMean * offset.Distance + std::log(offset.Geometry);
        if (sunPhase)
        {
          logWeight += std::log(std::max(offset.SunPhase, std::numeric_limits<double>::min()));
        }
        logWeights.push_back(logWeight);
        all.push_back(offset);
      }
    }
  }

  ReferencePattern pattern;
  if (all.empty())
  {
    return pattern;
  }
  const double maxLog = *std::max_element(logWeights.begin(), logWeights.end());
  for (std::size_t o = 0; o < all.size(); ++o)
  {
    all[o].Weight = std::exp(logWeights[o] - maxLog);
  }
  // Largest first; ties by position in the cube, so the order is fixed.
  std::vector<std::size_t> order(all.size());
  std::iota(order.begin(), order.end(), std::size_t{ 0 });
  std::sort(order.begin(), order.end(),
    [&all](std::size_t a, std::size_t b)
    { return all[a].Weight != all[b].Weight ? all[a].Weight > all[b].Weight : a < b; });
  double total = 0.0;
  for (const std::size_t o : order)
  {
    total += all[o].Weight;
  }
  double kept = 0.0;
  for (const std::size_t o : order)
  {
    if (options.PatternContribution < 1.0 && kept >= options.PatternContribution * total)
    {
      break;
    }
    kept += all[o].Weight;
    pattern.Kept.push_back(all[o]);
  }
  pattern.CoveredShare = options.PatternContribution < 1.0 ? kept / total : 1.0;
  double cumulative = 0.0;
  for (const PatternOffset& offset : pattern.Kept)
  {
    cumulative += offset.Weight;
    pattern.Cumulative.push_back(cumulative);
  }

  // Transmittance stencils: the interior trapezoid samples P + (m / M) o, m = 1..M-1,
  // on the planes of the longest axis a; bilinear in the other two axes.
  for (PatternOffset& offset : pattern.Kept)
  {
    offset.StencilBegin = pattern.Stencil.size();
    const int steps = offset.Intervals;
    int major = 0;
    for (int a = 1; a < 3; ++a)
    {
      if (std::abs(offset.Step[a]) > std::abs(offset.Step[major]))
      {
        major = a;
      }
    }
    for (int m = 1; m < steps; ++m)
    {
      std::array<int, 3> base;
      std::array<double, 3> fraction;
      for (int a = 0; a < 3; ++a)
      {
        // Exact in integers: the position along a is m o_a / M.
        const int numerator = m * offset.Step[a];
        const int floor = numerator >= 0 ? numerator / steps : -((-numerator + steps - 1) / steps);
        base[a] = floor;
        fraction[a] = a == major ? 0.0 : static_cast<double>(numerator - floor * steps) / steps;
      }
      for (int corner = 0; corner < 8; ++corner)
      {
        double weight = 1.0;
        std::array<int, 3> at = base;
        for (int a = 0; a < 3; ++a)
        {
          const bool upper = (corner >> a) & 1;
          weight *= upper ? fraction[a] : 1.0 - fraction[a];
          at[a] += upper ? 1 : 0;
        }
        if (weight > 0.0) // corners of weight 0 may lie outside the grid
        {
          pattern.Stencil.push_back(
            { (static_cast<std::ptrdiff_t>(at[2]) * n[1] + at[1]) * n[0] + at[0], weight });
        }
      }
    }
    offset.StencilEnd = pattern.Stencil.size();
  }
  return pattern;
}

/// The order-1 source without its phase: E_sun(z_j) exp(-tau_sun(j)) [irradiance], 3 per
/// point, at the points with extinction (0 elsewhere).
std::vector<float> SunLightAtPoints(
  const ExtinctionGrid& grid, const DirectionalLight& sun, const std::vector<float>& sunDepth)
{
  const std::size_t count = grid.NumberOfPoints();
  const std::array<int, 3>& n = grid.Dimensions;
  const std::vector<float>& sigmaT = grid.Extinction; // [1/m]
  std::vector<float> sunLight(3 * count, 0.0f);
  for (int k = 0; k < n[2]; ++k)
  {
    for (int j = 0; j < n[1]; ++j)
    {
      for (int i = 0; i < n[0]; ++i)
      {
        const std::size_t index = grid.Index(i, j, k);
        if (sigmaT[index] > 0.0f)
        {
          const Rgb irradiance = sun.IrradianceAt(grid.Position(i, j, k)[2]);
          const double transmittance = std::exp(-static_cast<double>(sunDepth[index]));
          for (int c = 0; c < 3; ++c)
          {
            sunLight[3 * index + c] = static_cast<float>(irradiance[c] * transmittance);
          }
        }
      }
    }
  }
  return sunLight;
}

/// The points whose J the mapper can use: some extinction in their 3x3x3 block.
std::vector<unsigned char> NeededPoints(const ExtinctionGrid& grid)
{
  const std::size_t count = grid.NumberOfPoints();
  const std::array<int, 3>& n = grid.Dimensions;
  const std::vector<float>& sigmaT = grid.Extinction; // [1/m]
  std::vector<unsigned char> needed(count, 0);
  for (int k = 0; k < n[2]; ++k)
  {
    for (int j = 0; j < n[1]; ++j)
    {
      for (int i = 0; i < n[0]; ++i)
      {
        if (sigmaT[grid.Index(i, j, k)] > 0.0f)
        {
          for (int dk = std::max(0, k - 1); dk <= std::min(n[2] - 1, k + 1); ++dk)
          {
            for (int dj = std::max(0, j - 1); dj <= std::min(n[1] - 1, j + 1); ++dj)
            {
              for (int di = std::max(0, i - 1); di <= std::min(n[0] - 1, i + 1); ++di)
              {
                needed[grid.Index(di, dj, dk)] = 1;
              }
            }
          }
        }
      }
    }
  }
  return needed;
}

/// 004 §3.4: n1 of the pattern's n2 kept offsets for one point, as (kept offset, its
/// factor W / (n1 w_i)): all of them (factor 1) when n1 = n2, else by systematic sampling
/// proportional to the weights from the point's own random state (seed, order, point).
void DrawOffsets(const ReferencePattern& pattern, std::size_t n1, std::uint64_t seed, int order,
  std::size_t p, std::vector<std::pair<std::uint32_t, double>>& drawn)
{
  const std::size_t n2 = pattern.Kept.size();
  const double keptWeight = n2 > 0 ? pattern.Cumulative.back() : 0.0; // W
  drawn.clear();
  if (n1 == n2)
  {
    for (std::size_t i = 0; i < n2; ++i)
    {
      drawn.emplace_back(static_cast<std::uint32_t>(i), 1.0);
    }
  }
  else // systematic sampling proportional to the weights
  {
    const std::uint64_t state = Mix(Mix(Mix(seed) ^ static_cast<std::uint64_t>(order)) ^ p);
    const double u0 = static_cast<double>(state >> 11) * 0x1.0p-53; // [0, 1)
    std::size_t i = 0;
    for (std::size_t m = 0; m < n1; ++m)
    {
      const double target = (u0 + static_cast<double>(m)) * keptWeight / n1;
      while (i + 1 < n2 && pattern.Cumulative[i] <= target)
      {
        ++i;
      }
      const double factor = keptWeight / (n1 * pattern.Kept[i].Weight);
      if (!drawn.empty() && drawn.back().first == i)
      {
        drawn.back().second += factor;
      }
      else
      {
        drawn.emplace_back(static_cast<std::uint32_t>(i), factor);
      }
    }
  }
}
} // namespace

void AddReferencePatternOrders(const ExtinctionGrid& grid, const CloudOptics& optics,
  const DirectionalLight& sun, const MultipleScatteringOptions& options,
  const std::vector<float>& sunDepth, std::vector<float>& coefficients,
  const std::function<void(double fraction)>& progress)
{
  const std::size_t count = grid.NumberOfPoints();
  if (grid.Extinction.size() != count || sunDepth.size() != count ||
    coefficients.size() != 12 * count)
  {
    throw std::invalid_argument(
      "AddReferencePatternOrders: extinction, sun depth or coefficients of the wrong size");
  }
  const std::array<int, 3>& n = grid.Dimensions;
  const std::vector<float>& sigmaT = grid.Extinction; // [1/m]
  double sigmaSum = 0.0;
  std::size_t cloudPoints = 0;
  for (const float sigma : sigmaT)
  {
    if (sigma > 0.0f)
    {
      sigmaSum += sigma;
      ++cloudPoints;
    }
  }
  if (options.Orders < 2 || cloudPoints == 0 || !(optics.Albedo > 0.0))
  {
    return;
  }
  const double sigmaMean = sigmaSum / static_cast<double>(cloudPoints); // [1/m]
  const Vector3 toLight = Normalized(sun.ToLight);

  // The order-1 source without its phase (the calling thread: sun.Irradiance need not
  // be thread-safe).
  const std::vector<float> sunLight = SunLightAtPoints(grid, sun, sunDepth);

  const std::vector<unsigned char> needed = NeededPoints(grid);

  const ReferencePattern sunPattern =
    BuildReferencePattern(grid, optics, toLight, options, sigmaMean, true);
  const ReferencePattern fieldPattern = options.Orders >= 3
    ? BuildReferencePattern(grid, optics, toLight, options, sigmaMean, false)
    : ReferencePattern();

  // The self cell: the radius [m] of the sphere of a cell's volume, and the SH of the
  // sun light's direction of travel -L_sun.
  const double selfRadius =
    std::cbrt(3.0 * grid.Spacing[0] * grid.Spacing[1] * grid.Spacing[2] / (4.0 * kPi));
  const double k1 = PhaseLegendreCoefficient(optics, 1);
  const std::array<double, 4> sunHarmonics{ { kY00, -kY1 * toLight[1], -kY1 * toLight[2],
    -kY1 * toLight[0] } };

  std::vector<float> previous; // J_n, 12 floats per point (n >= 2)
  std::vector<float> current(12 * count, 0.0f);
  const int orders = options.Orders - 1; // orders 2..Orders
  const std::size_t grain = std::max<std::size_t>(1, std::min<std::size_t>(4096, count / 64));
  for (int order = 2; order <= options.Orders; ++order)
  {
    const ReferencePattern& pattern = order == 2 ? sunPattern : fieldPattern;
    const std::size_t n2 = pattern.Kept.size();
    const std::size_t n1 = std::min(n2,
      std::max<std::size_t>(1,
        static_cast<std::size_t>(
          std::ceil(options.PatternSelection * static_cast<double>(n2) - 1e-9))));
    // 004 §3.4: the estimate of the kept offsets' sum / r, see the file comment.
    const double scale = n2 > 0 ? 1.0 / pattern.CoveredShare : 0.0;
    const bool fromSun = order == 2;

    const auto body = [&](std::size_t begin, std::size_t end)
    {
      std::vector<std::pair<std::uint32_t, double>> drawn; // (kept offset, its factor)
      drawn.reserve(n1);
      for (std::size_t p = begin; p < end; ++p)
      {
        float* out = current.data() + 12 * p;
        std::fill(out, out + 12, 0.0f);
        if (!needed[p])
        {
          continue;
        }
        const int pi = static_cast<int>(p % n[0]);
        const int pj = static_cast<int>((p / n[0]) % n[1]);
        const int pk = static_cast<int>(p / (static_cast<std::size_t>(n[0]) * n[1]));
        DrawOffsets(pattern, n1, options.Seed, order, p, drawn);
        const double sigmaP = sigmaT[p];
        double c[3][4] = { { 0, 0, 0, 0 }, { 0, 0, 0, 0 }, { 0, 0, 0, 0 } };
        for (const std::pair<std::uint32_t, double>& draw : drawn)
        {
          const PatternOffset& offset = pattern.Kept[draw.first];
          const int si = pi + offset.Step[0], sj = pj + offset.Step[1], sk = pk + offset.Step[2];
          if (si < 0 || si >= n[0] || sj < 0 || sj >= n[1] || sk < 0 || sk >= n[2])
          {
            continue;
          }
          const std::size_t source = p + offset.Delta;
          const double sigmaSource = sigmaT[source];
          if (!(sigmaSource > 0.0))
          {
            continue;
          }
          // tau(j -> P): trapezoid rule, one grid step along the longest axis [1].
          double sum = 0.5 * (sigmaP + sigmaSource);
          for (std::size_t t = offset.StencilBegin; t < offset.StencilEnd; ++t)
          {
            sum += pattern.Stencil[t].Weight * sigmaT[p + pattern.Stencil[t].Delta];
          }
          const double tau = sum * offset.Distance / offset.Intervals;
          // sigma_s T dV / r^2 [1/m]: times J [radiance] the irradiance E_j at P.
          const double transport =
            draw.second * optics.Albedo * sigmaSource * std::exp(-tau) * offset.Geometry;
          Rgb J;
          if (fromSun)
          {
            for (int ch = 0; ch < 3; ++ch)
            {
              J[ch] = offset.SunPhase * sunLight[3 * source + ch];
            }
          }
          else
          {
            J = EvaluateInScattering(previous.data() + 12 * source, offset.Propagation);
          }
          for (int ch = 0; ch < 3; ++ch)
          {
            const double irradiance = transport * J[ch];
            for (int lm = 0; lm < 4; ++lm)
            {
              c[ch][lm] += irradiance * offset.Harmonics[lm];
            }
          }
        }
        // The self cell, a sphere of the cell's volume around P (see the file comment):
        // sigma_s integral_0^R exp(-sigma r) dr = albedo (1 - exp(-sigma_P R)) [1] times
        // the order-n light at P projected through the phase function.
        double self[3][4] = { { 0, 0, 0, 0 }, { 0, 0, 0, 0 }, { 0, 0, 0, 0 } };
        if (sigmaP > 0.0)
        {
          const double share = -optics.Albedo * std::expm1(-sigmaP * selfRadius);
          for (int ch = 0; ch < 3; ++ch)
          {
            for (int lm = 0; lm < 4; ++lm)
            {
              const double kl = lm == 0 ? 1.0 : k1;
              // J_1(P, s) = p(s . -L) E T projects to k_l Y_lm(-L) E T (Funk-Hecke).
              self[ch][lm] = fromSun ? share * kl * kl * sunHarmonics[lm] * sunLight[3 * p + ch]
                                     : share * kl * previous[12 * p + 4 * ch + lm];
            }
          }
        }
        float* total = coefficients.data() + 12 * p;
        for (int ch = 0; ch < 3; ++ch)
        {
          for (int lm = 0; lm < 4; ++lm)
          {
            out[4 * ch + lm] = static_cast<float>(scale * c[ch][lm] + self[ch][lm]);
            total[4 * ch + lm] += out[4 * ch + lm];
          }
        }
      }
    };
    const int done = order - 2;
    const auto itemsDone = [&](std::size_t items)
    {
      if (progress)
      {
        progress((done * static_cast<double>(count) + static_cast<double>(items)) /
          (orders * static_cast<double>(count)));
      }
    };
    ParallelFor(count, grain, options.Threads, body, itemsDone);
    if (order < options.Orders)
    {
      previous.swap(current);
      current.resize(12 * count);
    }
  }
}
} // namespace nimbus
