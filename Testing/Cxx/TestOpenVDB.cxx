// Data tests of the OpenVDB reader and writer (IO/) and their plain-C++ core (VdbGrids).
// Files with special grids (bool/int grids, empty grids, rotated, sheared and frustum
// transforms, grids without statistics metadata) are made here with OpenVDB directly.
#include "VdbArchive.h"
#include "VdbGrids.h"
#include "vtkNimbusOpenVDBReader.h"
#include "vtkNimbusOpenVDBWriter.h"
#include "vtkNimbusSmokeSource.h"
#include "vtkSphereSource.h"

#include "vtkCallbackCommand.h"
#include "vtkCellData.h"
#include "vtkCommand.h"
#include "vtkDataArraySelection.h"
#include "vtkDoubleArray.h"
#include "vtkErrorCode.h"
#include "vtkExecutive.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkMatrix3x3.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include "vtkStringArray.h"

#include <openvdb/io/Compression.h>
#include <openvdb/io/File.h>
#include <openvdb/io/Stream.h>
#include <openvdb/openvdb.h>

#include "MessageCatcher.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <set>
#include <sstream>
#include <string>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>
#include <vector>

namespace vdb = nimbus::vdb;

namespace
{
// Collects vtkErrorMacro / vtkWarningMacro messages of one object instead of printing them.
using nimbus::testing::MessageCatcher;

bool Contains(const std::string& haystack, const std::string& needle)
{
  return haystack.find(needle) != std::string::npos;
}

std::string TempDir()
{
  static std::string dir;
  if (dir.empty())
  {
    char pattern[] = "/tmp/nimbus-openvdb-XXXXXX";
    dir = mkdtemp(pattern);
  }
  return dir;
}

std::string TempPath(const std::string& name)
{
  return TempDir() + "/" + name;
}

// An image with `n` points per axis over `extent`, a float array "density" = f(i,j,k) and
// a 3-component float array "velocity".
vtkSmartPointer<vtkImageData> MakeImage(
  const int extent[6], const double origin[3], const double spacing[3], bool sparse)
{
  auto image = vtkSmartPointer<vtkImageData>::New();
  image->SetExtent(const_cast<int*>(extent));
  image->SetOrigin(origin[0], origin[1], origin[2]);
  image->SetSpacing(spacing[0], spacing[1], spacing[2]);
  vtkNew<vtkFloatArray> density;
  density->SetName("density");
  vtkNew<vtkFloatArray> velocity;
  velocity->SetName("velocity");
  velocity->SetNumberOfComponents(3);
  const vtkIdType n = image->GetNumberOfPoints();
  density->SetNumberOfTuples(n);
  velocity->SetNumberOfTuples(n);
  vtkIdType id = 0;
  for (int k = extent[4]; k <= extent[5]; ++k)
  {
    for (int j = extent[2]; j <= extent[3]; ++j)
    {
      for (int i = extent[0]; i <= extent[1]; ++i, ++id)
      {
        float d = 0.5f + 0.25f * std::sin(0.7f * i) * std::cos(0.3f * j) + 0.01f * k;
        if (sparse && ((i + 2 * j + 3 * k) % 7 != 0))
        {
          d = 0.0f;
        }
        density->SetValue(id, d);
        const float v[3] = { 1.0f + 0.1f * i, -2.0f + 0.01f * j * k,
          0.5f * std::cos(float(i + k)) };
        velocity->SetTypedTuple(id, v);
      }
    }
  }
  image->GetPointData()->AddArray(density);
  image->GetPointData()->AddArray(velocity);
  return image;
}

bool Write(vtkImageData* image, const std::string& path, double tolerance = 0.0,
  MessageCatcher** catcherOut = nullptr)
{
  vtkNew<vtkNimbusOpenVDBWriter> writer;
  writer->SetInputData(image);
  writer->SetFileName(path.c_str());
  writer->SetTolerance(tolerance);
  MessageCatcher catcher(writer);
  const int ok = writer->Write();
  (void)catcherOut;
  return ok == 1 && catcher.Errors.empty();
}

void ExpectSameArray(vtkDataArray* a, vtkDataArray* b)
{
  ASSERT_NE(a, nullptr);
  ASSERT_NE(b, nullptr);
  ASSERT_EQ(a->GetNumberOfTuples(), b->GetNumberOfTuples());
  ASSERT_EQ(a->GetNumberOfComponents(), b->GetNumberOfComponents());
  vtkIdType mismatches = 0;
  for (vtkIdType i = 0; i < a->GetNumberOfValues(); ++i)
  {
    if (a->GetVariantValue(i).ToFloat() != b->GetVariantValue(i).ToFloat())
    {
      ++mismatches;
    }
  }
  EXPECT_EQ(mismatches, 0) << "array " << a->GetName();
}

// Writes a .vdb with OpenVDB directly.
void WriteGrids(const std::string& path, const openvdb::GridPtrVec& grids, bool stats = true)
{
  openvdb::initialize();
  openvdb::io::File file(path);
  file.setGridStatsMetadataEnabled(stats);
  file.write(grids);
  file.close();
}

openvdb::FloatGrid::Ptr FloatBlock(
  const std::string& name, openvdb::Coord lo, openvdb::Coord hi, double voxelSize, float value)
{
  openvdb::initialize();
  auto grid = openvdb::FloatGrid::create(0.0f);
  grid->setName(name);
  grid->setTransform(openvdb::math::Transform::createLinearTransform(voxelSize));
  auto acc = grid->getAccessor();
  for (int k = lo.z(); k <= hi.z(); ++k)
    for (int j = lo.y(); j <= hi.y(); ++j)
      for (int i = lo.x(); i <= hi.x(); ++i)
        acc.setValue(openvdb::Coord(i, j, k), value + 0.001f * (i + 10 * j + 100 * k));
  return grid;
}

std::string ReadErrors(
  const std::string& path, vtkIdType limit = 0, int* ok = nullptr, std::string* warnings = nullptr)
{
  vtkNew<vtkNimbusOpenVDBReader> reader;
  reader->SetFileName(path.c_str());
  if (limit > 0)
  {
    reader->SetMaximumNumberOfVoxels(limit);
  }
  MessageCatcher catcher(reader);
  reader->GetExecutive()->AddObserver(vtkCommand::ErrorEvent, vtkNew<vtkCallbackCommand>());
  const int status = reader->GetExecutive()->Update();
  if (ok)
  {
    *ok = status;
  }
  if (warnings)
  {
    *warnings = catcher.AllWarnings();
  }
  return catcher.AllErrors();
}

void Truncate(const std::string& from, const std::string& to, long size)
{
  std::ifstream in(from, std::ios::binary);
  std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::ofstream out(to, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), std::min<long>(size, static_cast<long>(bytes.size())));
}

long FileSize(const std::string& path)
{
  struct stat st;
  return ::stat(path.c_str(), &st) == 0 ? static_cast<long>(st.st_size) : -1;
}
} // namespace

// --- Core: boxes and transforms -------------------------------------------------------------

TEST(Core, IndexBox)
{
  vdb::IndexBox a;
  EXPECT_TRUE(a.Empty());
  EXPECT_EQ(a.VoxelCount(), 0u);
  vdb::IndexBox b;
  b.Min = { { -2, 0, 5 } };
  b.Max = { { 1, 9, 5 } };
  EXPECT_EQ(b.VoxelCount(), 4u * 10u * 1u);
  EXPECT_EQ(a.Union(b), b);
  vdb::IndexBox c;
  c.Min = { { 0, -5, 0 } };
  c.Max = { { 10, 3, 7 } };
  const auto u = b.Union(c);
  EXPECT_EQ(u.Min, (std::array<int64_t, 3>{ { -2, -5, 0 } }));
  EXPECT_EQ(u.Max, (std::array<int64_t, 3>{ { 10, 9, 7 } }));
  const auto x = b.Intersection(c);
  EXPECT_EQ(x.Min, (std::array<int64_t, 3>{ { 0, 0, 5 } }));
  EXPECT_EQ(x.Max, (std::array<int64_t, 3>{ { 1, 3, 5 } }));
  // The full 32-bit index range: 2^96 voxels saturate instead of wrapping.
  vdb::IndexBox huge;
  huge.Min = { { INT32_MIN, INT32_MIN, INT32_MIN } };
  huge.Max = { { INT32_MAX, INT32_MAX, INT32_MAX } };
  EXPECT_EQ(huge.VoxelCount(), UINT64_MAX);
}

TEST(Core, TransformAxisAlignedAndAnisotropic)
{
  std::array<std::array<double, 4>, 4> m{};
  m[0] = { { 0.5, 0, 0, 0 } };
  m[1] = { { 0, 0.5, 0, 0 } };
  m[2] = { { 0, 0, 0.5, 0 } };
  m[3] = { { 10, -20, 30.25, 1 } };
  auto t = vdb::AnalyseLinearMatrix(m);
  EXPECT_FALSE(t.Rotated || t.Sheared || t.Anisotropic);
  EXPECT_TRUE(t.Note.empty());
  EXPECT_EQ(t.Spacing, (std::array<double, 3>{ { 0.5, 0.5, 0.5 } }));
  EXPECT_EQ(t.Origin, (std::array<double, 3>{ { 10, -20, 30.25 } }));
  m[2][2] = 2.0;
  t = vdb::AnalyseLinearMatrix(m);
  EXPECT_TRUE(t.Anisotropic);
  EXPECT_FALSE(t.Rotated);
  EXPECT_TRUE(Contains(t.Note, "non-uniform voxel size")) << t.Note;
}

TEST(Core, TransformRotatedKeepsDirection)
{
  // 30 degrees about z, voxel 2: index axis x -> world (cos, sin, 0) * 2.
  const double a = M_PI / 6;
  std::array<std::array<double, 4>, 4> m{};
  m[0] = { { 2 * std::cos(a), 2 * std::sin(a), 0, 0 } };
  m[1] = { { -2 * std::sin(a), 2 * std::cos(a), 0, 0 } };
  m[2] = { { 0, 0, 2, 0 } };
  m[3] = { { 1, 2, 3, 1 } };
  const auto t = vdb::AnalyseLinearMatrix(m);
  EXPECT_TRUE(t.Rotated);
  EXPECT_FALSE(t.Sheared);
  EXPECT_TRUE(Contains(t.Note, "direction matrix")) << t.Note;
  for (int c = 0; c < 3; ++c)
  {
    EXPECT_NEAR(t.Spacing[c], 2.0, 1e-14);
  }
  // Column 0 of the direction (world direction of index axis 0).
  EXPECT_NEAR(t.Direction[0], std::cos(a), 1e-15);
  EXPECT_NEAR(t.Direction[1], std::sin(a), 1e-15);
  EXPECT_NEAR(t.Direction[3], -std::sin(a), 1e-15);
}

TEST(Core, TransformShearedAndDegenerate)
{
  std::array<std::array<double, 4>, 4> m{};
  m[0] = { { 1, 0, 0, 0 } };
  m[1] = { { 0.5, 1, 0, 0 } }; // index y axis leans towards x
  m[2] = { { 0, 0, 1, 0 } };
  m[3] = { { 0, 0, 0, 1 } };
  const auto t = vdb::AnalyseLinearMatrix(m);
  EXPECT_TRUE(t.Sheared);
  EXPECT_FALSE(t.Rotated);
  EXPECT_NEAR(t.Spacing[1], std::sqrt(1.25), 1e-15);
  EXPECT_TRUE(Contains(t.Note, "sheared")) << t.Note;
  m[1] = { { 0, 0, 0, 0 } };
  EXPECT_THROW(vdb::AnalyseLinearMatrix(m), vdb::Error);
}

// --- Write -> read round trips ----------------------------------------------------------------

TEST(RoundTrip, DenseFloatAndVec3Identical)
{
  const int extent[6] = { -3, 12, 5, 20, -7, 4 };
  const double origin[3] = { 10.0, -20.0, 30.5 };
  const double spacing[3] = { 0.25, 0.5, 2.0 };
  auto image = MakeImage(extent, origin, spacing, false);
  const std::string path = TempPath("dense.vdb");
  ASSERT_TRUE(Write(image, path));

  vtkNew<vtkNimbusOpenVDBReader> reader;
  reader->SetFileName(path.c_str());
  MessageCatcher catcher(reader);
  reader->Update();
  EXPECT_TRUE(catcher.Errors.empty()) << catcher.AllErrors();
  vtkImageData* out = reader->GetOutput();
  int outExtent[6];
  out->GetExtent(outExtent);
  for (int c = 0; c < 6; ++c)
  {
    EXPECT_EQ(outExtent[c], extent[c]);
  }
  for (int c = 0; c < 3; ++c)
  {
    EXPECT_EQ(out->GetOrigin()[c], origin[c]);
    EXPECT_EQ(out->GetSpacing()[c], spacing[c]);
  }
  ExpectSameArray(
    image->GetPointData()->GetArray("density"), out->GetPointData()->GetArray("density"));
  ExpectSameArray(
    image->GetPointData()->GetArray("velocity"), out->GetPointData()->GetArray("velocity"));
  // Non-uniform spacing is exact, and said so.
  EXPECT_TRUE(Contains(catcher.AllWarnings(), "non-uniform voxel size")) << catcher.AllWarnings();
}

TEST(RoundTrip, SparseWithToleranceKeepsActiveVoxels)
{
  const int extent[6] = { 0, 31, 0, 23, 0, 15 };
  const double origin[3] = { -1.0, 2.0, 3.0 };
  const double spacing[3] = { 0.1, 0.1, 0.1 };
  auto image = MakeImage(extent, origin, spacing, true);
  image->GetPointData()->RemoveArray("velocity");
  // Values under the tolerance become inactive (background 0).
  auto* density = vtkFloatArray::SafeDownCast(image->GetPointData()->GetArray("density"));
  density->SetValue(5, 0.004f);
  const std::string path = TempPath("sparse.vdb");
  vtkNew<vtkNimbusOpenVDBWriter> writer;
  writer->SetInputData(image);
  writer->SetFileName(path.c_str());
  writer->SetTolerance(0.005);
  ASSERT_EQ(writer->Write(), 1);
  vtkIdType nonZero = 0;
  for (vtkIdType i = 0; i < density->GetNumberOfValues(); ++i)
  {
    nonZero += std::abs(density->GetValue(i)) > 0.005f;
  }
  EXPECT_EQ(writer->GetNumberOfActiveVoxels(), nonZero);

  vtkNew<vtkNimbusOpenVDBReader> reader;
  reader->SetFileName(path.c_str());
  reader->Update();
  vtkImageData* out = reader->GetOutput();
  // Every original point inside the read box has its value (or 0 under the tolerance);
  // every point outside the box was background.
  vtkDataArray* read = out->GetPointData()->GetArray("density");
  ASSERT_NE(read, nullptr);
  int box[6];
  out->GetExtent(box);
  vtkIdType mismatches = 0, outsideNonZero = 0;
  for (int k = extent[4]; k <= extent[5]; ++k)
    for (int j = extent[2]; j <= extent[3]; ++j)
      for (int i = extent[0]; i <= extent[1]; ++i)
      {
        int ijk[3] = { i, j, k };
        const float v = density->GetValue(image->ComputePointId(ijk));
        const float expected = std::abs(v) > 0.005f ? v : 0.0f;
        if (i < box[0] || i > box[1] || j < box[2] || j > box[3] || k < box[4] || k > box[5])
        {
          outsideNonZero += expected != 0.0f;
          continue;
        }
        mismatches += read->GetTuple1(out->ComputePointId(ijk)) != expected;
      }
  EXPECT_EQ(mismatches, 0);
  EXPECT_EQ(outsideNonZero, 0);
  // The fog-volume class of a non-negative density.
  openvdb::initialize();
  openvdb::io::File file(path);
  file.open();
  EXPECT_EQ(file.readGridMetadata("density")->getGridClass(), openvdb::GRID_FOG_VOLUME);
}

TEST(RoundTrip, CellDataAndConvertedDoubles)
{
  vtkNew<vtkImageData> image;
  image->SetExtent(0, 4, 0, 3, 0, 2);
  image->SetSpacing(2.0, 2.0, 2.0);
  image->SetOrigin(1.0, 1.0, 1.0);
  vtkNew<vtkDoubleArray> temperature; // double point data: written as float
  temperature->SetName("temperature");
  temperature->SetNumberOfTuples(image->GetNumberOfPoints());
  for (vtkIdType i = 0; i < image->GetNumberOfPoints(); ++i)
  {
    temperature->SetValue(i, 280.0 + 0.5 * i);
  }
  image->GetPointData()->AddArray(temperature);
  vtkNew<vtkFloatArray> cells;
  cells->SetName("pressure");
  cells->SetNumberOfTuples(image->GetNumberOfCells());
  for (vtkIdType i = 0; i < image->GetNumberOfCells(); ++i)
  {
    cells->SetValue(i, 1000.0f - i);
  }
  image->GetCellData()->AddArray(cells);
  const std::string path = TempPath("cells.vdb");
  ASSERT_TRUE(Write(image, path));

  // The cell grid alone: its points are the cell centres.
  vtkNew<vtkNimbusOpenVDBReader> reader;
  reader->SetFileName(path.c_str());
  reader->UpdateInformation();
  ASSERT_EQ(reader->GetNumberOfGridArrays(), 2);
  reader->SetGridArrayStatus("temperature", 0);
  reader->Update();
  vtkImageData* out = reader->GetOutput();
  EXPECT_EQ(out->GetNumberOfPoints(), image->GetNumberOfCells());
  EXPECT_EQ(out->GetOrigin()[0], 2.0); // 1 + half a voxel of 2
  ExpectSameArray(cells, out->GetPointData()->GetArray("pressure"));
  EXPECT_EQ(out->GetPointData()->GetArray("temperature"), nullptr);

  reader->SetGridArrayStatus("temperature", 1);
  reader->SetGridArrayStatus("pressure", 0);
  reader->Update();
  vtkDataArray* t = reader->GetOutput()->GetPointData()->GetArray("temperature");
  ASSERT_NE(t, nullptr);
  for (vtkIdType i = 0; i < t->GetNumberOfTuples(); ++i)
  {
    EXPECT_EQ(t->GetTuple1(i), static_cast<double>(static_cast<float>(280.0 + 0.5 * i)));
  }
}

TEST(RoundTrip, RotatedImageKeepsDirection)
{
  const int extent[6] = { 0, 7, 0, 5, 0, 3 };
  const double origin[3] = { 5.0, 6.0, 7.0 };
  const double spacing[3] = { 1.5, 1.5, 1.5 };
  auto image = MakeImage(extent, origin, spacing, false);
  const double a = 0.4;
  image->SetDirectionMatrix(std::cos(a), -std::sin(a), 0, std::sin(a), std::cos(a), 0, 0, 0, 1);
  const std::string path = TempPath("rotated.vdb");
  ASSERT_TRUE(Write(image, path));
  vtkNew<vtkNimbusOpenVDBReader> reader;
  reader->SetFileName(path.c_str());
  MessageCatcher catcher(reader);
  reader->Update();
  vtkImageData* out = reader->GetOutput();
  // Measured: direction, spacing and origin come back bit-identical (difference 0); the
  // bounds allow one rounding in the row normalisation on another platform.
  for (int i = 0; i < 9; ++i)
  {
    EXPECT_NEAR(
      out->GetDirectionMatrix()->GetData()[i], image->GetDirectionMatrix()->GetData()[i], 1e-15);
  }
  for (int c = 0; c < 3; ++c)
  {
    EXPECT_NEAR(out->GetSpacing()[c], 1.5, 1e-14);
    EXPECT_NEAR(out->GetOrigin()[c], origin[c], 1e-14);
  }
  ExpectSameArray(
    image->GetPointData()->GetArray("density"), out->GetPointData()->GetArray("density"));
  EXPECT_TRUE(Contains(catcher.AllWarnings(), "direction matrix")) << catcher.AllWarnings();
}

// --- Files made by OpenVDB directly ------------------------------------------------------------

TEST(Read, InformationWithoutVoxels)
{
  // A far, sparse block: the information pass knows the extent from the metadata alone,
  // proven by a file whose voxel data is overwritten with 0xff (information works, the
  // read fails). (A truncated file fails already in the information pass: its layout is
  // checked first; see BadInput.TruncatedAtEveryTenthOfTheFile.)
  auto grid = FloatBlock(
    "smoke", openvdb::Coord(10000, -5000, 3000), openvdb::Coord(10003, -4998, 3004), 0.2, 1.0f);
  const std::string path = TempPath("far.vdb");
  WriteGrids(path, { grid });
  const std::string cut = TempPath("far-cut.vdb");
  {
    const vdb::FileLayout layout = vdb::ScanFile(path);
    ASSERT_EQ(layout.Grids.size(), 1u);
    std::ifstream in(path, std::ios::binary);
    std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::fill(bytes.begin() + layout.Grids[0].BlockPos, bytes.begin() + layout.Grids[0].EndPos,
      static_cast<char>(0xff));
    std::ofstream(cut, std::ios::binary).write(bytes.data(), bytes.size());
  }
  vtkNew<vtkNimbusOpenVDBReader> reader;
  reader->SetFileName(cut.c_str());
  MessageCatcher catcher(reader);
  reader->UpdateInformation();
  EXPECT_TRUE(catcher.Errors.empty()) << catcher.AllErrors();
  int whole[6];
  reader->GetOutputInformation(0)->Get(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), whole);
  const int expected[6] = { 10000, 10003, -5000, -4998, 3000, 3004 };
  for (int c = 0; c < 6; ++c)
  {
    EXPECT_EQ(whole[c], expected[c]);
  }
  ASSERT_EQ(reader->GetGridNames()->GetNumberOfValues(), 1);
  EXPECT_EQ(reader->GetGridNames()->GetValue(0), "smoke");
  int ok = 1;
  const std::string errors = ReadErrors(cut, 0, &ok);
  EXPECT_EQ(ok, 0);
  EXPECT_TRUE(Contains(errors, "corrupt")) << errors;
}

TEST(Read, FarSparseGridValuesAndPositions)
{
  auto grid = FloatBlock(
    "smoke", openvdb::Coord(10000, -5000, 3000), openvdb::Coord(10003, -4998, 3004), 0.2, 1.0f);
  const std::string path = TempPath("far-ok.vdb");
  WriteGrids(path, { grid });
  vtkNew<vtkNimbusOpenVDBReader> reader;
  reader->SetFileName(path.c_str());
  reader->Update();
  vtkImageData* out = reader->GetOutput();
  EXPECT_EQ(out->GetNumberOfPoints(), 4 * 3 * 5);
  int ijk[3] = { 10002, -4999, 3003 };
  double x[3];
  out->TransformIndexToPhysicalPoint(ijk, x);
  EXPECT_NEAR(x[0], 10002 * 0.2, 1e-9);
  EXPECT_NEAR(x[1], -4999 * 0.2, 1e-9);
  EXPECT_NEAR(x[2], 3003 * 0.2, 1e-9);
  EXPECT_EQ(out->GetPointData()->GetArray("smoke")->GetTuple1(out->ComputePointId(ijk)),
    grid->tree().getValue(openvdb::Coord(ijk[0], ijk[1], ijk[2])));
}

TEST(Read, DoubleAndVec3dGridsAndBackground)
{
  openvdb::initialize();
  auto d = openvdb::DoubleGrid::create(-3.0); // background -3 fills inactive voxels
  d->setName("temperature");
  d->tree().setValue(openvdb::Coord(0, 0, 0), 1.25);
  d->tree().setValue(openvdb::Coord(3, 2, 1), 2.5);
  auto v = openvdb::Vec3DGrid::create(openvdb::Vec3d(0.0));
  v->setName("vel");
  v->tree().setValue(openvdb::Coord(1, 1, 1), openvdb::Vec3d(1.5, -2.5, 3.5));
  const std::string path = TempPath("double.vdb");
  WriteGrids(path, { d, v });
  vtkNew<vtkNimbusOpenVDBReader> reader;
  reader->SetFileName(path.c_str());
  reader->Update();
  vtkImageData* out = reader->GetOutput();
  EXPECT_EQ(out->GetNumberOfPoints(), 4 * 3 * 2);
  vtkDataArray* t = out->GetPointData()->GetArray("temperature");
  vtkDataArray* vel = out->GetPointData()->GetArray("vel");
  ASSERT_TRUE(t && vel);
  EXPECT_EQ(vel->GetNumberOfComponents(), 3);
  int a[3] = { 0, 0, 0 }, b[3] = { 3, 2, 1 }, c[3] = { 1, 1, 1 }, e[3] = { 2, 0, 1 };
  EXPECT_EQ(t->GetTuple1(out->ComputePointId(a)), 1.25);
  EXPECT_EQ(t->GetTuple1(out->ComputePointId(b)), 2.5);
  EXPECT_EQ(t->GetTuple1(out->ComputePointId(e)), -3.0);
  EXPECT_EQ(vel->GetComponent(out->ComputePointId(c), 1), -2.5);
  EXPECT_EQ(vel->GetComponent(out->ComputePointId(e), 0), 0.0);
}

TEST(Read, GridWithoutStatisticsMetadata)
{
  auto grid = FloatBlock("density", openvdb::Coord(-4, 2, 7), openvdb::Coord(5, 3, 9), 1.0, 0.5f);
  const std::string path = TempPath("nostats.vdb");
  WriteGrids(path, { grid }, /*stats=*/false);
  const auto info = vdb::ReadFileInfo(path);
  ASSERT_EQ(info.size(), 1u);
  EXPECT_TRUE(info[0].TreeRead);
  EXPECT_EQ(info[0].ActiveBox.Min, (std::array<int64_t, 3>{ { -4, 2, 7 } }));
  EXPECT_EQ(info[0].ActiveBox.Max, (std::array<int64_t, 3>{ { 5, 3, 9 } }));
}

TEST(Read, DifferentTransformsResampledAndWarned)
{
  // "fine": voxel 1 over [0,8]^3; "coarse": voxel 3, a linear field (trilinear is exact up
  // to float rounding; weights 1/3 and 2/3 are not exact in binary).
  auto fine = FloatBlock("fine", openvdb::Coord(0), openvdb::Coord(8), 1.0, 1.0f);
  openvdb::initialize();
  auto coarse = openvdb::FloatGrid::create(0.0f);
  coarse->setName("coarse");
  coarse->setTransform(openvdb::math::Transform::createLinearTransform(3.0));
  for (int k = -1; k <= 5; ++k)
    for (int j = -1; j <= 5; ++j)
      for (int i = -1; i <= 5; ++i)
        coarse->tree().setValue(openvdb::Coord(i, j, k), float(2 * i + 3 * j - k) * 3.0f + 100.0f);
  const std::string path = TempPath("mixed.vdb");
  WriteGrids(path, { fine, coarse });
  vtkNew<vtkNimbusOpenVDBReader> reader;
  reader->SetFileName(path.c_str());
  reader->SetBoundsGrid("fine"); // its box and transform (else: the first grid OpenVDB lists)
  MessageCatcher catcher(reader);
  reader->Update();
  EXPECT_TRUE(Contains(catcher.AllWarnings(), "resampled trilinearly")) << catcher.AllWarnings();
  vtkImageData* out = reader->GetOutput();
  EXPECT_EQ(out->GetNumberOfPoints(), 9 * 9 * 9);
  EXPECT_EQ(out->GetSpacing()[0], 1.0);
  vtkDataArray* c = out->GetPointData()->GetArray("coarse");
  ASSERT_NE(c, nullptr);
  // Reference is "fine" (index = world); world x -> coarse value 2x + 3y - z + 100.
  double worst = 0.0;
  for (int k = 0; k <= 8; ++k)
    for (int j = 0; j <= 8; ++j)
      for (int i = 0; i <= 8; ++i)
      {
        int ijk[3] = { i, j, k };
        worst = std::max(worst,
          std::abs(c->GetTuple1(out->ComputePointId(ijk)) - (2.0 * i + 3.0 * j - k + 100.0)));
      }
  std::cout << "worst trilinear error " << worst << "\n";
  // Values up to 140 (float ulp 1.5e-5); OpenVDB interpolates in float. Measured worst: 0
  // (the integer-valued linear field rounds back exactly); bound: two ulps, to allow
  // another interpolation order.
  EXPECT_LE(worst, 3.1e-5);
}

TEST(Read, BoundsGridChoosesTheBox)
{
  const std::string path = TempPath("two-boxes.vdb");
  WriteGrids(path,
    { FloatBlock("small", openvdb::Coord(2), openvdb::Coord(4), 1.0, 1.0f),
      FloatBlock("large", openvdb::Coord(0), openvdb::Coord(9), 1.0, 2.0f) });
  vtkNew<vtkNimbusOpenVDBReader> reader;
  reader->SetFileName(path.c_str());
  for (const char* bounds : { "", "(union)" })
  {
    reader->SetBoundsGrid(bounds);
    reader->Update();
    EXPECT_EQ(reader->GetOutput()->GetNumberOfPoints(), 1000) << bounds;
  }
  reader->SetBoundsGrid("small");
  reader->Update();
  EXPECT_EQ(reader->GetOutput()->GetNumberOfPoints(), 27);
  EXPECT_EQ(reader->GetOutput()->GetExtent()[0], 2);
  ASSERT_NE(reader->GetOutput()->GetPointData()->GetArray("large"), nullptr);
  int ok = 1;
  vtkNew<vtkNimbusOpenVDBReader> bad;
  bad->SetFileName(path.c_str());
  bad->SetBoundsGrid("missing");
  MessageCatcher catcher(bad);
  bad->GetExecutive()->AddObserver(vtkCommand::ErrorEvent, vtkNew<vtkCallbackCommand>());
  ok = bad->GetExecutive()->Update();
  EXPECT_EQ(ok, 0);
  EXPECT_TRUE(Contains(catcher.AllErrors(), "BoundsGrid 'missing' is not")) << catcher.AllErrors();
}

TEST(Read, FrustumTransformWarns)
{
  openvdb::initialize();
  auto grid = FloatBlock("fog", openvdb::Coord(0), openvdb::Coord(3), 1.0, 1.0f);
  grid->setTransform(openvdb::math::Transform::createFrustumTransform(
    openvdb::BBoxd(openvdb::Vec3d(0), openvdb::Vec3d(10)), 0.5, 2.0, 1.0));
  const std::string path = TempPath("frustum.vdb");
  WriteGrids(path, { grid });
  int ok = 0;
  std::string warnings;
  const std::string errors = ReadErrors(path, 0, &ok, &warnings);
  EXPECT_EQ(ok, 1) << errors;
  EXPECT_TRUE(Contains(warnings, "non-linear")) << warnings;
}

// --- Bad inputs: clear errors, no crash
// -----------------------------------------------------------

TEST(BadInput, MissingFile)
{
  int ok = 1;
  const std::string errors = ReadErrors(TempPath("does-not-exist.vdb"), 0, &ok);
  EXPECT_EQ(ok, 0);
  EXPECT_TRUE(Contains(errors, "cannot open") && Contains(errors, "No such file")) << errors;
}

TEST(BadInput, NotAVdb)
{
  const std::string path = TempPath("text.vdb");
  std::ofstream(path) << "this is not a VDB file, just text\n";
  int ok = 1;
  std::string errors = ReadErrors(path, 0, &ok);
  EXPECT_EQ(ok, 0);
  EXPECT_TRUE(Contains(errors, "is not an OpenVDB file")) << errors;
  const std::string empty = TempPath("empty-file.vdb");
  std::ofstream(empty).close();
  errors = ReadErrors(empty, 0, &ok);
  EXPECT_EQ(ok, 0);
  EXPECT_TRUE(Contains(errors, "is not an OpenVDB file")) << errors;
  EXPECT_EQ(vtkNimbusOpenVDBReader::CanReadFile(path.c_str()), 0);
}

TEST(BadInput, TruncatedAtEveryTenthOfTheFile)
{
  const int extent[6] = { 0, 15, 0, 15, 0, 15 };
  const double origin[3] = { 0, 0, 0 };
  const double spacing[3] = { 1, 1, 1 };
  const std::string path = TempPath("whole.vdb");
  ASSERT_TRUE(Write(MakeImage(extent, origin, spacing, false), path));
  EXPECT_EQ(vtkNimbusOpenVDBReader::CanReadFile(path.c_str()), 1);
  const long size = FileSize(path);
  ASSERT_GT(size, 100);
  for (int tenth = 0; tenth < 10; ++tenth)
  {
    const long cutAt = std::max(1L, size * tenth / 10);
    const std::string cut = TempPath("cut.vdb");
    Truncate(path, cut, cutAt);
    int ok = 1;
    const std::string errors = ReadErrors(cut, 0, &ok);
    EXPECT_EQ(ok, 0) << "cut at " << cutAt << " of " << size;
    // Every cut is named as a truncation, with the byte where the file ends.
    EXPECT_TRUE((Contains(errors, "the file is truncated") &&
                  Contains(errors, "the file ends at byte " + std::to_string(cutAt))) ||
      (cutAt < 8 && Contains(errors, "not an OpenVDB file")))
      << "cut at " << cutAt << ": " << errors;
  }
}

TEST(BadInput, UnsupportedGridTypes)
{
  openvdb::initialize();
  auto mask = openvdb::BoolGrid::create(false);
  mask->setName("mask");
  mask->tree().setValue(openvdb::Coord(1, 2, 3), true);
  auto ids = openvdb::Int32Grid::create(0);
  ids->setName("ids");
  ids->tree().setValue(openvdb::Coord(0), 7);
  const std::string only = TempPath("unsupported.vdb");
  WriteGrids(only, { mask, ids });
  int ok = 1;
  std::string errors = ReadErrors(only, 0, &ok);
  EXPECT_EQ(ok, 0);
  EXPECT_TRUE(Contains(errors, "no float, double, Vec3s or Vec3d grid") &&
    Contains(errors, "'mask' (bool)") && Contains(errors, "'ids' (int32)"))
    << errors;

  // Mixed with a float grid: the float grid is read, the others named in a warning.
  const std::string mixed = TempPath("mixed-types.vdb");
  WriteGrids(
    mixed, { mask, FloatBlock("density", openvdb::Coord(0), openvdb::Coord(2), 1.0, 1.0f) });
  std::string warnings;
  errors = ReadErrors(mixed, 0, &ok, &warnings);
  EXPECT_EQ(ok, 1) << errors;
  EXPECT_TRUE(Contains(warnings, "skipped grids of unsupported value type") &&
    Contains(warnings, "'mask' (bool)"))
    << warnings;
}

TEST(BadInput, EmptyGrids)
{
  openvdb::initialize();
  auto empty = openvdb::FloatGrid::create(0.0f);
  empty->setName("nothing");
  const std::string only = TempPath("empty-grid.vdb");
  WriteGrids(only, { empty });
  int ok = 1;
  std::string errors = ReadErrors(only, 0, &ok);
  EXPECT_EQ(ok, 0);
  EXPECT_TRUE(Contains(errors, "every selected grid is empty") && Contains(errors, "'nothing'"))
    << errors;

  const std::string mixed = TempPath("empty-and-full.vdb");
  WriteGrids(
    mixed, { empty, FloatBlock("density", openvdb::Coord(0), openvdb::Coord(2), 1.0, 1.0f) });
  std::string warnings;
  errors = ReadErrors(mixed, 0, &ok, &warnings);
  EXPECT_EQ(ok, 1) << errors;
  EXPECT_TRUE(Contains(warnings, "'nothing' has no active voxels")) << warnings;

  // An empty file (no grids at all).
  const std::string none = TempPath("no-grids.vdb");
  WriteGrids(none, {});
  errors = ReadErrors(none, 0, &ok);
  EXPECT_EQ(ok, 0);
  EXPECT_TRUE(Contains(errors, "it has no grids")) << errors;
}

TEST(BadInput, OverTheVoxelLimit)
{
  // Two voxels 2^20 apart along each axis: a (2^20+1)^3 ~ 1.2e18-point image.
  openvdb::initialize();
  auto grid = openvdb::FloatGrid::create(0.0f);
  grid->setName("spread");
  grid->tree().setValue(openvdb::Coord(0), 1.0f);
  grid->tree().setValue(openvdb::Coord(1 << 20), 1.0f);
  const std::string path = TempPath("huge.vdb");
  WriteGrids(path, { grid });
  int ok = 1;
  std::string errors = ReadErrors(path, 0, &ok);
  EXPECT_EQ(ok, 0);
  EXPECT_TRUE(Contains(errors, "refusing to read") && Contains(errors, "MaximumNumberOfVoxels"))
    << errors;
  // A small limit refuses a small file too; raising it reads it.
  const std::string small = TempPath("small.vdb");
  WriteGrids(small, { FloatBlock("density", openvdb::Coord(0), openvdb::Coord(9), 1.0, 1.0f) });
  errors = ReadErrors(small, 999, &ok);
  EXPECT_EQ(ok, 0);
  EXPECT_TRUE(Contains(errors, "10 x 10 x 10 = 1000 points")) << errors;
  errors = ReadErrors(small, 1000, &ok);
  EXPECT_EQ(ok, 1) << errors;
}

TEST(BadInput, UnwritablePathAndNoArrays)
{
  const int extent[6] = { 0, 3, 0, 3, 0, 3 };
  const double origin[3] = { 0, 0, 0 };
  const double spacing[3] = { 1, 1, 1 };
  auto image = MakeImage(extent, origin, spacing, false);
  vtkNew<vtkNimbusOpenVDBWriter> writer;
  writer->SetInputData(image);
  writer->SetFileName("/nonexistent-dir/x.vdb");
  MessageCatcher catcher(writer);
  EXPECT_EQ(writer->Write(), 0);
  EXPECT_TRUE(Contains(catcher.AllErrors(), "cannot write '/nonexistent-dir/x.vdb'"))
    << catcher.AllErrors();

  vtkNew<vtkImageData> bare;
  bare->SetExtent(0, 2, 0, 2, 0, 2);
  vtkNew<vtkNimbusOpenVDBWriter> writer2;
  writer2->SetInputData(bare);
  writer2->SetFileName(TempPath("bare.vdb").c_str());
  MessageCatcher catcher2(writer2);
  EXPECT_EQ(writer2->Write(), 0);
  EXPECT_TRUE(Contains(catcher2.AllErrors(), "no named 1- or 3-component")) << catcher2.AllErrors();
}

TEST(BadInput, FailedWriteLeavesExistingFileIntact)
{
  const int extent[6] = { 0, 5, 0, 5, 0, 5 };
  const double origin[3] = { 0, 0, 0 };
  const double spacing[3] = { 1, 1, 1 };
  auto image = MakeImage(extent, origin, spacing, false);
  const std::string path = TempPath("keep.vdb");
  ASSERT_TRUE(Write(image, path));
  const long before = FileSize(path);
  // Block the temporary file name with a directory: the write must fail cleanly.
  const std::string blocker = path + ".tmp-" + std::to_string(::getpid());
  ASSERT_EQ(::mkdir(blocker.c_str(), 0700), 0);
  image->GetPointData()->GetArray("density")->SetTuple1(0, 123.0);
  vtkNew<vtkNimbusOpenVDBWriter> writer;
  writer->SetInputData(image);
  writer->SetFileName(path.c_str());
  MessageCatcher catcher(writer);
  EXPECT_EQ(writer->Write(), 0);
  EXPECT_FALSE(catcher.Errors.empty());
  ::rmdir(blocker.c_str());
  EXPECT_EQ(FileSize(path), before);
  int ok = 0;
  const std::string errors = ReadErrors(path, 0, &ok);
  EXPECT_EQ(ok, 1) << errors;
}

// --- Safe replacement of existing files (writer) -----------------------------------------------

namespace
{
std::vector<char> Bytes(const std::string& path)
{
  std::ifstream in(path, std::ios::binary);
  return std::vector<char>((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

vtkSmartPointer<vtkImageData> SmallImage(float scale)
{
  const int extent[6] = { 0, 15, 0, 15, 0, 15 };
  const double origin[3] = { 0, 0, 0 };
  const double spacing[3] = { 1, 1, 1 };
  auto image = MakeImage(extent, origin, spacing, false);
  auto* density = vtkFloatArray::SafeDownCast(image->GetPointData()->GetArray("density"));
  for (vtkIdType i = 0; i < density->GetNumberOfValues(); ++i)
  {
    density->SetValue(i, density->GetValue(i) * scale);
  }
  return image;
}

/// Writes `image` to `path`; returns Write()'s result, the errors, warnings and error code.
int WriteCatching(vtkImageData* image, const std::string& path, std::string* errors,
  std::string* warnings = nullptr, unsigned long* code = nullptr, double background = 0.0)
{
  vtkNew<vtkNimbusOpenVDBWriter> writer;
  writer->SetInputData(image);
  writer->SetFileName(path.c_str());
  writer->SetBackground(background);
  MessageCatcher catcher(writer);
  const int ok = writer->Write();
  *errors = catcher.AllErrors();
  if (warnings)
  {
    *warnings = catcher.AllWarnings();
  }
  if (code)
  {
    *code = writer->GetErrorCode();
  }
  return ok;
}

bool NoTemporaryLeft(const std::string& path)
{
  const std::string tmp = path + ".tmp-" + std::to_string(::getpid());
  struct stat st;
  return ::lstat(tmp.c_str(), &st) != 0;
}
} // namespace

TEST(SafeWrite, FileSizeLimitKeepsTheOldFileByteForByte)
{
  // A full disk, simulated by RLIMIT_FSIZE in a child process (SIGXFSZ ignored, so write(2)
  // fails with EFBIG "File too large", as it fails with ENOSPC on a full disk).
  const std::string path = TempPath("fsize.vdb");
  std::string errors;
  ASSERT_EQ(WriteCatching(SmallImage(1.0f), path, &errors), 1) << errors;
  const std::vector<char> before = Bytes(path);
  ASSERT_GT(before.size(), 20000u);
  const std::string report = TempPath("fsize-child.txt");
  std::fflush(nullptr);
  const pid_t pid = ::fork();
  if (pid == 0)
  {
    std::signal(SIGXFSZ, SIG_IGN);
    struct rlimit limit;
    limit.rlim_cur = limit.rlim_max = 8192; // bytes: far less than the new file needs
    ::setrlimit(RLIMIT_FSIZE, &limit);
    std::string childErrors;
    unsigned long code = 0;
    const int ok = WriteCatching(SmallImage(2.0f), path, &childErrors, nullptr, &code);
    std::ofstream(report) << ok << "\n" << code << "\n" << childErrors;
    std::_Exit(0);
  }
  int status = 0;
  ::waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
  std::ifstream in(report);
  int ok = -1;
  unsigned long code = 0;
  in >> ok >> code;
  const std::string childErrors(
    (std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(ok, 0);
  EXPECT_EQ(code, static_cast<unsigned long>(vtkErrorCode::OutOfDiskSpaceError));
  EXPECT_TRUE(Contains(childErrors, "File too large") &&
    Contains(childErrors, "the existing file was left as it was"))
    << childErrors;
  EXPECT_TRUE(Bytes(path) == before) << "the old file changed";
  EXPECT_TRUE(NoTemporaryLeft(path));
  int read = 0;
  const std::string readErrors = ReadErrors(path, 0, &read);
  EXPECT_EQ(read, 1) << readErrors;
}

TEST(SafeWrite, ReadOnlyTargetRefused)
{
  const std::string path = TempPath("readonly.vdb");
  std::string errors;
  ASSERT_EQ(WriteCatching(SmallImage(1.0f), path, &errors), 1) << errors;
  const std::vector<char> before = Bytes(path);
  ASSERT_EQ(::chmod(path.c_str(), 0444), 0);
  unsigned long code = 0;
  EXPECT_EQ(WriteCatching(SmallImage(2.0f), path, &errors, nullptr, &code), 0);
  EXPECT_TRUE(Contains(errors, "Permission denied") && Contains(errors, "read-only")) << errors;
  EXPECT_EQ(code, static_cast<unsigned long>(EACCES)); // as vtkXMLWriter: the system's errno
  EXPECT_TRUE(Bytes(path) == before);
  struct stat st;
  ASSERT_EQ(::stat(path.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 07777, 0444u);
  EXPECT_TRUE(NoTemporaryLeft(path));
}

TEST(SafeWrite, PermissionsKeptAndSymlinkWritesThroughToItsTarget)
{
  const std::string target = TempPath("link-target.vdb");
  const std::string link = TempPath("link.vdb");
  std::string errors;
  ASSERT_EQ(WriteCatching(SmallImage(1.0f), target, &errors), 1) << errors;
  ASSERT_EQ(::chmod(target.c_str(), 0640), 0);
  ::unlink(link.c_str());
  ASSERT_EQ(::symlink(target.c_str(), link.c_str()), 0);
  ASSERT_EQ(WriteCatching(SmallImage(2.0f), link, &errors), 1) << errors;
  struct stat st;
  ASSERT_EQ(::lstat(link.c_str(), &st), 0);
  EXPECT_TRUE(S_ISLNK(st.st_mode)) << "the link was replaced by a file";
  ASSERT_EQ(::stat(target.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 07777, 0640u) << "permission bits not kept";
  // The target holds the new data (density doubled).
  vtkNew<vtkNimbusOpenVDBReader> reader;
  reader->SetFileName(target.c_str());
  reader->Update();
  vtkDataArray* density = reader->GetOutput()->GetPointData()->GetArray("density");
  ASSERT_NE(density, nullptr);
  auto reference = SmallImage(2.0f);
  ExpectSameArray(reference->GetPointData()->GetArray("density"), density);
  EXPECT_TRUE(NoTemporaryLeft(target));
}

TEST(SafeWrite, HardLinkKeepsOldContentAndIsWarned)
{
  const std::string path = TempPath("hard-a.vdb");
  const std::string other = TempPath("hard-b.vdb");
  std::string errors, warnings;
  ASSERT_EQ(WriteCatching(SmallImage(1.0f), path, &errors), 1) << errors;
  ::unlink(other.c_str());
  ASSERT_EQ(::link(path.c_str(), other.c_str()), 0);
  const std::vector<char> before = Bytes(other);
  ASSERT_EQ(WriteCatching(SmallImage(2.0f), path, &errors, &warnings), 1) << errors;
  EXPECT_TRUE(Contains(warnings, "had 2 hard links") && Contains(warnings, "keep the old content"))
    << warnings;
  EXPECT_TRUE(Bytes(other) == before);
  EXPECT_FALSE(Bytes(path) == before);
}

TEST(SafeWrite, NaNAndInfiniteValuesAndBackgroundRefused)
{
  const std::string path = TempPath("nan.vdb");
  std::string errors;
  ASSERT_EQ(WriteCatching(SmallImage(1.0f), path, &errors), 1) << errors;
  const std::vector<char> before = Bytes(path);
  auto image = SmallImage(2.0f);
  auto* density = vtkFloatArray::SafeDownCast(image->GetPointData()->GetArray("density"));
  density->SetValue(7, std::nanf(""));
  density->SetValue(9, std::nanf(""));
  density->SetValue(11, INFINITY);
  EXPECT_EQ(WriteCatching(image, path, &errors), 0);
  EXPECT_TRUE(Contains(errors, "'density' has 2 NaN and 1 infinite values") &&
    Contains(errors, "value index 7") && Contains(errors, "nothing was written"))
    << errors;
  EXPECT_TRUE(Bytes(path) == before);
  for (double background : { std::nan(""), HUGE_VAL })
  {
    EXPECT_EQ(WriteCatching(SmallImage(2.0f), path, &errors, nullptr, nullptr, background), 0);
    EXPECT_TRUE(Contains(errors, "Background must be a finite number")) << errors;
    EXPECT_TRUE(Bytes(path) == before);
  }
}

TEST(SafeWrite, CellArrayNamesAreUniqueAndPredictable)
{
  vtkNew<vtkImageData> image;
  image->SetExtent(0, 3, 0, 3, 0, 3);
  auto add = [&](vtkDataSetAttributes* data, const char* name, vtkIdType n, float value)
  {
    vtkNew<vtkFloatArray> array;
    array->SetName(name);
    array->SetNumberOfTuples(n);
    array->Fill(value);
    data->AddArray(array);
  };
  add(image->GetPointData(), "density", image->GetNumberOfPoints(), 1.0f);
  add(image->GetCellData(), "density", image->GetNumberOfCells(), 2.0f);
  add(image->GetCellData(), "density_cells", image->GetNumberOfCells(), 3.0f);
  const std::string path = TempPath("names.vdb");
  std::string errors, warnings;
  ASSERT_EQ(WriteCatching(image, path, &errors, &warnings), 1) << errors;
  EXPECT_TRUE(Contains(warnings, "cell array 'density' -> grid 'density_cells_2'")) << warnings;
  const auto info = vdb::ReadFileInfo(path);
  std::set<std::string> names;
  for (const auto& g : info)
  {
    names.insert(g.StoredName);
  }
  EXPECT_EQ(names, (std::set<std::string>{ "density", "density_cells", "density_cells_2" }));
  // Each grid holds its own array's values.
  vtkNew<vtkNimbusOpenVDBReader> reader;
  reader->SetFileName(path.c_str());
  reader->UpdateInformation();
  reader->SetGridArrayStatus("density", 0);
  reader->Update();
  vtkDataArray* a = reader->GetOutput()->GetPointData()->GetArray("density_cells");
  vtkDataArray* b = reader->GetOutput()->GetPointData()->GetArray("density_cells_2");
  ASSERT_TRUE(a && b);
  EXPECT_EQ(a->GetTuple1(0), 3.0);
  EXPECT_EQ(b->GetTuple1(0), 2.0);
}

TEST(SafeWrite, UnnamedArrayIsNamedInTheMessage)
{
  vtkNew<vtkImageData> image;
  image->SetExtent(0, 2, 0, 2, 0, 2);
  vtkNew<vtkFloatArray> array;
  array->SetNumberOfTuples(image->GetNumberOfPoints());
  array->Fill(1.0f);
  image->GetPointData()->AddArray(array);
  std::string errors;
  EXPECT_EQ(WriteCatching(image, TempPath("unnamed.vdb"), &errors), 0);
  EXPECT_TRUE(Contains(errors, "an unnamed point array (1 components; a grid needs a name)"))
    << errors;
  EXPECT_FALSE(Contains(errors, "no arrays")) << errors;
}

// --- Reader: validation, budgets, censuses, names ------------------------------------------------

TEST(ReadChecks, TruncatedHeaderSaysTruncatedNotNoGrids)
{
  const std::string path = TempPath("header.vdb");
  std::string errors;
  ASSERT_EQ(WriteCatching(SmallImage(1.0f), path, &errors), 1) << errors;
  for (long cut : { 20L, 60L, 100L, 200L })
  {
    const std::string cutPath = TempPath("header-cut.vdb");
    Truncate(path, cutPath, cut);
    int ok = 1;
    errors = ReadErrors(cutPath, 0, &ok);
    EXPECT_EQ(ok, 0);
    EXPECT_TRUE(Contains(errors, "the file ends at byte " + std::to_string(cut)) &&
      Contains(errors, "the file is truncated (an interrupted download or copy?)") &&
      !Contains(errors, "has no grids"))
      << cut << ": " << errors;
  }
  // Cut inside the voxels of the last grid: the message names the grid and the bytes.
  const std::string last = TempPath("last-cut.vdb");
  const long size = FileSize(path);
  Truncate(path, last, size - 3);
  int ok = 1;
  errors = ReadErrors(last, 0, &ok);
  EXPECT_EQ(ok, 0);
  EXPECT_TRUE(Contains(errors,
    "the file ends at byte " + std::to_string(size - 3) +
      " but its grid 'velocity' needs bytes up to " + std::to_string(size)))
    << errors;
}

TEST(ReadChecks, DuplicateGridNamesAreAllRead)
{
  const std::string path = TempPath("duplicates.vdb");
  WriteGrids(path,
    { FloatBlock("density", openvdb::Coord(0), openvdb::Coord(3), 1.0, 1.0f),
      FloatBlock("density", openvdb::Coord(0), openvdb::Coord(3), 1.0, 5.0f) });
  vtkNew<vtkNimbusOpenVDBReader> reader;
  reader->SetFileName(path.c_str());
  MessageCatcher catcher(reader);
  reader->Update();
  EXPECT_TRUE(catcher.Errors.empty()) << catcher.AllErrors();
  ASSERT_EQ(reader->GetGridNames()->GetNumberOfValues(), 2);
  EXPECT_EQ(reader->GetGridNames()->GetValue(0), "density");
  EXPECT_EQ(reader->GetGridNames()->GetValue(1), "density[1]");
  vtkDataArray* first = reader->GetOutput()->GetPointData()->GetArray("density");
  vtkDataArray* second = reader->GetOutput()->GetPointData()->GetArray("density[1]");
  ASSERT_TRUE(first && second);
  EXPECT_FLOAT_EQ(first->GetTuple1(0), 1.0f);
  EXPECT_FLOAT_EQ(second->GetTuple1(0), 5.0f);
  EXPECT_TRUE(Contains(catcher.AllWarnings(), "has 2 grids named 'density'") &&
    Contains(catcher.AllWarnings(), "'density', 'density[1]'"))
    << catcher.AllWarnings();
}

TEST(ReadChecks, VoxelLimitAndMemoryBudgetCountAllGrids)
{
  // Nine sparse grids, each two voxels 255 apart: 9 x 256^3 voxels from a small file.
  openvdb::GridPtrVec grids;
  for (int g = 0; g < 9; ++g)
  {
    auto grid = openvdb::FloatGrid::create(0.0f);
    grid->setName("g" + std::to_string(g));
    grid->tree().setValue(openvdb::Coord(0), 1.0f);
    grid->tree().setValue(openvdb::Coord(255), 1.0f);
    grids.push_back(grid);
  }
  const std::string path = TempPath("many-sparse.vdb");
  WriteGrids(path, grids);
  EXPECT_LT(FileSize(path), 200000);
  int ok = 1;
  std::string errors = ReadErrors(path, 0, &ok);
  EXPECT_EQ(ok, 0);
  EXPECT_TRUE(
    Contains(errors, "256 x 256 x 256 = 16777216 points x 9 grid(s) = 150994944 voxels") &&
    Contains(errors, "all grids of the file together"))
    << errors;
  // Under the voxel limit but over a small memory budget: 9 x 64 MiB = 576 MiB > 100 MiB.
  vtkNew<vtkNimbusOpenVDBReader> reader;
  reader->SetFileName(path.c_str());
  reader->SetMaximumNumberOfVoxels(VTK_ID_MAX);
  reader->SetMemoryBudgetMiB(100);
  MessageCatcher catcher(reader);
  reader->GetExecutive()->AddObserver(vtkCommand::ErrorEvent, vtkNew<vtkCallbackCommand>());
  EXPECT_EQ(reader->GetExecutive()->Update(), 0);
  EXPECT_TRUE(Contains(catcher.AllErrors(), "memory budget") &&
    Contains(catcher.AllErrors(), "raise MemoryBudgetMiB"))
    << catcher.AllErrors();
  EXPECT_EQ(reader->GetOutput()->GetNumberOfPoints(), 0);
}

TEST(ReadChecks, HugeSparseGridAtTheLargestVoxelLimitDoesNotAbort)
{
  // Two voxels at -1e6 and +1e6: (2e6+1)^3 points. With MaximumNumberOfVoxels at its
  // maximum, the memory budget refuses it (this VTK aborts on a failed allocation).
  openvdb::initialize();
  auto grid = openvdb::FloatGrid::create(0.0f);
  grid->setName("spread");
  grid->tree().setValue(openvdb::Coord(-1000000), 1.0f);
  grid->tree().setValue(openvdb::Coord(1000000), 1.0f);
  const std::string path = TempPath("spread.vdb");
  WriteGrids(path, { grid });
  int ok = 1;
  const std::string errors = ReadErrors(path, VTK_ID_MAX, &ok);
  EXPECT_EQ(ok, 0);
  EXPECT_TRUE(Contains(errors, "memory budget")) << errors;
}

TEST(ReadChecks, NonFiniteAndNegativeValuesAreCountedInAWarning)
{
  openvdb::initialize();
  auto density = FloatBlock("density", openvdb::Coord(0), openvdb::Coord(3), 1.0, 1.0f);
  density->tree().setValue(openvdb::Coord(1, 1, 1), std::nanf(""));
  density->tree().setValue(openvdb::Coord(2, 1, 1), std::nanf(""));
  density->tree().setValue(openvdb::Coord(3, 1, 1), INFINITY);
  density->tree().setValue(openvdb::Coord(0, 2, 1), -0.5f);
  auto level = FloatBlock("distance", openvdb::Coord(0), openvdb::Coord(3), 1.0, -1.0f);
  const std::string path = TempPath("nonfinite.vdb");
  WriteGrids(path, { density, level });
  int ok = 0;
  std::string warnings;
  const std::string errors = ReadErrors(path, 0, &ok, &warnings);
  EXPECT_EQ(ok, 1) << errors;
  EXPECT_TRUE(Contains(warnings, "grid 'density'") && Contains(warnings, "2 NaN") &&
    Contains(warnings, "1 infinite") && Contains(warnings, "1 negative") &&
    Contains(warnings, "(of 64)"))
    << warnings;
  // Negative values of a grid that is not density-like are not warned about.
  EXPECT_FALSE(Contains(warnings, "grid 'distance'")) << warnings;
}

TEST(ReadChecks, StreamFilesWithoutOffsetsAreRefusedClearly)
{
  openvdb::initialize();
  const std::string path = TempPath("stream.vdb");
  {
    std::ofstream out(path, std::ios::binary);
    openvdb::io::Stream(out).write(openvdb::GridPtrVec{
      FloatBlock("density", openvdb::Coord(0), openvdb::Coord(2), 1.0, 1.0f) });
  }
  int ok = 1;
  const std::string errors = ReadErrors(path, 0, &ok);
  EXPECT_EQ(ok, 0);
  EXPECT_TRUE(Contains(errors, "without grid offsets")) << errors;
}

TEST(Guard, NegativeChunkSizeDoesNotOverflowTheBuffer)
{
  // OpenVDB 10.0.1's bloscFromStream reads -size bytes into the buffer before checking the
  // size; the replacement in IO/Core/VdbCompressionGuard.cxx checks first.
  openvdb::initialize();
  std::string bytes(8 + 64, 'x');
  const int64_t size = -64;
  std::memcpy(&bytes[0], &size, 8);
  std::istringstream in(bytes);
  char buffer[32];
  std::memset(buffer, 0, sizeof(buffer));
  EXPECT_THROW(openvdb::io::bloscFromStream(in, buffer, 16), openvdb::RuntimeError);
  EXPECT_EQ(buffer[16], 0) << "wrote past the 16-byte buffer";
  std::istringstream in2(bytes);
  EXPECT_THROW(openvdb::io::unzipFromStream(in2, buffer, 16), openvdb::RuntimeError);
  EXPECT_EQ(buffer[16], 0) << "wrote past the 16-byte buffer";
}

TEST(ReadChecks, UnknownGridTypeIsSkippedNotFatal)
{
  // A grid type OpenVDB does not know (its type name changed in the file, same length):
  // listed as unsupported and skipped; the other grid is read.
  const std::string path = TempPath("unknown-type.vdb");
  WriteGrids(path,
    { FloatBlock("alien", openvdb::Coord(0), openvdb::Coord(2), 1.0, 1.0f),
      FloatBlock("density", openvdb::Coord(0), openvdb::Coord(2), 1.0, 2.0f) });
  std::vector<char> bytes = Bytes(path);
  const vdb::FileLayout layout = vdb::ScanFile(path);
  ASSERT_EQ(layout.Grids.size(), 2u);
  ASSERT_EQ(layout.Grids[0].StoredName, "alien");
  const std::string type = "Tree_float_5_4_3";
  auto at = std::search(bytes.begin() + layout.Grids[0].DescriptorPos,
    bytes.begin() + layout.Grids[0].GridPos, type.begin(), type.end());
  ASSERT_NE(at, bytes.begin() + layout.Grids[0].GridPos);
  at[8] = 'e'; // "Tree_floet_5_4_3"
  std::ofstream(path, std::ios::binary | std::ios::trunc).write(bytes.data(), bytes.size());
  int ok = 0;
  std::string warnings;
  const std::string errors = ReadErrors(path, 0, &ok, &warnings);
  EXPECT_EQ(ok, 1) << errors;
  EXPECT_TRUE(Contains(warnings, "'alien' (unknown type 'Tree_floet_5_4_3')")) << warnings;
}

// Smoke in OpenVDB: the smoke source's output (density, temperature, velocity and the obstacle
// mask of a voxelised sphere) goes out as .vdb through the writer and comes back
// identical: FloatGrids, a Vec3SGrid, the cell centres' positions.
TEST(RoundTrip, SmokeOut)
{
  vtkNew<vtkNimbusSmokeSource> smoke;
  smoke->SetDimensions(12, 12, 20);
  smoke->SetCellSizeMetres(0.4);
  smoke->SetOrigin(-2.4, -2.4, 0.0);
  smoke->SetEmitterCentre(0.0, 0.0, 0.8);
  smoke->SetEmitterRadiusMetres(0.8);
  smoke->SetNumberOfFrames(12);
  vtkNew<vtkSphereSource> sphere;
  sphere->SetCenter(0.0, 0.0, 4.0);
  sphere->SetRadius(1.0);
  smoke->SetInputConnection(sphere->GetOutputPort());
  smoke->UpdateInformation();
  smoke->UpdateTimeStep(0.5);
  vtkImageData* image = smoke->GetOutput();
  ASSERT_GT(image->GetNumberOfPoints(), 0);
  const std::string path = TempPath("smoke.vdb");
  ASSERT_TRUE(Write(image, path));

  vtkNew<vtkNimbusOpenVDBReader> reader;
  reader->SetFileName(path.c_str());
  MessageCatcher catcher(reader);
  reader->Update();
  EXPECT_TRUE(catcher.Errors.empty()) << catcher.AllErrors();
  vtkImageData* out = reader->GetOutput();
  int extent[6];
  int outExtent[6];
  image->GetExtent(extent);
  out->GetExtent(outExtent);
  for (int c = 0; c < 6; ++c)
  {
    EXPECT_EQ(outExtent[c], extent[c]); // the temperature (~293 K) is active everywhere
  }
  for (int c = 0; c < 3; ++c)
  {
    EXPECT_NEAR(out->GetOrigin()[c], image->GetOrigin()[c], 1e-12);
    EXPECT_NEAR(out->GetSpacing()[c], image->GetSpacing()[c], 1e-12);
  }
  for (const char* name : { "density", "temperature", "velocity" })
  {
    SCOPED_TRACE(name);
    ExpectSameArray(image->GetPointData()->GetArray(name), out->GetPointData()->GetArray(name));
  }
  // The obstacle mask (unsigned char) becomes a FloatGrid of 0 and 1; outside its active
  // box the reader fills the background, 0.
  vtkDataArray* mask = image->GetPointData()->GetArray("obstacle");
  vtkDataArray* maskBack = out->GetPointData()->GetArray("obstacle");
  ASSERT_NE(mask, nullptr);
  ASSERT_NE(maskBack, nullptr);
  double solid = 0.0;
  for (vtkIdType i = 0; i < mask->GetNumberOfTuples(); ++i)
  {
    EXPECT_EQ(mask->GetComponent(i, 0), maskBack->GetComponent(i, 0)) << i;
    solid += mask->GetComponent(i, 0);
  }
  EXPECT_GT(solid, 0.0);
}
