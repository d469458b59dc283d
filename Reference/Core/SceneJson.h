// The versioned JSON scene file (format: docs/scene-format.md).
//
//   {"nimbus_scene": 4, "camera": {...}, "medium": {...}, "sun": {...}, ...}
//
// Version 4 adds spot lights (with an optional light map) and opaque occluders (boxes,
// meshes); version 3 adds lights (point, polyline), per-voxel emission and additional
// media; version 2 names the sun's and the air's parameters as Physics/Sun.h and
// Physics/Atmosphere.h do, with their units ("elevation_degrees",
// "mie_scattering_per_metre"). Version-1 files still load: their keys are renamed
// on reading (the table in docs/scene-format.md); version-2 and version-3 files are
// version-4 files without the newer keys. SceneToJson writes version 4.
//
// The reader stores the paths of light maps and meshes (resolved like a density's); it
// does not read those files: Reference/SceneAssets.h (VTK glue) fills the description's
// pixels and triangles, as vtkNimbusReferenceRenderer does before it renders.
//
// ParseScene/LoadScene validate everything they read and throw
// std::invalid_argument with a message that starts with the key path of the
// offending value, e.g.
//   scene.medium.phase[0].g: expected a number in [-1, 1], got 1.5
// SceneToJson writes the canonical form (every field, fixed key order, 2-space
// indent); ParseScene(SceneToJson(s)) reproduces s field by field for any scene
// ParseScene accepts. SceneHash hashes that canonical text.
#ifndef NimbusSceneJson_h
#define NimbusSceneJson_h

#include "NimbusReferenceModule.h" // for export macro
#include "SceneDescription.h"

#include <string>

namespace nimbus
{

/// Parses and validates a scene. A relative path (densities, light maps, meshes) is resolved
/// against baseDirectory (the current directory when empty) and stored
/// absolute and lexically normalised. Metaball-cloud parameters are stored in
/// the source's property order (vtkNimbusMetaballCloudSource.h), whatever
/// their order in the text. Throws std::invalid_argument (message starts with
/// the key path, "scene" being the root).
NIMBUSREFERENCE_EXPORT SceneDescription ParseScene(
  const std::string& jsonText, const std::string& baseDirectory);

/// Reads the file and parses it with the file's directory as base. Throws
/// std::runtime_error when the file cannot be read and std::invalid_argument
/// when it is not a valid scene; both messages start with the file's path.
NIMBUSREFERENCE_EXPORT SceneDescription LoadScene(const std::string& path);

/// The canonical JSON of a scene: every field, in the documented order, 2-space
/// indent, shortest round-trip number formatting, trailing newline. Does not
/// validate (write only scenes that ParseScene accepts if they must read back).
NIMBUSREFERENCE_EXPORT std::string SceneToJson(const SceneDescription& scene);

/// 16 lowercase hex digits: FNV-1a 64 of SceneToJson(scene). Covers the
/// description only: for a "file" density it hashes the (resolved, absolute)
/// path, not the file's contents, size or modification time.
NIMBUSREFERENCE_EXPORT std::string SceneHash(const SceneDescription& scene);

} // namespace nimbus

#endif
