// vtkNimbusLightningIllumination: the lightning's in-scattered radiance in the
// cloud's field data, over time, linear in the sources, the disk cache (hit, miss,
// damaged file), the extremes (one-voxel cloud, a stroke outside the cloud, zero
// intensity, xi = 0 and xi = 1), and bad input of every kind refused with a message and
// the cloud passed through unlit.
#include "vtkNimbusLightningIllumination.h"
#include "vtkNimbusLightningSource.h"
#include "vtkNimbusMetaballCloudSource.h"

#include "MessageCatcher.h"

#include "vtkCellArray.h"
#include "vtkCellData.h"
#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkIntArray.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkStreamingDemandDrivenPipeline.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

namespace
{
using nimbus::testing::MessageCatcher;

std::string TemporaryDirectory(const std::string& name)
{
  const std::string path = ::testing::TempDir() + "nimbus-lightning-" + name;
  std::filesystem::remove_all(path);
  std::filesystem::create_directories(path);
  return path;
}

/// A small metaball cumulus (24 x 24 x 16 points over 3 x 3 x 2 km, base 1000 m).
vtkNew<vtkNimbusMetaballCloudSource> SmallCloud()
{
  vtkNew<vtkNimbusMetaballCloudSource> cloud;
  cloud->SetDimensions(24, 24, 16);
  cloud->SetSeed(3);
  return cloud;
}

/// The filter on `cloud` and `lightning` (port 1: point sources), cheap settings: a
/// 12 x 12 x 8 grid, lights 750 m apart, 14 directions, 8 orders.
vtkNew<vtkNimbusLightningIllumination> Filter(
  vtkAlgorithm* cloud, vtkAlgorithm* lightning, const std::string& cache)
{
  vtkNew<vtkNimbusLightningIllumination> f;
  f->SetInputConnection(0, cloud->GetOutputPort(0));
  if (lightning)
  {
    f->SetInputConnection(1, lightning->GetOutputPort(1));
  }
  f->SetDownsampling(2);
  f->SetLightSpacingMetres(750.0);
  f->SetNumberOfDirections(14);
  f->SetOrders(8);
  f->SetNumberOfThreads(2);
  f->SetCacheDirectory(cache.c_str());
  f->SetUseDiskCache(!cache.empty());
  return f;
}

vtkFloatArray* Field(vtkNimbusLightningIllumination* f)
{
  return vtkFloatArray::SafeDownCast(
    f->GetOutput()->GetFieldData()->GetAbstractArray("nimbus_lightning_in_scattering"));
}

std::vector<float> Values(vtkFloatArray* a)
{
  return a ? std::vector<float>(a->GetPointer(0), a->GetPointer(0) + a->GetNumberOfValues())
           : std::vector<float>();
}

double SumOfC00(const std::vector<float>& v)
{
  double sum = 0.0;
  for (std::size_t i = 0; i < v.size(); i += 12)
  {
    sum += v[i] + v[i + 4] + v[i + 8];
  }
  return sum;
}

bool AllFinite(const std::vector<float>& v)
{
  for (float x : v)
  {
    if (!std::isfinite(x))
    {
      return false;
    }
  }
  return true;
}
} // namespace

// The arrays as documented; dark before the flash, lit at the return stroke, dimmer at a
// subsequent stroke; the time steps are the lightning's.
TEST(LightningIllumination, FieldOverTime)
{
  auto cloud = SmallCloud();
  vtkNew<vtkNimbusLightningSource> lightning;
  auto f = Filter(cloud, lightning, "");
  MessageCatcher messages(f);
  f->UpdateInformation();
  vtkInformation* outInfo = f->GetOutputInformation(0);
  ASSERT_TRUE(outInfo->Has(vtkStreamingDemandDrivenPipeline::TIME_STEPS()));
  lightning->UpdateInformation();
  EXPECT_EQ(outInfo->Length(vtkStreamingDemandDrivenPipeline::TIME_STEPS()),
    lightning->GetOutputInformation(1)->Length(vtkStreamingDemandDrivenPipeline::TIME_STEPS()));

  f->UpdateTimeStep(0.0); // before the flash: no sources
  vtkFloatArray* field = Field(f);
  ASSERT_NE(field, nullptr) << messages.AllErrors();
  EXPECT_EQ(field->GetNumberOfComponents(), 12);
  auto* grid = vtkIntArray::SafeDownCast(
    f->GetOutput()->GetFieldData()->GetAbstractArray("nimbus_lightning_grid"));
  ASSERT_NE(grid, nullptr);
  ASSERT_EQ(grid->GetNumberOfValues(), 7);
  EXPECT_EQ(grid->GetValue(0), 12);
  EXPECT_EQ(grid->GetValue(2), 8);
  EXPECT_EQ(grid->GetValue(3), 2);
  EXPECT_EQ(grid->GetValue(6), 0);
  EXPECT_EQ(field->GetNumberOfTuples(), 12 * 12 * 8);
  EXPECT_EQ(SumOfC00(Values(field)), 0.0);
  EXPECT_GT(f->GetLastPrecomputeSeconds(), 0.0);
  EXPECT_GT(f->GetNumberOfVirtualLights(), 8);

  const double peak = lightning->GetFlashStartTime() + lightning->GetLeaderDuration();
  f->UpdateTimeStep(peak);
  const std::vector<float> atPeak = Values(Field(f));
  EXPECT_EQ(f->GetLastPrecomputeSeconds(), 0.0) << "the basis is kept between time steps";
  f->UpdateTimeStep(peak + lightning->GetInterstrokeInterval());
  const std::vector<float> second = Values(Field(f));
  EXPECT_GT(SumOfC00(atPeak), 0.0);
  EXPECT_GT(SumOfC00(second), 0.0);
  EXPECT_LT(SumOfC00(second), SumOfC00(atPeak)); // the main channel alone, 0.6 as bright
  EXPECT_TRUE(AllFinite(atPeak));
  EXPECT_TRUE(messages.Errors.empty()) << messages.AllErrors();
  // The cloud itself passes through.
  EXPECT_NE(f->GetOutput()->GetPointData()->GetArray("density"), nullptr);
}

// J is linear in the sources (003 Eq. 9): twice the intensity, twice the field; the
// strokes (port 0, split here into sources) light the cloud as the source's own point
// sources do.
TEST(LightningIllumination, LinearAndStrokesAsSources)
{
  auto cloud = SmallCloud();
  vtkNew<vtkNimbusLightningSource> lightning;
  auto f = Filter(cloud, lightning, "");
  f->Update();
  const std::vector<float> once = Values(Field(f));
  lightning->SetIntensity(2.0 * lightning->GetIntensity());
  f->Update();
  const std::vector<float> twice = Values(Field(f));
  ASSERT_EQ(once.size(), twice.size());
  double worst = 0.0, largest = 0.0;
  for (std::size_t i = 0; i < once.size(); ++i)
  {
    worst = std::max(worst, static_cast<double>(std::abs(twice[i] - 2.0f * once[i])));
    largest = std::max(largest, static_cast<double>(std::abs(twice[i])));
  }
  EXPECT_LT(worst, 1e-5 * largest);

  f->SetInputConnection(1, lightning->GetOutputPort(0));
  f->SetPointSourceSpacing(lightning->GetPointSourceSpacing());
  f->Update();
  const std::vector<float> fromStrokes = Values(Field(f));
  ASSERT_EQ(fromStrokes.size(), twice.size());
  EXPECT_NEAR(SumOfC00(fromStrokes), SumOfC00(twice), 1e-4 * SumOfC00(twice));
}

// The first scattering on the density's grid: its arrays (E and F per point of the
// density's grid, the layout and the colour), zero before the flash; from the strokes it is
// computed once per class of brightness and kept across the time steps that only scale
// it (a stroke's decay), and it follows their scale; off, the arrays are gone and the
// basis's field gains the first scattering back.
TEST(LightningIllumination, FirstScatteringOnTheDensityGrid)
{
  auto cloud = SmallCloud();
  vtkNew<vtkNimbusLightningSource> lightning;
  auto f = Filter(cloud, lightning, "");
  f->SetInputConnection(1, lightning->GetOutputPort(0)); // the strokes: grouped by brightness
  MessageCatcher messages(f);
  const double peak = lightning->GetFlashStartTime() + lightning->GetLeaderDuration();
  f->UpdateTimeStep(peak);
  const auto first = [&f]()
  {
    return vtkFloatArray::SafeDownCast(
      f->GetOutput()->GetFieldData()->GetAbstractArray("nimbus_lightning_first_scattering"));
  };
  ASSERT_NE(first(), nullptr) << messages.AllErrors();
  EXPECT_EQ(first()->GetNumberOfComponents(), 4);
  EXPECT_EQ(first()->GetNumberOfTuples(), 24 * 24 * 16); // the density's own grid
  auto* layout = vtkDoubleArray::SafeDownCast(
    f->GetOutput()->GetFieldData()->GetAbstractArray("nimbus_lightning_first_scattering_grid"));
  ASSERT_NE(layout, nullptr);
  ASSERT_EQ(layout->GetNumberOfValues(), 10);
  EXPECT_EQ(layout->GetValue(0), 24);
  EXPECT_EQ(layout->GetValue(3), 1);
  EXPECT_EQ(layout->GetValue(7), 0.85); // the default colour
  const std::vector<float> atPeak = Values(first());
  EXPECT_TRUE(AllFinite(atPeak));
  double e = 0.0;
  for (std::size_t i = 0; i < atPeak.size(); i += 4)
  {
    EXPECT_GE(atPeak[i], 0.0f);
    // |F| <= E: a net flux cannot exceed the light arriving.
    EXPECT_LE(
      std::hypot(atPeak[i + 1], atPeak[i + 2], atPeak[i + 3]), atPeak[i] * 1.0001f + 1e-30f);
    e += atPeak[i];
  }
  EXPECT_GT(e, 0.0);
  const int computed = f->GetFirstScatteringGroupsComputed();
  EXPECT_GE(computed, 1);
  // 4 ms later the return stroke has decayed by exp(-4/15): the same field, scaled.
  f->UpdateTimeStep(peak + 0.004);
  EXPECT_EQ(f->GetFirstScatteringGroupsComputed(), computed) << "kept, not computed again";
  const std::vector<float> later = Values(first());
  double eLater = 0.0;
  for (std::size_t i = 0; i < later.size(); i += 4)
  {
    eLater += later[i];
  }
  EXPECT_NEAR(eLater / e, std::exp(-0.004 / lightning->GetStrokeDecaySeconds()), 1e-4);
  // Off: no first-scattering arrays; the basis holds the first scattering again.
  const double withoutFirst = SumOfC00(Values(Field(f)));
  f->FirstScatteringOnDensityGridOff();
  f->UpdateTimeStep(peak + 0.004);
  EXPECT_EQ(first(), nullptr);
  EXPECT_GT(SumOfC00(Values(Field(f))), withoutFirst);
  EXPECT_TRUE(messages.Errors.empty()) << messages.AllErrors();
}

// The leader's steps: its reached set grows, so each step's group holds the last step's
// sources and a few more; the filter computes only those (extending the kept field), and
// the field is the one a filter without that history computes, to the merging of sources
// that share a grid point (a fresh computation merges them into one at their weighted
// centre; the extension computes the new ones apart).
TEST(LightningIllumination, LeaderStepsExtendTheKeptField)
{
  auto cloud = SmallCloud();
  vtkNew<vtkNimbusLightningSource> lightning;
  auto stepped = Filter(cloud, lightning, "");
  stepped->SetInputConnection(1, lightning->GetOutputPort(0));
  MessageCatcher messages(stepped);
  const double start = lightning->GetFlashStartTime();
  const double leader = lightning->GetLeaderDuration();
  for (int step = 1; step <= 6; ++step)
  {
    stepped->UpdateTimeStep(start + leader * step / 8.0);
  }
  EXPECT_GE(stepped->GetFirstScatteringGroupsExtended(), 4) << "the leader's steps extended";
  vtkNew<vtkNimbusLightningSource> sameLightning;
  auto fresh = Filter(cloud, sameLightning, "");
  fresh->SetInputConnection(1, sameLightning->GetOutputPort(0));
  fresh->UpdateTimeStep(start + leader * 6 / 8.0);
  EXPECT_EQ(fresh->GetFirstScatteringGroupsExtended(), 0);
  for (const char* name :
    { "nimbus_lightning_first_scattering", "nimbus_lightning_first_scattering_reduced" })
  {
    const auto get = [name](vtkNimbusLightningIllumination* f)
    {
      return Values(
        vtkFloatArray::SafeDownCast(f->GetOutput()->GetFieldData()->GetAbstractArray(name)));
    };
    const std::vector<float> a = get(stepped), b = get(fresh);
    ASSERT_EQ(a.size(), b.size()) << name;
    ASSERT_FALSE(a.empty()) << name;
    double sumA = 0.0, sumB = 0.0, largest = 0.0, worst = 0.0;
    for (std::size_t i = 0; i < a.size(); i += 4)
    {
      sumA += a[i];
      sumB += b[i];
      largest = std::max(largest, static_cast<double>(b[i]));
      worst = std::max(worst, std::abs(static_cast<double>(a[i]) - b[i]));
    }
    // Measured: the sums agree to 1.4e-3, and the points where a new source shares a grid
    // point with a kept one (merged into one source by a fresh computation, two here) to
    // 6.8 % of the brightest point.
    EXPECT_GT(sumB, 0.0) << name;
    EXPECT_NEAR(sumA / sumB, 1.0, 3e-3) << name;
    EXPECT_LT(worst, 0.1 * largest) << name;
  }
  EXPECT_TRUE(messages.Errors.empty()) << messages.AllErrors();
}

// The disk cache: a second filter reads the first one's basis (same field), other
// optics miss, a damaged file is replaced.
TEST(LightningIllumination, DiskCache)
{
  const std::string cache = TemporaryDirectory("cache");
  auto cloud = SmallCloud();
  vtkNew<vtkNimbusLightningSource> lightning;
  auto first = Filter(cloud, lightning, cache);
  first->Update();
  EXPECT_FALSE(first->GetLastBasisFromDisk());
  EXPECT_GT(first->GetLastPrecomputeSeconds(), 0.0);
  const std::string file = first->GetCacheFile();
  ASSERT_TRUE(std::filesystem::exists(file)) << file;
  EXPECT_EQ(file.rfind(cache, 0), 0u);

  auto second = Filter(cloud, lightning, cache);
  second->Update();
  EXPECT_TRUE(second->GetLastBasisFromDisk());
  EXPECT_EQ(second->GetLastPrecomputeSeconds(), 0.0);
  EXPECT_EQ(Values(Field(first)), Values(Field(second)));
  EXPECT_DOUBLE_EQ(first->GetBasisBytes(), second->GetBasisBytes());

  second->SetCloudG(0.8);
  second->Update();
  EXPECT_FALSE(second->GetLastBasisFromDisk());
  EXPECT_NE(second->GetCacheFile(), file);

  // Damaged: cut in half.
  const auto size = std::filesystem::file_size(file);
  std::filesystem::resize_file(file, size / 2);
  auto third = Filter(cloud, lightning, cache);
  MessageCatcher messages(third);
  third->Update();
  EXPECT_FALSE(third->GetLastBasisFromDisk());
  EXPECT_EQ(std::filesystem::file_size(file), size) << "rewritten";
  EXPECT_EQ(Values(Field(first)), Values(Field(third)));
  EXPECT_TRUE(messages.Errors.empty()) << messages.AllErrors();

  // An unwritable directory: a warning, the field still made.
  auto fourth = Filter(cloud, lightning, "/proc/nimbus-cannot-write-here");
  fourth->SetCloudG(0.7);
  MessageCatcher warnings(fourth);
  fourth->Update();
  EXPECT_NE(Field(fourth), nullptr);
  EXPECT_NE(warnings.AllWarnings().find("could not be cached"), std::string::npos)
    << warnings.AllWarnings();
  std::filesystem::remove_all(cache);
}

// The extremes give finite fields: a one-voxel cloud, a stroke far outside the cloud
// (dimmed, not brought close), zero intensity, xi = 0 and xi = 1, no lightning input.
TEST(LightningIllumination, Extremes)
{
  vtkNew<vtkImageData> voxel;
  voxel->SetDimensions(1, 1, 1);
  voxel->SetOrigin(0, 0, 1500);
  vtkNew<vtkFloatArray> one;
  one->SetName("density");
  one->InsertNextValue(1.0f);
  voxel->GetPointData()->SetScalars(one);
  vtkNew<vtkNimbusLightningSource> lightning;
  {
    vtkNew<vtkNimbusLightningIllumination> f;
    f->SetInputData(0, voxel);
    f->SetInputConnection(1, lightning->GetOutputPort(1));
    f->SetNumberOfDirections(14);
    f->SetUseDiskCache(false);
    MessageCatcher messages(f);
    f->Update();
    ASSERT_NE(Field(f), nullptr) << messages.AllErrors();
    EXPECT_EQ(Field(f)->GetNumberOfTuples(), 1);
    EXPECT_TRUE(AllFinite(Values(Field(f))));
  }

  auto cloud = SmallCloud();
  auto f = Filter(cloud, lightning, "");
  MessageCatcher messages(f);
  f->Update();
  const double near = SumOfC00(Values(Field(f)));
  // The same stroke 20 km east: far dimmer, though its sources land on the box's face.
  lightning->SetStartPoint(20000.0, 0.0, 2000.0);
  f->Update();
  const double far = SumOfC00(Values(Field(f)));
  EXPECT_GT(f->GetNumberOfSourcesOutside(), 0);
  EXPECT_GT(far, 0.0);
  EXPECT_LT(far, 0.05 * near) << "a stroke 20 km away lights the cloud";
  lightning->SetStartPoint(0.0, 0.0, 2000.0);
  lightning->SetIntensity(0.0);
  f->Update();
  EXPECT_EQ(SumOfC00(Values(Field(f))), 0.0);
  lightning->SetIntensity(100.0);
  for (double xi : { 0.0, 1.0 })
  {
    f->SetThreshold(xi);
    f->Update();
    EXPECT_TRUE(AllFinite(Values(Field(f)))) << xi;
    EXPECT_GT(SumOfC00(Values(Field(f))), 0.0) << xi; // xi = 1 keeps the ambient term
  }
  EXPECT_TRUE(messages.Errors.empty()) << messages.AllErrors();

  vtkNew<vtkNimbusLightningIllumination> alone;
  alone->SetInputConnection(0, cloud->GetOutputPort(0));
  alone->Update();
  EXPECT_EQ(Field(alone), nullptr);
  EXPECT_NE(alone->GetOutput()->GetPointData()->GetArray("density"), nullptr);
}

// Every kind of bad input ends in an error naming it and the cloud unlit (no lightning
// arrays), never a crash: densities with NaN, infinities or negatives at random places
// (40 clouds), no density array, sources with non-finite positions or intensities (40),
// sources without intensities, strokes without intensities, a bad colour, a tiny
// memory budget.
TEST(LightningIllumination, BadInputRefused)
{
  vtkNew<vtkNimbusLightningSource> lightning;
  lightning->Update();
  const auto expectRefused = [](vtkNimbusLightningIllumination* f, const char* words)
  {
    MessageCatcher messages(f);
    f->Modified();
    f->Update();
    EXPECT_EQ(Field(f), nullptr) << words;
    EXPECT_NE(messages.AllErrors().find(words), std::string::npos) << messages.AllErrors();
  };
  std::uint64_t state = 7;
  const auto next = [&state]()
  {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return state >> 33;
  };
  const float bad[3] = { std::numeric_limits<float>::quiet_NaN(),
    std::numeric_limits<float>::infinity(), -1.0f };
  for (int trial = 0; trial < 40; ++trial)
  {
    vtkNew<vtkImageData> image;
    image->SetDimensions(6, 5, 4);
    image->SetSpacing(200, 200, 200);
    image->SetOrigin(-500, -400, 1000);
    vtkNew<vtkFloatArray> density;
    density->SetName("density");
    density->SetNumberOfValues(120);
    for (vtkIdType i = 0; i < 120; ++i)
    {
      density->SetValue(i, 0.5f);
    }
    const int count = 1 + static_cast<int>(next() % 5);
    for (int k = 0; k < count; ++k)
    {
      density->SetValue(static_cast<vtkIdType>(next() % 120), bad[next() % 3]);
    }
    image->GetPointData()->SetScalars(density);
    vtkNew<vtkNimbusLightningIllumination> f;
    f->SetInputData(0, image);
    f->SetInputConnection(1, lightning->GetOutputPort(1));
    f->SetUseDiskCache(false);
    expectRefused(f, "negative, NaN or infinite");
  }

  auto cloud = SmallCloud();
  {
    vtkNew<vtkImageData> empty;
    empty->SetDimensions(4, 4, 4);
    vtkNew<vtkNimbusLightningIllumination> f;
    f->SetInputData(0, empty);
    f->SetInputConnection(1, lightning->GetOutputPort(1));
    expectRefused(f, "no density array");
  }
  const double badValues[3] = { std::nan(""), std::numeric_limits<double>::infinity(), -5.0 };
  for (int trial = 0; trial < 40; ++trial)
  {
    vtkNew<vtkPolyData> sources;
    vtkNew<vtkPoints> points;
    vtkNew<vtkFloatArray> intensity;
    intensity->SetName("intensity");
    for (int i = 0; i < 20; ++i)
    {
      points->InsertNextPoint(10.0 * i, 0.0, 1500.0);
      intensity->InsertNextValue(1.0f);
    }
    const vtkIdType which = static_cast<vtkIdType>(next() % 20);
    const double value = badValues[next() % 3];
    if (next() % 2 == 0)
    {
      intensity->SetValue(which, static_cast<float>(value));
    }
    else
    {
      points->SetPoint(which, value, 0.0, 1500.0);
      if (value == -5.0)
      {
        intensity->SetValue(which, -1.0f); // a negative position is fine; this is not
      }
    }
    sources->SetPoints(points);
    sources->GetPointData()->AddArray(intensity);
    auto f = Filter(cloud, nullptr, "");
    f->SetInputData(1, sources);
    expectRefused(f, "not finite or is negative");
  }
  {
    vtkNew<vtkPolyData> sources;
    vtkNew<vtkPoints> points;
    points->InsertNextPoint(0, 0, 1500);
    sources->SetPoints(points);
    auto f = Filter(cloud, nullptr, "");
    f->SetInputData(1, sources);
    expectRefused(f, "no point array \"intensity\"");
  }
  {
    vtkNew<vtkPolyData> strokes;
    vtkNew<vtkPoints> points;
    points->InsertNextPoint(0, 0, 1500);
    points->InsertNextPoint(0, 0, 500);
    vtkNew<vtkCellArray> lines;
    const vtkIdType ids[2] = { 0, 1 };
    lines->InsertNextCell(2, ids);
    strokes->SetPoints(points);
    strokes->SetLines(lines);
    auto f = Filter(cloud, nullptr, "");
    f->SetInputData(1, strokes);
    expectRefused(f, "no cell array \"intensity\"");
  }
  {
    auto f = Filter(cloud, lightning, "");
    f->SetLightningColor(1.0, std::nan(""), 1.0);
    expectRefused(f, "LightningColor");
  }
  {
    auto f = Filter(cloud, lightning, "");
    f->SetMemoryBudgetMiB(0.01);
    expectRefused(f, "budget");
  }
}
