// Image tests of the sky pass (vtkNimbusSkyPass): noon, sunset and twilight skies
// and a scene with aerial perspective (ground, distant boxes and hills), compared with
// Data/Baseline/TestSkyImage_<mode>.png (ImageComparison.h criteria). Usage: TestSkyImage <mode>
// <baseline.png> <outputdir>.
#include "ImageComparison.h"

#include "vtkNimbusOffscreenRenderWindow.h"
#include "vtkNimbusSky.h"
#include "vtkNimbusSkyPass.h"
#include "vtkNimbusSunlight.h"

#include "vtkActor.h"
#include "vtkCamera.h"
#include "vtkConeSource.h"
#include "vtkCubeSource.h"
#include "vtkLight.h"
#include "vtkMath.h"
#include "vtkNew.h"
#include "vtkOpenGLRenderer.h"
#include "vtkPNGWriter.h"
#include "vtkPlaneSource.h"
#include "vtkPolyDataMapper.h"
#include "vtkProperty.h"
#include "vtkRenderStepsPass.h"
#include "vtkRenderWindow.h"
#include "vtkWindowToImageFilter.h"

#include <cmath>
#include <cstdlib>
#include <iostream>
#include <string>

namespace
{
void AddActor(vtkRenderer* renderer, vtkAlgorithm* source, double r, double g, double b)
{
  vtkNew<vtkPolyDataMapper> mapper;
  mapper->SetInputConnection(source->GetOutputPort());
  vtkNew<vtkActor> actor;
  actor->SetMapper(mapper);
  actor->GetProperty()->SetColor(r, g, b);
  actor->GetProperty()->SetDiffuse(0.8);
  actor->GetProperty()->SetAmbient(0.2);
  renderer->AddActor(actor);
}
}

int main(int argc, char* argv[])
{
  // --offscreen or NIMBUS_OFFSCREEN=egl: render on an EGL pbuffer, no X server.
  if (vtkNimbusOffscreenRenderWindow::InstallIfRequested(argc, argv) < 0)
  {
    return 2;
  }
  if (argc != 4)
  {
    std::cerr << "usage: TestSkyImage noon|sunset|twilight|aerial baseline.png outputdir\n";
    return EXIT_FAILURE;
  }
  const std::string mode = argv[1];
  vtkNew<vtkNimbusSky> sky;
  vtkNew<vtkOpenGLRenderer> renderer;
  vtkCamera* camera = renderer->GetActiveCamera();
  camera->SetViewUp(0.0, 0.0, 1.0);
  if (mode == "noon" || mode == "sunset" || mode == "twilight")
  {
    sky->SetPreset(mode == "noon"
        ? vtkNimbusSky::Noon
        : (mode == "sunset" ? vtkNimbusSky::Sunset : vtkNimbusSky::Twilight));
    sky->SetExposure(mode == "noon" ? 12.0 : (mode == "sunset" ? 25.0 : 400.0));
    // Looking toward the sun's azimuth, a little above the horizon, wide angle.
    const double a =
      vtkMath::RadiansFromDegrees(sky->GetSunAzimuthDegrees() + (mode == "noon" ? 180.0 : 0.0));
    camera->SetPosition(0.0, 0.0, 2.0);
    camera->SetFocalPoint(std::sin(a), std::cos(a), 2.0 + (mode == "noon" ? 0.45 : 0.25));
    camera->SetViewAngle(80.0);
    camera->SetClippingRange(0.1, 10.0);
  }
  else if (mode == "aerial")
  {
    sky->SetPreset(vtkNimbusSky::Afternoon);
    sky->SetSunAzimuthDegrees(150.0);
    sky->SetExposure(12.0);
    sky->SetTurbidity(3.0); // clear, a little hazier than the default (aerosol optical depth 0.20)
    vtkNew<vtkPlaneSource> ground;
    ground->SetOrigin(-2.0e5, -2.0e5, 0.0);
    ground->SetPoint1(2.0e5, -2.0e5, 0.0);
    ground->SetPoint2(-2.0e5, 2.0e5, 0.0);
    AddActor(renderer, ground, 0.35, 0.45, 0.25);
    // Boxes 2..40 km away and hills 10..60 km away.
    const double boxes[][2] = { { -400.0, 2000.0 }, { 900.0, 5000.0 }, { -2500.0, 12000.0 },
      { 5000.0, 25000.0 }, { -12000.0, 40000.0 } };
    for (const auto& b : boxes)
    {
      vtkNew<vtkCubeSource> box;
      box->SetCenter(b[0], b[1], 150.0);
      box->SetXLength(300.0);
      box->SetYLength(300.0);
      box->SetZLength(300.0);
      AddActor(renderer, box, 0.8, 0.3, 0.2);
    }
    const double hills[][3] = { { 15000.0, 30000.0, 2500.0 }, { -8000.0, 20000.0, 1200.0 },
      { -30000.0, 60000.0, 5000.0 } };
    for (const auto& h : hills)
    {
      vtkNew<vtkConeSource> cone;
      cone->SetCenter(h[0], h[1], 0.5 * h[2]);
      cone->SetDirection(0.0, 0.0, 1.0);
      cone->SetHeight(h[2]);
      cone->SetRadius(2.5 * h[2]);
      cone->SetResolution(48);
      AddActor(renderer, cone, 0.3, 0.4, 0.3);
    }
    // No cloud volume here: VTK's vtkGPUVolumeRayCastMapper fails to copy the
    // depth of this pass's framebuffer (GL_INVALID_OPERATION in its
    // CaptureDepthTexture blit, measured) and draws nothing; clouds get the sky
    // through the Nimbus cloud mapper (vtkNimbusCloudVolumeMapper) instead.
    vtkNew<vtkNimbusSunlight> sun;
    sun->SetSunElevationDegrees(sky->GetSunElevationDegrees());
    sun->SetSunAzimuthDegrees(sky->GetSunAzimuthDegrees());
    vtkNew<vtkLight> light;
    sun->ApplyToLight(light);
    renderer->AddLight(light);
    camera->SetPosition(0.0, -3000.0, 300.0);
    camera->SetFocalPoint(0.0, 10000.0, 600.0);
    camera->SetViewAngle(50.0);
    camera->SetClippingRange(100.0, 3.0e5);
  }
  else
  {
    std::cerr << "unknown mode " << mode << "\n";
    return EXIT_FAILURE;
  }

  vtkNew<vtkRenderStepsPass> steps;
  vtkNew<vtkNimbusSkyPass> pass;
  pass->SetSky(sky);
  pass->SetDelegatePass(steps);
  renderer->SetPass(pass);

  vtkNew<vtkRenderWindow> window;
  window->SetSize(320, 240);
  window->SetMultiSamples(0);
  window->AddRenderer(renderer);
  window->Render();

  vtkNew<vtkWindowToImageFilter> capture;
  capture->SetInput(window);
  capture->ReadFrontBufferOff();
  const std::string image = std::string(argv[3]) + "/TestSkyImage_" + mode + ".png";
  vtkNew<vtkPNGWriter> writer;
  writer->SetFileName(image.c_str());
  writer->SetInputConnection(capture->GetOutputPort());
  writer->Write();
  const bool same = nimbus::testing::CompareImageFiles(
    image, argv[2], argv[3], nimbus::testing::ImageComparisonLimits(), std::cout);
  return same ? EXIT_SUCCESS : EXIT_FAILURE;
}
