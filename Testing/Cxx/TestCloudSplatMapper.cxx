// Image test: a metaball cloud (vtkNimbusMetaballCloudSource's balls, port 1) drawn by
// billboard splatting (vtkNimbusCloudSplatMapper, 002 §3.3) with the sun's light from the
// accumulation texture (integrated along each fragment's ray: SunLightSamples 8),
// compared with a baseline PNG (criteria: ImageComparison.h); the same frame with the
// sun's light read back per ball (the paper's variant) must agree with the texture's
// per-ball light (SunLightSamples 0) to an RMSE of 6 (8-bit), and a frame that moves
// only the camera must not redo the sun pass's work; bad balls are skipped and a missing
// array named. Over a Nimbus sky (SetSkyBackground) the same balls are compared with a
// second baseline (<baseline>_sky.png): the sky's light must make them brighter,
// the air between a far camera and them must bring them toward the sky behind, and the
// mapper's own sun must not matter while it follows the sky.
//
//   TestCloudSplatMapper <baseline.png> <output dir>
#include "vtkNimbusCloudSplatMapper.h"
#include "vtkNimbusMetaballCloudSource.h"
#include "vtkNimbusOffscreenRenderWindow.h"
#include "vtkNimbusSky.h"
#include "vtkNimbusSkyBackground.h"

#include "vtkActor.h"
#include "vtkAlgorithmOutput.h"
#include "vtkCamera.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkNew.h"
#include "vtkPNGWriter.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkUnsignedCharArray.h"
#include "vtkWindowToImageFilter.h"

#include "ImageComparison.h"
#include "MessageCatcher.h"

#include <array>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <string>

namespace
{
vtkSmartPointer<vtkImageData> Capture(vtkRenderWindow* window)
{
  vtkNew<vtkWindowToImageFilter> capture;
  capture->SetInput(window);
  capture->ReadFrontBufferOff();
  capture->Update();
  vtkSmartPointer<vtkImageData> image = capture->GetOutput();
  return image;
}

double Rmse(vtkImageData* a, vtkImageData* b)
{
  vtkDataArray* x = a->GetPointData()->GetScalars();
  vtkDataArray* y = b->GetPointData()->GetScalars();
  double sum = 0.0;
  vtkIdType count = 0;
  for (vtkIdType i = 0; i < x->GetNumberOfTuples(); ++i)
  {
    for (int c = 0; c < 3; ++c)
    {
      const double d = x->GetComponent(i, c) - y->GetComponent(i, c);
      sum += d * d;
      ++count;
    }
  }
  return std::sqrt(sum / std::max<vtkIdType>(count, 1));
}

double MeanValue(vtkImageData* image)
{
  vtkDataArray* x = image->GetPointData()->GetScalars();
  double sum = 0.0;
  for (vtkIdType i = 0; i < x->GetNumberOfTuples(); ++i)
  {
    sum += x->GetComponent(i, 0) + x->GetComponent(i, 1) + x->GetComponent(i, 2);
  }
  return sum / std::max<vtkIdType>(3 * x->GetNumberOfTuples(), 1);
}
}

// The mean colour (8-bit) of `image` where `reference` and `other` differ by more than 6
// in some channel.
std::array<double, 3> MeanWhereDifferent(
  vtkImageData* image, vtkImageData* reference, vtkImageData* other)
{
  auto* x = vtkUnsignedCharArray::SafeDownCast(image->GetPointData()->GetScalars());
  auto* r = vtkUnsignedCharArray::SafeDownCast(reference->GetPointData()->GetScalars());
  auto* o = vtkUnsignedCharArray::SafeDownCast(other->GetPointData()->GetScalars());
  std::array<double, 3> sum{ { 0.0, 0.0, 0.0 } };
  vtkIdType count = 0;
  for (vtkIdType i = 0; i < x->GetNumberOfTuples(); ++i)
  {
    double difference = 0.0;
    for (int c = 0; c < 3; ++c)
    {
      difference = std::max(
        difference, std::abs(r->GetTypedComponent(i, c) - 1.0 * o->GetTypedComponent(i, c)));
    }
    if (difference > 6.0)
    {
      for (int c = 0; c < 3; ++c)
      {
        sum[c] += x->GetTypedComponent(i, c);
      }
      ++count;
    }
  }
  for (double& c : sum)
  {
    c /= std::max<vtkIdType>(count, 1);
  }
  return sum;
}

double ColourDistance(const std::array<double, 3>& a, const std::array<double, 3>& b)
{
  return std::sqrt(
    (a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}

// The balls over a Nimbus sky (the sun 30 degrees up behind the camera's left): the
// picture against its baseline; the sky's light (brighter balls in every channel); the air
// (a camera 30 km away sees the balls closer to the sky's colour behind them with it
// than without); the mapper's own sun ignored while it follows the sky.
bool CheckSky(vtkAlgorithmOutput* balls, const std::string& baseline, const std::string& outputDir)
{
  vtkNew<vtkNimbusSkyBackground> background;
  background->GetSky()->SetSunElevationDegrees(30.0);
  background->GetSky()->SetSunAzimuthDegrees(210.0);
  vtkNew<vtkNimbusCloudSplatMapper> mapper;
  mapper->SetInputConnection(balls);
  mapper->SetExtinctionPerDensity(0.004);
  mapper->SetMultipleScatteringGridSize(16); // the sky light's solve
  mapper->SetSkyBackground(background);
  vtkNew<vtkActor> actor;
  actor->SetMapper(mapper);
  vtkNew<vtkRenderer> renderer;
  renderer->AddViewProp(background); // before the balls: they composite over the sky
  renderer->AddActor(actor);
  vtkCamera* camera = renderer->GetActiveCamera();
  camera->SetPosition(0.0, -6000.0, 1500.0);
  camera->SetFocalPoint(0.0, 0.0, 1600.0);
  camera->SetViewUp(0.0, 0.0, 1.0);
  camera->SetViewAngle(35.0);
  camera->SetClippingRange(100.0, 50000.0);
  vtkNew<vtkRenderWindow> window;
  window->SetSize(320, 240);
  window->SetMultiSamples(0);
  window->AddRenderer(renderer);
  window->Render();
  vtkSmartPointer<vtkImageData> sky = Capture(window);
  const std::string image = outputDir + "/TestCloudSplatMapper_sky.png";
  vtkNew<vtkPNGWriter> writer;
  writer->SetFileName(image.c_str());
  writer->SetInputData(sky);
  writer->Write();
  bool ok = nimbus::testing::CompareImageFiles(
    image, baseline, outputDir, nimbus::testing::ImageComparisonLimits(), std::cout);

  actor->VisibilityOff();
  window->Render();
  vtkSmartPointer<vtkImageData> clear = Capture(window);
  actor->VisibilityOn();
  mapper->SkyLightOff();
  window->Render();
  vtkSmartPointer<vtkImageData> unlit = Capture(window);
  const auto lit = MeanWhereDifferent(sky, sky, clear);
  const auto dark = MeanWhereDifferent(unlit, sky, clear);
  std::cout << "sky light: balls " << dark[0] << " " << dark[1] << " " << dark[2] << " -> "
            << lit[0] << " " << lit[1] << " " << lit[2] << " (8-bit, sRGB)\n";
  if (!(lit[0] > dark[0] + 10.0 && lit[1] > dark[1] + 10.0 && lit[2] > dark[2] + 10.0))
  {
    std::cerr << "the sky's light does not brighten the balls\n";
    ok = false;
  }
  mapper->SkyLightOn();

  // 30 km away: the air between brings the balls toward the sky behind them.
  camera->SetPosition(0.0, -30000.0, 1500.0);
  window->Render();
  vtkSmartPointer<vtkImageData> hazed = Capture(window);
  actor->VisibilityOff();
  window->Render();
  vtkSmartPointer<vtkImageData> farClear = Capture(window);
  actor->VisibilityOn();
  mapper->AerialPerspectiveOff();
  window->Render();
  vtkSmartPointer<vtkImageData> clean = Capture(window);
  mapper->AerialPerspectiveOn();
  const auto behind = MeanWhereDifferent(farClear, clean, farClear);
  const double withAir = ColourDistance(MeanWhereDifferent(hazed, clean, farClear), behind);
  const double withoutAir = ColourDistance(MeanWhereDifferent(clean, clean, farClear), behind);
  std::cout << "air at 30 km: the balls' colour " << withoutAir << " -> " << withAir
            << " from the sky's behind them (8-bit)\n";
  if (!(withAir < 0.8 * withoutAir))
  {
    std::cerr << "the air does not bring far balls toward the sky's colour\n";
    ok = false;
  }

  // The mapper's own sun is not used while it follows the sky.
  mapper->SetSunElevationDegrees(-60.0);
  window->Render();
  const double own = Rmse(hazed, Capture(window));
  if (!(own < 0.5))
  {
    std::cerr << "the mapper's own sun changes the picture over the sky (RMSE " << own << ")\n";
    ok = false;
  }
  return ok;
}

int main(int argc, char* argv[])
{
  if (vtkNimbusOffscreenRenderWindow::InstallIfRequested(argc, argv) < 0)
  {
    return 2;
  }
  if (argc != 3)
  {
    std::cerr << "usage: TestCloudSplatMapper baseline.png outputdir\n";
    return EXIT_FAILURE;
  }
  const std::string baseline = argv[1];
  const std::string outputDir = argv[2];

  vtkNew<vtkNimbusMetaballCloudSource> cloud;
  cloud->SetDimensions(40, 40, 28);
  cloud->SetSeed(3);
  cloud->Update();

  vtkNew<vtkNimbusCloudSplatMapper> mapper;
  mapper->SetInputConnection(cloud->GetOutputPort(1));
  mapper->SetSunElevationDegrees(25.0);
  mapper->SetSunAzimuthDegrees(30.0);
  mapper->SetExposure(10.0);
  mapper->SetSunTextureSize(256);
  mapper->SetExtinctionPerDensity(0.004); // optically thinner than the default: light gets through
  vtkNew<vtkActor> actor;
  actor->SetMapper(mapper);

  vtkNew<vtkRenderer> renderer;
  renderer->AddActor(actor);
  renderer->SetBackground(0.25, 0.42, 0.72);
  vtkCamera* camera = renderer->GetActiveCamera();
  camera->SetPosition(0.0, -6000.0, 1500.0);
  camera->SetFocalPoint(0.0, 0.0, 1600.0);
  camera->SetViewUp(0.0, 0.0, 1.0);
  camera->SetViewAngle(35.0);
  camera->SetClippingRange(100.0, 20000.0);

  vtkNew<vtkRenderWindow> window;
  window->SetSize(320, 240);
  window->SetMultiSamples(0);
  window->AddRenderer(renderer);
  window->Render();
  if (mapper->GetLastNumberOfBalls() < 100)
  {
    std::cerr << "expected the cloud's balls, drew " << mapper->GetLastNumberOfBalls() << "\n";
    return EXIT_FAILURE;
  }
  vtkSmartPointer<vtkImageData> texture = Capture(window);
  const std::string image = outputDir + "/TestCloudSplatMapper.png";
  vtkNew<vtkPNGWriter> writer;
  writer->SetFileName(image.c_str());
  writer->SetInputData(texture);
  writer->Write();
  bool ok = nimbus::testing::CompareImageFiles(
    image, baseline, outputDir, nimbus::testing::ImageComparisonLimits(), std::cout);

  // The paper's read-back gives nearly the same picture as the accumulation texture with
  // the light taken at each ball's centre (SunLightSamples 0): it takes each ball's light
  // before the balls behind its centre plane, the texture between two planes.
  mapper->SetSunLightSamples(0);
  window->Render();
  vtkSmartPointer<vtkImageData> centre = Capture(window);
  mapper->SetSunLightMethodToFramebufferReadBack();
  window->Render();
  vtkSmartPointer<vtkImageData> readBack = Capture(window);
  const double rmse = Rmse(centre, readBack);
  std::cout << "read-back vs accumulation texture: RMSE " << rmse << " (8-bit)\n";
  writer->SetFileName((outputDir + "/TestCloudSplatMapper_readback.png").c_str());
  writer->SetInputData(readBack);
  writer->Write();
  if (!(rmse < 6.0))
  {
    std::cerr << "the read-back variant differs from the accumulation texture's\n";
    ok = false;
  }

  // Moving the camera only: the sun pass is not redone (its time is the check's).
  mapper->SetSunLightMethodToAccumulationTexture();
  mapper->SetSunLightSamples(8);
  window->Render();
  camera->Azimuth(20.0);
  window->Render();
  if (mapper->GetLastSunPassSeconds() > 1e-3)
  {
    std::cerr << "the sun pass ran again for a camera move (" << mapper->GetLastSunPassSeconds()
              << " s)\n";
    ok = false;
  }

  // Multiple scattering on: the cloud brighter (the light scattered more than once added;
  // the mean over the whole frame, blue sky included, measured 1.09 x),
  // solved once, again for a new sun, not for a camera move; off again for what follows.
  {
    const double single = MeanValue(Capture(window));
    mapper->MultipleScatteringOn();
    mapper->SetMultipleScatteringGridSize(16);
    window->Render();
    vtkSmartPointer<vtkImageData> multiple = Capture(window);
    writer->SetFileName((outputDir + "/TestCloudSplatMapper_multiple.png").c_str());
    writer->SetInputData(multiple);
    writer->Write();
    const double brighter = MeanValue(multiple) / std::max(single, 1e-30);
    const int solves = mapper->GetNumberOfMultipleScatteringSolves();
    camera->Azimuth(-10.0);
    window->Render();
    const int afterCamera = mapper->GetNumberOfMultipleScatteringSolves();
    mapper->SetSunAzimuthDegrees(mapper->GetSunAzimuthDegrees() + 10.0);
    window->Render();
    const int afterSun = mapper->GetNumberOfMultipleScatteringSolves();
    std::cout << "multiple scattering: mean " << brighter << " x single, solve "
              << mapper->GetLastMultipleScatteringSeconds() << " s\n";
    if (!(brighter > 1.05) || solves != 1 || afterCamera != 1 || afterSun != 2)
    {
      std::cerr << "multiple scattering: " << brighter << " x the single scattering's mean, "
                << solves << ", " << afterCamera << ", " << afterSun
                << " solves (expected > 1.05 x; 1, 1, 2)\n";
      ok = false;
    }
    mapper->MultipleScatteringOff();
    mapper->SetSunAzimuthDegrees(mapper->GetSunAzimuthDegrees() - 10.0);
  }

  // Bad input: a missing array is named once and nothing is drawn; balls with NaN,
  // infinite, zero or negative radii or densities are skipped (the others drawn).
  {
    vtkNew<vtkPolyData> balls;
    vtkNew<vtkPoints> points;
    vtkNew<vtkFloatArray> radius;
    vtkNew<vtkFloatArray> density;
    radius->SetName("radius");
    density->SetName("density");
    const float nan = std::nanf("");
    const float values[5][2] = { { 300.0f, 1.0f }, { nan, 1.0f }, { 300.0f, INFINITY },
      { -5.0f, 1.0f }, { 200.0f, 0.0f } };
    for (int i = 0; i < 5; ++i)
    {
      points->InsertNextPoint(300.0 * i - 600.0, 0.0, 1600.0);
      radius->InsertNextValue(values[i][0]);
      density->InsertNextValue(values[i][1]);
    }
    balls->SetPoints(points);
    balls->GetPointData()->AddArray(radius);
    balls->GetPointData()->AddArray(density);
    mapper->SetInputData(balls);
    nimbus::testing::MessageCatcher catcher(mapper);
    window->Render();
    if (mapper->GetLastNumberOfBalls() != 1 || !catcher.Errors.empty())
    {
      std::cerr << "bad balls: drew " << mapper->GetLastNumberOfBalls()
                << " (expected 1), errors: " << catcher.AllErrors() << "\n";
      ok = false;
    }
    mapper->SetSunElevationDegrees(std::nan(""));
    mapper->SetExtinctionPerDensity(INFINITY);
    if (catcher.Errors.size() != 2 || mapper->GetSunElevationDegrees() != 25.0 ||
      mapper->GetExtinctionPerDensity() != 0.004)
    {
      std::cerr << "non-finite settings not refused: " << catcher.AllErrors() << "\n";
      ok = false;
    }
    catcher.Errors.clear();
    mapper->SetDensityArrayName("no such array");
    window->Render();
    window->Render();
    if (mapper->GetLastNumberOfBalls() != 0 || catcher.Errors.size() != 1 ||
      catcher.Errors[0].find("no such array") == std::string::npos)
    {
      std::cerr << "missing array: drew " << mapper->GetLastNumberOfBalls()
                << ", errors: " << catcher.AllErrors() << "\n";
      ok = false;
    }
  }
  const std::string skyBaseline = baseline.substr(0, baseline.size() - 4) + "_sky.png";
  ok = CheckSky(cloud->GetOutputPort(1), skyBaseline, outputDir) && ok;
  return ok ? EXIT_SUCCESS : EXIT_FAILURE;
}
