// The files a version-4 scene names besides its densities (Reference/SceneAssets.h), read
// with VTK: light maps (PGM, PNG 8 and 16 bits, grey, grey + alpha, RGB) with their row
// order and decoding, meshes (PLY, OBJ) triangulated, and every way a file can be bad,
// named by its scene key; then whole scenes through vtkNimbusReferenceRenderer: a spot
// through a light map onto a wall pins the map's orientation from the file to the image,
// and a missing file is an error naming the key.
#include "MessageCatcher.h"
#include "SceneAssets.h"
#include "SceneJson.h"
#include "vtkNimbusReferenceRenderer.h"

#include "vtkCubeSource.h"
#include "vtkDataArray.h"
#include "vtkImageData.h"
#include "vtkNew.h"
#include "vtkPLYWriter.h"
#include "vtkPNGWriter.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkUnsignedCharArray.h"
#include "vtkUnsignedShortArray.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#ifndef NIMBUS_SCENES_DIR
#error "NIMBUS_SCENES_DIR must name Data/Scenes"
#endif

namespace
{
namespace fs = std::filesystem;
using nimbus::testing::MessageCatcher;

fs::path TemporaryDirectory()
{
  static const fs::path dir = []
  {
    const fs::path d =
      fs::temp_directory_path() / ("nimbus-scene-assets-" + std::to_string(std::random_device{}()));
    fs::create_directories(d);
    return d;
  }();
  return dir;
}

/// A binary PGM (P5, maxval 255) whose bytes are written here: the file's first row first.
std::string WritePgm(
  const std::string& name, int width, int height, const std::vector<unsigned char>& rowsFromTheTop)
{
  const fs::path path = TemporaryDirectory() / name;
  std::ofstream out(path, std::ios::binary);
  out << "P5\n" << width << " " << height << "\n255\n";
  out.write(reinterpret_cast<const char*>(rowsFromTheTop.data()),
    static_cast<std::streamsize>(rowsFromTheTop.size()));
  return path.string();
}

/// A PNG written by vtkPNGWriter from an image whose VTK row j = 0 is the bottom (the
/// writer puts VTK's top row first in the file).
template <class Array, class T>
std::string WritePng(const std::string& name, int width, int height, int components,
  const std::vector<T>& vtkRowsFromTheBottom)
{
  vtkNew<vtkImageData> image;
  image->SetDimensions(width, height, 1);
  vtkNew<Array> values;
  values->SetNumberOfComponents(components);
  values->SetNumberOfTuples(static_cast<vtkIdType>(width) * height);
  for (std::size_t i = 0; i < vtkRowsFromTheBottom.size(); ++i)
  {
    values->SetValue(static_cast<vtkIdType>(i), vtkRowsFromTheBottom[i]);
  }
  image->GetPointData()->SetScalars(values);
  const fs::path path = TemporaryDirectory() / name;
  vtkNew<vtkPNGWriter> writer;
  writer->SetFileName(path.string().c_str());
  writer->SetInputData(image);
  writer->Write();
  return path.string();
}

std::string WriteText(const std::string& name, const std::string& text)
{
  const fs::path path = TemporaryDirectory() / name;
  std::ofstream(path) << text;
  return path.string();
}

double DecodeSrgb(double c)
{
  return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}

/// Expects f to throw std::invalid_argument whose message starts with `prefix`.
template <class F>
void ExpectError(F f, const std::string& prefix)
{
  try
  {
    f();
    ADD_FAILURE() << "no error; expected " << prefix;
  }
  catch (const std::invalid_argument& error)
  {
    EXPECT_EQ(std::string(error.what()).rfind(prefix, 0), 0u)
      << "message: " << error.what() << "\nexpected prefix: " << prefix;
  }
}
} // namespace

//------------------------------------------------------------------------------
// PGM: linear (value / 255), the file's first row is row 0 (v = 0.5 / Height).
TEST(ReferenceSceneAssets, PgmLightMapRowsAndValues)
{
  // 3 x 2: first row 255 0 51, second row 0 128 255.
  const std::string path = WritePgm("map.pgm", 3, 2, { 255, 0, 51, 0, 128, 255 });
  const nimbus::LightMapDescription map = nimbus::ReadLightMap(path, "scene.lights[0].light_map");
  EXPECT_EQ(map.Path, path);
  ASSERT_EQ(map.Width, 3);
  ASSERT_EQ(map.Height, 2);
  const std::vector<float> expected = { 1.0f, 0.0f, 0.2f, 0.0f, 128.0f / 255.0f, 1.0f };
  ASSERT_EQ(map.Luminance.size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i)
  {
    EXPECT_FLOAT_EQ(map.Luminance[i], expected[i]) << i;
  }
}

//------------------------------------------------------------------------------
// PNG: sRGB-decoded (8 and 16 bits), grey, grey + alpha (alpha ignored), RGB as Y of
// linear sRGB; the same row order as PGM (the file's first row is row 0).
TEST(ReferenceSceneAssets, PngLightMapsDecodeSrgbAndKeepTheRowOrder)
{
  // Grey 2 x 2, VTK rows from the bottom: bottom 10 20, top 200 128: the file's first row
  // (the top of the picture) is 200 128.
  const std::string grey =
    WritePng<vtkUnsignedCharArray, unsigned char>("grey.png", 2, 2, 1, { 10, 20, 200, 128 });
  nimbus::LightMapDescription map = nimbus::ReadLightMap(grey, "key");
  ASSERT_EQ(map.Luminance.size(), 4u);
  const double values[4] = { 200, 128, 10, 20 };
  for (int i = 0; i < 4; ++i)
  {
    EXPECT_NEAR(map.Luminance[i], DecodeSrgb(values[i] / 255.0), 1e-7) << i;
  }
  EXPECT_NEAR(map.Luminance[1], 0.2158605, 1e-6); // sRGB 128 is 21.6 % linear
  // Grey + alpha: the alpha does not change the luminance.
  const std::string alpha =
    WritePng<vtkUnsignedCharArray, unsigned char>("alpha.png", 1, 1, 2, { 128, 7 });
  EXPECT_NEAR(nimbus::ReadLightMap(alpha, "key").Luminance[0], 0.2158605, 1e-6);
  // RGB: Y = 0.2126 R + 0.7152 G + 0.0722 B of the decoded channels.
  const std::string rgb =
    WritePng<vtkUnsignedCharArray, unsigned char>("rgb.png", 2, 1, 3, { 255, 0, 0, 30, 200, 90 });
  map = nimbus::ReadLightMap(rgb, "key");
  EXPECT_NEAR(map.Luminance[0], 0.2126, 1e-6);
  EXPECT_NEAR(map.Luminance[1],
    0.2126 * DecodeSrgb(30 / 255.0) + 0.7152 * DecodeSrgb(200 / 255.0) +
      0.0722 * DecodeSrgb(90 / 255.0),
    1e-6);
  // 16 bits: decoded from sRGB over 65535.
  const std::string deep =
    WritePng<vtkUnsignedShortArray, unsigned short>("deep.png", 2, 1, 1, { 65535, 32768 });
  map = nimbus::ReadLightMap(deep, "key");
  EXPECT_NEAR(map.Luminance[0], 1.0, 1e-7);
  EXPECT_NEAR(map.Luminance[1], DecodeSrgb(32768.0 / 65535.0), 1e-7);
}

//------------------------------------------------------------------------------
TEST(ReferenceSceneAssets, BadLightMapsAreNamedByTheirKey)
{
  const std::string key = "scene.lights[2].light_map";
  const std::string missing = (TemporaryDirectory() / "none.png").string();
  ExpectError([&] { nimbus::ReadLightMap(missing, key); },
    key + ": cannot read '" + missing + "': no such file");
  const std::string folder = (TemporaryDirectory() / "folder.png").string();
  fs::create_directories(folder);
  ExpectError([&] { nimbus::ReadLightMap(folder, key); },
    key + ": cannot read '" + folder + "': it is a folder");
  const std::string text = WriteText("text.png", "not a picture\n");
  ExpectError(
    [&] { nimbus::ReadLightMap(text, key); }, key + ": cannot read '" + text + "' as an image");
  const std::string truncated = WriteText("truncated.pgm", "P5\n4 4\n255\nab");
  ExpectError([&] { nimbus::ReadLightMap(truncated, key); },
    key + ": cannot read '" + truncated +
      "' as an image: it is truncated (4 x 4 pixels need 16 bytes after the header, it has 2)");
  const std::string deep = WriteText("deep.pgm", "P5\n1 1\n65535\nab");
  ExpectError([&] { nimbus::ReadLightMap(deep, key); },
    key + ": '" + deep + "' has maxval 65535; a PGM or PPM light map needs maxval 255 (8 bits)");
  const std::string empty = WriteText("empty.pgm", "");
  ExpectError([&] { nimbus::ReadLightMap(empty, key); }, key + ": cannot read '" + empty + "'");
}

//------------------------------------------------------------------------------
// Meshes: a cube from PLY (6 quads: 12 triangles), an OBJ with a quad and a triangle (3),
// in the file's coordinates; empty, garbage and missing files named by their key.
TEST(ReferenceSceneAssets, MeshesAreTriangulated)
{
  vtkNew<vtkCubeSource> cube;
  cube->SetBounds(-1.0, 1.0, -2.0, 2.0, 0.0, 10.0);
  const std::string ply = (TemporaryDirectory() / "cube.ply").string();
  vtkNew<vtkPLYWriter> writer;
  writer->SetInputConnection(cube->GetOutputPort());
  writer->SetFileName(ply.c_str());
  ASSERT_EQ(writer->Write(), 1);
  const std::vector<std::array<double, 3>> triangles =
    nimbus::ReadMeshTriangles(ply, "scene.occluders[0].path");
  ASSERT_EQ(triangles.size(), 36u);
  for (const auto& x : triangles)
  {
    EXPECT_TRUE(std::abs(x[0]) == 1.0 && std::abs(x[1]) == 2.0 && (x[2] == 0.0 || x[2] == 10.0));
  }
  const std::string obj = WriteText("post.obj",
    "# a quad and a triangle\nv 0 0 0\nv 1 0 0\nv 1 0 3\nv 0 0 3\nv 0 1 0\n"
    "f 1 2 3 4\nf 1 4 5\n");
  const std::vector<std::array<double, 3>> post = nimbus::ReadMeshTriangles(obj, "key");
  EXPECT_EQ(post.size(), 9u);
  const std::string key = "scene.occluders[1].path";
  const std::string points = WriteText("points.obj", "v 0 0 0\nv 1 0 0\n");
  ExpectError(
    [&] { nimbus::ReadMeshTriangles(points, key); }, key + ": '" + points + "' holds no triangles");
  const std::string lines = WriteText("lines.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nl 1 2 3\n");
  ExpectError(
    [&] { nimbus::ReadMeshTriangles(lines, key); }, key + ": '" + lines + "' holds no triangles");
  const std::string garbage = WriteText("garbage.ply", "this is not a PLY file\n");
  ExpectError([&] { nimbus::ReadMeshTriangles(garbage, key); },
    key + ": cannot read '" + garbage + "' as a PLY mesh");
  const std::string missing = (TemporaryDirectory() / "none.obj").string();
  ExpectError([&] { nimbus::ReadMeshTriangles(missing, key); },
    key + ": cannot read '" + missing + "': no such file");
  const std::string nan = WriteText("nan.obj", "v nan 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\n");
  try
  {
    const auto read = nimbus::ReadMeshTriangles(nan, key);
    // vtkOBJReader may read "nan" as 0; then the mesh is finite.
    for (const auto& x : read)
    {
      EXPECT_TRUE(std::isfinite(x[0]) && std::isfinite(x[1]) && std::isfinite(x[2]));
    }
  }
  catch (const std::invalid_argument& error)
  {
    EXPECT_EQ(std::string(error.what()).rfind(key + ": ", 0), 0u) << error.what();
  }
}

//------------------------------------------------------------------------------
// The project's scenes lit by lights (Data/Scenes, format version 4) name files that exist
// and read: every light map has pixels, every mesh triangles.
TEST(ReferenceSceneAssets, ProjectScenesReadTheirFiles)
{
  int maps = 0, meshes = 0;
  for (const auto& entry : fs::directory_iterator(NIMBUS_SCENES_DIR))
  {
    if (entry.path().extension() != ".json")
    {
      continue;
    }
    SCOPED_TRACE(entry.path().string());
    nimbus::SceneDescription scene = nimbus::LoadScene(entry.path().string());
    ASSERT_NO_THROW(nimbus::LoadSceneAssets(scene));
    for (const nimbus::LightDescription& light : scene.Lights)
    {
      if (!light.LightMap.Path.empty())
      {
        ++maps;
        EXPECT_EQ(light.LightMap.Luminance.size(),
          static_cast<std::size_t>(light.LightMap.Width) * light.LightMap.Height);
        EXPECT_GT(
          *std::max_element(light.LightMap.Luminance.begin(), light.LightMap.Luminance.end()),
          0.0f);
      }
    }
    for (const nimbus::OccluderDescription& occluder : scene.Occluders)
    {
      if (occluder.Type == "mesh")
      {
        ++meshes;
        EXPECT_GE(occluder.TriangleVertices.size(), 3u);
      }
    }
  }
  std::printf("the project's scenes: %d light maps and %d meshes read\n", maps, meshes);
}

//------------------------------------------------------------------------------
// LoadSceneAssets fills what a parsed scene names (relative paths resolved against the
// scene file's folder), each file once, and leaves pixels given in code alone.
TEST(ReferenceSceneAssets, LoadSceneAssetsFillsTheDescription)
{
  WritePgm("gobo.pgm", 2, 1, { 0, 255 });
  WriteText("post.obj", "v 0 0 0\nv 1 0 0\nv 1 0 3\nv 0 0 3\nf 1 2 3 4\n");
  const std::string scene = WriteText("assets.json", R"({
    "nimbus_scene": 4,
    "camera": {"position": [0, -50, 5], "focal_point": [0, 0, 5]},
    "medium": {"density": {"type": "metaball_cloud"}, "extinction_per_density": 0},
    "sun": {"azimuth_degrees": 0, "elevation_degrees": 30},
    "lights": [
      {"type": "spot", "position": [0, -20, 5], "direction": [0, 1, 0],
       "cone_angle_degrees": 30, "intensity": 1000, "light_map": "gobo.pgm"},
      {"type": "spot", "position": [0, -20, 5], "direction": [0, 1, 0],
       "cone_angle_degrees": 30, "intensity": 1000, "light_map": "gobo.pgm"}],
    "occluders": [{"type": "mesh", "path": "post.obj", "scale": 2},
                  {"type": "box", "min": [0, 0, 0], "max": [1, 1, 1]}]
  })");
  nimbus::SceneDescription s = nimbus::LoadScene(scene);
  nimbus::LoadSceneAssets(s);
  ASSERT_EQ(s.Lights[0].LightMap.Luminance.size(), 2u);
  EXPECT_EQ(s.Lights[0].LightMap.Luminance[1], 1.0f);
  EXPECT_EQ(s.Lights[1].LightMap.Luminance, s.Lights[0].LightMap.Luminance);
  EXPECT_EQ(s.Occluders[0].TriangleVertices.size(), 6u);
  EXPECT_TRUE(s.Occluders[1].TriangleVertices.empty());
  // Pixels already there are kept (a description built in code).
  s.Lights[0].LightMap.Luminance = { 0.25f, 0.5f };
  nimbus::LoadSceneAssets(s);
  EXPECT_EQ(s.Lights[0].LightMap.Luminance[0], 0.25f);
  // Missing files: the key of the first one.
  s = nimbus::LoadScene(scene);
  s.Occluders[0].Path = (TemporaryDirectory() / "gone.obj").string();
  ExpectError([&] { nimbus::LoadSceneAssets(s); }, "scene.occluders[0].path: cannot read '");
}

//------------------------------------------------------------------------------
// End to end through vtkNimbusReferenceRenderer: a spot aiming north at a white wall
// through a light map black on its left half (the file's left columns), then through one
// black on its top half (the file's first rows). The light map is thrown like a slide
// projector's picture, upright and unmirrored to someone behind the light looking along
// the beam (Physics/SpotLight.h: e1 = +x, east, and e2 = +z, up, for a beam aiming north;
// the file's first row at the top, v = 1). The camera stands behind the light, looking
// north (east to its right, up up), so at single scattering it sees the picture as it is:
// with the first map the east half of the wall (the right half of the image) lit and the
// west half exactly black (but for the column that holds the map's bilinear ramp across
// the axis); with the second the lower half lit and the upper half exactly black (but for
// the row that holds the ramp). A post (OBJ mesh) stands in the lit half of the first
// beam. Single scattering refuses the scene by name; a missing light map is an error naming
// its key.
TEST(ReferenceSceneAssets, SpotThroughALightMapOntoAWall)
{
  std::vector<unsigned char> gobo(32 * 32, 0), topBlack(32 * 32, 0);
  for (int row = 0; row < 32; ++row)
  {
    for (int column = 0; column < 32; ++column)
    {
      gobo[row * 32 + column] = column < 16 ? 0 : 255;
      topBlack[row * 32 + column] = row < 16 ? 0 : 255;
    }
  }
  WritePgm("wall-gobo.pgm", 32, 32, gobo);
  WritePgm("wall-gobo-top-black.pgm", 32, 32, topBlack);
  WriteText("wall-post.obj", "v 0 0 -30\nv 0.5 0 -30\nv 0.5 0 30\nv 0 0 30\nf 1 2 3 4\n");
  const std::string text = R"({
    "nimbus_scene": 4, "name": "wall",
    "camera": {"position": [0, -50, 5], "focal_point": [0, 0, 5], "view_angle": 20,
               "width": 16, "height": 8},
    "medium": {"density": {"type": "metaball_cloud", "parameters": {"Dimensions": [4, 4, 4],
               "NumberOfLevels": 0, "NumberOfBaseBalls": 1}}, "extinction_per_density": 0},
    "sun": {"azimuth_degrees": 0, "elevation_degrees": 30, "illuminance": 0},
    "atmosphere": {"enabled": false}, "ground": {"enabled": false},
    "background": {"type": "black"}, "spectral_samples": 4,
    "lights": [{"type": "spot", "position": [0, -20, 5], "direction": [0, 1, 0],
                "cone_angle_degrees": 30, "intensity": 1000, "light_map": "@MAP@"}],
    "occluders": [{"type": "box", "min": [-40, 0, -40], "max": [40, 1, 40], "albedo": 1},
                  {"type": "mesh", "path": "wall-post.obj", "albedo": 0.5,
                   "translate": [5.5, -10, 0]}]
  })";
  auto write = [&](const std::string& name, const std::string& map)
  {
    std::string t = text;
    t.replace(t.find("@MAP@"), 5, map);
    return WriteText(name, t);
  };
  const std::string good = write("wall.json", "wall-gobo.pgm");
  const std::string top = write("wall-top-black.json", "wall-gobo-top-black.pgm");
  vtkNew<vtkNimbusReferenceRenderer> renderer;
  MessageCatcher messages(renderer);
  renderer->SetModeToPathTracing();
  renderer->SetMinSamplesPerPixel(64);
  renderer->SetMaxSamplesPerPixel(64);
  renderer->SetMaxScatteringOrder(1);
  renderer->SetNumberOfThreads(2);
  // The green radiance of pixel (i, j), i = 0 the image's left (west), j = 0 its bottom.
  auto render = [&](const std::string& scene, const char* what)
  {
    std::vector<double> green;
    renderer->SetSceneFileName(scene.c_str());
    renderer->Update();
    EXPECT_EQ(messages.AllErrors(), "");
    vtkDataArray* radiance = renderer->GetOutput()->GetPointData()->GetArray("radiance");
    EXPECT_NE(radiance, nullptr);
    if (radiance == nullptr || radiance->GetNumberOfTuples() != 16 * 8)
    {
      ADD_FAILURE() << what << ": no 16 x 8 radiance image";
      return green;
    }
    green.resize(16 * 8);
    std::string picture;
    for (int j = 7; j >= 0; --j)
    {
      for (int i = 0; i < 16; ++i)
      {
        green[j * 16 + i] = radiance->GetComponent(j * 16 + i, 1);
        EXPECT_TRUE(std::isfinite(green[j * 16 + i]));
        picture += green[j * 16 + i] > 0.0 ? '#' : '.';
      }
      picture += '\n';
    }
    std::printf("the wall at single scattering through %s (# lit), west on the left:\n%s", what,
      picture.c_str());
    return green;
  };
  {
    const std::vector<double> g = render(good, "a light map black on its left half");
    ASSERT_EQ(g.size(), 16u * 8u);
    // The image's columns meet at the axis (x = 0 on the wall, 2.2 m wide): column 7 holds
    // the map's ramp between its columns 15 and 16 (u from 0.484 to 0.516), which reaches
    // 0.37 m west of the axis.
    double west = 0.0, east = 0.0;
    for (int j = 0; j < 8; ++j)
    {
      for (int i = 0; i < 16; ++i)
      {
        west += i < 7 ? g[j * 16 + i] : 0.0;
        east += i > 7 ? g[j * 16 + i] : 0.0;
      }
    }
    EXPECT_EQ(west, 0.0);
    EXPECT_GT(east, 0.0);
  }
  {
    const std::vector<double> g = render(top, "a light map black on its top half");
    ASSERT_EQ(g.size(), 16u * 8u);
    // The image's rows meet at the axis (z = 5 m on the wall, 2.2 m high): row 4 holds the
    // map's ramp between its rows 15 and 16 (v from 0.516 to 0.484), which reaches 0.37 m
    // above the axis.
    double upper = 0.0, lower = 0.0;
    for (int j = 0; j < 8; ++j)
    {
      for (int i = 0; i < 16; ++i)
      {
        upper += j > 4 ? g[j * 16 + i] : 0.0;
        lower += j < 4 ? g[j * 16 + i] : 0.0;
      }
    }
    EXPECT_EQ(upper, 0.0);
    EXPECT_GT(lower, 0.0);
  }
  // Single scattering refuses spots and occluders by name.
  messages.Errors.clear();
  renderer->SetModeToSingleScattering();
  renderer->Update();
  EXPECT_NE(messages.AllErrors().find("the single-scattering renderer does not render point, "
                                      "polyline and spot lights (scene.lights), occluders "
                                      "(scene.occluders)"),
    std::string::npos)
    << messages.AllErrors();
  // A missing light map: the scene file, then the key.
  const std::string bad = write("wall-missing.json", "nowhere.pgm");
  messages.Errors.clear();
  renderer->SetSceneFileName(bad.c_str());
  renderer->SetModeToPathTracing();
  renderer->Update();
  EXPECT_NE(messages.AllErrors().find(bad + ": scene.lights[0].light_map: cannot read '" +
              (TemporaryDirectory() / "nowhere.pgm").string() + "': no such file"),
    std::string::npos)
    << messages.AllErrors();
  EXPECT_EQ(renderer->GetOutput()->GetPointData()->GetArray("radiance"), nullptr);
}
