// Clouds over the Nimbus sky: vtkNimbusCloudVolumeMapper given the
// vtkNimbusSkyBackground of its renderer (SetSkyBackground) follows the sky's sun
// and air and composites cloud, cloud shadow and shafts over the sky
// (I = S - T_cl S_clear + T_cl L_sky).
//
//   TestCloudSky aerial <baseline.png> <outputdir>   image test: three identical
//       cumulus 5, 13 and 31 km away in afternoon haze (aerial perspective)
//   TestCloudSky aerial-ray-march | checks-ray-march ...: the same drawn by the ray march
//       (RenderingMethod RayMarching).
//   TestCloudSky checks                              numeric checks, no baseline:
//     - a zero-density cloud leaves the sky image unchanged (max 1 of 255),
//     - a real cloud leaves the sky unchanged away from it and its shadow,
//     - the mapper takes the sky's sun (and a sky change re-lights the cloud:
//       a low sun reddens it), and with UseSceneSky off, the background hidden
//       or no background set it keeps its own,
//     - the sun at the zenith and below the horizon: finite radiance,
//     - aerial perspective: the same cloud 28 km away differs less from the sky
//       behind it than at 4 km.
#include "ImageComparison.h"

#include "vtkNimbusCloudVolumeMapper.h"
#include "vtkNimbusMetaballCloudSource.h"
#include "vtkNimbusOffscreenRenderWindow.h"
#include "vtkNimbusSky.h"
#include "vtkNimbusSkyBackground.h"

#include "vtkCamera.h"
#include "vtkDataArray.h"
#include "vtkImageData.h"
#include "vtkNew.h"
#include "vtkPNGWriter.h"
#include "vtkPointData.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkUnsignedCharArray.h"
#include "vtkVolume.h"
#include "vtkWindowToImageFilter.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <string>
#include <vector>

namespace
{
constexpr int kWidth = 320, kHeight = 240;

struct Frame
{
  std::vector<unsigned char> Rgb; // row 0 at the bottom
  int At(int x, int y, int c) const { return Rgb[3 * (y * kWidth + x) + c]; }
};

Frame Grab(vtkRenderWindow* window)
{
  window->Render();
  vtkNew<vtkWindowToImageFilter> capture;
  capture->SetInput(window);
  capture->ReadFrontBufferOff();
  capture->SetInputBufferTypeToRGB();
  capture->Update();
  auto* values =
    vtkUnsignedCharArray::SafeDownCast(capture->GetOutput()->GetPointData()->GetScalars());
  Frame frame;
  frame.Rgb.assign(values->GetPointer(0), values->GetPointer(0) + 3 * kWidth * kHeight);
  return frame;
}

// Largest channel difference over the pixels where keep(x, y).
template <typename Keep>
int MaxDifference(const Frame& a, const Frame& b, Keep keep)
{
  int worst = 0;
  for (int y = 0; y < kHeight; ++y)
  {
    for (int x = 0; x < kWidth; ++x)
    {
      if (keep(x, y))
      {
        for (int c = 0; c < 3; ++c)
        {
          worst = std::max(worst, std::abs(a.At(x, y, c) - b.At(x, y, c)));
        }
      }
    }
  }
  return worst;
}

// The method every Scene draws with (the modes ending in -ray-march set the ray march).
int gRenderingMethod = vtkNimbusCloudVolumeMapper::ShadowViewSlicing;

struct Scene
{
  vtkNew<vtkRenderer> Renderer;
  vtkNew<vtkRenderWindow> Window;
  vtkNew<vtkNimbusSkyBackground> Sky;
  vtkNew<vtkNimbusMetaballCloudSource> Cloud;
  vtkNew<vtkNimbusCloudVolumeMapper> Mapper;

  Scene()
  {
    this->Sky->GetSky()->SetPreset(vtkNimbusSky::Afternoon); // sun 30 deg, south-west
    this->Sky->GetSky()->SetExposure(10.0);
    this->Renderer->AddViewProp(this->Sky);
    this->Mapper->SetSkyBackground(this->Sky);
    this->Mapper->SetRenderingMethod(gRenderingMethod);
    this->Cloud->SetDimensions(64, 64, 48);
    this->Mapper->SetInputConnection(this->Cloud->GetOutputPort());
    this->Mapper->SetMultipleScattering(3.0);
    // The compositing over the sky is what these cases test (baselines from before
    // the multiple-scattering texture).
    this->Mapper->SetMultipleScatteringMethodToNone();
    // Baseline from before the air's multiple scattering (with it, distant clouds
    // fade a little more into the sky, as the sky's own aerial perspective does).
    this->Mapper->AirMultipleScatteringOff();
    this->Mapper->SetNumberOfSlices(128);
    this->Window->SetSize(kWidth, kHeight);
    this->Window->SetMultiSamples(0);
    this->Window->AddRenderer(this->Renderer);
    vtkCamera* camera = this->Renderer->GetActiveCamera();
    camera->SetViewUp(0.0, 0.0, 1.0);
    camera->SetPosition(0.0, -3000.0, 200.0);
    camera->SetFocalPoint(0.0, 1000.0, 900.0);
    camera->SetViewAngle(60.0);
    camera->SetClippingRange(10.0, 1e6);
  }
  vtkVolume* AddCloud(double x, double y)
  {
    vtkNew<vtkVolume> volume;
    volume->SetMapper(this->Mapper);
    volume->SetPosition(x, y, 0.0);
    this->Renderer->AddVolume(volume);
    return volume;
  }
};

bool Check(bool ok, const std::string& what)
{
  std::cout << (ok ? "ok:     " : "FAILED: ") << what << "\n";
  return ok;
}

int RunChecks()
{
  bool ok = true;
  {
    Scene scene;
    const Frame skyOnly = Grab(scene.Window);
    // A zero-density cloud: S = S_clear and T_cl = 1 everywhere.
    scene.Mapper->SetExtinctionPerDensity(0.0);
    vtkVolume* volume = scene.AddCloud(0.0, 2000.0);
    const Frame empty = Grab(scene.Window);
    const int emptyDiff = MaxDifference(skyOnly, empty, [](int, int) { return true; });
    ok &= Check(emptyDiff <= 1,
      "zero-density cloud leaves the sky unchanged: max diff " + std::to_string(emptyDiff) +
        " of 255");
    ok &= Check(scene.Mapper->GetLastRenderUsedSceneSky(), "the mapper follows the scene sky");
    // A real cloud: the sky away from it (left quarter, above the horizon) is
    // unchanged; the sun is behind-left of the camera, so the cloud's shadow
    // and shafts fall away from the camera, to the right and down.
    scene.Mapper->SetExtinctionPerDensity(0.02);
    const Frame cloudy = Grab(scene.Window);
    const int awayDiff =
      MaxDifference(skyOnly, cloudy, [](int x, int y) { return x < 60 && y > 140; });
    const int cloudDiff = MaxDifference(skyOnly, cloudy, [](int, int) { return true; });
    ok &= Check(awayDiff <= 1 && cloudDiff > 60,
      "the sky away from the cloud is unchanged (max diff " + std::to_string(awayDiff) +
        ") while the cloud is drawn (max diff " + std::to_string(cloudDiff) + ")");
    // The sun is shared: lower it on the sky and the cloud reddens.
    // Colour of the light the cloud adds to its sky: R/B of the summed positive
    // differences from the sky-only image (the sunlit parts of the cloud).
    auto cloudRedness = [&](vtkVolume* volume)
    {
      volume->VisibilityOff();
      const Frame sky = Grab(scene.Window);
      volume->VisibilityOn();
      const Frame f = Grab(scene.Window);
      double added[3] = { 0.0, 0.0, 0.0 };
      for (size_t i = 0; i < f.Rgb.size(); ++i)
      {
        added[i % 3] += std::max(0, f.Rgb[i] - sky.Rgb[i]);
      }
      return added[0] / std::max(added[2], 1.0); // at least one level of blue
    };
    const double highRedness = cloudRedness(volume);
    scene.Sky->GetSky()->SetSunElevationDegrees(4.0);
    const double lowRedness = cloudRedness(volume);
    ok &= Check(std::abs(scene.Mapper->GetLastSunElevationDegrees() - 4.0) < 1e-12,
      "the mapper lit the cloud with the sky's sun (elevation " +
        std::to_string(scene.Mapper->GetLastSunElevationDegrees()) + ")");
    ok &= Check(lowRedness > highRedness * 1.5,
      "a low sun reddens the cloud: R/B of its light " + std::to_string(highRedness) +
        " (sun 30 deg) -> " + std::to_string(lowRedness) + " (4 deg)");
    // Extremes of the shared sun: at the zenith and 6 deg below the horizon the
    // cloud's float radiance stays finite and non-negative.
    scene.Mapper->CaptureRadianceOn();
    for (double elevation : { 90.0, -6.0 })
    {
      scene.Sky->GetSky()->SetSunElevationDegrees(elevation);
      Grab(scene.Window);
      vtkDataArray* radiance =
        scene.Mapper->GetRadianceImage()->GetPointData()->GetArray("radiance");
      bool finite = radiance && radiance->GetNumberOfTuples() == kWidth * kHeight;
      for (vtkIdType i = 0; finite && i < radiance->GetNumberOfValues(); ++i)
      {
        const double v = radiance->GetVariantValue(i).ToDouble();
        finite = std::isfinite(v) && v >= 0.0;
      }
      ok &= Check(
        finite, "sun at " + std::to_string(elevation) + " deg: finite, non-negative radiance");
    }
    scene.Mapper->CaptureRadianceOff();
    scene.Mapper->UseSceneSkyOff();
    scene.Mapper->SetSunElevationDegrees(60.0);
    Grab(scene.Window);
    ok &= Check(!scene.Mapper->GetLastRenderUsedSceneSky() &&
        scene.Mapper->GetLastSunElevationDegrees() == 60.0,
      "with UseSceneSky off the mapper keeps its own sun");
    // The coupling is explicit: a hidden background, or none set, is not followed.
    scene.Mapper->UseSceneSkyOn();
    scene.Sky->VisibilityOff();
    Grab(scene.Window);
    ok &= Check(!scene.Mapper->GetLastRenderUsedSceneSky(),
      "with the sky background hidden the mapper keeps its own sun");
    scene.Sky->VisibilityOn();
    scene.Mapper->SetSkyBackground(nullptr);
    Grab(scene.Window);
    ok &= Check(!scene.Mapper->GetLastRenderUsedSceneSky(),
      "without SetSkyBackground the mapper ignores the sky in its renderer");
  }
  {
    // Aerial perspective: one cloud 4 km and 28 km away, the camera's view angle
    // scaled so that it covers the same part of the image. Contrast = mean
    // channel difference from the sky-only image over the frame.
    auto contrast = [](double distance)
    {
      Scene scene;
      vtkCamera* camera = scene.Renderer->GetActiveCamera();
      camera->SetPosition(0.0, -distance, 1800.0);
      camera->SetFocalPoint(0.0, 0.0, 1800.0);
      camera->SetViewAngle(2.0 * std::atan(2500.0 / distance) * 180.0 / 3.14159265358979);
      const Frame skyOnly = Grab(scene.Window);
      scene.AddCloud(0.0, 0.0);
      const Frame cloudy = Grab(scene.Window);
      double sum = 0.0;
      for (size_t i = 0; i < cloudy.Rgb.size(); ++i)
      {
        sum += std::abs(cloudy.Rgb[i] - skyOnly.Rgb[i]);
      }
      return sum / cloudy.Rgb.size();
    };
    const double nearContrast = contrast(4000.0), farContrast = contrast(28000.0);
    ok &= Check(farContrast < 0.8 * nearContrast && farContrast > 0.0,
      "aerial perspective fades the far cloud toward the sky: contrast " +
        std::to_string(nearContrast) + " at 4 km, " + std::to_string(farContrast) + " at 28 km");
  }
  return ok ? EXIT_SUCCESS : EXIT_FAILURE;
}
}

int main(int argc, char* argv[])
{
  // --offscreen or NIMBUS_OFFSCREEN=egl: render on an EGL pbuffer, no X server.
  if (vtkNimbusOffscreenRenderWindow::InstallIfRequested(argc, argv) < 0)
  {
    return 2;
  }
  std::string mode = argc > 1 ? argv[1] : "";
  const std::string rayMarch = "-ray-march";
  if (mode.size() > rayMarch.size() &&
    mode.compare(mode.size() - rayMarch.size(), rayMarch.size(), rayMarch) == 0)
  {
    gRenderingMethod = vtkNimbusCloudVolumeMapper::RayMarching;
    mode.resize(mode.size() - rayMarch.size());
  }
  if (mode == "checks" && argc == 2)
  {
    return RunChecks();
  }
  if (mode != "aerial" || argc != 4)
  {
    std::cerr << "usage: TestCloudSky checks | TestCloudSky aerial baseline.png outputdir\n";
    return EXIT_FAILURE;
  }
  Scene scene;
  scene.Sky->GetSky()->SetTurbidity(3.0); // a little hazier than the default (optical depth 0.20)
  // Far to near (volumes are composited in the order they were added).
  scene.AddCloud(-9000.0, 28000.0);
  scene.AddCloud(2500.0, 10000.0);
  scene.AddCloud(-1800.0, 2000.0);
  scene.Window->Render();
  vtkNew<vtkWindowToImageFilter> capture;
  capture->SetInput(scene.Window);
  capture->ReadFrontBufferOff();
  const std::string image = std::string(argv[3]) + "/TestCloudSky_aerial" +
    (gRenderingMethod == vtkNimbusCloudVolumeMapper::RayMarching ? "_RayMarch" : "") + ".png";
  vtkNew<vtkPNGWriter> writer;
  writer->SetFileName(image.c_str());
  writer->SetInputConnection(capture->GetOutputPort());
  writer->Write();
  return nimbus::testing::CompareImageFiles(
           image, argv[2], argv[3], nimbus::testing::ImageComparisonLimits(), std::cout)
    ? EXIT_SUCCESS
    : EXIT_FAILURE;
}
