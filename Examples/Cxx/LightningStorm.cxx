// nimbus-lightning-storm: a cumulus at night lit from inside by a lightning flash
// (003's precomputed lightning), to a PNG. The C++ twin of Examples/Python/lightning_storm_vtk.py.
//
//   nimbus-lightning-storm [--output storm.png] [--time SECONDS] [--size W H]
//
// vtkNimbusMetaballCloudSource (the cloud) and vtkNimbusLightningSource (the strokes and
// their point sources over time) feed vtkNimbusLightningIllumination, which precomputes
// the cloud's answer to virtual point lights once (kept on disk, see its class comment)
// and relights it per time step; vtkNimbusCloudVolumeMapper draws it under a night sky
// (sun 12 degrees below the horizon), the strokes as lines in their brightness with the
// glow of the rainy air around them (vtkNimbusLightningGlowMapper). Without --time: the
// return stroke's peak.
#include "vtkNimbusCloudVolumeMapper.h"
#include "vtkNimbusLightningGlowMapper.h"
#include "vtkNimbusLightningIllumination.h"
#include "vtkNimbusLightningSource.h"
#include "vtkNimbusMetaballCloudSource.h"
#include "vtkNimbusOffscreenRenderWindow.h"
#include "vtkNimbusSky.h"
#include "vtkNimbusSkyBackground.h"

#include "vtkActor.h"
#include "vtkCamera.h"
#include "vtkCellData.h"
#include "vtkDataArray.h"
#include "vtkFieldData.h"
#include "vtkImageData.h"
#include "vtkLookupTable.h"
#include "vtkNew.h"
#include "vtkPNGWriter.h"
#include "vtkPolyData.h"
#include "vtkPolyDataMapper.h"
#include "vtkProperty.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkVolume.h"
#include "vtkWindowToImageFilter.h"

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <string>

namespace
{
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
  std::string output = "lightning-storm.png";
  double time = -1.0; // < 0: the return stroke's peak
  double width = 960, height = 540;
  for (int i = 1; i < argc; ++i)
  {
    const std::string arg = argv[i];
    bool ok = true;
    if (arg == "--help" || arg == "-h")
    {
      std::cout << "usage: nimbus-lightning-storm [--output FILE.png] [--time SECONDS] "
                   "[--size W H] [--offscreen]\n"
                   "  --offscreen (or NIMBUS_OFFSCREEN=egl): render with EGL, no X server.\n";
      return 0;
    }
    else if (arg == "--output" && i + 1 < argc)
    {
      output = argv[++i];
    }
    else if (arg == "--time" && i + 1 < argc)
    {
      ok = ParseNumber(argv[++i], time) && time >= 0.0;
    }
    else if (arg == "--size" && i + 2 < argc)
    {
      ok = ParseNumber(argv[++i], width) && ParseNumber(argv[++i], height) && width >= 1 &&
        height >= 1 && width <= 8192 && height <= 8192 && width == std::floor(width) &&
        height == std::floor(height);
    }
    else
    {
      ok = false;
    }
    if (!ok)
    {
      std::cerr << "nimbus-lightning-storm: bad or incomplete argument '" << arg
                << "' (see --help)\n";
      return 2;
    }
  }

  vtkNew<vtkNimbusMetaballCloudSource> cloud; // 3 km wide, base 1000 m
  cloud->SetSeed(3);
  vtkNew<vtkNimbusLightningSource> lightning;
  lightning->SetStartPoint(200.0, 0.0, 2000.0); // metres, inside the cloud
  lightning->SetDirection(0.15, 0.0, -1.0);
  lightning->SetLength(3500.0);
  lightning->SetSeed(11);

  vtkNew<vtkNimbusLightningIllumination> illumination;
  illumination->SetInputConnection(0, cloud->GetOutputPort(0));
  illumination->SetLightningConnection(lightning->GetOutputPort(1)); // the point sources
  if (time >= 0.0)
  {
    // The filter asks the lightning for this time; the outputs then go to the mappers
    // as they are (a mapper's own update requests no time).
    illumination->UpdateTimeStep(time);
    lightning->UpdateTimeStep(time);
  }
  else
  {
    illumination->Update();
    lightning->Update();
  }
  if (!illumination->GetOutput()->GetFieldData()->GetArray("nimbus_lightning_in_scattering"))
  {
    std::cerr << "nimbus-lightning-storm: the lightning illumination failed\n";
    return 1;
  }
  std::cerr << "lightning: " << illumination->GetNumberOfVirtualLights() << " virtual lights, "
            << (illumination->GetLastBasisFromDisk()
                   ? "basis read from " + illumination->GetCacheFile()
                   : "precomputed in " + std::to_string(illumination->GetLastPrecomputeSeconds()) +
                     " s")
            << ", relit in " << 1000.0 * illumination->GetLastRelightSeconds() << " ms\n";

  vtkNew<vtkNimbusCloudVolumeMapper> mapper;
  mapper->SetInputData(illumination->GetOutput());
  mapper->SetNumberOfSlices(256);
  mapper->SetEncodeSrgb(true);
  mapper->SetExposure(2.0);
  vtkNew<vtkVolume> volume;
  volume->SetMapper(mapper);
  vtkNew<vtkNimbusSkyBackground> sky;
  sky->GetSky()->SetSunElevationDegrees(-12.0); // nautical twilight: a dark sky
  sky->GetSky()->SetSunAzimuthDegrees(250.0);
  sky->GetSky()->SetExposure(2.0);
  mapper->SetSkyBackground(sky);

  // The channels in their brightness now: black to blue-white at the return stroke.
  vtkPolyData* strokes = lightning->GetOutput(0);
  double peak[2] = { 0.0, 1.0 };
  if (vtkDataArray* peaks = strokes->GetCellData()->GetArray("peak_intensity"))
  {
    peaks->GetRange(peak);
  }
  vtkNew<vtkLookupTable> colours;
  colours->SetTableRange(0.0, peak[1] > 0.0 ? peak[1] : 1.0);
  colours->SetHueRange(0.62, 0.62);
  colours->SetSaturationRange(0.15, 0.15);
  colours->SetValueRange(0.0, 1.0);
  colours->Build();
  vtkNew<vtkPolyDataMapper> strokeMapper;
  strokeMapper->SetInputData(strokes);
  strokeMapper->SetScalarModeToUseCellFieldData();
  strokeMapper->SelectColorArray("intensity");
  strokeMapper->SetLookupTable(colours);
  strokeMapper->UseLookupTableScalarRangeOn();
  vtkNew<vtkActor> channel;
  channel->SetMapper(strokeMapper);
  channel->GetProperty()->SetLineWidth(2.0);
  channel->GetProperty()->LightingOff();

  // The glow of the rainy air around the channels (003 §8): emissive splats at the point
  // sources with the single-scattering profile of a point source in air.
  vtkNew<vtkNimbusLightningGlowMapper> glowMapper;
  glowMapper->SetInputData(vtkPolyData::SafeDownCast(lightning->GetOutputDataObject(1)));
  glowMapper->SetExposure(2.0);
  vtkNew<vtkActor> glow;
  glow->SetMapper(glowMapper);

  vtkNew<vtkRenderer> renderer;
  renderer->AddViewProp(sky);
  renderer->AddActor(channel);
  renderer->AddActor(glow);
  renderer->AddVolume(volume);
  renderer->SetBackground(0.0, 0.0, 0.0);
  vtkCamera* camera = renderer->GetActiveCamera();
  camera->SetPosition(-600.0, -4200.0, 250.0);
  camera->SetFocalPoint(0.0, 0.0, 1250.0);
  camera->SetViewUp(0.0, 0.0, 1.0);
  camera->SetViewAngle(50.0);
  camera->SetClippingRange(10.0, 1e6);

  vtkNew<vtkRenderWindow> window;
  window->SetOffScreenRendering(1);
  window->SetMultiSamples(0);
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
    std::cerr << "nimbus-lightning-storm: could not write " << output << "\n";
    return 1;
  }
  std::cout << output << std::endl;
  return 0;
}
