// nimbus::ViewLights — which of the view's own lights (lamps, spotlights: not the sun)
// light the Cloud's medium and air in a frame, and the frames of their shadow maps.
// Plain C++ (no GL), for vtkNimbusCloudVolumeMapper (docs/lights.md).
//
// Units: positions in world units; a light's Intensity is its radiant intensity on the
// beam's axis in the sun's relative units, Y/sr per channel of linear sRGB: at d metres
// in vacuum it gives the irradiance Intensity / d^2, the irradiance a sun of illuminance
// Intensity / d^2 gives at normal incidence (the scene format's point and spot lights).
//
// A frame lights only what needs it: a light is dropped when its intensity is zero or
// not finite, or when its cone misses the region that is drawn (the union of the scene's
// geometry and the medium, as a box); at most MaximumLights are kept, the brightest at
// that region first, and the selection says how many it dropped and why.
#ifndef nimbus_ViewLights_h
#define nimbus_ViewLights_h

#include "NimbusRepresentationsModule.h"

#include "Math.h"      // for Vector3
#include "SpotLight.h" // for SpotProfile

#include <array>
#include <string>
#include <vector>

namespace nimbus
{
struct ViewLight
{
  Vector3 Position{ { 0.0, 0.0, 0.0 } }; // world units
  SpotProfile Spot;                      // a point light unless its cone is < 90 degrees
  std::array<double, 3> Intensity{ { 1.0, 1.0, 1.0 } }; // Y/sr on the axis, linear sRGB
};

/// The lights a frame draws, and a message (empty when none was dropped for the count).
struct ViewLightSelection
{
  std::vector<ViewLight> Lights;
  int DroppedForCount = 0;
  int DroppedOutside = 0; // cones that miss the region or the view
  std::string Message;
};

/// The most lights one frame draws (the shaders' arrays).
constexpr int kMaximumViewLights = 8;

/// True when the light's cone (or sphere, for a point light) can reach the axis-aligned
/// box `bounds` (xmin, xmax, ymin, ymax, zmin, zmax): the cone against the box's
/// bounding sphere, conservatively.
NIMBUSREPRESENTATIONS_EXPORT bool LightReachesBox(
  const ViewLight& light, const std::array<double, 6>& bounds);

/// True unless the part of the light's cone within `range` (world units) of the light
/// lies wholly outside one of the view's frustum planes (a x + b y + c z + d >= 0 inside,
/// VTK's vtkCamera::GetFrustumPlanes order and sign): the cone against the sphere around
/// that part (conservative). A point light: the sphere of radius `range`.
NIMBUSREPRESENTATIONS_EXPORT bool LightReachesFrustum(
  const ViewLight& light, const std::array<double, 24>& planes, double range);

/// The lights of `candidates` that light `region` (and, when `frustum` is given, reach
/// the view's frustum within the region), brightest first (intensity's largest channel
/// over the squared distance to the region's centre, at least its radius), at most
/// `maximumLights` (clamped to [0, kMaximumViewLights]).
NIMBUSREPRESENTATIONS_EXPORT ViewLightSelection SelectViewLights(
  const std::vector<ViewLight>& candidates, const std::array<double, 6>& region, int maximumLights,
  const std::array<double, 24>* frustum = nullptr);

/// One face of a light's cube of shadow maps: a 90-degree square view from the light
/// along Forward with Up, Right = Forward x Up. The six faces look along +x, -x, +y,
/// -y, +z, -z; the shaders (nimbusLights.glsl, LightShadowFace) use the same table.
struct ShadowFace
{
  Vector3 Forward;
  Vector3 Up;
};
NIMBUSREPRESENTATIONS_EXPORT const std::array<ShadowFace, 6>& ShadowFaces();

/// The near and far planes (world units) of a light's shadow maps: the far plane just
/// beyond the farthest corner of `region`, the near plane 1e-4 of it (depth precision of
/// a 24-bit or float depth buffer is ample at that ratio for the shadow bias used).
NIMBUSREPRESENTATIONS_EXPORT std::array<double, 2> ShadowDepthRange(
  const Vector3& lightPosition, const std::array<double, 6>& region);

/// The column-major OpenGL projection of a 90-degree square face for [near, far].
NIMBUSREPRESENTATIONS_EXPORT std::array<double, 16> ShadowFaceProjection(
  double nearPlane, double farPlane);
}

#endif
