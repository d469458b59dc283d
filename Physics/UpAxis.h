// Which axis of the user's data points up, and the rotation that turns the data's
// frame into Nimbus's physical frame (x east, y north, z up: Sun.h).
//
// Files come y up (Houdini, Maya, glTF, most VFX tools), z up (Blender, LES models,
// ParaView's own sources) or, rarely, x up or y down (image stacks). Nimbus keeps the
// user's coordinates and turns its sun, sky, ground and air instead: every renderer
// works in the up frame U = R W of the world point W, where R is a proper rotation
// (det R = +1) that takes the chosen axis to +z. R is a signed permutation of the
// axes, so an axis-aligned box stays an axis-aligned box.
//
//   +X up: U = ( y,  z, x)   (cyclic: east = +y, north = +z)
//   +Y up: U = ( x, -z, y)   (the y-up -> z-up conversion of glTF and Blender:
//                              east = +x, north = -z)
//   +Z up: U = ( x,  y, z)   (identity)
//   -Y up: U = ( x,  z, -y)  (east = +x, north = +z)
#ifndef nimbus_UpAxis_h
#define nimbus_UpAxis_h

#include <array>
#include <string>

namespace nimbus
{

/// The axis of the data that points up. The values are the ones of the VTK and
/// ParaView properties (UpAxis): keep them.
enum class UpAxis : int
{
  PositiveX = 0,
  PositiveY = 1,
  PositiveZ = 2,
  NegativeY = 3
};

/// True for the four values above.
inline bool IsUpAxis(int value)
{
  return value >= 0 && value <= 3;
}

/// The rotation R (row-major, entries -1, 0, +1) from world to the up frame.
inline std::array<std::array<int, 3>, 3> WorldToUpFrame(UpAxis axis)
{
  switch (axis)
  {
    case UpAxis::PositiveX:
      return { { { { 0, 1, 0 } }, { { 0, 0, 1 } }, { { 1, 0, 0 } } } };
    case UpAxis::PositiveY:
      return { { { { 1, 0, 0 } }, { { 0, 0, -1 } }, { { 0, 1, 0 } } } };
    case UpAxis::NegativeY:
      return { { { { 1, 0, 0 } }, { { 0, 0, 1 } }, { { 0, -1, 0 } } } };
    case UpAxis::PositiveZ:
    default:
      return { { { { 1, 0, 0 } }, { { 0, 1, 0 } }, { { 0, 0, 1 } } } };
  }
}

/// U = R w.
inline std::array<double, 3> ToUpFrame(UpAxis axis, const std::array<double, 3>& world)
{
  const auto r = WorldToUpFrame(axis);
  std::array<double, 3> u{};
  for (int i = 0; i < 3; ++i)
  {
    u[i] = r[i][0] * world[0] + r[i][1] * world[1] + r[i][2] * world[2];
  }
  return u;
}

/// w = R^T U.
inline std::array<double, 3> FromUpFrame(UpAxis axis, const std::array<double, 3>& up)
{
  const auto r = WorldToUpFrame(axis);
  std::array<double, 3> w{};
  for (int i = 0; i < 3; ++i)
  {
    w[i] = r[0][i] * up[0] + r[1][i] * up[1] + r[2][i] * up[2];
  }
  return w;
}

/// "+X", "+Y", "+Z", "-Y" (messages, metadata, docs).
inline std::string UpAxisName(UpAxis axis)
{
  switch (axis)
  {
    case UpAxis::PositiveX:
      return "+X";
    case UpAxis::PositiveY:
      return "+Y";
    case UpAxis::NegativeY:
      return "-Y";
    case UpAxis::PositiveZ:
    default:
      return "+Z";
  }
}

/// The message of a setter refusing `value` (empty when it is an up axis): the values
/// allowed and the axis kept (`current`).
inline std::string UpAxisRefusal(int value, int current)
{
  if (IsUpAxis(value))
  {
    return std::string();
  }
  return "SetUpAxis(" + std::to_string(value) +
    "): not an up axis (0 +X, 1 +Y, 2 +Z, 3 -Y); the up axis stays " +
    UpAxisName(static_cast<UpAxis>(current));
}

} // namespace nimbus

#endif
