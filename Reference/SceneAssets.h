// The files a scene names besides its densities (scene format version 4): the light maps
// of spot lights and the meshes of occluders, read with VTK into the plain C++ description
// (SceneDescription.h) that the reference renderers use. Not wrapped (plain C++ types);
// VTK glue, so it lives beside the vtk classes, not in Core/. vtkNimbusReferenceRenderer
// calls LoadSceneAssets after reading the scene.
//
// Light maps (LightMapDescription): any image vtkImageReader2Factory reads; the scene
// format allows .png, .pgm, .ppm and .pnm. Luminance per pixel, row 0 the file's first
// row (the top of the picture as an image viewer shows it; VTK's readers put it last, and
// it is flipped back here). PNG (8 or 16 bits per channel) is decoded from sRGB
// (IEC 61966-2-1) to linear; PNM (binary P5/P6, maxval 255) is taken as linear,
// value / 255. One channel: that value; two: grey and alpha (alpha ignored); three or
// four: Y = 0.2126 R + 0.7152 G + 0.0722 B of the linear values (alpha ignored). So a
// white pixel is 1 and a black one 0.
//
// Meshes (OccluderDescription::TriangleVertices): .ply by vtkPLYReader, .obj by
// vtkOBJReader, polygons and strips triangulated by vtkTriangleFilter (points and lines
// are dropped), in the file's coordinates (the renderer applies scale and translate).
#ifndef NimbusSceneAssets_h
#define NimbusSceneAssets_h

#include "NimbusReferenceModule.h"
#include "SceneDescription.h"

#include <array>
#include <cstddef>
#include <string>
#include <vector>

namespace nimbus
{
/// Largest light map read: 16384 pixels a side and 2^26 pixels (256 MiB of floats).
constexpr int kMaxLightMapSide = 16384;
constexpr std::size_t kMaxLightMapPixels = std::size_t(1) << 26;
/// Most triangles a mesh may have: 2^21 (about 2.1 million). Each costs about 280 bytes
/// while the renderer holds it (the description's 72, the hierarchy's triangle 104, its
/// nodes ~30, the build's bounds 72): 0.6 GiB at the limit.
constexpr std::size_t kMaxMeshTriangles = std::size_t(1) << 21;

/// Reads an image into a light map (Path set to `path`). Throws std::invalid_argument
/// whose message starts with `key` (e.g. "scene.lights[0].light_map") when the file is
/// missing, cannot be read as an image, is empty or too large.
NIMBUSREFERENCE_EXPORT LightMapDescription ReadLightMap(
  const std::string& path, const std::string& key);

/// Reads a .ply or .obj mesh's triangles, three vertices each, in the file's coordinates.
/// Throws std::invalid_argument whose message starts with `key` when the file is missing
/// or unreadable, holds no triangles, too many, or a vertex that is not finite.
NIMBUSREFERENCE_EXPORT std::vector<std::array<double, 3>> ReadMeshTriangles(
  const std::string& path, const std::string& key);

/// Fills every spot light's light map and every mesh occluder's triangles that the
/// description names but does not hold yet (each file read once). Throws
/// std::invalid_argument naming the scene key, as ReadLightMap and ReadMeshTriangles do.
NIMBUSREFERENCE_EXPORT void LoadSceneAssets(SceneDescription& scene);
} // namespace nimbus

#endif
