#include "vtkNimbusSky.h"

#include "Sky.h"
#include "SkyTableCache.h"
#include "Sun.h"
#include "UpAxis.h"

#include "FiniteSetters.h"
#include "vtkMath.h"
#include "vtkObjectFactory.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

vtkStandardNewMacro(vtkNimbusSky);

// Non-finite values are refused (an error; the value is kept), finite ones clamped
// (Common/FiniteSetters.h).
nimbusDefineFiniteSetter(vtkNimbusSky, SunElevationDegrees);
nimbusDefineFiniteSetter(vtkNimbusSky, SunAzimuthDegrees);
nimbusDefineFiniteSetter(vtkNimbusSky, GroundAlbedo);
nimbusDefineFiniteSetter(vtkNimbusSky, Exposure);
nimbusDefineFiniteSetter(vtkNimbusSky, SceneAltitudeMetres);
nimbusDefineFiniteSetter(vtkNimbusSky, MetresPerUnit);

void vtkNimbusSky::SetUpAxis(int value)
{
  const std::string refusal = nimbus::UpAxisRefusal(value, this->UpAxis);
  if (!refusal.empty())
  {
    vtkErrorMacro(<< refusal);
    return;
  }
  if (value != this->UpAxis)
  {
    this->UpAxis = value;
    this->Modified();
  }
}
nimbusDefineFiniteSetter(vtkNimbusSky, MaxAerialDistanceMetres);

struct vtkNimbusSky::Internals
{
  // The model (keyed by the aerosol, the ground albedo and the scattering orders), the
  // observer's sky-view table (slot ObserverView), a camera's (slot CameraView, so that
  // the observer's table of GetRadiance and the dome is not rebuilt as the camera moves)
  // and the aerial perspective.
  nimbus::SkyTableCache Tables;
  static constexpr int ObserverView = 0;
  static constexpr int CameraView = 1;
};

namespace
{
// The sky's build counters (vtkGetMacro members) follow its cache's.
void CopyBuildCounts(const nimbus::SkyTableCache& tables, int& model, int& view, int& aerial)
{
  model = tables.GetModelBuilds();
  view = tables.GetSkyViewBuilds();
  aerial = tables.GetAerialBuilds();
}
}

vtkNimbusSky::vtkNimbusSky()
  : Internal(new Internals)
{
  const nimbus::SunParameters sun;
  this->SunElevationDegrees = sun.ElevationDegrees;
  this->SunAzimuthDegrees = sun.AzimuthDegrees;
  this->Turbidity = nimbus::kDefaultTurbidity;
  this->MieScatteringPerMetre = nimbus::MieScatteringFromTurbidity(
    this->Turbidity, nimbus::ClearSkyAtmosphere(this->Turbidity));
}

// Turbidity and MieScatteringPerMetre are one setting (nimbus::MieScatteringFromTurbidity
// and its inverse for the sky's atmosphere: scale height, albedo and Ångström exponent
// do not depend on the turbidity).
void vtkNimbusSky::SetTurbidity(double value)
{
  if (!std::isfinite(value))
  {
    vtkErrorMacro(
      "SetTurbidity(" << value << "): not a finite number; Turbidity stays " << this->Turbidity);
    return;
  }
  const double clamped =
    std::clamp(value, this->GetTurbidityMinValue(), this->GetTurbidityMaxValue());
  if (clamped != this->Turbidity)
  {
    this->Turbidity = clamped;
    this->MieScatteringPerMetre =
      nimbus::MieScatteringFromTurbidity(clamped, nimbus::ClearSkyAtmosphere(clamped));
    this->Modified();
  }
}

void vtkNimbusSky::SetMieScatteringPerMetre(double value)
{
  if (!std::isfinite(value))
  {
    vtkErrorMacro("SetMieScatteringPerMetre(" << value
                                              << "): not a finite number; MieScatteringPerMetre "
                                                 "stays "
                                              << this->MieScatteringPerMetre);
    return;
  }
  const double clamped = std::clamp(
    value, this->GetMieScatteringPerMetreMinValue(), this->GetMieScatteringPerMetreMaxValue());
  if (clamped != this->MieScatteringPerMetre)
  {
    this->MieScatteringPerMetre = clamped;
    this->Turbidity = nimbus::TurbidityFromMieScattering(
      clamped, nimbus::ClearSkyAtmosphere(nimbus::kDefaultTurbidity));
    this->Modified();
  }
}

vtkNimbusSky::~vtkNimbusSky() = default;

void vtkNimbusSky::SetPreset(int preset)
{
  switch (preset)
  {
    case Noon:
      this->SetSunElevationDegrees(60.0);
      this->SetSunAzimuthDegrees(180.0);
      break;
    case Afternoon:
      this->SetSunElevationDegrees(30.0);
      this->SetSunAzimuthDegrees(240.0);
      break;
    case Sunset:
      this->SetSunElevationDegrees(2.0);
      this->SetSunAzimuthDegrees(270.0);
      break;
    case Twilight:
      this->SetSunElevationDegrees(-4.0);
      this->SetSunAzimuthDegrees(270.0);
      break;
    default:
      vtkErrorMacro(
        "SetPreset: unknown preset " << preset << " (0 Noon, 1 Afternoon, 2 Sunset, 3 Twilight)");
  }
}

void vtkNimbusSky::GetSunDirection(double direction[3])
{
  const auto s = nimbus::SunDirection(this->SunElevationDegrees, this->SunAzimuthDegrees);
  for (int i = 0; i < 3; ++i)
  {
    direction[i] = s[i];
  }
}

const nimbus::SkyModel& vtkNimbusSky::GetSkyModel()
{
  Internals& in = *this->Internal;
  const nimbus::SkyModel& model = in.Tables.Model({ this->MieScatteringPerMetre, this->GroundAlbedo,
                                                    static_cast<double>(this->ScatteringOrders) },
    [this]()
    {
      nimbus::SkyParameters p;
      // The clear sky (Ångström exponent, phase function, ozone) with this aerosol amount.
      p.Atmosphere = nimbus::ClearSkyAtmosphere(nimbus::kDefaultTurbidity);
      p.Atmosphere.MieScatteringPerMetre = this->MieScatteringPerMetre;
      p.GroundAlbedo = this->GroundAlbedo;
      p.ScatteringOrders = this->ScatteringOrders;
      return p;
    });
  CopyBuildCounts(in.Tables, this->ModelBuilds, this->SkyViewBuilds, this->AerialBuilds);
  return model;
}

const nimbus::SkyViewLut& vtkNimbusSky::GetSkyViewLut()
{
  this->GetSkyModel();
  Internals& in = *this->Internal;
  const nimbus::SkyViewLut& view = in.Tables.SkyView(
    Internals::ObserverView, this->SunElevationDegrees, this->SceneAltitudeMetres, 0.0);
  CopyBuildCounts(in.Tables, this->ModelBuilds, this->SkyViewBuilds, this->AerialBuilds);
  return view;
}

const nimbus::SkyViewLut& vtkNimbusSky::GetSkyViewLutAt(double altitude)
{
  const nimbus::SkyViewLut& observer = this->GetSkyViewLut();
  Internals& in = *this->Internal;
  altitude = std::max(0.0, altitude);
  const double tolerance = std::max(25.0, 0.02 * altitude);
  if (std::abs(altitude - this->SceneAltitudeMetres) <= tolerance)
  {
    return observer;
  }
  const nimbus::SkyViewLut& view =
    in.Tables.SkyView(Internals::CameraView, this->SunElevationDegrees, altitude, tolerance);
  CopyBuildCounts(in.Tables, this->ModelBuilds, this->SkyViewBuilds, this->AerialBuilds);
  return view;
}

const nimbus::AerialPerspectiveLut& vtkNimbusSky::GetAerialPerspectiveLut(double cameraAltitude)
{
  this->GetSkyModel();
  Internals& in = *this->Internal;
  cameraAltitude = std::max(0.0, cameraAltitude);
  const double tolerance = std::max(10.0, 0.01 * cameraAltitude);
  const nimbus::AerialPerspectiveLut& aerial = in.Tables.Aerial(
    this->SunElevationDegrees, cameraAltitude, tolerance, this->MaxAerialDistanceMetres);
  CopyBuildCounts(in.Tables, this->ModelBuilds, this->SkyViewBuilds, this->AerialBuilds);
  return aerial;
}

void vtkNimbusSky::GetRadiance(const double direction[3], double rgb[3])
{
  const double n = std::sqrt(
    direction[0] * direction[0] + direction[1] * direction[1] + direction[2] * direction[2]);
  if (!(n > 0.0) || !std::isfinite(n))
  {
    vtkErrorMacro("GetRadiance: direction must be finite and non-zero");
    rgb[0] = rgb[1] = rgb[2] = 0.0;
    return;
  }
  const auto L = this->GetSkyViewLut().Radiance(
    { { direction[0] / n, direction[1] / n, direction[2] / n } }, this->SunAzimuthDegrees);
  for (int i = 0; i < 3; ++i)
  {
    rgb[i] = L[i];
  }
}

void vtkNimbusSky::GetDisplayScale(double scale[3])
{
  const nimbus::SkyModel& model = this->GetSkyModel();
  const auto sun = model.GetSpectrum().ToLinearSrgb(model.GetSunIrradiance());
  for (int i = 0; i < 3; ++i)
  {
    scale[i] = this->Exposure / (this->WhiteBalance && sun[i] > 0.0 ? sun[i] : 1.0);
  }
}

void vtkNimbusSky::GetDisplayColor(const double direction[3], double rgb[3])
{
  double scale[3];
  this->GetDisplayScale(scale);
  this->GetRadiance(direction, rgb);
  for (int i = 0; i < 3; ++i)
  {
    rgb[i] *= scale[i];
  }
}

void vtkNimbusSky::AerialPerspective(
  const double camera[3], const double point[3], double transmittance[3], double inscatter[3])
{
  const nimbus::SkyModel& model = this->GetSkyModel();
  const double base =
    model.GetParameters().Atmosphere.EarthRadiusMetres + this->SceneAltitudeMetres;
  const double m = this->MetresPerUnit;
  const nimbus::SkyModel::Vector3 p0{ { camera[0] * m, camera[1] * m, base + camera[2] * m } };
  const nimbus::SkyModel::Vector3 p1{ { point[0] * m, point[1] * m, base + point[2] * m } };
  std::array<double, 3> t, l;
  try
  {
    model.AerialPerspective(
      p0, p1, nimbus::SunDirection(this->SunElevationDegrees, this->SunAzimuthDegrees), t, l);
  }
  catch (const std::exception& e)
  {
    vtkErrorMacro("AerialPerspective: " << e.what());
    t = { { 1.0, 1.0, 1.0 } };
    l = { { 0.0, 0.0, 0.0 } };
  }
  for (int i = 0; i < 3; ++i)
  {
    transmittance[i] = t[i];
    inscatter[i] = l[i];
  }
}

void vtkNimbusSky::GetSunDiscRadiance(double rgb[3])
{
  const nimbus::SkyModel& model = this->GetSkyModel();
  const double r = model.GetParameters().Atmosphere.EarthRadiusMetres + this->SceneAltitudeMetres;
  std::vector<double> T(model.GetSunIrradiance().size());
  model.SunTransmittance(r, std::sin(this->SunElevationDegrees * nimbus::kDegree), T.data());
  std::vector<double> spectrum(T.size());
  for (std::size_t i = 0; i < T.size(); ++i)
  {
    spectrum[i] = model.GetSunIrradiance()[i] * T[i];
  }
  const auto c = model.GetSpectrum().ToLinearSrgb(spectrum);
  // Uniform disc of the same irradiance: E / (pi r^2) (the limb darkening in the
  // shader is normalised to keep the mean).
  const double solidAngle = vtkMath::Pi() * GetSunAngularRadius() * GetSunAngularRadius();
  for (int i = 0; i < 3; ++i)
  {
    rgb[i] = std::max(0.0, c[i]) / solidAngle;
  }
}

void vtkNimbusSky::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "SunElevationDegrees: " << this->SunElevationDegrees << "\n";
  os << indent << "SunAzimuthDegrees: " << this->SunAzimuthDegrees << "\n";
  os << indent << "Turbidity: " << this->Turbidity << "\n";
  os << indent << "MieScatteringPerMetre: " << this->MieScatteringPerMetre << "\n";
  os << indent << "GroundAlbedo: " << this->GroundAlbedo << "\n";
  os << indent << "Exposure: " << this->Exposure << "\n";
  os << indent << "SceneAltitudeMetres: " << this->SceneAltitudeMetres << "\n";
  os << indent << "MetresPerUnit: " << this->MetresPerUnit << "\n";
  os << indent << "UpAxis: " << nimbus::UpAxisName(static_cast<nimbus::UpAxis>(this->UpAxis))
     << "\n";
  os << indent << "MaxAerialDistanceMetres: " << this->MaxAerialDistanceMetres << "\n";
  os << indent << "ScatteringOrders: " << this->ScatteringOrders << "\n";
  os << indent << "WhiteBalance: " << this->WhiteBalance << "\n";
  os << indent << "SunDisc: " << this->SunDisc << "\n";
  os << indent << "ModelBuilds: " << this->ModelBuilds << " SkyViewBuilds: " << this->SkyViewBuilds
     << " AerialBuilds: " << this->AerialBuilds << "\n";
}
