#include "vtkNimbusSunlight.h"

#include "Sun.h"

#include "Atmosphere.h"
#include "SpectralColor.h"

#include "FiniteSetters.h"
#include "vtkLight.h"
#include "vtkMath.h"
#include "vtkObjectFactory.h"

#include <algorithm>
#include <cmath>

vtkStandardNewMacro(vtkNimbusSunlight);

// Non-finite values are refused (an error; the value is kept), finite ones clamped
// (Common/FiniteSetters.h).
nimbusDefineFiniteSetter(vtkNimbusSunlight, SunElevationDegrees);
nimbusDefineFiniteSetter(vtkNimbusSunlight, SunAzimuthDegrees);
nimbusDefineFiniteSetter(vtkNimbusSunlight, SceneAltitudeMetres);

namespace
{
constexpr double SunTemperatureK = 5778.0; // effective temperature of the solar photosphere
}

vtkNimbusSunlight::vtkNimbusSunlight()
{
  const nimbus::SunParameters sun;
  this->SunElevationDegrees = sun.ElevationDegrees;
  this->SunAzimuthDegrees = sun.AzimuthDegrees;
}

void vtkNimbusSunlight::GetDirection(double direction[3])
{
  const nimbus::Vector3 toSun =
    nimbus::SunDirection(this->SunElevationDegrees, this->SunAzimuthDegrees);
  std::copy(toSun.begin(), toSun.end(), direction);
}

void vtkNimbusSunlight::ComputeXyz(double transmitted[3], double outside[3])
{
  const nimbus::Atmosphere atmosphere;
  const nimbus::SpectralSamples samples;
  double direction[3];
  this->GetDirection(direction);
  // Observer on the z axis of an earth-centred frame; the local frame is the scene frame.
  const nimbus::Atmosphere::Vector3 observer{ { 0.0, 0.0,
    atmosphere.GetParameters().EarthRadiusMetres + this->SceneAltitudeMetres } };
  const nimbus::OpticalLengths lengths =
    atmosphere.OpticalLengthsToTop(observer, { { direction[0], direction[1], direction[2] } });

  const auto solarSpectrum = samples.Sample(
    [](double lambda) { return nimbus::PlanckSpectralRadiance(lambda, SunTemperatureK); });
  std::vector<double> transmittedSpectrum = solarSpectrum;
  const auto& wavelengths = samples.GetWavelengths();
  for (std::size_t i = 0; i < transmittedSpectrum.size(); ++i)
  {
    // Beer-Lambert along the path to the top of the atmosphere (000 Eq. 2).
    transmittedSpectrum[i] *= atmosphere.Transmittance(lengths, wavelengths[i]);
  }
  const auto xyzOutside = samples.ToXyz(solarSpectrum);
  const auto xyzTransmitted = samples.ToXyz(transmittedSpectrum);
  for (int c = 0; c < 3; ++c)
  {
    transmitted[c] = xyzTransmitted[c] / xyzOutside[1];
    outside[c] = xyzOutside[c] / xyzOutside[1];
  }
}

void vtkNimbusSunlight::GetColor(double rgb[3])
{
  double xyz[3], xyzOutside[3];
  this->ComputeXyz(xyz, xyzOutside);
  const auto linear = nimbus::XyzToLinearSrgb({ { xyz[0], xyz[1], xyz[2] } });
  const auto white = nimbus::XyzToLinearSrgb({ { xyzOutside[0], xyzOutside[1], xyzOutside[2] } });
  for (int c = 0; c < 3; ++c)
  {
    const double balanced = this->WhiteBalance ? linear[c] / white[c] : linear[c];
    rgb[c] = std::max(0.0, balanced); // out-of-gamut negatives clipped
  }
}

double vtkNimbusSunlight::GetRelativeLuminance()
{
  double xyz[3], xyzOutside[3];
  this->ComputeXyz(xyz, xyzOutside);
  return xyz[1];
}

void vtkNimbusSunlight::ApplyToLight(vtkLight* light)
{
  if (!light)
  {
    vtkErrorMacro(<< "ApplyToLight: no light given.");
    return;
  }
  double direction[3], rgb[3];
  this->GetDirection(direction);
  this->GetColor(rgb);
  const double brightest = std::max({ rgb[0], rgb[1], rgb[2] });
  light->SetLightTypeToSceneLight();
  light->PositionalOff();
  light->SetFocalPoint(0.0, 0.0, 0.0);
  light->SetPosition(direction);
  if (brightest > 0.0)
  {
    light->SetColor(rgb[0] / brightest, rgb[1] / brightest, rgb[2] / brightest);
  }
  else
  {
    light->SetColor(0.0, 0.0, 0.0);
  }
  light->SetIntensity(brightest);
}

void vtkNimbusSunlight::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "SunElevationDegrees: " << this->SunElevationDegrees << "\n";
  os << indent << "SunAzimuthDegrees: " << this->SunAzimuthDegrees << "\n";
  os << indent << "SceneAltitudeMetres: " << this->SceneAltitudeMetres << "\n";
  os << indent << "WhiteBalance: " << (this->WhiteBalance ? "On" : "Off") << "\n";
}
