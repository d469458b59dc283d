// Older versions of the scene format (docs/scene-format.md): what each version
// changed, and how a file of an older version is read as the current one.
//
// Version 1 named the sun's and the air's parameters without their units; version 2
// names them as Physics/Sun.h and Physics/Atmosphere.h do (and as the mapper, the
// sky, the Python API and the plugin do). A version-1 file is read by renaming
// those keys; nothing else changed. Version 3 only added keys (lights, media,
// medium.emission), and so did version 4 (spot lights, occluders): version-2 and
// version-3 files need no migration, and SceneJson.cxx refuses the new keys (and the
// light type "spot") in older files. Private to SceneJson.cxx.
#ifndef NimbusSceneMigration_h
#define NimbusSceneMigration_h

#include <nlohmann/json.hpp>

#include <string>

namespace nimbus
{
/// The oldest version this build reads.
constexpr int kFirstSceneFormatVersion = 1;

/// Renames a version-1 document's keys to their version-2 names, in place. A
/// version-2 name in a version-1 file is an error (it was unknown in version 1):
/// throws std::invalid_argument with the key path.
void MigrateSceneVersion1(nlohmann::ordered_json& root);

/// A message about a migrated version-1 file, in that file's own key names.
std::string InSceneVersion1Words(std::string message);
} // namespace nimbus

#endif
