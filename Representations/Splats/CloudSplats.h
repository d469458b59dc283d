// nimbus CloudSplats — the plain-C++ numerics of billboard splatting of metaball clouds
// (002 §3.3; vtkNimbusCloudSplatMapper draws with them, docs/splats.md).
//
// A metaball of centre c, radius R (m) and centre density d has the density
// d f(|x - c|^2 / R^2) with the degree-6 kernel of Nimbus's metaball cloud
// (Wyvill et al.; 004 §4, Filters/Core/Metaballs.h):
//   f(q) = 1 - 22/9 q + 17/9 q^2 - 4/9 q^3 for q < 1, 0 beyond.
// A straight line at impact parameter u R from the centre crosses it for
// t in [-s, s] (t in units of R along the line, s = sqrt(1 - u^2)). The "cumulative
// density" of 002 §3.3 is the density integrated along the line, in units of d R:
//   P(u, h) = integral from -s to h of f(u^2 + t^2) dt   (the part in front of the plane
//             at signed distance h R from the centre, h clamped to [-s, s]),
//   C(u)    = P(u, 1) = 2 F(s)                              (the whole column),
// in closed form from the antiderivative F(t) = c0 t + c2 t^3 / 3 + c4 t^5 / 5 + c6 t^7 / 7
// (f expanded in powers of t with a = u^2). The optical depth of the column is
// k d R C(u) (k: extinction per density, 1/m), its attenuation ratio exp(-k d R C(u)).
//
// The textures: the billboard texture (the whole column C over the billboard's square,
// each texel the mean over its area) and the partial-column table P(u, h) that the
// sun pass's accumulation texture integrates layer by layer. Sorting: the order of the
// billboards along a direction (toward the sun: nearest first; from the eye: farthest
// first).
#ifndef nimbus_CloudSplats_h
#define nimbus_CloudSplats_h

#include "NimbusRepresentationsModule.h"

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace nimbus
{
/// The metaball kernel f(q), q = r^2 / R^2 (the same polynomial as
/// nimbus::WyvillFalloff in Filters/Core/Metaballs.h; 004 §4).
NIMBUSREPRESENTATIONS_EXPORT double SplatKernel(double q);

/// P(u, h): the kernel integrated along the line at impact parameter u (units of R) from
/// where it enters the ball to the plane at signed distance h (units of R) from the
/// centre, in units of R. 0 for u >= 1; h clamped to [-s, s].
NIMBUSREPRESENTATIONS_EXPORT double SplatPartialColumn(double u, double h);

/// C(u) = P(u, 1): the whole column at impact parameter u (units of R). C(0) = 944/945.
NIMBUSREPRESENTATIONS_EXPORT double SplatColumn(double u);

/// The billboard texture: size x size texels over the billboard's square [-1, 1]^2 (units
/// of R), each the mean of C over its area (supersample^2 points), row-major, x fastest.
NIMBUSREPRESENTATIONS_EXPORT std::vector<float> SplatColumnTexture(int size, int supersample);

/// The partial-column table: uSize x hSize values of P(u_i, h_j) at u_i = i / (uSize - 1)
/// in [0, 1] and h_j = -1 + 2 j / (hSize - 1) in [-1, 1], u fastest. Sizes >= 2.
NIMBUSREPRESENTATIONS_EXPORT std::vector<float> SplatPartialColumnTable(int uSize, int hSize);

/// The indices 0..n-1 ordered by the key dot(centre_i, direction) + offset_i (offsets may be
/// empty: 0), ascending, ties by index (a stable order: the same picture every frame).
/// centres: 3 n values (x, y, z).
NIMBUSREPRESENTATIONS_EXPORT std::vector<std::uint32_t> SplatOrder(
  const std::vector<float>& centres, const std::array<double, 3>& direction,
  const std::vector<float>& offsets);

/// The billboards' order for a perspective eye: by distance from the eye, farthest first
/// (back to front).
NIMBUSREPRESENTATIONS_EXPORT std::vector<std::uint32_t> SplatOrderBackToFront(
  const std::vector<float>& centres, const std::array<double, 3>& eye);

/// An orthonormal frame whose third axis is `axis` (unit): the sun's view of the billboards.
NIMBUSREPRESENTATIONS_EXPORT std::array<std::array<double, 3>, 3> SplatFrame(
  const std::array<double, 3>& axis);

/// The sun pass's accumulation layers: planes at depths z_k = zMin + k (zMax - zMin) /
/// (layers - 1), k = 0 .. layers - 1, along the sun's light (depth = -dot(x, toSun)). Layer
/// k adds the balls' columns in the slab (z_{k-1}, z_k] to the running sum of the layers
/// before it. With the billboards sorted by their front depth (depth - R) ascending, the
/// balls that may cross slab k are the range [first_k, end_k): those whose front lies
/// before z_k and, as no ball is deeper than maxDiameter, whose front lies after
/// z_{k-1} - maxDiameter (the shader skips the few in the range that end before the slab).
/// Returns (first_k, end_k) per layer; layer 0's range is empty.
NIMBUSREPRESENTATIONS_EXPORT std::vector<std::array<std::size_t, 2>> SplatLayerRanges(
  const std::vector<float>& sortedFronts, double zMin, double zMax, int layers, double maxDiameter);
/// The mass of a ball of centre density 1 and radius 1: the kernel integrated over the
/// unit ball, 4 pi (1/3 - 22/45 + 17/63 - 4/81) = 0.81559 (a ball's mass is d R^3 times
/// this).
NIMBUSREPRESENTATIONS_EXPORT double SplatBallVolume();

/// The balls' density on a regular grid (for the multiple-scattering solve,
/// Physics/MultipleScattering.h): points Origin + (i, j, k) Spacing, x fastest, over the
/// balls' bounds (centre +- R) padded by one spacing on every side, `longestSide` points
/// (>= 4) on the longest axis, the same spacing on every axis.
struct NIMBUSREPRESENTATIONS_EXPORT SplatDensityGrid
{
  std::array<int, 3> Dimensions{ { 0, 0, 0 } };
  std::array<double, 3> Origin{ { 0, 0, 0 } }; // world units
  double Spacing = 1.0;                        // world units
  std::vector<float> Density;                  // dimensionless (as the balls' d)
};

/// Splats the balls (centres: 3 per ball; radii in world units; centre densities) onto a
/// SplatDensityGrid. A ball at least one spacing in radius adds d f(|x - c|^2 / R^2) at
/// the grid points inside it, scaled so that its points' sum times Spacing^3 is its mass
/// d R^3 SplatBallVolume() (the point samples alone miss the mass by the kernel's
/// discretisation error: TestCloudSplats measures it); a smaller ball (or one that hits
/// no point) puts its mass on the 8 points around its centre, trilinearly (cloud in
/// cell). The grid's total mass is the balls' to float rounding. Empty input: an empty grid.
NIMBUSREPRESENTATIONS_EXPORT SplatDensityGrid SplatBallsOntoGrid(const std::vector<float>& centres,
  const std::vector<float>& radii, const std::vector<float>& densities, int longestSide);
} // namespace nimbus

#endif
