// Dunes and wind ripples (002 §5; Nishimori and Ouchi 1993): the physics of the automaton
// (ripple wavelength against the saltation length, sand volume, Bagnold's law for the
// migration speed), its determinism and thread independence, the ripple levels of detail,
// and the VTK source (outputs, time steps, bad parameters, abort).
#include "DuneAutomaton.h"
#include "MessageCatcher.h"
#include "vtkNimbusDunesSource.h"

#include "vtkCallbackCommand.h"
#include "vtkCommand.h"
#include "vtkDataArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPolyData.h"
#include "vtkStreamingDemandDrivenPipeline.h"

#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <limits>
#include <vector>

namespace
{
constexpr double Pi = 3.14159265358979323846;

// The dominant wavelength along x (metres): the power spectrum of every row summed, its
// peak refined by the power-weighted mean wavenumber of the peak and its two neighbours
// on each side.
double DominantWavelength(const std::vector<double>& h, int nx, int ny, double dx)
{
  std::vector<double> power(static_cast<std::size_t>(nx / 2 + 1), 0.0);
  for (int y = 0; y < ny; ++y)
  {
    for (int k = 1; k <= nx / 2; ++k)
    {
      std::complex<double> sum = 0.0;
      for (int x = 0; x < nx; ++x)
      {
        sum += h[x + static_cast<std::size_t>(nx) * y] * std::polar(1.0, -2.0 * Pi * k * x / nx);
      }
      power[k] += std::norm(sum);
    }
  }
  int best = 1;
  for (int k = 1; k <= nx / 2; ++k)
  {
    best = power[k] > power[best] ? k : best;
  }
  double weighted = 0.0, total = 0.0;
  for (int k = std::max(1, best - 2); k <= std::min(nx / 2, best + 2); ++k)
  {
    weighted += k * power[k];
    total += power[k];
  }
  return nx * dx / (weighted / total);
}

struct LineFit
{
  double Slope, Intercept, RSquared;
};

LineFit FitLine(const std::vector<double>& x, const std::vector<double>& y)
{
  const double n = static_cast<double>(x.size());
  double mx = 0.0, my = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i)
  {
    mx += x[i] / n;
    my += y[i] / n;
  }
  double sxy = 0.0, sxx = 0.0, syy = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i)
  {
    sxy += (x[i] - mx) * (y[i] - my);
    sxx += (x[i] - mx) * (x[i] - mx);
    syy += (y[i] - my) * (y[i] - my);
  }
  return { sxy / sxx, my - sxy / sxx * mx, sxy * sxy / (sxx * syy) };
}

// The crest's position along a row (cells), refined by a parabola through the maximum.
double CrestPosition(const std::vector<double>& h, int nx)
{
  int best = 0;
  for (int x = 0; x < nx; ++x)
  {
    best = h[x] > h[best] ? x : best;
  }
  const double l = h[(best + nx - 1) % nx], c = h[best], r = h[(best + 1) % nx];
  const double curvature = l - 2.0 * c + r;
  return best + (curvature < 0.0 ? 0.5 * (l - r) / curvature : 0.0);
}

double Maximum(const std::vector<double>& h)
{
  double m = -std::numeric_limits<double>::infinity();
  for (double v : h)
  {
    m = std::max(m, v);
  }
  return m;
}
}

// Nishimori and Ouchi (1993): the ripples' wavelength grows linearly with the saltation
// length L0. Five lengths, 2 to 8 cm, on 2.56 m x 16 cm beds of 1 cm cells, 300 steps.
TEST(DuneAutomaton, RippleWavelengthGrowsLinearlyWithSaltationLength)
{
  std::vector<double> lengths, wavelengths;
  for (double l0 : { 0.02, 0.03, 0.04, 0.06, 0.08 })
  {
    nimbus::SandParameters p = nimbus::RippleParameters();
    p.Dimensions[0] = 256;
    p.Dimensions[1] = 16;
    p.SaltationLengthMetres = l0;
    nimbus::SandAutomaton ripples(p, nimbus::RandomSandBed(256, 16, 0.0, 0.01, 7));
    ripples.Run(300, 1);
    lengths.push_back(l0);
    wavelengths.push_back(DominantWavelength(ripples.Heights(), 256, 16, p.CellSizeMetres));
    std::printf("L0 %.3f m: wavelength %.4f m\n", l0, wavelengths.back());
  }
  const LineFit fit = FitLine(lengths, wavelengths);
  std::printf(
    "wavelength = %.3f L0 + %.4f m, R^2 = %.4f\n", fit.Slope, fit.Intercept, fit.RSquared);
  EXPECT_GT(fit.RSquared, 0.98);
  EXPECT_GT(fit.Slope, 1.0);
  EXPECT_LT(fit.Slope, 2.0);
  EXPECT_LT(std::abs(fit.Intercept), 0.02); // under 2 cells: proportional, nearly
}

// Every rule moves sand and never makes or destroys it: the volume is kept to rounding.
TEST(DuneAutomaton, SandVolumeConserved)
{
  for (const bool dunes : { true, false })
  {
    nimbus::SandParameters p = dunes ? nimbus::DuneParameters() : nimbus::RippleParameters();
    p.Dimensions[0] = 64;
    p.Dimensions[1] = 48;
    const double mean = dunes ? 2.0 : 0.0;
    const double spread = dunes ? 3.0 : 0.01; // dunes: bare rock in places
    nimbus::SandAutomaton automaton(p, nimbus::RandomSandBed(64, 48, mean, spread, 11));
    const double before = automaton.Volume();
    automaton.Run(500, 2);
    const double after = automaton.Volume();
    const double scale = dunes ? before : 64.0 * 48.0 * 0.01 * p.CellSizeMetres * p.CellSizeMetres;
    std::printf("%s: volume %.17g -> %.17g m^3, relative change %.2e\n",
      dunes ? "dunes" : "ripples", before, after, std::abs(after - before) / scale);
    EXPECT_LT(std::abs(after - before), 1e-12 * scale);
    for (double h : automaton.Heights())
    {
      ASSERT_TRUE(std::isfinite(h));
      if (dunes)
      {
        ASSERT_GE(h, 0.0);
      }
    }
  }
}

// Bagnold's law: a dune's migration speed falls as 1 / height. Isolated transverse dunes
// of five heights on bare rock (one row: uniform across the wind), a stoss side at 11
// degrees and a slip face at 31; after the shape settles, the crest's speed over a run in
// which it moves about three dune heights (after four to settle), against the mean crest height.
double MigrationExponent(double heightGain, bool print)
{
  std::vector<double> logHeight, logSpeed;
  for (double h0 : { 4.0, 6.0, 8.0, 12.0, 16.0 })
  {
    const int nx = 512;
    nimbus::SandParameters p = nimbus::DuneParameters();
    p.Dimensions[0] = nx;
    p.Dimensions[1] = 1;
    p.SaltationHeightGain = heightGain;
    std::vector<double> h(nx, 0.0);
    for (int x = 0; x < nx; ++x)
    {
      const double r = (x - 100) * p.CellSizeMetres;
      h[x] = std::max(0.0, r < 0.0 ? h0 + 0.2 * r : h0 - 0.6 * r);
    }
    nimbus::SandAutomaton dune(p, h);
    // c ~ q L0 / H: steps to move about n heights = n H^2 / (q L0) (in cells and metres).
    const double stepsPerHeight = h0 * h0 / (p.SaltationDepthMetres * p.SaltationLengthMetres);
    dune.Run(static_cast<long long>(4.0 * stepsPerHeight), 1);
    const double x0 = CrestPosition(dune.Heights(), nx);
    const double height0 = Maximum(dune.Heights());
    const auto steps = static_cast<long long>(3.0 * stepsPerHeight);
    dune.Run(steps, 1);
    double moved = CrestPosition(dune.Heights(), nx) - x0;
    moved += moved < -0.5 * nx ? nx : 0.0;
    const double speed = moved * p.CellSizeMetres / steps;           // m per step
    const double height = 0.5 * (height0 + Maximum(dune.Heights())); // m
    if (print)
    {
      std::printf("b = %.2f, height %.2f m: %.5f m per step, speed x height %.4f m^2\n", heightGain,
        height, speed, speed * height);
    }
    logHeight.push_back(std::log(height));
    logSpeed.push_back(std::log(speed));
  }
  const LineFit fit = FitLine(logHeight, logSpeed);
  std::printf("b = %.2f: speed ~ height^%.3f (R^2 %.4f)\n", heightGain, fit.Slope, fit.RSquared);
  return fit.Slope;
}

TEST(DuneAutomaton, MigrationSpeedFallsAsOneOverHeight)
{
  // The defaults (b = 0.02): L grows a little with the height, so the crest flux does too.
  const double exponent = MigrationExponent(nimbus::DuneParameters().SaltationHeightGain, true);
  EXPECT_GT(exponent, -1.1);
  EXPECT_LT(exponent, -0.85);
  // b = 0: a flux over the crest independent of the height, exactly Bagnold's law.
  const double flat = MigrationExponent(0.0, true);
  EXPECT_NEAR(flat, -1.0, 0.08);
}

// Same seed, same heights, bit for bit, whatever the thread count; another seed differs.
TEST(DuneAutomaton, DeterministicAndThreadIndependent)
{
  for (const bool dunes : { true, false })
  {
    nimbus::SandParameters p = dunes ? nimbus::DuneParameters() : nimbus::RippleParameters();
    p.Dimensions[0] = 64;
    p.Dimensions[1] = 40;
    const double mean = dunes ? 2.0 : 0.0;
    const double spread = dunes ? 2.0 : 0.01;
    std::vector<double> reference;
    for (int threads : { 1, 2, 3, 7 })
    {
      nimbus::SandAutomaton automaton(p, nimbus::RandomSandBed(64, 40, mean, spread, 5));
      automaton.Run(150, threads);
      if (reference.empty())
      {
        reference = automaton.Heights();
      }
      else
      {
        ASSERT_EQ(automaton.Heights(), reference) << threads << " threads";
      }
    }
    nimbus::SandAutomaton again(p, nimbus::RandomSandBed(64, 40, mean, spread, 5));
    again.Run(100, 4);
    again.Run(50, 1); // split runs: the same state
    EXPECT_EQ(again.Heights(), reference);
    nimbus::SandAutomaton other(p, nimbus::RandomSandBed(64, 40, mean, spread, 6));
    other.Run(150, 1);
    EXPECT_NE(other.Heights(), reference);
  }
}

// 002 §5.2: 256^2, 128^2, 64^2, 32^2 normal maps; the level grows by one per doubling of
// the distance.
TEST(DuneAutomaton, RippleLevelsOfDetail)
{
  nimbus::SandParameters p = nimbus::RippleParameters();
  p.Dimensions[0] = p.Dimensions[1] = 256;
  nimbus::SandAutomaton ripples(p, nimbus::RandomSandBed(256, 256, 0.0, 0.001, 3));
  ripples.Run(20, 0);
  const auto pyramid = nimbus::RippleNormalPyramid(ripples.Heights(), 256, 0.01, 4);
  ASSERT_EQ(pyramid.size(), 4u);
  for (int k = 0; k < 4; ++k)
  {
    EXPECT_EQ(pyramid[k].Size, 256 >> k);
    EXPECT_DOUBLE_EQ(pyramid[k].TexelMetres, 0.01 * (1 << k));
    for (std::size_t t = 0; t < pyramid[k].Normals.size(); t += 3)
    {
      const float* n = &pyramid[k].Normals[t];
      ASSERT_NEAR(n[0] * n[0] + n[1] * n[1] + n[2] * n[2], 1.0f, 1e-5f);
      ASSERT_GT(n[2], 0.0f);
    }
  }
  EXPECT_EQ(nimbus::RippleLevelOfDetail(10.0, 50.0, 4), 0);
  EXPECT_EQ(nimbus::RippleLevelOfDetail(60.0, 50.0, 4), 1);
  EXPECT_EQ(nimbus::RippleLevelOfDetail(150.0, 50.0, 4), 2);
  EXPECT_EQ(nimbus::RippleLevelOfDetail(1e6, 50.0, 4), 3);
  EXPECT_EQ(nimbus::RippleLevelOfDetail(std::nan(""), 50.0, 4), 0);
}

namespace
{
vtkNew<vtkNimbusDunesSource> SmallSource()
{
  vtkNew<vtkNimbusDunesSource> source;
  source->SetDimensions(32, 24);
  source->SetSpinUpSteps(200);
  source->SetRippleResolution(32);
  source->SetRippleSteps(40);
  source->SetNumberOfTimeSteps(5);
  return source;
}
}

TEST(DunesSource, OutputsAndTimeSteps)
{
  auto source = SmallSource();
  source->UpdateInformation();
  vtkInformation* info = source->GetOutputInformation(0);
  ASSERT_EQ(info->Length(vtkStreamingDemandDrivenPipeline::TIME_STEPS()), 6);
  EXPECT_EQ(info->Get(vtkStreamingDemandDrivenPipeline::TIME_STEPS())[5], 50.0);
  source->UpdateTimeStep(20.0);
  vtkPolyData* surface = source->GetOutput();
  EXPECT_EQ(surface->GetNumberOfPoints(), 33 * 25);
  EXPECT_EQ(surface->GetNumberOfCells(), 32 * 24);
  ASSERT_NE(surface->GetPointData()->GetNormals(), nullptr);
  ASSERT_NE(surface->GetPointData()->GetTCoords(), nullptr);
  ASSERT_NE(surface->GetPointData()->GetTangents(), nullptr);
  ASSERT_NE(surface->GetPointData()->GetArray("Height"), nullptr);
  EXPECT_EQ(source->GetNumberOfStepsComputed(), 220);
  vtkImageData* ripples = source->GetRippleOutput();
  int dims[3];
  ripples->GetDimensions(dims);
  EXPECT_EQ(dims[0], 32);
  ASSERT_NE(ripples->GetPointData()->GetArray("RippleNormalMap"), nullptr);
  vtkNew<vtkImageData> coarse;
  ASSERT_TRUE(vtkNimbusDunesSource::RippleNormalLevel(ripples, 2, coarse));
  coarse->GetDimensions(dims);
  EXPECT_EQ(dims[0], 8);
  EXPECT_FALSE(vtkNimbusDunesSource::RippleNormalLevel(ripples, 6, coarse));

  // Back to time 10 and forward again: the same surface as a fresh source at time 20.
  std::vector<double> at20(surface->GetNumberOfPoints());
  for (vtkIdType i = 0; i < surface->GetNumberOfPoints(); ++i)
  {
    at20[i] = surface->GetPoint(i)[2];
  }
  source->UpdateTimeStep(10.0);
  source->UpdateTimeStep(20.0);
  auto fresh = SmallSource();
  fresh->SetNumberOfThreads(3);
  fresh->UpdateTimeStep(20.0);
  for (vtkIdType i = 0; i < surface->GetNumberOfPoints(); ++i)
  {
    ASSERT_EQ(source->GetOutput()->GetPoint(i)[2], at20[i]);
    ASSERT_EQ(fresh->GetOutput()->GetPoint(i)[2], at20[i]);
  }
}

// Many bad values: each ends in an error and empty outputs, never in a crash.
TEST(DunesSource, BadParametersRefused)
{
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  using Setter = void (vtkNimbusDunesSource::*)(double);
  const Setter setters[] = { &vtkNimbusDunesSource::SetCellSizeMetres,
    &vtkNimbusDunesSource::SetSandDepthMetres, &vtkNimbusDunesSource::SetSandDepthVariationMetres,
    &vtkNimbusDunesSource::SetSaltationLengthMetres, &vtkNimbusDunesSource::SetSaltationHeightGain,
    &vtkNimbusDunesSource::SetSaltationDepthMetres, &vtkNimbusDunesSource::SetCreepRate,
    &vtkNimbusDunesSource::SetShadowAngleDegrees, &vtkNimbusDunesSource::SetReposeAngleDegrees,
    &vtkNimbusDunesSource::SetRippleCellSizeMetres,
    &vtkNimbusDunesSource::SetRippleSaltationLengthMetres,
    &vtkNimbusDunesSource::SetRippleSaltationHeightGain,
    &vtkNimbusDunesSource::SetRippleSaltationDepthMetres,
    &vtkNimbusDunesSource::SetRippleCreepRate };
  int refused = 0;
  for (const Setter setter : setters)
  {
    for (const double bad : { nan, inf, -inf, -1.0, 1e300 })
    {
      auto source = SmallSource();
      nimbus::testing::MessageCatcher messages(source);
      (source.Get()->*setter)(bad);
      source->Update();
      EXPECT_FALSE(messages.Errors.empty()) << "value " << bad;
      EXPECT_EQ(source->GetOutput()->GetNumberOfPoints(), 0);
      refused += messages.Errors.empty() ? 0 : 1;
    }
  }
  // Zero sizes and impossible grids.
  const struct
  {
    int Dimensions[2];
    int Ripples;
    double Cell;
  } cases[] = { { { 0, 32 }, 32, 2.0 }, { { 32, -5 }, 32, 2.0 }, { { 100000, 32 }, 32, 2.0 },
    { { 32, 32 }, 0, 2.0 }, { { 32, 32 }, 30, 2.0 }, { { 32, 32 }, 1 << 20, 2.0 },
    { { 32, 32 }, 32, 0.0 } };
  for (const auto& c : cases)
  {
    auto source = SmallSource();
    nimbus::testing::MessageCatcher messages(source);
    source->SetDimensions(c.Dimensions[0], c.Dimensions[1]);
    source->SetRippleResolution(c.Ripples);
    source->SetCellSizeMetres(c.Cell);
    source->Update();
    EXPECT_FALSE(messages.Errors.empty());
    EXPECT_EQ(source->GetOutput()->GetNumberOfPoints(), 0);
    refused += messages.Errors.empty() ? 0 : 1;
  }
  std::printf("%d bad settings refused\n", refused);
  // Too much work is refused up front.
  auto source = SmallSource();
  nimbus::testing::MessageCatcher messages(source);
  source->SetDimensions(8192, 8192);
  source->SetSpinUpSteps(10000000);
  source->Update();
  ASSERT_FALSE(messages.Errors.empty());
  EXPECT_NE(messages.Errors[0].find("cell steps"), std::string::npos);
}

// Progress moves, and AbortExecute stops the steps with empty outputs.
TEST(DunesSource, ProgressAndAbort)
{
  auto source = SmallSource();
  nimbus::testing::MessageCatcher messages(source);
  source->Update();
  EXPECT_GT(messages.ProgressEvents, 2);
  auto aborted = SmallSource();
  aborted->SetSpinUpSteps(1000000);
  vtkNew<vtkCallbackCommand> abort;
  abort->SetCallback([](vtkObject* caller, unsigned long, void*, void*)
    { static_cast<vtkAlgorithm*>(caller)->SetAbortExecute(1); });
  aborted->AddObserver(vtkCommand::ProgressEvent, abort);
  aborted->Update();
  EXPECT_LT(aborted->GetNumberOfStepsComputed(), 1000);
  EXPECT_EQ(aborted->GetOutput()->GetNumberOfPoints(), 0);
}
