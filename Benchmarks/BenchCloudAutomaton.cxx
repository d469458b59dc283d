// Benchmarks of the cloud cellular automaton (002 §3) and its smoothing: cell updates per
// second and time per step for the paper's 256 x 256 x 64 grid, scaling with grid size and
// with the number of threads. Not a test: run build/bin/BenchCloudAutomaton.
#include "CloudAutomaton.h"

#include <benchmark/benchmark.h>

#include <vector>

namespace
{
// The VTK source's default probabilities, with wind and shear so the shift pass runs.
nimbus::CloudAutomatonParameters Parameters(int nx, int ny, int nz, int threads, bool fields)
{
  nimbus::CloudAutomatonParameters p;
  p.Dimensions[0] = nx;
  p.Dimensions[1] = ny;
  p.Dimensions[2] = nz;
  p.Seed = 7;
  p.Extinction = nimbus::ProbabilityField::Uniform(0.05);
  p.HumiditySupply = nimbus::ProbabilityField::Uniform(0.002);
  p.ActivationSupply = nimbus::ProbabilityField::Uniform(0.0002);
  if (fields)
  {
    const std::size_t plane = static_cast<std::size_t>(nx) * ny;
    p.Extinction = nimbus::ProbabilityField::Plane(std::vector<float>(plane, 0.05f));
    p.HumiditySupply = nimbus::ProbabilityField::Plane(std::vector<float>(plane, 0.002f));
    p.ActivationSupply = nimbus::ProbabilityField::Plane(std::vector<float>(plane, 0.0002f));
  }
  p.InitialHumidity = 0.3;
  p.InitialActivation = 0.001;
  p.Wind[0] = 0.5;
  p.Shear[0] = 0.02;
  p.NumberOfThreads = threads;
  return p;
}

// Args: nx, ny, nz, threads, per-cell probability fields (0/1).
void BM_Step(benchmark::State& state)
{
  const int nx = static_cast<int>(state.range(0)), ny = static_cast<int>(state.range(1)),
            nz = static_cast<int>(state.range(2));
  nimbus::CloudAutomaton automaton(
    Parameters(nx, ny, nz, static_cast<int>(state.range(3)), state.range(4) != 0));
  automaton.StepTo(20); // past the initial transient
  for (auto _ : state)
  {
    automaton.Step();
  }
  const double cells = static_cast<double>(nx) * ny * nz;
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations() * cells));
  state.counters["cell_updates_per_s"] =
    benchmark::Counter(cells, benchmark::Counter::kIsIterationInvariantRate);
}

// Args: nx, ny, nz, threads. Smoothing (R = 2.5 cells) of one state into a density.
void BM_Smooth(benchmark::State& state)
{
  const int nx = static_cast<int>(state.range(0)), ny = static_cast<int>(state.range(1)),
            nz = static_cast<int>(state.range(2));
  nimbus::CloudAutomaton automaton(Parameters(nx, ny, nz, 1, false));
  automaton.StepTo(20);
  nimbus::CloudSmoothingParameters smoothing;
  smoothing.NumberOfThreads = static_cast<int>(state.range(3));
  std::vector<float> density;
  for (auto _ : state)
  {
    nimbus::SmoothCloud(automaton, smoothing, density);
    benchmark::DoNotOptimize(density.data());
  }
  state.SetItemsProcessed(
    static_cast<int64_t>(state.iterations() * static_cast<double>(nx) * ny * nz));
}
}

BENCHMARK(BM_Step)
  ->Args({ 64, 64, 16, 1, 0 })
  ->Args({ 128, 128, 32, 1, 0 })
  ->Args({ 256, 256, 64, 1, 0 })
  ->Args({ 256, 256, 64, 2, 0 })
  ->Args({ 512, 512, 64, 1, 0 })
  ->Args({ 256, 256, 64, 1, 1 })
  ->Args({ 256, 256, 64, 2, 1 })
  ->Unit(benchmark::kMillisecond)
  ->UseRealTime();
BENCHMARK(BM_Smooth)
  ->Args({ 128, 128, 32, 1 })
  ->Args({ 256, 256, 64, 1 })
  ->Args({ 256, 256, 64, 2 })
  ->Unit(benchmark::kMillisecond)
  ->UseRealTime();

BENCHMARK_MAIN();
