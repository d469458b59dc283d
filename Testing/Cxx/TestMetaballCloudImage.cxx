// Image test: the metaball cloud rendered with VTK's own vtkGPUVolumeRayCastMapper,
// lit by vtkNimbusSunlight, compared with a baseline PNG (vtkTesting).
//
//   TestMetaballCloudImage <baseline.png> <output dir>
//
// Writes its render to <output dir>/TestMetaballCloudImage.png and compares it
// with the baseline (criteria and their measured justification: ImageComparison.h).
#include "vtkNimbusMetaballCloudSource.h"
#include "vtkNimbusOffscreenRenderWindow.h"
#include "vtkNimbusSunlight.h"

#include "vtkCamera.h"
#include "vtkColorTransferFunction.h"
#include "vtkGPUVolumeRayCastMapper.h"
#include "vtkImageData.h"
#include "vtkLight.h"
#include "vtkNew.h"
#include "vtkPNGWriter.h"
#include "vtkPiecewiseFunction.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkWindowToImageFilter.h"

#include "ImageComparison.h"
#include "vtkVolume.h"
#include "vtkVolumeProperty.h"

#include <cmath>
#include <cstdlib>
#include <iostream>
#include <string>

int main(int argc, char* argv[])
{
  // --offscreen or NIMBUS_OFFSCREEN=egl: render on an EGL pbuffer, no X server.
  if (vtkNimbusOffscreenRenderWindow::InstallIfRequested(argc, argv) < 0)
  {
    return 2;
  }
  if (argc != 3)
  {
    std::cerr << "usage: TestMetaballCloudImage baseline.png outputdir\n";
    return EXIT_FAILURE;
  }
  const std::string baseline = argv[1];
  const std::string outputDir = argv[2];

  vtkNew<vtkNimbusMetaballCloudSource> cloud;
  cloud->SetDimensions(64, 64, 44);
  cloud->SetSeed(3);
  cloud->Update();

  // Extinction 0.02 /m per unit density; opacity over the unit distance u is
  // 1 - exp(-sigma_t u) (Beer-Lambert).
  const double unitDistance = cloud->GetOutput()->GetSpacing()[0];
  vtkNew<vtkPiecewiseFunction> opacity;
  for (double density : { 0.0, 0.1, 0.25, 0.5, 1.0, 2.0 })
  {
    opacity->AddPoint(density, 1.0 - std::exp(-0.02 * density * unitDistance));
  }
  vtkNew<vtkColorTransferFunction> albedo;
  albedo->AddRGBPoint(0.0, 1.0, 1.0, 1.0);
  vtkNew<vtkVolumeProperty> property;
  property->SetScalarOpacity(opacity);
  property->SetColor(albedo);
  property->SetScalarOpacityUnitDistance(unitDistance);
  property->SetInterpolationTypeToLinear();
  property->ShadeOn();
  property->SetAmbient(0.4);
  property->SetDiffuse(0.7);
  property->SetSpecular(0.0);

  vtkNew<vtkGPUVolumeRayCastMapper> mapper;
  mapper->SetInputConnection(cloud->GetOutputPort());
  mapper->AutoAdjustSampleDistancesOff();
  mapper->SetSampleDistance(static_cast<float>(0.5 * unitDistance));
  vtkNew<vtkVolume> volume;
  volume->SetMapper(mapper);
  volume->SetProperty(property);

  // Low sun (15 degrees) from the camera's right: warm light, visible shading.
  vtkNew<vtkNimbusSunlight> sun;
  sun->SetSunElevationDegrees(15.0);
  sun->SetSunAzimuthDegrees(60.0);
  vtkNew<vtkLight> light;
  sun->ApplyToLight(light);
  light->SetAmbientColor(1.0, 1.0, 1.0);

  vtkNew<vtkRenderer> renderer;
  renderer->AddVolume(volume);
  renderer->AddLight(light);
  renderer->SetBackground(0.25, 0.42, 0.72);
  vtkCamera* camera = renderer->GetActiveCamera();
  camera->SetPosition(0.0, -6000.0, 1500.0);
  camera->SetFocalPoint(0.0, 0.0, 1600.0);
  camera->SetViewUp(0.0, 0.0, 1.0);
  camera->SetViewAngle(35.0);
  renderer->ResetCameraClippingRange();

  vtkNew<vtkRenderWindow> window;
  window->SetSize(320, 240);
  window->SetMultiSamples(0);
  window->AddRenderer(renderer);
  window->Render();

  vtkNew<vtkWindowToImageFilter> capture;
  capture->SetInput(window);
  capture->ReadFrontBufferOff();
  const std::string image = outputDir + "/TestMetaballCloudImage.png";
  vtkNew<vtkPNGWriter> writer;
  writer->SetFileName(image.c_str());
  writer->SetInputConnection(capture->GetOutputPort());
  writer->Write();
  const bool same = nimbus::testing::CompareImageFiles(
    image, baseline, outputDir, nimbus::testing::ImageComparisonLimits(), std::cout);
  return same ? EXIT_SUCCESS : EXIT_FAILURE;
}
