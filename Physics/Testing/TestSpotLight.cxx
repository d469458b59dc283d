// A spotlight's beam (SpotLight.h): the soft-edged cone's factor and the light map's
// frame and coordinates, at ordinary and extreme cones.
#include "SpotLight.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace
{
using nimbus::kDegree;
using nimbus::SpotFactor;
using nimbus::SpotLightMapCoordinates;
using nimbus::SpotProfile;
using nimbus::Vector3;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

SpotProfile Spot(const Vector3& axis, double cone, double edge)
{
  SpotProfile profile;
  profile.Axis = nimbus::Normalized(axis);
  profile.ConeHalfAngleDegrees = cone;
  profile.EdgeWidthDegrees = edge;
  return profile;
}

// The unit direction at `degrees` from the axis, turned toward e1 (or e2).
Vector3 Tilted(const SpotProfile& profile, double degrees, bool towardE2 = false)
{
  Vector3 e1, e2;
  nimbus::SpotLightMapFrame(profile.Axis, e1, e2);
  const Vector3& side = towardE2 ? e2 : e1;
  const double c = std::cos(degrees * kDegree), s = std::sin(degrees * kDegree);
  return { { c * profile.Axis[0] + s * side[0], c * profile.Axis[1] + s * side[1],
    c * profile.Axis[2] + s * side[2] } };
}

const Vector3 kAxes[] = { { { 0, 0, -1 } }, { { 0, 0, 1 } }, { { 1, 0, 0 } },
  { { 0.3, -0.5, 0.8 } }, { { -0.2, 0.9, -0.1 } }, { { 0.001, 0.0, -1.0 } } };

TEST(SpotLight, FactorIsOneOnTheAxisAndZeroOutside)
{
  for (const Vector3& axis : kAxes)
  {
    for (double edge : { 0.0, 5.0, 20.0 })
    {
      const SpotProfile spot = Spot(axis, 30.0, edge);
      EXPECT_EQ(SpotFactor(spot, spot.Axis), 1.0);
      EXPECT_EQ(SpotFactor(spot, Tilted(spot, 30.0 - edge - 0.01)), 1.0) << edge;
      EXPECT_EQ(SpotFactor(spot, Tilted(spot, 30.01, true)), 0.0);
      EXPECT_EQ(SpotFactor(spot, Tilted(spot, 90.0)), 0.0);
      EXPECT_EQ(SpotFactor(spot, Tilted(spot, 180.0)), 0.0);
    }
  }
}

TEST(SpotLight, FactorFallsMonotonicallyAcrossTheSoftEdge)
{
  const SpotProfile spot = Spot({ { 0.3, -0.5, 0.8 } }, 25.0, 10.0);
  double previous = 1.0;
  for (double degrees = 14.0; degrees <= 26.0; degrees += 0.05)
  {
    const double f = SpotFactor(spot, Tilted(spot, degrees));
    EXPECT_LE(f, previous + 1e-12) << degrees;
    EXPECT_GE(f, 0.0);
    previous = f;
  }
  // A smoothstep of the angle: 1/2 half-way through the edge, 0.84375 a quarter in.
  EXPECT_NEAR(SpotFactor(spot, Tilted(spot, 20.0)), 0.5, 1e-12);
  EXPECT_NEAR(SpotFactor(spot, Tilted(spot, 17.5)), 0.84375, 1e-12);
}

TEST(SpotLight, ZeroEdgeWidthIsAHardEdge)
{
  const SpotProfile spot = Spot({ { 0, 0, -1 } }, 20.0, 0.0);
  EXPECT_EQ(SpotFactor(spot, Tilted(spot, 19.999)), 1.0);
  EXPECT_EQ(SpotFactor(spot, Tilted(spot, 20.001)), 0.0);
  // An edge wider than the cone is clamped to the cone: the factor falls from the axis.
  const SpotProfile wide = Spot({ { 0, 0, -1 } }, 20.0, 50.0);
  EXPECT_EQ(SpotFactor(wide, wide.Axis), 1.0); // the axis (0, 0, -1): the angle is exactly 0
  EXPECT_NEAR(SpotFactor(wide, Tilted(wide, 10.0)), 0.5, 1e-12);
  EXPECT_EQ(SpotFactor(wide, Tilted(wide, 20.001)), 0.0);
}

TEST(SpotLight, ConeOfNinetyDegreesOrMoreIsAPointLight)
{
  for (double cone : { 90.0, 120.0, 180.0, kInf })
  {
    const SpotProfile light = Spot({ { 0, 0, -1 } }, cone, 5.0);
    EXPECT_FALSE(nimbus::IsSpot(light));
    for (double degrees : { 0.0, 45.0, 89.0, 90.0, 135.0, 180.0 })
    {
      EXPECT_EQ(SpotFactor(light, Tilted(light, degrees)), 1.0) << cone << " " << degrees;
    }
    double u = -1.0, v = -1.0;
    EXPECT_FALSE(SpotLightMapCoordinates(light, light.Axis, u, v));
  }
  EXPECT_FALSE(nimbus::IsSpot(SpotProfile{})); // the default is a point light
  EXPECT_TRUE(nimbus::IsSpot(Spot({ { 0, 0, -1 } }, 89.9, 0.0)));
}

TEST(SpotLight, ExtremeCones)
{
  // 0 degrees: no direction off the axis receives light. (On the axis itself the
  // angle equals the cone's edge; SpotFactor counts the edge as outside: 0.)
  const SpotProfile needle = Spot({ { 0.3, -0.5, 0.8 } }, 0.0, 0.0);
  EXPECT_TRUE(nimbus::IsSpot(needle));
  for (double degrees : { 1e-6, 0.01, 1.0, 90.0, 180.0 })
  {
    EXPECT_EQ(SpotFactor(needle, Tilted(needle, degrees)), 0.0) << degrees;
  }
  EXPECT_EQ(SpotFactor(needle, needle.Axis), 0.0);
  double u = 0.0, v = 0.0;
  ASSERT_TRUE(SpotLightMapCoordinates(needle, needle.Axis, u, v));
  EXPECT_NEAR(u, 0.5, 1e-9);
  EXPECT_NEAR(v, 0.5, 1e-9);
  // 89.9 degrees: almost a half-space; the light map still works at its edge.
  const SpotProfile broad = Spot({ { 0, 0, -1 } }, 89.9, 0.0);
  EXPECT_EQ(SpotFactor(broad, Tilted(broad, 89.8)), 1.0);
  EXPECT_EQ(SpotFactor(broad, Tilted(broad, 89.95)), 0.0);
  EXPECT_EQ(SpotFactor(broad, Tilted(broad, 135.0)), 0.0);
  ASSERT_TRUE(SpotLightMapCoordinates(broad, Tilted(broad, 89.9), u, v));
  EXPECT_NEAR(u, 1.0, 1e-9);
  EXPECT_NEAR(v, 0.5, 1e-12);
  ASSERT_TRUE(SpotLightMapCoordinates(broad, Tilted(broad, 45.0, true), u, v));
  EXPECT_NEAR(u, 0.5, 1e-12);
  EXPECT_NEAR(v, 0.5 + 0.5 / std::tan(89.9 * kDegree), 1e-12);
}

// Non-finite input: SpotLightMapCoordinates refuses it (false), SpotFactor gives 0 (no
// light rather than a NaN that would spread through a whole solve or image).
TEST(SpotLight, NonFiniteDirectionHasNoLightMapPlace)
{
  const SpotProfile spot = Spot({ { 0, 0, -1 } }, 30.0, 5.0);
  double u = 0.25, v = 0.75;
  EXPECT_FALSE(SpotLightMapCoordinates(spot, { { kNaN, 0.0, -1.0 } }, u, v));
  EXPECT_FALSE(SpotLightMapCoordinates(spot, { { 0.0, 0.0, kNaN } }, u, v));
  EXPECT_FALSE(SpotLightMapCoordinates(spot, { { kInf, 0.0, -1.0 } }, u, v)); // w.axis = 1
  EXPECT_EQ(u, 0.25);                                                         // untouched
  EXPECT_EQ(v, 0.75);
}

TEST(SpotLight, NonFiniteDirectionGivesNoLight)
{
  const SpotProfile spot = Spot({ { 0, 0, -1 } }, 30.0, 5.0);
  for (const Vector3& w : { Vector3{ { kNaN, 0.0, -1.0 } }, Vector3{ { 0.0, 0.0, kNaN } },
         Vector3{ { kInf, 0.0, -1.0 } } })
  {
    EXPECT_EQ(SpotFactor(spot, w), 0.0);
    EXPECT_EQ(SpotFactor(SpotProfile{}, w), 0.0);
  }
}

// Seen from behind the light, looking along the axis, e1 points right and e2 up (a slide
// projector's frame): e1 x e2 points back toward the viewer, -axis.
TEST(SpotLight, LightMapFrameIsOrthonormalRightAndUp)
{
  for (const Vector3& axis : kAxes)
  {
    const Vector3 a = nimbus::Normalized(axis);
    Vector3 e1, e2;
    nimbus::SpotLightMapFrame(a, e1, e2);
    EXPECT_NEAR(nimbus::Length(e1), 1.0, 1e-12);
    EXPECT_NEAR(nimbus::Length(e2), 1.0, 1e-12);
    EXPECT_NEAR(nimbus::Dot(e1, e2), 0.0, 1e-12);
    EXPECT_NEAR(nimbus::Dot(e1, a), 0.0, 1e-12);
    const Vector3 third = nimbus::Cross(e1, e2); // e1 x e2 = -axis
    for (int i = 0; i < 3; ++i)
    {
      EXPECT_NEAR(third[i], -a[i], 1e-12);
    }
  }
  // Axis +-z: the helper vector is +y, e1 = axis x +y.
  Vector3 e1, e2;
  nimbus::SpotLightMapFrame({ { 0, 0, 1 } }, e1, e2);
  EXPECT_EQ(e1, (Vector3{ { -1, 0, 0 } }));
  EXPECT_EQ(e2, (Vector3{ { 0, 1, 0 } }));
  nimbus::SpotLightMapFrame({ { 0, 0, -1 } }, e1, e2);
  EXPECT_EQ(e1, (Vector3{ { 1, 0, 0 } }));
  EXPECT_EQ(e2, (Vector3{ { 0, 1, 0 } }));
  // Elsewhere +z: the axis +y (north) gives e1 = +y x +z = +x (east, the right of
  // someone looking north), e2 = +x x +y = +z (up).
  nimbus::SpotLightMapFrame({ { 0, 1, 0 } }, e1, e2);
  EXPECT_EQ(e1, (Vector3{ { 1, 0, 0 } }));
  EXPECT_EQ(e2, (Vector3{ { 0, 0, 1 } }));
}

TEST(SpotLight, LightMapCoordinatesOfTheAxisAndTheEdge)
{
  for (const Vector3& axis : kAxes)
  {
    for (double cone : { 5.0, 30.0, 60.0 })
    {
      const SpotProfile spot = Spot(axis, cone, 2.0);
      double u = -1.0, v = -1.0;
      ASSERT_TRUE(SpotLightMapCoordinates(spot, spot.Axis, u, v));
      EXPECT_NEAR(u, 0.5, 1e-12);
      EXPECT_NEAR(v, 0.5, 1e-12);
      ASSERT_TRUE(SpotLightMapCoordinates(spot, Tilted(spot, cone), u, v)); // edge along e1
      EXPECT_NEAR(u, 1.0, 1e-12);
      EXPECT_NEAR(v, 0.5, 1e-12);
      ASSERT_TRUE(SpotLightMapCoordinates(spot, Tilted(spot, -cone), u, v));
      EXPECT_NEAR(u, 0.0, 1e-12);
      ASSERT_TRUE(SpotLightMapCoordinates(spot, Tilted(spot, cone, true), u, v)); // along e2
      EXPECT_NEAR(u, 0.5, 1e-12);
      EXPECT_NEAR(v, 1.0, 1e-12);
      // Inside the cone: inside the map's inscribed circle; gnomonic, so half the cone's
      // angle lands at tan(cone / 2) / tan(cone) of the radius, not at half of it.
      ASSERT_TRUE(SpotLightMapCoordinates(spot, Tilted(spot, 0.5 * cone, true), u, v));
      EXPECT_NEAR(v - 0.5, 0.5 * std::tan(0.5 * cone * kDegree) / std::tan(cone * kDegree), 1e-12);
      // Behind the light's half-space: no place on the map. (At 90 degrees the rounded
      // cosine, 6e-17, is still > 0: the place is far outside the map.)
      EXPECT_FALSE(SpotLightMapCoordinates(spot, Tilted(spot, 90.5), u, v));
      EXPECT_FALSE(SpotLightMapCoordinates(spot, Tilted(spot, 150.0), u, v));
    }
  }
}
} // namespace
