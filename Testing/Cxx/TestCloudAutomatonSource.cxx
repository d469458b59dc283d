// Data tests of vtkNimbusCloudAutomatonSource: time steps advertised, the output equals the
// core automaton's smoothed field at each step and its linear interpolation between steps,
// the same bytes whatever order times are requested in, checkpoints are used, probability
// maps from an input image shape where clouds form, and bad input gives clear errors.
#include "CloudAutomaton.h"
#include "vtkNimbusCloudAutomatonSource.h"

#include "vtkDataArray.h"
#include "vtkFieldData.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkStreamingDemandDrivenPipeline.h"

#include "MessageCatcher.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iostream>
#include <string>
#include <vector>

namespace
{
using nimbus::testing::MessageCatcher;

void Configure(vtkNimbusCloudAutomatonSource* source)
{
  source->SetDimensions(40, 36, 12);
  source->SetBounds(0, 3900, 0, 3500, 1000, 2100); // 100 m cells
  source->SetSeed(5);
  source->SetStepDuration(2.0);
  source->SetNumberOfTimeSteps(60);
  source->SetWind(30.0, -10.0); // 0.6 and -0.2 cells per step
  source->SetShear(0.05, 0.0);  // +0.1 cell/step per layer
  source->SetCheckpointInterval(8);
  // The mechanics below are checked against the core with uniform probabilities and no
  // spin-up (the defaults' formation regions and spin-up have their own tests).
  source->SetNumberOfFormationRegions(0);
  source->SetSpinUpSteps(0);
  source->SetPeriodicBoundary(true);
  source->SetExtinctionProbability(0.05);
  source->SetHumidityProbability(0.002);
  source->SetActivationProbability(0.0002);
  source->SetInitialHumidity(0.3);
  source->SetInitialActivation(0.001);
}

std::vector<float> DensityAt(vtkNimbusCloudAutomatonSource* source, double time)
{
  source->UpdateTimeStep(time);
  auto* array =
    vtkFloatArray::SafeDownCast(source->GetOutput()->GetPointData()->GetArray("density"));
  if (!array)
  {
    return {};
  }
  return std::vector<float>(
    array->GetPointer(0), array->GetPointer(0) + array->GetNumberOfTuples());
}

// The same run through the core, for comparison.
nimbus::CloudAutomatonParameters CoreParameters()
{
  nimbus::CloudAutomatonParameters p;
  p.Dimensions[0] = 40;
  p.Dimensions[1] = 36;
  p.Dimensions[2] = 12;
  p.Seed = 5;
  p.Extinction = nimbus::ProbabilityField::Uniform(0.05);
  p.HumiditySupply = nimbus::ProbabilityField::Uniform(0.002);
  p.ActivationSupply = nimbus::ProbabilityField::Uniform(0.0002);
  p.InitialHumidity = 0.3;
  p.InitialActivation = 0.001;
  p.Wind[0] = 30.0 * 2.0 / 100.0;
  p.Wind[1] = -10.0 * 2.0 / 100.0;
  p.Shear[0] = 0.05 * 100.0 * 2.0 / 100.0;
  p.Boundary = nimbus::CloudBoundary::Periodic;
  return p;
}
}

TEST(CloudAutomatonSource, AdvertisesTimeStepsAndGeometry)
{
  vtkNew<vtkNimbusCloudAutomatonSource> source;
  Configure(source);
  source->UpdateInformation();
  vtkInformation* info = source->GetOutputInformation(0);
  ASSERT_TRUE(info->Has(vtkStreamingDemandDrivenPipeline::TIME_STEPS()));
  ASSERT_EQ(info->Length(vtkStreamingDemandDrivenPipeline::TIME_STEPS()), 61);
  const double* times = info->Get(vtkStreamingDemandDrivenPipeline::TIME_STEPS());
  EXPECT_EQ(times[0], 0.0);
  EXPECT_EQ(times[60], 120.0);
  EXPECT_EQ(times[7], 14.0);
  const double* range = info->Get(vtkStreamingDemandDrivenPipeline::TIME_RANGE());
  EXPECT_EQ(range[0], 0.0);
  EXPECT_EQ(range[1], 120.0);
  source->UpdateTimeStep(0.0);
  vtkImageData* image = source->GetOutput();
  int dims[3];
  image->GetDimensions(dims);
  EXPECT_EQ(dims[0], 40);
  EXPECT_EQ(dims[2], 12);
  double spacing[3];
  image->GetSpacing(spacing);
  EXPECT_DOUBLE_EQ(spacing[0], 100.0);
  EXPECT_DOUBLE_EQ(spacing[2], 100.0);
}

TEST(CloudAutomatonSource, MatchesTheCoreAtStepsAndInterpolatesBetween)
{
  vtkNew<vtkNimbusCloudAutomatonSource> source;
  Configure(source);
  source->SetNumberOfThreads(2);
  nimbus::CloudAutomaton core(CoreParameters());
  std::vector<float> expected, next, mixed;
  for (const int step : { 0, 5, 17 })
  {
    core.StepTo(step);
    nimbus::SmoothCloud(core, nimbus::CloudSmoothingParameters(), expected);
    EXPECT_EQ(DensityAt(source, 2.0 * step), expected) << "step " << step;
    EXPECT_DOUBLE_EQ(
      source->GetOutput()->GetFieldData()->GetArray("AutomatonStep")->GetComponent(0, 0), step);
  }
  // t = 17.25 steps: a quarter of the way from step 17 to 18.
  nimbus::CloudAutomaton later(CoreParameters());
  later.StepTo(18);
  nimbus::SmoothCloud(later, nimbus::CloudSmoothingParameters(), next);
  nimbus::InterpolateDensity(expected, next, 0.25, mixed);
  const std::vector<float> got = DensityAt(source, 2.0 * 17.25);
  ASSERT_EQ(got.size(), mixed.size());
  double cloud = 0.0;
  for (std::size_t i = 0; i < got.size(); ++i)
  {
    ASSERT_FLOAT_EQ(got[i], mixed[i]);
    cloud += got[i];
  }
  EXPECT_GT(cloud, 1.0); // there is cloud to compare
  // InterpolateInTime off: the step at or before the time.
  source->InterpolateInTimeOff();
  EXPECT_EQ(DensityAt(source, 2.0 * 17.25), expected);
}

TEST(CloudAutomatonSource, SameOutputWhateverTheRequestOrder)
{
  const double times[] = { 0.0, 33.0, 12.5, 119.0, 47.3, 12.5, 2.0, 120.0, 500.0, -3.0 };
  // Reference: a fresh source per time (always from step 0).
  std::vector<std::vector<float>> reference;
  for (const double t : times)
  {
    vtkNew<vtkNimbusCloudAutomatonSource> fresh;
    Configure(fresh);
    reference.push_back(DensityAt(fresh, t));
  }
  // One source, times in the order above (backwards jumps use checkpoints), then reversed,
  // with a different number of threads.
  vtkNew<vtkNimbusCloudAutomatonSource> source;
  Configure(source);
  source->SetNumberOfThreads(1);
  for (std::size_t i = 0; i < reference.size(); ++i)
  {
    EXPECT_EQ(DensityAt(source, times[i]), reference[i]) << "t = " << times[i];
  }
  vtkNew<vtkNimbusCloudAutomatonSource> reversed;
  Configure(reversed);
  reversed->SetNumberOfThreads(3);
  for (std::size_t i = reference.size(); i-- > 0;)
  {
    EXPECT_EQ(DensityAt(reversed, times[i]), reference[i]) << "t = " << times[i];
  }
  // Tiny caches: no checkpoints at all (every backwards jump restarts from step 0), and a
  // checkpoint every step thinned to 3 (the eviction path), give the same bytes.
  for (const int maximum : { 0, 3 })
  {
    vtkNew<vtkNimbusCloudAutomatonSource> small;
    Configure(small);
    small->SetCheckpointInterval(1);
    small->SetMaximumNumberOfCheckpoints(maximum);
    for (std::size_t i = 0; i < reference.size(); ++i)
    {
      EXPECT_EQ(DensityAt(small, times[i]), reference[i])
        << "t = " << times[i] << ", at most " << maximum << " checkpoints";
    }
  }
  // Out-of-range times clamp to the advertised range.
  EXPECT_EQ(reference[8], reference[7]); // 500 s -> 120 s
  EXPECT_EQ(reference[9], reference[0]); // -3 s -> 0 s
}

TEST(CloudAutomatonSource, ComputesIncrementallyFromCachedStates)
{
  vtkNew<vtkNimbusCloudAutomatonSource> source;
  Configure(source);
  MessageCatcher catcher(source);
  DensityAt(source, 2.0 * 40);
  EXPECT_EQ(source->GetNumberOfStepsComputed(), 40);
  EXPECT_GT(catcher.ProgressEvents, 10); // progress while stepping
  DensityAt(source, 2.0 * 41);           // one more step
  EXPECT_EQ(source->GetNumberOfStepsComputed(), 41);
  DensityAt(source, 2.0 * 41.5); // needs step 42 only
  EXPECT_EQ(source->GetNumberOfStepsComputed(), 42);
  DensityAt(source, 2.0 * 41.0); // cached
  EXPECT_EQ(source->GetNumberOfStepsComputed(), 42);
  DensityAt(source, 2.0 * 19); // back: from the checkpoint at 16, 3 steps
  EXPECT_EQ(source->GetNumberOfStepsComputed(), 45);
  DensityAt(source, 2.0 * 3); // before any checkpoint: from step 0
  EXPECT_EQ(source->GetNumberOfStepsComputed(), 48);
  // A parameter change resets the cache.
  source->SetExtinctionProbability(0.1);
  DensityAt(source, 2.0 * 4);
  EXPECT_EQ(source->GetNumberOfStepsComputed(), 4);
  EXPECT_TRUE(catcher.Errors.empty());
}

TEST(CloudAutomatonSource, InputMapsShapeWhereCloudsForm)
{
  // A 2-D map: supply of vapour and activation only in a disc of radius 10 cells; no
  // vapour at the start. Clouds then stay within the disc plus the smoothing radius.
  vtkNew<vtkImageData> map;
  map->SetDimensions(40, 36, 1);
  vtkNew<vtkFloatArray> pHum, pAct;
  pHum->SetName("p_hum");
  pAct->SetName("p_act");
  for (int y = 0; y < 36; ++y)
  {
    for (int x = 0; x < 40; ++x)
    {
      const bool inside = std::hypot(x - 20.0, y - 18.0) < 10.0;
      pHum->InsertNextValue(inside ? 0.05f : 0.0f);
      pAct->InsertNextValue(inside ? 0.01f : 0.0f);
    }
  }
  map->GetPointData()->AddArray(pHum);
  map->GetPointData()->AddArray(pAct);
  vtkNew<vtkNimbusCloudAutomatonSource> source;
  Configure(source);
  source->SetWind(0.0, 0.0);
  source->SetShear(0.0, 0.0);
  source->SetInitialHumidity(0.0);
  source->SetInitialActivation(0.0);
  source->SetInputData(map);
  const std::vector<float> density = DensityAt(source, 2.0 * 30);
  ASSERT_EQ(density.size(), 40u * 36 * 12);
  double inside = 0.0, outside = 0.0;
  for (int z = 0; z < 12; ++z)
    for (int y = 0; y < 36; ++y)
      for (int x = 0; x < 40; ++x)
      {
        const double r = std::hypot(x - 20.0, y - 18.0);
        const float d = density[x + 40 * (y + 36 * z)];
        if (r < 8.0)
          inside += d;
        else if (r >= 10.0 + 2.0 * std::sqrt(2.0)) // beyond the disc and the kernel's
                                                   // reach (|dx|, |dy| <= 2)
          outside += d;
      }
  EXPECT_GT(inside, 100.0);
  EXPECT_EQ(outside, 0.0);
}

TEST(CloudAutomatonSource, BadInputGivesClearErrors)
{
  vtkNew<vtkNimbusCloudAutomatonSource> source;
  Configure(source);
  MessageCatcher catcher(source);
  vtkNew<vtkImageData> wrong;
  wrong->SetDimensions(10, 10, 1);
  vtkNew<vtkFloatArray> p;
  p->SetName("p_ext");
  p->SetNumberOfTuples(100);
  p->FillValue(0.1f);
  wrong->GetPointData()->AddArray(p);
  source->SetInputData(wrong);
  EXPECT_TRUE(DensityAt(source, 0.0).empty());
  ASSERT_EQ(catcher.Errors.size(), 1u);
  EXPECT_NE(catcher.Errors[0].find("40 x 36"), std::string::npos) << catcher.Errors[0];

  vtkNew<vtkImageData> outOfRange;
  outOfRange->SetDimensions(40, 36, 1);
  vtkNew<vtkFloatArray> q;
  q->SetName("p_act");
  q->SetNumberOfTuples(40 * 36);
  q->FillValue(255.0f); // an 8-bit image given as is
  outOfRange->GetPointData()->AddArray(q);
  source->SetInputData(outOfRange);
  EXPECT_TRUE(DensityAt(source, 0.0).empty());
  ASSERT_EQ(catcher.Errors.size(), 2u);
  EXPECT_NE(catcher.Errors[1].find("ActivationSupply"), std::string::npos) << catcher.Errors[1];
  EXPECT_NE(catcher.Errors[1].find("255"), std::string::npos) << catcher.Errors[1];

  source->SetInputData(nullptr);
  source->SetStepDuration(0.0);
  source->Update();
  ASSERT_EQ(catcher.Errors.size(), 3u);
  EXPECT_NE(catcher.Errors[2].find("StepDuration"), std::string::npos);
  EXPECT_EQ(source->GetOutput()->GetNumberOfPoints(), 0);

  source->SetStepDuration(1.0);
  source->SetDimensions(0, 5, 5);
  source->Update();
  ASSERT_EQ(catcher.Errors.size(), 4u);
  EXPECT_NE(catcher.Errors[3].find("Dimensions"), std::string::npos);

  // Extremes run: one cell, probabilities 1.
  source->SetDimensions(1, 1, 1);
  source->SetExtinctionProbability(1.0);
  source->SetHumidityProbability(1.0);
  source->SetActivationProbability(1.0);
  const std::vector<float> one = DensityAt(source, 7.5);
  ASSERT_EQ(one.size(), 1u);
  EXPECT_TRUE(std::isfinite(one[0]));
  EXPECT_EQ(catcher.Errors.size(), 4u);
}

TEST(CloudAutomatonSource, ExtremeParametersAreRefusedWithMessages)
{
  const double NaN = std::nan("");
  const double Inf = HUGE_VAL;
  struct Case
  {
    const char* Name;
    void (*Apply)(vtkNimbusCloudAutomatonSource*);
    const char* Expected;
    // Refused by the setter at once (the previous value kept, so the run then succeeds)
    // rather than by the run.
    bool BySetter = false;
  };
  static double nan, inf;
  nan = NaN;
  inf = Inf;
  const Case cases[] = {
    // Escaped RequestData as std::invalid_argument (the smoothing's check) once; refused by
    // the setters now.
    { "SmoothingRadius NaN", [](vtkNimbusCloudAutomatonSource* s) { s->SetSmoothingRadius(nan); },
      "SetSmoothingRadius(nan)", true },
    // Clamped silently to 1 once; refused by the setter now.
    { "ExtinctionProbability +Inf",
      [](vtkNimbusCloudAutomatonSource* s) { s->SetExtinctionProbability(inf); },
      "SetExtinctionProbability(inf)", true },
    { "InitialHumidity NaN", [](vtkNimbusCloudAutomatonSource* s) { s->SetInitialHumidity(nan); },
      "SetInitialHumidity(nan)", true },
    { "StepDuration 1e308", [](vtkNimbusCloudAutomatonSource* s) { s->SetStepDuration(1e308); },
      "StepDuration" },
    { "StepDuration 1e-300", [](vtkNimbusCloudAutomatonSource* s) { s->SetStepDuration(1e-300); },
      "StepDuration" },
    { "Wind 1e308 m/s", [](vtkNimbusCloudAutomatonSource* s) { s->SetWind(1e308, 0); },
      "cells per step" },
    { "Shear 1e6 (m/s)/m", [](vtkNimbusCloudAutomatonSource* s) { s->SetShear(0, 1e6); },
      "cells per step" },
    { "Bounds 1e300 m",
      [](vtkNimbusCloudAutomatonSource* s) { s->SetBounds(-1e300, 1e300, 0, 1000, 0, 1000); },
      "Bounds" },
    { "INT_MAX cells along x",
      [](vtkNimbusCloudAutomatonSource* s)
      {
        s->SetDimensions(2147483647, 36, 12);
        s->SetWind(0, 0);
        s->SetShear(0, 0);
      },
      "memory budget" },
    { "INT_MAX cubed cells",
      [](vtkNimbusCloudAutomatonSource* s)
      {
        s->SetDimensions(2147483647, 2147483647, 2147483647);
        s->SetWind(0, 0);
        s->SetShear(0, 0);
      },
      "64 bits" },
    { "tiny memory budget", [](vtkNimbusCloudAutomatonSource* s) { s->SetMemoryBudgetMiB(0.01); },
      "memory budget" },
    { "NaN memory budget", [](vtkNimbusCloudAutomatonSource* s) { s->SetMemoryBudgetMiB(nan); },
      "MemoryBudgetMiB" },
  };
  for (const Case& c : cases)
  {
    vtkNew<vtkNimbusCloudAutomatonSource> source;
    Configure(source);
    MessageCatcher catcher(source);
    c.Apply(source);
    EXPECT_EQ(catcher.Errors.size(), c.BySetter ? 1u : 0u) << c.Name << ": " << catcher.AllErrors();
    EXPECT_EQ(DensityAt(source, 10.0).empty(), !c.BySetter) << c.Name;
    ASSERT_EQ(catcher.Errors.size(), 1u) << c.Name << ": " << catcher.AllErrors();
    EXPECT_NE(catcher.Errors[0].find(c.Expected), std::string::npos)
      << c.Name << ": " << catcher.Errors[0];
  }
}

TEST(CloudAutomatonSource, AMillionStepsAreRefusedWithAnEstimate)
{
  // The default 128 x 128 x 32 grid at step 1e6 ran for many minutes before.
  vtkNew<vtkNimbusCloudAutomatonSource> source;
  source->SetNumberOfTimeSteps(1000000);
  source->SetStepDuration(1.0);
  source->SetSpinUpSteps(0);
  MessageCatcher catcher(source);
  const auto start = std::chrono::steady_clock::now();
  EXPECT_TRUE(DensityAt(source, 1.0e6).empty());
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 2.0);
  ASSERT_EQ(catcher.Errors.size(), 1u) << catcher.AllErrors();
  EXPECT_NE(catcher.Errors[0].find("cell updates"), std::string::npos) << catcher.Errors[0];
  EXPECT_NE(catcher.Errors[0].find("1000000"), std::string::npos) << catcher.Errors[0];
  // Nearby times still work, and the refusal left nothing broken.
  EXPECT_EQ(DensityAt(source, 3.0).size(), 128u * 128u * 32u);
  EXPECT_EQ(catcher.Errors.size(), 1u);
}

TEST(CloudAutomatonSource, BadInputMapValuesAreCounted)
{
  vtkNew<vtkNimbusCloudAutomatonSource> source;
  Configure(source);
  MessageCatcher catcher(source);
  vtkNew<vtkImageData> map;
  map->SetDimensions(40, 36, 1);
  vtkNew<vtkFloatArray> p;
  p->SetName("p_hum");
  p->SetNumberOfTuples(40 * 36);
  p->FillValue(0.01f);
  p->SetValue(3, std::nanf(""));
  p->SetValue(5, -0.5f);
  p->SetValue(7, HUGE_VALF);
  map->GetPointData()->AddArray(p);
  source->SetInputData(map);
  EXPECT_TRUE(DensityAt(source, 0.0).empty());
  ASSERT_EQ(catcher.Errors.size(), 1u);
  EXPECT_NE(catcher.Errors[0].find("1 NaN, 1 infinite and 1 negative"), std::string::npos)
    << catcher.Errors[0];
}

TEST(CloudAutomatonSource, FormationRegionWeightsAreGaussianEllipsoids)
{
  const int dims[3] = { 40, 30, 10 };
  nimbus::FormationRegion region;
  region.Center[0] = 2.0; // near the x = 0 face: wraps when periodic
  region.Center[1] = 15.0;
  region.Center[2] = 4.0;
  region.Radius[0] = 3.0;
  region.Radius[1] = 2.0;
  region.Radius[2] = 1.0;
  auto at = [&](const std::vector<float>& w, int x, int y, int z)
  { return w[x + dims[0] * (y + dims[1] * z)]; };
  const std::vector<float> open = nimbus::FormationRegionWeights(dims, { region }, false);
  const std::vector<float> periodic = nimbus::FormationRegionWeights(dims, { region }, true);
  EXPECT_FLOAT_EQ(at(open, 2, 15, 4), 1.0f);
  EXPECT_NEAR(at(open, 5, 15, 4), std::exp(-0.5), 1e-6);                   // one semi-axis along x
  EXPECT_NEAR(at(open, 2, 17, 4), std::exp(-0.5), 1e-6);                   // along y
  EXPECT_NEAR(at(open, 2, 15, 5), std::exp(-0.5), 1e-6);                   // along z
  EXPECT_EQ(at(open, 2, 15, 8), 0.0f);                                     // beyond 3 semi-axes
  EXPECT_EQ(at(open, 38, 15, 4), 0.0f);                                    // open: no wrap
  EXPECT_NEAR(at(periodic, 38, 15, 4), std::exp(-0.5 * 16.0 / 9.0), 1e-6); // 4 cells away
  // Random regions: deterministic per seed, inside the grid, radii in range.
  const double range[2] = { 3.0, 5.0 };
  const auto a = nimbus::RandomFormationRegions(dims, 4, range, 0.5, 3.0, 7);
  const auto b = nimbus::RandomFormationRegions(dims, 4, range, 0.5, 3.0, 7);
  const auto c = nimbus::RandomFormationRegions(dims, 4, range, 0.5, 3.0, 8);
  ASSERT_EQ(a.size(), 4u);
  for (std::size_t r = 0; r < a.size(); ++r)
  {
    EXPECT_EQ(a[r].Center[0], b[r].Center[0]);
    EXPECT_EQ(a[r].Center[1], b[r].Center[1]);
    EXPECT_GE(a[r].Center[0], 0.0);
    EXPECT_LT(a[r].Center[0], 40.0);
    EXPECT_GE(a[r].Radius[0], 3.0);
    EXPECT_LE(a[r].Radius[0], 5.0);
    EXPECT_DOUBLE_EQ(a[r].Radius[2], 0.5 * a[r].Radius[0]);
    EXPECT_DOUBLE_EQ(a[r].Center[2], 3.0);
  }
  EXPECT_NE(a[0].Center[0], c[0].Center[0]);
}

namespace
{
// Cloudy columns (vertical sum of density above `threshold` cells' worth) and their
// 4-connected groups on the periodic x-y grid.
struct Cover
{
  double Fraction = 0.0;
  int Groups = 0;
};

Cover MeasureCover(const std::vector<float>& density, int nx, int ny, int nz, double threshold)
{
  std::vector<int> cloudy(static_cast<std::size_t>(nx) * ny, 0);
  Cover cover;
  for (int y = 0; y < ny; ++y)
    for (int x = 0; x < nx; ++x)
    {
      double column = 0.0;
      for (int z = 0; z < nz; ++z)
        column += density[x + nx * (y + static_cast<std::size_t>(ny) * z)];
      if (column > threshold)
      {
        cloudy[x + nx * y] = 1;
        cover.Fraction += 1.0;
      }
    }
  cover.Fraction /= static_cast<double>(nx) * ny;
  std::vector<int> stack;
  for (int start = 0; start < nx * ny; ++start)
  {
    if (cloudy[start] != 1)
      continue;
    ++cover.Groups;
    stack.push_back(start);
    cloudy[start] = 2;
    while (!stack.empty())
    {
      const int i = stack.back();
      stack.pop_back();
      const int x = i % nx, y = i / nx;
      const int next[4] = { (x + 1) % nx + nx * y, (x + nx - 1) % nx + nx * y,
        x + nx * ((y + 1) % ny), x + nx * ((y + ny - 1) % ny) };
      for (const int j : next)
        if (cloudy[j] == 1)
        {
          cloudy[j] = 2;
          stack.push_back(j);
        }
    }
  }
  return cover;
}
}

TEST(CloudAutomatonSource, DefaultsGiveSeparateCumulusThatDrift)
{
  // The first Apply in ParaView: time 0 of the defaults. The earlier defaults (uniform
  // vapour 0.3, no regions, no wind) filled the whole box: every column cloudy, one group.
  vtkNew<vtkNimbusCloudAutomatonSource> source;
  const std::vector<float> first = DensityAt(source, 0.0);
  ASSERT_EQ(first.size(), 128u * 128u * 32u);
  EXPECT_DOUBLE_EQ(
    source->GetOutput()->GetFieldData()->GetArray("AutomatonStep")->GetComponent(0, 0), 40.0);
  const Cover cover = MeasureCover(first, 128, 128, 32, 1.0);
  std::cout << "defaults at t = 0: cloudy columns " << 100.0 * cover.Fraction << " %, "
            << cover.Groups << " separate clouds\n";
  EXPECT_GT(cover.Fraction, 0.03);
  EXPECT_LT(cover.Fraction, 0.35);
  EXPECT_GE(cover.Groups, 4);
  // Nothing touches the top of the box (no slab with a lid).
  double top = 0.0;
  for (int i = 0; i < 128 * 128; ++i)
    top = std::max(top, static_cast<double>(first[i + 128 * 128 * 31]));
  EXPECT_LT(top, 0.05);
  vtkNew<vtkNimbusCloudAutomatonSource> again;
  const std::vector<float> repeat = DensityAt(again, 0.0);
  EXPECT_EQ(repeat, first); // same seed, same clouds
  again->SetSeed(2);
  EXPECT_NE(DensityAt(again, 0.0), first);
  // Spin-up: time 0 with 40 spin-up steps is step 40 of the run without.
  vtkNew<vtkNimbusCloudAutomatonSource> noSpinUp;
  noSpinUp->SetSpinUpSteps(0);
  EXPECT_EQ(DensityAt(noSpinUp, 400.0), first);
}
