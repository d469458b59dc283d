// Vectors and constants shared by all of Nimbus's numerics: one definition of a 3-D
// vector, its dot and cross products, and pi. Header-only, plain C++.
#ifndef nimbus_Math_h
#define nimbus_Math_h

#include <array>
#include <cmath>
#include <stdexcept>

namespace nimbus
{

/// A point or direction in a right-handed frame (Nimbus scenes: x east, y north, z up).
using Vector3 = std::array<double, 3>;

constexpr double kPi = 3.14159265358979323846;
/// Radians per degree.
constexpr double kDegree = kPi / 180.0;

inline double Dot(const Vector3& a, const Vector3& b)
{
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

inline Vector3 Cross(const Vector3& a, const Vector3& b)
{
  return { { a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0] } };
}

inline double Length(const Vector3& v)
{
  return std::sqrt(Dot(v, v));
}

inline bool IsFinite(const Vector3& v)
{
  return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]);
}

/// The point origin + t direction.
inline Vector3 Along(const Vector3& origin, const Vector3& direction, double t)
{
  return { { origin[0] + t * direction[0], origin[1] + t * direction[1],
    origin[2] + t * direction[2] } };
}

/// v / |v|. Throws std::invalid_argument for a zero or non-finite v.
inline Vector3 Normalized(const Vector3& v)
{
  const double length = Length(v);
  if (!(length > 0.0) || !std::isfinite(length))
  {
    throw std::invalid_argument("direction must be finite and non-zero");
  }
  return { { v[0] / length, v[1] / length, v[2] / length } };
}

} // namespace nimbus

#endif
