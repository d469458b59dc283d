// Sun shadows across the pieces of a distributed cloud (under MPI).
//
// Under MPI each rank renders only its piece of the density (a box), but the sun
// reaches that piece through the other ranks' pieces. Every rank holds a coarse copy
// of the whole density (CoarseDensityGrid, all-gathered once per time step by the
// ParaView representation), and from it this file computes, on a 2-D map facing the
// sun, the optical depth of the density OUTSIDE the piece along each sun line:
//
//   Beyond(line) = integral of sigma ds from where the line leaves the piece toward
//                  the sun to where it leaves the whole grid   (0 if it misses the piece)
//   Whole(line)  = integral of sigma ds over the whole line, the piece excluded
//
// sigma = ExtinctionPerDensity * density [1/m], ds in metres (MetresPerUnit per world
// unit): the same optical depth as the shadow surface of 000 Eq. 10. A point inside
// the piece sees the sun through ShadowSurface(p) + Beyond; a point of the air or the
// ground outside the piece through (its line meets the piece ? ShadowSurface : 0) + Whole.
// Plain C++ (no GL); the mapper uploads the map as a 2-channel float texture.
#ifndef nimbus_ExternalShadow_h
#define nimbus_ExternalShadow_h

#include "NimbusRepresentationsModule.h" // for export macro
#include "SliceGeometry.h"               // for Vector3, ShadowFrame

#include <array>
#include <vector>

namespace nimbus
{

/// A coarse density on a regular lattice of points in world coordinates: value
/// (i, j, k) at Origin + (i, j, k) * Spacing, i fastest; trilinear between points,
/// zero outside the lattice's box; NaN, infinite and negative values count as 0 (as
/// the GPU's density texture has them).
struct NIMBUSREPRESENTATIONS_EXPORT CoarseDensityGrid
{
  std::array<double, 3> Origin{ { 0.0, 0.0, 0.0 } };
  std::array<double, 3> Spacing{ { 1.0, 1.0, 1.0 } };
  std::array<int, 3> Dimensions{ { 0, 0, 0 } };
  std::vector<float> Values;

  bool IsValid() const;
  double Sample(const Vector3& p) const;
};

/// The map: Frame (as the shadow surface's: texel (s, t) of Size x Size is the sun
/// line through Origin + (s + 0.5) / Size * Width * U + (t + 0.5) / Size * Height * W),
/// and two floats per texel, (Beyond, Whole), row by row.
struct NIMBUSREPRESENTATIONS_EXPORT ExternalShadowMap
{
  ShadowFrame Frame;
  int Size = 0;
  std::vector<float> Depths;
};

/// The map of `grid` outside the box `pieceBounds` (xmin, xmax, ymin, ymax, zmin, zmax,
/// world) for the sun direction `toSun` (unit, toward the sun), over the whole grid's
/// footprint, sampled every half coarse spacing (midpoint rule). Threads as ParallelFor.
NIMBUSREPRESENTATIONS_EXPORT ExternalShadowMap ComputeExternalShadowMap(
  const CoarseDensityGrid& grid, const std::array<double, 6>& pieceBounds, const Vector3& toSun,
  double extinctionPerDensity, double metresPerUnit, int size, int threads = 0);

} // namespace nimbus

#endif
