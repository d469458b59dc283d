#include "SceneMigration.h"

#include <stdexcept>

namespace nimbus
{
namespace
{
struct Version1Rename
{
  const char* Section;
  const char* Version1;
  const char* Version2;
};
constexpr Version1Rename kVersion1Renames[] = {
  { "sun", "azimuth", "azimuth_degrees" },
  { "sun", "elevation", "elevation_degrees" },
  { "sun", "temperature", "temperature_kelvin" },
  { "atmosphere", "scene_altitude", "scene_altitude_metres" },
  { "atmosphere", "earth_radius", "earth_radius_metres" },
  { "atmosphere", "top_radius", "top_radius_metres" },
  { "atmosphere", "rayleigh_scattering_550", "rayleigh_scattering_per_metre" },
  { "atmosphere", "rayleigh_scale_height", "rayleigh_scale_height_metres" },
  { "atmosphere", "mie_scattering", "mie_scattering_per_metre" },
  { "atmosphere", "mie_scale_height", "mie_scale_height_metres" },
};
} // namespace

void MigrateSceneVersion1(nlohmann::ordered_json& root)
{
  for (const Version1Rename& rename : kVersion1Renames)
  {
    if (!root.contains(rename.Section) || !root[rename.Section].is_object())
    {
      continue; // a missing or malformed section fails later, as in version 2
    }
    nlohmann::ordered_json& section = root[rename.Section];
    if (section.contains(rename.Version2))
    {
      throw std::invalid_argument(std::string("scene.") + rename.Section + "." + rename.Version2 +
        ": unknown key in a version-1 file (version 1 calls it \"" + rename.Version1 +
        "\"; version 2 \"" + rename.Version2 + "\")");
    }
    if (section.contains(rename.Version1))
    {
      section[rename.Version2] = section[rename.Version1];
      section.erase(rename.Version1);
    }
  }
}

std::string InSceneVersion1Words(std::string message)
{
  for (const Version1Rename& rename : kVersion1Renames)
  {
    const std::string from = rename.Version2, to = rename.Version1;
    for (std::size_t at = message.find(from); at != std::string::npos;
         at = message.find(from, at + to.size()))
    {
      message.replace(at, from.size(), to);
    }
  }
  return message;
}
} // namespace nimbus
