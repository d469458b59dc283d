// Benchmark (not a test) of multiple scattering (003, 004): the solver's cost against
// its grid, directions and orders, per method, and in the mapper the precompute when
// the sun moves and the frame time against SVS single scattering.
//
//   BenchMultipleScattering [threads = 2] [frames = 5]
//
// Part 1 runs the solver alone (Physics/MultipleScattering.h) on the test cumulus
// (128^3, 3 km wide, k_cl 0.02 /m) downsampled by D; part 2 renders that cumulus at
// 320x240 with vtkNimbusCloudVolumeMapper (needs an OpenGL context: run it under
// Testing/with-display.sh, or with --offscreen for EGL without X). Every ratio compares timings
// taken in this one run; the frame times of the methods and of single scattering are interleaved,
// frame by frame.
#include "MultipleScattering.h"
#include "MultipleScatteringTexture.h"
#include "TestCumulus.h"
#include "vtkNimbusCloudVolumeMapper.h"
#include "vtkNimbusOffscreenRenderWindow.h"

#include "vtkCamera.h"
#include "vtkDataArray.h"
#include "vtkImageData.h"
#include "vtkMatrix4x4.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkSmartPointer.h"
#include "vtkVolume.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

namespace
{
using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point start)
{
  return std::chrono::duration<double>(Clock::now() - start).count();
}

nimbus::ExtinctionGrid Grid(vtkImageData* cloud, int downsampling)
{
  nimbus::MultipleScatteringTexture::Request request;
  request.Downsampling = downsampling;
  request.ExtinctionPerDensity = 0.02;
  nimbus::ExtinctionGrid grid;
  std::array<int, 3> factors;
  std::string error;
  vtkNew<vtkMatrix4x4> identity;
  nimbus::MultipleScatteringTexture::BuildGrid(
    cloud, cloud->GetPointData()->GetScalars(), false, identity, request, grid, factors, error);
  return grid;
}

struct SolveResult
{
  double Seconds;
  double MiB;
  int Orders;
};

SolveResult Solve(const nimbus::ExtinctionGrid& grid, nimbus::MultipleScatteringOptions options)
{
  nimbus::CloudOptics optics{ 0.999, nimbus::PhaseFunctionKind::CornetteShanks, 0.85 };
  nimbus::CloudLighting lighting;
  lighting.Sun.ToLight = nimbus::Normalized({ { 0.3, -0.3, 0.9 } });
  lighting.Sky = [](const nimbus::Vector3& w) {
    return w[2] > 0.0 ? nimbus::Rgb{ { 0.05, 0.08, 0.15 } } : nimbus::Rgb{ { 0.04, 0.04, 0.04 } };
  };
  const auto start = Clock::now();
  try
  {
    const auto field = nimbus::SolveMultipleScattering(grid, optics, lighting, options);
    return { Seconds(start), nimbus::EstimateMultipleScatteringBytes(grid, options) / (1 << 20),
      field.OrdersComputed };
  }
  catch (const std::exception& error)
  {
    std::printf("(%s)\n", error.what());
    return { -1.0, 0.0, 0 };
  }
}

const char* MethodName(int method)
{
  static const char* names[4] = { "none", "octaves", "reference patterns", "discrete directions" };
  return names[method];
}
}

int main(int argc, char* argv[])
{
  // --offscreen or NIMBUS_OFFSCREEN=egl: render on an EGL pbuffer, no X server.
  if (vtkNimbusOffscreenRenderWindow::InstallIfRequested(argc, argv) < 0)
  {
    return 2;
  }
  const int threads = argc > 1 ? std::max(1, std::atoi(argv[1])) : 2;
  const int frames = argc > 2 ? std::max(1, std::atoi(argv[2])) : 5;
  vtkSmartPointer<vtkImageData> cloud = nimbus::testing::TestCumulus(128, 128, 128);
  std::printf("BenchMultipleScattering: %d threads, test cumulus 128^3\n\n", threads);

  std::printf("Solver alone, by grid (D: the density's texels per solver cell), default knobs\n\n"
              "| method | D | grid | seconds | solver MiB | orders |\n|---|---|---|---|---|---|\n");
  for (int method : { 1, 2, 3 })
  {
    for (int downsampling : { 8, 4, 2 })
    {
      const nimbus::ExtinctionGrid grid = Grid(cloud, downsampling);
      nimbus::MultipleScatteringOptions options;
      options.Method = static_cast<nimbus::MultipleScatteringMethod>(method);
      options.Orders = method == 2 ? 3 : 32;
      options.Threads = threads;
      const SolveResult r = Solve(grid, options);
      std::printf("| %s | %d | %dx%dx%d | %.3f | %.1f | %d |\n", MethodName(method), downsampling,
        grid.Dimensions[0], grid.Dimensions[1], grid.Dimensions[2], r.Seconds, r.MiB, r.Orders);
    }
  }

  const nimbus::ExtinctionGrid grid32 = Grid(cloud, 4);
  std::printf("\nDiscrete directions on the 32^3 grid, by directions (32 orders)\n\n"
              "| directions | seconds | solver MiB | orders |\n|---|---|---|---|\n");
  for (int directions : { 6, 14, 26, 50, 100 })
  {
    nimbus::MultipleScatteringOptions options;
    options.NumberOfDirections = directions;
    options.Threads = threads;
    const SolveResult r = Solve(grid32, options);
    std::printf("| %d | %.3f | %.1f | %d |\n", directions, r.Seconds, r.MiB, r.Orders);
  }
  std::printf("\nBy orders on the 32^3 grid (26 directions; reference patterns: its own orders)\n\n"
              "| orders | discrete directions, s | reference patterns, s |\n|---|---|---|\n");
  for (int orders : { 2, 3, 4, 8, 16, 32, 64 })
  {
    nimbus::MultipleScatteringOptions options;
    options.Orders = orders;
    options.Threads = threads;
    const SolveResult directions = Solve(grid32, options);
    double patterns = -1.0;
    if (orders <= 4)
    {
      options.Method = nimbus::MultipleScatteringMethod::ReferencePatterns;
      patterns = Solve(grid32, options).Seconds;
    }
    std::printf("| %d | %.3f | %s |\n", orders, directions.Seconds,
      patterns >= 0.0 ? std::to_string(patterns).c_str() : "");
  }

  // Part 2: the mapper.
  std::printf("\nIn the mapper (320x240, 256 slices, atmosphere and ground): the precompute after\n"
              "the sun moved by 5 degrees, and the frame time without a re-solve (median of %d\n"
              "frames, interleaved with single scattering)\n\n"
              "| method | precompute after a sun move, s | frame, ms | / single scattering |\n"
              "|---|---|---|---|\n",
    frames);
  struct View
  {
    vtkNew<vtkNimbusCloudVolumeMapper> Mapper;
    vtkNew<vtkVolume> Volume;
    vtkNew<vtkRenderer> Renderer;
    vtkNew<vtkRenderWindow> Window;
    explicit View(vtkImageData* density, int method)
    {
      this->Mapper->SetInputData(density);
      this->Mapper->SetMultipleScatteringMethod(method);
      this->Volume->SetMapper(this->Mapper);
      this->Renderer->AddVolume(this->Volume);
      this->Window->SetOffScreenRendering(1);
      this->Window->SetMultiSamples(0);
      this->Window->SetSize(320, 240);
      this->Window->AddRenderer(this->Renderer);
      vtkCamera* camera = this->Renderer->GetActiveCamera();
      camera->SetPosition(0, -6000, 1500);
      camera->SetFocalPoint(0, 0, 1600);
      camera->SetViewUp(0, 0, 1);
      camera->SetViewAngle(35);
      camera->SetClippingRange(10, 1e6);
    }
    double Frame()
    {
      // A small camera turn: the mapper reuses its last image when nothing changed.
      this->Renderer->GetActiveCamera()->Azimuth((this->Frames++ % 2) ? 0.01 : -0.01);
      const auto start = Clock::now();
      this->Window->Render();
      this->Window->WaitForCompletion();
      return Seconds(start);
    }
    int Frames = 0;
  };
  View single(cloud, 0);
  single.Frame();
  for (int method : { 1, 2, 3 })
  {
    View view(cloud, method);
    view.Mapper->SetMultipleScatteringDirections(26);
    view.Frame(); // builds the sky model and solves
    view.Mapper->SetSunElevationDegrees(view.Mapper->GetSunElevationDegrees() + 5.0);
    view.Frame();
    const double precompute = view.Mapper->GetLastMultipleScatteringSeconds();
    std::vector<double> mine, theirs;
    for (int f = 0; f < frames; ++f)
    {
      theirs.push_back(single.Frame());
      mine.push_back(view.Frame());
    }
    std::sort(mine.begin(), mine.end());
    std::sort(theirs.begin(), theirs.end());
    const double a = mine[mine.size() / 2], b = theirs[theirs.size() / 2];
    std::printf("| %s | %.3f | %.1f | %.2f |\n", MethodName(method), precompute, 1000.0 * a, a / b);
  }
  return EXIT_SUCCESS;
}
