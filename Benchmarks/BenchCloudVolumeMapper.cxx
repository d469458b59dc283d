// Benchmark (not a test) of the shadow-view-slice mapper: frame time against the
// slice count and the volume size, the cost of each optional component, and the
// ratio to the floor (the same slices composited unlit) and to VTK's
// vtkGPUVolumeRayCastMapper with volumetric scattering (GlobalIlluminationReach 1).
//
//   BenchCloudVolumeMapper [frames = 5] [width = 320] [height = 240] [sky | march | lights | side]
//
// With a number `side` the volume sweep adds a side^3 cloud (one node's piece of a
// large field). With "sky" only the sky table runs: what a vtkNimbusSkyBackground
// adds to a cloud frame (the background pass plus the mapper's second target). With
// "march" only the ray-marched method's table runs (docs/ray-march.md): frame time
// against the volume and the step beside the slices and VTK's plain GPU ray caster, and
// one frame's passes timed on the GPU. With "lights" only the view lights' table runs
// (docs/lights.md): a frame with spotlights (their shafts in the haze, the cloud lit
// from below, a box's shadow map) against the same frame without them, by ray marching
// and by virtual planes, against the samples, the planes, the lights and the maps.
//
// Prints one table; every ratio compares timings taken in this one run. Run it
// under Testing/with-display.sh (needs an OpenGL context), or with --offscreen (EGL, no X).
#include "TestCumulus.h"
#include "vtkNimbusCloudVolumeMapper.h"
#include "vtkNimbusOffscreenRenderWindow.h"
#include "vtkNimbusSky.h"
#include "vtkNimbusSkyBackground.h"

#include "vtkActor.h"
#include "vtkCamera.h"
#include "vtkColorTransferFunction.h"
#include "vtkCubeSource.h"
#include "vtkGPUVolumeRayCastMapper.h"
#include "vtkImageData.h"
#include "vtkLight.h"
#include "vtkNew.h"
#include "vtkPiecewiseFunction.h"
#include "vtkPolyDataMapper.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkSmartPointer.h"
#include "vtkVolume.h"
#include "vtkVolumeProperty.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <string>
#include <vector>

namespace
{
int Frames = 5;
int Width = 320;
int Height = 240;
int ExtraSide = 0; // the volume sweep's extra side^3 cloud (0: none)

struct Bench
{
  vtkNew<vtkRenderer> Renderer;
  vtkNew<vtkRenderWindow> Window;
  vtkNew<vtkVolume> Volume;
  Bench()
  {
    this->Renderer->AddVolume(this->Volume);
    this->Window->SetOffScreenRendering(1);
    this->Window->SetMultiSamples(0);
    this->Window->SetSize(Width, Height);
    this->Window->AddRenderer(this->Renderer);
    vtkCamera* camera = this->Renderer->GetActiveCamera();
    camera->SetPosition(0, -6000, 1500);
    camera->SetFocalPoint(0, 0, 1600);
    camera->SetViewUp(0, 0, 1);
    camera->SetViewAngle(35);
    camera->SetClippingRange(10, 1e6);
  }
  /// Median frame time in ms after one warm-up frame.
  double Time()
  {
    this->Window->Render();
    this->Window->WaitForCompletion();
    std::vector<double> times;
    for (int i = 0; i < Frames; ++i)
    {
      // Move the camera a little so nothing is cached between frames except what
      // the mapper caches on purpose (the interval/phase texture is rebuilt).
      this->Renderer->GetActiveCamera()->Azimuth(i % 2 ? 0.01 : -0.01);
      const auto start = std::chrono::steady_clock::now();
      this->Window->Render();
      this->Window->WaitForCompletion();
      times.push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
          .count());
    }
    std::sort(times.begin(), times.end());
    return times[times.size() / 2];
  }
};

// One window for the whole run (a window per measurement exhausted Xvfb's client
// connections after a few dozen).
Bench* TheBench = nullptr;

double TimeSvs(vtkImageData* image, int slices,
  const std::function<void(vtkNimbusCloudVolumeMapper*)>& configure,
  std::string* passTimes = nullptr)
{
  Bench& bench = *TheBench;
  vtkNew<vtkNimbusCloudVolumeMapper> mapper;
  mapper->SetInputData(image);
  mapper->SetNumberOfSlices(slices);
  mapper->SetSunAzimuthDegrees(135);
  mapper->SetSunElevationDegrees(65);
  configure(mapper);
  bench.Volume->SetMapper(mapper);
  const double t = bench.Time();
  if (passTimes)
  {
    *passTimes = mapper->GetLastPassTimes();
  }
  bench.Volume->SetMapper(nullptr);
  mapper->ReleaseGraphicsResources(bench.Window);
  return t;
}

// VTK's GPU ray caster as ParaView's Volume representation draws a still frame: one
// sample per voxel, absorption and emission without shading.
double TimeVtkPlain(vtkImageData* image)
{
  Bench& bench = *TheBench;
  vtkNew<vtkGPUVolumeRayCastMapper> mapper;
  mapper->SetInputData(image);
  mapper->AutoAdjustSampleDistancesOff();
  const double spacing = image->GetSpacing()[0];
  mapper->SetSampleDistance(spacing);
  vtkNew<vtkPiecewiseFunction> opacity;
  opacity->AddPoint(0.0, 0.0);
  opacity->AddPoint(3.0, 1.0);
  vtkNew<vtkColorTransferFunction> color;
  color->AddRGBPoint(0.0, 0.2, 0.3, 0.8);
  color->AddRGBPoint(3.0, 1, 1, 1);
  vtkNew<vtkVolumeProperty> property;
  property->SetScalarOpacity(opacity);
  property->SetColor(color);
  property->SetInterpolationTypeToLinear();
  bench.Volume->SetProperty(property);
  bench.Volume->SetMapper(mapper);
  const double t = bench.Time();
  bench.Volume->SetMapper(nullptr);
  mapper->ReleaseGraphicsResources(bench.Window);
  return t;
}

// The ray-marched method's table: frame time against the volume and the step, beside
// the slices (256) and VTK's plain GPU ray caster; then its passes (GL timer queries).
void RayMarchTables()
{
  const auto march = [](double step, bool air, bool unlit)
  {
    return [step, air, unlit](vtkNimbusCloudVolumeMapper* m)
    {
      m->SetRenderingMethodToRayMarching();
      m->SetRayMarchStepTexels(step);
      m->SetAtmosphere(air);
      m->SetGround(air);
      m->SetUnlit(unlit);
    };
  };
  const auto none = [](vtkNimbusCloudVolumeMapper*) {};
  std::printf(
    "\nRay march (RenderingMethod RayMarching) against the slices and VTK's plain GPU "
    "ray caster\n\n| volume | step (texels) | full scene | cloud only | unlit floor | "
    "slices (256), full | VTK GPU, plain | full / VTK |\n|---|---|---|---|---|---|---|---|\n");
  for (const int side : { 64, 128, 256 })
  {
    vtkSmartPointer<vtkImageData> c = nimbus::testing::TestCumulus(side, side, side);
    const double slices = TimeSvs(c, 256, none);
    const double vtkPlain = TimeVtkPlain(c);
    for (const double step : { 0.5, 1.0, 2.0 })
    {
      const double full = TimeSvs(c, 256, march(step, true, false));
      const double cloud = TimeSvs(c, 256, march(step, false, false));
      const double floor = TimeSvs(c, 256, march(step, false, true));
      std::printf("| %d^3 | %.1f | %.1f | %.1f | %.1f | %.1f | %.1f | %.2f |\n", side, step, full,
        cloud, floor, slices, vtkPlain, full / vtkPlain);
    }
  }
  std::printf("\nPasses of one frame (128^3, the default step, GL_TIME_ELAPSED), seconds:\n\n");
  vtkSmartPointer<vtkImageData> c128 = nimbus::testing::TestCumulus(128, 128, 128);
  for (const int method :
    { vtkNimbusCloudVolumeMapper::RayMarching, vtkNimbusCloudVolumeMapper::ShadowViewSlicing })
  {
    std::string passes;
    const double t = TimeSvs(
      c128, 256,
      [method](vtkNimbusCloudVolumeMapper* m)
      {
        m->SetRenderingMethod(method);
        m->TimePassesOn();
      },
      &passes);
    std::printf("- %s (frame %.1f ms): %s\n",
      method == vtkNimbusCloudVolumeMapper::RayMarching ? "ray march" : "slices, 256", t,
      passes.c_str());
  }
}

// The view lights' tables (docs/lights.md): a frame with lights against the same frame
// without them (LightSources NoLights), in pairs taken one after the other (the ratio's
// median over the pairs: a shared machine's load changes less within a pair), for two
// scenes: a 128^3 cloud at night lit from the ground by spotlights beside a tower (its
// shadow map), and a street lamp in fog (no cloud) with a post in the beam.
struct LightsScene
{
  vtkSmartPointer<vtkImageData> Density;
  std::vector<vtkSmartPointer<vtkLight>> Lights;
  vtkNew<vtkCubeSource> Occluder;
  std::array<double, 6> Camera{}; // position, focal point
  double ViewAngle = 35.0, Near = 10.0, SunElevation = -20.0, Mie = 1e-4;
};

LightsScene CloudAtNight()
{
  LightsScene scene;
  scene.Density = nimbus::testing::TestCumulus(128, 128, 128);
  scene.Occluder->SetBounds(-250, -150, -1900, -1800, 0, 300);
  for (int i = 0; i < 4; ++i)
  {
    auto light = vtkSmartPointer<vtkLight>::New();
    light->SetPositional(true);
    light->SetPosition(-200.0 + 150.0 * i, -2000, 10);
    light->SetFocalPoint(-300.0 + 200.0 * i, 0, 1500);
    light->SetConeAngle(6.0);
    light->SetIntensity(2e5);
    scene.Lights.push_back(light);
  }
  scene.Camera = { { 0, -6000, 1500, 0, 0, 1600 } };
  return scene;
}

LightsScene LampInFog()
{
  LightsScene scene;
  scene.Density = vtkSmartPointer<vtkImageData>::New();
  scene.Density->SetDimensions(4, 4, 4);
  scene.Density->SetOrigin(-10, -6, 0);
  scene.Density->SetSpacing(20.0 / 3.0, 6.0, 8.0 / 3.0);
  scene.Density->AllocateScalars(VTK_FLOAT, 1);
  std::fill_n(static_cast<float*>(scene.Density->GetScalarPointer()), 64, 0.0f);
  scene.Occluder->SetBounds(1.2, 1.7, -0.25, 0.25, 0, 3);
  for (int i = 0; i < 4; ++i)
  {
    auto light = vtkSmartPointer<vtkLight>::New();
    light->SetPositional(true);
    light->SetPosition(3.0 * i, 0, 4.5);
    light->SetFocalPoint(3.0 * i + 7.0, 0, 0.5);
    light->SetConeAngle(35.0);
    light->SetIntensity(1.0);
    scene.Lights.push_back(light);
  }
  scene.Camera = { { -2, -9, 1.7, 3, 0, 2 } };
  scene.ViewAngle = 50.0;
  scene.Near = 0.1;
  scene.SunElevation = -10.0;
  scene.Mie = 0.9 * 3.912 / 80.0; // fog, 80 m visibility
  return scene;
}

struct LightsRow
{
  int Lights, Method, Samples, Downsampling, Maps;
};

void LightsTable(const char* title, LightsScene scene)
{
  Bench& bench = *TheBench;
  vtkCamera* camera = bench.Renderer->GetActiveCamera();
  camera->SetPosition(scene.Camera[0], scene.Camera[1], scene.Camera[2]);
  camera->SetFocalPoint(scene.Camera[3], scene.Camera[4], scene.Camera[5]);
  camera->SetViewAngle(scene.ViewAngle);
  camera->SetClippingRange(scene.Near, 1e6);
  vtkNew<vtkPolyDataMapper> occluderMapper;
  occluderMapper->SetInputConnection(scene.Occluder->GetOutputPort());
  vtkNew<vtkActor> occluder;
  occluder->SetMapper(occluderMapper);
  bench.Renderer->AddActor(occluder);
  vtkNew<vtkNimbusCloudVolumeMapper> mapper;
  mapper->SetInputData(scene.Density);
  mapper->SetRenderingMethodToRayMarching();
  mapper->SetSunElevationDegrees(scene.SunElevation);
  mapper->SetMieScatteringPerMetre(scene.Mie);
  mapper->SetMultipleScatteringMethodToNone();
  bench.Volume->SetMapper(mapper);
  const int march = vtkNimbusCloudVolumeMapper::LightShaftsByRayMarching;
  const int planes = vtkNimbusCloudVolumeMapper::LightShaftsByVirtualPlanes;
  std::printf("\n%s (multiple scattering off; median over %d pairs of frames with and "
              "without the lights)\n\n| lights | method | samples or planes | shafts on 1 in n "
              "pixels per side | shadow map | without, ms | with, ms | with / without "
              "|\n|---|---|---|---|---|---|---|---|\n",
    title, Frames);
  for (const LightsRow& row : std::vector<LightsRow>{ { 1, march, 32, 2, 256 },
         { 1, march, 16, 2, 256 }, { 1, march, 64, 2, 256 }, { 1, march, 32, 1, 256 },
         { 1, march, 32, 4, 256 }, { 1, march, 32, 2, 0 }, { 1, march, 32, 2, 1024 },
         { 4, march, 32, 2, 256 }, { 1, planes, 32, 1, 256 }, { 1, planes, 64, 1, 256 } })
  {
    bench.Renderer->RemoveAllLights();
    for (int i = 0; i < row.Lights; ++i)
    {
      bench.Renderer->AddLight(scene.Lights[i]);
    }
    mapper->SetLightShaftMethod(row.Method);
    mapper->SetLightSamples(row.Samples);
    mapper->SetNumberOfVirtualPlanes(row.Samples);
    mapper->SetLightShaftDownsampling(row.Downsampling);
    mapper->SetLightShadowMapSize(row.Maps);
    std::vector<double> with, without, ratios;
    for (int k = -1; k < Frames; ++k) // k = -1: the settings' first frames, not timed
    {
      double pair[2];
      for (int on = 0; on < 2; ++on)
      {
        mapper->SetLightSources(
          on ? vtkNimbusCloudVolumeMapper::PositionalLights : vtkNimbusCloudVolumeMapper::NoLights);
        bench.Window->Render(); // the change's own frame
        camera->Azimuth(k % 2 ? 0.01 : -0.01);
        const auto start = std::chrono::steady_clock::now();
        bench.Window->Render();
        bench.Window->WaitForCompletion();
        pair[on] =
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
            .count();
      }
      if (k >= 0)
      {
        without.push_back(pair[0]);
        with.push_back(pair[1]);
        ratios.push_back(pair[1] / pair[0]);
      }
    }
    const auto median = [](std::vector<double> v)
    {
      std::sort(v.begin(), v.end());
      return v[v.size() / 2];
    };
    std::printf("| %d | %s | %d | %d | %d | %.1f | %.1f | %.2f |\n", row.Lights,
      row.Method == march ? "ray march" : "virtual planes", row.Samples, row.Downsampling, row.Maps,
      median(without), median(with), median(ratios));
    std::fflush(stdout);
  }
  bench.Volume->SetMapper(nullptr);
  mapper->ReleaseGraphicsResources(bench.Window);
  bench.Renderer->RemoveAllLights();
  bench.Renderer->RemoveActor(occluder);
}

double TimeVtkGpu(vtkImageData* image, double reach)
{
  Bench& bench = *TheBench;
  vtkNew<vtkGPUVolumeRayCastMapper> mapper;
  mapper->SetInputData(image);
  mapper->AutoAdjustSampleDistancesOff();
  const double spacing = image->GetSpacing()[0];
  mapper->SetSampleDistance(0.5 * spacing);
  mapper->SetVolumetricScatteringBlending(1.0);
  mapper->SetGlobalIlluminationReach(reach);
  vtkNew<vtkPiecewiseFunction> opacity;
  opacity->AddPoint(0.0, 0.0);
  opacity->AddPoint(3.0, 1.0 - std::exp(-0.02 * 3.0 * spacing));
  vtkNew<vtkColorTransferFunction> color;
  color->AddRGBPoint(0.0, 1, 1, 1);
  vtkNew<vtkVolumeProperty> property;
  property->SetScalarOpacity(opacity);
  property->SetColor(color);
  property->SetScalarOpacityUnitDistance(spacing);
  property->SetInterpolationTypeToLinear();
  property->ShadeOn();
  property->SetScatteringAnisotropy(0.85);
  bench.Volume->SetProperty(property);
  bench.Volume->SetMapper(mapper);
  const double t = bench.Time();
  bench.Volume->SetMapper(nullptr);
  mapper->ReleaseGraphicsResources(bench.Window);
  return t;
}
}

int main(int argc, char* argv[])
{
  // --offscreen or NIMBUS_OFFSCREEN=egl: render on an EGL pbuffer, no X server.
  if (vtkNimbusOffscreenRenderWindow::InstallIfRequested(argc, argv) < 0)
  {
    return 2;
  }
  if (argc > 1)
    Frames = std::max(1, std::atoi(argv[1]));
  if (argc > 2)
    Width = std::max(16, std::atoi(argv[2]));
  if (argc > 3)
    Height = std::max(16, std::atoi(argv[3]));
  if (argc > 4 && std::isdigit(static_cast<unsigned char>(argv[4][0])))
    ExtraSide = std::max(2, std::atoi(argv[4]));
  std::printf("BenchCloudVolumeMapper: %dx%d pixels, median of %d frames, times in ms\n", Width,
    Height, Frames);
  Bench bench;
  TheBench = &bench;
  const auto none = [](vtkNimbusCloudVolumeMapper*) {};
  const auto cloudOnly = [](vtkNimbusCloudVolumeMapper* m)
  {
    m->SetAtmosphere(false);
    m->SetGround(false);
  };
  const auto unlit = [](vtkNimbusCloudVolumeMapper* m) { m->SetUnlit(true); };

  if (argc > 4 && std::string(argv[4]) == "lights")
  {
    LightsTable("A street lamp in fog at night, a post in the beam", LampInFog());
    LightsTable("A 128^3 cloud at night lit by spotlights from the ground", CloudAtNight());
    return EXIT_SUCCESS;
  }
  if (argc > 4 && std::string(argv[4]) == "march")
  {
    RayMarchTables();
    return EXIT_SUCCESS;
  }
  if (argc > 4 && std::string(argv[4]) == "sky")
  {
    // Sky at 65 deg (as the mapper's sun here); tables built in the warm-up frame.
    vtkNew<vtkNimbusSkyBackground> sky;
    sky->GetSky()->SetSunElevationDegrees(65);
    sky->GetSky()->SetSunAzimuthDegrees(135);
    const double empty = bench.Time();
    bench.Renderer->AddViewProp(sky);
    const double skyOnly = bench.Time();
    bench.Renderer->RemoveViewProp(sky);
    std::printf("\n| frame | ms | / empty |\n|---|---|---|\n| empty | %.2f | 1 |\n"
                "| sky background only | %.2f | %.1f |\n",
      empty, skyOnly, skyOnly / empty);
    vtkSmartPointer<vtkImageData> c = nimbus::testing::TestCumulus(128, 128, 128);
    std::printf("\n| cloud 128^3 | mapper's own atmosphere, ms | over the sky, ms | sky adds "
                "|\n|---|---|---|---|\n");
    const auto overSky = [&sky](vtkNimbusCloudVolumeMapper* m) { m->SetSkyBackground(sky); };
    for (int slices : { 64, 256 })
    {
      const double own = TimeSvs(c, slices, none);
      bench.Renderer->AddViewProp(sky);
      const double over = TimeSvs(c, slices, overSky);
      bench.Renderer->RemoveViewProp(sky);
      std::printf(
        "| %d slices | %.1f | %.1f | %+.1f %% |\n", slices, own, over, 100.0 * (over - own) / own);
    }
    return EXIT_SUCCESS;
  }

  vtkSmartPointer<vtkImageData> c128 = nimbus::testing::TestCumulus(128, 128, 128);
  std::printf("\n| volume | slices | full scene | cloud only (no air, no ground) | unlit floor | "
              "cloud only / floor | full / floor |\n|---|---|---|---|---|---|---|\n");
  for (int slices : { 64, 128, 256, 512 })
  {
    const double full = TimeSvs(c128, slices, none);
    const double cloud = TimeSvs(c128, slices, cloudOnly);
    const double floor = TimeSvs(c128, slices, unlit);
    std::printf("| 128^3 | %d | %.1f | %.1f | %.1f | %.2f | %.2f |\n", slices, full, cloud, floor,
      cloud / floor, full / floor);
  }
  std::vector<std::array<int, 3>> volumes{ { 64, 64, 64 }, { 256, 256, 64 } };
  if (ExtraSide > 0)
  {
    volumes.push_back({ ExtraSide, ExtraSide, ExtraSide }); // e.g. one node's piece of 2048^3
  }
  for (const auto& dims : volumes)
  {
    vtkSmartPointer<vtkImageData> c = nimbus::testing::TestCumulus(dims[0], dims[1], dims[2]);
    const double full = TimeSvs(c, 256, none);
    const double cloud = TimeSvs(c, 256, cloudOnly);
    const double floor = TimeSvs(c, 256, unlit);
    std::printf("| %dx%dx%d | 256 | %.1f | %.1f | %.1f | %.2f | %.2f |\n", dims[0], dims[1],
      dims[2], full, cloud, floor, cloud / floor, full / floor);
  }

  std::printf("\nComponents (128^3, 256 slices): each switched off alone\n\n| configuration | ms | "
              "saving vs full |\n|---|---|---|\n");
  const double full = TimeSvs(c128, 256, none);
  std::printf("| full (atmosphere, ground, shafts) | %.1f | |\n", full);
  const std::vector<std::pair<std::string, std::function<void(vtkNimbusCloudVolumeMapper*)>>>
    parts = {
      { "no shafts", [](vtkNimbusCloudVolumeMapper* m) { m->SetShafts(false); } },
      { "no ground", [](vtkNimbusCloudVolumeMapper* m) { m->SetGround(false); } },
      { "no atmosphere", [](vtkNimbusCloudVolumeMapper* m) { m->SetAtmosphere(false); } },
      { "no atmosphere, no ground", cloudOnly },
      { "atmosphere steps 64 (default 16)",
        [](vtkNimbusCloudVolumeMapper* m) { m->SetAtmosphereSteps(64); } },
      { "shadow surface 256 (default 512)",
        [](vtkNimbusCloudVolumeMapper* m) { m->SetShadowSurfaceSize(256); } },
    };
  for (const auto& part : parts)
  {
    const double t = TimeSvs(c128, 256, part.second);
    std::printf("| %s | %.1f | %.0f %% |\n", part.first.c_str(), t, 100.0 * (full - t) / full);
  }

  std::printf(
    "\nVTK's vtkGPUVolumeRayCastMapper, volumetric scattering, sample distance 0.5 voxel "
    "(128^3)\n\n| GlobalIlluminationReach | ms | / SVS 256 slices full |\n|---|---|---|\n");
  for (double reach : { 0.0, 0.5, 1.0 })
  {
    const double t = TimeVtkGpu(c128, reach);
    std::printf("| %.1f | %.1f | %.2f |\n", reach, t, t / full);
  }
  return EXIT_SUCCESS;
}
