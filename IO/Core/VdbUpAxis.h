// VdbUpAxis: which way is up in a .vdb file, and the turn of the reader's image into
// Nimbus's up frame, in plain C++ (no VTK, no OpenVDB). docs/openvdb.md, "Which way is up".
//
//  * The rotation R and the values of the UpAxis property are defined once, in
//    Physics/UpAxis.h: the reader's output is the file's data in the up frame U = R W of the
//    world point W, so the chosen axis becomes +z (x east, y north, z up: Sun.h).
//  * ChooseUpAxis: the Auto rule. An explicit file metadata entry "up_axis" wins (Nimbus's
//    writer writes "+Z"); otherwise a "creator" naming Houdini (Houdini's VDB writers put
//    "Houdini <version>/GEO_VDBTranslator" or "Houdini/SOP_OpenVDB_Write" there; Blender's own
//    importer treats a "creator" starting with "Houdini" as y up) means +Y; otherwise +Z.
//  * UpTurn: the image turned into the up frame. For an image whose direction matrix D is a
//    signed permutation (the identity included: every axis-aligned VDB transform), the voxels
//    are re-indexed into an image with identity direction: new index q_a = sigma_a p_pi(a),
//    where (R D)[a][pi(a)] = sigma_a, so that the origin is R o, the spacing along a is the
//    file's spacing along pi(a), and the extent of axis a is the file's extent along pi(a),
//    negated (order flipped) where sigma_a = -1. For any other D, nothing is re-indexed: the
//    direction becomes R D and the origin R o. 3-component values (velocities) are rotated,
//    v -> R v, in both cases. +Z is the identity: UpTurn changes nothing, bit for bit.
#ifndef NimbusVdbUpAxis_h
#define NimbusVdbUpAxis_h

#include "UpAxis.h"
#include "VdbGrids.h"

#include <array>
#include <map>
#include <string>
#include <vector>

namespace nimbus
{
namespace vdb
{

/// Reads an up-axis text: "+Y", "Y", "y", "+y", "-Y", "Y_UP", "y-up", "Y up" (case and blanks
/// ignored; no sign means +). Returns false for anything else, -X and -Z included (no
/// UpAxis value for them).
bool ParseUpAxis(const std::string& text, UpAxis& axis);

/// The value of the UpAxis property that means "decide from the file".
constexpr int AutoUpAxis = -1;

/// What the reader decided, and why, in words ("+Y (creator 'Houdini 20.5/GEO_VDBTranslator')").
struct UpAxisChoice
{
  UpAxis Axis = UpAxis::PositiveZ;
  /// "<axis> (<why>)": "(chosen)", "(file metadata up_axis = '...')", "(creator '...')",
  /// "(default)".
  std::string Source;
  /// Non-empty when the file says something the rule could not use (an up_axis it cannot
  /// read): for a warning.
  std::string Warning;
};

/// The up axis for `requested` (AutoUpAxis or an UpAxis value): a requested axis is taken as
/// it is; Auto looks at the file-level string metadata (`fileStrings`, as stored) and then at
/// the grids' "creator" metadata (`gridCreators`). Keys are compared case-insensitively.
UpAxisChoice ChooseUpAxis(int requested, const std::map<std::string, std::string>& fileStrings,
  const std::vector<std::string>& gridCreators);

/// The turn of an image into the up frame (see the top of this file).
class UpTurn
{
public:
  /// `reference`: the transform of the image as read (its direction decides whether voxels
  /// are re-indexed; a direction within 1e-9 of a signed permutation counts as one).
  UpTurn(UpAxis axis, const TransformInfo& reference);

  /// +Z: nothing changes.
  bool Identity() const { return this->IsIdentity; }
  /// True when the voxels are re-indexed (signed-permutation direction, not +Z).
  bool Reindexes() const { return this->Reindex; }
  UpAxis Axis() const { return this->UpAxisValue; }

  /// The index box in the up frame of a box of the file's index space, and back.
  IndexBox TurnBox(const IndexBox& fileBox) const;
  IndexBox FileBox(const IndexBox& turnedBox) const;

  /// Origin, spacing and direction of the turned image for an image of transform `t` (the
  /// same direction class as the constructor's reference: pass the transform read with the
  /// voxels). Identity: `t` unchanged.
  TransformInfo TurnTransform(const TransformInfo& t) const;

  /// R v.
  std::array<float, 3> TurnVector(const std::array<float, 3>& v) const;

  /// Values over `fileBox` (x fastest, `components` floats per point; 3 components are
  /// rotated) into `out`, laid out over TurnBox(fileBox). `in` and `out` must not overlap
  /// when Reindexes(); otherwise they may be the same buffer.
  void TurnValues(const IndexBox& fileBox, const float* in, int components, float* out) const;

private:
  UpAxis UpAxisValue;
  bool IsIdentity = true;
  bool Reindex = false;
  std::array<std::array<int, 3>, 3> R;
  /// Turned axis a reads file axis Perm[a], with sign Sign[a]: p[Perm[a]] = Sign[a] q[a].
  std::array<int, 3> Perm{ { 0, 1, 2 } };
  std::array<int, 3> Sign{ { 1, 1, 1 } };
};

} // namespace vdb
} // namespace nimbus

#endif
