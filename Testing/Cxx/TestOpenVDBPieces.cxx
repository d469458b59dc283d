// A piece of a grid read by the reader (IO/Core/VdbGrids.h ReadDense, which reads only the
// topology that touches the piece: IO/Core/VdbClippedRead.h) equals the same box of the whole
// grid as OpenVDB's own io::File reads it, bit for bit: grids written here with OpenVDB that
// span several upper and lower internal nodes (negative and positive coordinates, across the
// 128-voxel boundaries), with leaves partly active, inactive voxels of their own values, tiles
// at every level (a leaf-sized tile, a 128^3 tile, an inactive root tile) and a background
// that is not zero; float, double and Vec3s grids; written without compression, with zip,
// Blosc and active-mask compression, and as half floats. Then a y-up file through
// vtkNimbusOpenVDBReader: the pieces of the turned image equal the whole image. The same with
// only the reader's own OpenVDB registrations (RegisterOpenVdbTypes: no point-data registries,
// no delayed-load table), and a file's grids of other types listed with their value types.
#include "VdbArchive.h"
#include "VdbGrids.h"
#include "vtkNimbusOpenVDBReader.h"

#include "vtkDataArray.h"
#include "vtkExtentTranslator.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkSmartPointer.h"
#include "vtkStreamingDemandDrivenPipeline.h"

#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>
#include <openvdb/points/PointDataGrid.h>

#include <gtest/gtest.h>

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>
#include <unistd.h>
#include <vector>

namespace
{
using nimbus::vdb::IndexBox;

std::string TempPath(const std::string& name)
{
  return ::testing::TempDir() + "nimbus_vdbpieces_" + std::to_string(getpid()) + "_" + name;
}

float ValueAt(int i, int j, int k)
{
  const uint32_t h = uint32_t(i) * 73856093u ^ uint32_t(j) * 19349663u ^ uint32_t(k) * 83492791u;
  return float(h % 100000u) * 1.0e-3f + 0.001f; // fractions that half floats round
}

/// Voxels over x -40..170, y -10..140, z 100..150 (across index 0 and 128 on every axis, so
/// in 2 upper and several lower nodes), about 3 in 4 set: active, and every 11th set inactive
/// with its own value; a leaf-sized tile, an inactive one beside it, an inactive root tile far
/// away and (`bigTile`) an active 128^3 tile in an upper node; no tiles without `tiles`.
template <typename GridT, typename Convert>
typename GridT::Ptr MakeGrid(const std::string& name, typename GridT::ValueType background,
  Convert convert, bool tiles, bool bigTile)
{
  auto grid = GridT::create(background);
  grid->setName(name);
  auto accessor = grid->getAccessor();
  for (int k = 100; k <= 150; ++k)
    for (int j = -10; j <= 140; ++j)
      for (int i = -40; i <= 170; ++i)
      {
        const int h = (i * 7 + j * 13 + k * 29) & 3;
        if (h == 0 && (i + j) % 5 != 0)
        {
          continue; // a quarter left out (whole leaves too, below)
        }
        if ((i / 8 + j / 8 + k / 8) % 9 == 0)
        {
          continue;
        }
        const openvdb::Coord xyz(i, j, k);
        if ((i + 3 * j + 5 * k) % 11 == 0)
        {
          accessor.setValueOff(xyz, convert(ValueAt(i, j, k)));
        }
        else
        {
          accessor.setValueOn(xyz, convert(ValueAt(i, j, k)));
        }
      }
  if (!tiles)
  {
    return grid;
  }
  grid->tree().addTile(1, openvdb::Coord(200, 8, 16), convert(2.5f), true);
  grid->tree().addTile(1, openvdb::Coord(208, 8, 16), convert(-1.0f), false);
  grid->tree().addTile(3, openvdb::Coord(8192, 0, 0), convert(3.0f), false);
  if (bigTile)
  {
    grid->tree().addTile(2, openvdb::Coord(256, 0, 128), convert(1.75f), true);
  }
  return grid;
}

openvdb::GridPtrVec MakeGrids(bool tiles, bool bigTile, bool half)
{
  auto density = MakeGrid<openvdb::FloatGrid>(
    "density", 0.25f, [](float v) { return v; }, tiles, bigTile);
  density->setGridClass(openvdb::GRID_FOG_VOLUME);
  auto velocity = MakeGrid<openvdb::Vec3SGrid>(
    "velocity", openvdb::Vec3s(0.5f, 0.0f, -2.0f),
    [](float v) { return openvdb::Vec3s(v, 2.0f * v, -v); }, tiles, bigTile);
  auto temperature = MakeGrid<openvdb::DoubleGrid>(
    "temperature", 280.0, [](float v) { return 270.0 + double(v) / 3.0; }, tiles, bigTile);
  const auto transform = openvdb::math::Transform::createLinearTransform(0.5);
  transform->postTranslate(openvdb::Vec3d(10.0, -4.0, 2.0));
  openvdb::GridPtrVec grids{ density, velocity, temperature };
  for (auto& grid : grids)
  {
    grid->setTransform(transform->copy());
    grid->setSaveFloatAsHalf(half);
  }
  return grids;
}

std::string WriteGrids(const std::string& name, uint32_t compression, bool half, bool tiles,
  bool bigTile, const std::string& upAxis = "")
{
  openvdb::initialize();
  const std::string path = TempPath(name);
  openvdb::io::File file(path);
  file.setCompression(compression);
  openvdb::MetaMap meta;
  if (!upAxis.empty())
  {
    meta.insertMeta("up_axis", openvdb::StringMetadata(upAxis));
  }
  file.write(MakeGrids(tiles, bigTile, half), meta);
  file.close();
  return path;
}

IndexBox Box(int x0, int y0, int z0, int x1, int y1, int z1)
{
  IndexBox box;
  box.Min = { { x0, y0, z0 } };
  box.Max = { { x1, y1, z1 } };
  return box;
}

float Component(float v, int)
{
  return v;
}
float Component(double v, int)
{
  return float(v);
}
float Component(const openvdb::Vec3s& v, int c)
{
  return v[c];
}

/// The box's values of the grid as OpenVDB reads the whole grid (io::File), as floats.
template <typename GridT>
std::vector<float> WholeGridCropped(const openvdb::GridBase::Ptr& base, const IndexBox& box)
{
  const auto grid = openvdb::gridPtrCast<GridT>(base);
  const auto accessor = grid->getConstAccessor();
  constexpr int components = openvdb::VecTraits<typename GridT::ValueType>::Size;
  std::vector<float> values;
  values.reserve(box.VoxelCount() * components);
  for (int64_t k = box.Min[2]; k <= box.Max[2]; ++k)
    for (int64_t j = box.Min[1]; j <= box.Max[1]; ++j)
      for (int64_t i = box.Min[0]; i <= box.Max[0]; ++i)
      {
        const auto v = accessor.getValue(openvdb::Coord(int(i), int(j), int(k)));
        for (int c = 0; c < components; ++c)
        {
          values.push_back(Component(v, c));
        }
      }
  return values;
}

/// The boxes read as pieces by ExpectPiecesEqualTheWholeGrid.
std::vector<IndexBox> PieceBoxes()
{
  return {
    Box(-40, -10, 100, 170, 140, 150),       // all the voxels
    Box(100, -5, 120, 140, 30, 135),         // across lower nodes
    Box(-9, -9, 126, 9, 9, 130),             // across upper nodes
    Box(250, 100, 120, 300, 130, 140),       // the 128^3 tile's corner and background
    Box(190, 0, 10, 215, 20, 30),            // the leaf-sized tiles
    Box(8180, 0, 0, 8200, 5, 5),             // the root tile's edge
    Box(1000, 1000, 1000, 1010, 1010, 1010), // nothing but background
    Box(57, 33, 111, 57, 33, 111),           // one voxel
  };
}

/// Reads every box of every grid of `path` as a piece (ReadDense), then compares each with
/// OpenVDB's whole read. With `readersRegistry`, the pieces are read after
/// openvdb::uninitialize(): with only what the reader registers itself, checked (no point-data
/// registries, no delayed-load table); then openvdb::initialize() for OpenVDB's own read.
void ExpectPiecesEqualTheWholeGrid(
  const std::string& path, const std::string& what, bool readersRegistry = false)
{
  if (readersRegistry)
  {
    openvdb::uninitialize();
  }
  const auto infos = nimbus::vdb::ReadFileInfo(path);
  ASSERT_EQ(infos.size(), 3u);
  const std::vector<IndexBox> boxes = PieceBoxes();
  std::vector<std::vector<float>> pieces;
  for (const auto& info : infos)
  {
    for (const IndexBox& box : boxes)
    {
      std::vector<float> piece(box.VoxelCount() * info.Components, -999.0f);
      std::vector<std::string> resampled;
      nimbus::vdb::ReadDense(
        path, { info.Name }, infos[0].Transform, box, { piece.data() }, &resampled);
      EXPECT_TRUE(resampled.empty());
      pieces.push_back(std::move(piece));
    }
  }
  if (readersRegistry)
  {
    EXPECT_TRUE(openvdb::FloatGrid::isRegistered() && openvdb::Vec3SGrid::isRegistered());
    EXPECT_FALSE(openvdb::points::PointDataGrid::isRegistered());
    EXPECT_FALSE(openvdb::Int32Grid::isRegistered());
    EXPECT_FALSE(openvdb::Metadata::isRegisteredType("__delayedload"));
    openvdb::initialize();
  }
  openvdb::io::File file(path);
  file.open(/*delayLoad=*/false);
  size_t n = 0;
  for (const auto& info : infos)
  {
    const auto whole = file.readGrid(info.StoredName);
    for (const IndexBox& box : boxes)
    {
      std::vector<float> expected;
      if (info.Kind == nimbus::vdb::ValueKind::Float)
      {
        expected = WholeGridCropped<openvdb::FloatGrid>(whole, box);
      }
      else if (info.Kind == nimbus::vdb::ValueKind::Double)
      {
        expected = WholeGridCropped<openvdb::DoubleGrid>(whole, box);
      }
      else
      {
        expected = WholeGridCropped<openvdb::Vec3SGrid>(whole, box);
      }
      const std::vector<float>& piece = pieces[n++];
      ASSERT_EQ(piece.size(), expected.size());
      ASSERT_EQ(std::memcmp(piece.data(), expected.data(), expected.size() * sizeof(float)), 0)
        << what << ": grid " << info.Name << ", box " << box.Min[0] << " " << box.Min[1] << " "
        << box.Min[2] << " .. " << box.Max[0] << " " << box.Max[1] << " " << box.Max[2];
    }
  }
  file.close();
}

// A file per compression case, written and read back in pieces (the cases Blosc needs are
// left out where OpenVDB was built without it).
struct CompressionCase
{
  const char* Name;
  uint32_t Compression;
  bool Half;
};

void ExpectPiecesForEveryCase(
  const std::vector<CompressionCase>& cases, bool readersRegistry = false)
{
  for (const auto& c : cases)
  {
    if ((c.Compression & openvdb::io::COMPRESS_BLOSC) &&
      !openvdb::io::Archive::hasBloscCompression())
    {
      continue;
    }
    const std::string path =
      WriteGrids(std::string(c.Name) + ".vdb", c.Compression, c.Half, true, true);
    ExpectPiecesEqualTheWholeGrid(path, c.Name, readersRegistry);
    std::remove(path.c_str());
  }
}

TEST(Pieces, EqualTheWholeGridForEveryCompression)
{
  using namespace openvdb::io;
  ExpectPiecesForEveryCase({
    { "none", COMPRESS_NONE, false },
    { "zip", COMPRESS_ZIP, false },
    { "mask", COMPRESS_ACTIVE_MASK, false },
    { "zip-mask", COMPRESS_ZIP | COMPRESS_ACTIVE_MASK, false },
    { "blosc-mask", COMPRESS_BLOSC | COMPRESS_ACTIVE_MASK, false },
    { "blosc", COMPRESS_BLOSC, false },
    { "half-none", COMPRESS_NONE, true },
    { "half-blosc-mask", COMPRESS_BLOSC | COMPRESS_ACTIVE_MASK, true },
  });
}

// The reader registers with OpenVDB only what it reads (RegisterOpenVdbTypes): the pieces are
// the same without the point-data registries and without decoding the delayed-load table.
TEST(Pieces, EqualTheWholeGridWithTheReadersOwnRegistry)
{
  using namespace openvdb::io;
  ExpectPiecesForEveryCase(
    {
      { "own-zip-mask", COMPRESS_ZIP | COMPRESS_ACTIVE_MASK, false },
      { "own-blosc-mask", COMPRESS_BLOSC | COMPRESS_ACTIVE_MASK, false },
      { "own-half-blosc", COMPRESS_BLOSC, true },
    },
    /*readersRegistry=*/true);
}

// A grid of a type the reader does not register up front is still listed with its value type
// (the file's scan registers the rest of OpenVDB's grid types).
TEST(Pieces, OtherGridTypesListedWithTheReadersOwnRegistry)
{
  openvdb::initialize();
  auto density = openvdb::FloatGrid::create(0.0f);
  density->setName("density");
  density->tree().setValue(openvdb::Coord(1, 2, 3), 0.5f);
  auto ids = openvdb::Int32Grid::create(0);
  ids->setName("ids");
  ids->tree().setValue(openvdb::Coord(1, 2, 3), 7);
  const std::string path = TempPath("other-types.vdb");
  openvdb::io::File file(path);
  file.write({ density, ids });
  file.close();
  openvdb::uninitialize();
  const auto infos = nimbus::vdb::ReadFileInfo(path);
  ASSERT_EQ(infos.size(), 2u);
  EXPECT_EQ(infos[0].ValueType, "float");
  EXPECT_TRUE(infos[0].Supported());
  EXPECT_EQ(infos[1].ValueType, "int32");
  EXPECT_FALSE(infos[1].Supported());
  EXPECT_TRUE(openvdb::Int32Grid::isRegistered());
  EXPECT_TRUE(openvdb::points::PointDataGrid::isRegistered());
  openvdb::initialize();
  std::remove(path.c_str());
}

TEST(Pieces, YUpFilePiecesEqualTheWholeImage)
{
  const std::string path = WriteGrids("yup.vdb",
    openvdb::io::COMPRESS_BLOSC | openvdb::io::COMPRESS_ACTIVE_MASK, false, false, false, "+Y");
  vtkNew<vtkNimbusOpenVDBReader> reader;
  reader->SetFileName(path.c_str());
  reader->Update();
  ASSERT_EQ(reader->GetResolvedUpAxis(), 1);
  vtkNew<vtkImageData> whole;
  whole->DeepCopy(reader->GetOutput());
  int wholeExtent[6];
  whole->GetExtent(wholeExtent);
  ASSERT_GT(whole->GetNumberOfPoints(), 1000000);
  const int pieces = 5;
  for (int piece = 0; piece < pieces; ++piece)
  {
    reader->UpdatePiece(piece, pieces, 1);
    vtkImageData* part = reader->GetOutput();
    int extent[6];
    part->GetExtent(extent);
    ASSERT_LT(part->GetNumberOfPoints(), whole->GetNumberOfPoints());
    for (const char* name : { "density", "velocity", "temperature" })
    {
      vtkDataArray* a = part->GetPointData()->GetArray(name);
      vtkDataArray* b = whole->GetPointData()->GetArray(name);
      ASSERT_TRUE(a && b) << name;
      const int n = a->GetNumberOfComponents();
      for (int k = extent[4]; k <= extent[5]; ++k)
        for (int j = extent[2]; j <= extent[3]; ++j)
        {
          int ijk[3] = { extent[0], j, k };
          const float* pa =
            static_cast<const float*>(a->GetVoidPointer(0)) + n * part->ComputePointId(ijk);
          const float* pb =
            static_cast<const float*>(b->GetVoidPointer(0)) + n * whole->ComputePointId(ijk);
          ASSERT_EQ(std::memcmp(pa, pb, sizeof(float) * n * (extent[1] - extent[0] + 1)), 0)
            << name << " piece " << piece << " row " << j << " " << k;
        }
    }
  }
  std::remove(path.c_str());
}

} // namespace
