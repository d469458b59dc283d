// The beam of a spotlight: how its intensity falls across the cone's soft edge and
// where a direction lands on its light map (002 §6.2: the light's luminous-intensity
// distribution mapped onto the virtual planes). Plain C++, shared by the path tracer,
// the multiple-scattering solver and (as a GLSL twin in nimbusLights.glsl) the GPU.
//
// Conventions (VTK's vtkLight and the scene format agree):
//  - ConeHalfAngleDegrees is the angle between the beam's axis and its edge (VTK's
//    ConeAngle). At 90 or more the light is a point light: no cone, no light map.
//  - EdgeWidthDegrees: the soft edge lies inside the cone. The factor is 1 within
//    ConeHalfAngle - EdgeWidth of the axis, 0 beyond ConeHalfAngle, and a smoothstep of
//    the angle in between (EdgeWidth 0: a hard edge).
//  - The light map's frame: e1 = normalize(cross(axis, h)), e2 = cross(e1, axis), where
//    h = +z unless |axis.z| > 0.999, then h = +y: seen from behind the light, looking
//    along its axis, e1 points right and e2 up. A direction w (from the light) lands at
//    u = 0.5 + 0.5 (w.e1 / w.axis) / tan(ConeHalfAngle), v the same with e2 (a gnomonic
//    projection: the map is the image a slide projector would throw on a screen
//    perpendicular to the axis, filling the cone's circle's bounding square, upright and
//    unmirrored to someone standing behind the projector: u = 0 the picture's left edge,
//    v = 0 its bottom edge).
#ifndef nimbus_SpotLight_h
#define nimbus_SpotLight_h

#include "Math.h"
#include "NimbusPhysicsExport.h" // for export macro

namespace nimbus
{

struct NIMBUSPHYSICS_EXPORT SpotProfile
{
  Vector3 Axis{ { 0.0, 0.0, -1.0 } };  // unit, the beam's direction away from the light
  double ConeHalfAngleDegrees = 180.0; // >= 90: a point light (isotropic)
  double EdgeWidthDegrees = 0.0;       // in [0, ConeHalfAngleDegrees]
};

/// True when the profile has a cone (ConeHalfAngleDegrees < 90).
NIMBUSPHYSICS_EXPORT bool IsSpot(const SpotProfile& profile);

/// The beam's factor in [0, 1] toward unit direction w (from the light); 0 for a
/// non-finite w.
NIMBUSPHYSICS_EXPORT double SpotFactor(const SpotProfile& profile, const Vector3& w);

/// The light map's frame (e1, e2) of the axis (see the header's conventions).
NIMBUSPHYSICS_EXPORT void SpotLightMapFrame(const Vector3& axis, Vector3& e1, Vector3& e2);

/// Where unit direction w (from the light) lands on the light map, (u, v) in [0, 1]^2
/// inside the cone's bounding square; false when the profile is not a spot or w points
/// away from the axis' half-space.
NIMBUSPHYSICS_EXPORT bool SpotLightMapCoordinates(
  const SpotProfile& profile, const Vector3& w, double& u, double& v);

} // namespace nimbus

#endif
