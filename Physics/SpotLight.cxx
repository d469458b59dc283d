#include "SpotLight.h"

#include <algorithm>
#include <cmath>

namespace nimbus
{

bool IsSpot(const SpotProfile& profile)
{
  return profile.ConeHalfAngleDegrees < 90.0;
}

double SpotFactor(const SpotProfile& profile, const Vector3& w)
{
  if (!IsFinite(w))
  {
    return 0.0; // no direction: no light (never NaN)
  }
  if (!IsSpot(profile))
  {
    return 1.0;
  }
  const double cosine = std::clamp(Dot(profile.Axis, w), -1.0, 1.0);
  const double angle = std::acos(cosine) / kDegree;
  const double outer = std::max(profile.ConeHalfAngleDegrees, 0.0);
  const double inner = outer - std::clamp(profile.EdgeWidthDegrees, 0.0, outer);
  if (angle >= outer)
  {
    return 0.0;
  }
  if (angle <= inner)
  {
    return 1.0;
  }
  const double t = (outer - angle) / (outer - inner); // 1 at the inner edge
  return t * t * (3.0 - 2.0 * t);
}

void SpotLightMapFrame(const Vector3& axis, Vector3& e1, Vector3& e2)
{
  const Vector3 h =
    std::abs(axis[2]) > 0.999 ? Vector3{ { 0.0, 1.0, 0.0 } } : Vector3{ { 0.0, 0.0, 1.0 } };
  e1 = Normalized(Cross(axis, h)); // right, seen from behind the light
  e2 = Cross(e1, axis);            // up
}

bool SpotLightMapCoordinates(const SpotProfile& profile, const Vector3& w, double& u, double& v)
{
  const double along = Dot(profile.Axis, w);
  if (!IsSpot(profile) || !(along > 0.0) || !IsFinite(w))
  {
    return false;
  }
  Vector3 e1, e2;
  SpotLightMapFrame(profile.Axis, e1, e2);
  const double spread = std::tan(std::max(profile.ConeHalfAngleDegrees, 1e-6) * kDegree);
  u = 0.5 + 0.5 * (Dot(w, e1) / along) / spread;
  v = 0.5 + 0.5 * (Dot(w, e2) / along) / spread;
  return true;
}

} // namespace nimbus
