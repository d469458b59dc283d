// The versioned JSON scene file (Reference/Core/SceneJson.h,
// docs/scene-format.md): the project's scenes parse, round trip, hashing,
// error messages (each starts with the key path), sun.direction, relative paths.
#include "SceneJson.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <random>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#ifndef NIMBUS_SCENES_DIR
#error "NIMBUS_SCENES_DIR must name Data/Scenes"
#endif
#ifndef NIMBUS_TEST_DATA_DIR
#error "NIMBUS_TEST_DATA_DIR must name Testing/Data"
#endif

namespace
{
namespace fs = std::filesystem;
using nimbus::SceneDescription;
using Json = nlohmann::ordered_json;

/// Field-by-field comparison (SceneDescription has no operator==).
void ExpectSameScene(const SceneDescription& a, const SceneDescription& b)
{
  EXPECT_EQ(a.Name, b.Name);
  EXPECT_EQ(a.Description, b.Description);
  EXPECT_EQ(a.Camera.Position, b.Camera.Position);
  EXPECT_EQ(a.Camera.FocalPoint, b.Camera.FocalPoint);
  EXPECT_EQ(a.Camera.ViewUp, b.Camera.ViewUp);
  EXPECT_EQ(a.Camera.ViewAngle, b.Camera.ViewAngle);
  EXPECT_EQ(a.Camera.Width, b.Camera.Width);
  EXPECT_EQ(a.Camera.Height, b.Camera.Height);
  EXPECT_EQ(a.Medium.Density.Type, b.Medium.Density.Type);
  EXPECT_EQ(a.Medium.Density.Path, b.Medium.Density.Path);
  EXPECT_EQ(a.Medium.Density.ArrayName, b.Medium.Density.ArrayName);
  EXPECT_EQ(a.Medium.Density.Parameters, b.Medium.Density.Parameters);
  EXPECT_EQ(a.Medium.ExtinctionPerDensity, b.Medium.ExtinctionPerDensity);
  EXPECT_EQ(a.Medium.SingleScatteringAlbedo, b.Medium.SingleScatteringAlbedo);
  ASSERT_EQ(a.Medium.Phase.size(), b.Medium.Phase.size());
  for (std::size_t i = 0; i < a.Medium.Phase.size(); ++i)
  {
    EXPECT_EQ(a.Medium.Phase[i].Type, b.Medium.Phase[i].Type);
    EXPECT_EQ(a.Medium.Phase[i].G, b.Medium.Phase[i].G);
    EXPECT_EQ(a.Medium.Phase[i].Weight, b.Medium.Phase[i].Weight);
  }
  EXPECT_EQ(a.Sun.AzimuthDegrees, b.Sun.AzimuthDegrees);
  EXPECT_EQ(a.Sun.ElevationDegrees, b.Sun.ElevationDegrees);
  EXPECT_EQ(a.Sun.Illuminance, b.Sun.Illuminance);
  EXPECT_EQ(a.Sun.TemperatureKelvin, b.Sun.TemperatureKelvin);
  const auto &x = a.Atmosphere, &y = b.Atmosphere;
  EXPECT_EQ(x.Enabled, y.Enabled);
  EXPECT_EQ(x.SceneAltitudeMetres, y.SceneAltitudeMetres);
  EXPECT_EQ(x.EarthRadiusMetres, y.EarthRadiusMetres);
  EXPECT_EQ(x.TopRadiusMetres, y.TopRadiusMetres);
  EXPECT_EQ(x.RayleighScatteringPerMetre, y.RayleighScatteringPerMetre);
  EXPECT_EQ(x.RayleighScaleHeightMetres, y.RayleighScaleHeightMetres);
  EXPECT_EQ(x.MieScatteringPerMetre, y.MieScatteringPerMetre);
  EXPECT_EQ(x.MieScaleHeightMetres, y.MieScaleHeightMetres);
  EXPECT_EQ(x.MieAlbedo, y.MieAlbedo);
  EXPECT_EQ(x.MieG, y.MieG);
  EXPECT_EQ(a.Ground.Enabled, b.Ground.Enabled);
  EXPECT_EQ(a.Ground.Height, b.Ground.Height);
  EXPECT_EQ(a.Ground.Albedo, b.Ground.Albedo);
  EXPECT_EQ(a.Background.Type, b.Background.Type);
  EXPECT_EQ(a.Background.Radiance, b.Background.Radiance);
  EXPECT_EQ(a.SpectralSamples, b.SpectralSamples);
  // Version 3.
  auto sameEmission = [](const nimbus::EmissionDescription& x, const nimbus::EmissionDescription& y)
  {
    EXPECT_EQ(x.Enabled, y.Enabled);
    EXPECT_EQ(x.Source, y.Source);
    EXPECT_EQ(x.ArrayName, y.ArrayName);
    EXPECT_EQ(x.RadiancePerMetre, y.RadiancePerMetre);
    EXPECT_EQ(x.TemperatureKelvin, y.TemperatureKelvin);
  };
  sameEmission(a.Medium.Emission, b.Medium.Emission);
  ASSERT_EQ(a.Lights.size(), b.Lights.size());
  for (std::size_t i = 0; i < a.Lights.size(); ++i)
  {
    EXPECT_EQ(a.Lights[i].Type, b.Lights[i].Type);
    EXPECT_EQ(a.Lights[i].TemperatureKelvin, b.Lights[i].TemperatureKelvin);
    if (a.Lights[i].Type == "point")
    {
      EXPECT_EQ(a.Lights[i].Position, b.Lights[i].Position);
      EXPECT_EQ(a.Lights[i].Intensity, b.Lights[i].Intensity);
    }
    else if (a.Lights[i].Type == "spot")
    {
      EXPECT_EQ(a.Lights[i].Position, b.Lights[i].Position);
      EXPECT_EQ(a.Lights[i].Intensity, b.Lights[i].Intensity);
      EXPECT_EQ(a.Lights[i].Direction, b.Lights[i].Direction);
      EXPECT_EQ(a.Lights[i].ConeAngleDegrees, b.Lights[i].ConeAngleDegrees);
      EXPECT_EQ(a.Lights[i].EdgeDegrees, b.Lights[i].EdgeDegrees);
      EXPECT_EQ(a.Lights[i].LightMap.Path, b.Lights[i].LightMap.Path);
    }
    else
    {
      EXPECT_EQ(a.Lights[i].Vertices, b.Lights[i].Vertices);
      EXPECT_EQ(a.Lights[i].IntensityPerMetre, b.Lights[i].IntensityPerMetre);
    }
  }
  ASSERT_EQ(a.Media.size(), b.Media.size());
  for (std::size_t i = 0; i < a.Media.size(); ++i)
  {
    EXPECT_EQ(a.Media[i].Density.Type, b.Media[i].Density.Type);
    EXPECT_EQ(a.Media[i].Density.Path, b.Media[i].Density.Path);
    EXPECT_EQ(a.Media[i].Density.ArrayName, b.Media[i].Density.ArrayName);
    EXPECT_EQ(a.Media[i].Density.Parameters, b.Media[i].Density.Parameters);
    EXPECT_EQ(a.Media[i].ExtinctionPerDensity, b.Media[i].ExtinctionPerDensity);
    EXPECT_EQ(a.Media[i].SingleScatteringAlbedo, b.Media[i].SingleScatteringAlbedo);
    ASSERT_EQ(a.Media[i].Phase.size(), b.Media[i].Phase.size());
    for (std::size_t k = 0; k < a.Media[i].Phase.size(); ++k)
    {
      EXPECT_EQ(a.Media[i].Phase[k].Type, b.Media[i].Phase[k].Type);
      EXPECT_EQ(a.Media[i].Phase[k].G, b.Media[i].Phase[k].G);
      EXPECT_EQ(a.Media[i].Phase[k].Weight, b.Media[i].Phase[k].Weight);
    }
    sameEmission(a.Media[i].Emission, b.Media[i].Emission);
  }
  // Version 4.
  ASSERT_EQ(a.Occluders.size(), b.Occluders.size());
  for (std::size_t i = 0; i < a.Occluders.size(); ++i)
  {
    const nimbus::OccluderDescription &x = a.Occluders[i], &y = b.Occluders[i];
    EXPECT_EQ(x.Type, y.Type);
    EXPECT_EQ(x.Albedo, y.Albedo);
    if (x.Type == "box")
    {
      EXPECT_EQ(x.Min, y.Min);
      EXPECT_EQ(x.Max, y.Max);
    }
    else
    {
      EXPECT_EQ(x.Path, y.Path);
      EXPECT_EQ(x.Translate, y.Translate);
      EXPECT_EQ(x.Scale, y.Scale);
    }
  }
}

/// The smallest valid scene text.
Json MinimalJson()
{
  return Json::parse(R"({
    "nimbus_scene": 2,
    "camera": { "position": [0, -6000, 1500], "focal_point": [0, 0, 1600] },
    "medium": { "density": { "type": "metaball_cloud" }, "extinction_per_density": 0.02 },
    "sun": { "azimuth_degrees": 135, "elevation_degrees": 45 }
  })");
}

SceneDescription Parse(const Json& j, const std::string& base = "/scenes")
{
  return nimbus::ParseScene(j.dump(), base);
}

/// A scene in which every field differs from the struct defaults.
SceneDescription NonDefaultScene()
{
  SceneDescription s;
  s.Name = "everything";
  s.Description = "Every field set; \"quotes\", unicode \u00b0 and\nnewlines.";
  s.Camera.Position = { { 1.25, -7000.5, 1234.0 } };
  s.Camera.FocalPoint = { { 10.0, 20.0, 1700.0 } };
  s.Camera.ViewUp = { { 0.1, 0.0, 1.0 } };
  s.Camera.ViewAngle = 27.5;
  s.Camera.Width = 320;
  s.Camera.Height = 240;
  s.Medium.Density.Type = "file";
  s.Medium.Density.Path = "/data/clouds/cloud.vti";
  s.Medium.Density.ArrayName = "lwc";
  s.Medium.ExtinctionPerDensity = 0.0375;
  s.Medium.SingleScatteringAlbedo = 0.999;
  s.Medium.Phase = { { "henyey_greenstein", 0.9, 0.7 }, { "henyey_greenstein", -0.3, 0.3 },
    { "isotropic", 0.85, 0.1 } };
  s.Sun = { 271.5, 12.25, 3.5, 6000.0 };
  s.Atmosphere.Enabled = false;
  s.Atmosphere.SceneAltitudeMetres = 250.0;
  s.Atmosphere.EarthRadiusMetres = 6371000.0;
  s.Atmosphere.TopRadiusMetres = 6471000.0;
  s.Atmosphere.RayleighScatteringPerMetre = 1.1e-5;
  s.Atmosphere.RayleighScaleHeightMetres = 8500.0;
  s.Atmosphere.MieScatteringPerMetre = 1.0e-4;
  s.Atmosphere.MieScaleHeightMetres = 900.0;
  s.Atmosphere.MieAlbedo = 0.95;
  s.Atmosphere.MieG = 0.7;
  s.Ground = { false, 12.0, 0.35 };
  s.Background = { "constant", 0.125 };
  s.SpectralSamples = 24;
  return s;
}

/// NonDefaultScene with every version-3 feature: a point light, a polyline, emission
/// from an array, and two additional media (one emitting from its density).
SceneDescription Version3Scene()
{
  SceneDescription s = NonDefaultScene();
  s.Name = "version3";
  s.Medium.Emission = { true, "array", "temperature", 0.25, 1200.0 };
  nimbus::LightDescription point;
  point.Type = "point";
  point.Position = { { 10.0, -20.0, 1500.5 } };
  point.Intensity = 2.5e6;
  point.TemperatureKelvin = 3000.0;
  nimbus::LightDescription channel;
  channel.Type = "polyline";
  channel.Vertices = { { { 0.0, 0.0, 3000.0 } }, { { 50.0, 10.0, 2000.0 } },
    { { 20.0, -30.0, 0.0 } } };
  channel.IntensityPerMetre = 1.0e4;
  channel.TemperatureKelvin = 28000.0;
  s.Lights = { point, channel };
  nimbus::AdditionalMediumDescription smoke;
  smoke.Density.Type = "file";
  smoke.Density.Path = "/data/clouds/smoke.vti";
  smoke.Density.ArrayName = "soot";
  smoke.ExtinctionPerDensity = 0.5;
  smoke.SingleScatteringAlbedo = 0.3;
  smoke.Phase = { { "henyey_greenstein", 0.4, 1.0 } };
  smoke.Emission = { true, "from_density", "", 2.0, 900.0 };
  nimbus::AdditionalMediumDescription haze;
  haze.Density.Type = "file";
  haze.Density.Path = "/data/clouds/cloud.vti";
  haze.Density.ArrayName = "haze";
  haze.ExtinctionPerDensity = 0.001;
  haze.SingleScatteringAlbedo = 1.0;
  haze.Phase = { { "isotropic", 0.85, 1.0 } };
  s.Media = { smoke, haze };
  return s;
}

/// Version3Scene with every version-4 feature: a soft-edged spot with a light map, a hard
/// one without, a box occluder and a placed mesh.
SceneDescription Version4Scene()
{
  SceneDescription s = Version3Scene();
  s.Name = "version4";
  nimbus::LightDescription spot;
  spot.Type = "spot";
  spot.Position = { { 5.0, -3.0, 8.5 } };
  spot.Direction = { { 0.0, 0.5, -2.0 } };
  spot.ConeAngleDegrees = 25.0;
  spot.EdgeDegrees = 4.5;
  spot.Intensity = 3.0e4;
  spot.TemperatureKelvin = 3200.0;
  spot.LightMap.Path = "/data/gobos/leaves.png";
  nimbus::LightDescription hard = spot;
  hard.Direction = { { 1.0, 0.0, 0.0 } };
  hard.EdgeDegrees = 0.0;
  hard.LightMap.Path.clear();
  s.Lights.push_back(spot);
  s.Lights.push_back(hard);
  nimbus::OccluderDescription box;
  box.Type = "box";
  box.Min = { { -1.0, -2.0, 0.0 } };
  box.Max = { { 1.0, 2.0, 0.0 } }; // flat
  box.Albedo = 0.3;
  nimbus::OccluderDescription mesh;
  mesh.Type = "mesh";
  mesh.Path = "/data/meshes/post.ply";
  mesh.Translate = { { 2.0, 0.0, -0.5 } };
  mesh.Scale = 0.01;
  mesh.Albedo = 0.0;
  s.Occluders = { box, mesh };
  return s;
}

SceneDescription MetaballScene()
{
  SceneDescription s;
  s.Name = "metaballs";
  s.Medium.Density.Parameters = { { "Dimensions", { 64, 48, 32 } },
    { "Bounds", { -1000, 1000, -900, 900, 700, 2500 } }, { "Seed", { -7 } },
    { "NumberOfLevels", { 2 } }, { "NumberOfBaseBalls", { 12 } },
    { "BaseBallRadiusRange", { 300, 550.5 } }, { "FootprintRadius", { 650 } },
    { "TowerHeight", { 500 } }, { "BallsPerLevel", { 40 } }, { "BallCountFactor", { 1.5 } },
    { "RadiusScalePerLevel", { 0.45 } }, { "BallDensity", { 0.8 } }, { "IsoValue", { 0.4 } },
    { "FlatBase", { 0 } }, { "BaseHeight", { 900 } }, { "BaseTransitionThickness", { 80 } } };
  return s;
}

/// Expects ParseScene to throw std::invalid_argument whose message starts with `prefix`.
void ExpectErrorText(const std::string& text, const std::string& prefix)
{
  try
  {
    nimbus::ParseScene(text, "/scenes");
    ADD_FAILURE() << "no error; expected one starting with '" << prefix << "' for\n" << text;
  }
  catch (const std::invalid_argument& error)
  {
    const std::string message = error.what();
    EXPECT_EQ(message.rfind(prefix, 0), 0u)
      << "message: " << message << "\nexpected prefix: " << prefix;
  }
}

void ExpectError(const Json& j, const std::string& prefix)
{
  ExpectErrorText(j.dump(), prefix);
}

/// A scene with one value set (JSON pointer) or removed.
Json Set(Json j, const std::string& pointer, const Json& value)
{
  j[Json::json_pointer(pointer)] = value;
  return j;
}

Json Remove(Json j, const std::string& pointer)
{
  const Json::json_pointer p(pointer);
  j[p.parent_pointer()].erase(p.back());
  return j;
}

/// MinimalJson with one value set or removed.
Json With(const std::string& pointer, const Json& value)
{
  return Set(MinimalJson(), pointer, value);
}

Json Without(const std::string& pointer)
{
  return Remove(MinimalJson(), pointer);
}

fs::path MakeTemporaryDirectory(const std::string& name)
{
  const fs::path dir =
    fs::temp_directory_path() / (name + "-" + std::to_string(std::random_device{}()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}
} // namespace

//------------------------------------------------------------------------------
TEST(SceneJson, ProjectScenesParse)
{
  // The sun-lit scenes, and (format version 4) the scenes lit by lights: a streetlight in
  // fog behind a post, a spot through a gobo in haze, a searchlight under a cloud.
  const std::set<std::string> expected = { "cumulus_noon", "cumulus_sunset", "silver_lining",
    "haze_shafts", "cumulonimbus", "streetlight_fog", "gobo_haze", "searchlight_cloud" };
  std::set<std::string> found;
  for (const auto& entry : fs::directory_iterator(NIMBUS_SCENES_DIR))
  {
    if (entry.path().extension() != ".json")
    {
      continue;
    }
    SCOPED_TRACE(entry.path().string());
    SceneDescription scene;
    ASSERT_NO_THROW(scene = nimbus::LoadScene(entry.path().string()));
    found.insert(entry.path().stem().string());
    EXPECT_EQ(scene.Name, entry.path().stem().string());
    EXPECT_FALSE(scene.Description.empty());
    // Small by default, everything generated (no data file needed).
    EXPECT_LE(scene.Camera.Width * scene.Camera.Height, 320 * 256);
    EXPECT_EQ(scene.SpectralSamples, 16);
    EXPECT_EQ(scene.Medium.Density.Type, "metaball_cloud");
    for (const auto& p : scene.Medium.Density.Parameters)
    {
      if (p.first == "Dimensions")
      {
        EXPECT_LE(p.second[0] * p.second[1] * p.second[2], 1.0e6)
          << "grid too large to render fast";
      }
    }
    ExpectSameScene(nimbus::ParseScene(nimbus::SceneToJson(scene), ""), scene);
  }
  EXPECT_EQ(found, expected);
}

TEST(SceneJson, ProjectScenesPhysics)
{
  const std::string dir = NIMBUS_SCENES_DIR;
  const SceneDescription noon = nimbus::LoadScene(dir + "/cumulus_noon.json");
  const SceneDescription sunset = nimbus::LoadScene(dir + "/cumulus_sunset.json");
  const SceneDescription silver = nimbus::LoadScene(dir + "/silver_lining.json");
  const SceneDescription haze = nimbus::LoadScene(dir + "/haze_shafts.json");
  const SceneDescription cb = nimbus::LoadScene(dir + "/cumulonimbus.json");
  EXPECT_NEAR(noon.Sun.ElevationDegrees, 65.0, 5.0);
  EXPECT_NEAR(sunset.Sun.ElevationDegrees, 5.0, 0.5);
  EXPECT_EQ(noon.Medium.Density.Parameters, sunset.Medium.Density.Parameters); // same cloud
  EXPECT_EQ(noon.Camera.Position, sunset.Camera.Position);
  EXPECT_TRUE(noon.Atmosphere.Enabled && noon.Ground.Enabled);
  EXPECT_EQ(noon.Background.Type, "atmosphere");
  // Silver lining: the camera looks toward the sun.
  const double kDegree = 3.14159265358979323846 / 180.0;
  const double sunToward[3] = { std::cos(silver.Sun.ElevationDegrees * kDegree) *
      std::sin(silver.Sun.AzimuthDegrees * kDegree),
    std::cos(silver.Sun.ElevationDegrees * kDegree) * std::cos(silver.Sun.AzimuthDegrees * kDegree),
    std::sin(silver.Sun.ElevationDegrees * kDegree) };
  double view[3], length = 0.0, dot = 0.0;
  for (int a = 0; a < 3; ++a)
  {
    view[a] = silver.Camera.FocalPoint[a] - silver.Camera.Position[a];
    length += view[a] * view[a];
  }
  for (int a = 0; a < 3; ++a)
  {
    dot += view[a] / std::sqrt(length) * sunToward[a];
  }
  EXPECT_GT(dot, std::cos(15.0 * kDegree));
  EXPECT_GE(silver.Medium.Phase.at(0).G, 0.8);
  EXPECT_GE(haze.Atmosphere.MieScatteringPerMetre, 5.0e-5);
  EXPECT_LT(haze.Atmosphere.MieScaleHeightMetres, 1200.0);
  EXPECT_GE(cb.Medium.ExtinctionPerDensity, 0.1);
  EXPECT_NE(cb.Description.find("optical thickness"), std::string::npos);
}

TEST(SceneJson, RoundTrip)
{
  for (const SceneDescription& s :
    { SceneDescription{}, NonDefaultScene(), MetaballScene(), Version3Scene(), Version4Scene() })
  {
    SCOPED_TRACE(s.Name);
    const std::string text = nimbus::SceneToJson(s);
    const SceneDescription back = nimbus::ParseScene(text, "/elsewhere");
    ExpectSameScene(back, s);
    EXPECT_EQ(nimbus::SceneToJson(back), text);
  }
}

TEST(SceneJson, DefaultsOfOptionalKeys)
{
  const SceneDescription s = Parse(MinimalJson());
  const SceneDescription d;
  SceneDescription expected = d;
  expected.Camera.FocalPoint = { { 0.0, 0.0, 1600.0 } };
  ExpectSameScene(s, expected);
  EXPECT_TRUE(s.Medium.Density.Parameters.empty());
}

TEST(SceneJson, CanonicalForm)
{
  const std::string text = nimbus::SceneToJson(MetaballScene());
  // Fixed key order, integers and booleans where the property is one.
  EXPECT_LT(text.find("\"nimbus_scene\": 4"), text.find("\"camera\""));
  // Version 3's and version 4's keys are written only when used.
  EXPECT_EQ(text.find("\"lights\""), std::string::npos);
  EXPECT_EQ(text.find("\"media\""), std::string::npos);
  EXPECT_EQ(text.find("\"emission\""), std::string::npos);
  EXPECT_EQ(text.find("\"occluders\""), std::string::npos);
  EXPECT_NE(text.find("\"Seed\": -7"), std::string::npos);
  EXPECT_NE(text.find("\"FlatBase\": false"), std::string::npos);
  EXPECT_NE(text.find("\"width\": 256"), std::string::npos);
  EXPECT_EQ(text.back(), '\n');
  // Parameters are stored in the source's property order, whatever the text's order.
  Json j =
    With("/medium/density/parameters", Json::parse(R"({"Seed": 4, "Dimensions": [8, 8, 8]})"));
  const SceneDescription s = Parse(j);
  ASSERT_EQ(s.Medium.Density.Parameters.size(), 2u);
  EXPECT_EQ(s.Medium.Density.Parameters[0].first, "Dimensions");
  EXPECT_EQ(s.Medium.Density.Parameters[1].first, "Seed");
  j = With("/medium/density/parameters", Json::parse(R"({"Dimensions": [8, 8, 8], "Seed": [4]})"));
  EXPECT_EQ(nimbus::SceneHash(Parse(j)), nimbus::SceneHash(s));
}

TEST(SceneJson, HashStable)
{
  const SceneDescription s = NonDefaultScene();
  const std::string hash = nimbus::SceneHash(s);
  ASSERT_EQ(hash.size(), 16u);
  EXPECT_EQ(hash.find_first_not_of("0123456789abcdef"), std::string::npos);
  EXPECT_EQ(nimbus::SceneHash(s), hash);
  // Pinned: the canonical form (and so every cached reference image's key) changes only
  // on purpose. Update this when a field is added or the format changes deliberately.
  // Version 3 changed it from 5e1d742df6799b74 (version 2) by the version number alone,
  // and version 4 from da42e138a75ee723 (version 3) the same way.
  EXPECT_EQ(hash, "679165bfed029662"); // format version 4
  EXPECT_EQ(nimbus::SceneHash(nimbus::ParseScene(nimbus::SceneToJson(s), "")), hash);
  // Formatting and key order of the text do not matter, only the description.
  Json a = MinimalJson(), b = Json::parse(R"({
    "sun": {"elevation_degrees": 45.0, "azimuth_degrees": 135},
    "medium": {"extinction_per_density": 2e-2, "density": {"type": "metaball_cloud"}},
    "camera": {"focal_point": [0, 0, 1600], "position": [0.0, -6000, 1.5e3]},
    "nimbus_scene": 2})");
  EXPECT_EQ(nimbus::SceneHash(Parse(a)), nimbus::SceneHash(Parse(b)));
}

namespace
{
/// A named change of one field of a scene.
using Mutation = std::pair<const char*, std::function<void(SceneDescription&)>>;

/// Each mutation of base gives a hash that neither base nor any other mutation has.
void ExpectEachMutationChangesTheHash(
  const SceneDescription& base, const std::vector<Mutation>& mutations)
{
  std::set<std::string> hashes = { nimbus::SceneHash(base) };
  for (const auto& mutation : mutations)
  {
    SceneDescription changed = base;
    mutation.second(changed);
    EXPECT_TRUE(hashes.insert(nimbus::SceneHash(changed)).second)
      << "changing " << mutation.first << " did not change the hash";
  }
}
} // namespace

TEST(SceneJson, HashSensitiveToEveryField)
{
  const std::vector<Mutation> mutations = {
    { "Name", [](SceneDescription& s) { s.Name += "x"; } },
    { "Description", [](SceneDescription& s) { s.Description += "x"; } },
    { "Camera.Position", [](SceneDescription& s) { s.Camera.Position[0] += 1; } },
    { "Camera.Position[2]", [](SceneDescription& s) { s.Camera.Position[2] += 1e-9; } },
    { "Camera.FocalPoint", [](SceneDescription& s) { s.Camera.FocalPoint[1] += 1; } },
    { "Camera.ViewUp", [](SceneDescription& s) { s.Camera.ViewUp[0] += 0.1; } },
    { "Camera.ViewAngle", [](SceneDescription& s) { s.Camera.ViewAngle += 1; } },
    { "Camera.Width", [](SceneDescription& s) { s.Camera.Width += 1; } },
    { "Camera.Height", [](SceneDescription& s) { s.Camera.Height += 1; } },
    { "Density.Type", [](SceneDescription& s) { s.Medium.Density.Type = "metaball_cloud"; } },
    { "Density.Path", [](SceneDescription& s) { s.Medium.Density.Path += "x"; } },
    { "Density.ArrayName", [](SceneDescription& s) { s.Medium.Density.ArrayName += "x"; } },
    { "Density.Parameters",
      [](SceneDescription& s) {
        s.Medium.Density.Parameters.push_back({ "Seed", { 2 } });
      } },
    { "ExtinctionPerDensity", [](SceneDescription& s) { s.Medium.ExtinctionPerDensity *= 1.01; } },
    { "SingleScatteringAlbedo",
      [](SceneDescription& s) { s.Medium.SingleScatteringAlbedo -= 0.001; } },
    { "Phase.size", [](SceneDescription& s) { s.Medium.Phase.pop_back(); } },
    { "Phase.Type", [](SceneDescription& s) { s.Medium.Phase[0].Type = "cornette_shanks"; } },
    { "Phase.G", [](SceneDescription& s) { s.Medium.Phase[1].G += 0.01; } },
    { "Phase.Weight", [](SceneDescription& s) { s.Medium.Phase[2].Weight += 0.01; } },
    { "Sun.AzimuthDegrees", [](SceneDescription& s) { s.Sun.AzimuthDegrees += 1; } },
    { "Sun.ElevationDegrees", [](SceneDescription& s) { s.Sun.ElevationDegrees += 1; } },
    { "Sun.Illuminance", [](SceneDescription& s) { s.Sun.Illuminance += 1; } },
    { "Sun.TemperatureKelvin", [](SceneDescription& s) { s.Sun.TemperatureKelvin += 1; } },
    { "Atmosphere.Enabled", [](SceneDescription& s) { s.Atmosphere.Enabled = true; } },
    { "Atmosphere.SceneAltitudeMetres",
      [](SceneDescription& s) { s.Atmosphere.SceneAltitudeMetres += 1; } },
    { "Atmosphere.EarthRadiusMetres",
      [](SceneDescription& s) { s.Atmosphere.EarthRadiusMetres += 1; } },
    { "Atmosphere.TopRadiusMetres",
      [](SceneDescription& s) { s.Atmosphere.TopRadiusMetres += 1; } },
    { "Atmosphere.RayleighScatteringPerMetre",
      [](SceneDescription& s) { s.Atmosphere.RayleighScatteringPerMetre *= 1.01; } },
    { "Atmosphere.RayleighScaleHeightMetres",
      [](SceneDescription& s) { s.Atmosphere.RayleighScaleHeightMetres += 1; } },
    { "Atmosphere.MieScatteringPerMetre",
      [](SceneDescription& s) { s.Atmosphere.MieScatteringPerMetre *= 1.01; } },
    { "Atmosphere.MieScaleHeightMetres",
      [](SceneDescription& s) { s.Atmosphere.MieScaleHeightMetres += 1; } },
    { "Atmosphere.MieAlbedo", [](SceneDescription& s) { s.Atmosphere.MieAlbedo -= 0.01; } },
    { "Atmosphere.MieG", [](SceneDescription& s) { s.Atmosphere.MieG += 0.01; } },
    { "Ground.Enabled", [](SceneDescription& s) { s.Ground.Enabled = true; } },
    { "Ground.Height", [](SceneDescription& s) { s.Ground.Height += 1; } },
    { "Ground.Albedo", [](SceneDescription& s) { s.Ground.Albedo += 0.01; } },
    { "Background.Type", [](SceneDescription& s) { s.Background.Type = "black"; } },
    { "Background.Radiance", [](SceneDescription& s) { s.Background.Radiance += 0.01; } },
    { "SpectralSamples", [](SceneDescription& s) { s.SpectralSamples += 1; } },
  };
  ExpectEachMutationChangesTheHash(NonDefaultScene(), mutations);
  // And each metaball parameter's value.
  const SceneDescription metaballs = MetaballScene();
  std::set<std::string> hashes = { nimbus::SceneHash(metaballs) };
  for (std::size_t i = 0; i < metaballs.Medium.Density.Parameters.size(); ++i)
  {
    SceneDescription changed = metaballs;
    auto& values = changed.Medium.Density.Parameters[i].second;
    values.back() = values.back() == 0.0 ? 1.0 : values.back() + 1.0;
    EXPECT_TRUE(hashes.insert(nimbus::SceneHash(changed)).second)
      << "changing " << metaballs.Medium.Density.Parameters[i].first;
  }
}

TEST(SceneJson, Errors)
{
  // Syntax, top level and version.
  ExpectErrorText("{\"nimbus_scene\": 2,", "scene");
  ExpectErrorText("[1, 2]", "scene: expected an object");
  ExpectError(Without("/nimbus_scene"), "scene: missing required key \"nimbus_scene\"");
  ExpectError(With("/nimbus_scene", 5),
    "scene.nimbus_scene: unsupported format version 5; this build of Nimbus reads versions 1 to 4");
  ExpectError(With("/nimbus_scene", 0), "scene.nimbus_scene: unsupported format version 0");
  ExpectError(With("/nimbus_scene", "2"), "scene.nimbus_scene: expected the format version");
  ExpectError(With("/nimbus_scene", 1.5), "scene.nimbus_scene: expected the format version");
  ExpectError(With("/colour", 1), "scene.colour: unknown key (known: nimbus_scene, name,");
  ExpectErrorText(R"({"nimbus_scene": 2, "nimbus_scene": 2})", "scene.nimbus_scene: duplicate key");
  ExpectErrorText(R"({"nimbus_scene": 2, "sun": {"elevation_degrees": 1, "elevation_degrees": 2}})",
    "scene.sun.elevation_degrees: duplicate key");
  ExpectError(With("/name", 3), "scene.name: expected a string, got 3");
  ExpectError(
    With("/spectral_samples", 2), "scene.spectral_samples: expected an integer in [3, 256], got 2");
  ExpectError(With("/spectral_samples", 16.5), "scene.spectral_samples: expected an integer");
  // Huge numbers (JSON cannot hold NaN or Inf; 1e999 overflows).
  {
    std::string text = MinimalJson().dump();
    const std::string key = "\"elevation_degrees\":45";
    ASSERT_NE(text.find(key), std::string::npos);
    text.replace(text.find(key), key.size(), "\"elevation_degrees\":1e999");
    ExpectErrorText(text, "scene.sun.elevation_degrees: invalid JSON");
  }

  // Required sections and keys.
  ExpectError(Without("/camera"), "scene: missing required key \"camera\"");
  ExpectError(Without("/medium"), "scene: missing required key \"medium\"");
  ExpectError(Without("/sun"), "scene: missing required key \"sun\"");
  ExpectError(
    Without("/sun/elevation_degrees"), "scene.sun: missing required key \"elevation_degrees\"");
  ExpectError(
    Without("/sun/azimuth_degrees"), "scene.sun: missing required key \"azimuth_degrees\"");
  ExpectError(Without("/camera/position"), "scene.camera: missing required key \"position\"");
  ExpectError(Without("/medium/density"), "scene.medium: missing required key \"density\"");
  ExpectError(
    Without("/medium/density/type"), "scene.medium.density: missing required key \"type\"");
  ExpectError(Without("/medium/extinction_per_density"),
    "scene.medium: missing required key \"extinction_per_density\"");

  // Camera.
  ExpectError(With("/camera/posiiton", Json::array({ 0, 0, 0 })),
    "scene.camera.posiiton: unknown key (known: position, focal_point, view_up, view_angle, width, "
    "height)");
  ExpectError(With("/camera", 5), "scene.camera: expected an object, got 5");
  ExpectError(With("/camera/position", Json::array({ 0, 0 })),
    "scene.camera.position: expected an array of 3 numbers, got 2 elements");
  ExpectError(With("/camera/position", Json::array({ 0, "a", 0 })),
    "scene.camera.position[1]: expected a number in [-1000000000, 1000000000], got the string "
    "\"a\"");
  ExpectError(With("/camera/focal_point", Json::array({ 0, -6000, 1500 })),
    "scene.camera.focal_point: must differ from camera.position");
  ExpectError(With("/camera/view_up", Json::array({ 0, 6000, 100 })), "scene.camera.view_up:");
  ExpectError(With("/camera/view_up", Json::array({ 0, 0, 0 })), "scene.camera.view_up:");
  ExpectError(With("/camera/view_angle", 180),
    "scene.camera.view_angle: expected a number in (0, 180), got 180");
  ExpectError(
    With("/camera/width", 0), "scene.camera.width: expected an integer in [1, 16384], got 0");
  ExpectError(
    With("/camera/height", -5), "scene.camera.height: expected an integer in [1, 16384], got -5");
  ExpectError(With("/camera/width", true),
    "scene.camera.width: expected an integer in [1, 16384], got the boolean true");

  // Medium.
  ExpectError(With("/medium/extinction_per_density", -1),
    "scene.medium.extinction_per_density: expected a number in [0, 1000], got -1");
  ExpectError(With("/medium/extinction_per_density", "0.02"),
    "scene.medium.extinction_per_density: expected a number in [0, 1000], got the string \"0.02\"");
  ExpectError(With("/medium/single_scattering_albedo", 1.01),
    "scene.medium.single_scattering_albedo: expected a number in [0, 1], got 1.01");
  ExpectError(With("/medium/phase", Json::parse(R"([{"type": "cornette_shanks", "g": 1.5}])")),
    "scene.medium.phase[0].g: expected a number in [-1, 1], got 1.5");
  ExpectError(
    With("/medium/phase", Json::parse(R"([{"type": "isotropic"}, {"type": "mie", "g": 0.5}])")),
    "scene.medium.phase[1].type: unknown value \"mie\" (known: isotropic, rayleigh, "
    "henyey_greenstein, cornette_shanks)");
  ExpectError(With("/medium/phase", Json::parse(R"([{"type": "henyey_greenstein"}])")),
    "scene.medium.phase[0]: missing required key \"g\"");
  ExpectError(With("/medium/phase", Json::parse(R"([{"type": "isotropic", "weight": -1}])")),
    "scene.medium.phase[0].weight: expected a number in [0, 1000000], got -1");
  ExpectError(With("/medium/phase", Json::parse(R"([{"type": "isotropic", "weight": 0}])")),
    "scene.medium.phase: the weights must not all be zero");
  ExpectError(With("/medium/phase", Json::array()), "scene.medium.phase: expected at least one");
  ExpectError(With("/medium/phase", "isotropic"), "scene.medium.phase: expected a phase component");
  ExpectError(With("/medium/phase", Json::parse(R"({"type": "isotropic", "gg": 1})")),
    "scene.medium.phase.gg: unknown key");
  ExpectError(With("/medium/density/type", "vdb"),
    "scene.medium.density.type: unknown value \"vdb\" (known: file, metaball_cloud)");
  ExpectError(With("/medium/density", Json::parse(R"({"type": "file"})")),
    "scene.medium.density: missing required key \"path\"");
  ExpectError(With("/medium/density", Json::parse(R"({"type": "file", "path": ""})")),
    "scene.medium.density.path: expected a non-empty string");
  ExpectError(With("/medium/density",
                Json::parse(R"({"type": "file", "path": "a.vti", "parameters": {"Seed": 1}})")),
    "scene.medium.density.parameters: only used by type \"metaball_cloud\"");
  ExpectError(
    With("/medium/density/path", "a.vti"), "scene.medium.density.path: only used by type \"file\"");
  ExpectError(With("/medium/density/array", "lwc"), "scene.medium.density.array:");

  // Metaball parameters: names, counts, values.
  const std::string parameters = "/medium/density/parameters";
  ExpectError(With(parameters + "/Dimension", Json::array({ 8, 8, 8 })),
    "scene.medium.density.parameters.Dimension: unknown metaball_cloud parameter (known: "
    "Dimensions, Bounds, Seed,");
  ExpectError(With(parameters + "/Dimensions", Json::array({ 8, 8 })),
    "scene.medium.density.parameters.Dimensions: expected 3 values, got 2");
  ExpectError(With(parameters + "/Dimensions", 8),
    "scene.medium.density.parameters.Dimensions: expected an array of 3 numbers, got 8");
  ExpectError(With(parameters + "/Dimensions", Json::array({ 8, 0, 8 })),
    "scene.medium.density.parameters.Dimensions[1]: expected an integer in [1, 2048], got 0");
  ExpectError(With(parameters + "/Dimensions", Json::array({ 8, 8.5, 8 })),
    "scene.medium.density.parameters.Dimensions[1]: expected an integer");
  ExpectError(With(parameters + "/Dimensions", Json::array({ 2048, 2048, 2048 })),
    "scene.medium.density.parameters.Dimensions: too many grid points");
  ExpectError(With(parameters + "/Bounds", Json::array({ 0, 1, 0, 1, 0 })),
    "scene.medium.density.parameters.Bounds: expected 6 values, got 5");
  ExpectError(With(parameters + "/Bounds", Json::array({ 0, 1, 0, 1, 5, 2 })),
    "scene.medium.density.parameters.Bounds: expected min < max on every axis, axis z has (5, 2)");
  ExpectError(With(parameters + "/BaseBallRadiusRange", Json::array({ 600, 300 })),
    "scene.medium.density.parameters.BaseBallRadiusRange: expected min <= max");
  ExpectError(With(parameters + "/BaseBallRadiusRange", Json::array({ 0, 300 })),
    "scene.medium.density.parameters.BaseBallRadiusRange[0]: expected a number in (0, 100000000], "
    "got 0");
  ExpectError(With(parameters + "/Seed", Json::array({ 1, 2 })),
    "scene.medium.density.parameters.Seed: expected 1 value, got 2");
  ExpectError(
    With(parameters + "/Seed", 1e10), "scene.medium.density.parameters.Seed: expected an integer");
  ExpectError(With(parameters + "/NumberOfBaseBalls", 0),
    "scene.medium.density.parameters.NumberOfBaseBalls: expected an integer in [1, 100000], got 0");
  ExpectError(With(parameters + "/TowerHeight", -1),
    "scene.medium.density.parameters.TowerHeight: expected a number in [0, 100000000], got -1");
  ExpectError(With(parameters + "/RadiusScalePerLevel", 0),
    "scene.medium.density.parameters.RadiusScalePerLevel: expected a number in (0, 1], got 0");
  ExpectError(With(parameters + "/FlatBase", "yes"),
    "scene.medium.density.parameters.FlatBase: expected true or false");
  ExpectError(With(parameters + "/IsoValue", true),
    "scene.medium.density.parameters.IsoValue: expected a number in [-1000000, 1000000], got the "
    "boolean true");
  ExpectError(
    With(parameters, Json::array()), "scene.medium.density.parameters: expected an object");

  // Sun.
  ExpectError(With("/sun/elevation_degrees", 91),
    "scene.sun.elevation_degrees: expected a number in [-90, 90], got 91");
  ExpectError(With("/sun/azimuth_degrees", 1000),
    "scene.sun.azimuth_degrees: expected a number in [-360, 360], got 1000");
  ExpectError(With("/sun/illuminance", -1),
    "scene.sun.illuminance: expected a number in [0, 1000000], got -1");
  ExpectError(With("/sun/temperature_kelvin", 500),
    "scene.sun.temperature_kelvin: expected a number in [1000, 100000], got 500");
  ExpectError(With("/sun/direction", Json::array({ 0, 1, 1 })),
    "scene.sun.direction: give either direction or azimuth_degrees and elevation_degrees, not "
    "both");
  {
    Json j = MinimalJson();
    j["sun"] = Json::parse(R"({"direction": [0, 0, 0]})");
    ExpectError(j, "scene.sun.direction: must be a non-zero vector");
    j["sun"] = Json::parse(R"({"direction": [0, 1]})");
    ExpectError(j, "scene.sun.direction: expected an array of 3 numbers, got 2 elements");
    j["sun"] = Json::parse(R"({"direction": [0, 1, 1], "azimuth_degrees": 3})");
    ExpectError(j, "scene.sun.direction: give either");
  }

  // Atmosphere, ground, background.
  ExpectError(
    With("/atmosphere/enabled", 1), "scene.atmosphere.enabled: expected true or false, got 1");
  ExpectError(With("/atmosphere/top_radius_metres", 6000000),
    "scene.atmosphere.top_radius_metres: must be greater than earth_radius_metres");
  ExpectError(With("/atmosphere/earth_radius_metres", 0),
    "scene.atmosphere.earth_radius_metres: expected a number in [100000, 100000000], got 0");
  ExpectError(With("/atmosphere/scene_altitude_metres", -1),
    "scene.atmosphere.scene_altitude_metres: expected a number >= 0, got -1");
  ExpectError(With("/atmosphere/scene_altitude_metres", 70000),
    "scene.atmosphere.scene_altitude_metres: must be below the top");
  ExpectError(With("/atmosphere/mie_scattering_per_metre", -1e-5),
    "scene.atmosphere.mie_scattering_per_metre: expected a number in [0, 0.01]");
  ExpectError(With("/atmosphere/mie_scale_height_metres", 0),
    "scene.atmosphere.mie_scale_height_metres: expected a number in [1, 1000000]");
  ExpectError(With("/atmosphere/rayleigh_scale_height_metres", -8000),
    "scene.atmosphere.rayleigh_scale_height_metres: expected a number in [1, 1000000]");
  ExpectError(With("/atmosphere/mie_albedo", 0),
    "scene.atmosphere.mie_albedo: expected a number in (0, 1], got 0");
  ExpectError(
    With("/atmosphere/mie_g", 1), "scene.atmosphere.mie_g: expected a number in (-1, 1), got 1");
  ExpectError(With("/atmosphere/ozone", 1), "scene.atmosphere.ozone: unknown key");
  ExpectError(
    With("/ground/albedo", 1.5), "scene.ground.albedo: expected a number in [0, 1], got 1.5");
  ExpectError(With("/ground/height", nullptr),
    "scene.ground.height: expected a number in [-1000000000, 1000000000], got null");
  ExpectError(With("/background/type", "sky"),
    "scene.background.type: unknown value \"sky\" (known: black, constant, atmosphere)");
  ExpectError(With("/background/radiance", -0.5),
    "scene.background.radiance: expected a number in [0, 1000000], got -0.5");
  ExpectError(With("/atmosphere/enabled", false),
    "scene.background.type: \"atmosphere\" needs atmosphere.enabled");
}

TEST(SceneJson, PhaseAsSingleObject)
{
  const SceneDescription s =
    Parse(With("/medium/phase", Json::parse(R"({"type": "henyey_greenstein", "g": 0.6})")));
  ASSERT_EQ(s.Medium.Phase.size(), 1u);
  EXPECT_EQ(s.Medium.Phase[0].Type, "henyey_greenstein");
  EXPECT_EQ(s.Medium.Phase[0].G, 0.6);
  EXPECT_EQ(s.Medium.Phase[0].Weight, 1.0);
  const SceneDescription iso =
    Parse(With("/medium/phase", Json::parse(R"({"type": "isotropic"})")));
  EXPECT_EQ(iso.Medium.Phase[0].Type, "isotropic");
}

TEST(SceneJson, SunDirection)
{
  struct Case
  {
    std::array<double, 3> Direction;
    double Azimuth, Elevation;
  };
  const std::vector<Case> cases = {
    { { { 0, 1, 0 } }, 0, 0 },                                // north, on the horizon
    { { { 1, 0, 0 } }, 90, 0 },                               // east
    { { { 0, -1, 1 } }, 180, 45 },                            // south, 45 degrees up
    { { { -2, 0, 0 } }, 270, 0 },                             // west, not unit length
    { { { 0, 0, 5 } }, 0, 90 },                               // zenith: azimuth 0 by convention
    { { { 1, 1, 0 } }, 45, 0 }, { { { 0, 1, -1 } }, 0, -45 }, // below the horizon
  };
  for (const Case& c : cases)
  {
    Json j = MinimalJson();
    j["sun"] = Json{ { "direction", c.Direction }, { "illuminance", 2.0 } };
    const SceneDescription s = Parse(j);
    EXPECT_NEAR(s.Sun.AzimuthDegrees, c.Azimuth, 1e-12) << c.Direction[0] << " " << c.Direction[1];
    EXPECT_NEAR(s.Sun.ElevationDegrees, c.Elevation, 1e-12);
    EXPECT_EQ(s.Sun.Illuminance, 2.0);
    EXPECT_FALSE(std::signbit(s.Sun.AzimuthDegrees));
  }
  // Inverse of RenderContext's (cos e sin a, cos e cos a, sin e).
  const double kDegree = 3.14159265358979323846 / 180.0;
  const std::array<double, 3> d{ { 0.3, -0.5, 0.4 } };
  Json j = MinimalJson();
  j["sun"] = Json{ { "direction", d } };
  const SceneDescription s = Parse(j);
  const double n = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  const double e = s.Sun.ElevationDegrees * kDegree, a = s.Sun.AzimuthDegrees * kDegree;
  EXPECT_NEAR(std::cos(e) * std::sin(a), d[0] / n, 1e-12);
  EXPECT_NEAR(std::cos(e) * std::cos(a), d[1] / n, 1e-12);
  EXPECT_NEAR(std::sin(e), d[2] / n, 1e-12);
  // Written back as azimuth/elevation.
  const std::string text = nimbus::SceneToJson(s);
  EXPECT_EQ(text.find("direction"), std::string::npos);
  ExpectSameScene(nimbus::ParseScene(text, ""), s);
}

TEST(SceneJson, RelativePaths)
{
  auto fileScene = [](const std::string& path) {
    return With("/medium/density", Json{ { "type", "file" }, { "path", path } });
  };
  EXPECT_EQ(Parse(fileScene("clouds/a.vti"), "/data/scenes").Medium.Density.Path,
    "/data/scenes/clouds/a.vti");
  EXPECT_EQ(Parse(fileScene("../clouds/./a.vti"), "/data/scenes/").Medium.Density.Path,
    "/data/clouds/a.vti");
  EXPECT_EQ(Parse(fileScene("/abs/x/../a.vti"), "/data/scenes").Medium.Density.Path, "/abs/a.vti");
  EXPECT_EQ(Parse(fileScene("a.vti"), "").Medium.Density.Path,
    (fs::current_path() / "a.vti").lexically_normal().string());
  const SceneDescription s = Parse(fileScene("a.vti"), "/d");
  EXPECT_EQ(s.Medium.Density.ArrayName, "density");
  EXPECT_TRUE(s.Medium.Density.Parameters.empty());

  // LoadScene resolves against the file's directory, wherever the caller is.
  const fs::path dir = MakeTemporaryDirectory("nimbus-scene-json");
  fs::create_directories(dir / "scenes");
  const fs::path file = dir / "scenes" / "s.json";
  {
    std::ofstream out(file);
    out << fileScene("../grids/cloud.vti").dump(2);
  }
  EXPECT_EQ(nimbus::LoadScene(file.string()).Medium.Density.Path,
    (dir / "grids" / "cloud.vti").lexically_normal().string());
  const fs::path previous = fs::current_path();
  fs::current_path(dir);
  EXPECT_EQ(nimbus::LoadScene("scenes/s.json").Medium.Density.Path,
    (dir / "grids" / "cloud.vti").lexically_normal().string());
  fs::current_path(previous);

  // LoadScene's errors name the file.
  const std::string missing = (dir / "missing.json").string();
  try
  {
    nimbus::LoadScene(missing);
    ADD_FAILURE() << "no error for a missing file";
  }
  catch (const std::runtime_error& error)
  {
    EXPECT_EQ(std::string(error.what()).rfind(missing + ": ", 0), 0u) << error.what();
  }
  {
    std::ofstream out(dir / "bad.json");
    out << With("/sun/elevation_degrees", 100).dump();
  }
  try
  {
    nimbus::LoadScene((dir / "bad.json").string());
    ADD_FAILURE() << "no error for an invalid scene";
  }
  catch (const std::invalid_argument& error)
  {
    EXPECT_EQ(std::string(error.what()),
      (dir / "bad.json").string() +
        ": scene.sun.elevation_degrees: expected a number in [-90, 90], got 100");
  }
  fs::remove_all(dir);
}

//------------------------------------------------------------------------------
// Version 1 of the format named the sun's and the air's parameters without their
// units ("elevation", "mie_scattering"); version 2 uses the names of Physics/Sun.h and
// Physics/Atmosphere.h ("elevation_degrees", "mie_scattering_per_metre"). Version-1
// files keep loading: they are read by renaming those keys (docs/scene-format.md).

/// Every key version 2 renamed: (section, version-1 name, version-2 name).
const std::vector<std::array<std::string, 3>> kRenamedKeys = {
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

/// A version-2 document written back in version-1 words.
Json AsVersion1(Json j)
{
  j["nimbus_scene"] = 1;
  for (const auto& key : kRenamedKeys)
  {
    if (j.contains(key[0]) && j[key[0]].contains(key[2]))
    {
      j[key[0]][key[1]] = j[key[0]][key[2]];
      j[key[0]].erase(key[2]);
    }
  }
  return j;
}

TEST(SceneJson, Version1FilesLoadAsTheSameScene)
{
  // The project's haze_shafts scene as it was committed in version 1, against today's file.
  const SceneDescription old =
    nimbus::LoadScene(std::string(NIMBUS_TEST_DATA_DIR) + "/haze_shafts_version1.json");
  const SceneDescription now =
    nimbus::LoadScene(std::string(NIMBUS_SCENES_DIR) + "/haze_shafts.json");
  ExpectSameScene(old, now);
  EXPECT_EQ(nimbus::SceneHash(old), nimbus::SceneHash(now));
  // Every renamed key, with a value that differs from the default.
  const SceneDescription everything = NonDefaultScene();
  const Json written = Json::parse(nimbus::SceneToJson(everything));
  for (const auto& key : kRenamedKeys)
  {
    ASSERT_TRUE(written[key[0]].contains(key[2])) << key[2];
  }
  ExpectSameScene(Parse(AsVersion1(written)), Parse(written));
  // Written back, a version-1 scene is version 4.
  EXPECT_NE(nimbus::SceneToJson(old).find("\"nimbus_scene\": 4"), std::string::npos);
}

TEST(SceneJson, Version1ErrorsNameTheVersion1Keys)
{
  const Json v1 = AsVersion1(MinimalJson());
  Json j = v1;
  j["sun"]["elevation"] = 91;
  ExpectError(j, "scene.sun.elevation: expected a number in [-90, 90], got 91");
  j = v1;
  j["sun"].erase("azimuth");
  ExpectError(j, "scene.sun: missing required key \"azimuth\"");
  j = v1;
  j["atmosphere"] = Json::parse(R"({"top_radius": 6000000})");
  ExpectError(j, "scene.atmosphere.top_radius: must be greater than earth_radius (");
  // A version-2 name was unknown in version 1: rejected, with both names.
  j = v1;
  j["sun"]["elevation_degrees"] = 10;
  ExpectError(j,
    "scene.sun.elevation_degrees: unknown key in a version-1 file (version 1 "
    "calls it \"elevation\"");
  // And a version-1 name is unknown in version 2.
  j = MinimalJson();
  j["atmosphere"] = Json::parse(R"({"mie_scattering": 1e-5})");
  ExpectError(j, "scene.atmosphere.mie_scattering: unknown key");
}

//------------------------------------------------------------------------------
// Bad input (the robustness issue): deep nesting, values that cannot be physical,
// messages that name the real problem.

/// MinimalJson with its "name" replaced by `depth` nested arrays around a 1.
std::string NestedNameText(std::size_t depth)
{
  std::string text = MinimalJson().dump();
  const std::string nested = std::string(depth, '[') + "1" + std::string(depth, ']');
  const std::string key = "\"nimbus_scene\":2";
  text.replace(text.find(key), key.size(), key + ",\"name\":" + nested);
  return text;
}

TEST(SceneJson, DeepNestingIsRefusedQuicklyWithItsDepth)
{
  // 100 000 levels (200 KB): the key-path tracker copied the path at every level
  // (quadratic: gigabytes); now each level holds its index, and the depth limit
  // stops the parser at level 65.
  const auto start = std::chrono::steady_clock::now();
  ExpectErrorText(
    NestedNameText(100000),
    "scene.name" +
      []
      {
        std::string p;
        for (int i = 0; i < 63; ++i) // the root object is level 1
        {
          p += "[0]";
        }
        return p;
      }() +
      ": arrays and objects nested deeper than 64 levels (a scene needs 5)");
  const double seconds =
    std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_LT(seconds, 1.0);
  // Exactly at the limit (63 arrays inside the root object: 64 levels) the parser
  // reads on, and the reader names the wrong type.
  ExpectErrorText(NestedNameText(63), "scene.name: expected a string, got the array [[[[");
  ExpectErrorText(NestedNameText(64), "scene.name[0]");
  // Objects count as levels too; the message names the path.
  std::string objects = "{\"nimbus_scene\":2,\"camera\":";
  for (int i = 0; i < 70; ++i)
  {
    objects += "{\"a\":";
  }
  ExpectErrorText(objects, "scene.camera.a.a.a");
}

TEST(SceneJson, SyntaxErrorsInLongArraysNameTheirIndex)
{
  // The path is joined only when a message needs it; it still names the element.
  std::string text = "{\"nimbus_scene\":2,\"name\":[";
  for (int i = 0; i < 2000; ++i)
  {
    text += "{\"k\":[1,2,3]},";
  }
  text += "}";
  ExpectErrorText(text, "scene.name[2000]: invalid JSON");
}

TEST(SceneJson, ValuesThatCannotBePhysicalAreRefused)
{
  // Each of these was accepted and made nimbus-render write Inf or NaN pixels.
  ExpectError(With("/sun/illuminance", 1e308),
    "scene.sun.illuminance: expected a number in [0, 1000000], got 1e+308");
  ExpectError(With("/atmosphere", Json{ { "rayleigh_scattering_per_metre", 1e308 } }),
    "scene.atmosphere.rayleigh_scattering_per_metre: expected a number in [0, 0.001], got 1e+308");
  ExpectError(With("/atmosphere", Json{ { "top_radius_metres", 1e308 } }),
    "scene.atmosphere.top_radius_metres: expected a number in [100000, 100000000], got 1e+308");
  ExpectError(With("/background", Json{ { "type", "constant" }, { "radiance", 1e308 } }),
    "scene.background.radiance: expected a number in [0, 1000000], got 1e+308");
  ExpectError(With("/medium/extinction_per_density", 1e308),
    "scene.medium.extinction_per_density: expected a number in [0, 1000], got 1e+308");
  ExpectError(With("/atmosphere", Json{ { "mie_scale_height_metres", 1e-308 } }),
    "scene.atmosphere.mie_scale_height_metres: expected a number in [1, 1000000], got 1e-308");
  ExpectError(With("/ground", Json{ { "height", -1e308 } }),
    "scene.ground.height: expected a number in [-1000000000, 1000000000], got -1e+308");
  ExpectError(With("/medium/phase", Json{ { { "type", "isotropic" }, { "weight", 1e308 } } }),
    "scene.medium.phase[0].weight: expected a number in [0, 1000000], got 1e+308");
  ExpectError(
    With("/medium/density/parameters", Json{ { "Bounds", { -1e308, 1e308, 0, 1, 0, 1 } } }),
    "scene.medium.density.parameters.Bounds[0]: expected a number in [-100000000, 100000000]");
  ExpectError(With("/medium/density/parameters", Json{ { "BallDensity", 1e308 } }),
    "scene.medium.density.parameters.BallDensity: expected a number in [0, 1000000]");
  // 1000 balls per level, doubling over 10 levels: 1 023 010 balls.
  ExpectError(
    With("/medium/density/parameters", Json{ { "BallsPerLevel", 1000 }, { "NumberOfLevels", 10 } }),
    "scene.medium.density.parameters: too many metaballs: NumberOfBaseBalls + BallsPerLevel x "
    "BallCountFactor^(level - 1) over NumberOfLevels levels makes 1023010, more than 1000000");
  // The limits themselves are accepted.
  EXPECT_NO_THROW(Parse(With("/sun/illuminance", 1e6)));
  EXPECT_NO_THROW(Parse(With("/atmosphere",
    Json{ { "rayleigh_scattering_per_metre", 1e-3 }, { "mie_scattering_per_metre", 1e-2 } })));
  EXPECT_NO_THROW(Parse(With("/medium/density/parameters",
    Json{ { "BallsPerLevel", 1000 }, { "NumberOfLevels", 9 }, { "NumberOfBaseBalls", 10 } })));
}

TEST(SceneJson, HugeCameraCoordinatesAreNamedNotCalledEqual)
{
  // Was "scene.camera.focal_point: must differ from camera.position" (the
  // difference overflowed to Inf).
  ExpectError(With("/camera/position", Json{ 1e308, -6000, 1500 }),
    "scene.camera.position[0]: expected a number in [-1000000000, 1000000000], got 1e+308");
  ExpectError(With("/camera/focal_point", Json{ 0, -1e308, 1600 }),
    "scene.camera.focal_point[1]: expected a number in [-1000000000, 1000000000], got -1e+308");
  // Opposite extremes within the limits: the difference is finite.
  Json j = MinimalJson();
  j["camera"]["position"] = Json{ -1e9, -1e9, 0 };
  j["camera"]["focal_point"] = Json{ 1e9, 1e9, 10 };
  EXPECT_NO_THROW(Parse(j));
  ExpectError(With("/camera/focal_point", Json{ 0, -6000, 1500 }),
    "scene.camera.focal_point: must differ from camera.position");
  // Any finite view-up and sun direction, however large or small, is a direction.
  j = MinimalJson();
  j["camera"]["view_up"] = Json{ 1e308, 0, 1e308 };
  EXPECT_NO_THROW(Parse(j));
  j["camera"]["view_up"] = Json{ 0, 0, 1e-308 };
  EXPECT_NO_THROW(Parse(j));
  j["camera"]["view_up"] = Json{ 0, 6e307, 1e306 }; // parallel to the view (0, 6000, 100)
  ExpectError(j, "scene.camera.view_up: must be non-zero and not parallel to the view direction");
  Json sun = { { "direction", { 1e308, 1e308, 1e308 } } };
  const SceneDescription s = Parse(With("/sun", sun));
  EXPECT_NEAR(s.Sun.ElevationDegrees, std::atan(1.0 / std::sqrt(2.0)) * 180.0 / M_PI, 1e-12);
  EXPECT_EQ(s.Sun.AzimuthDegrees, 45.0);
}

//------------------------------------------------------------------------------
// Version 3: lights (point, polyline), per-voxel emission, additional media.

namespace
{
/// MinimalJson as version 3 with every new key.
Json Version3Json()
{
  Json j = MinimalJson();
  j["nimbus_scene"] = 3;
  j["medium"]["density"] = Json::parse(R"({"type": "file", "path": "grids/c.vti"})");
  j["medium"]["emission"] =
    Json::parse(R"({"source": "array", "array": "heat", "radiance_per_metre": 0.5})");
  j["lights"] = Json::parse(R"([
    {"type": "point", "position": [0, 0, 1000], "intensity": 1e6, "temperature_kelvin": 3200},
    {"type": "polyline", "vertices": [[0, 0, 3000], [100, 0, 2000], [100, 50, 0]],
     "intensity_per_metre": 2e4}
  ])");
  j["media"] = Json::parse(R"([
    {"density": {"type": "file", "path": "grids/smoke.vti", "array": "soot"},
     "extinction_per_density": 0.3, "single_scattering_albedo": 0.4,
     "phase": {"type": "henyey_greenstein", "g": 0.5},
     "emission": {"source": "from_density", "radiance_per_metre": 3, "temperature_kelvin": 900}}
  ])");
  return j;
}

Json V3With(const std::string& pointer, const Json& value)
{
  return Set(Version3Json(), pointer, value);
}

Json V3Without(const std::string& pointer)
{
  return Remove(Version3Json(), pointer);
}
} // namespace

TEST(SceneJson, Version3KeysParse)
{
  const SceneDescription s = Parse(Version3Json(), "/scenes");
  EXPECT_TRUE(s.UsesVersion3Features());
  EXPECT_TRUE(s.Medium.Emission.Enabled);
  EXPECT_EQ(s.Medium.Emission.Source, "array");
  EXPECT_EQ(s.Medium.Emission.ArrayName, "heat");
  EXPECT_EQ(s.Medium.Emission.RadiancePerMetre, 0.5);
  EXPECT_EQ(s.Medium.Emission.TemperatureKelvin, 1500.0); // default
  ASSERT_EQ(s.Lights.size(), 2u);
  EXPECT_EQ(s.Lights[0].Type, "point");
  EXPECT_EQ(s.Lights[0].Position, (std::array<double, 3>{ { 0.0, 0.0, 1000.0 } }));
  EXPECT_EQ(s.Lights[0].Intensity, 1e6);
  EXPECT_EQ(s.Lights[0].TemperatureKelvin, 3200.0);
  EXPECT_EQ(s.Lights[1].Type, "polyline");
  ASSERT_EQ(s.Lights[1].Vertices.size(), 3u);
  EXPECT_EQ(s.Lights[1].Vertices[2], (std::array<double, 3>{ { 100.0, 50.0, 0.0 } }));
  EXPECT_EQ(s.Lights[1].IntensityPerMetre, 2e4);
  EXPECT_EQ(s.Lights[1].TemperatureKelvin, 6500.0); // default
  ASSERT_EQ(s.Media.size(), 1u);
  EXPECT_EQ(s.Media[0].Density.Path, "/scenes/grids/smoke.vti"); // resolved like medium's
  EXPECT_EQ(s.Media[0].Density.ArrayName, "soot");
  EXPECT_EQ(s.Media[0].ExtinctionPerDensity, 0.3);
  EXPECT_EQ(s.Media[0].SingleScatteringAlbedo, 0.4);
  ASSERT_EQ(s.Media[0].Phase.size(), 1u);
  EXPECT_EQ(s.Media[0].Phase[0].G, 0.5);
  EXPECT_TRUE(s.Media[0].Emission.Enabled);
  EXPECT_EQ(s.Media[0].Emission.Source, "from_density");
  EXPECT_EQ(s.Media[0].Emission.TemperatureKelvin, 900.0);
  // Canonical round trip.
  const std::string text = nimbus::SceneToJson(s);
  EXPECT_NE(text.find("\"lights\""), std::string::npos);
  const SceneDescription back = nimbus::ParseScene(text, "/elsewhere");
  ExpectSameScene(back, s);
  EXPECT_EQ(nimbus::SceneToJson(back), text);
  // Empty arrays are allowed and mean no lights / no media.
  Json j = Version3Json();
  j["lights"] = Json::array();
  j["media"] = Json::array();
  j["medium"].erase("emission");
  const SceneDescription none = Parse(j);
  EXPECT_FALSE(none.UsesVersion3Features());
}

TEST(SceneJson, Version3KeysNeedVersion3)
{
  // A version-2 (or 1) file with a version-3 key: an unknown key, saying which version.
  Json j = MinimalJson();
  j["lights"] = Json::array();
  ExpectError(j,
    "scene.lights: unknown key (known: nimbus_scene, name, description, camera, medium, sun, "
    "atmosphere, ground, background, spectral_samples); \"lights\" needs format version 3 "
    "(\"nimbus_scene\": 3), this file is version 2");
  j = MinimalJson();
  j["media"] = Json::array();
  ExpectError(j, "scene.media: unknown key (known: ");
  j = MinimalJson();
  j["medium"]["emission"] = Json::parse(R"({"source": "from_density", "radiance_per_metre": 1})");
  ExpectError(j, "scene.medium.emission: unknown key (known: density, ");
  ExpectError(AsVersion1(j), "scene.medium.emission: unknown key");
  // The same keys in version 3 are fine, and a version-2 file still reads as before.
  j["nimbus_scene"] = 3;
  EXPECT_NO_THROW(Parse(j));
  Json v2 = MinimalJson(), v3 = MinimalJson();
  v3["nimbus_scene"] = 3;
  ExpectSameScene(Parse(v2), Parse(v3));
  EXPECT_EQ(nimbus::SceneHash(Parse(v2)), nimbus::SceneHash(Parse(v3)));
}

TEST(SceneJson, Version3Errors)
{
  // Lights.
  ExpectError(V3With("/lights", 1), "scene.lights: expected an array of lights, got 1");
  ExpectError(V3With("/lights", Json::array({ Json::array() })),
    "scene.lights[0]: expected an object, got the array []");
  ExpectError(V3With("/lights/0/type", "spot"),
    "scene.lights[0].type: unknown value \"spot\" (known: point, polyline)");
  ExpectError(
    V3Without("/lights/0/type"), "scene.lights[0]: missing required key \"type\" (known: point");
  ExpectError(
    V3Without("/lights/0/position"), "scene.lights[0]: missing required key \"position\"");
  ExpectError(
    V3Without("/lights/0/intensity"), "scene.lights[0]: missing required key \"intensity\"");
  ExpectError(V3With("/lights/0/position/2", 2e9),
    "scene.lights[0].position[2]: expected a number in [-1000000000, 1000000000], got 2000000000");
  ExpectError(V3With("/lights/0/position", Json::array({ 1, 2 })),
    "scene.lights[0].position: expected an array of 3 numbers, got 2 elements");
  ExpectError(V3With("/lights/0/intensity", -1),
    "scene.lights[0].intensity: expected a number in [0, 1000000000000], got -1");
  ExpectError(V3With("/lights/0/intensity", 1e13),
    "scene.lights[0].intensity: expected a number in [0, 1000000000000], got 10000000000000");
  ExpectError(V3With("/lights/0/temperature_kelvin", 100),
    "scene.lights[0].temperature_kelvin: expected a number in [500, 100000], got 100");
  ExpectError(V3With("/lights/0/vertices", Json::array()),
    "scene.lights[0].vertices: unknown key (known: type, position, intensity, "
    "temperature_kelvin)");
  ExpectError(V3With("/lights/1/intensity", 1),
    "scene.lights[1].intensity: unknown key (known: type, vertices, intensity_per_metre, "
    "temperature_kelvin)");
  ExpectError(V3With("/lights/1/vertices", Json::parse("[[0, 0, 0]]")),
    "scene.lights[1].vertices: expected at least 2 vertices, got 1");
  ExpectError(V3With("/lights/1/vertices", 5),
    "scene.lights[1].vertices: expected an array of vertices ([x, y, z], m), got 5");
  ExpectError(V3With("/lights/1/vertices/1", Json::parse("[0, 0, 3000]")),
    "scene.lights[1].vertices[1]: a segment of zero length: the same point as vertex 0");
  ExpectError(V3With("/lights/1/vertices/2/0", "x"),
    "scene.lights[1].vertices[2][0]: expected a number in [-1000000000, 1000000000], got the "
    "string \"x\"");
  ExpectError(V3With("/lights/1/intensity_per_metre", 1e300),
    "scene.lights[1].intensity_per_metre: expected a number in [0, 1000000000000], got 1e+300");
  ExpectError(V3Without("/lights/1/intensity_per_metre"),
    "scene.lights[1]: missing required key \"intensity_per_metre\"");
  {
    Json many = Version3Json();
    many["lights"] = Json::array();
    for (int i = 0; i < 1025; ++i)
    {
      many["lights"].push_back(Version3Json()["lights"][0]);
    }
    ExpectError(many, "scene.lights: expected at most 1024 lights, got 1025");
    Json vertices = Json::array();
    for (int i = 0; i < 100001; ++i)
    {
      vertices.push_back(Json::array({ i, 0, 0 }));
    }
    ExpectError(V3With("/lights/1/vertices", vertices),
      "scene.lights[1].vertices: expected at most 100000 vertices ([x, y, z], m), got 100001");
  }
  // Emission.
  ExpectError(V3With("/medium/emission", 1), "scene.medium.emission: expected an object, got 1");
  ExpectError(
    V3Without("/medium/emission/source"), "scene.medium.emission: missing required key \"source\"");
  ExpectError(V3With("/medium/emission/source", "temperature"),
    "scene.medium.emission.source: unknown value \"temperature\" (known: from_density, array, "
    "blackbody)");
  ExpectError(
    V3Without("/medium/emission/array"), "scene.medium.emission: missing required key \"array\"");
  ExpectError(V3With("/medium/emission/array", ""),
    "scene.medium.emission.array: expected a non-empty string");
  ExpectError(V3Without("/medium/emission/radiance_per_metre"),
    "scene.medium.emission: missing required key \"radiance_per_metre\"");
  ExpectError(V3With("/medium/emission/radiance_per_metre", -0.5),
    "scene.medium.emission.radiance_per_metre: expected a number in [0, 1000000], got -0.5");
  ExpectError(V3With("/medium/emission/radiance_per_metre", 1e7),
    "scene.medium.emission.radiance_per_metre: expected a number in [0, 1000000], got 10000000");
  ExpectError(V3With("/medium/emission/temperature_kelvin", 1e6),
    "scene.medium.emission.temperature_kelvin: expected a number in [500, 100000], got 1000000");
  ExpectError(V3With("/medium/emission/glow", 1),
    "scene.medium.emission.glow: unknown key (known: source, array, radiance_per_metre, "
    "temperature_kelvin)");
  ExpectError(V3With("/media/0/emission/array", "heat"),
    "scene.media[0].emission.array: only used by sources \"array\" and \"blackbody\"");
  {
    Json j = Version3Json();
    j["medium"]["density"] = Json::parse(R"({"type": "metaball_cloud"})");
    ExpectError(j,
      "scene.medium.emission.source: \"array\" reads another point-data array of the "
      "density's .vti, so it needs a \"file\" density (this density is \"metaball_cloud\"");
  }
  // Media.
  ExpectError(V3With("/media", Json::object()), "scene.media: expected an array of media, got");
  ExpectError(V3With("/media/0", 1), "scene.media[0]: expected an object, got 1");
  ExpectError(V3Without("/media/0/density"), "scene.media[0]: missing required key \"density\"");
  ExpectError(V3Without("/media/0/extinction_per_density"),
    "scene.media[0]: missing required key \"extinction_per_density\"");
  ExpectError(V3With("/media/0/extinction_per_density", 1001),
    "scene.media[0].extinction_per_density: expected a number in [0, 1000], got 1001");
  ExpectError(V3With("/media/0/single_scattering_albedo", 1.5),
    "scene.media[0].single_scattering_albedo: expected a number in [0, 1], got 1.5");
  ExpectError(
    V3With("/media/0/phase/g", 2), "scene.media[0].phase.g: expected a number in [-1, 1], got 2");
  ExpectError(V3With("/media/0/phase", Json::array()),
    "scene.media[0].phase: expected at least one phase component");
  ExpectError(V3With("/media/0/density/type", "cloud"),
    "scene.media[0].density.type: unknown value \"cloud\"");
  ExpectError(V3With("/media/0/multiple_scattering_constant", 1),
    "scene.media[0].multiple_scattering_constant: unknown key (known: density, "
    "extinction_per_density, single_scattering_albedo, phase, emission)");
  {
    // Two metaball clouds share a grid only with the same Dimensions and Bounds (the
    // source's defaults where omitted).
    Json j = MinimalJson();
    j["nimbus_scene"] = 3;
    j["media"] = Json::parse(R"([{"density": {"type": "metaball_cloud", "parameters":
      {"Dimensions": [96, 96, 64], "Seed": 5}}, "extinction_per_density": 0.01}])");
    EXPECT_NO_THROW(Parse(j));
    j["media"][0]["density"]["parameters"]["Dimensions"] = Json::array({ 32, 32, 32 });
    ExpectError(j,
      "scene.media[0].density.parameters.Dimensions: every medium must be on the main medium's "
      "grid: medium.density's Dimensions is [96, 96, 64], this one's [32, 32, 32]");
    j["media"][0]["density"]["parameters"].erase("Dimensions");
    j["media"][0]["density"]["parameters"]["Bounds"] = Json::array({ -1, 1, -1, 1, 0, 1 });
    ExpectError(j, "scene.media[0].density.parameters.Bounds: every medium must be on the main");
  }
  {
    Json many = Version3Json();
    for (int i = 0; i < 16; ++i)
    {
      many["media"].push_back(many["media"][0]);
    }
    ExpectError(many, "scene.media: expected at most 16 media, got 17");
  }
}

TEST(SceneJson, Version3HashCoversTheNewFields)
{
  const std::vector<Mutation> mutations = {
    { "a light moves", [](SceneDescription& s) { s.Lights[0].Position[2] += 1e-6; } },
    { "Light.Intensity", [](SceneDescription& s) { s.Lights[0].Intensity *= 1.01; } },
    { "Light.Temperature", [](SceneDescription& s) { s.Lights[0].TemperatureKelvin += 1; } },
    { "Light.Vertices", [](SceneDescription& s) { s.Lights[1].Vertices[1][0] += 1; } },
    { "Light.Vertices.size",
      [](SceneDescription& s) {
        s.Lights[1].Vertices.push_back({ { 0.0, 0.0, -5.0 } });
      } },
    { "Light.IntensityPerMetre", [](SceneDescription& s) { s.Lights[1].IntensityPerMetre += 1; } },
    { "Lights.size", [](SceneDescription& s) { s.Lights.pop_back(); } },
    { "Lights.order", [](SceneDescription& s) { std::swap(s.Lights[0], s.Lights[1]); } },
    { "Emission.Enabled", [](SceneDescription& s) { s.Medium.Emission.Enabled = false; } },
    { "Emission.Source", [](SceneDescription& s) { s.Medium.Emission.Source = "from_density"; } },
    { "Emission.ArrayName", [](SceneDescription& s) { s.Medium.Emission.ArrayName += "x"; } },
    { "Emission.RadiancePerMetre",
      [](SceneDescription& s) { s.Medium.Emission.RadiancePerMetre += 1; } },
    { "Emission.TemperatureKelvin",
      [](SceneDescription& s) { s.Medium.Emission.TemperatureKelvin += 1; } },
    { "Media.size", [](SceneDescription& s) { s.Media.pop_back(); } },
    { "Media.Density.Path", [](SceneDescription& s) { s.Media[0].Density.Path += "x"; } },
    { "Media.Density.ArrayName", [](SceneDescription& s) { s.Media[1].Density.ArrayName += "x"; } },
    { "Media.ExtinctionPerDensity",
      [](SceneDescription& s) { s.Media[0].ExtinctionPerDensity += 1; } },
    { "Media.SingleScatteringAlbedo",
      [](SceneDescription& s) { s.Media[0].SingleScatteringAlbedo += 0.1; } },
    { "Media.Phase", [](SceneDescription& s) { s.Media[0].Phase[0].G += 0.1; } },
    { "Media.Emission", [](SceneDescription& s) { s.Media[0].Emission.RadiancePerMetre += 0.1; } },
  };
  ExpectEachMutationChangesTheHash(Version3Scene(), mutations);
}

// The annotated example of docs/scene-format.md (version 3, with a point light and a
// lightning channel) is a valid scene, and says what the notes under it say.
TEST(SceneJson, DocumentedExampleParses)
{
  std::ifstream in(NIMBUS_SCENE_FORMAT_DOC);
  const std::string doc((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::size_t section = doc.find("## Annotated example");
  ASSERT_NE(section, std::string::npos);
  const std::size_t begin = doc.find("```json\n", section);
  ASSERT_NE(begin, std::string::npos);
  const std::size_t end = doc.find("```", begin + 8);
  ASSERT_NE(end, std::string::npos);
  const SceneDescription s = nimbus::ParseScene(doc.substr(begin + 8, end - begin - 8), "/docs");
  ASSERT_EQ(s.Lights.size(), 2u);
  EXPECT_EQ(s.Lights[0].Type, "point");
  EXPECT_EQ(s.Lights[0].Intensity, 2e5);
  EXPECT_EQ(s.Lights[1].Type, "polyline");
  EXPECT_EQ(s.Lights[1].Vertices.size(), 4u);
  EXPECT_EQ(s.Lights[1].TemperatureKelvin, 28000.0);
  double length = 0.0;
  for (std::size_t i = 1; i < s.Lights[1].Vertices.size(); ++i)
  {
    double d2 = 0.0;
    for (int a = 0; a < 3; ++a)
    {
      const double d = s.Lights[1].Vertices[i][a] - s.Lights[1].Vertices[i - 1][a];
      d2 += d * d;
    }
    length += std::sqrt(d2);
  }
  std::printf("documented channel: %.0f m, %.3g Y/sr in all\n", length,
    length * s.Lights[1].IntensityPerMetre);
  EXPECT_NEAR(length, 2600.0, 200.0); // "about 2.6 km long"
}

//------------------------------------------------------------------------------
// Version 4: spot lights (with light maps) and occluders (boxes, meshes).

namespace
{
/// MinimalJson as version 4 with every new key: a spot with a light map, a box and a mesh.
Json Version4Json()
{
  Json j = MinimalJson();
  j["nimbus_scene"] = 4;
  j["lights"] = Json::parse(R"([
    {"type": "spot", "position": [0, 0, 10], "direction": [0, 0, -2],
     "cone_angle_degrees": 30, "edge_degrees": 5, "intensity": 1e4,
     "light_map": "gobos/leaves.png"},
    {"type": "point", "position": [0, 0, 1000], "intensity": 1e6}
  ])");
  j["occluders"] = Json::parse(R"([
    {"type": "box", "min": [-1, -1, 0], "max": [1, 1, 4], "albedo": 0.4},
    {"type": "mesh", "path": "meshes/post.obj", "translate": [3, 0, 0], "scale": 0.5}
  ])");
  return j;
}

Json V4With(const std::string& pointer, const Json& value)
{
  return Set(Version4Json(), pointer, value);
}

Json V4Without(const std::string& pointer)
{
  return Remove(Version4Json(), pointer);
}

/// One bad version-4 scene and the start of the message it must give.
struct BadScene
{
  std::string What;
  Json Text;
  std::string Prefix;
};

/// The classes of bad values of the version-4 keys: every number, vector and path key
/// with each wrong kind of value, then the rules between keys (ranges, cones, corners,
/// extensions, required and unknown keys).
std::vector<BadScene> BadVersion4Scenes()
{
  std::vector<BadScene> bad;
  const std::string spot = "/lights/0", box = "/occluders/0", mesh = "/occluders/1";
  auto key = [](const std::string& pointer)
  {
    // "/lights/0/cone_angle_degrees" -> "scene.lights[0].cone_angle_degrees"
    std::string path = "scene";
    std::size_t at = 1;
    while (at <= pointer.size())
    {
      const std::size_t next = std::min(pointer.find('/', at), pointer.size());
      const std::string token = pointer.substr(at, next - at);
      path += std::isdigit(static_cast<unsigned char>(token[0])) ? "[" + token + "]" : "." + token;
      at = next + 1;
    }
    return path;
  };
  // Numbers: every other JSON type is refused, naming the key.
  for (const std::string& pointer :
    { spot + "/cone_angle_degrees", spot + "/edge_degrees", spot + "/intensity",
      spot + "/temperature_kelvin", box + "/albedo", mesh + "/albedo", mesh + "/scale" })
  {
    for (const Json& value :
      { Json("1"), Json(true), Json(nullptr), Json::array({ 1 }), Json::object() })
    {
      bad.push_back({ pointer + " = " + value.dump(), V4With(pointer, value),
        key(pointer) + ": expected a number" });
    }
  }
  // Vectors of three coordinates: wrong types, lengths, elements.
  for (const std::string& pointer :
    { spot + "/position", spot + "/direction", box + "/min", box + "/max", mesh + "/translate" })
  {
    bad.push_back(
      { pointer + " = 5", V4With(pointer, 5), key(pointer) + ": expected an array of 3 numbers" });
    bad.push_back({ pointer + " has 2", V4With(pointer, Json::array({ 1, 2 })),
      key(pointer) + ": expected an array of 3 numbers, got 2 elements" });
    bad.push_back({ pointer + " has 4", V4With(pointer, Json::array({ 1, 2, 3, 4 })),
      key(pointer) + ": expected an array of 3 numbers, got 4 elements" });
    bad.push_back({ pointer + "[1] a string", V4With(pointer, Json::parse(R"([1, "a", 3])")),
      key(pointer) + "[1]: expected a" });
    if (pointer != spot + "/direction")
    {
      bad.push_back({ pointer + "[2] beyond 1e9 m", V4With(pointer, Json::array({ 0, 0, 2e9 })),
        key(pointer) + "[2]: expected a number in [-1000000000, 1000000000], got 2000000000" });
    }
  }
  // Paths: types, emptiness, extensions.
  for (const auto& item : { std::make_pair(spot + "/light_map", std::string("an image file")),
         std::make_pair(mesh + "/path", std::string("a mesh file")) })
  {
    const std::string& pointer = item.first;
    bad.push_back({ pointer + " = 1", V4With(pointer, 1), key(pointer) + ": expected a string" });
    bad.push_back(
      { pointer + " empty", V4With(pointer, ""), key(pointer) + ": expected a non-empty string" });
    for (const char* name : { "file.txt", "file", "file.png.bak", "file.stl", "file.jpg" })
    {
      bad.push_back({ pointer + " = " + name, V4With(pointer, name),
        key(pointer) + ": expected " + item.second + " (" });
    }
  }
  // Rules between keys and ranges.
  const std::vector<BadScene> rules = {
    { "cone 0", V4With(spot + "/cone_angle_degrees", 0),
      "scene.lights[0].cone_angle_degrees: expected a number in (0, 90), got 0" },
    { "cone -5", V4With(spot + "/cone_angle_degrees", -5),
      "scene.lights[0].cone_angle_degrees: expected a number in (0, 90), got -5" },
    { "cone 90", V4With(spot + "/cone_angle_degrees", 90),
      "scene.lights[0].cone_angle_degrees: expected a number in (0, 90), got 90 (a cone of 90 "
      "degrees or more lights every direction: use a \"point\" light)" },
    { "cone 120", V4With(spot + "/cone_angle_degrees", 120),
      "scene.lights[0].cone_angle_degrees: expected a number in (0, 90), got 120 (a cone" },
    { "edge wider than the cone", V4With(spot + "/edge_degrees", 31),
      "scene.lights[0].edge_degrees: expected a number in [0, cone_angle_degrees] = [0, 30] (the "
      "soft edge lies inside the cone), got 31" },
    { "edge -1", V4With(spot + "/edge_degrees", -1),
      "scene.lights[0].edge_degrees: expected a number in [0, 90], got -1" },
    { "zero direction", V4With(spot + "/direction", Json::array({ 0, 0, 0 })),
      "scene.lights[0].direction: must be a non-zero vector (the beam's axis, away from the "
      "light)" },
    { "tiny but non-zero direction is fine",
      V4With(spot + "/direction", Json::array({ 0, 0, 1e-300 })), "" },
    { "intensity -1", V4With(spot + "/intensity", -1),
      "scene.lights[0].intensity: expected a number in [0, 1000000000000], got -1" },
    { "intensity 1e13", V4With(spot + "/intensity", 1e13),
      "scene.lights[0].intensity: expected a number in [0, 1000000000000]" },
    { "temperature 100", V4With(spot + "/temperature_kelvin", 100),
      "scene.lights[0].temperature_kelvin: expected a number in [500, 100000], got 100" },
    { "overflowing cone", Json(), "scene.lights[0].cone_angle_degrees: invalid JSON" },
    { "no position", V4Without(spot + "/position"),
      "scene.lights[0]: missing required key \"position\"" },
    { "no direction", V4Without(spot + "/direction"),
      "scene.lights[0]: missing required key \"direction\"" },
    { "no cone", V4Without(spot + "/cone_angle_degrees"),
      "scene.lights[0]: missing required key \"cone_angle_degrees\"" },
    { "no intensity", V4Without(spot + "/intensity"),
      "scene.lights[0]: missing required key \"intensity\"" },
    { "a spot with vertices", V4With(spot + "/vertices", Json::array()),
      "scene.lights[0].vertices: unknown key (known: type, position, direction, "
      "cone_angle_degrees, edge_degrees, intensity, temperature_kelvin, light_map)" },
    { "a point light with a light map", V4With("/lights/1/light_map", "a.png"),
      "scene.lights[1].light_map: unknown key (known: type, position, intensity, "
      "temperature_kelvin)" },
    { "unknown light type", V4With(spot + "/type", "cone"),
      "scene.lights[0].type: unknown value \"cone\" (known: point, polyline, spot)" },
    { "no light type", V4Without(spot + "/type"),
      "scene.lights[0]: missing required key \"type\" (known: point, polyline, spot)" },
    { "occluders not an array", V4With("/occluders", Json::object()),
      "scene.occluders: expected an array of occluders, got the object {}" },
    { "an occluder not an object", V4With(box, 3),
      "scene.occluders[0]: expected an object, got 3" },
    { "no occluder type", V4Without(box + "/type"),
      "scene.occluders[0]: missing required key \"type\" (known: box, mesh)" },
    { "unknown occluder type", V4With(box + "/type", "sphere"),
      "scene.occluders[0].type: unknown value \"sphere\" (known: box, mesh)" },
    { "min > max on x", V4With(box + "/max/0", -2),
      "scene.occluders[0].max: expected max >= min on every axis, axis x has min -1 and max -2" },
    { "min > max on y", V4With(box + "/min/1", 1.5),
      "scene.occluders[0].max: expected max >= min on every axis, axis y has min 1.5 and max 1" },
    { "min > max on z", V4With(box + "/min/2", 5),
      "scene.occluders[0].max: expected max >= min on every axis, axis z has min 5 and max 4" },
    { "no min", V4Without(box + "/min"), "scene.occluders[0]: missing required key \"min\"" },
    { "no max", V4Without(box + "/max"), "scene.occluders[0]: missing required key \"max\"" },
    { "a box with a path", V4With(box + "/path", "post.ply"),
      "scene.occluders[0].path: unknown key (known: type, min, max, albedo)" },
    { "albedo 1.5", V4With(box + "/albedo", 1.5),
      "scene.occluders[0].albedo: expected a number in [0, 1], got 1.5" },
    { "albedo -0.1", V4With(mesh + "/albedo", -0.1),
      "scene.occluders[1].albedo: expected a number in [0, 1], got -0.1" },
    { "no mesh path", V4Without(mesh + "/path"),
      "scene.occluders[1]: missing required key \"path\"" },
    { "a mesh with min", V4With(mesh + "/min", Json::array({ 0, 0, 0 })),
      "scene.occluders[1].min: unknown key (known: type, path, albedo, translate, scale)" },
    { "scale 0", V4With(mesh + "/scale", 0),
      "scene.occluders[1].scale: expected a number in [1e-09, 1000000000], got 0" },
    { "scale -1", V4With(mesh + "/scale", -1),
      "scene.occluders[1].scale: expected a number in [1e-09, 1000000000], got -1" },
    { "scale 2e9", V4With(mesh + "/scale", 2e9),
      "scene.occluders[1].scale: expected a number in [1e-09, 1000000000], got 2000000000" },
  };
  bad.insert(bad.end(), rules.begin(), rules.end());
  {
    Json many = Version4Json();
    many["occluders"] = Json::array();
    for (int i = 0; i < 4097; ++i)
    {
      many["occluders"].push_back(Version4Json()["occluders"][0]);
    }
    bad.push_back(
      { "4097 occluders", many, "scene.occluders: expected at most 4096 occluders, got 4097" });
  }
  return bad;
}
} // namespace

TEST(SceneJson, Version4KeysParse)
{
  const SceneDescription s = Parse(Version4Json(), "/scenes");
  EXPECT_TRUE(s.UsesVersion4Features());
  EXPECT_TRUE(s.UsesVersion3Features()); // it has lights
  ASSERT_EQ(s.Lights.size(), 2u);
  const nimbus::LightDescription& spot = s.Lights[0];
  EXPECT_EQ(spot.Type, "spot");
  EXPECT_EQ(spot.Position, (std::array<double, 3>{ { 0.0, 0.0, 10.0 } }));
  EXPECT_EQ(spot.Direction, (std::array<double, 3>{ { 0.0, 0.0, -2.0 } })); // as given
  EXPECT_EQ(spot.ConeAngleDegrees, 30.0);
  EXPECT_EQ(spot.EdgeDegrees, 5.0);
  EXPECT_EQ(spot.Intensity, 1e4);
  EXPECT_EQ(spot.TemperatureKelvin, 6500.0);                 // default
  EXPECT_EQ(spot.LightMap.Path, "/scenes/gobos/leaves.png"); // resolved like a density's
  EXPECT_TRUE(spot.LightMap.Luminance.empty());              // the reader does not read the image
  ASSERT_EQ(s.Occluders.size(), 2u);
  EXPECT_EQ(s.Occluders[0].Type, "box");
  EXPECT_EQ(s.Occluders[0].Min, (std::array<double, 3>{ { -1.0, -1.0, 0.0 } }));
  EXPECT_EQ(s.Occluders[0].Max, (std::array<double, 3>{ { 1.0, 1.0, 4.0 } }));
  EXPECT_EQ(s.Occluders[0].Albedo, 0.4);
  EXPECT_EQ(s.Occluders[1].Type, "mesh");
  EXPECT_EQ(s.Occluders[1].Path, "/scenes/meshes/post.obj");
  EXPECT_EQ(s.Occluders[1].Translate, (std::array<double, 3>{ { 3.0, 0.0, 0.0 } }));
  EXPECT_EQ(s.Occluders[1].Scale, 0.5);
  EXPECT_EQ(s.Occluders[1].Albedo, 0.0); // default: black
  EXPECT_TRUE(s.Occluders[1].TriangleVertices.empty());
  // Defaults: a spot's edge 0 (a hard edge), no light map; a flat box; a mesh in place.
  Json j = Version4Json();
  j["lights"][0].erase("edge_degrees");
  j["lights"][0].erase("light_map");
  j["occluders"][0]["max"] = Json::array({ 1, 1, 0 });
  j["occluders"][1].erase("translate");
  j["occluders"][1].erase("scale");
  j["occluders"][1]["path"] = "/abs/Post.PLY"; // any case of the extension
  const SceneDescription d = Parse(j);
  EXPECT_EQ(d.Lights[0].EdgeDegrees, 0.0);
  EXPECT_TRUE(d.Lights[0].LightMap.Path.empty());
  EXPECT_EQ(d.Occluders[0].Max[2], 0.0);
  EXPECT_EQ(d.Occluders[1].Translate, (std::array<double, 3>{ { 0.0, 0.0, 0.0 } }));
  EXPECT_EQ(d.Occluders[1].Scale, 1.0);
  EXPECT_EQ(d.Occluders[1].Path, "/abs/Post.PLY");
  // Canonical round trip; a spot without a light map writes none.
  for (const SceneDescription& scene : { s, d })
  {
    const std::string text = nimbus::SceneToJson(scene);
    EXPECT_NE(text.find("\"occluders\""), std::string::npos);
    EXPECT_EQ(
      text.find("\"light_map\"") == std::string::npos, scene.Lights[0].LightMap.Path.empty());
    const SceneDescription back = nimbus::ParseScene(text, "/elsewhere");
    ExpectSameScene(back, scene);
    EXPECT_EQ(nimbus::SceneToJson(back), text);
  }
  // Empty occluders mean none, and no spot: no version-4 feature.
  j = Version4Json();
  j["occluders"] = Json::array();
  j["lights"].erase(0);
  EXPECT_FALSE(Parse(j).UsesVersion4Features());
}

TEST(SceneJson, Version4KeysNeedVersion4)
{
  // A version-3 file with occluders or a spot: an unknown key or value, saying which
  // version it needs.
  Json j = Version3Json();
  j["occluders"] = Json::array();
  ExpectError(j,
    "scene.occluders: unknown key (known: nimbus_scene, name, description, camera, medium, sun, "
    "atmosphere, ground, background, spectral_samples, lights, media); \"occluders\" needs "
    "format version 4 (\"nimbus_scene\": 4), this file is version 3");
  j = Version3Json();
  j["lights"][0]["type"] = "spot";
  ExpectError(j,
    "scene.lights[0].type: unknown value \"spot\" (known: point, polyline); \"spot\" needs "
    "format version 4 (\"nimbus_scene\": 4), this file is version 3");
  // In a version-2 file lights themselves are unknown (the version-3 message).
  Json v2 = MinimalJson();
  v2["occluders"] = Json::array();
  ExpectError(v2,
    "scene.occluders: unknown key (known: nimbus_scene, name, description, camera, "
    "medium, sun, atmosphere, ground, background, spectral_samples); \"occluders\" "
    "needs format version 4 (\"nimbus_scene\": 4), this file is version 2");
  // A version-3 file reads exactly as before: the same text marked version 4 gives the same
  // description and hash (and so does a version-2 one).
  Json v3 = Version3Json(), v4 = Version3Json();
  v4["nimbus_scene"] = 4;
  ExpectSameScene(Parse(v3), Parse(v4));
  EXPECT_EQ(nimbus::SceneHash(Parse(v3)), nimbus::SceneHash(Parse(v4)));
  Json m4 = MinimalJson();
  m4["nimbus_scene"] = 4;
  EXPECT_EQ(nimbus::SceneHash(Parse(MinimalJson())), nimbus::SceneHash(Parse(m4)));
}

TEST(SceneJson, Version4Errors)
{
  const std::vector<BadScene> bad = BadVersion4Scenes();
  int refused = 0;
  for (const BadScene& scene : bad)
  {
    SCOPED_TRACE(scene.What);
    if (scene.Prefix.empty())
    {
      EXPECT_NO_THROW(Parse(scene.Text));
      continue;
    }
    if (scene.Text.is_null()) // a number that overflows a double, in the text
    {
      std::string text = Version4Json().dump();
      const std::string from = "\"cone_angle_degrees\":30";
      ASSERT_NE(text.find(from), std::string::npos);
      text.replace(text.find(from), from.size(), "\"cone_angle_degrees\":1e999");
      ExpectErrorText(text, scene.Prefix);
    }
    else
    {
      ExpectError(scene.Text, scene.Prefix);
    }
    ++refused;
  }
  std::printf("%d bad version-4 scenes refused, each with its key path\n", refused);
  EXPECT_GT(refused, 100);
}

TEST(SceneJson, Version4HashCoversTheNewFields)
{
  const std::vector<Mutation> mutations = {
    { "Spot.Position", [](SceneDescription& s) { s.Lights[2].Position[0] += 1e-6; } },
    { "Spot.Direction", [](SceneDescription& s) { s.Lights[2].Direction[1] += 0.01; } },
    { "Spot.Direction length", [](SceneDescription& s) { s.Lights[2].Direction[2] *= 2.0; } },
    { "Spot.ConeAngleDegrees", [](SceneDescription& s) { s.Lights[2].ConeAngleDegrees += 1; } },
    { "Spot.EdgeDegrees", [](SceneDescription& s) { s.Lights[2].EdgeDegrees += 1; } },
    { "Spot.Intensity", [](SceneDescription& s) { s.Lights[2].Intensity *= 1.01; } },
    { "Spot.Temperature", [](SceneDescription& s) { s.Lights[2].TemperatureKelvin += 1; } },
    { "Spot.LightMap", [](SceneDescription& s) { s.Lights[2].LightMap.Path += "x"; } },
    { "Spot.LightMap removed", [](SceneDescription& s) { s.Lights[2].LightMap.Path.clear(); } },
    { "Occluder.Type", [](SceneDescription& s) { s.Occluders[0].Type = "mesh"; } },
    { "Occluder.Min", [](SceneDescription& s) { s.Occluders[0].Min[0] -= 1; } },
    { "Occluder.Max", [](SceneDescription& s) { s.Occluders[0].Max[2] += 1; } },
    { "Occluder.Albedo", [](SceneDescription& s) { s.Occluders[0].Albedo += 0.1; } },
    { "Mesh.Path", [](SceneDescription& s) { s.Occluders[1].Path += "x"; } },
    { "Mesh.Translate", [](SceneDescription& s) { s.Occluders[1].Translate[2] += 1; } },
    { "Mesh.Scale", [](SceneDescription& s) { s.Occluders[1].Scale *= 2; } },
    { "Mesh.Albedo", [](SceneDescription& s) { s.Occluders[1].Albedo = 0.5; } },
    { "Occluders.size", [](SceneDescription& s) { s.Occluders.pop_back(); } },
    { "Occluders.order", [](SceneDescription& s) { std::swap(s.Occluders[0], s.Occluders[1]); } },
  };
  ExpectEachMutationChangesTheHash(Version4Scene(), mutations);
  // The pixels and triangles the glue reads are not part of the description's text.
  SceneDescription read = Version4Scene();
  read.Lights[2].LightMap.Width = read.Lights[2].LightMap.Height = 1;
  read.Lights[2].LightMap.Luminance = { 0.5f };
  read.Occluders[1].TriangleVertices = { { { 0, 0, 0 } }, { { 1, 0, 0 } }, { { 0, 1, 0 } } };
  EXPECT_EQ(nimbus::SceneHash(read), nimbus::SceneHash(Version4Scene()));
}

// The version-4 example of docs/scene-format.md is a valid scene and says what its notes say.
TEST(SceneJson, DocumentedVersion4ExampleParses)
{
  std::ifstream in(NIMBUS_SCENE_FORMAT_DOC);
  const std::string doc((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::size_t section = doc.find("#### Version 4 example");
  ASSERT_NE(section, std::string::npos);
  const std::size_t begin = doc.find("```json\n", section);
  ASSERT_NE(begin, std::string::npos);
  const std::size_t end = doc.find("```", begin + 8);
  ASSERT_NE(end, std::string::npos);
  const SceneDescription s = nimbus::ParseScene(doc.substr(begin + 8, end - begin - 8), "/docs");
  EXPECT_TRUE(s.UsesVersion4Features());
  ASSERT_EQ(s.Lights.size(), 2u);
  EXPECT_EQ(s.Lights[0].Type, "spot");
  EXPECT_NEAR(s.Lights[0].Intensity / (s.Lights[0].Position[2] * s.Lights[0].Position[2]), 1.4,
    0.05); // "50 / 6^2 = 1.4"
  EXPECT_EQ(s.Lights[1].LightMap.Path, "/docs/lights/window_gobo.png");
  ASSERT_EQ(s.Occluders.size(), 2u);
  EXPECT_EQ(s.Occluders[0].Albedo, 0.0);                                  // black by default
  EXPECT_NEAR(s.Occluders[1].Max[0] - s.Occluders[1].Min[0], 0.3, 1e-12); // 30 cm
  // The projector's axis meets the wall (x = 6) inside it.
  const auto& p = s.Lights[1].Position;
  const auto& d = s.Lights[1].Direction;
  const double t = (6.0 - p[0]) / d[0];
  EXPECT_GT(p[1] + t * d[1], s.Occluders[1].Min[1]);
  EXPECT_LT(p[1] + t * d[1], s.Occluders[1].Max[1]);
  EXPECT_GT(p[2] + t * d[2], 0.0);
  EXPECT_LT(p[2] + t * d[2], s.Occluders[1].Max[2]);
}
