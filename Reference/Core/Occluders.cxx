#include "Occluders.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace nimbus
{

namespace
{
constexpr double kInfinity = std::numeric_limits<double>::infinity();
/// Deepest stack a traversal needs: median splits halve the primitives, so the depth is
/// about log2(primitives / kLeafPrimitives) (2^32 primitives: 30); the build stops
/// splitting before this.
constexpr int kMaxDepth = 60;

Vector3 Subtract(const Vector3& a, const Vector3& b)
{
  return { { a[0] - b[0], a[1] - b[1], a[2] - b[2] } };
}
} // namespace

/// A ray with what the slab tests need.
struct OccluderSet::Ray
{
  Vector3 Origin, Direction, Inverse;
  bool Zero[3];

  Ray(const Vector3& origin, const Vector3& direction)
    : Origin(origin)
    , Direction(direction)
  {
    for (int a = 0; a < 3; ++a)
    {
      this->Zero[a] = direction[a] == 0.0;
      this->Inverse[a] = this->Zero[a] ? 0.0 : 1.0 / direction[a];
    }
  }

  /// The parameter interval [tNear, tFar] inside the box (an empty one when tNear > tFar),
  /// and the axes by which the ray enters and leaves it.
  void Slabs(const Vector3& lower, const Vector3& upper, double& tNear, double& tFar, int& nearAxis,
    int& farAxis) const
  {
    tNear = -kInfinity;
    tFar = kInfinity;
    nearAxis = farAxis = 0;
    for (int a = 0; a < 3; ++a)
    {
      if (this->Zero[a])
      {
        if (this->Origin[a] < lower[a] || this->Origin[a] > upper[a])
        {
          tNear = kInfinity;
          tFar = -kInfinity;
          return;
        }
        continue;
      }
      double t0 = (lower[a] - this->Origin[a]) * this->Inverse[a];
      double t1 = (upper[a] - this->Origin[a]) * this->Inverse[a];
      if (t0 > t1)
      {
        std::swap(t0, t1);
      }
      if (t0 > tNear)
      {
        tNear = t0;
        nearAxis = a;
      }
      if (t1 < tFar)
      {
        tFar = t1;
        farAxis = a;
      }
    }
  }
};

void OccluderSet::AddBox(const Vector3& lower, const Vector3& upper, double albedo)
{
  for (int a = 0; a < 3; ++a)
  {
    if (!(lower[a] <= upper[a]) || !std::isfinite(lower[a]) || !std::isfinite(upper[a]))
    {
      throw std::invalid_argument("nimbus::OccluderSet: a box needs finite corners with "
                                  "lower <= upper on every axis");
    }
  }
  this->Boxes.push_back({ lower, upper, albedo });
  this->Nodes.clear();
}

void OccluderSet::AddTriangle(const Vector3& a, const Vector3& b, const Vector3& c, double albedo)
{
  if (!IsFinite(a) || !IsFinite(b) || !IsFinite(c))
  {
    throw std::invalid_argument("nimbus::OccluderSet: a triangle needs finite vertices");
  }
  Triangle t;
  t.A = a;
  t.E1 = Subtract(b, a);
  t.E2 = Subtract(c, a);
  const Vector3 n = Cross(t.E1, t.E2);
  const double length = Length(n);
  if (!(length > 0.0) || !std::isfinite(length))
  {
    return; // zero area: never hit
  }
  t.Normal = { { n[0] / length, n[1] / length, n[2] / length } };
  t.Albedo = albedo;
  this->Triangles.push_back(t);
  this->Nodes.clear();
}

void OccluderSet::Bounds(std::uint32_t primitive, Vector3& lower, Vector3& upper) const
{
  if (primitive < this->Boxes.size())
  {
    lower = this->Boxes[primitive].Lower;
    upper = this->Boxes[primitive].Upper;
    return;
  }
  const Triangle& t = this->Triangles[primitive - this->Boxes.size()];
  for (int a = 0; a < 3; ++a)
  {
    const double b = t.A[a] + t.E1[a], c = t.A[a] + t.E2[a];
    lower[a] = std::min({ t.A[a], b, c });
    upper[a] = std::max({ t.A[a], b, c });
  }
}

void OccluderSet::Build()
{
  const std::size_t count = this->Boxes.size() + this->Triangles.size();
  if (count >= std::numeric_limits<std::uint32_t>::max() / 2)
  {
    throw std::length_error("nimbus::OccluderSet: too many primitives");
  }
  this->Order.resize(count);
  std::vector<Vector3> lower(count), upper(count), centre(count);
  for (std::uint32_t i = 0; i < count; ++i)
  {
    this->Order[i] = i;
    this->Bounds(i, lower[i], upper[i]);
    for (int a = 0; a < 3; ++a)
    {
      centre[i][a] = 0.5 * (lower[i][a] + upper[i][a]);
    }
  }
  this->Nodes.clear();
  if (count == 0)
  {
    return;
  }
  this->Nodes.reserve(2 * (count / kLeafPrimitives + 1));
  struct Task
  {
    std::uint32_t Node, Begin, End;
    int Depth;
  };
  std::vector<Task> tasks;
  this->Nodes.emplace_back();
  tasks.push_back({ 0, 0, static_cast<std::uint32_t>(count), 0 });
  while (!tasks.empty())
  {
    const Task task = tasks.back();
    tasks.pop_back();
    Vector3 lo{ { kInfinity, kInfinity, kInfinity } }, hi{ { -kInfinity, -kInfinity, -kInfinity } };
    Vector3 clo = lo, chi = hi;
    for (std::uint32_t k = task.Begin; k < task.End; ++k)
    {
      const std::uint32_t p = this->Order[k];
      for (int a = 0; a < 3; ++a)
      {
        lo[a] = std::min(lo[a], lower[p][a]);
        hi[a] = std::max(hi[a], upper[p][a]);
        clo[a] = std::min(clo[a], centre[p][a]);
        chi[a] = std::max(chi[a], centre[p][a]);
      }
    }
    Node& node = this->Nodes[task.Node];
    node.Lower = lo;
    node.Upper = hi;
    const std::uint32_t n = task.End - task.Begin;
    int axis = 0;
    for (int a = 1; a < 3; ++a)
    {
      if (chi[a] - clo[a] > chi[axis] - clo[axis])
      {
        axis = a;
      }
    }
    if (n <= static_cast<std::uint32_t>(kLeafPrimitives) || task.Depth >= kMaxDepth - 2 ||
      !(chi[axis] > clo[axis]))
    {
      node.First = task.Begin;
      node.Count = n; // a leaf (also when every centroid coincides: no split separates them)
      continue;
    }
    const std::uint32_t middle = task.Begin + n / 2;
    std::nth_element(this->Order.begin() + task.Begin, this->Order.begin() + middle,
      this->Order.begin() + task.End,
      [&centre, axis](std::uint32_t x, std::uint32_t y)
      { return centre[x][axis] < centre[y][axis]; });
    const auto left = static_cast<std::uint32_t>(this->Nodes.size());
    node.First = left;
    node.Count = 0;
    this->Nodes.emplace_back(); // invalidates `node`
    this->Nodes.emplace_back();
    tasks.push_back({ left, task.Begin, middle, task.Depth + 1 });
    tasks.push_back({ left + 1, middle, task.End, task.Depth + 1 });
  }
}

bool OccluderSet::HitPrimitive(
  std::uint32_t primitive, const Ray& ray, double tMax, OccluderHit* hit) const
{
  if (primitive < this->Boxes.size())
  {
    const Box& box = this->Boxes[primitive];
    double tNear, tFar;
    int nearAxis, farAxis;
    ray.Slabs(box.Lower, box.Upper, tNear, tFar, nearAxis, farAxis);
    if (!(tNear <= tFar))
    {
      return false;
    }
    // A closed surface: its near face, or its far face from inside.
    double t;
    int axis;
    if (tNear > 0.0)
    {
      t = tNear;
      axis = nearAxis;
    }
    else
    {
      t = tFar;
      axis = farAxis;
    }
    if (!(t > 0.0 && t < tMax))
    {
      return false;
    }
    if (hit)
    {
      hit->T = t;
      hit->Normal = { { 0.0, 0.0, 0.0 } };
      hit->Normal[axis] = ray.Direction[axis] > 0.0 ? -1.0 : 1.0;
      hit->Albedo = box.Albedo;
    }
    return true;
  }
  // Moller & Trumbore, "Fast, Minimum Storage Ray/Triangle Intersection", JGT 1997.
  const Triangle& tri = this->Triangles[primitive - this->Boxes.size()];
  const Vector3 p = Cross(ray.Direction, tri.E2);
  const double det = Dot(tri.E1, p);
  if (det == 0.0 || !std::isfinite(det))
  {
    return false; // parallel to the plane
  }
  const double inverse = 1.0 / det;
  const Vector3 s = Subtract(ray.Origin, tri.A);
  const double u = Dot(s, p) * inverse;
  if (!(u >= 0.0 && u <= 1.0))
  {
    return false;
  }
  const Vector3 q = Cross(s, tri.E1);
  const double v = Dot(ray.Direction, q) * inverse;
  if (!(v >= 0.0 && u + v <= 1.0))
  {
    return false;
  }
  const double t = Dot(tri.E2, q) * inverse;
  if (!(t > 0.0 && t < tMax))
  {
    return false;
  }
  if (hit)
  {
    hit->T = t;
    const double side = Dot(tri.Normal, ray.Direction) > 0.0 ? -1.0 : 1.0;
    hit->Normal = { { side * tri.Normal[0], side * tri.Normal[1], side * tri.Normal[2] } };
    hit->Albedo = tri.Albedo;
  }
  return true;
}

template <bool AnyHit>
bool OccluderSet::Traverse(
  const Vector3& origin, const Vector3& direction, double tMax, OccluderHit* hit) const
{
  if (this->Nodes.empty())
  {
    return false;
  }
  const Ray ray(origin, direction);
  double nearest = tMax;
  bool found = false;
  std::uint32_t stack[kMaxDepth + 2];
  int top = 0;
  stack[top++] = 0;
  while (top > 0)
  {
    const Node& node = this->Nodes[stack[--top]];
    double tNear, tFar;
    int nearAxis, farAxis;
    ray.Slabs(node.Lower, node.Upper, tNear, tFar, nearAxis, farAxis);
    if (!(tNear <= tFar && tFar > 0.0 && tNear < nearest))
    {
      continue;
    }
    if (node.Count > 0)
    {
      for (std::uint32_t k = node.First; k < node.First + node.Count; ++k)
      {
        if (this->HitPrimitive(this->Order[k], ray, nearest, hit))
        {
          if (AnyHit)
          {
            return true;
          }
          found = true;
          nearest = hit->T;
        }
      }
      continue;
    }
    // Both children; the nearer one (by its entry distance) is visited first.
    const Node& left = this->Nodes[node.First];
    const Node& right = this->Nodes[node.First + 1];
    double leftNear, rightNear, ignored;
    ray.Slabs(left.Lower, left.Upper, leftNear, ignored, nearAxis, farAxis);
    ray.Slabs(right.Lower, right.Upper, rightNear, ignored, nearAxis, farAxis);
    if (leftNear < rightNear)
    {
      stack[top++] = node.First + 1;
      stack[top++] = node.First;
    }
    else
    {
      stack[top++] = node.First;
      stack[top++] = node.First + 1;
    }
  }
  return found;
}

bool OccluderSet::Intersect(
  const Vector3& origin, const Vector3& direction, double tMax, OccluderHit& hit) const
{
  return this->Traverse<false>(origin, direction, tMax, &hit);
}

bool OccluderSet::Occluded(const Vector3& origin, const Vector3& direction, double tMax) const
{
  return this->Traverse<true>(origin, direction, tMax, nullptr);
}

bool OccluderSet::IntersectBruteForce(
  const Vector3& origin, const Vector3& direction, double tMax, OccluderHit& hit) const
{
  const Ray ray(origin, direction);
  bool found = false;
  double nearest = tMax;
  const std::size_t count = this->Boxes.size() + this->Triangles.size();
  for (std::uint32_t p = 0; p < count; ++p)
  {
    if (this->HitPrimitive(p, ray, nearest, &hit))
    {
      found = true;
      nearest = hit.T;
    }
  }
  return found;
}

Vector3 OffsetFromSurface(const Vector3& point, const Vector3& normal)
{
  const double scale =
    1e-8 * std::max({ 1.0, std::abs(point[0]), std::abs(point[1]), std::abs(point[2]) });
  return { { point[0] + scale * normal[0], point[1] + scale * normal[1],
    point[2] + scale * normal[2] } };
}

} // namespace nimbus
