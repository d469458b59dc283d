// Geometry of shadow-view slices (000 §4.2, Fig. 4): the slice normal between the
// view and sun directions, the traversal order, the slice planes over a box, and
// the orthographic frame of the shadow surface that faces the sun.
//
// Conventions (world frame, any length unit):
//  - toSun  L: unit vector from the scene toward the sun; sunlight travels along -L.
//  - view   V: unit viewing direction of the camera (from the eye into the scene).
//  - A slice is the plane {x : dot(x, n) = d}. Slices are processed in order of
//    increasing d, and n always points away from the sun (dot(n, -L) > 0), so the
//    sun attenuation accumulates "in an ascendant order, depending on the distance
//    from the sun" (000 §4.2) whatever the view.
//  - Front-to-back traversal when moving away from the sun also moves away from the
//    eye (the sun is behind the camera: dot(V, L) < 0); back-to-front when the
//    camera looks toward the sun (dot(V, L) >= 0). 000 Fig. 4 writes this as
//    Ve.Vs >= 0 -> back-to-front with Vs the direction toward the sun.
//  - The normal makes angles theta_e with +-V (the sign that lies on the sun's
//    far side) and theta_s with -L in the ratio theta_e : theta_s = 1 : a
//    (000 §4.2), i.e. it is the slerp from +-V toward -L by 1/(1+a) of the angle.
#ifndef nimbus_SliceGeometry_h
#define nimbus_SliceGeometry_h

#include "Math.h"
#include "NimbusRepresentationsModule.h"

#include <array>
#include <vector>

namespace nimbus
{
struct NIMBUSREPRESENTATIONS_EXPORT SliceAxis
{
  Vector3 Normal{ { 0.0, 0.0, 1.0 } }; // n, unit, dot(n, -L) > 0
  bool BackToFront = false;            // traversal order on the screen (000 §4.3)
  double ThetaView = 0.0;              // angle between n and +-V [rad]
  double ThetaSun = 0.0;               // angle between n and -L  [rad]
  double SunCosine = 1.0;              // dot(n, -L) > 0: Delta s = Delta d / SunCosine
};

/// Slice normal for view V, sun L (need not be unit; throws std::invalid_argument
/// when zero or non-finite) and ratio a = theta_s / theta_e (clamped to [0.01, 100];
/// the paper uses 1..2). Degenerate cases: V parallel or anti-parallel to L give
/// n = -L exactly.
NIMBUSREPRESENTATIONS_EXPORT SliceAxis ComputeSliceAxis(
  const Vector3& view, const Vector3& toSun, double a);

/// Range [dMin, dMax] of dot(x, n) over the 8 corners of an axis-aligned or
/// transformed box (corners given explicitly).
NIMBUSREPRESENTATIONS_EXPORT std::array<double, 2> ProjectedRange(
  const std::vector<Vector3>& corners, const Vector3& n);

/// Slice plane offsets: `count` planes at the centres of equal slabs covering
/// [dMin, dMax]; spacing = (dMax - dMin)/count. count >= 1.
struct NIMBUSREPRESENTATIONS_EXPORT SlicePlanes
{
  std::vector<double> Offsets; // increasing d
  double Spacing = 0.0;        // Delta d
};
NIMBUSREPRESENTATIONS_EXPORT SlicePlanes MakeSlicePlanes(double dMin, double dMax, int count);

/// Vertices of the polygon where the plane dot(x, n) = d cuts the box whose 8
/// corners are given in the order corner c = (c & 1 ? x1 : x0, c & 2 ? y1 : y0,
/// c & 4 ? z1 : z0) (any affine image of such a box). Empty when the plane misses
/// the box. Used to scissor each slice's passes to the pixels it can touch.
NIMBUSREPRESENTATIONS_EXPORT std::vector<Vector3> SlicePolygon(
  const std::vector<Vector3>& corners, const Vector3& n, double d);

/// Vertices of the box's part between the planes dot(x, n) = d - halfWidth and
/// d + halfWidth: both planes' polygons and the corners between them. Their convex
/// hull holds every polygon of a plane in that range (a jittered slice's, see
/// vtkNimbusCloudVolumeMapper::SetSliceJitter). Empty when the slab misses the box.
NIMBUSREPRESENTATIONS_EXPORT std::vector<Vector3> SlabPoints(
  const std::vector<Vector3>& corners, const Vector3& n, double d, double halfWidth);

/// Orthographic frame of the shadow surface: it faces the sun (normal -L) and
/// covers the projection of the box corners. A point x maps to texture
/// coordinates ((dot(x - Origin, U)) / Width, (dot(x - Origin, W)) / Height).
struct NIMBUSREPRESENTATIONS_EXPORT ShadowFrame
{
  Vector3 Origin{ { 0.0, 0.0, 0.0 } };
  Vector3 U{ { 1.0, 0.0, 0.0 } };
  Vector3 W{ { 0.0, 1.0, 0.0 } };
  double Width = 1.0;
  double Height = 1.0;
};
/// `margin` is a fraction of the extent added on every side (texels at the rim
/// then stay unshadowed, so clamp-to-edge lookups outside are exact).
NIMBUSREPRESENTATIONS_EXPORT ShadowFrame ComputeShadowFrame(
  const std::vector<Vector3>& corners, const Vector3& toSun, double margin);

/// Scissor rectangles: a slice's passes only touch the pixels (and shadow texels)
/// onto which its polygon (SlicePolygon) projects; outside it the density is zero.
/// Pixels (x, y, width, height) of a width x height viewport covering the
/// projection of `polygon` by `worldToNdc` (row-major 4 x 4, vtkMatrix4x4's element
/// order), with a pixel of margin, clamped to the viewport; false when a vertex is
/// behind the eye (no finite rectangle).
NIMBUSREPRESENTATIONS_EXPORT bool ScreenRectangle(const std::vector<Vector3>& polygon,
  const double worldToNdc[16], int width, int height, int rect[4]);
/// Texels (x, y, width, height) of the size x size shadow surface covering the
/// projection of `polygon` along the sun onto `frame`, with a texel of margin, clamped.
NIMBUSREPRESENTATIONS_EXPORT void ShadowRectangle(
  const std::vector<Vector3>& polygon, const ShadowFrame& frame, int size, int rect[4]);
} // namespace nimbus

#endif
