// Benchmark (not a test) of vtkNimbusSkyPass per frame: mean frame time of
// (a) an empty renderer, (b) the same with the sky pass (background only),
// (c) a scene of 5 boxes + ground without and (d) with the pass (aerial
// perspective). Tables are built before timing (the first frame). Usage:
// BenchSkyPass [frames=30] [width=640] [height=480]
#include "vtkNimbusOffscreenRenderWindow.h"
#include "vtkNimbusSky.h"
#include "vtkNimbusSkyPass.h"

#include "vtkActor.h"
#include "vtkCamera.h"
#include "vtkCubeSource.h"
#include "vtkNew.h"
#include "vtkOpenGLRenderer.h"
#include "vtkPlaneSource.h"
#include "vtkPolyDataMapper.h"
#include "vtkRenderStepsPass.h"
#include "vtkRenderWindow.h"

#include <chrono>
#include <cstdio>
#include <cstdlib>

namespace
{
double FrameSeconds(bool scene, bool sky, int frames, int width, int height)
{
  vtkNew<vtkOpenGLRenderer> renderer;
  vtkNew<vtkNimbusSky> nimbusSky;
  nimbusSky->SetPreset(vtkNimbusSky::Afternoon);
  vtkNew<vtkRenderStepsPass> steps;
  vtkNew<vtkNimbusSkyPass> pass;
  pass->SetSky(nimbusSky);
  pass->SetDelegatePass(steps);
  if (sky)
  {
    renderer->SetPass(pass);
  }
  if (scene)
  {
    vtkNew<vtkPlaneSource> ground;
    ground->SetOrigin(-1e5, -1e5, 0);
    ground->SetPoint1(1e5, -1e5, 0);
    ground->SetPoint2(-1e5, 1e5, 0);
    vtkNew<vtkPolyDataMapper> gm;
    gm->SetInputConnection(ground->GetOutputPort());
    vtkNew<vtkActor> ga;
    ga->SetMapper(gm);
    renderer->AddActor(ga);
    for (int i = 0; i < 5; ++i)
    {
      vtkNew<vtkCubeSource> box;
      box->SetCenter(-2000.0 + 1000.0 * i, 3000.0 * (i + 1), 150.0);
      box->SetXLength(300);
      box->SetYLength(300);
      box->SetZLength(300);
      vtkNew<vtkPolyDataMapper> m;
      m->SetInputConnection(box->GetOutputPort());
      vtkNew<vtkActor> a;
      a->SetMapper(m);
      renderer->AddActor(a);
    }
  }
  vtkCamera* camera = renderer->GetActiveCamera();
  camera->SetPosition(0, -3000, 300);
  camera->SetFocalPoint(0, 10000, 600);
  camera->SetViewUp(0, 0, 1);
  camera->SetViewAngle(50);
  camera->SetClippingRange(100, 3e5);
  vtkNew<vtkRenderWindow> window;
  window->SetSize(width, height);
  window->SetMultiSamples(0);
  window->AddRenderer(renderer);
  window->Render(); // builds the tables and shaders
  window->Render();
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < frames; ++i)
  {
    // Turn the camera a little each frame (no table rebuild: same altitude and sun).
    camera->Azimuth(0.5);
    window->Render();
  }
  window->WaitForCompletion();
  if (sky)
  {
    std::printf("  (table builds during the run: model %d, sky view %d, aerial %d)\n",
      nimbusSky->GetModelBuilds(), nimbusSky->GetSkyViewBuilds(), nimbusSky->GetAerialBuilds());
  }
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() / frames;
}
}

int main(int argc, char* argv[])
{
  // --offscreen or NIMBUS_OFFSCREEN=egl: render on an EGL pbuffer, no X server.
  if (vtkNimbusOffscreenRenderWindow::InstallIfRequested(argc, argv) < 0)
  {
    return 2;
  }
  const int frames = argc > 1 ? std::atoi(argv[1]) : 30;
  const int width = argc > 2 ? std::atoi(argv[2]) : 640;
  const int height = argc > 3 ? std::atoi(argv[3]) : 480;
  const double empty = FrameSeconds(false, false, frames, width, height);
  const double sky = FrameSeconds(false, true, frames, width, height);
  const double scene = FrameSeconds(true, false, frames, width, height);
  const double aerial = FrameSeconds(true, true, frames, width, height);
  std::printf("frame %dx%d, mean of %d frames\n", width, height, frames);
  std::printf("empty frame            %8.2f ms\n", 1e3 * empty);
  std::printf("sky pass (background)  %8.2f ms  ratio %.2f\n", 1e3 * sky, sky / empty);
  std::printf("ground + 5 boxes       %8.2f ms\n", 1e3 * scene);
  std::printf("  + sky pass (aerial)  %8.2f ms  ratio %.2f, added %.2f ms\n", 1e3 * aerial,
    aerial / scene, 1e3 * (aerial - scene));
  return 0;
}
