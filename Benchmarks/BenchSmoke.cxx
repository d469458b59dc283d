// Benchmark (not a test) of the smoke solver (002 §4): time per frame against the grid
// (N^3 cells over an 8 m cube, a hot sphere of radius 0.75 m at (0, 0, 0.75), vorticity
// confinement 0.3, Smagorinsky 0.15, MacCormack, 24 frames per second), the same scene as
// measurements/mantaflow-smoke-bench.py for Blender's Mantaflow.
//
//   BenchSmoke [threads = 2] [frames = 24] [N ...]   (default N: 32 64)
//
// NIMBUS_SMOKE_TOLERANCE (environment) overrides the pressure solve's relative residual
// (SmokeParameters::PressureTolerance) to measure what it costs.
#include "SmokeSolver.h"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <vector>

int main(int argc, char** argv)
{
  const int threads = argc > 1 ? std::atoi(argv[1]) : 2;
  const int frames = argc > 2 ? std::atoi(argv[2]) : 24;
  std::vector<int> sizes;
  for (int a = 3; a < argc; ++a)
  {
    sizes.push_back(std::atoi(argv[a]));
  }
  if (sizes.empty())
  {
    sizes = { 32, 64 };
  }
  std::printf("%6s %10s %12s %14s %10s %14s %12s\n", "N", "cells", "setup s", "ms per frame",
    "sub-steps", "ns per cell-step", "CG its/step");
  for (int n : sizes)
  {
    nimbus::SmokeParameters p;
    p.Dimensions = { { n, n, n } };
    p.CellSizeMetres = 8.0 / n;
    p.Origin = { { -4.0, -4.0, 0.0 } };
    p.Threads = threads;
    p.VorticityConfinement = 0.3;
    p.SmagorinskyConstant = 0.15;
    nimbus::SmokeEmitter e;
    e.Centre = { { 0.0, 0.0, 0.75 } };
    e.RadiusMetres = 0.75;
    e.DensityPerSecond = 2.0;
    e.TemperatureKelvin = 600.0;
    p.Emitters = { e };
    if (const char* tolerance = std::getenv("NIMBUS_SMOKE_TOLERANCE"))
    {
      p.PressureTolerance = std::atof(tolerance);
    }
    auto start = std::chrono::steady_clock::now();
    nimbus::SmokeSolver solver(p);
    const double setup =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    start = std::chrono::steady_clock::now();
    int substeps = 0;
    double iterations = 0.0;
    for (int f = 0; f < frames; ++f)
    {
      const nimbus::SmokeStepReport report = solver.Step(1.0 / 24.0);
      substeps += report.Substeps;
      iterations += report.PressureIterations; // of the frame's last sub-step
    }
    const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const double cells = static_cast<double>(n) * n * n;
    std::printf("%6d %10.0f %12.2f %14.1f %10d %14.1f %12.1f\n", n, cells, setup,
      1000.0 * seconds / frames, substeps, 1e9 * seconds / (cells * substeps), iterations / frames);
  }
  return 0;
}
