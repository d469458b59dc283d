// Data tests of the OpenVDB reader's UpAxis (docs/openvdb.md, "Which way is up"): small
// .vdb files written here with OpenVDB directly (an independent producer) -- a y-up file with
// voxel size 3.33 offset from the origin, a float grid and a Vec3s grid of known voxels, with
// and without the metadata Houdini and Nimbus write -- read for each of the four axes and
// Auto. The expected bounds, spacing, origin and values at world points are computed by hand
// from the table of Physics/UpAxis.h (HandUp), with OpenVDB's own indexToWorld for the world
// points; pieces of the turned image are checked against the whole read.
#include "VdbUpAxis.h"
#include "vtkNimbusOpenVDBReader.h"
#include "vtkNimbusOpenVDBWriter.h"

#include "vtkCallbackCommand.h"
#include "vtkCommand.h"
#include "vtkExecutive.h"
#include "vtkExtentTranslator.h"
#include "vtkFieldData.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkMatrix3x3.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include "vtkStringArray.h"

#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>

#include "MessageCatcher.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <map>
#include <string>
#include <unistd.h>
#include <vector>

using nimbus::UpAxis;
using nimbus::testing::MessageCatcher;

namespace
{
using Vec3 = std::array<double, 3>;

// U for world point (or vector) W, by hand (Physics/UpAxis.h's table):
//   +X up: ( y,  z, x)   +Y up: ( x, -z, y)   +Z up: ( x, y, z)   -Y up: ( x, z, -y)
Vec3 HandUp(int axis, const Vec3& w)
{
  switch (axis)
  {
    case 0:
      return { { w[1], w[2], w[0] } };
    case 1:
      return { { w[0], -w[2], w[1] } };
    case 3:
      return { { w[0], w[2], -w[1] } };
    default:
      return w;
  }
}

std::string TempPath(const std::string& name)
{
  static std::string dir;
  if (dir.empty())
  {
    char pattern[] = "/tmp/nimbus-upaxis-XXXXXX";
    dir = mkdtemp(pattern);
  }
  return dir + "/" + name;
}

// The voxels: a box of 5 x 8 x 3 (all extents differ, so a swapped axis shows).
const openvdb::Coord BoxMin(2, -3, 1), BoxMax(6, 4, 3);
float Density(int i, int j, int k)
{
  return float(50 + i + 10 * j + 100 * k); // > 0 over the box; one value per voxel
}
openvdb::Vec3s Velocity(int i, int j, int k)
{
  return openvdb::Vec3s(float(1000 + i), float(2000 + j), float(3000 + k));
}

// Voxel size 3.33, index (0,0,0) at (100.5, -20.25, 7.75).
openvdb::math::Transform::Ptr OffsetTransform()
{
  auto t = openvdb::math::Transform::createLinearTransform(3.33);
  t->postTranslate(openvdb::Vec3d(100.5, -20.25, 7.75));
  return t;
}

// Writes "density" (fog volume) and "velocity" over the box with transform `t`, and the
// file-level string metadata `fileMeta`; `gridCreator` as each grid's "creator".
std::string WriteFile(const std::string& name, openvdb::math::Transform::Ptr t,
  const std::map<std::string, std::string>& fileMeta, const std::string& gridCreator = "")
{
  openvdb::initialize();
  auto density = openvdb::FloatGrid::create(0.0f);
  density->setName("density");
  density->setGridClass(openvdb::GRID_FOG_VOLUME);
  auto velocity = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
  velocity->setName("velocity");
  for (int k = BoxMin.z(); k <= BoxMax.z(); ++k)
    for (int j = BoxMin.y(); j <= BoxMax.y(); ++j)
      for (int i = BoxMin.x(); i <= BoxMax.x(); ++i)
      {
        density->tree().setValue(openvdb::Coord(i, j, k), Density(i, j, k));
        velocity->tree().setValue(openvdb::Coord(i, j, k), Velocity(i, j, k));
      }
  density->setTransform(t);
  velocity->setTransform(t->copy());
  if (!gridCreator.empty())
  {
    density->setCreator(gridCreator);
    velocity->setCreator(gridCreator);
  }
  openvdb::MetaMap meta;
  for (const auto& m : fileMeta)
  {
    meta.insertMeta(m.first, openvdb::StringMetadata(m.second));
  }
  const std::string path = TempPath(name);
  openvdb::io::File file(path);
  file.write(openvdb::GridPtrVec{ density, velocity }, meta);
  file.close();
  return path;
}

struct Read
{
  vtkSmartPointer<vtkImageData> Image;
  std::string Source;
  int Resolved = -1;
  std::string Warnings;
  std::string Errors;
};

Read ReadFile(const std::string& path, int upAxis)
{
  vtkNew<vtkNimbusOpenVDBReader> reader;
  reader->SetFileName(path.c_str());
  reader->SetUpAxis(upAxis);
  MessageCatcher catcher(reader);
  reader->Update();
  Read r;
  r.Image = vtkSmartPointer<vtkImageData>::New();
  r.Image->ShallowCopy(reader->GetOutput());
  r.Resolved = reader->GetResolvedUpAxis();
  r.Warnings = catcher.AllWarnings();
  r.Errors = catcher.AllErrors();
  auto* source = vtkStringArray::SafeDownCast(
    r.Image->GetFieldData()->GetAbstractArray(vtkNimbusOpenVDBReader::UpAxisSourceArrayName()));
  if (source && source->GetNumberOfValues() == 1)
  {
    r.Source = source->GetValue(0);
  }
  EXPECT_EQ(r.Source, std::string(reader->GetResolvedUpAxisSource()));
  return r;
}

// The world point of file voxel (i, j, k), by OpenVDB.
Vec3 World(const openvdb::math::Transform& t, int i, int j, int k)
{
  const openvdb::Vec3d w = t.indexToWorld(openvdb::Coord(i, j, k));
  return { { w.x(), w.y(), w.z() } };
}

// Checks every voxel of the box: its world point, turned by hand, is an image point that
// holds the voxel's density and the voxel's velocity turned by hand.
void CheckEveryVoxel(const vtkSmartPointer<vtkImageData>& image, const openvdb::math::Transform& t,
  int axis, const std::string& what)
{
  auto* density = vtkFloatArray::SafeDownCast(image->GetPointData()->GetArray("density"));
  auto* velocity = vtkFloatArray::SafeDownCast(image->GetPointData()->GetArray("velocity"));
  ASSERT_TRUE(density && velocity) << what;
  ASSERT_EQ(image->GetNumberOfPoints(), vtkIdType(5 * 8 * 3)) << what;
  int extent[6];
  image->GetExtent(extent);
  for (int k = BoxMin.z(); k <= BoxMax.z(); ++k)
    for (int j = BoxMin.y(); j <= BoxMax.y(); ++j)
      for (int i = BoxMin.x(); i <= BoxMax.x(); ++i)
      {
        const Vec3 up = HandUp(axis, World(t, i, j, k));
        double index[3];
        image->TransformPhysicalPointToContinuousIndex(up.data(), index);
        int ijk[3];
        for (int a = 0; a < 3; ++a)
        {
          ijk[a] = int(std::lround(index[a]));
          ASSERT_NEAR(index[a], ijk[a], 1e-6) << what << ": voxel " << i << " " << j << " " << k;
          ASSERT_GE(ijk[a], extent[2 * a]) << what;
          ASSERT_LE(ijk[a], extent[2 * a + 1]) << what;
        }
        const vtkIdType id = image->ComputePointId(ijk);
        ASSERT_EQ(density->GetValue(id), Density(i, j, k))
          << what << ": voxel " << i << " " << j << " " << k;
        const openvdb::Vec3s v = Velocity(i, j, k);
        const Vec3 expected = HandUp(axis, { { v.x(), v.y(), v.z() } });
        for (int c = 0; c < 3; ++c)
        {
          ASSERT_EQ(velocity->GetComponent(id, c), float(expected[c]))
            << what << ": velocity component " << c << " of voxel " << i << " " << j << " " << k;
        }
      }
}

// The value of `array` at the image point nearest world point `u` (which must be a point).
double ValueAt(vtkImageData* image, const char* array, const Vec3& u, int component = 0)
{
  double index[3];
  image->TransformPhysicalPointToContinuousIndex(u.data(), index);
  int ijk[3];
  for (int a = 0; a < 3; ++a)
  {
    ijk[a] = int(std::lround(index[a]));
    EXPECT_NEAR(index[a], ijk[a], 1e-6) << "not an image point";
  }
  return image->GetPointData()->GetArray(array)->GetComponent(
    image->ComputePointId(ijk), component);
}
}

// The y-up file: bounds, spacing, origin and values, for each axis, against numbers worked
// out by hand. Voxel (2, -3, 1) is at world (100.5 + 2 x 3.33, -20.25 - 3 x 3.33,
// 7.75 + 3.33) = (107.16, -30.24, 11.08) with density 50 + 2 - 30 + 100 = 122 and velocity
// (1002, 1997, 3001). The box spans x 107.16..120.48, y -30.24..-6.93, z 11.08..17.74.
TEST(UpAxis, EachAxisByHand)
{
  const std::string path = WriteFile("yup.vdb", OffsetTransform(), {});
  const auto transform = OffsetTransform();
  struct Expected
  {
    int Axis;
    Vec3 Point;    // the world point (107.16, -30.24, 11.08) in the up frame
    Vec3 Velocity; // (1002, 1997, 3001) in the up frame
    double Bounds[6];
  };
  const Expected cases[] = {
    { 0, { { -30.24, 11.08, 107.16 } }, { { 1997, 3001, 1002 } },
      { -30.24, -6.93, 11.08, 17.74, 107.16, 120.48 } },
    { 1, { { 107.16, -11.08, -30.24 } }, { { 1002, -3001, 1997 } },
      { 107.16, 120.48, -17.74, -11.08, -30.24, -6.93 } },
    { 2, { { 107.16, -30.24, 11.08 } }, { { 1002, 1997, 3001 } },
      { 107.16, 120.48, -30.24, -6.93, 11.08, 17.74 } },
    { 3, { { 107.16, 11.08, 30.24 } }, { { 1002, 3001, -1997 } },
      { 107.16, 120.48, 11.08, 17.74, 6.93, 30.24 } },
  };
  for (const Expected& e : cases)
  {
    const std::string what = "UpAxis " + std::to_string(e.Axis);
    const Read r = ReadFile(path, e.Axis);
    ASSERT_EQ(r.Errors, "") << what;
    EXPECT_EQ(r.Resolved, e.Axis);
    EXPECT_EQ(r.Source, nimbus::UpAxisName(static_cast<UpAxis>(e.Axis)) + " (chosen)");
    double bounds[6];
    r.Image->GetBounds(bounds);
    for (int b = 0; b < 6; ++b)
    {
      EXPECT_NEAR(bounds[b], e.Bounds[b], 1e-9) << what << " bound " << b;
    }
    double spacing[3];
    r.Image->GetSpacing(spacing);
    for (int a = 0; a < 3; ++a)
    {
      EXPECT_NEAR(spacing[a], 3.33, 1e-12) << what;
    }
    // The origin: the world position of index (0,0,0), (100.5, -20.25, 7.75), turned.
    const Vec3 origin = HandUp(e.Axis, { { 100.5, -20.25, 7.75 } });
    for (int a = 0; a < 3; ++a)
    {
      EXPECT_EQ(r.Image->GetOrigin()[a], origin[a]) << what;
    }
    EXPECT_TRUE(r.Image->GetDirectionMatrix()->IsIdentity()) << what;
    EXPECT_EQ(ValueAt(r.Image, "density", e.Point), 122.0) << what;
    for (int c = 0; c < 3; ++c)
    {
      EXPECT_EQ(ValueAt(r.Image, "velocity", e.Point, c), e.Velocity[c]) << what;
    }
    CheckEveryVoxel(r.Image, *transform, e.Axis, what);
  }
  // +Y by hand in index terms: the file's extent [2,6] x [-3,4] x [1,3] becomes
  // [2,6] x [-3,-1] x [-3,4] (turned y = -file k, turned z = file j).
  const Read y = ReadFile(path, 1);
  int extent[6];
  y.Image->GetExtent(extent);
  EXPECT_EQ((std::vector<int>(extent, extent + 6)), (std::vector<int>{ 2, 6, -3, -1, -3, 4 }));
}

// Non-uniform voxels: the spacing follows its axis.
TEST(UpAxis, AnisotropicSpacingFollowsItsAxis)
{
  openvdb::Mat4d m = openvdb::Mat4d::identity();
  m.setToScale(openvdb::Vec3d(3.33, 2.0, 1.25));
  m.setTranslation(openvdb::Vec3d(-4.5, 12.0, 0.5));
  auto t = openvdb::math::Transform::createLinearTransform(m);
  const std::string path = WriteFile("aniso.vdb", t, {});
  const Vec3 file{ { 3.33, 2.0, 1.25 } };
  for (int axis = 0; axis < 4; ++axis)
  {
    const Read r = ReadFile(path, axis);
    ASSERT_EQ(r.Errors, "");
    const Vec3 turned = HandUp(axis, file);
    for (int a = 0; a < 3; ++a)
    {
      EXPECT_EQ(r.Image->GetSpacing()[a], std::abs(turned[a])) << "UpAxis " << axis;
    }
    CheckEveryVoxel(r.Image, *t, axis, "anisotropic, UpAxis " + std::to_string(axis));
  }
}

// A rotated transform (30 degrees about z): not re-indexed; direction R D, origin R o.
TEST(UpAxis, RotatedTransformGetsTurnedDirection)
{
  auto t = openvdb::math::Transform::createLinearTransform(3.33);
  t->postRotate(M_PI / 6, openvdb::math::Z_AXIS);
  t->postTranslate(openvdb::Vec3d(100.5, -20.25, 7.75));
  const std::string path = WriteFile("rotated.vdb", t, {});
  const Read z = ReadFile(path, 2);
  for (int axis = 0; axis < 4; ++axis)
  {
    const Read r = ReadFile(path, axis);
    ASSERT_EQ(r.Errors, "");
    int extent[6], zExtent[6];
    r.Image->GetExtent(extent);
    z.Image->GetExtent(zExtent);
    EXPECT_EQ(std::vector<int>(extent, extent + 6), std::vector<int>(zExtent, zExtent + 6));
    // Every image point sits at its file voxel's world point, turned.
    for (int k = BoxMin.z(); k <= BoxMax.z(); k += 2)
      for (int j = BoxMin.y(); j <= BoxMax.y(); j += 3)
        for (int i = BoxMin.x(); i <= BoxMax.x(); i += 2)
        {
          double p[3];
          r.Image->TransformIndexToPhysicalPoint(i, j, k, p);
          const Vec3 up = HandUp(axis, World(*t, i, j, k));
          for (int a = 0; a < 3; ++a)
          {
            EXPECT_NEAR(p[a], up[a], 1e-9) << "UpAxis " << axis;
          }
        }
    CheckEveryVoxel(r.Image, *t, axis, "rotated, UpAxis " + std::to_string(axis));
  }
}

// Auto, with and without metadata.
TEST(UpAxis, AutoFromTheFilesMetadata)
{
  const auto t = OffsetTransform();
  struct Case
  {
    std::string Name;
    std::map<std::string, std::string> Meta;
    std::string GridCreator;
    int Axis;
    std::string Source;
  };
  const Case cases[] = {
    { "none.vdb", {}, "", 2, "+Z (default)" },
    { "houdini.vdb", { { "creator", "Houdini 20.5.278/GEO_VDBTranslator" } }, "", 1,
      "+Y (creator 'Houdini 20.5.278/GEO_VDBTranslator')" },
    { "houdini_write_sop.vdb", { { "creator", "Houdini/SOP_OpenVDB_Write" } }, "", 1,
      "+Y (creator 'Houdini/SOP_OpenVDB_Write')" },
    { "grid_creator.vdb", {}, "Houdini/SOP_OpenVDB_Write", 1,
      "+Y (grid creator 'Houdini/SOP_OpenVDB_Write')" },
    { "up_y.vdb", { { "up_axis", "y" } }, "", 1, "+Y (file metadata up_axis = 'y')" },
    { "up_minus_y.vdb", { { "UP_AXIS", "-Y" } }, "", 3, "-Y (file metadata up_axis = '-Y')" },
    { "up_x.vdb", { { "up_axis", "+x" } }, "", 0, "+X (file metadata up_axis = '+x')" },
    { "houdini_says_z.vdb",
      { { "creator", "Houdini 20.5.278/GEO_VDBTranslator" }, { "up_axis", "+Z" } }, "", 2,
      "+Z (file metadata up_axis = '+Z')" },
    { "blender.vdb", { { "creator", "Blender" } }, "", 2, "+Z (default)" },
  };
  for (const Case& c : cases)
  {
    const std::string path = WriteFile(c.Name, t, c.Meta, c.GridCreator);
    const Read automatic = ReadFile(path, -1);
    ASSERT_EQ(automatic.Errors, "") << c.Name;
    EXPECT_EQ(automatic.Resolved, c.Axis) << c.Name;
    EXPECT_EQ(automatic.Source, c.Source) << c.Name;
    // Auto reads exactly what choosing that axis reads.
    const Read chosen = ReadFile(path, c.Axis);
    EXPECT_EQ(std::vector<double>(automatic.Image->GetBounds(), automatic.Image->GetBounds() + 6),
      std::vector<double>(chosen.Image->GetBounds(), chosen.Image->GetBounds() + 6))
      << c.Name;
    CheckEveryVoxel(automatic.Image, *t, c.Axis, c.Name + ", Auto");
  }
  // An up_axis the rule cannot read: a warning, then the creator decides.
  const std::string odd = WriteFile(
    "odd.vdb", t, { { "up_axis", "sideways" }, { "creator", "Houdini/SOP_OpenVDB_Write" } });
  const Read r = ReadFile(odd, -1);
  EXPECT_EQ(r.Resolved, 1);
  EXPECT_NE(r.Warnings.find("up_axis = 'sideways'"), std::string::npos) << r.Warnings;
  // A chosen axis overrides the file.
  const Read chosen = ReadFile(WriteFile("h2.vdb", t, { { "up_axis", "y" } }), 0);
  EXPECT_EQ(chosen.Source, "+X (chosen)");
}

// Nimbus's writer says its data is z up, and a written image reads back as it was.
TEST(UpAxis, WriterWritesUpAxisAndReadsBackUnchanged)
{
  vtkNew<vtkImageData> image;
  image->SetExtent(-2, 3, 0, 4, 1, 3);
  image->SetOrigin(10.0, -5.0, 2.5);
  image->SetSpacing(3.33, 3.33, 3.33);
  vtkNew<vtkFloatArray> density;
  density->SetName("density");
  density->SetNumberOfTuples(image->GetNumberOfPoints());
  for (vtkIdType n = 0; n < image->GetNumberOfPoints(); ++n)
  {
    density->SetValue(n, 1.0f + float(n));
  }
  image->GetPointData()->AddArray(density);
  const std::string path = TempPath("written.vdb");
  vtkNew<vtkNimbusOpenVDBWriter> writer;
  writer->SetInputData(image);
  writer->SetFileName(path.c_str());
  ASSERT_EQ(writer->Write(), 1);

  openvdb::initialize();
  openvdb::io::File file(path);
  file.open();
  const auto meta = file.getMetadata();
  file.close();
  ASSERT_TRUE(meta->getMetadata<openvdb::StringMetadata>("up_axis"));
  EXPECT_EQ(meta->metaValue<std::string>("up_axis"), "+Z");

  const Read r = ReadFile(path, -1);
  EXPECT_EQ(r.Source, "+Z (file metadata up_axis = '+Z')");
  int extent[6];
  r.Image->GetExtent(extent);
  EXPECT_EQ((std::vector<int>(extent, extent + 6)), (std::vector<int>{ -2, 3, 0, 4, 1, 3 }));
  for (int a = 0; a < 3; ++a)
  {
    EXPECT_EQ(r.Image->GetOrigin()[a], image->GetOrigin()[a]);
    EXPECT_EQ(r.Image->GetSpacing()[a], image->GetSpacing()[a]);
  }
  auto* back = vtkFloatArray::SafeDownCast(r.Image->GetPointData()->GetArray("density"));
  ASSERT_TRUE(back);
  for (vtkIdType n = 0; n < image->GetNumberOfPoints(); ++n)
  {
    ASSERT_EQ(back->GetValue(n), density->GetValue(n));
  }
}

// +Z is the file as it is: Auto on a file without metadata and UpAxis = +Z read the same
// arrays, bit for bit, with the file's own extent.
TEST(UpAxis, PlusZIsTheFileAsItIs)
{
  const std::string path = WriteFile("plain.vdb", OffsetTransform(), {});
  const Read a = ReadFile(path, -1);
  const Read z = ReadFile(path, 2);
  int extent[6];
  z.Image->GetExtent(extent);
  EXPECT_EQ((std::vector<int>(extent, extent + 6)),
    (std::vector<int>{ BoxMin.x(), BoxMax.x(), BoxMin.y(), BoxMax.y(), BoxMin.z(), BoxMax.z() }));
  for (const char* name : { "density", "velocity" })
  {
    auto* x = vtkFloatArray::SafeDownCast(a.Image->GetPointData()->GetArray(name));
    auto* y = vtkFloatArray::SafeDownCast(z.Image->GetPointData()->GetArray(name));
    ASSERT_TRUE(x && y);
    ASSERT_EQ(x->GetNumberOfValues(), y->GetNumberOfValues());
    for (vtkIdType n = 0; n < x->GetNumberOfValues(); ++n)
    {
      ASSERT_EQ(x->GetValue(n), y->GetValue(n));
    }
  }
  // Voxel (i, j, k) is image point (i, j, k) for +Z.
  const int ijk[3] = { 4, -1, 2 };
  EXPECT_EQ(z.Image->GetPointData()->GetArray("density")->GetComponent(
              z.Image->ComputePointId(const_cast<int*>(ijk)), 0),
    Density(4, -1, 2));
}

// Pieces of the turned image: the whole extent announced is the turned one, each piece is
// VTK's block of it (grown by the ghost levels), and every point of a piece equals the same
// point of the whole read.
TEST(UpAxis, PiecesOfTheTurnedImageEqualTheWhole)
{
  const std::string path = WriteFile("pieces.vdb", OffsetTransform(), {});
  for (int axis : { 0, 1, 3 })
  {
    const Read whole = ReadFile(path, axis);
    int wholeExtent[6];
    whole.Image->GetExtent(wholeExtent);
    vtkNew<vtkNimbusOpenVDBReader> reader;
    reader->SetFileName(path.c_str());
    reader->SetUpAxis(axis);
    reader->UpdateInformation();
    int announced[6];
    reader->GetOutputInformation(0)->Get(
      vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), announced);
    EXPECT_EQ(
      std::vector<int>(announced, announced + 6), std::vector<int>(wholeExtent, wholeExtent + 6))
      << "UpAxis " << axis;
    double origin[3], spacing[3];
    reader->GetOutputInformation(0)->Get(vtkDataObject::ORIGIN(), origin);
    reader->GetOutputInformation(0)->Get(vtkDataObject::SPACING(), spacing);
    for (int a = 0; a < 3; ++a)
    {
      EXPECT_EQ(origin[a], whole.Image->GetOrigin()[a]);
      EXPECT_EQ(spacing[a], whole.Image->GetSpacing()[a]);
    }
    for (int ghosts : { 0, 1 })
    {
      const int pieces = 4;
      std::vector<bool> covered(size_t(whole.Image->GetNumberOfPoints()), false);
      for (int piece = 0; piece < pieces; ++piece)
      {
        reader->UpdatePiece(piece, pieces, ghosts);
        vtkImageData* part = reader->GetOutput();
        int extent[6], expected[6];
        part->GetExtent(extent);
        vtkNew<vtkExtentTranslator> translator;
        translator->PieceToExtentThreadSafe(
          piece, pieces, ghosts, wholeExtent, expected, vtkExtentTranslator::BLOCK_MODE, 0);
        EXPECT_EQ(std::vector<int>(extent, extent + 6), std::vector<int>(expected, expected + 6))
          << "UpAxis " << axis << " piece " << piece;
        for (const char* name : { "density", "velocity" })
        {
          vtkDataArray* a = part->GetPointData()->GetArray(name);
          vtkDataArray* b = whole.Image->GetPointData()->GetArray(name);
          ASSERT_TRUE(a && b);
          for (int k = extent[4]; k <= extent[5]; ++k)
            for (int j = extent[2]; j <= extent[3]; ++j)
              for (int i = extent[0]; i <= extent[1]; ++i)
              {
                int ijk[3] = { i, j, k };
                const vtkIdType pa = part->ComputePointId(ijk);
                const vtkIdType pb = whole.Image->ComputePointId(ijk);
                covered[size_t(pb)] = true;
                for (int c = 0; c < a->GetNumberOfComponents(); ++c)
                {
                  ASSERT_EQ(a->GetComponent(pa, c), b->GetComponent(pb, c))
                    << name << " UpAxis " << axis << " piece " << piece << " at " << i << " " << j
                    << " " << k;
                }
              }
        }
      }
      EXPECT_EQ(std::count(covered.begin(), covered.end(), false), 0)
        << "points of the image in no piece";
    }
  }
}
