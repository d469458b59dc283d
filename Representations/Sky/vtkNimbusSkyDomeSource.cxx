#include "vtkNimbusSkyDomeSource.h"

#include "UpAxis.h"

#include "vtkNimbusSky.h"

#include "SpectralColor.h"

#include "FiniteSetters.h"
#include "vtkCellArray.h"
#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkFloatArray.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkMath.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkUnsignedCharArray.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

vtkStandardNewMacro(vtkNimbusSkyDomeSource);
vtkCxxSetObjectMacro(vtkNimbusSkyDomeSource, Sky, vtkNimbusSky);

// Non-finite values are refused (an error; the value is kept), finite ones clamped
// (Common/FiniteSetters.h).
nimbusDefineFiniteSetter(vtkNimbusSkyDomeSource, Radius);

void vtkNimbusSkyDomeSource::SetCenter(double x, double y, double z)
{
  if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z))
  {
    vtkErrorMacro("SetCenter(" << x << ", " << y << ", " << z << "): not finite; Center stays "
                               << this->Center[0] << ", " << this->Center[1] << ", "
                               << this->Center[2] << ".");
    return;
  }
  if (this->Center[0] != x || this->Center[1] != y || this->Center[2] != z)
  {
    this->Center[0] = x;
    this->Center[1] = y;
    this->Center[2] = z;
    this->Modified();
  }
}

void vtkNimbusSkyDomeSource::SetCenter(const double center[3])
{
  this->SetCenter(center[0], center[1], center[2]);
}

vtkNimbusSkyDomeSource::vtkNimbusSkyDomeSource()
{
  this->SetNumberOfInputPorts(0);
  vtkNew<vtkNimbusSky> sky;
  this->SetSky(sky);
}

#define NIMBUS_FORWARD(name)                                                                       \
  void vtkNimbusSkyDomeSource::Set##name(double v)                                                 \
  {                                                                                                \
    if (this->Sky)                                                                                 \
    {                                                                                              \
      this->Sky->Set##name(v);                                                                     \
    }                                                                                              \
  }
NIMBUS_FORWARD(SunElevationDegrees)
NIMBUS_FORWARD(SunAzimuthDegrees)
NIMBUS_FORWARD(GroundAlbedo)
NIMBUS_FORWARD(Exposure)
NIMBUS_FORWARD(SceneAltitudeMetres)
NIMBUS_FORWARD(MetresPerUnit)
#undef NIMBUS_FORWARD

void vtkNimbusSkyDomeSource::SetUpAxis(int v)
{
  if (this->Sky)
  {
    this->Sky->SetUpAxis(v);
  }
}

void vtkNimbusSkyDomeSource::SetTurbidity(double v)
{
  if (!std::isfinite(v))
  {
    vtkErrorMacro("SetTurbidity(" << v << "): not a finite number; ignored");
    return;
  }
  if (this->Turbidity != v)
  {
    this->Turbidity = v;
    this->Modified();
  }
  this->ApplyHaze();
}

void vtkNimbusSkyDomeSource::SetMieScatteringPerMetre(double v)
{
  if (!std::isfinite(v))
  {
    vtkErrorMacro("SetMieScatteringPerMetre(" << v << "): not a finite number; ignored");
    return;
  }
  if (this->MieScatteringPerMetre != v)
  {
    this->MieScatteringPerMetre = v;
    this->Modified();
  }
  this->ApplyHaze();
}

void vtkNimbusSkyDomeSource::ApplyHaze()
{
  if (!this->Sky)
  {
    return;
  }
  if (this->MieScatteringPerMetre >= 0.0)
  {
    this->Sky->SetMieScatteringPerMetre(this->MieScatteringPerMetre);
  }
  else
  {
    this->Sky->SetTurbidity(this->Turbidity);
  }
}

void vtkNimbusSkyDomeSource::SetScatteringOrders(int v)
{
  if (this->Sky)
  {
    this->Sky->SetScatteringOrders(v);
  }
}

void vtkNimbusSkyDomeSource::SetWhiteBalance(bool v)
{
  if (this->Sky)
  {
    this->Sky->SetWhiteBalance(v);
  }
}

void vtkNimbusSkyDomeSource::SetSunDisc(bool v)
{
  if (this->Sky)
  {
    this->Sky->SetSunDisc(v);
  }
}

namespace
{
// The sky parameters carried in the output's field data: array name, read, write.
struct SkyParameter
{
  const char* Name;
  double (*Get)(vtkNimbusSky*);
  void (*Set)(vtkNimbusSky*, double);
};

#define NIMBUS_PARAMETER(name, type)                                                               \
  SkyParameter                                                                                     \
  {                                                                                                \
#name, [](vtkNimbusSky * s) { return static_cast<double>(s->Get##name()); },                   \
      [](vtkNimbusSky * s, double v) { s->Set##name(static_cast<type>(v)); }                       \
  }
const SkyParameter SkyParameters[] = {
  NIMBUS_PARAMETER(SunElevationDegrees, double),
  NIMBUS_PARAMETER(SunAzimuthDegrees, double),
  NIMBUS_PARAMETER(Turbidity, double),
  NIMBUS_PARAMETER(MieScatteringPerMetre, double),
  NIMBUS_PARAMETER(GroundAlbedo, double),
  NIMBUS_PARAMETER(Exposure, double),
  NIMBUS_PARAMETER(WhiteBalance, bool),
  NIMBUS_PARAMETER(SunDisc, bool),
  NIMBUS_PARAMETER(SceneAltitudeMetres, double),
  NIMBUS_PARAMETER(MetresPerUnit, double),
  NIMBUS_PARAMETER(MaxAerialDistanceMetres, double),
  NIMBUS_PARAMETER(ScatteringOrders, int),
  NIMBUS_PARAMETER(UpAxis, int),
};
#undef NIMBUS_PARAMETER
}

void vtkNimbusSkyDomeSource::AddSkyParameters(vtkNimbusSky* sky, vtkFieldData* fieldData)
{
  if (!sky || !fieldData)
  {
    return;
  }
  for (const SkyParameter& parameter : SkyParameters)
  {
    vtkNew<vtkDoubleArray> array;
    array->SetName(parameter.Name);
    array->SetNumberOfValues(1);
    array->SetValue(0, parameter.Get(sky));
    fieldData->AddArray(array); // replaces an array of the same name
  }
}

int vtkNimbusSkyDomeSource::ApplySkyParameters(vtkFieldData* fieldData, vtkNimbusSky* sky)
{
  if (!sky)
  {
    return 0;
  }
  vtkNew<vtkNimbusSky> defaults;
  int found = 0;
  bool turbidityFound = false;
  for (const SkyParameter& parameter : SkyParameters)
  {
    vtkDataArray* array = fieldData ? fieldData->GetArray(parameter.Name) : nullptr;
    const bool isTurbidity = std::string(parameter.Name) == "Turbidity";
    if (array && array->GetNumberOfTuples() > 0 && array->GetNumberOfComponents() > 0)
    {
      parameter.Set(sky, array->GetComponent(0, 0));
      turbidityFound = turbidityFound || isTurbidity;
      ++found;
    }
    else if (turbidityFound && std::string(parameter.Name) == "MieScatteringPerMetre")
    {
      // The same setting as Turbidity, already set: no default over it.
    }
    else
    {
      parameter.Set(sky, parameter.Get(defaults));
    }
  }
  return found;
}

vtkNimbusSkyDomeSource::~vtkNimbusSkyDomeSource()
{
  this->SetSky(nullptr);
}

vtkMTimeType vtkNimbusSkyDomeSource::GetMTime()
{
  vtkMTimeType t = this->Superclass::GetMTime();
  if (this->Sky)
  {
    t = std::max(t, this->Sky->GetMTime());
  }
  return t;
}

int vtkNimbusSkyDomeSource::RequestData(
  vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  // No exception leaves a render or a pipeline request (VTK does not catch).
  try
  {
    vtkPolyData* output = vtkPolyData::GetData(outputVector, 0);
    vtkNimbusSky* sky = this->Sky;
    if (!sky)
    {
      vtkErrorMacro("Sky is null: set a vtkNimbusSky");
      return 0;
    }
    if (this->Preset >= 0)
    {
      sky->SetPreset(this->Preset);
    }
    const int rings = this->ElevationResolution, columns = this->AzimuthResolution;
    vtkNew<vtkPoints> points;
    vtkNew<vtkUnsignedCharArray> colors;
    colors->SetName("Colors");
    colors->SetNumberOfComponents(3);
    vtkNew<vtkFloatArray> radiance;
    radiance->SetName("Radiance");
    radiance->SetNumberOfComponents(3);
    double scale[3];
    sky->GetDisplayScale(scale);

    auto addPoint = [&](double elevationDeg, double azimuthDeg)
    {
      const double e = vtkMath::RadiansFromDegrees(elevationDeg);
      const double a = vtkMath::RadiansFromDegrees(azimuthDeg);
      const double d[3] = { std::cos(e) * std::sin(a), std::cos(e) * std::cos(a), std::sin(e) };
      // The dome stands on the sky's up axis: its direction in world axes.
      const auto w = nimbus::FromUpFrame(
        static_cast<nimbus::UpAxis>(sky->GetUpAxis()), { { d[0], d[1], d[2] } });
      points->InsertNextPoint(this->Center[0] + this->Radius * w[0],
        this->Center[1] + this->Radius * w[1], this->Center[2] + this->Radius * w[2]);
      double L[3];
      sky->GetRadiance(d, L);
      radiance->InsertNextTuple(L);
      unsigned char c[3];
      for (int i = 0; i < 3; ++i)
      {
        c[i] = static_cast<unsigned char>(std::lround(255.0 * nimbus::SrgbEncode(L[i] * scale[i])));
      }
      colors->InsertNextTypedTuple(c);
    };
    // Ring i (0 = horizon) at elevation 90 (i/n)^1.5; the zenith is one point.
    for (int i = 0; i < rings; ++i)
    {
      if (i % 4 == 0)
      {
        this->UpdateProgress(static_cast<double>(i) / rings);
      }
      const double elevation = 90.0 * std::pow(static_cast<double>(i) / rings, 1.5);
      for (int j = 0; j < columns; ++j)
      {
        addPoint(elevation, 360.0 * j / columns);
      }
    }
    addPoint(90.0, 0.0);
    const vtkIdType zenith = points->GetNumberOfPoints() - 1;

    vtkNew<vtkCellArray> polys;
    for (int i = 0; i + 1 < rings; ++i)
    {
      for (int j = 0; j < columns; ++j)
      {
        const vtkIdType a = static_cast<vtkIdType>(i) * columns + j;
        const vtkIdType b = static_cast<vtkIdType>(i) * columns + (j + 1) % columns;
        const vtkIdType quad[4] = { a, b, b + columns, a + columns };
        polys->InsertNextCell(4, quad);
      }
    }
    for (int j = 0; j < columns; ++j)
    {
      const vtkIdType a = static_cast<vtkIdType>(rings - 1) * columns + j;
      const vtkIdType b = static_cast<vtkIdType>(rings - 1) * columns + (j + 1) % columns;
      const vtkIdType tri[3] = { a, b, zenith };
      polys->InsertNextCell(3, tri);
    }
    output->SetPoints(points);
    output->SetPolys(polys);
    output->GetPointData()->SetScalars(colors);
    output->GetPointData()->AddArray(radiance);
    vtkNimbusSkyDomeSource::AddSkyParameters(sky, output->GetFieldData());
    this->UpdateProgress(1.0);
    return 1;
  }
  catch (const std::exception& error)
  {
    vtkErrorMacro("The sky dome was not built: " << error.what());
  }
  catch (...)
  {
    vtkErrorMacro("The sky dome was not built: an unknown exception.");
  }
  return 0;
}

void vtkNimbusSkyDomeSource::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Sky: " << this->Sky << "\n";
  os << indent << "Preset: " << this->Preset << "\n";
  os << indent << "Radius: " << this->Radius << "\n";
  os << indent << "Center: " << this->Center[0] << " " << this->Center[1] << " " << this->Center[2]
     << "\n";
  os << indent << "ElevationResolution: " << this->ElevationResolution << "\n";
  os << indent << "AzimuthResolution: " << this->AzimuthResolution << "\n";
  os << indent << "Turbidity: " << this->Turbidity << "\n";
  os << indent << "MieScatteringPerMetre: " << this->MieScatteringPerMetre << "\n";
}
