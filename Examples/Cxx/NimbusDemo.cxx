// nimbus-demo: renders the Nimbus demo scene to a PNG and prints the file's path.
//
//   nimbus-demo [--output FILE.png] [--size W H] [--sun-elevation DEG] [--sun-azimuth DEG]
//               [--seed N] [--k-multi K] [--exposure E] [--no-sky]
//
// Scene: a metaball cumulus (vtkNimbusMetaballCloudSource, 004 §4) over a ground
// plane, lit by the sun whose colour comes from the atmosphere model
// through the atmosphere, rendered with Nimbus's shadow-view-slice mapper
// (vtkNimbusCloudVolumeMapper, paper 000): cloud and ground shadows, shafts of
// light and multiple scattering in the cloud, in front of the Nimbus sky
// (vtkNimbusSkyBackground: Rayleigh + Mie with multiple scattering) whose sun and air
// the cloud mapper shares. With --no-sky the mapper draws its own atmosphere instead.
// Units: metres; z up.
#include "vtkNimbusCloudVolumeMapper.h"
#include "vtkNimbusMetaballCloudSource.h"
#include "vtkNimbusOffscreenRenderWindow.h"
#include "vtkNimbusSky.h"
#include "vtkNimbusSkyBackground.h"

#include "vtkCamera.h"
#include "vtkImageData.h"
#include "vtkNew.h"
#include "vtkPNGWriter.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkVolume.h"
#include "vtkWindowToImageFilter.h"

#include <cmath>
#include <cstdlib>
#include <iostream>
#include <string>

namespace
{
void Usage()
{
  std::cout
    << "usage: nimbus-demo [--output FILE.png] [--size W H] [--sun-elevation DEG]"
       " [--sun-azimuth DEG] [--seed N] [--k-multi K] [--exposure E] [--no-sky] [--offscreen]\n"
       "  W, H in [16, 8192] pixels; sun elevation in [-90, 90] degrees, azimuth within"
       " +-1e6 degrees;\n  seed a 32-bit integer; k-multi in [0, 100]; exposure in"
       " [0, 1e6]. A bad value exits with status 2.\n"
       "  --offscreen (or NIMBUS_OFFSCREEN=egl): render with EGL, no X server.\n";
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
  // --offscreen or NIMBUS_OFFSCREEN=egl: render on an EGL pbuffer, no X server.
  if (vtkNimbusOffscreenRenderWindow::InstallIfRequested(argc, argv) < 0)
  {
    return 2;
  }
  std::string output = "nimbus-demo.png";
  double width = 960, height = 540, sunElevation = 35.0, sunAzimuth = 120.0, seed = 7, kMulti = 0.0,
         exposure = 8.0;
  bool drawSky = true;
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
      ok = ParseNumber(argv[++i], sunAzimuth) && std::abs(sunAzimuth) <= 1.0e6;
    }
    else if (arg == "--k-multi" && hasValue)
    {
      ok = ParseNumber(argv[++i], kMulti) && kMulti >= 0.0 && kMulti <= 100.0;
    }
    else if (arg == "--exposure" && hasValue)
    {
      ok = ParseNumber(argv[++i], exposure) && exposure >= 0.0 && exposure <= 1.0e6;
    }
    else if (arg == "--no-sky")
    {
      drawSky = false;
    }
    else if (arg == "--seed" && hasValue)
    {
      // An integer the source's int Seed holds (a cast of anything else is undefined).
      ok = ParseNumber(argv[++i], seed) && seed == std::floor(seed) && seed >= -2147483648.0 &&
        seed <= 2147483647.0;
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

  // The cloud rendered with Nimbus's shadow-view-slice mapper (000): single
  // scattering, multiple scattering (the mapper's default: 003's discrete
  // directions, the sky's and the ground's light; --k-multi adds 000's constant on
  // top, 0 by default), sun shadows (also on the ground), the atmosphere (sky
  // colour, reddened sun, haze) and shafts of light.
  vtkNew<vtkNimbusCloudVolumeMapper> cloudMapper;
  cloudMapper->SetInputConnection(cloud->GetOutputPort(0));
  cloudMapper->SetExtinctionPerDensity(0.02); // 1/m per unit density: a cumulus
  cloudMapper->SetAlbedo(0.99);
  cloudMapper->SetCloudG(0.85);
  cloudMapper->SetMultipleScattering(kMulti);
  cloudMapper->SetSunElevationDegrees(sunElevation);
  cloudMapper->SetSunAzimuthDegrees(sunAzimuth);
  cloudMapper->SetGroundAlbedo(0.25);
  cloudMapper->SetNumberOfSlices(256);
  cloudMapper->SetExposure(exposure);
  cloudMapper->SetEncodeSrgb(true);
  vtkNew<vtkVolume> volume;
  volume->SetMapper(cloudMapper);

  vtkNew<vtkRenderer> renderer;
  renderer->AddVolume(volume);
  renderer->SetBackground(0.0, 0.0, 0.0); // space: the mapper draws the atmosphere
  if (drawSky)
  {
    // The sky behind everything; the cloud mapper, given it, takes its sun,
    // air, ground albedo and exposure (UseSceneSky), so sky and cloud agree.
    vtkNew<vtkNimbusSkyBackground> sky;
    sky->GetSky()->SetSunElevationDegrees(sunElevation);
    sky->GetSky()->SetSunAzimuthDegrees(sunAzimuth);
    sky->GetSky()->SetGroundAlbedo(0.25);
    sky->GetSky()->SetExposure(exposure);
    renderer->AddViewProp(sky);
    cloudMapper->SetSkyBackground(sky);
  }

  vtkCamera* camera = renderer->GetActiveCamera();
  camera->SetPosition(0.0, -5600.0, 600.0);
  camera->SetFocalPoint(0.0, 0.0, 1500.0);
  camera->SetViewUp(0.0, 0.0, 1.0);
  camera->SetViewAngle(40.0);
  camera->SetClippingRange(10.0, 1e6);

  vtkNew<vtkRenderWindow> window;
  window->SetOffScreenRendering(1);
  window->SetMultiSamples(0); // the mapper composites with the scene's depth
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
