// vtkNimbusLightningSource: the strokes and point sources it outputs, the flash over
// the advertised time steps, determinism for a seed, and bad input (an error, empty
// outputs, no exception).
#include "vtkNimbusLightningSource.h"

#include "vtkCallbackCommand.h"
#include "vtkCellData.h"
#include "vtkCommand.h"
#include "vtkDataArray.h"
#include "vtkInformation.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPolyData.h"
#include "vtkStreamingDemandDrivenPipeline.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <vector>

namespace
{
/// Sum over the strokes of per-metre intensity x segment length.
double StrokeEmission(vtkPolyData* strokes, const char* array = "intensity")
{
  vtkDataArray* intensity = strokes->GetCellData()->GetArray(array);
  double sum = 0.0;
  for (vtkIdType c = 0; c < strokes->GetNumberOfCells(); ++c)
  {
    double a[3], b[3];
    strokes->GetPoint(2 * c, a);
    strokes->GetPoint(2 * c + 1, b);
    sum += intensity->GetTuple1(c) *
      std::sqrt((b[0] - a[0]) * (b[0] - a[0]) + (b[1] - a[1]) * (b[1] - a[1]) +
        (b[2] - a[2]) * (b[2] - a[2]));
  }
  return sum;
}

double SourceEmission(vtkPolyData* sources)
{
  vtkDataArray* intensity = sources->GetPointData()->GetArray("intensity");
  double sum = 0.0;
  for (vtkIdType i = 0; intensity && i < intensity->GetNumberOfTuples(); ++i)
  {
    sum += intensity->GetTuple1(i);
  }
  return sum;
}

/// Collects the error messages of an algorithm (and keeps them off the console).
class ErrorCatcher
{
public:
  explicit ErrorCatcher(vtkObject* object)
  {
    this->Callback->SetClientData(this);
    this->Callback->SetCallback(
      [](vtkObject*, unsigned long, void* client, void* call)
      {
        static_cast<ErrorCatcher*>(client)->Messages +=
          std::string(call ? static_cast<const char*>(call) : "") + "\n";
      });
    object->AddObserver(vtkCommand::ErrorEvent, this->Callback);
  }
  std::string Messages;

private:
  vtkNew<vtkCallbackCommand> Callback;
};

void UpdateAt(vtkNimbusLightningSource* source, double time)
{
  source->UpdateInformation();
  source->UpdateTimeStep(time);
}
} // namespace

// Defaults: a branched channel from the seed to the ground, point sources carrying its
// emission, arrays named as documented; the return stroke's peak without a time.
TEST(LightningSource, OutputsAtThePeak)
{
  vtkNew<vtkNimbusLightningSource> source;
  source->Update();
  vtkPolyData* strokes = source->GetOutput(0);
  vtkPolyData* sources = vtkPolyData::SafeDownCast(source->GetOutputDataObject(1));
  ASSERT_GT(strokes->GetNumberOfCells(), 50);
  ASSERT_NE(strokes->GetCellData()->GetArray("depth"), nullptr);
  ASSERT_NE(strokes->GetCellData()->GetArray("peak_intensity"), nullptr);
  ASSERT_NE(strokes->GetPointData()->GetArray("path_length"), nullptr);
  double range[2];
  strokes->GetCellData()->GetArray("depth")->GetRange(range);
  EXPECT_GE(range[1], 1.0) << "the default flash should branch";
  double bounds[6];
  strokes->GetBounds(bounds);
  EXPECT_NEAR(bounds[4], 0.0, 1e-9) << "the main channel should reach the ground";
  EXPECT_LE(bounds[5], 2000.0 + 1e-9);
  const double emission = StrokeEmission(strokes);
  EXPECT_GT(emission, 0.0);
  EXPECT_NEAR(SourceEmission(sources), emission, 1e-6 * emission);
  // At the peak (no time requested) intensity = peak intensity.
  EXPECT_NEAR(emission, StrokeEmission(strokes, "peak_intensity"), 1e-6 * emission);
}

// Time: advertised steps cover the flash; dark before it; the same flash (geometry) at
// every time; strokes brighter at a return stroke than between strokes.
TEST(LightningSource, FlashOverTime)
{
  vtkNew<vtkNimbusLightningSource> source;
  source->UpdateInformation();
  vtkInformation* info = source->GetOutputInformation(0);
  ASSERT_TRUE(info->Has(vtkStreamingDemandDrivenPipeline::TIME_STEPS()));
  const int n = info->Length(vtkStreamingDemandDrivenPipeline::TIME_STEPS());
  EXPECT_EQ(n, 61 + source->GetNumberOfStrokes()); // the frames and every stroke's peak
  const double* steps = info->Get(vtkStreamingDemandDrivenPipeline::TIME_STEPS());
  EXPECT_EQ(steps[0], 0.0);
  EXPECT_GT(steps[n - 1],
    source->GetFlashStartTime() + source->GetLeaderDuration() +
      (source->GetNumberOfStrokes() - 1) * source->GetInterstrokeInterval());
  UpdateAt(source, 0.0);
  const vtkIdType cells = source->GetOutput(0)->GetNumberOfCells();
  EXPECT_EQ(StrokeEmission(source->GetOutput(0)), 0.0);
  EXPECT_EQ(vtkPolyData::SafeDownCast(source->GetOutputDataObject(1))->GetNumberOfPoints(), 0);
  const double stroke = source->GetFlashStartTime() + source->GetLeaderDuration();
  UpdateAt(source, stroke);
  const double peak = StrokeEmission(source->GetOutput(0));
  EXPECT_EQ(source->GetOutput(0)->GetNumberOfCells(), cells);
  UpdateAt(source, stroke + 0.5 * source->GetInterstrokeInterval());
  const double between = StrokeEmission(source->GetOutput(0));
  UpdateAt(source, stroke + source->GetInterstrokeInterval());
  const double second = StrokeEmission(source->GetOutput(0));
  EXPECT_LT(between, 0.5 * peak);
  EXPECT_GT(second, between);
  EXPECT_LT(second, peak);
}

// The same parameters give the same flash; another seed another one.
TEST(LightningSource, DeterministicForASeed)
{
  vtkNew<vtkNimbusLightningSource> a, b;
  a->SetSeed(9);
  b->SetSeed(9);
  a->Update();
  b->Update();
  ASSERT_EQ(a->GetOutput(0)->GetNumberOfPoints(), b->GetOutput(0)->GetNumberOfPoints());
  for (vtkIdType i = 0; i < a->GetOutput(0)->GetNumberOfPoints(); ++i)
  {
    double p[3], q[3];
    a->GetOutput(0)->GetPoint(i, p);
    b->GetOutput(0)->GetPoint(i, q);
    ASSERT_EQ(p[0], q[0]);
    ASSERT_EQ(p[1], q[1]);
    ASSERT_EQ(p[2], q[2]);
  }
  b->SetSeed(10);
  b->Update();
  double pa[3], pb[3];
  a->GetOutput(0)->GetPoint(a->GetOutput(0)->GetNumberOfPoints() - 1, pa);
  b->GetOutput(0)->GetPoint(b->GetOutput(0)->GetNumberOfPoints() - 1, pb);
  EXPECT_TRUE(pa[0] != pb[0] || pa[1] != pb[1]);
}

// Every parameter's bad values: an error, empty outputs, no exception; the next good
// update works again.
TEST(LightningSource, BadInputGivesAnErrorAndEmptyOutputs)
{
  const double nan = std::nan(""), inf = std::numeric_limits<double>::infinity();
  using S = vtkNimbusLightningSource;
  const std::vector<std::function<void(S*)>> bad = {
    [&](S* s) { s->SetStartPoint(nan, 0, 0); },
    [&](S* s) { s->SetDirection(0, 0, 0); },
    [&](S* s) { s->SetLength(-1.0); },
    [&](S* s) { s->SetLength(inf); },
    [&](S* s) { s->SetSegmentLength(0.0); },
    [&](S* s) { s->SetBranchProbability(2.0); },
    [&](S* s) { s->SetMaxBranchDepth(-2); },
    [&](S* s) { s->SetBranchIntensityFactor(nan); },
    [&](S* s) { s->SetBranchLengthFactor(0.0); },
    [&](S* s) { s->SetMeanAngleDegrees(-5.0); },
    [&](S* s) { s->SetStraightness(nan); },
    [&](S* s) { s->SetIntensity(-1.0); },
    [&](S* s) { s->SetGroundHeight(nan); },
    [&](S* s) { s->SetPointSourceSpacing(0.0); },
    [&](S* s) { s->SetPointSourceSpacing(1e-5); },
    [&](S* s) { s->SetFlashStartTime(nan); },
    [&](S* s) { s->SetLeaderDuration(-1.0); },
    [&](S* s) { s->SetNumberOfStrokes(0); },
    [&](S* s) { s->SetInterstrokeInterval(0.0); },
    [&](S* s) { s->SetSubsequentStrokeFactor(5.0); },
    [&](S* s) { s->SetStrokeDecaySeconds(inf); },
    [&](S* s)
    {
      s->SetSegmentLength(1e-4);
      s->SetLength(1e5);
    },
  };
  for (std::size_t i = 0; i < bad.size(); ++i)
  {
    vtkNew<vtkNimbusLightningSource> source;
    ErrorCatcher errors(source);
    bad[i](source);
    EXPECT_NO_THROW(source->Update()) << "case " << i;
    EXPECT_NE(errors.Messages.find("Lightning: "), std::string::npos) << "case " << i;
    EXPECT_EQ(source->GetOutput(0)->GetNumberOfCells(), 0) << "case " << i;
    EXPECT_EQ(vtkPolyData::SafeDownCast(source->GetOutputDataObject(1))->GetNumberOfPoints(), 0)
      << "case " << i;
    source->GlobalWarningDisplayOn();
  }
  vtkNew<vtkNimbusLightningSource> source;
  source->SetLength(inf);
  source->GlobalWarningDisplayOff();
  source->Update();
  source->GlobalWarningDisplayOn();
  source->SetLength(500.0);
  source->Update();
  EXPECT_GT(source->GetOutput(0)->GetNumberOfCells(), 0);
}
