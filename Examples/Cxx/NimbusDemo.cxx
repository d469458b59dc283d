// nimbus-demo: renders the Nimbus demo scene to a PNG and prints the file's path.
//
//   nimbus-demo [--output FILE.png] [--size W H] [--sun-elevation DEG] [--sun-azimuth DEG]
//               [--seed N]
//
// Scene: a metaball cumulus (vtkNimbusMetaballCloudSource, 004 §4) over a ground
// plane, lit by the sun whose colour comes from the atmosphere model
// (vtkNimbusSunlight). Rendered with VTK's own vtkGPUVolumeRayCastMapper until
// Nimbus's own mappers land. Units: metres; z up.
#include "vtkNimbusMetaballCloudSource.h"
#include "vtkNimbusSunlight.h"

#include "vtkActor.h"
#include "vtkCamera.h"
#include "vtkColorTransferFunction.h"
#include "vtkGPUVolumeRayCastMapper.h"
#include "vtkLight.h"
#include "vtkNew.h"
#include "vtkPNGWriter.h"
#include "vtkPiecewiseFunction.h"
#include "vtkPlaneSource.h"
#include "vtkPolyDataMapper.h"
#include "vtkProperty.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkVolume.h"
#include "vtkVolumeProperty.h"
#include "vtkWindowToImageFilter.h"

#include <cmath>
#include <cstdlib>
#include <iostream>
#include <string>

namespace
{
void Usage()
{
  std::cout << "usage: nimbus-demo [--output FILE.png] [--size W H] [--sun-elevation DEG]"
               " [--sun-azimuth DEG] [--seed N]\n";
}

bool ParseNumber(const char* text, double& value)
{
  char* end = nullptr;
  value = std::strtod(text, &end);
  return end != text && *end == '\0' && std::isfinite(value);
}
}

int main(int argc, char* argv[])
{
  std::string output = "nimbus-demo.png";
  double width = 960, height = 540, sunElevation = 35.0, sunAzimuth = 120.0, seed = 7;
  for (int i = 1; i < argc; ++i)
  {
    const std::string arg = argv[i];
    const bool hasValue = i + 1 < argc;
    bool ok = true;
    if (arg == "--help" || arg == "-h")
    {
      Usage();
      return 0;
    }
    if (arg == "--output" && hasValue)
    {
      output = argv[++i];
    }
    else if (arg == "--size" && i + 2 < argc)
    {
      ok = ParseNumber(argv[i + 1], width) && ParseNumber(argv[i + 2], height) && width >= 16 &&
        height >= 16 && width <= 8192 && height <= 8192;
      i += 2;
    }
    else if (arg == "--sun-elevation" && hasValue)
    {
      ok = ParseNumber(argv[++i], sunElevation) && std::abs(sunElevation) <= 90.0;
    }
    else if (arg == "--sun-azimuth" && hasValue)
    {
      ok = ParseNumber(argv[++i], sunAzimuth);
    }
    else if (arg == "--seed" && hasValue)
    {
      ok = ParseNumber(argv[++i], seed);
    }
    else
    {
      ok = false;
    }
    if (!ok)
    {
      std::cerr << "nimbus-demo: bad or incomplete argument '" << arg << "' (see --help)\n";
      return 2;
    }
  }

  // The cloud: base at 1000 m, about 3 km across.
  vtkNew<vtkNimbusMetaballCloudSource> cloud;
  cloud->SetSeed(static_cast<int>(seed));
  cloud->Update();
  if (cloud->GetOutput()->GetNumberOfPoints() == 0)
  {
    std::cerr << "nimbus-demo: the cloud source produced no data\n";
    return 1;
  }

  // Optics of the cloud mapped onto VTK's transfer functions: extinction
  // sigma_t = kExtinction * density (1/m); opacity over one voxel-sized step u is
  // 1 - exp(-sigma_t u) (Beer-Lambert, 000 Eq. 2), sampled at a few densities.
  constexpr double kExtinction = 0.02; // 1/m per unit density: a cumulus
  const double unitDistance = cloud->GetOutput()->GetSpacing()[0];
  vtkNew<vtkPiecewiseFunction> opacity;
  for (double density : { 0.0, 0.05, 0.1, 0.2, 0.4, 0.7, 1.0, 1.5, 2.5 })
  {
    opacity->AddPoint(density, 1.0 - std::exp(-kExtinction * density * unitDistance));
  }
  vtkNew<vtkColorTransferFunction> albedo; // white droplets: albedo ~1
  albedo->AddRGBPoint(0.0, 1.0, 1.0, 1.0);
  albedo->AddRGBPoint(2.5, 1.0, 1.0, 1.0);

  vtkNew<vtkVolumeProperty> volumeProperty;
  volumeProperty->SetScalarOpacity(opacity);
  volumeProperty->SetColor(albedo);
  volumeProperty->SetScalarOpacityUnitDistance(unitDistance);
  volumeProperty->SetInterpolationTypeToLinear();
  volumeProperty->ShadeOn();
  volumeProperty->SetAmbient(0.5);
  volumeProperty->SetDiffuse(0.5);
  volumeProperty->SetSpecular(0.0);

  vtkNew<vtkGPUVolumeRayCastMapper> volumeMapper;
  volumeMapper->SetInputConnection(cloud->GetOutputPort(0));
  volumeMapper->SetSampleDistance(static_cast<float>(0.5 * unitDistance));
  volumeMapper->AutoAdjustSampleDistancesOff();
  // VTK's volumetric shadows blended with gradient shading (0 = gradient only,
  // 1 = volumetric single scattering only). Pure single scattering leaves a
  // front-lit cumulus dark (it lacks multiple scattering), so the demo blends.
  volumeMapper->SetVolumetricScatteringBlending(0.3f);
  volumeMapper->SetGlobalIlluminationReach(0.3f);
  volumeProperty->SetScatteringAnisotropy(0.2f);
  vtkNew<vtkVolume> volume;
  volume->SetMapper(volumeMapper);
  volume->SetProperty(volumeProperty);

  // Ground: 30 km square at z = 0, grassy.
  vtkNew<vtkPlaneSource> ground;
  ground->SetOrigin(-15000.0, -15000.0, 0.0);
  ground->SetPoint1(15000.0, -15000.0, 0.0);
  ground->SetPoint2(-15000.0, 15000.0, 0.0);
  vtkNew<vtkPolyDataMapper> groundMapper;
  groundMapper->SetInputConnection(ground->GetOutputPort());
  vtkNew<vtkActor> groundActor;
  groundActor->SetMapper(groundMapper);
  groundActor->GetProperty()->SetColor(0.30, 0.36, 0.22);
  groundActor->GetProperty()->SetAmbient(0.3);
  groundActor->GetProperty()->SetDiffuse(0.7);

  // The sun, attenuated by the atmosphere.
  vtkNew<vtkNimbusSunlight> sun;
  sun->SetSunElevation(sunElevation);
  sun->SetSunAzimuth(sunAzimuth);
  vtkNew<vtkLight> sunLight;
  sun->ApplyToLight(sunLight);
  // Sky light stand-in until the sky model lands: a bluish light from the zenith,
  // and VTK's ambient term (which takes the lights' ambient colour).
  vtkNew<vtkLight> skyLight;
  skyLight->SetLightTypeToSceneLight();
  skyLight->PositionalOff();
  skyLight->SetPosition(0.0, 0.0, 1.0);
  skyLight->SetFocalPoint(0.0, 0.0, 0.0);
  skyLight->SetColor(0.55, 0.68, 0.95);
  skyLight->SetIntensity(0.5);
  sunLight->SetAmbientColor(0.6, 0.68, 0.8);

  vtkNew<vtkRenderer> renderer;
  renderer->AddActor(groundActor);
  renderer->AddVolume(volume);
  renderer->AddLight(sunLight);
  renderer->AddLight(skyLight);
  renderer->GradientBackgroundOn(); // a placeholder sky until the sky model lands
  renderer->SetBackground(0.62, 0.74, 0.88);
  renderer->SetBackground2(0.22, 0.40, 0.70);

  vtkCamera* camera = renderer->GetActiveCamera();
  camera->SetPosition(0.0, -5600.0, 600.0);
  camera->SetFocalPoint(0.0, 0.0, 1500.0);
  camera->SetViewUp(0.0, 0.0, 1.0);
  camera->SetViewAngle(40.0);
  camera->SetClippingRange(100.0, 40000.0);

  vtkNew<vtkRenderWindow> window;
  window->SetOffScreenRendering(1);
  window->SetSize(static_cast<int>(width), static_cast<int>(height));
  window->AddRenderer(renderer);
  window->Render();

  vtkNew<vtkWindowToImageFilter> capture;
  capture->SetInput(window);
  capture->ReadFrontBufferOff();
  vtkNew<vtkPNGWriter> writer;
  writer->SetFileName(output.c_str());
  writer->SetInputConnection(capture->GetOutputPort());
  writer->Write();
  if (writer->GetErrorCode() != 0)
  {
    std::cerr << "nimbus-demo: could not write " << output << "\n";
    return 1;
  }
  std::cout << output << std::endl;
  return 0;
}
