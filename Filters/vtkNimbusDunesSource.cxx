#include "vtkNimbusDunesSource.h"

#include "DuneAutomaton.h"

#include "vtkCellArray.h"
#include "vtkFieldData.h"
#include "vtkFloatArray.h"
#include "vtkIdTypeArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include "vtkUnsignedCharArray.h"

#include <algorithm>
#include <cmath>
#include <new>
#include <stdexcept>
#include <string>
#include <vector>

vtkStandardNewMacro(vtkNimbusDunesSource);

namespace
{
constexpr double MaximumWork = 1.0e11; // cell steps in one request (minutes)
constexpr int MaximumCells = 8192;     // a side
constexpr double RippleNoiseMetres = 0.001;
constexpr double MinimumShownSandMetres = 1.0e-6;
}

struct vtkNimbusDunesSource::vtkInternals
{
  bool Valid = false;
  vtkMTimeType SourceTime = 0;
  std::unique_ptr<nimbus::SandAutomaton> Dunes;  // the latest state
  std::unique_ptr<nimbus::SandAutomaton> SpinUp; // the state at time 0
  std::vector<double> Ripples;                   // the ripple tile's heights
  void Clear()
  {
    this->Valid = false;
    this->Dunes.reset();
    this->SpinUp.reset();
    this->Ripples.clear();
  }
};

vtkNimbusDunesSource::vtkNimbusDunesSource()
  : Internals(new vtkInternals)
{
  this->SetNumberOfInputPorts(0);
  this->SetNumberOfOutputPorts(2);
  const nimbus::SandParameters dunes = nimbus::DuneParameters();
  const nimbus::SandParameters ripples = nimbus::RippleParameters();
  this->Dimensions[0] = 128;
  this->Dimensions[1] = 128;
  this->CellSizeMetres = dunes.CellSizeMetres;
  this->SandDepthMetres = 3.0;
  this->SandDepthVariationMetres = 3.0;
  this->SaltationLengthMetres = dunes.SaltationLengthMetres;
  this->SaltationHeightGain = dunes.SaltationHeightGain;
  this->SaltationDepthMetres = dunes.SaltationDepthMetres;
  this->CreepRate = dunes.CreepRate;
  this->ShadowAngleDegrees = dunes.ShadowAngleDegrees;
  this->ReposeAngleDegrees = dunes.ReposeAngleDegrees;
  this->SpinUpSteps = 2000;
  this->StepsPerTimeStep = 10;
  this->NumberOfTimeSteps = 100;
  this->RippleResolution = 256;
  this->RippleCellSizeMetres = ripples.CellSizeMetres;
  this->RippleSteps = 400;
  this->RippleSaltationLengthMetres = ripples.SaltationLengthMetres;
  this->RippleSaltationHeightGain = ripples.SaltationHeightGain;
  this->RippleSaltationDepthMetres = ripples.SaltationDepthMetres;
  this->RippleCreepRate = ripples.CreepRate;
  this->Seed = 1;
  this->NumberOfThreads = 0;
  this->NumberOfStepsComputed = 0;
}

vtkNimbusDunesSource::~vtkNimbusDunesSource() = default;

vtkImageData* vtkNimbusDunesSource::GetRippleOutput()
{
  return vtkImageData::SafeDownCast(this->GetOutputDataObject(1));
}

int vtkNimbusDunesSource::FillOutputPortInformation(int port, vtkInformation* info)
{
  info->Set(vtkDataObject::DATA_TYPE_NAME(), port == 0 ? "vtkPolyData" : "vtkImageData");
  return 1;
}

int vtkNimbusDunesSource::RequestInformation(
  vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  for (int port = 0; port < 2; ++port)
  {
    vtkInformation* outInfo = outputVector->GetInformationObject(port);
    outInfo->Remove(vtkStreamingDemandDrivenPipeline::TIME_STEPS());
    outInfo->Remove(vtkStreamingDemandDrivenPipeline::TIME_RANGE());
    std::vector<double> times(static_cast<std::size_t>(this->NumberOfTimeSteps) + 1);
    for (std::size_t k = 0; k < times.size(); ++k)
    {
      times[k] = static_cast<double>(k) * this->StepsPerTimeStep;
    }
    outInfo->Set(
      vtkStreamingDemandDrivenPipeline::TIME_STEPS(), times.data(), static_cast<int>(times.size()));
    const double range[2] = { 0.0, times.back() };
    outInfo->Set(vtkStreamingDemandDrivenPipeline::TIME_RANGE(), range, 2);
    if (port == 1)
    {
      const int r = std::max(this->RippleResolution, 1);
      const int extent[6] = { 0, r - 1, 0, r - 1, 0, 0 };
      outInfo->Set(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), extent, 6);
      const double spacing =
        std::isfinite(this->RippleCellSizeMetres) && this->RippleCellSizeMetres > 0.0
        ? this->RippleCellSizeMetres
        : 1.0;
      const double spacings[3] = { spacing, spacing, spacing };
      const double origin[3] = { 0.0, 0.0, 0.0 };
      outInfo->Set(vtkDataObject::SPACING(), spacings, 3);
      outInfo->Set(vtkDataObject::ORIGIN(), origin, 3);
    }
  }
  return 1;
}

bool vtkNimbusDunesSource::CheckParameters()
{
  const int* d = this->Dimensions;
  if (d[0] < 4 || d[1] < 4 || d[0] > MaximumCells || d[1] > MaximumCells)
  {
    vtkErrorMacro(<< "Dimensions must be 4 to " << MaximumCells << " cells a side, got (" << d[0]
                  << ", " << d[1] << ").");
    return false;
  }
  const int r = this->RippleResolution;
  if (r < 8 || r > 4096 || r % 8 != 0)
  {
    vtkErrorMacro(<< "RippleResolution must be a multiple of 8 in [8, 4096] texels, got " << r
                  << ".");
    return false;
  }
  const struct
  {
    const char* Name;
    double Value;
    bool Positive; // > 0, else >= 0
  } lengths[] = { { "CellSizeMetres", this->CellSizeMetres, true },
    { "SandDepthMetres", this->SandDepthMetres, true },
    { "SandDepthVariationMetres", this->SandDepthVariationMetres, false },
    { "SaltationLengthMetres", this->SaltationLengthMetres, false },
    { "SaltationDepthMetres", this->SaltationDepthMetres, false },
    { "RippleCellSizeMetres", this->RippleCellSizeMetres, true },
    { "RippleSaltationLengthMetres", this->RippleSaltationLengthMetres, false },
    { "RippleSaltationDepthMetres", this->RippleSaltationDepthMetres, false } };
  for (const auto& length : lengths)
  {
    if (!std::isfinite(length.Value) || length.Value < 0.0 ||
      (length.Positive && !(length.Value > 0.0)) || length.Value > 1.0e6)
    {
      vtkErrorMacro(<< length.Name << " must be a finite length " << (length.Positive ? ">" : ">=")
                    << " 0 and at most 1e6 m, got " << length.Value << ".");
      return false;
    }
  }
  nimbus::SandParameters dunes = nimbus::DuneParameters();
  dunes.Dimensions[0] = d[0];
  dunes.Dimensions[1] = d[1];
  dunes.CellSizeMetres = this->CellSizeMetres;
  dunes.SaltationLengthMetres = this->SaltationLengthMetres;
  dunes.SaltationHeightGain = this->SaltationHeightGain;
  dunes.SaltationDepthMetres = this->SaltationDepthMetres;
  dunes.CreepRate = this->CreepRate;
  dunes.ShadowAngleDegrees = this->ShadowAngleDegrees;
  dunes.ReposeAngleDegrees = this->ReposeAngleDegrees;
  std::string problem = nimbus::CheckSandParameters(dunes);
  if (problem.empty())
  {
    nimbus::SandParameters ripples = nimbus::RippleParameters();
    ripples.Dimensions[0] = r;
    ripples.Dimensions[1] = r;
    ripples.CellSizeMetres = this->RippleCellSizeMetres;
    ripples.SaltationLengthMetres = this->RippleSaltationLengthMetres;
    ripples.SaltationHeightGain = this->RippleSaltationHeightGain;
    ripples.SaltationDepthMetres = this->RippleSaltationDepthMetres;
    ripples.CreepRate = this->RippleCreepRate;
    problem = nimbus::CheckSandParameters(ripples);
    if (!problem.empty())
    {
      problem = "ripples: " + problem;
    }
  }
  if (!problem.empty())
  {
    vtkErrorMacro(<< "Bad dune parameters: " << problem << ".");
    return false;
  }
  const double work = static_cast<double>(d[0]) * d[1] *
      (static_cast<double>(this->SpinUpSteps) +
        static_cast<double>(this->NumberOfTimeSteps) * this->StepsPerTimeStep) +
    static_cast<double>(r) * r * this->RippleSteps;
  if (!(work <= MaximumWork))
  {
    vtkErrorMacro(<< "The dunes would need " << work << " cell steps, more than the limit of "
                  << MaximumWork << "; lower Dimensions, SpinUpSteps, NumberOfTimeSteps, "
                  << "StepsPerTimeStep or RippleSteps.");
    return false;
  }
  return true;
}

int vtkNimbusDunesSource::RequestData(
  vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  vtkPolyData* surface = vtkPolyData::GetData(outputVector, 0);
  vtkImageData* ripples = vtkImageData::GetData(outputVector, 1);
  surface->Initialize();
  ripples->Initialize();
  if (!this->CheckParameters())
  {
    this->Internals->Clear();
    return 1;
  }
  try
  {
    return this->Generate(outputVector);
  }
  catch (const std::bad_alloc&)
  {
    vtkErrorMacro(<< "Out of memory while growing the dunes; lower Dimensions or "
                     "RippleResolution.");
  }
  catch (const std::exception& error)
  {
    vtkErrorMacro(<< "Cannot grow the dunes: " << error.what());
  }
  this->Internals->Clear();
  surface->Initialize();
  ripples->Initialize();
  return 1;
}

namespace
{
// Dune surface: (nx + 1) x (ny + 1) points, the periodic field closed on its far sides.
void FillSurface(
  const std::vector<double>& h, int nx, int ny, double dx, double tile, vtkPolyData* surface)
{
  const int px = nx + 1;
  const int py = ny + 1;
  const vtkIdType count = static_cast<vtkIdType>(px) * py;
  vtkNew<vtkPoints> points;
  points->SetDataTypeToFloat();
  points->SetNumberOfPoints(count);
  vtkNew<vtkFloatArray> height, normals, tcoords, tangents;
  height->SetName("Height");
  normals->SetName("Normals");
  tcoords->SetName("TextureCoordinates");
  tangents->SetName("Tangents");
  height->SetNumberOfTuples(count);
  for (auto* array : { normals.Get(), tangents.Get() })
  {
    array->SetNumberOfComponents(3);
    array->SetNumberOfTuples(count);
  }
  tcoords->SetNumberOfComponents(2);
  tcoords->SetNumberOfTuples(count);
  auto at = [&](int x, int y)
  {
    return h[static_cast<std::size_t>((x + nx) % nx) +
      static_cast<std::size_t>(nx) * ((y + ny) % ny)];
  };
  const double x0 = -0.5 * nx * dx;
  const double y0 = -0.5 * ny * dx;
  for (int j = 0; j < py; ++j)
  {
    for (int i = 0; i < px; ++i)
    {
      const vtkIdType id = static_cast<vtkIdType>(i) + static_cast<vtkIdType>(px) * j;
      // Sand thinner than a micrometre (what the hops leave on bare rock) is shown as rock.
      const double z = at(i, j) < MinimumShownSandMetres ? 0.0 : at(i, j);
      const double x = x0 + i * dx;
      const double y = y0 + j * dx;
      points->SetPoint(id, x, y, z);
      height->SetValue(id, static_cast<float>(z));
      const double gx = (at(i + 1, j) - at(i - 1, j)) / (2.0 * dx);
      const double gy = (at(i, j + 1) - at(i, j - 1)) / (2.0 * dx);
      const double n = std::sqrt(gx * gx + gy * gy + 1.0);
      normals->SetTuple3(id, -gx / n, -gy / n, 1.0 / n);
      const double t = std::sqrt(1.0 + gx * gx);
      tangents->SetTuple3(id, 1.0 / t, 0.0, gx / t);
      tcoords->SetTuple2(id, (x - x0) / tile, (y - y0) / tile);
    }
  }
  vtkNew<vtkCellArray> quads;
  vtkNew<vtkIdTypeArray> offsets, connectivity;
  const vtkIdType cells = static_cast<vtkIdType>(nx) * ny;
  offsets->SetNumberOfValues(cells + 1);
  connectivity->SetNumberOfValues(4 * cells);
  vtkIdType c = 0;
  for (int j = 0; j < ny; ++j)
  {
    for (int i = 0; i < nx; ++i, ++c)
    {
      const vtkIdType a = static_cast<vtkIdType>(i) + static_cast<vtkIdType>(px) * j;
      offsets->SetValue(c, 4 * c);
      connectivity->SetValue(4 * c + 0, a);
      connectivity->SetValue(4 * c + 1, a + 1);
      connectivity->SetValue(4 * c + 2, a + 1 + px);
      connectivity->SetValue(4 * c + 3, a + px);
    }
  }
  offsets->SetValue(cells, 4 * cells);
  quads->SetData(offsets, connectivity);
  surface->SetPoints(points);
  surface->SetPolys(quads);
  surface->GetPointData()->AddArray(height);
  surface->GetPointData()->SetScalars(height);
  surface->GetPointData()->SetNormals(normals);
  surface->GetPointData()->SetTCoords(tcoords);
  surface->GetPointData()->SetTangents(tangents);
}

// Ripple arrays for one level of the pyramid.
void FillRipples(const nimbus::RippleNormalLevel& level, vtkImageData* image)
{
  const int n = level.Size;
  image->SetDimensions(n, n, 1);
  image->SetSpacing(level.TexelMetres, level.TexelMetres, level.TexelMetres);
  image->SetOrigin(0.0, 0.0, 0.0);
  const vtkIdType count = static_cast<vtkIdType>(n) * n;
  vtkNew<vtkFloatArray> height, normal;
  vtkNew<vtkUnsignedCharArray> map;
  height->SetName("RippleHeight");
  normal->SetName("RippleNormal");
  map->SetName("RippleNormalMap");
  height->SetNumberOfTuples(count);
  normal->SetNumberOfComponents(3);
  normal->SetNumberOfTuples(count);
  map->SetNumberOfComponents(3);
  map->SetNumberOfTuples(count);
  for (vtkIdType t = 0; t < count; ++t)
  {
    height->SetValue(t, level.Heights[t]);
    for (int c = 0; c < 3; ++c)
    {
      const float v = level.Normals[3 * t + c];
      normal->SetTypedComponent(t, c, v);
      map->SetTypedComponent(
        t, c, static_cast<unsigned char>(std::lround(std::clamp(127.5 * (v + 1.0), 0.0, 255.0))));
    }
  }
  image->GetPointData()->SetScalars(height);
  image->GetPointData()->AddArray(normal);
  image->GetPointData()->AddArray(map);
}
}

int vtkNimbusDunesSource::Generate(vtkInformationVector* outputVector)
{
  auto& internals = *this->Internals;
  if (!internals.Valid || internals.SourceTime != this->GetMTime())
  {
    internals.Clear();
    internals.SourceTime = this->GetMTime();
    this->NumberOfStepsComputed = 0;
  }
  const int nx = this->Dimensions[0];
  const int ny = this->Dimensions[1];
  const int r = this->RippleResolution;
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  double time = 0.0;
  if (outInfo->Has(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP()))
  {
    time = outInfo->Get(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP());
  }
  const double lastTime = static_cast<double>(this->NumberOfTimeSteps) * this->StepsPerTimeStep;
  time = std::isfinite(time) ? std::clamp(time, 0.0, lastTime) : 0.0;
  const long long target = this->SpinUpSteps + static_cast<long long>(std::floor(time));

  // What this request runs, for the progress bar: the ripples, the spin-up, the steps.
  const double rippleWork =
    internals.Ripples.empty() ? static_cast<double>(r) * r * this->RippleSteps : 0.0;
  long long duneSteps = target;
  if (internals.Dunes && internals.Dunes->StepCount() <= target)
  {
    duneSteps = target - internals.Dunes->StepCount();
  }
  else if (internals.SpinUp)
  {
    duneSteps = target - internals.SpinUp->StepCount();
  }
  const double totalWork =
    std::max(1.0, rippleWork + static_cast<double>(nx) * ny * static_cast<double>(duneSteps));
  double doneWork = 0.0;
  bool aborted = false;
  auto progress = [&](double cellsPerStep)
  {
    return [&, cellsPerStep](long long stepsDone)
    {
      if (stepsDone % 16 == 0)
      {
        this->UpdateProgress(std::min(1.0, (doneWork + cellsPerStep * stepsDone) / totalWork));
        if (this->CheckAbort())
        {
          aborted = true;
          return false;
        }
      }
      return true;
    };
  };
  const auto seed = static_cast<std::uint64_t>(static_cast<std::uint32_t>(this->Seed));

  if (internals.Ripples.empty())
  {
    nimbus::SandParameters p = nimbus::RippleParameters();
    p.Dimensions[0] = r;
    p.Dimensions[1] = r;
    p.CellSizeMetres = this->RippleCellSizeMetres;
    p.SaltationLengthMetres = this->RippleSaltationLengthMetres;
    p.SaltationHeightGain = this->RippleSaltationHeightGain;
    p.SaltationDepthMetres = this->RippleSaltationDepthMetres;
    p.CreepRate = this->RippleCreepRate;
    nimbus::SandAutomaton ripples(
      p, nimbus::RandomSandBed(r, r, 0.0, RippleNoiseMetres, seed ^ 0x5249504cULL));
    ripples.Run(this->RippleSteps, this->NumberOfThreads, progress(static_cast<double>(r) * r));
    if (aborted)
    {
      internals.Clear();
      return 1;
    }
    internals.Ripples = ripples.Heights();
    doneWork += rippleWork;
  }

  if (!internals.Dunes || internals.Dunes->StepCount() > target)
  {
    if (internals.SpinUp)
    {
      internals.Dunes.reset(new nimbus::SandAutomaton(*internals.SpinUp));
    }
    else
    {
      nimbus::SandParameters p = nimbus::DuneParameters();
      p.Dimensions[0] = nx;
      p.Dimensions[1] = ny;
      p.CellSizeMetres = this->CellSizeMetres;
      p.SaltationLengthMetres = this->SaltationLengthMetres;
      p.SaltationHeightGain = this->SaltationHeightGain;
      p.SaltationDepthMetres = this->SaltationDepthMetres;
      p.CreepRate = this->CreepRate;
      p.ShadowAngleDegrees = this->ShadowAngleDegrees;
      p.ReposeAngleDegrees = this->ReposeAngleDegrees;
      internals.Dunes.reset(new nimbus::SandAutomaton(p,
        nimbus::RandomSandBed(
          nx, ny, this->SandDepthMetres, this->SandDepthVariationMetres, seed)));
    }
  }
  auto& dunes = *internals.Dunes;
  const double cellsPerStep = static_cast<double>(nx) * ny;
  if (!internals.SpinUp)
  {
    const long long before = dunes.StepCount();
    dunes.Run(this->SpinUpSteps - before, this->NumberOfThreads, progress(cellsPerStep));
    this->NumberOfStepsComputed += dunes.StepCount() - before;
    if (aborted)
    {
      internals.Clear();
      return 1;
    }
    doneWork += cellsPerStep * static_cast<double>(dunes.StepCount() - before);
    internals.SpinUp.reset(new nimbus::SandAutomaton(dunes));
  }
  const long long before = dunes.StepCount();
  dunes.Run(target - before, this->NumberOfThreads, progress(cellsPerStep));
  this->NumberOfStepsComputed += dunes.StepCount() - before;
  if (aborted)
  {
    internals.Dunes.reset();
    vtkPolyData::GetData(outputVector, 0)->Initialize();
    return 1;
  }
  internals.Valid = true;

  const double tile = r * this->RippleCellSizeMetres;
  vtkPolyData* surface = vtkPolyData::GetData(outputVector, 0);
  FillSurface(dunes.Heights(), nx, ny, this->CellSizeMetres, tile, surface);
  vtkNew<vtkFloatArray> step;
  step->SetName("DuneAutomatonStep");
  step->InsertNextValue(static_cast<float>(dunes.StepCount()));
  surface->GetFieldData()->AddArray(step);
  surface->GetInformation()->Set(vtkDataObject::DATA_TIME_STEP(), time);

  const auto pyramid =
    nimbus::RippleNormalPyramid(internals.Ripples, r, this->RippleCellSizeMetres, 1);
  vtkImageData* ripples = vtkImageData::GetData(outputVector, 1);
  FillRipples(pyramid[0], ripples);
  ripples->GetInformation()->Set(vtkDataObject::DATA_TIME_STEP(), time);
  this->UpdateProgress(1.0);
  return 1;
}

bool vtkNimbusDunesSource::RippleNormalLevel(vtkImageData* ripples, int level, vtkImageData* output)
{
  if (!ripples || !output || level < 0 || level > 12)
  {
    return false;
  }
  vtkDataArray* heights = ripples->GetPointData()->GetArray("RippleHeight");
  int dims[3];
  ripples->GetDimensions(dims);
  const int n = dims[0];
  if (!heights || n != dims[1] || dims[2] != 1 || n < 1 || n % (1 << level) != 0 ||
    heights->GetNumberOfTuples() != static_cast<vtkIdType>(n) * n)
  {
    return false;
  }
  std::vector<double> values(static_cast<std::size_t>(n) * n);
  for (std::size_t t = 0; t < values.size(); ++t)
  {
    values[t] = heights->GetComponent(static_cast<vtkIdType>(t), 0);
  }
  const double spacing = ripples->GetSpacing()[0];
  if (!(spacing > 0.0) || !std::isfinite(spacing))
  {
    return false;
  }
  const auto pyramid = nimbus::RippleNormalPyramid(values, n, spacing, level + 1);
  output->Initialize();
  FillRipples(pyramid[level], output);
  return true;
}

void vtkNimbusDunesSource::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Dimensions: (" << this->Dimensions[0] << ", " << this->Dimensions[1] << ")\n";
  os << indent << "CellSizeMetres: " << this->CellSizeMetres << "\n";
  os << indent << "SandDepthMetres: " << this->SandDepthMetres << "\n";
  os << indent << "SandDepthVariationMetres: " << this->SandDepthVariationMetres << "\n";
  os << indent << "SaltationLengthMetres: " << this->SaltationLengthMetres << "\n";
  os << indent << "SaltationHeightGain: " << this->SaltationHeightGain << "\n";
  os << indent << "SaltationDepthMetres: " << this->SaltationDepthMetres << "\n";
  os << indent << "CreepRate: " << this->CreepRate << "\n";
  os << indent << "ShadowAngleDegrees: " << this->ShadowAngleDegrees << "\n";
  os << indent << "ReposeAngleDegrees: " << this->ReposeAngleDegrees << "\n";
  os << indent << "SpinUpSteps: " << this->SpinUpSteps << "\n";
  os << indent << "StepsPerTimeStep: " << this->StepsPerTimeStep << "\n";
  os << indent << "NumberOfTimeSteps: " << this->NumberOfTimeSteps << "\n";
  os << indent << "RippleResolution: " << this->RippleResolution << "\n";
  os << indent << "RippleCellSizeMetres: " << this->RippleCellSizeMetres << "\n";
  os << indent << "RippleSteps: " << this->RippleSteps << "\n";
  os << indent << "RippleSaltationLengthMetres: " << this->RippleSaltationLengthMetres << "\n";
  os << indent << "RippleSaltationHeightGain: " << this->RippleSaltationHeightGain << "\n";
  os << indent << "RippleSaltationDepthMetres: " << this->RippleSaltationDepthMetres << "\n";
  os << indent << "RippleCreepRate: " << this->RippleCreepRate << "\n";
  os << indent << "Seed: " << this->Seed << "\n";
  os << indent << "NumberOfThreads: " << this->NumberOfThreads << "\n";
  os << indent << "NumberOfStepsComputed: " << this->NumberOfStepsComputed << "\n";
}
