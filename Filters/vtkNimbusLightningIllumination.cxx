#include "vtkNimbusLightningIllumination.h"

#include "FiniteSetters.h"

#include "LightningBasis.h"
#include "LightningFirstScattering.h"

#include "vtkCellArray.h"
#include "vtkCellData.h"
#include "vtkDataArray.h"
#include "vtkDataObject.h"
#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkIntArray.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPolyData.h"
#include "vtkStreamingDemandDrivenPipeline.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <stdexcept>
#include <vector>

vtkStandardNewMacro(vtkNimbusLightningIllumination);

// Setters with a range refuse NaN and infinity at once (the value is kept) and clamp
// finite values (Common/FiniteSetters.h).
nimbusDefineFiniteSetter(vtkNimbusLightningIllumination, ExtinctionPerDensity);
nimbusDefineFiniteSetter(vtkNimbusLightningIllumination, Albedo);
nimbusDefineFiniteSetter(vtkNimbusLightningIllumination, CloudG);
nimbusDefineFiniteSetter(vtkNimbusLightningIllumination, MetresPerUnit);
nimbusDefineFiniteSetter(vtkNimbusLightningIllumination, LightSpacingMetres);
nimbusDefineFiniteSetter(vtkNimbusLightningIllumination, Threshold);
nimbusDefineFiniteSetter(vtkNimbusLightningIllumination, MemoryBudgetMiB);
nimbusDefineFiniteSetter(vtkNimbusLightningIllumination, PointSourceSpacing);

namespace
{
constexpr int kAutomaticGridSide = 16; // points along the longest side when automatic
// The first scattering's grid: the density's, in blocks when it has more samples than this.
constexpr double kFirstScatteringPoints = 64.0 * 64.0 * 64.0;
struct Aborted
{
};
} // namespace

struct vtkNimbusLightningIllumination::vtkInternals
{
  std::string Fingerprint; // of Basis; "" when none
  nimbus::LightningBasis Basis;
  std::array<int, 3> Factors{ { 1, 1, 1 } };
  std::string CacheFile;
  double PrecomputeSeconds = 0.0;
  bool FromDisk = false;
  double RelightSeconds = 0.0;
  int SourcesOutside = 0;
  // The first scattering on the density's grid: the sources grouped by brightness, and
  // each group's field kept across time steps.
  std::vector<nimbus::LightningSourceGroup> FirstScatteringGroups;
  nimbus::LightningFirstScatteringCache FirstScattering;
  double FirstScatteringSeconds = 0.0;
};

vtkNimbusLightningIllumination::vtkNimbusLightningIllumination()
  : Internals(new vtkInternals)
{
  this->SetNumberOfInputPorts(2);
  this->SetNumberOfOutputPorts(1);
  this->SetInputArrayToProcess(
    0, 0, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, vtkDataSetAttributes::SCALARS);
}

vtkNimbusLightningIllumination::~vtkNimbusLightningIllumination() = default;

int vtkNimbusLightningIllumination::FillInputPortInformation(int port, vtkInformation* info)
{
  if (port == 0)
  {
    info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkImageData");
    return 1;
  }
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkPolyData");
  info->Set(vtkAlgorithm::INPUT_IS_OPTIONAL(), 1);
  return 1;
}

int vtkNimbusLightningIllumination::RequestInformation(
  vtkInformation* request, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  if (!this->Superclass::RequestInformation(request, inputVector, outputVector))
  {
    return 0;
  }
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  outInfo->Remove(vtkStreamingDemandDrivenPipeline::TIME_STEPS());
  outInfo->Remove(vtkStreamingDemandDrivenPipeline::TIME_RANGE());
  vtkInformation* lightningInfo = inputVector[1]->GetInformationObject(0);
  if (lightningInfo)
  {
    // The time is the lightning's; the cloud is taken as steady.
    for (vtkInformationDoubleVectorKey* key : { vtkStreamingDemandDrivenPipeline::TIME_STEPS(),
           vtkStreamingDemandDrivenPipeline::TIME_RANGE() })
    {
      if (lightningInfo->Has(key))
      {
        outInfo->CopyEntry(lightningInfo, key);
      }
    }
  }
  return 1;
}

int vtkNimbusLightningIllumination::RequestUpdateExtent(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector*)
{
  // The basis needs the whole cloud.
  vtkInformation* cloudInfo = inputVector[0]->GetInformationObject(0);
  cloudInfo->Set(vtkStreamingDemandDrivenPipeline::UPDATE_EXTENT(),
    cloudInfo->Get(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT()), 6);
  return 1;
}

namespace
{
// The density in blocks of `factors` input samples (each block's mean), sigma_t =
// extinctionPerDensity x density; the grid placed in metres. "" or what is wrong.
std::string BuildCloudGrid(vtkImageData* image, vtkDataArray* scalars, bool cellData,
  int downsampling, double extinctionPerDensity, double metresPerUnit, nimbus::ExtinctionGrid& grid,
  std::array<int, 3>& factors)
{
  int pointDims[3];
  image->GetDimensions(pointDims);
  int samples[3];
  int longest = 1;
  for (int k = 0; k < 3; ++k)
  {
    samples[k] = cellData ? std::max(pointDims[k] - 1, 1) : pointDims[k];
    longest = std::max(longest, samples[k]);
  }
  const int d =
    downsampling > 0 ? downsampling : (longest + kAutomaticGridSide - 1) / kAutomaticGridSide;
  for (int k = 0; k < 3; ++k)
  {
    factors[k] = std::min(samples[k], std::max(1, d));
    grid.Dimensions[k] = (samples[k] + factors[k] - 1) / factors[k];
  }
  if (scalars->GetNumberOfTuples() != static_cast<vtkIdType>(samples[0]) * samples[1] * samples[2])
  {
    return "the density array does not have one value per sample";
  }
  grid.Extinction.assign(grid.NumberOfPoints(), 0.0f);
  std::vector<int> counts(grid.NumberOfPoints(), 0);
  vtkIdType bad = 0;
  vtkIdType id = 0;
  for (int k = 0; k < samples[2]; ++k)
  {
    for (int j = 0; j < samples[1]; ++j)
    {
      for (int i = 0; i < samples[0]; ++i, ++id)
      {
        const double v = scalars->GetComponent(id, 0);
        if (!std::isfinite(v) || v < 0.0)
        {
          ++bad;
          continue;
        }
        const std::size_t cell = grid.Index(i / factors[0], j / factors[1], k / factors[2]);
        grid.Extinction[cell] += static_cast<float>(v);
        ++counts[cell];
      }
    }
  }
  if (bad > 0)
  {
    std::ostringstream why;
    why << bad << " density values are negative, NaN or infinite";
    return why.str();
  }
  for (std::size_t c = 0; c < grid.Extinction.size(); ++c)
  {
    grid.Extinction[c] = counts[c] > 0
      ? static_cast<float>(extinctionPerDensity * grid.Extinction[c] / counts[c])
      : 0.0f;
  }
  double origin[3], spacing[3];
  int extent[6];
  image->GetOrigin(origin);
  image->GetSpacing(spacing);
  image->GetExtent(extent);
  for (int k = 0; k < 3; ++k)
  {
    const double first = extent[2 * k] + 0.5 * (factors[k] - 1) + (cellData ? 0.5 : 0.0);
    grid.Origin[k] = (origin[k] + first * spacing[k]) * metresPerUnit;
    const double step = std::abs(spacing[k] * factors[k] * metresPerUnit);
    grid.Spacing[k] = step > 0.0 && std::isfinite(step) ? step : 1.0;
    if (spacing[k] < 0.0)
    {
      grid.Axes[k][k] = -1.0;
    }
  }
  return "";
}

std::string ExpandUser(const std::string& path)
{
  if (!path.empty() && path[0] == '~')
  {
    if (const char* home = std::getenv("HOME"))
    {
      return std::string(home) + path.substr(1);
    }
  }
  return path;
}
} // namespace

std::string vtkNimbusLightningIllumination::DefaultCacheDirectory()
{
  if (const char* explicitDirectory = std::getenv("NIMBUS_CACHE_DIR"))
  {
    if (*explicitDirectory)
    {
      return explicitDirectory;
    }
  }
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"))
  {
    if (*xdg)
    {
      return std::string(xdg) + "/nimbus";
    }
  }
  if (const char* home = std::getenv("HOME"))
  {
    return std::string(home) + "/.cache/nimbus";
  }
  return "";
}

int vtkNimbusLightningIllumination::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkImageData* cloud = vtkImageData::GetData(inputVector[0], 0);
  vtkPolyData* lightning = vtkPolyData::GetData(inputVector[1], 0);
  vtkImageData* output = vtkImageData::GetData(outputVector, 0);
  output->ShallowCopy(cloud);
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  if (outInfo->Has(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP()))
  {
    output->GetInformation()->Set(vtkDataObject::DATA_TIME_STEP(),
      outInfo->Get(vtkStreamingDemandDrivenPipeline::UPDATE_TIME_STEP()));
  }
  // A shallow copy shares the input's field data object: the lightning goes on a copy.
  vtkNew<vtkFieldData> fieldData;
  if (cloud->GetFieldData())
  {
    fieldData->ShallowCopy(cloud->GetFieldData());
  }
  for (const char* name : { "nimbus_lightning_in_scattering", "nimbus_lightning_grid",
         "nimbus_lightning_optics", "nimbus_lightning_first_scattering",
         "nimbus_lightning_first_scattering_reduced", "nimbus_lightning_first_scattering_grid" })
  {
    fieldData->RemoveArray(name);
  }
  output->SetFieldData(fieldData);
  if (!lightning)
  {
    return 1; // no lightning: the cloud as it is
  }

  int association = vtkDataObject::FIELD_ASSOCIATION_POINTS;
  vtkDataArray* scalars = this->GetInputArrayToProcess(0, inputVector, association);
  if (!scalars)
  {
    scalars = cloud->GetPointData()->GetScalars();
    association = vtkDataObject::FIELD_ASSOCIATION_POINTS;
  }
  if (!scalars)
  {
    scalars = cloud->GetCellData()->GetScalars();
    association = vtkDataObject::FIELD_ASSOCIATION_CELLS;
  }
  if (!scalars)
  {
    vtkErrorMacro("Lightning illumination: the cloud has no density array (point or cell "
                  "scalars); the cloud passes through unlit.");
    return 1;
  }
  const bool cellData = association == vtkDataObject::FIELD_ASSOCIATION_CELLS;
  const double colour[3] = { this->LightningColor[0], this->LightningColor[1],
    this->LightningColor[2] };
  for (double c : colour)
  {
    if (!std::isfinite(c) || c < 0.0)
    {
      vtkErrorMacro("Lightning illumination: LightningColor must be finite and >= 0; the "
                    "cloud passes through unlit.");
      return 1;
    }
  }

  std::vector<nimbus::PointLight> sources;
  if (!this->ReadLightningSources(lightning, colour, sources))
  {
    return 1;
  }

  nimbus::ExtinctionGrid grid;
  std::array<int, 3> factors{ { 1, 1, 1 } };
  nimbus::VirtualLightGrid lights;
  double low[3], high[3];
  if (!this->BuildIlluminationGrids(cloud, scalars, cellData, grid, factors, lights, low, high))
  {
    return 1;
  }

  nimbus::CloudOptics optics;
  optics.Albedo = this->Albedo;
  optics.G = this->CloudG;
  nimbus::LightningBasisOptions options;
  options.NumberOfDirections = this->NumberOfDirections;
  options.Orders = this->Orders;
  options.Threshold = this->Threshold;
  options.Threads = this->NumberOfThreads;
  options.MemoryBudgetBytes = this->MemoryBudgetMiB * 1048576.0;
  // The first scattering on the density's grid replaces the basis's own (003's b_il).
  options.IncludeFirstScattering = !this->FirstScatteringOnDensityGrid;
  const std::string fingerprint = nimbus::LightningBasisFingerprint(grid, optics, lights, options);

  if (this->Method == DirectSolve)
  {
    return this->SolveDirectly(fieldData, cloud, scalars, cellData, grid, optics, sources, factors);
  }
  if (!this->EnsureBasis(grid, optics, lights, options, fingerprint, factors))
  {
    return 1;
  }
  vtkInternals& in = *this->Internals;

  // Sources outside the virtual lights' box would be moved onto it (Eq. 6's cells end
  // there), closer to the cloud than they are: their intensity is dimmed by the inverse
  // square of the distances to the cloud's centre, where they are and where they land.
  const nimbus::VirtualLightGrid& box = in.Basis.Lights;
  nimbus::Vector3 centre;
  for (int k = 0; k < 3; ++k)
  {
    centre[k] = 0.5 * (low[k] + high[k]);
  }
  int outside = 0;
  for (nimbus::PointLight& s : sources)
  {
    nimbus::Vector3 landed = s.Position;
    for (int k = 0; k < 3; ++k)
    {
      landed[k] = std::clamp(landed[k], box.Nodes[k].front(), box.Nodes[k].back());
    }
    if (landed != s.Position)
    {
      ++outside;
      double far = 0.0, near = 0.0;
      for (int k = 0; k < 3; ++k)
      {
        far += (s.Position[k] - centre[k]) * (s.Position[k] - centre[k]);
        near += (landed[k] - centre[k]) * (landed[k] - centre[k]);
      }
      const double dim = far > 0.0 ? std::min(1.0, near / far) : 1.0;
      for (int k = 0; k < 3; ++k)
      {
        s.Intensity[k] *= dim;
      }
    }
  }
  in.SourcesOutside = outside;

  // The relight (003 Eqs. 6-10).
  const auto start = std::chrono::steady_clock::now();
  nimbus::MultipleScatteringField field;
  try
  {
    field = nimbus::RelightLightning(
      in.Basis, nimbus::DistributeToVirtualLights(in.Basis.Lights, sources));
  }
  catch (const std::exception& problem)
  {
    vtkErrorMacro(
      "Lightning illumination: " << problem.what() << "; the cloud passes through unlit.");
    return 1;
  }
  in.RelightSeconds =
    std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  this->AddLightningArrays(fieldData, field, cellData);
  this->AddFirstScattering(fieldData, cloud, scalars, cellData);
  this->UpdateProgress(1.0);
  return 1;
}

// The forward peak the solver folds into the beam (delta-M: f = k_2 of the cloud's phase
// function, as MultipleScattering.cxx's truncation takes it), which the first scattering
// must give back (FirstScatteringForwardPeak).
nimbus::FirstScatteringForwardPeak vtkNimbusLightningIllumination::ForwardPeak() const
{
  nimbus::CloudOptics optics;
  optics.Albedo = this->Albedo;
  optics.G = this->CloudG;
  const double k1 = nimbus::PhaseLegendreCoefficient(optics, 1);
  const double k2 = nimbus::PhaseLegendreCoefficient(optics, 2);
  nimbus::FirstScatteringForwardPeak peak;
  peak.Fraction = (k2 > 0.0 && k1 > k2 && k2 < 0.999) ? k2 : 0.0;
  peak.Albedo = this->Albedo;
  return peak;
}

// The point sources at this time (strokes split every PointSourceSpacing metres, or the
// given points), times the colour; the first scattering's groups by brightness. False,
// with an error, when they are malformed.
bool vtkNimbusLightningIllumination::ReadLightningSources(
  vtkPolyData* lightning, const double colour[3], std::vector<nimbus::PointLight>& sources)
{
  this->Internals->FirstScatteringGroups.clear();
  vtkDataArray* pointIntensity = lightning->GetPointData()->GetArray("intensity");
  vtkDataArray* cellIntensity = lightning->GetCellData()->GetArray("intensity");
  if (lightning->GetNumberOfLines() > 0)
  {
    if (!cellIntensity)
    {
      vtkErrorMacro("Lightning illumination: the strokes have no cell array \"intensity\" "
                    "(radiant intensity per metre); the cloud passes through unlit.");
      return false;
    }
    std::vector<nimbus::LightningSegment> segments;
    std::vector<double> peaks; // each segment's peak intensity, when the strokes say
    vtkDataArray* peakIntensity = lightning->GetCellData()->GetArray("peak_intensity");
    vtkCellArray* lines = lightning->GetLines();
    const vtkIdType offset = lightning->GetNumberOfVerts();
    vtkIdType npts = 0;
    const vtkIdType* ids = nullptr;
    vtkIdType cell = 0;
    for (lines->InitTraversal(); lines->GetNextCell(npts, ids); ++cell)
    {
      const double intensity = cellIntensity->GetComponent(offset + cell, 0);
      for (vtkIdType p = 0; p + 1 < npts; ++p)
      {
        nimbus::LightningSegment s;
        double a[3], b[3];
        lightning->GetPoint(ids[p], a);
        lightning->GetPoint(ids[p + 1], b);
        for (int k = 0; k < 3; ++k)
        {
          s.A[k] = a[k] * this->MetresPerUnit;
          s.B[k] = b[k] * this->MetresPerUnit;
        }
        s.Intensity = intensity;
        segments.push_back(s);
        if (peakIntensity)
        {
          peaks.push_back(peakIntensity->GetComponent(offset + cell, 0));
        }
      }
    }
    try
    {
      for (const nimbus::LightningSegment& s : segments)
      {
        if (!std::isfinite(s.Intensity) || s.Intensity < 0.0 || !std::isfinite(s.Length()))
        {
          throw std::invalid_argument("a stroke is not finite or has a negative intensity");
        }
      }
      sources = nimbus::LightningPointSources(segments, this->PointSourceSpacing);
      if (this->FirstScatteringOnDensityGrid)
      {
        for (double& peak : peaks)
        {
          peak = std::isfinite(peak) ? peak : 0.0; // a bad peak: its segment alone
        }
        this->Internals->FirstScatteringGroups =
          nimbus::GroupLightningSegments(segments, peaks, this->PointSourceSpacing);
      }
    }
    catch (const std::exception& problem)
    {
      vtkErrorMacro(
        "Lightning illumination: " << problem.what() << "; the cloud passes through unlit.");
      return false;
    }
  }
  else if (lightning->GetNumberOfPoints() > 0)
  {
    if (!pointIntensity)
    {
      vtkErrorMacro("Lightning illumination: the point sources have no point array "
                    "\"intensity\"; the cloud passes through unlit.");
      return false;
    }
    sources.resize(static_cast<std::size_t>(lightning->GetNumberOfPoints()));
    for (vtkIdType i = 0; i < lightning->GetNumberOfPoints(); ++i)
    {
      double x[3];
      lightning->GetPoint(i, x);
      const double intensity = pointIntensity->GetComponent(i, 0);
      for (int k = 0; k < 3; ++k)
      {
        sources[i].Position[k] = x[k] * this->MetresPerUnit;
        sources[i].Intensity[k] = intensity;
      }
    }
    if (this->FirstScatteringOnDensityGrid)
    {
      // Grouped by brightness when the sources say their peak (the lightning source does).
      vtkDataArray* peakIntensity = lightning->GetPointData()->GetArray("peak_intensity");
      std::vector<nimbus::ScalarPointSource> scalar;
      std::vector<double> peaks;
      for (vtkIdType i = 0; i < lightning->GetNumberOfPoints(); ++i)
      {
        const nimbus::PointLight& s = sources[i];
        if (nimbus::IsFinite(s.Position) && std::isfinite(s.Intensity[0]) && s.Intensity[0] >= 0)
        {
          scalar.push_back({ s.Position, s.Intensity[0] });
          const double peak = peakIntensity ? peakIntensity->GetComponent(i, 0) : 0.0;
          peaks.push_back(std::isfinite(peak) ? peak : 0.0);
        }
      }
      this->Internals->FirstScatteringGroups = nimbus::GroupPointSources(scalar, peaks);
    }
  }
  for (nimbus::PointLight& s : sources)
  {
    for (int k = 0; k < 3; ++k)
    {
      s.Intensity[k] *= colour[k];
      if (!std::isfinite(s.Position[k]) || !std::isfinite(s.Intensity[k]) || s.Intensity[k] < 0.0)
      {
        vtkErrorMacro("Lightning illumination: a lightning source's position or intensity "
                      "is not finite or is negative; the cloud passes through unlit.");
        return false;
      }
    }
  }
  return true;
}

// The cloud's extinction grid (blocks of Downsampling samples) and the virtual lights
// over it (003 Eq. 4); low and high: the grid's box. False, with an error, when refused.
bool vtkNimbusLightningIllumination::BuildIlluminationGrids(vtkImageData* cloud,
  vtkDataArray* scalars, bool cellData, nimbus::ExtinctionGrid& grid, std::array<int, 3>& factors,
  nimbus::VirtualLightGrid& lights, double low[3], double high[3])
{
  const std::string gridProblem = BuildCloudGrid(cloud, scalars, cellData, this->Downsampling,
    this->ExtinctionPerDensity, this->MetresPerUnit, grid, factors);
  if (!gridProblem.empty())
  {
    vtkErrorMacro("Lightning illumination: " << gridProblem << "; the cloud passes through unlit.");
    return false;
  }
  for (int k = 0; k < 3; ++k)
  {
    const double a = grid.Origin[k];
    const double b = grid.Origin[k] + grid.Axes[k][k] * grid.Spacing[k] * (grid.Dimensions[k] - 1);
    low[k] = std::min(a, b);
    high[k] = std::max(a, b);
  }
  // The cloud bottom z_cld: the lowest layer holding density.
  double cloudBottom = high[2];
  for (int k = 0; k < grid.Dimensions[2] && cloudBottom == high[2]; ++k)
  {
    for (int j = 0; j < grid.Dimensions[1]; ++j)
    {
      for (int i = 0; i < grid.Dimensions[0]; ++i)
      {
        if (grid.Extinction[grid.Index(i, j, k)] > 0.0f)
        {
          cloudBottom = grid.Position(i, j, k)[2];
        }
      }
    }
  }
  nimbus::VirtualLightGridParameters lightParameters;
  const double side = std::max(high[0] - low[0], high[1] - low[1]);
  lightParameters.BaseInterval = this->LightSpacingMetres > 0.0
    ? this->LightSpacingMetres
    : std::max(side / 12.0, std::max(grid.Spacing[0], grid.Spacing[1]));
  const double bottom = std::isfinite(this->SimulationBottomMetres)
    ? std::min(this->SimulationBottomMetres, cloudBottom)
    : cloudBottom;
  lightParameters.Low = { { low[0], low[1], bottom } };
  lightParameters.High = { { high[0], high[1], std::max(high[2], bottom + 1.0) } };
  for (int k = 0; k < 2; ++k)
  {
    if (!(lightParameters.High[k] > lightParameters.Low[k]))
    {
      // A cloud one sample wide: a box one light spacing wide around it.
      lightParameters.Low[k] -= 0.5 * lightParameters.BaseInterval;
      lightParameters.High[k] += 0.5 * lightParameters.BaseInterval;
    }
  }
  lightParameters.CloudBottom = std::min(cloudBottom, lightParameters.High[2]);
  try
  {
    lights = nimbus::MakeVirtualLightGrid(lightParameters);
  }
  catch (const std::exception& problem)
  {
    vtkErrorMacro("Lightning illumination: the virtual lights: "
      << problem.what() << "; the cloud passes through unlit.");
    return false;
  }
  return true;
}

// The reference method: the solver with the actual point sources, every time step.
int vtkNimbusLightningIllumination::SolveDirectly(vtkFieldData* fieldData, vtkImageData* cloud,
  vtkDataArray* scalars, bool cellData, const nimbus::ExtinctionGrid& grid,
  const nimbus::CloudOptics& optics, const std::vector<nimbus::PointLight>& sources,
  const std::array<int, 3>& factors)
{
  vtkInternals& in = *this->Internals;
  // The reference: the solver with the actual point sources, every time step.
  const auto start = std::chrono::steady_clock::now();
  nimbus::MultipleScatteringField field;
  try
  {
    nimbus::CloudLighting lighting;
    lighting.HasSun = false;
    lighting.PointLights = sources;
    nimbus::MultipleScatteringOptions solver;
    solver.NumberOfDirections = this->NumberOfDirections;
    solver.Orders = this->Orders;
    solver.SkyLight = false;
    solver.PointLightFirstScattering = !this->FirstScatteringOnDensityGrid;
    solver.Threads = this->NumberOfThreads;
    if (sources.empty())
    {
      field.Dimensions = grid.Dimensions;
      field.Coefficients.assign(12 * grid.NumberOfPoints(), 0.0f);
    }
    else
    {
      field = nimbus::SolveMultipleScattering(grid, optics, lighting, solver,
        [this](double fraction)
        {
          this->UpdateProgress(0.95 * fraction);
          if (this->CheckAbort())
          {
            throw Aborted();
          }
        });
    }
  }
  catch (const Aborted&)
  {
    return 1;
  }
  catch (const std::exception& problem)
  {
    vtkErrorMacro("Lightning illumination: the direct solve refused: "
      << problem.what() << ". The cloud passes through unlit.");
    return 1;
  }
  in.RelightSeconds =
    std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  in.Factors = factors;
  this->AddLightningArrays(fieldData, field, cellData);
  this->AddFirstScattering(fieldData, cloud, scalars, cellData);
  this->UpdateProgress(1.0);
  return 1;
}

// The basis for this grid, optics, lights and options: kept in memory, read from the
// disk cache, or precomputed (and cached). False when stopped or refused (with an error).
bool vtkNimbusLightningIllumination::EnsureBasis(const nimbus::ExtinctionGrid& grid,
  const nimbus::CloudOptics& optics, const nimbus::VirtualLightGrid& lights,
  const nimbus::LightningBasisOptions& options, const std::string& fingerprint,
  const std::array<int, 3>& factors)
{
  vtkInternals& in = *this->Internals;
  if (fingerprint != in.Fingerprint)
  {
    in.Fingerprint.clear();
    in.Basis = nimbus::LightningBasis();
    in.PrecomputeSeconds = 0.0;
    in.FromDisk = false;
    in.CacheFile.clear();
    const std::string directory =
      ExpandUser(this->CacheDirectory.empty() ? DefaultCacheDirectory() : this->CacheDirectory);
    if (this->UseDiskCache && !directory.empty())
    {
      in.CacheFile = directory + "/lightning-basis-" + fingerprint + ".bin";
      std::string why;
      if (nimbus::ReadLightningBasis(in.CacheFile, fingerprint, in.Basis, why))
      {
        in.FromDisk = true;
        in.Fingerprint = fingerprint;
      }
    }
    if (!in.FromDisk)
    {
      try
      {
        in.Basis = nimbus::PrecomputeLightningBasis(grid, optics, lights, options,
          [this](double fraction)
          {
            this->UpdateProgress(0.95 * fraction);
            if (this->CheckAbort())
            {
              throw Aborted();
            }
          });
      }
      catch (const Aborted&)
      {
        in.Basis = nimbus::LightningBasis();
        return false; // stopped by the user: the cloud unlit
      }
      catch (const std::exception& problem)
      {
        in.Basis = nimbus::LightningBasis();
        vtkErrorMacro("Lightning illumination: the precompute refused: "
          << problem.what() << ". The cloud passes through unlit.");
        return false;
      }
      in.PrecomputeSeconds = in.Basis.Seconds;
      in.Fingerprint = fingerprint;
      if (!in.CacheFile.empty())
      {
        try
        {
          std::filesystem::create_directories(std::filesystem::path(in.CacheFile).parent_path());
          nimbus::WriteLightningBasis(in.Basis, fingerprint, in.CacheFile);
        }
        catch (const std::exception& problem)
        {
          vtkWarningMacro("Lightning illumination: the basis could not be cached on disk ("
            << problem.what() << "); it is kept in memory.");
        }
      }
    }
    in.Factors = factors;
  }
  else
  {
    in.PrecomputeSeconds = 0.0; // from memory
  }
  return true;
}

void vtkNimbusLightningIllumination::AddFirstScattering(
  vtkFieldData* fieldData, vtkImageData* cloud, vtkDataArray* scalars, bool cellData)
{
  vtkInternals& in = *this->Internals;
  in.FirstScatteringSeconds = 0.0;
  if (!this->FirstScatteringOnDensityGrid)
  {
    return;
  }
  // The density's grid, in blocks when it has more than kFirstScatteringPoints samples.
  int dims[3];
  cloud->GetDimensions(dims);
  double samples = 1.0;
  for (int k = 0; k < 3; ++k)
  {
    samples *= cellData ? std::max(dims[k] - 1, 1) : dims[k];
  }
  int blocks = this->FirstScatteringDownsampling;
  if (blocks <= 0)
  {
    blocks = 1;
    while (samples / (blocks * blocks * blocks) > kFirstScatteringPoints)
    {
      ++blocks;
    }
  }
  nimbus::ExtinctionGrid grid;
  std::array<int, 3> factors{ { 1, 1, 1 } };
  const std::string problem = BuildCloudGrid(cloud, scalars, cellData, blocks,
    this->ExtinctionPerDensity, this->MetresPerUnit, grid, factors);
  if (!problem.empty())
  {
    return; // the same grid refused above already
  }
  const auto start = std::chrono::steady_clock::now();
  nimbus::FirstScatteringField field;
  try
  {
    field = in.FirstScattering.Evaluate(grid, in.FirstScatteringGroups, this->ForwardPeak(),
      this->NumberOfThreads,
      [this](double fraction)
      {
        if (this->CheckAbort())
        {
          throw Aborted();
        }
        this->UpdateProgress(0.95 + 0.05 * fraction);
      });
  }
  catch (const Aborted&)
  {
    return;
  }
  // The delta-M view's first scattering (the mapper's LightningDeltaMView): the beam
  // through the reduced extinction (1 - f albedo) sigma_t alone, no peak given back,
  // E' = I exp(-(1 - f albedo) tau) / r^2 (Wiscombe 1977, delta-M).
  const nimbus::FirstScatteringForwardPeak peak = this->ForwardPeak();
  nimbus::FirstScatteringField reduced;
  if (peak.Fraction > 0.0)
  {
    const float scale = static_cast<float>(1.0 - peak.Fraction * peak.Albedo);
    for (float& sigma : grid.Extinction)
    {
      sigma *= scale;
    }
    try
    {
      reduced = in.FirstScattering.Evaluate(grid, in.FirstScatteringGroups,
        nimbus::FirstScatteringForwardPeak(), this->NumberOfThreads,
        [this](double)
        {
          if (this->CheckAbort())
          {
            throw Aborted();
          }
        });
    }
    catch (const Aborted&)
    {
      return;
    }
  }
  in.FirstScatteringSeconds =
    std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  // E and F carry the lightning's colour: the grey sources' field times it, per channel
  // in the mapper (the colour is in nimbus_lightning_first_scattering_grid).
  auto addField = [fieldData](const nimbus::FirstScatteringField& f, const char* name)
  {
    vtkNew<vtkFloatArray> array;
    array->SetName(name);
    array->SetNumberOfComponents(4);
    array->SetNumberOfTuples(static_cast<vtkIdType>(f.Values.size() / 4));
    std::copy(f.Values.begin(), f.Values.end(), array->GetPointer(0));
    fieldData->AddArray(array);
  };
  addField(field, "nimbus_lightning_first_scattering");
  if (!reduced.Values.empty())
  {
    addField(reduced, "nimbus_lightning_first_scattering_reduced");
  }
  vtkNew<vtkDoubleArray> gridArray;
  gridArray->SetName("nimbus_lightning_first_scattering_grid");
  gridArray->SetNumberOfTuples(10);
  for (int k = 0; k < 3; ++k)
  {
    gridArray->SetValue(k, field.Dimensions[k]);
    gridArray->SetValue(3 + k, factors[k]);
    gridArray->SetValue(7 + k, this->LightningColor[k]);
  }
  gridArray->SetValue(6, cellData ? 1 : 0);
  fieldData->AddArray(gridArray);
}

void vtkNimbusLightningIllumination::AddLightningArrays(
  vtkFieldData* fieldData, const nimbus::MultipleScatteringField& field, bool cellData)
{
  vtkNew<vtkFloatArray> inScattering;
  inScattering->SetName("nimbus_lightning_in_scattering");
  inScattering->SetNumberOfComponents(12);
  inScattering->SetNumberOfTuples(static_cast<vtkIdType>(field.Coefficients.size() / 12));
  std::copy(field.Coefficients.begin(), field.Coefficients.end(), inScattering->GetPointer(0));
  vtkNew<vtkIntArray> gridArray;
  gridArray->SetName("nimbus_lightning_grid");
  gridArray->SetNumberOfTuples(7);
  for (int k = 0; k < 3; ++k)
  {
    gridArray->SetValue(k, field.Dimensions[k]);
    gridArray->SetValue(3 + k, this->Internals->Factors[k]);
  }
  gridArray->SetValue(6, cellData ? 1 : 0);
  vtkNew<vtkDoubleArray> opticsArray;
  opticsArray->SetName("nimbus_lightning_optics");
  opticsArray->SetNumberOfTuples(4);
  opticsArray->SetValue(0, this->ExtinctionPerDensity);
  opticsArray->SetValue(1, this->Albedo);
  opticsArray->SetValue(2, this->CloudG);
  opticsArray->SetValue(3, this->MetresPerUnit);
  fieldData->AddArray(inScattering);
  fieldData->AddArray(gridArray);
  fieldData->AddArray(opticsArray);
}

double vtkNimbusLightningIllumination::GetLastFirstScatteringSeconds() const
{
  return this->Internals->FirstScatteringSeconds;
}

int vtkNimbusLightningIllumination::GetFirstScatteringGroupsKept() const
{
  return this->Internals->FirstScattering.GetHits();
}

int vtkNimbusLightningIllumination::GetFirstScatteringGroupsComputed() const
{
  return this->Internals->FirstScattering.GetMisses();
}

int vtkNimbusLightningIllumination::GetFirstScatteringGroupsExtended() const
{
  return this->Internals->FirstScattering.GetExtensions();
}

double vtkNimbusLightningIllumination::GetLastPrecomputeSeconds() const
{
  return this->Internals->PrecomputeSeconds;
}

bool vtkNimbusLightningIllumination::GetLastBasisFromDisk() const
{
  return this->Internals->FromDisk;
}

int vtkNimbusLightningIllumination::GetNumberOfVirtualLights() const
{
  return static_cast<int>(this->Internals->Basis.Lights.NumberOfNodes());
}

void vtkNimbusLightningIllumination::GetGridDimensions(int dims[3]) const
{
  for (int k = 0; k < 3; ++k)
  {
    dims[k] = this->Internals->Basis.Dimensions[k];
  }
}

double vtkNimbusLightningIllumination::GetBasisBytes() const
{
  return this->Internals->Basis.CompressedBytes();
}

double vtkNimbusLightningIllumination::GetUncompressedBasisBytes() const
{
  return this->Internals->Basis.Fields.empty() ? 0.0 : this->Internals->Basis.UncompressedBytes();
}

double vtkNimbusLightningIllumination::GetLastRelightSeconds() const
{
  return this->Internals->RelightSeconds;
}

int vtkNimbusLightningIllumination::GetNumberOfSourcesOutside() const
{
  return this->Internals->SourcesOutside;
}

std::string vtkNimbusLightningIllumination::GetCacheFile() const
{
  return this->Internals->CacheFile;
}

void vtkNimbusLightningIllumination::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Method: " << (this->Method == DirectSolve ? "DirectSolve" : "Basis") << "\n";
  os << indent << "ExtinctionPerDensity: " << this->ExtinctionPerDensity << " /m per unit\n";
  os << indent << "Albedo: " << this->Albedo << "\n";
  os << indent << "CloudG: " << this->CloudG << "\n";
  os << indent << "MetresPerUnit: " << this->MetresPerUnit << "\n";
  os << indent << "Downsampling: " << this->Downsampling
     << (this->Downsampling == 0 ? " (automatic)" : "") << "\n";
  os << indent << "LightSpacingMetres: " << this->LightSpacingMetres
     << (this->LightSpacingMetres == 0.0 ? " (automatic)" : "") << "\n";
  os << indent << "SimulationBottomMetres: " << this->SimulationBottomMetres << "\n";
  os << indent << "NumberOfDirections: " << this->NumberOfDirections << "\n";
  os << indent << "Orders: " << this->Orders << "\n";
  os << indent << "Threshold: " << this->Threshold << "\n";
  os << indent << "NumberOfThreads: " << this->NumberOfThreads << "\n";
  os << indent << "MemoryBudgetMiB: " << this->MemoryBudgetMiB << "\n";
  os << indent << "UseDiskCache: " << this->UseDiskCache << "\n";
  os << indent << "CacheDirectory: "
     << (this->CacheDirectory.empty() ? "(default) " + DefaultCacheDirectory()
                                      : this->CacheDirectory)
     << "\n";
  os << indent << "LightningColor: " << this->LightningColor[0] << ", " << this->LightningColor[1]
     << ", " << this->LightningColor[2] << "\n";
  os << indent << "PointSourceSpacing: " << this->PointSourceSpacing << " m\n";
  os << indent << "FirstScatteringOnDensityGrid: " << this->FirstScatteringOnDensityGrid << "\n";
  os << indent << "FirstScatteringDownsampling: " << this->FirstScatteringDownsampling << "\n";
  os << indent << "Virtual lights: " << this->GetNumberOfVirtualLights() << "\n";
  os << indent << "Last precompute: " << this->GetLastPrecomputeSeconds() << " s"
     << (this->GetLastBasisFromDisk() ? " (read from the disk cache)" : "") << "\n";
  os << indent << "Last relight: " << this->GetLastRelightSeconds() << " s\n";
}
