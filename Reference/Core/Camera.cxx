#include "Camera.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace nimbus
{

namespace
{
Vector3 Scaled(const Vector3& a, double s)
{
  return { { a[0] * s, a[1] * s, a[2] * s } };
}

/// v times the power of two (exact) that brings its largest component into [1, 2),
/// so that its length neither overflows nor underflows; zero stays zero.
Vector3 ScaledToOrderOne(const Vector3& v)
{
  const double largest = std::max({ std::abs(v[0]), std::abs(v[1]), std::abs(v[2]) });
  if (!(largest > 0.0) || !std::isfinite(largest))
  {
    return v;
  }
  const int exponent = std::ilogb(largest);
  return { { std::ldexp(v[0], -exponent), std::ldexp(v[1], -exponent),
    std::ldexp(v[2], -exponent) } };
}
}

Camera::Camera(const CameraDescription& d)
  : Position(d.Position)
  , Width(d.Width)
  , Height(d.Height)
{
  // Finiteness first: an overflowing difference is not "equal points".
  if (!IsFinite(d.Position) || !IsFinite(d.FocalPoint) || !IsFinite(d.ViewUp))
  {
    throw std::invalid_argument("camera: position, focal point and view-up must be finite");
  }
  const Vector3 difference{ { d.FocalPoint[0] - d.Position[0], d.FocalPoint[1] - d.Position[1],
    d.FocalPoint[2] - d.Position[2] } };
  if (!IsFinite(difference))
  {
    throw std::invalid_argument(
      "camera: position and focal point are too far apart (their difference overflows)");
  }
  const Vector3 view = ScaledToOrderOne(difference);
  const double viewLength = Length(view);
  if (!(viewLength > 0.0))
  {
    throw std::invalid_argument("camera: position and focal point must differ");
  }
  this->Forward = Scaled(view, 1.0 / viewLength);
  const Vector3 up = ScaledToOrderOne(d.ViewUp);
  const Vector3 right = Cross(this->Forward, up);
  const double rightLength = Length(right);
  if (!(rightLength > 1e-9 * Length(up)) || !std::isfinite(rightLength))
  {
    throw std::invalid_argument("camera: view-up must not be parallel to the view direction");
  }
  this->Right = Scaled(right, 1.0 / rightLength);
  this->Up = Cross(this->Right, this->Forward);
  if (!(d.ViewAngle > 0.0 && d.ViewAngle < 180.0))
  {
    throw std::invalid_argument("camera: view angle must be in (0, 180) degrees");
  }
  if (d.Width < 1 || d.Height < 1)
  {
    throw std::invalid_argument("camera: image width and height must be >= 1");
  }
  this->TanHalfAngle = std::tan(0.5 * d.ViewAngle * 3.14159265358979323846 / 180.0);
}

Camera::Vector3 Camera::RayDirection(double x, double y) const
{
  const double aspect = static_cast<double>(this->Width) / this->Height;
  const double sx = (2.0 * x / this->Width - 1.0) * this->TanHalfAngle * aspect;
  const double sy = (2.0 * y / this->Height - 1.0) * this->TanHalfAngle;
  Vector3 direction;
  for (int a = 0; a < 3; ++a)
  {
    direction[a] = this->Forward[a] + sx * this->Right[a] + sy * this->Up[a];
  }
  return Scaled(direction, 1.0 / Length(direction));
}

} // namespace nimbus
