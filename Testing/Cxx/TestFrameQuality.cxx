// The cloud mapper's automatic quality without a render window (FrameQuality.h):
// the levels, and the cost model that chooses one for a frame budget.
#include "FrameQuality.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

using nimbus::ComputeFrameLevel;
using nimbus::FrameCostModel;
using nimbus::FrameLevel;
using nimbus::kMinimumFrameQuality;

TEST(FrameQuality, LevelsTakeSlicesFirstThenTheImage)
{
  const FrameLevel full = ComputeFrameLevel(1.0, 256, 512, 1280, 800);
  EXPECT_EQ(full.Slices, 256);
  EXPECT_EQ(full.ShadowSurfaceSize, 512);
  EXPECT_EQ(full.Width, 1280);
  EXPECT_EQ(full.Height, 800);
  EXPECT_DOUBLE_EQ(full.Quality, 1.0);

  // q = 1/4: half the slices, half the pixels (0.707 per side).
  const FrameLevel quarter = ComputeFrameLevel(0.25, 256, 512, 1280, 800);
  EXPECT_EQ(quarter.Slices, 128);
  EXPECT_NEAR(quarter.ImageScale, std::sqrt(0.5), 1e-12);
  EXPECT_EQ(quarter.Width, 905);
  EXPECT_NEAR(quarter.Quality, 0.25, 1e-12);

  // Below 1/16 the slices stay at a quarter and the image shrinks.
  const FrameLevel low = ComputeFrameLevel(0.01, 256, 512, 1280, 800);
  EXPECT_EQ(low.Slices, 64);
  EXPECT_NEAR(low.ImageScale, 0.2, 1e-12);
  EXPECT_EQ(low.Width, 256);
  EXPECT_EQ(low.Height, 160);
  EXPECT_EQ(low.ShadowSurfaceSize, 102);

  // The floor, and what is not a quality.
  for (double q : { 0.0, -1.0, 1e-9 })
  {
    const FrameLevel floor = ComputeFrameLevel(q, 256, 512, 1280, 800);
    EXPECT_NEAR(floor.Quality, kMinimumFrameQuality, 1e-15) << q;
    EXPECT_EQ(floor.Width, 80) << q;
  }
  EXPECT_DOUBLE_EQ(ComputeFrameLevel(std::nan(""), 256, 512, 64, 64).Quality, 1.0);
  EXPECT_DOUBLE_EQ(ComputeFrameLevel(5.0, 256, 512, 64, 64).Quality, 1.0);
  // Tiny frames and one slice: never below one of anything.
  const FrameLevel tiny = ComputeFrameLevel(kMinimumFrameQuality, 1, 1, 1, 1);
  EXPECT_EQ(tiny.Slices, 1);
  EXPECT_EQ(tiny.ShadowSurfaceSize, 1);
  EXPECT_EQ(tiny.Width, 1);
  EXPECT_EQ(tiny.Height, 1);
}

// A machine whose frames cost t = a + b q: the model, fed the frames it chose, meets
// the budget within a few frames, from a still frame at q = 1.
TEST(FrameQuality, CostModelMeetsTheBudgetWithinFewFrames)
{
  for (double fixed : { 0.0, 0.02, 0.1 })
  {
    const double perQuality = 30.0; // a 30 s still frame (llvmpipe, 1280 x 800)
    const auto machine = [&](double q) { return fixed + perQuality * q; };
    FrameCostModel model;
    EXPECT_DOUBLE_EQ(model.QualityFor(0.16, 1.0), 1.0); // nothing measured: the first frame
    model.AddSample(1.0, machine(1.0));
    double q = 1.0;
    for (int frame = 0; frame < 4; ++frame)
    {
      q = model.QualityFor(0.16, 1.0);
      model.AddSample(q, machine(q));
    }
    EXPECT_LE(machine(q), 0.16 * 1.001) << fixed;
    EXPECT_GE(machine(q), 0.16 * 0.95) << fixed;
    EXPECT_NEAR(model.PredictSeconds(q), machine(q), 1e-9) << fixed;
  }
}

// A budget below the fixed cost gives the lowest level; a generous one the top.
TEST(FrameQuality, BudgetOutsideTheModelsRange)
{
  FrameCostModel model;
  model.AddSample(1.0, 10.1);
  model.AddSample(0.1, 1.1);
  EXPECT_NEAR(model.PredictSeconds(0.0), 0.1, 1e-9);
  EXPECT_DOUBLE_EQ(model.QualityFor(0.05, 1.0), kMinimumFrameQuality);
  EXPECT_DOUBLE_EQ(model.QualityFor(100.0, 1.0), 1.0);
  EXPECT_DOUBLE_EQ(model.QualityFor(100.0, 0.5), 0.5);
  EXPECT_DOUBLE_EQ(model.QualityFor(0.0, 0.5), 0.5); // no budget: the maximum
}

// A slow frame at a level (a reallocation, a busy machine) is replaced by the next
// frame at that level instead of holding the model down.
TEST(FrameQuality, NewestFramePerLevelReplacesAnOutlier)
{
  FrameCostModel model;
  model.AddSample(1.0, 30.0);
  model.AddSample(0.001, 3.0); // an outlier
  const double stuck = model.QualityFor(0.16, 1.0);
  model.AddSample(0.001, 0.05);
  const double recovered = model.QualityFor(0.16, 1.0);
  EXPECT_GT(recovered, 2.0 * stuck);
  EXPECT_NEAR(model.PredictSeconds(0.001), 0.05, 0.005);
}

TEST(FrameQuality, SamplesThatAreNotTimesAreIgnored)
{
  FrameCostModel model;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  for (double q : { nan, inf, -1.0, 0.0, 0.5 })
  {
    for (double t : { nan, inf, -1.0, 0.0 })
    {
      model.AddSample(q, t);
    }
  }
  model.AddSample(nan, 1.0);
  EXPECT_FALSE(model.HasSamples());
  EXPECT_DOUBLE_EQ(model.QualityFor(0.1, 1.0), 1.0);
  EXPECT_DOUBLE_EQ(model.PredictSeconds(1.0), 0.0);
}
