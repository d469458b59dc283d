// nimbus::SunDepthVolume — the cloud's optical depth toward the sun at every texel of
// the density texture, for the ray-marched Cloud method of vtkNimbusCloudVolumeMapper
// (docs/ray-march.md): the view ray's samples read the sun's transmittance
// exp(-tau) from a 3-D texture instead of from SVS's shadow surface (000 Eq. 7).
//
// tau(x) = integral from x along the unit direction toward the sun L to where the line
// leaves the density box of k rho(x + s L) ds [dimensionless], with k the extinction
// per unit density [1/m] and s in metres.
//
// Computed by one sweep through the texels, slice by slice along the axis the sun's
// direction is closest to (in texel units), starting on the sun's side: a texel's line
// toward the sun crosses the neighbouring slice at a point y, so
//   tau(x) = tau(y) + (k rho(x) + k rho(y)) / 2 * |x - y|   (trapezoid rule),
// with tau(y) and rho(y) interpolated bilinearly in that slice, and, where the line
// leaves the box before the next slice, tau(x) = k rho(x) * (distance to the box's
// face). Cost: one bilinear look-up per texel (O(N), not O(N^(4/3)) of a march from
// every texel). The bilinear interpolation repeated slice after slice blurs a shadow
// edge by about the square root of the number of slices crossed, in texels
// (measured in TestSunDepthVolume and docs/ray-march.md).
//
// What is interpolated: by default the transmittance T = exp(-tau) (T(x) = T(y)
// exp(-segment)), so a line between a lit and a shadowed neighbour gets their mean
// light, as a texel-wide beam would, and a narrow gap between clouds stays lit; tau
// interpolated instead averages the depths, which darkens every penumbra and gap
// (measured against the path tracer: docs/ray-march.md).
#ifndef nimbus_SunDepthVolume_h
#define nimbus_SunDepthVolume_h

#include "NimbusRepresentationsModule.h"

#include "Math.h" // for Vector3

#include <array>
#include <vector>

namespace nimbus
{
/// The density texture's grid: texel (i, j, k) has index coordinates (i, j, k);
/// world points map to index coordinates by Linear * x + Offset (Linear row-major).
struct SunDepthGrid
{
  std::array<int, 3> Dimensions{ { 0, 0, 0 } };
  std::array<double, 9> Linear{ { 1, 0, 0, 0, 1, 0, 0, 0, 1 } };
  /// The density box in index coordinates: [0, n - 1] for point data, [-1/2, n - 1/2]
  /// for cell data (CloudDensityTexture's box).
  std::array<double, 3> BoxLow{ { 0, 0, 0 } };
  std::array<double, 3> BoxHigh{ { 0, 0, 0 } };
};

/// What the sweep interpolates between texels (see above).
enum class SunDepthInterpolation
{
  Transmittance,
  OpticalDepth
};

/// tau at every texel (x fastest, as `density`), for the unit direction `toSun` in
/// world coordinates, extinction k = extinctionPerDensity [1/m per density unit] and
/// metresPerUnit metres per world unit. Negative and non-finite densities count as 0;
/// tau is capped at 1e30. `threads`: as nimbus::ParallelFor (0: all cores).
NIMBUSREPRESENTATIONS_EXPORT std::vector<float> ComputeSunDepthVolume(const float* density,
  const SunDepthGrid& grid, const Vector3& toSun, double extinctionPerDensity, double metresPerUnit,
  int threads = 0, SunDepthInterpolation interpolation = SunDepthInterpolation::Transmittance);

/// The block maxima of `density` for empty-space skipping: block (I, J, K) holds the
/// largest density of the texels a trilinear look-up inside that block of
/// `blockSize`^3 texels can reach (the block grown by one texel on each side), so a
/// zero block is empty for every sample inside it. Dimensions of the result:
/// ceil(n / blockSize) per axis, written to `blocks`.
NIMBUSREPRESENTATIONS_EXPORT std::vector<float> ComputeBlockMaxima(const float* density,
  const std::array<int, 3>& dimensions, int blockSize, std::array<int, 3>& blocks);
}

#endif
