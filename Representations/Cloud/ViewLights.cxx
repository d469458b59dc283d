#include "ViewLights.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace nimbus
{
namespace
{
Vector3 BoxCentre(const std::array<double, 6>& b)
{
  return { { 0.5 * (b[0] + b[1]), 0.5 * (b[2] + b[3]), 0.5 * (b[4] + b[5]) } };
}

double BoxRadius(const std::array<double, 6>& b)
{
  const double x = b[1] - b[0], y = b[3] - b[2], z = b[5] - b[4];
  return 0.5 * std::sqrt(x * x + y * y + z * z);
}

bool Usable(const ViewLight& light)
{
  const double largest = std::max({ light.Intensity[0], light.Intensity[1], light.Intensity[2] });
  if (!IsFinite(light.Position) || !IsFinite(light.Spot.Axis) || !(largest > 0.0) ||
    !std::isfinite(largest) || !std::isfinite(light.Spot.ConeHalfAngleDegrees))
  {
    return false;
  }
  for (double c : light.Intensity)
  {
    if (!(c >= 0.0) || !std::isfinite(c))
    {
      return false;
    }
  }
  // A cone of zero width lights nothing.
  return !(IsSpot(light.Spot) && !(light.Spot.ConeHalfAngleDegrees > 0.0));
}

// How bright the light is at the region (for keeping the brightest).
double Brightness(const ViewLight& light, const std::array<double, 6>& region)
{
  const Vector3 c = BoxCentre(region);
  const Vector3 d{ { c[0] - light.Position[0], c[1] - light.Position[1],
    c[2] - light.Position[2] } };
  const double r = std::max(BoxRadius(region), 1e-30);
  const double distance = std::max(Length(d), r);
  return std::max({ light.Intensity[0], light.Intensity[1], light.Intensity[2] }) /
    (distance * distance);
}
}

bool LightReachesBox(const ViewLight& light, const std::array<double, 6>& bounds)
{
  if (!(bounds[0] <= bounds[1] && bounds[2] <= bounds[3] && bounds[4] <= bounds[5]))
  {
    return false;
  }
  if (!IsSpot(light.Spot))
  {
    return true;
  }
  const Vector3 c = BoxCentre(bounds);
  const double r = BoxRadius(bounds);
  const Vector3 d{ { c[0] - light.Position[0], c[1] - light.Position[1],
    c[2] - light.Position[2] } };
  const double distance = Length(d);
  if (distance <= r)
  {
    return true; // the light is inside the sphere around the box
  }
  // The sphere subtends asin(r / distance) around d; the cone reaches it when the angle
  // between the axis and d is less than the cone's half angle plus that.
  const double cosine = std::clamp(Dot(light.Spot.Axis, d) / distance, -1.0, 1.0);
  const double angle = std::acos(cosine);
  return angle < light.Spot.ConeHalfAngleDegrees * kDegree + std::asin(r / distance);
}

bool LightReachesFrustum(const ViewLight& light, const std::array<double, 24>& planes, double range)
{
  // The sphere around the cone's part within `range`: for a cone of half angle theta,
  // the sphere through the apex and the base circle (centre on the axis at
  // range / (2 cos^2 theta), radius the same), or around the apex when that is larger
  // than the sphere of radius `range` itself.
  Vector3 centre = light.Position;
  double radius = range;
  if (IsSpot(light.Spot))
  {
    const double c = std::cos(light.Spot.ConeHalfAngleDegrees * kDegree);
    const double r = range / (2.0 * std::max(c * c, 1e-12));
    if (r < range)
    {
      centre = Along(light.Position, light.Spot.Axis, r);
      radius = r;
    }
  }
  for (int p = 0; p < 6; ++p)
  {
    const double distance = planes[4 * p] * centre[0] + planes[4 * p + 1] * centre[1] +
      planes[4 * p + 2] * centre[2] + planes[4 * p + 3];
    const double norm = std::sqrt(planes[4 * p] * planes[4 * p] +
      planes[4 * p + 1] * planes[4 * p + 1] + planes[4 * p + 2] * planes[4 * p + 2]);
    if (norm > 0.0 && distance < -radius * norm)
    {
      return false;
    }
  }
  return true;
}

ViewLightSelection SelectViewLights(const std::vector<ViewLight>& candidates,
  const std::array<double, 6>& region, int maximumLights, const std::array<double, 24>* frustum)
{
  ViewLightSelection selection;
  std::vector<std::pair<double, const ViewLight*>> kept;
  for (const ViewLight& light : candidates)
  {
    if (!Usable(light))
    {
      continue;
    }
    if (!LightReachesBox(light, region) ||
      (frustum &&
        !LightReachesFrustum(light, *frustum, ShadowDepthRange(light.Position, region)[1])))
    {
      ++selection.DroppedOutside;
      continue;
    }
    kept.emplace_back(Brightness(light, region), &light);
  }
  std::stable_sort(
    kept.begin(), kept.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  const std::size_t limit =
    static_cast<std::size_t>(std::clamp(maximumLights, 0, kMaximumViewLights));
  for (std::size_t i = 0; i < kept.size(); ++i)
  {
    if (i < limit)
    {
      selection.Lights.push_back(*kept[i].second);
    }
    else
    {
      ++selection.DroppedForCount;
    }
  }
  if (selection.DroppedForCount > 0)
  {
    std::ostringstream message;
    message << "The view has " << kept.size() << " lights whose beams reach the scene; the "
            << limit << " brightest light the haze and the cloud, the other "
            << selection.DroppedForCount << " are left out (at most " << kMaximumViewLights
            << " per view).";
    selection.Message = message.str();
  }
  return selection;
}

const std::array<ShadowFace, 6>& ShadowFaces()
{
  static const std::array<ShadowFace, 6> faces{ {
    { { { 1, 0, 0 } }, { { 0, 0, 1 } } },
    { { { -1, 0, 0 } }, { { 0, 0, 1 } } },
    { { { 0, 1, 0 } }, { { 0, 0, 1 } } },
    { { { 0, -1, 0 } }, { { 0, 0, 1 } } },
    { { { 0, 0, 1 } }, { { 0, 1, 0 } } },
    { { { 0, 0, -1 } }, { { 0, 1, 0 } } },
  } };
  return faces;
}

std::array<double, 2> ShadowDepthRange(
  const Vector3& lightPosition, const std::array<double, 6>& region)
{
  double farthest = 0.0;
  for (int i = 0; i < 8; ++i)
  {
    const Vector3 corner{ { region[(i & 1) ? 1 : 0], region[(i & 2) ? 3 : 2],
      region[(i & 4) ? 5 : 4] } };
    const Vector3 d{ { corner[0] - lightPosition[0], corner[1] - lightPosition[1],
      corner[2] - lightPosition[2] } };
    farthest = std::max(farthest, Length(d));
  }
  // A face's far plane is a distance along its axis; the region's farthest corner is
  // at most that far along any axis.
  const double farPlane = std::max(1.01 * farthest, 1e-6);
  return { { 1e-4 * farPlane, farPlane } };
}

std::array<double, 16> ShadowFaceProjection(double n, double f)
{
  // 90 degrees: cot(45 degrees) = 1. Column-major.
  std::array<double, 16> m{};
  m[0] = 1.0;
  m[5] = 1.0;
  m[10] = -(f + n) / (f - n);
  m[11] = -1.0;
  m[14] = -2.0 * f * n / (f - n);
  return m;
}
}
