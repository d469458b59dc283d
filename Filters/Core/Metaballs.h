// Metaball clouds (004 §4): the degree-6 density field of Wyvill et al. and the
// fractal growth step that seeds smaller balls on an isosurface.
//
// Plain C++ (no VTK): the VTK source vtkNimbusMetaballCloudSource extracts the
// isosurface with VTK's contouring and calls these functions for the numerics.
//
// Units: positions and radii in metres; density is dimensionless (the renderer
// multiplies it by an extinction coefficient in 1/m).
#ifndef NimbusMetaballs_h
#define NimbusMetaballs_h

#include "NimbusFiltersModule.h"

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

namespace nimbus
{
class Random;

struct Metaball
{
  std::array<double, 3> Center{ { 0.0, 0.0, 0.0 } }; // m
  double Radius = 1.0;                               // m, the field is 0 beyond it
  double Density = 1.0;                              // density at the centre
  int Level = 0;                                     // 0: basic shape, k: k-th growth level
};

/// Wyvill, McPheeters & Wyvill's "soft object" falloff, a degree-6 polynomial of
/// the distance r from the centre (004 §4, after its ref. [21]):
///   f(r) = 1 - 4/9 q^3 + 17/9 q^2 - 22/9 q,  q = (r/R)^2,  for r < R;  0 otherwise.
/// f(0) = 1, f(R/2) = 1/2, f(R) = 0, f'(0) = f'(R) = 0, 0 <= f <= 1.
/// Takes squared distances so that callers need no square root.
NIMBUSFILTERS_EXPORT double WyvillFalloff(double distanceSquared, double radiusSquared);

/// Density of a set of metaballs at a point: sum of Density_i * f(|p - c_i|).
NIMBUSFILTERS_EXPORT double MetaballDensity(
  const std::vector<Metaball>& balls, const std::array<double, 3>& point);

/// Gradient of MetaballDensity at a point (1/m); the outward surface normal is
/// its negative, normalised.
NIMBUSFILTERS_EXPORT std::array<double, 3> MetaballDensityGradient(
  const std::vector<Metaball>& balls, const std::array<double, 3>& point);

/// A regular grid: point (i, j, k) is at Origin + (i, j, k) * Spacing; x varies fastest.
struct GridGeometry
{
  std::array<int, 3> Dimensions{ { 1, 1, 1 } };
  std::array<double, 3> Origin{ { 0.0, 0.0, 0.0 } };  // m
  std::array<double, 3> Spacing{ { 1.0, 1.0, 1.0 } }; // m
  std::size_t NumberOfPoints() const
  {
    return static_cast<std::size_t>(this->Dimensions[0]) * this->Dimensions[1] *
      this->Dimensions[2];
  }
};

/// Called now and then by long loops with the fraction of the work done (0..1); returning
/// false stops the loop early (the caller then discards the partial result).
using ProgressCallback = std::function<bool(double)>;

/// Samples the metaball field on the grid: density[idx] = sum over balls. Each
/// ball only visits the grid points inside its bounding box, so the cost is
/// sum_i (2 R_i / spacing)^3, not (points x balls). A ball's box is clipped to the grid in
/// floating point before any conversion to an index, so any finite or infinite centre,
/// radius and spacing is safe (a ball that reaches no grid point adds nothing).
/// `progress` (optional) is called about every 4 million grid-point updates; when it
/// returns false sampling stops and the function returns false (density incomplete).
NIMBUSFILTERS_EXPORT bool SampleMetaballs(const std::vector<Metaball>& balls,
  const GridGeometry& grid, std::vector<float>& density,
  const ProgressCallback& progress = nullptr);

/// An index box of a grid: (i0, i1, j0, j1, k0, k1), inclusive (VTK's extent order).
using GridExtent = std::array<int, 6>;

/// The whole grid's extent: (0, nx - 1, 0, ny - 1, 0, nz - 1).
NIMBUSFILTERS_EXPORT GridExtent WholeExtent(const GridGeometry& grid);

/// SampleMetaballs over the points of `extent` only (a piece of the grid, within it):
/// density holds the extent's points, x fastest. Every point gets the same terms, added in
/// the same ball order, as in the whole grid's sampling, so a piece equals the whole's crop
/// bit for bit. Throws std::invalid_argument for an extent outside the grid.
NIMBUSFILTERS_EXPORT bool SampleMetaballs(const std::vector<Metaball>& balls,
  const GridGeometry& grid, const GridExtent& extent, std::vector<float>& density,
  const ProgressCallback& progress = nullptr);

/// Number of grid points a ball of this radius visits in SampleMetaballs at most (its
/// bounding box clipped to the grid), as a double so that nothing overflows. For work
/// estimates.
NIMBUSFILTERS_EXPORT double MetaballBoxPoints(double radius, const GridGeometry& grid);

/// Flat cloud base: multiplies the density by a smoothstep that is 0 at and below
/// baseHeight (z, m) and 1 from baseHeight + transitionThickness up. Below the
/// base the air is not saturated (lifting condensation level), so no cloud.
NIMBUSFILTERS_EXPORT void ApplyCloudBase(const GridGeometry& grid, double baseHeight,
  double transitionThickness, std::vector<float>& density);

/// ApplyCloudBase on the points of `extent` (density holds them, x fastest).
NIMBUSFILTERS_EXPORT void ApplyCloudBase(const GridGeometry& grid, const GridExtent& extent,
  double baseHeight, double transitionThickness, std::vector<float>& density);

/// Parameters of the random basic shape (the first, largest balls).
struct BasicShapeParameters
{
  int NumberOfBalls = 10;
  double RadiusMin = 350.0;                          // m
  double RadiusMax = 600.0;                          // m
  double Density = 1.0;                              // at each centre
  std::array<double, 3> Center{ { 0.0, 0.0, 0.0 } }; // horizontal centre (x, y) used
  double FootprintRadius = 700.0;                    // m, centres lie within this disc
  double BaseHeight = 0.0;                           // m, cloud base (z)
  double TowerHeight = 600.0;                        // m, centres rise up to this above the base
};

/// Places the basic shape: centres uniformly in a disc of FootprintRadius around
/// Center, at heights base + R/2 + U(0, 1) * TowerHeight, so every ball's lower
/// half-density level sits at or above the base.
NIMBUSFILTERS_EXPORT std::vector<Metaball> MakeBasicShape(
  const BasicShapeParameters& parameters, Random& random);

/// Parameters of one fractal growth level.
struct GrowthParameters
{
  int NumberOfBalls = 60;
  double RadiusMin = 150.0; // m
  double RadiusMax = 300.0; // m
  double Density = 1.0;
  int Level = 1;
  /// Triangles whose outward normal has a z component below this do not grow
  /// balls (004 §4: "if the normal vector is not downward new balls are created").
  /// -0.3 means: grow unless the surface faces down by more than ~17 degrees.
  double MinimumNormalZ = -0.3;
};

/// One fractal growth step (004 §4): given the isosurface of the current field as
/// triangles (points xyz, 3 point ids per triangle), picks NumberOfBalls triangles
/// with probability proportional to area among those not facing down, places a
/// ball at a uniformly random point of each, radius uniform in [RadiusMin, RadiusMax].
/// Outward normals come from the analytic field gradient, not the triangle winding.
/// Returns the new balls (none if no triangle qualifies). The cost is about
/// triangles x balls (the gradient at each triangle). `progress` (optional) is called about
/// every 4 million ball evaluations; when it returns false the function stops and
/// returns no balls.
NIMBUSFILTERS_EXPORT std::vector<Metaball> GrowOnSurface(const std::vector<Metaball>& balls,
  const std::vector<double>& points, const std::vector<std::int64_t>& triangles,
  const GrowthParameters& parameters, Random& random, const ProgressCallback& progress = nullptr);

} // namespace nimbus

#endif
