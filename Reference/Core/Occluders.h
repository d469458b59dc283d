// Opaque surfaces for the reference renderers (scene format version 4, `occluders`):
// axis-aligned boxes and triangles, grey Lambertian, two-sided, in one bounding volume
// hierarchy. Plain C++ (no VTK): the path tracer asks for the nearest surface along a ray
// (Intersect) and whether anything blocks a shadow ray (Occluded).
//
// The hierarchy: axis-aligned bounds per node, built by median splits of the primitives'
// centroids along the longest axis of their bounds, at most kLeafPrimitives primitives per
// leaf; traversed front to back with a stack. A box is a closed surface of six faces (a ray
// starting inside one hits its far face); a box with Min == Max on one axis is a flat
// rectangle. Triangles are intersected by the Moller-Trumbore test in double precision.
// Rays count hits at 0 < t < tMax: a ray leaving a surface must start off it (the path
// tracer offsets the point along the normal, OffsetFromSurface).
#ifndef NimbusOccluders_h
#define NimbusOccluders_h

#include "Math.h"
#include "NimbusReferenceModule.h"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace nimbus
{

/// The nearest surface along a ray.
struct NIMBUSREFERENCE_EXPORT OccluderHit
{
  double T = 0.0;                      // distance along the (unit) direction, m
  Vector3 Normal{ { 0.0, 0.0, 1.0 } }; // unit, facing the ray's origin
  double Albedo = 0.0;                 // grey Lambertian, [0, 1]
};

class NIMBUSREFERENCE_EXPORT OccluderSet
{
public:
  static constexpr int kLeafPrimitives = 4;

  /// A box between two corners (lower <= upper on every axis).
  void AddBox(const Vector3& lower, const Vector3& upper, double albedo);
  /// A triangle; one of zero area is dropped (it can never be hit).
  void AddTriangle(const Vector3& a, const Vector3& b, const Vector3& c, double albedo);
  /// Builds the hierarchy: call after the last Add and before any query.
  void Build();

  bool IsEmpty() const { return this->Boxes.empty() && this->Triangles.empty(); }
  std::size_t GetNumberOfBoxes() const { return this->Boxes.size(); }
  std::size_t GetNumberOfTriangles() const { return this->Triangles.size(); }
  std::size_t GetNumberOfNodes() const { return this->Nodes.size(); }

  /// The nearest surface at 0 < t < tMax along origin + t direction (direction unit);
  /// false if none.
  bool Intersect(
    const Vector3& origin, const Vector3& direction, double tMax, OccluderHit& hit) const;
  /// Whether any surface lies at 0 < t < tMax (a shadow ray; stops at the first).
  bool Occluded(const Vector3& origin, const Vector3& direction, double tMax) const;

  /// The same queries by testing every primitive (no hierarchy): for tests.
  bool IntersectBruteForce(
    const Vector3& origin, const Vector3& direction, double tMax, OccluderHit& hit) const;

private:
  struct Box
  {
    Vector3 Lower, Upper;
    double Albedo;
  };
  struct Triangle
  {
    Vector3 A, E1, E2; // a vertex and the two edges from it
    Vector3 Normal;    // unit
    double Albedo;
  };
  struct Node
  {
    Vector3 Lower, Upper;
    std::uint32_t First = 0; // leaf: first entry of Order; inner: the left child (right = + 1)
    std::uint32_t Count = 0; // leaf: number of primitives; 0: an inner node
  };
  struct Ray;

  void Bounds(std::uint32_t primitive, Vector3& lower, Vector3& upper) const;
  bool HitPrimitive(std::uint32_t primitive, const Ray& ray, double tMax, OccluderHit* hit) const;
  template <bool AnyHit>
  bool Traverse(
    const Vector3& origin, const Vector3& direction, double tMax, OccluderHit* hit) const;

  std::vector<Box> Boxes;
  std::vector<Triangle> Triangles;
  /// Primitive ids in leaf order: id < Boxes.size() a box, else Triangles[id - Boxes.size()].
  std::vector<std::uint32_t> Order;
  std::vector<Node> Nodes;
};

/// A point on a surface moved off it along the normal, toward the side the normal faces,
/// by a distance relative to the point's coordinates (1e-8 of the largest, at least 1e-8
/// m; 10 um at 1 km): rays leaving it then do not hit the surface they start on, whose
/// intersection is accurate to ~1e-15 of the coordinates.
NIMBUSREFERENCE_EXPORT Vector3 OffsetFromSurface(const Vector3& point, const Vector3& normal);

} // namespace nimbus

#endif
