// Data tests of the metaball cloud source (004 §4) and its plain-C++ core.
// Filters compare data, not images.
#include "MemoryBudget.h"
#include "Metaballs.h"
#include "Random.h"
#include "vtkNimbusMetaballCloudSource.h"

#include "vtkCallbackCommand.h"
#include "vtkCommand.h"
#include "vtkFloatArray.h"
#include "vtkFlyingEdges3D.h"
#include "vtkImageData.h"
#include "vtkMassProperties.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPolyData.h"
#include "vtkTriangleFilter.h"

#include "MessageCatcher.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <iostream>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

namespace
{
// Collects vtkErrorMacro / vtkWarningMacro messages of one object instead of printing them.
using nimbus::testing::MessageCatcher;

// A cheap configuration for tests: 48 x 48 x 32 points.
void MakeSmall(vtkNimbusMetaballCloudSource* source)
{
  source->SetDimensions(48, 48, 32);
}

vtkFloatArray* Density(vtkNimbusMetaballCloudSource* source)
{
  return vtkFloatArray::SafeDownCast(source->GetOutput()->GetPointData()->GetArray("density"));
}

double IsosurfaceArea(vtkImageData* image, double isoValue)
{
  vtkNew<vtkFlyingEdges3D> contour;
  contour->SetInputData(image);
  contour->SetValue(0, isoValue);
  vtkNew<vtkTriangleFilter> triangles;
  triangles->SetInputConnection(contour->GetOutputPort());
  vtkNew<vtkMassProperties> mass;
  mass->SetInputConnection(triangles->GetOutputPort());
  mass->Update();
  return contour->GetOutput()->GetNumberOfCells() > 0 ? mass->GetSurfaceArea() : 0.0;
}
}

// --- the plain-C++ core -------------------------------------------------------------

TEST(WyvillFalloff, KnownValues)
{
  const double R2 = 4.0; // R = 2
  EXPECT_DOUBLE_EQ(nimbus::WyvillFalloff(0.0, R2), 1.0);
  EXPECT_NEAR(nimbus::WyvillFalloff(1.0, R2), 0.5, 1e-15); // f(R/2) = 1/2
  EXPECT_NEAR(nimbus::WyvillFalloff(R2, R2), 0.0, 0.0);
  EXPECT_EQ(nimbus::WyvillFalloff(9.0, R2), 0.0);
  // Monotone decreasing and within [0, 1].
  double previous = 1.0;
  for (int i = 1; i <= 1000; ++i)
  {
    const double r = 2.0 * i / 1000.0;
    const double f = nimbus::WyvillFalloff(r * r, R2);
    EXPECT_LE(f, previous);
    EXPECT_GE(f, 0.0);
    previous = f;
  }
}

TEST(MetaballDensityGradient, MatchesFiniteDifferences)
{
  std::vector<nimbus::Metaball> balls(2);
  balls[0].Center = { { 0.0, 0.0, 0.0 } };
  balls[0].Radius = 3.0;
  balls[1].Center = { { 1.5, 0.5, -0.3 } };
  balls[1].Radius = 2.0;
  balls[1].Density = 0.7;
  const std::array<double, 3> p{ { 0.7, -0.4, 0.9 } };
  const auto gradient = nimbus::MetaballDensityGradient(balls, p);
  const double h = 1e-6;
  for (int a = 0; a < 3; ++a)
  {
    auto plus = p, minus = p;
    plus[a] += h;
    minus[a] -= h;
    const double numeric =
      (nimbus::MetaballDensity(balls, plus) - nimbus::MetaballDensity(balls, minus)) / (2 * h);
    EXPECT_NEAR(gradient[a], numeric, 1e-7);
  }
}

TEST(SampleMetaballs, MatchesPointEvaluation)
{
  std::vector<nimbus::Metaball> balls(1);
  balls[0].Center = { { 0.3, -0.2, 0.1 } };
  balls[0].Radius = 1.7;
  nimbus::GridGeometry grid;
  grid.Dimensions = { { 9, 8, 7 } };
  grid.Origin = { { -2.0, -2.0, -1.5 } };
  grid.Spacing = { { 0.5, 0.5, 0.5 } };
  std::vector<float> density;
  nimbus::SampleMetaballs(balls, grid, density);
  ASSERT_EQ(density.size(), grid.NumberOfPoints());
  std::size_t idx = 0;
  for (int k = 0; k < 7; ++k)
    for (int j = 0; j < 8; ++j)
      for (int i = 0; i < 9; ++i, ++idx)
      {
        const std::array<double, 3> p{ { -2.0 + 0.5 * i, -2.0 + 0.5 * j, -1.5 + 0.5 * k } };
        EXPECT_NEAR(density[idx], nimbus::MetaballDensity(balls, p), 1e-6);
      }
}

TEST(SampleMetaballs, PieceEqualsCropOfWhole)
{
  std::vector<nimbus::Metaball> balls(3);
  balls[0].Center = { { 0.3, -0.2, 0.1 } };
  balls[0].Radius = 1.7;
  balls[1].Center = { { -1.1, 0.9, 0.4 } };
  balls[1].Radius = 1.1;
  balls[1].Density = 0.7;
  balls[2].Center = { { 1.4, 1.2, -0.6 } };
  balls[2].Radius = 0.9;
  nimbus::GridGeometry grid;
  grid.Dimensions = { { 11, 9, 8 } };
  grid.Origin = { { -2.5, -2.0, -1.5 } };
  grid.Spacing = { { 0.45, 0.5, 0.41 } };
  std::vector<float> whole, piece;
  nimbus::SampleMetaballs(balls, grid, whole);
  nimbus::ApplyCloudBase(grid, -1.0, 0.6, whole);
  const nimbus::GridExtent extent{ { 3, 9, 0, 4, 2, 7 } };
  nimbus::SampleMetaballs(balls, grid, extent, piece);
  nimbus::ApplyCloudBase(grid, extent, -1.0, 0.6, piece);
  ASSERT_EQ(piece.size(), std::size_t(7 * 5 * 6));
  std::size_t idx = 0;
  int nonzero = 0;
  for (int k = extent[4]; k <= extent[5]; ++k)
    for (int j = extent[2]; j <= extent[3]; ++j)
      for (int i = extent[0]; i <= extent[1]; ++i, ++idx)
      {
        const float expected = whole[(std::size_t(k) * 9 + j) * 11 + i];
        ASSERT_EQ(std::memcmp(&piece[idx], &expected, sizeof(float)), 0)
          << i << " " << j << " " << k;
        nonzero += expected != 0.0f;
      }
  EXPECT_GT(nonzero, 20);
  const nimbus::GridExtent outside{ { 3, 11, 0, 4, 2, 7 } };
  EXPECT_THROW(nimbus::SampleMetaballs(balls, grid, outside, piece), std::invalid_argument);
}

TEST(Random, SameSeedSameSequenceInUnitInterval)
{
  nimbus::Random a(42), b(42), c(43);
  bool differs = false;
  for (int i = 0; i < 1000; ++i)
  {
    const double x = a.Uniform();
    EXPECT_EQ(x, b.Uniform());
    EXPECT_GE(x, 0.0);
    EXPECT_LT(x, 1.0);
    differs = differs || x != c.Uniform();
  }
  EXPECT_TRUE(differs);
}

// --- the VTK source --------------------------------------------------------------------

TEST(MetaballCloudSource, DefaultsProduceACloud)
{
  vtkNew<vtkNimbusMetaballCloudSource> source;
  MessageCatcher messages(source);
  source->Update();
  EXPECT_TRUE(messages.Errors.empty());
  vtkImageData* image = source->GetOutput();
  int dims[3];
  image->GetDimensions(dims);
  EXPECT_EQ(dims[0], 96);
  EXPECT_EQ(dims[1], 96);
  EXPECT_EQ(dims[2], 64);
  double bounds[6];
  image->GetBounds(bounds);
  EXPECT_DOUBLE_EQ(bounds[0], -1500.0);
  EXPECT_DOUBLE_EQ(bounds[5], 2800.0);
  vtkFloatArray* density = Density(source);
  ASSERT_NE(density, nullptr);
  EXPECT_EQ(image->GetPointData()->GetScalars(), density);
  double range[2];
  density->GetRange(range);
  EXPECT_GT(range[1], 0.5); // there is a cloud
  vtkPolyData* balls = source->GetMetaballs();
  ASSERT_NE(balls, nullptr);
  EXPECT_GT(balls->GetNumberOfPoints(), 10);
  for (const char* name : { "radius", "density", "level" })
  {
    EXPECT_NE(balls->GetPointData()->GetArray(name), nullptr) << name;
  }
}

TEST(MetaballCloudSource, SameSeedGivesIdenticalBytes)
{
  vtkNew<vtkNimbusMetaballCloudSource> a, b, c;
  for (auto* s : { a.Get(), b.Get(), c.Get() })
  {
    MakeSmall(s);
    s->SetSeed(11);
  }
  c->SetSeed(12);
  a->Update();
  b->Update();
  c->Update();
  vtkFloatArray* da = Density(a);
  vtkFloatArray* db = Density(b);
  vtkFloatArray* dc = Density(c);
  ASSERT_EQ(da->GetNumberOfValues(), db->GetNumberOfValues());
  const std::size_t bytes = sizeof(float) * static_cast<std::size_t>(da->GetNumberOfValues());
  EXPECT_EQ(std::memcmp(da->GetPointer(0), db->GetPointer(0), bytes), 0);
  EXPECT_NE(std::memcmp(da->GetPointer(0), dc->GetPointer(0), bytes), 0);
  EXPECT_EQ(a->GetMetaballs()->GetNumberOfPoints(), b->GetMetaballs()->GetNumberOfPoints());
}

TEST(MetaballCloudSource, DensityIsNonNegativeAndBounded)
{
  vtkNew<vtkNimbusMetaballCloudSource> source;
  MakeSmall(source);
  source->Update();
  // f <= 1, so the density never exceeds the sum of the balls' centre densities.
  vtkDataArray* ballDensity = source->GetMetaballs()->GetPointData()->GetArray("density");
  double bound = 0.0;
  for (vtkIdType i = 0; i < ballDensity->GetNumberOfTuples(); ++i)
  {
    bound += ballDensity->GetTuple1(i);
  }
  vtkFloatArray* density = Density(source);
  for (vtkIdType i = 0; i < density->GetNumberOfValues(); ++i)
  {
    const float value = density->GetValue(i);
    ASSERT_TRUE(std::isfinite(value));
    ASSERT_GE(value, 0.0f);
    ASSERT_LE(value, bound);
  }
}

TEST(MetaballCloudSource, EachGrowthLevelIncreasesIsosurfaceArea)
{
  double previousArea = 0.0;
  int previousBalls = 0;
  for (int levels = 0; levels <= 3; ++levels)
  {
    vtkNew<vtkNimbusMetaballCloudSource> source;
    source->SetDimensions(72, 72, 48);
    source->SetNumberOfLevels(levels);
    source->Update();
    const double area = IsosurfaceArea(source->GetOutput(), source->GetIsoValue());
    const int balls = static_cast<int>(source->GetMetaballs()->GetNumberOfPoints());
    EXPECT_GT(area, previousArea) << "levels " << levels;
    EXPECT_GT(balls, previousBalls) << "levels " << levels;
    std::cout << "levels " << levels << ": " << balls << " balls, isosurface area " << area
              << " m^2\n";
    previousArea = area;
    previousBalls = balls;
  }
}

TEST(MetaballCloudSource, NoDensityBelowTheBase)
{
  vtkNew<vtkNimbusMetaballCloudSource> source;
  MakeSmall(source);
  source->SetBounds(-1500, 1500, -1500, 1500, 500, 2500);
  source->SetBaseHeight(1000.0);
  source->Update();
  vtkImageData* image = source->GetOutput();
  vtkFloatArray* density = Density(source);
  double maxBelow = 0.0, maxAbove = 0.0;
  for (vtkIdType id = 0; id < image->GetNumberOfPoints(); ++id)
  {
    double p[3];
    image->GetPoint(id, p);
    double& maximum = p[2] <= 1000.0 ? maxBelow : maxAbove;
    maximum = std::max(maximum, static_cast<double>(density->GetValue(id)));
  }
  EXPECT_EQ(maxBelow, 0.0);
  EXPECT_GT(maxAbove, 0.5);

  // Without the flat-base fade the normal-limited growth alone keeps almost all of
  // the mass above the base: the basic shape's balls reach at most R/2 below it.
  // Measured 0.25 % for the default seed; 1 % leaves room for other seeds.
  source->FlatBaseOff();
  source->Update();
  double massBelow = 0.0, massTotal = 0.0;
  for (vtkIdType id = 0; id < image->GetNumberOfPoints(); ++id)
  {
    double p[3];
    source->GetOutput()->GetPoint(id, p);
    const double value = Density(source)->GetValue(id);
    massTotal += value;
    massBelow += p[2] < 1000.0 ? value : 0.0;
  }
  std::cout << "without the fade, " << 100.0 * massBelow / massTotal
            << " % of the density lies below the base\n";
  EXPECT_LT(massBelow, 0.01 * massTotal);
}

TEST(MetaballCloudSource, UserBallsReplaceTheRandomShape)
{
  vtkNew<vtkNimbusMetaballCloudSource> source;
  MakeSmall(source);
  source->SetNumberOfLevels(0);
  source->FlatBaseOff();
  source->AddBall(0.0, 0.0, 1800.0, 500.0, 2.0);
  EXPECT_EQ(source->GetNumberOfUserBalls(), 1);
  source->Update();
  EXPECT_EQ(source->GetMetaballs()->GetNumberOfPoints(), 1);
  // The grid point nearest the centre: density 2 * f(distance).
  vtkImageData* image = source->GetOutput();
  double centre[3] = { 0.0, 0.0, 1800.0 };
  const vtkIdType id = image->FindPoint(centre);
  double p[3];
  image->GetPoint(id, p);
  const double d2 = p[0] * p[0] + p[1] * p[1] + (p[2] - 1800.0) * (p[2] - 1800.0);
  EXPECT_NEAR(Density(source)->GetValue(id), 2.0 * nimbus::WyvillFalloff(d2, 500.0 * 500.0), 1e-5);
  source->RemoveAllBalls();
  EXPECT_EQ(source->GetNumberOfUserBalls(), 0);
}

TEST(MetaballCloudSource, ReportsProgress)
{
  vtkNew<vtkNimbusMetaballCloudSource> source;
  MakeSmall(source);
  source->SetNumberOfLevels(3);
  std::vector<double> progress;
  vtkNew<vtkCallbackCommand> callback;
  callback->SetClientData(&progress);
  callback->SetCallback([](vtkObject*, unsigned long, void* clientData, void* callData)
    { static_cast<std::vector<double>*>(clientData)->push_back(*static_cast<double*>(callData)); });
  source->AddObserver(vtkCommand::ProgressEvent, callback);
  source->Update();
  // One report per growth level, one for the final sampling, and the end.
  ASSERT_GE(progress.size(), 5u);
  EXPECT_TRUE(std::is_sorted(progress.begin(), progress.end()));
  EXPECT_EQ(progress.back(), 1.0);
}

TEST(MetaballCloudSource, OneVoxelVolume)
{
  vtkNew<vtkNimbusMetaballCloudSource> source;
  MessageCatcher messages(source);
  source->SetDimensions(1, 1, 1);
  source->Update();
  EXPECT_TRUE(messages.Errors.empty());
  EXPECT_EQ(source->GetOutput()->GetNumberOfPoints(), 1);
  EXPECT_TRUE(std::isfinite(Density(source)->GetValue(0)));
}

// Bad parameters: an error naming the problem, empty outputs, no crash.
struct BadParameterCase
{
  const char* Name;
  void (*Apply)(vtkNimbusMetaballCloudSource*);
  const char* ExpectedText;
};

// Names the case in test listings (instead of gtest's byte dump).
void PrintTo(const BadParameterCase& badCase, std::ostream* os)
{
  *os << badCase.Name;
}

class MetaballCloudSourceBadParameters : public ::testing::TestWithParam<BadParameterCase>
{
};

TEST_P(MetaballCloudSourceBadParameters, ReportsAnErrorAndOutputsNothing)
{
  const BadParameterCase& badCase = GetParam();
  vtkNew<vtkNimbusMetaballCloudSource> source;
  MakeSmall(source);
  MessageCatcher messages(source);
  badCase.Apply(source);
  source->Update();
  ASSERT_EQ(messages.Errors.size(), 1u) << badCase.Name;
  EXPECT_NE(messages.Errors[0].find(badCase.ExpectedText), std::string::npos)
    << "message was: " << messages.Errors[0];
  EXPECT_EQ(source->GetOutput()->GetNumberOfPoints(), 0);
  EXPECT_EQ(source->GetMetaballs()->GetNumberOfPoints(), 0);

  // Fixing the parameter recovers: nothing was left corrupted.
  vtkNew<vtkNimbusMetaballCloudSource> fresh;
  MakeSmall(fresh);
  fresh->Update();
  EXPECT_GT(fresh->GetOutput()->GetNumberOfPoints(), 0);
}

const double NaN = std::numeric_limits<double>::quiet_NaN();
const double Inf = std::numeric_limits<double>::infinity();

INSTANTIATE_TEST_SUITE_P(Cases, MetaballCloudSourceBadParameters,
  ::testing::Values(
    BadParameterCase{ "zero dimension",
      [](vtkNimbusMetaballCloudSource* s) { s->SetDimensions(0, 10, 10); }, "Dimensions" },
    BadParameterCase{ "negative dimension",
      [](vtkNimbusMetaballCloudSource* s) { s->SetDimensions(10, -3, 10); }, "Dimensions" },
    BadParameterCase{ "zero balls",
      [](vtkNimbusMetaballCloudSource* s) { s->SetNumberOfBaseBalls(0); }, "No balls" },
    BadParameterCase{ "NaN bounds",
      [](vtkNimbusMetaballCloudSource* s) { s->SetBounds(0, NaN, 0, 1, 0, 1); }, "Bounds" },
    BadParameterCase{ "empty bounds",
      [](vtkNimbusMetaballCloudSource* s) { s->SetBounds(0, 1, 5, 5, 0, 1); }, "Bounds" },
    BadParameterCase{
      "NaN iso-value", [](vtkNimbusMetaballCloudSource* s) { s->SetIsoValue(NaN); }, "NaN" },
    BadParameterCase{ "infinite density",
      [](vtkNimbusMetaballCloudSource* s) { s->SetBallDensity(Inf); }, "NaN or infinite" },
    BadParameterCase{ "non-positive radius",
      [](vtkNimbusMetaballCloudSource* s) { s->SetBaseBallRadiusRange(0.0, 100.0); },
      "BaseBallRadiusRange" },
    BadParameterCase{ "NaN user ball",
      [](vtkNimbusMetaballCloudSource* s) { s->AddBall(0, 0, NaN, 100, 1); }, "AddBall" },
    BadParameterCase{ "negative levels",
      [](vtkNimbusMetaballCloudSource* s) { s->SetNumberOfLevels(-1); }, "NumberOfLevels" },
    // The reported cases: exceptions escaped RequestData, NaN/Inf came out, work ran on.
    BadParameterCase{ "3000 cubed points",
      [](vtkNimbusMetaballCloudSource* s) { s->SetDimensions(3000, 3000, 3000); },
      "memory budget" },
    BadParameterCase{ "INT_MAX cubed points",
      [](vtkNimbusMetaballCloudSource* s) { s->SetDimensions(2147483647, 2147483647, 2147483647); },
      "64 bits" },
    BadParameterCase{ "INT_MAX points along x",
      [](vtkNimbusMetaballCloudSource* s) { s->SetDimensions(2147483647, 48, 32); },
      "memory budget" },
    BadParameterCase{ "density 1e308",
      [](vtkNimbusMetaballCloudSource* s) { s->SetBallDensity(1e308); }, "BallDensity" },
    BadParameterCase{ "1000 levels",
      [](vtkNimbusMetaballCloudSource* s) { s->SetNumberOfLevels(1000); }, "NumberOfLevels" },
    BadParameterCase{ "too many balls",
      [](vtkNimbusMetaballCloudSource* s)
      {
        s->SetNumberOfLevels(30);
        s->SetBallCountFactor(3.0);
      },
      "metaballs or more" },
    BadParameterCase{ "too much work",
      [](vtkNimbusMetaballCloudSource* s)
      {
        s->SetDimensions(600, 600, 600);
        s->SetNumberOfLevels(40);
        s->SetBallCountFactor(1.0);
        s->SetRadiusScalePerLevel(1.0);
      },
      "updates" },
    BadParameterCase{ "radii growing with level",
      [](vtkNimbusMetaballCloudSource* s) { s->SetRadiusScalePerLevel(2.0); },
      "RadiusScalePerLevel" },
    BadParameterCase{ "bounds of 1e300 m",
      [](vtkNimbusMetaballCloudSource* s) { s->SetBounds(-1e300, 1e300, 0, 1, 0, 1); }, "Bounds" },
    BadParameterCase{ "NaN memory budget",
      [](vtkNimbusMetaballCloudSource* s) { s->SetMemoryBudgetMiB(NaN); }, "MemoryBudgetMiB" },
    BadParameterCase{ "tiny memory budget",
      [](vtkNimbusMetaballCloudSource* s) { s->SetMemoryBudgetMiB(0.01); }, "memory budget" }),
  [](const ::testing::TestParamInfo<BadParameterCase>& info)
  {
    std::string name = info.param.Name;
    for (char& c : name)
    {
      c = std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
    }
    return name;
  });

TEST(MetaballCloudSource, DefaultMemoryBudgetIsTheMachines)
{
  vtkNew<vtkNimbusMetaballCloudSource> source;
  EXPECT_EQ(source->GetMemoryBudgetMiB(), nimbus::DefaultMemoryBudgetMiB());
  EXPECT_GT(source->GetMemoryBudgetMiB(), 0.0);
}

TEST(MetaballCloudSource, TinyAndHugeGridsStayFinite)
{
  // Spacing of about 1e-299 m; the random shape's balls lie far outside the grid.
  vtkNew<vtkNimbusMetaballCloudSource> source;
  MessageCatcher messages(source);
  source->SetDimensions(8, 8, 8);
  source->SetBounds(0, 1e-298, 0, 1e-298, 0, 1e-298);
  source->SetNumberOfLevels(1);
  source->FlatBaseOff();
  source->AddBall(0, 0, 0, 1e-298, 1); // its squared radius underflows to 0: no density
  source->Update();
  EXPECT_TRUE(messages.Errors.empty()) << messages.AllErrors();
  ASSERT_EQ(source->GetOutput()->GetNumberOfPoints(), 512);
  for (vtkIdType i = 0; i < 512; ++i)
  {
    ASSERT_TRUE(std::isfinite(Density(source)->GetValue(i)) && Density(source)->GetValue(i) >= 0);
  }
}

TEST(WyvillFalloff, NeverNegativeJustInsideTheRadius)
{
  // Rounding made the polynomial -2.2e-16 just inside R (for 3 in 4 of the 100000 squared
  // distances below 9 m^2 tried here, before the clamp); densities must not be negative.
  for (const double r2 : { 1.0, 9.0, 250000.0, 360000.0 })
  {
    double d2 = r2;
    for (int k = 0; k < 100000; ++k)
    {
      d2 = std::nextafter(d2, 0.0);
      ASSERT_GE(nimbus::WyvillFalloff(d2, r2), 0.0) << "d2 = " << d2 << ", r2 = " << r2;
    }
  }
}
