// Unit tests of the up-axis core of the OpenVDB reader (IO/Core/VdbUpAxis.{h,cxx}): reading
// up-axis texts, the Auto rule, and the turn of an index box, a transform and voxel values
// into the up frame. The expected up-frame coordinates are written out by hand from the table
// of Physics/UpAxis.h (HandUp below), not taken from WorldToUpFrame.
#include "VdbUpAxis.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <map>
#include <string>
#include <vector>

namespace vdb = nimbus::vdb;
using nimbus::UpAxis;

namespace
{
// U for world point W, by hand (Physics/UpAxis.h's table):
//   +X up: ( y,  z, x)   +Y up: ( x, -z, y)   +Z up: ( x, y, z)   -Y up: ( x, z, -y)
template <typename T>
std::array<T, 3> HandUp(UpAxis axis, const std::array<T, 3>& w)
{
  switch (axis)
  {
    case UpAxis::PositiveX:
      return { { w[1], w[2], w[0] } };
    case UpAxis::PositiveY:
      return { { w[0], -w[2], w[1] } };
    case UpAxis::NegativeY:
      return { { w[0], w[2], -w[1] } };
    case UpAxis::PositiveZ:
    default:
      return w;
  }
}

const UpAxis AllAxes[] = { UpAxis::PositiveX, UpAxis::PositiveY, UpAxis::PositiveZ,
  UpAxis::NegativeY };

vdb::IndexBox Box(int64_t i0, int64_t i1, int64_t j0, int64_t j1, int64_t k0, int64_t k1)
{
  vdb::IndexBox b;
  b.Min = { { i0, j0, k0 } };
  b.Max = { { i1, j1, k1 } };
  return b;
}

int64_t Offset(const vdb::IndexBox& box, const std::array<int64_t, 3>& p)
{
  const int64_t nx = box.Max[0] - box.Min[0] + 1;
  const int64_t ny = box.Max[1] - box.Min[1] + 1;
  return (p[0] - box.Min[0]) + nx * ((p[1] - box.Min[1]) + ny * (p[2] - box.Min[2]));
}
}

TEST(UpAxisCore, ParsesTheUsualSpellings)
{
  const std::map<std::string, UpAxis> good = { { "+Y", UpAxis::PositiveY },
    { "Y", UpAxis::PositiveY }, { "y", UpAxis::PositiveY }, { " +y ", UpAxis::PositiveY },
    { "Y_UP", UpAxis::PositiveY }, { "y-up", UpAxis::PositiveY }, { "Y up", UpAxis::PositiveY },
    { "x", UpAxis::PositiveX }, { "+X", UpAxis::PositiveX }, { "Z", UpAxis::PositiveZ },
    { "+z", UpAxis::PositiveZ }, { "Z_UP", UpAxis::PositiveZ }, { "-Y", UpAxis::NegativeY },
    { "-y", UpAxis::NegativeY } };
  for (const auto& g : good)
  {
    UpAxis axis = UpAxis::PositiveZ;
    EXPECT_TRUE(vdb::ParseUpAxis(g.first, axis)) << "'" << g.first << "'";
    EXPECT_EQ(axis, g.second) << "'" << g.first << "'";
  }
  for (const std::string bad : { "", "-X", "-z", "w", "yy", "+-y", "sideways", "up", "1" })
  {
    UpAxis axis = UpAxis::PositiveX;
    EXPECT_FALSE(vdb::ParseUpAxis(bad, axis)) << "'" << bad << "'";
  }
}

TEST(UpAxisCore, AutoRule)
{
  using Strings = std::map<std::string, std::string>;
  const std::vector<std::string> none;
  // A chosen axis is taken whatever the file says.
  auto c = vdb::ChooseUpAxis(0, Strings{ { "up_axis", "y" } }, none);
  EXPECT_EQ(c.Axis, UpAxis::PositiveX);
  EXPECT_EQ(c.Source, "+X (chosen)");
  c = vdb::ChooseUpAxis(3, Strings{}, none);
  EXPECT_EQ(c.Axis, UpAxis::NegativeY);
  EXPECT_EQ(c.Source, "-Y (chosen)");
  // Nothing in the file: +Z.
  c = vdb::ChooseUpAxis(vdb::AutoUpAxis, Strings{}, none);
  EXPECT_EQ(c.Axis, UpAxis::PositiveZ);
  EXPECT_EQ(c.Source, "+Z (default)");
  EXPECT_EQ(c.Warning, "");
  // Houdini's two creators (GEO_VDBTranslator.cc, SOP_OpenVDB_Write.cc); Blender's "Creator".
  c = vdb::ChooseUpAxis(
    vdb::AutoUpAxis, Strings{ { "creator", "Houdini 20.5.278/GEO_VDBTranslator" } }, none);
  EXPECT_EQ(c.Axis, UpAxis::PositiveY);
  EXPECT_EQ(c.Source, "+Y (creator 'Houdini 20.5.278/GEO_VDBTranslator')");
  c =
    vdb::ChooseUpAxis(vdb::AutoUpAxis, Strings{ { "Creator", "Houdini/SOP_OpenVDB_Write" } }, none);
  EXPECT_EQ(c.Axis, UpAxis::PositiveY);
  // Another creator: +Z.
  c = vdb::ChooseUpAxis(
    vdb::AutoUpAxis, Strings{ { "creator", "Nimbus vtkNimbusOpenVDBWriter" } }, none);
  EXPECT_EQ(c.Axis, UpAxis::PositiveZ);
  EXPECT_EQ(c.Source, "+Z (default)");
  // An explicit up_axis wins over the creator, whatever the key's case.
  c = vdb::ChooseUpAxis(vdb::AutoUpAxis,
    Strings{ { "creator", "Houdini 20.5/GEO_VDBTranslator" }, { "up_axis", "+Z" } }, none);
  EXPECT_EQ(c.Axis, UpAxis::PositiveZ);
  EXPECT_EQ(c.Source, "+Z (file metadata up_axis = '+Z')");
  c = vdb::ChooseUpAxis(vdb::AutoUpAxis, Strings{ { "UpAxis", "x" } }, none);
  EXPECT_EQ(c.Axis, UpAxis::PositiveX);
  c = vdb::ChooseUpAxis(vdb::AutoUpAxis, Strings{ { "UP_AXIS", "-y" } }, none);
  EXPECT_EQ(c.Axis, UpAxis::NegativeY);
  EXPECT_EQ(c.Source, "-Y (file metadata up_axis = '-y')");
  // An up_axis it cannot read: warned, then the creator decides.
  c = vdb::ChooseUpAxis(vdb::AutoUpAxis,
    Strings{ { "up_axis", "-Z" }, { "creator", "Houdini/SOP_OpenVDB_Write" } }, none);
  EXPECT_EQ(c.Axis, UpAxis::PositiveY);
  EXPECT_NE(c.Warning.find("up_axis = '-Z'"), std::string::npos) << c.Warning;
  // The grids' creators count when the file has none.
  c = vdb::ChooseUpAxis(vdb::AutoUpAxis, Strings{}, { "Blender", "Houdini/SOP_OpenVDB_Write" });
  EXPECT_EQ(c.Axis, UpAxis::PositiveY);
  EXPECT_EQ(c.Source, "+Y (grid creator 'Houdini/SOP_OpenVDB_Write')");
}

TEST(UpAxisCore, AxisAlignedBoxesAndValuesAreReindexedByHand)
{
  // Unit spacing, origin 0, identity direction: turned index q = HandUp(p).
  const vdb::TransformInfo identity;
  const vdb::IndexBox file = Box(-1, 1, 2, 5, 3, 7); // 3 x 4 x 5 points, all different
  std::vector<float> values(file.VoxelCount());
  for (size_t n = 0; n < values.size(); ++n)
  {
    values[n] = float(n);
  }
  for (const UpAxis axis : AllAxes)
  {
    const vdb::UpTurn turn(axis, identity);
    EXPECT_EQ(turn.Identity(), axis == UpAxis::PositiveZ);
    EXPECT_EQ(turn.Reindexes(), axis != UpAxis::PositiveZ);
    const vdb::IndexBox turned = turn.TurnBox(file);
    ASSERT_EQ(turned.VoxelCount(), file.VoxelCount());
    EXPECT_TRUE(turn.FileBox(turned) == file);
    std::vector<float> out(values.size(), -1.0f);
    turn.TurnValues(file, values.data(), 1, out.data());
    for (int64_t k = file.Min[2]; k <= file.Max[2]; ++k)
    {
      for (int64_t j = file.Min[1]; j <= file.Max[1]; ++j)
      {
        for (int64_t i = file.Min[0]; i <= file.Max[0]; ++i)
        {
          const std::array<int64_t, 3> p{ { i, j, k } };
          const std::array<int64_t, 3> q = HandUp(axis, p);
          for (int a = 0; a < 3; ++a)
          {
            ASSERT_GE(q[a], turned.Min[a]);
            ASSERT_LE(q[a], turned.Max[a]);
          }
          ASSERT_EQ(out[Offset(turned, q)], values[Offset(file, p)])
            << nimbus::UpAxisName(axis) << " at file point " << i << " " << j << " " << k;
        }
      }
    }
    // The transform: origin R o, spacing permuted, identity direction.
    vdb::TransformInfo t;
    t.Origin = { { 10.0, -20.0, 30.0 } };
    t.Spacing = { { 1.0, 2.0, 4.0 } };
    const vdb::TransformInfo u = turn.TurnTransform(t);
    EXPECT_EQ(u.Origin, HandUp(axis, t.Origin));
    const auto spacing = HandUp(axis, t.Spacing);
    for (int a = 0; a < 3; ++a)
    {
      EXPECT_EQ(u.Spacing[a], std::abs(spacing[a])) << nimbus::UpAxisName(axis);
    }
    EXPECT_EQ(u.Direction, identity.Direction);
  }
}

TEST(UpAxisCore, VectorsAreRotated)
{
  const vdb::IndexBox file = Box(0, 1, 0, 0, 0, 0);
  const std::vector<float> v = { 1.0f, 2.0f, 3.0f, -4.0f, 5.0f, -6.0f };
  for (const UpAxis axis : AllAxes)
  {
    const vdb::UpTurn turn(axis, vdb::TransformInfo());
    const auto r = turn.TurnVector({ { 1.0f, 2.0f, 3.0f } });
    EXPECT_EQ(r, HandUp(axis, std::array<float, 3>{ { 1.0f, 2.0f, 3.0f } }));
    std::vector<float> out(6, 0.0f);
    turn.TurnValues(file, v.data(), 3, out.data());
    // Point n of the file is turned point HandUp(n, 0, 0), its vector HandUp(v).
    const vdb::IndexBox turned = turn.TurnBox(file);
    for (int n = 0; n < 2; ++n)
    {
      const std::array<int64_t, 3> q = HandUp(axis, std::array<int64_t, 3>{ { n, 0, 0 } });
      const auto expected =
        HandUp(axis, std::array<float, 3>{ { v[3 * n], v[3 * n + 1], v[3 * n + 2] } });
      const int64_t o = Offset(turned, q);
      EXPECT_EQ(out[3 * o], expected[0]);
      EXPECT_EQ(out[3 * o + 1], expected[1]);
      EXPECT_EQ(out[3 * o + 2], expected[2]);
    }
  }
}

TEST(UpAxisCore, MirroredDirectionIsReindexedToTheIdentity)
{
  // D = diag(1, -1, 1): world = o + (i sx, -j sy, k sz). Turned, the image is axis-aligned
  // and the point of file index p is at U = HandUp(o + D S p).
  vdb::TransformInfo t;
  t.Origin = { { 1.0, 2.0, 3.0 } };
  t.Spacing = { { 0.5, 2.0, 3.0 } };
  t.Direction = { { 1, 0, 0, 0, -1, 0, 0, 0, 1 } };
  t.Rotated = true;
  const vdb::IndexBox file = Box(0, 2, 0, 3, 0, 1);
  for (const UpAxis axis : { UpAxis::PositiveX, UpAxis::PositiveY, UpAxis::NegativeY })
  {
    const vdb::UpTurn turn(axis, t);
    ASSERT_TRUE(turn.Reindexes());
    const vdb::TransformInfo u = turn.TurnTransform(t);
    EXPECT_EQ(u.Direction, vdb::TransformInfo().Direction);
    EXPECT_FALSE(u.Rotated);
    const vdb::IndexBox turned = turn.TurnBox(file);
    std::vector<float> values(file.VoxelCount()), out(file.VoxelCount(), -1.0f);
    for (size_t n = 0; n < values.size(); ++n)
    {
      values[n] = float(n);
    }
    turn.TurnValues(file, values.data(), 1, out.data());
    for (int64_t k = 0; k <= 1; ++k)
      for (int64_t j = 0; j <= 3; ++j)
        for (int64_t i = 0; i <= 2; ++i)
        {
          const std::array<double, 3> w{ { t.Origin[0] + i * t.Spacing[0],
            t.Origin[1] - j * t.Spacing[1], t.Origin[2] + k * t.Spacing[2] } };
          const auto up = HandUp(axis, w);
          std::array<int64_t, 3> q{};
          for (int a = 0; a < 3; ++a)
          {
            const double index = (up[a] - u.Origin[a]) / u.Spacing[a];
            q[a] = std::llround(index);
            ASSERT_NEAR(index, double(q[a]), 1e-12);
            ASSERT_GE(q[a], turned.Min[a]);
            ASSERT_LE(q[a], turned.Max[a]);
          }
          ASSERT_EQ(out[Offset(turned, q)], values[Offset(file, { { i, j, k } })]);
        }
  }
}

TEST(UpAxisCore, GeneralDirectionIsTurnedNotReindexed)
{
  // A rotation by 30 degrees about z: R D is no signed permutation.
  const double c = std::cos(M_PI / 6), s = std::sin(M_PI / 6);
  vdb::TransformInfo t;
  t.Origin = { { 5.0, 6.0, 7.0 } };
  t.Spacing = { { 3.33, 3.33, 3.33 } };
  t.Direction = { { c, s, 0, -s, c, 0, 0, 0, 1 } }; // columns: index axes in world
  t.Rotated = true;
  const vdb::IndexBox file = Box(-2, 3, 0, 4, 1, 1);
  for (const UpAxis axis : { UpAxis::PositiveX, UpAxis::PositiveY, UpAxis::NegativeY })
  {
    const vdb::UpTurn turn(axis, t);
    EXPECT_FALSE(turn.Reindexes());
    EXPECT_TRUE(turn.TurnBox(file) == file);
    EXPECT_TRUE(turn.FileBox(file) == file);
    const vdb::TransformInfo u = turn.TurnTransform(t);
    EXPECT_EQ(u.Origin, HandUp(axis, t.Origin));
    EXPECT_EQ(u.Spacing, t.Spacing);
    for (int col = 0; col < 3; ++col)
    {
      const std::array<double, 3> d{ { t.Direction[3 * col], t.Direction[3 * col + 1],
        t.Direction[3 * col + 2] } };
      const auto e = HandUp(axis, d);
      for (int a = 0; a < 3; ++a)
      {
        EXPECT_EQ(u.Direction[3 * col + a], e[a]);
      }
    }
    // Scalars stay, vectors turn (in place).
    std::vector<float> v = { 1.0f, 2.0f, 3.0f };
    turn.TurnValues(Box(0, 0, 0, 0, 0, 0), v.data(), 3, v.data());
    EXPECT_EQ((std::array<float, 3>{ { v[0], v[1], v[2] } }),
      HandUp(axis, std::array<float, 3>{ { 1.0f, 2.0f, 3.0f } }));
    std::vector<float> scalar = { 9.0f };
    turn.TurnValues(Box(0, 0, 0, 0, 0, 0), scalar.data(), 1, scalar.data());
    EXPECT_EQ(scalar[0], 9.0f);
  }
}

TEST(UpAxisCore, PieceBoxesMapBackToTheFile)
{
  const vdb::IndexBox file = Box(-7, 11, 3, 4, -20, -2);
  for (const UpAxis axis : AllAxes)
  {
    const vdb::UpTurn turn(axis, vdb::TransformInfo());
    const vdb::IndexBox whole = turn.TurnBox(file);
    // Every sub-box of the turned box is the turn of one file box.
    for (int64_t cut = 0; cut < 3; ++cut)
    {
      vdb::IndexBox piece = whole;
      piece.Min[cut] = whole.Min[cut] + (whole.Max[cut] - whole.Min[cut]) / 2;
      const vdb::IndexBox back = turn.FileBox(piece);
      EXPECT_TRUE(turn.TurnBox(back) == piece) << nimbus::UpAxisName(axis);
      EXPECT_EQ(back.VoxelCount(), piece.VoxelCount());
      EXPECT_TRUE(back.Intersection(file) == back) << "a piece reads inside the file's box";
    }
  }
}
