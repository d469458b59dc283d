#include "SceneAssets.h"

#include "vtkAlgorithm.h"
#include "vtkCallbackCommand.h"
#include "vtkCellArray.h"
#include "vtkCommand.h"
#include "vtkDataArray.h"
#include "vtkIdList.h"
#include "vtkImageData.h"
#include "vtkImageReader2.h"
#include "vtkImageReader2Factory.h"
#include "vtkNew.h"
#include "vtkOBJReader.h"
#include "vtkPLYReader.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkPolyDataAlgorithm.h"
#include "vtkSmartPointer.h"
#include "vtkTriangleFilter.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <stdexcept>

namespace nimbus
{
namespace
{
[[noreturn]] void Fail(const std::string& key, const std::string& what)
{
  throw std::invalid_argument(key + ": " + what);
}

std::string LowerExtension(const std::string& path)
{
  std::string extension = std::filesystem::path(path).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
    [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return extension;
}

/// A file that exists and is not a folder, else an error naming the key.
void RequireFile(const std::string& path, const std::string& key)
{
  std::error_code error;
  if (!std::filesystem::exists(path, error))
  {
    Fail(key, "cannot read '" + path + "': no such file");
  }
  if (std::filesystem::is_directory(path, error))
  {
    Fail(key, "cannot read '" + path + "': it is a folder");
  }
}

/// Collects a VTK algorithm's error and warning messages (a reader that cannot read part
/// of a file may only warn, as vtkImageReader2 does for a truncated file); the text goes
/// into the exception. The caller's output window still shows them as VTK reports them.
class ErrorCollector
{
public:
  explicit ErrorCollector(vtkAlgorithm* algorithm)
  {
    this->Command->SetClientData(&this->Text);
    this->Command->SetCallback(
      [](vtkObject*, unsigned long, void* clientData, void* callData)
      {
        auto* text = static_cast<std::string*>(clientData);
        std::string message = callData ? static_cast<const char*>(callData) : "";
        const std::size_t object = message.find("): ");
        message = object == std::string::npos ? message : message.substr(object + 3);
        while (!message.empty() && (message.back() == '\n' || message.back() == ' '))
        {
          message.pop_back();
        }
        *text += (text->empty() ? "" : "; ") + message;
      });
    algorithm->AddObserver(vtkCommand::ErrorEvent, this->Command);
    algorithm->AddObserver(vtkCommand::WarningEvent, this->Command);
  }
  const std::string& GetText() const { return this->Text; }

private:
  std::string Text;
  vtkNew<vtkCallbackCommand> Command;
};

/// A binary PGM or PPM (P5, P6) file's header, checked before VTK reads it: vtkPNMReader
/// reads a truncated file with only a generic warning (no event to observe) and ignores
/// maxval, so here the file must hold every pixel and maxval must be 255. Other magic
/// numbers are left to the reader (which refuses them).
void CheckPnm(const std::string& path, const std::string& key)
{
  std::ifstream in(path, std::ios::binary);
  std::string magic(2, '\0');
  if (!in.read(&magic[0], 2) || (magic != "P5" && magic != "P6"))
  {
    return;
  }
  long long fields[3] = { 0, 0, 0 };
  for (long long& field : fields)
  {
    int c = in.get();
    while (c != EOF && (std::isspace(c) || c == '#'))
    {
      if (c == '#')
      {
        while (c != EOF && c != '\n')
        {
          c = in.get();
        }
      }
      c = in.get();
    }
    if (c == EOF || !std::isdigit(c))
    {
      Fail(key, "cannot read '" + path + "' as an image: a bad " + magic + " header");
    }
    while (c != EOF && std::isdigit(c) && field < 1000000000)
    {
      field = 10 * field + (c - '0');
      c = in.get();
    }
  }
  if (fields[2] != 255)
  {
    Fail(key,
      "'" + path + "' has maxval " + std::to_string(fields[2]) +
        "; a PGM or PPM light map needs maxval 255 (8 bits)");
  }
  const long long header = static_cast<long long>(in.tellg());
  const long long need = fields[0] * fields[1] * (magic == "P6" ? 3 : 1);
  std::error_code error;
  const auto size = static_cast<long long>(std::filesystem::file_size(path, error));
  if (error || header < 0 || size - header < need)
  {
    Fail(key,
      "cannot read '" + path + "' as an image: it is truncated (" + std::to_string(fields[0]) +
        " x " + std::to_string(fields[1]) + " pixels need " + std::to_string(need) +
        " bytes after the header, it has " + std::to_string(std::max(0LL, size - header)) + ")");
  }
}

/// sRGB's electro-optical transfer function (IEC 61966-2-1): encoded [0, 1] to linear.
double DecodeSrgb(double c)
{
  return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}
} // namespace

LightMapDescription ReadLightMap(const std::string& path, const std::string& key)
{
  RequireFile(path, key);
  const std::string extension = LowerExtension(path);
  if (extension == ".pgm" || extension == ".ppm" || extension == ".pnm")
  {
    CheckPnm(path, key);
  }
  vtkSmartPointer<vtkImageReader2> reader;
  reader.TakeReference(vtkImageReader2Factory::CreateImageReader2(path.c_str()));
  if (!reader)
  {
    Fail(key, "cannot read '" + path + "' as an image (.png, .pgm, .ppm, .pnm)");
  }
  const ErrorCollector errors(reader);
  reader->SetFileName(path.c_str());
  reader->Update();
  vtkImageData* image = reader->GetOutput();
  vtkDataArray* scalars = image ? image->GetPointData()->GetScalars() : nullptr;
  int dims[3] = { 0, 0, 0 };
  if (image)
  {
    image->GetDimensions(dims);
  }
  if (!scalars || !errors.GetText().empty() || dims[0] < 1 || dims[1] < 1)
  {
    Fail(key,
      "cannot read '" + path + "' as an image" +
        (errors.GetText().empty() ? std::string(" (no pixels)") : ": " + errors.GetText()));
  }
  if (dims[2] != 1)
  {
    Fail(key, "'" + path + "' is a volume of " + std::to_string(dims[2]) + " slices, not an image");
  }
  if (dims[0] > kMaxLightMapSide || dims[1] > kMaxLightMapSide ||
    static_cast<std::size_t>(dims[0]) * static_cast<std::size_t>(dims[1]) > kMaxLightMapPixels)
  {
    Fail(key,
      "'" + path + "' has " + std::to_string(dims[0]) + " x " + std::to_string(dims[1]) +
        " pixels; a light map may have at most " + std::to_string(kMaxLightMapSide) +
        " a side and " + std::to_string(kMaxLightMapPixels) + " in all");
  }
  // Integer samples are normalised by their type's range (8 bits: 255, 16 bits: 65535);
  // PNG is sRGB-encoded, PNM linear.
  const int type = scalars->GetDataType();
  double scale = 1.0;
  if (type == VTK_UNSIGNED_CHAR)
  {
    scale = 1.0 / 255.0;
  }
  else if (type == VTK_UNSIGNED_SHORT)
  {
    scale = 1.0 / 65535.0;
  }
  else
  {
    Fail(key,
      "'" + path + "' has " + std::string(scalars->GetDataTypeAsString()) +
        " samples; a light map needs 8 or 16 bits per channel");
  }
  const bool srgb = extension == ".png";
  const int components = scalars->GetNumberOfComponents();
  LightMapDescription map;
  map.Path = path;
  map.Width = dims[0];
  map.Height = dims[1];
  map.Luminance.resize(static_cast<std::size_t>(dims[0]) * static_cast<std::size_t>(dims[1]));
  auto linear = [&](vtkIdType id, int c)
  {
    const double x = scalars->GetComponent(id, c) * scale;
    return srgb ? DecodeSrgb(x) : x;
  };
  for (int j = 0; j < dims[1]; ++j)
  {
    // VTK's row j counts from the bottom; the description's row 0 is the file's first.
    const std::size_t row = static_cast<std::size_t>(dims[1] - 1 - j);
    for (int i = 0; i < dims[0]; ++i)
    {
      const vtkIdType id = static_cast<vtkIdType>(j) * dims[0] + i;
      const double y = components >= 3
        ? 0.2126 * linear(id, 0) + 0.7152 * linear(id, 1) + 0.0722 * linear(id, 2)
        : linear(id, 0);
      map.Luminance[row * static_cast<std::size_t>(dims[0]) + i] = static_cast<float>(y);
    }
  }
  return map;
}

std::vector<std::array<double, 3>> ReadMeshTriangles(
  const std::string& path, const std::string& key)
{
  RequireFile(path, key);
  const std::string extension = LowerExtension(path);
  vtkSmartPointer<vtkPolyDataAlgorithm> reader;
  if (extension == ".ply")
  {
    auto ply = vtkSmartPointer<vtkPLYReader>::New();
    if (!ply->CanReadFile(path.c_str()))
    {
      Fail(key, "cannot read '" + path + "' as a PLY mesh");
    }
    ply->SetFileName(path.c_str());
    reader = ply;
  }
  else if (extension == ".obj")
  {
    auto obj = vtkSmartPointer<vtkOBJReader>::New();
    obj->SetFileName(path.c_str());
    reader = obj;
  }
  else
  {
    Fail(key, "cannot read '" + path + "': a mesh must be a .ply or .obj file");
  }
  const ErrorCollector readErrors(reader);
  vtkNew<vtkTriangleFilter> triangles;
  const ErrorCollector triangleErrors(triangles);
  triangles->SetInputConnection(reader->GetOutputPort());
  triangles->PassVertsOff();
  triangles->PassLinesOff();
  triangles->Update();
  if (!readErrors.GetText().empty() || !triangleErrors.GetText().empty())
  {
    Fail(key,
      "cannot read '" + path + "' as a mesh: " + readErrors.GetText() +
        (readErrors.GetText().empty() || triangleErrors.GetText().empty() ? "" : "; ") +
        triangleErrors.GetText());
  }
  vtkPolyData* mesh = triangles->GetOutput();
  vtkCellArray* polys = mesh->GetPolys();
  const vtkIdType count = polys ? polys->GetNumberOfCells() : 0;
  if (count == 0)
  {
    vtkPolyData* read = reader->GetOutput();
    Fail(key,
      "'" + path + "' holds no triangles (" + std::to_string(read->GetNumberOfPoints()) +
        " points, " + std::to_string(read->GetNumberOfCells()) +
        " cells read; an occluder needs polygons)");
  }
  if (static_cast<std::size_t>(count) > kMaxMeshTriangles)
  {
    Fail(key,
      "'" + path + "' has " + std::to_string(count) + " triangles; a mesh may have at most " +
        std::to_string(kMaxMeshTriangles));
  }
  std::vector<std::array<double, 3>> vertices;
  vertices.reserve(3 * static_cast<std::size_t>(count));
  vtkPoints* points = mesh->GetPoints();
  vtkNew<vtkIdList> ids;
  for (vtkIdType c = 0; c < count; ++c)
  {
    polys->GetCellAtId(c, ids);
    if (ids->GetNumberOfIds() != 3)
    {
      continue; // vtkTriangleFilter leaves only triangles; degenerate cells are skipped
    }
    for (vtkIdType k = 0; k < 3; ++k)
    {
      std::array<double, 3> x;
      points->GetPoint(ids->GetId(k), x.data());
      if (!(std::isfinite(x[0]) && std::isfinite(x[1]) && std::isfinite(x[2])))
      {
        Fail(key,
          "'" + path + "' has a vertex that is not finite (point " + std::to_string(ids->GetId(k)) +
            ")");
      }
      vertices.push_back(x);
    }
  }
  if (vertices.empty())
  {
    Fail(key, "'" + path + "' holds no triangles");
  }
  return vertices;
}

void LoadSceneAssets(SceneDescription& scene)
{
  std::map<std::string, LightMapDescription> maps;
  for (std::size_t i = 0; i < scene.Lights.size(); ++i)
  {
    LightMapDescription& map = scene.Lights[i].LightMap;
    if (scene.Lights[i].Type != "spot" || map.Path.empty() || !map.Luminance.empty())
    {
      continue;
    }
    auto found = maps.find(map.Path);
    if (found == maps.end())
    {
      found = maps
                .emplace(map.Path,
                  ReadLightMap(map.Path, "scene.lights[" + std::to_string(i) + "].light_map"))
                .first;
    }
    map = found->second;
  }
  std::map<std::string, std::vector<std::array<double, 3>>> meshes;
  for (std::size_t i = 0; i < scene.Occluders.size(); ++i)
  {
    OccluderDescription& o = scene.Occluders[i];
    if (o.Type != "mesh" || !o.TriangleVertices.empty())
    {
      continue;
    }
    auto found = meshes.find(o.Path);
    if (found == meshes.end())
    {
      found = meshes
                .emplace(o.Path,
                  ReadMeshTriangles(o.Path, "scene.occluders[" + std::to_string(i) + "].path"))
                .first;
    }
    o.TriangleVertices = found->second;
  }
}
} // namespace nimbus
