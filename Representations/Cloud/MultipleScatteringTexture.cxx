#include "MultipleScatteringTexture.h"

#include "BlackbodyEmission.h"
#include "CloudDensityTexture.h"
#include "EmissionTexture.h"
#include "MemoryBudget.h"
#include "SpectralColor.h"

#include "vtkDataArray.h"
#include "vtkImageData.h"
#include "vtkMatrix4x4.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkTextureObject.h"
#include "vtk_glew.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace nimbus
{
bool UploadFloatTexture3D(vtkOpenGLRenderWindow* window, vtkTextureObject* texture,
  const std::array<int, 3>& dimensions, int components, const float* texels)
{
  texture->SetContext(window);
  texture->ReleaseGraphicsResources(window);
  texture->SetWrapS(vtkTextureObject::ClampToEdge);
  texture->SetWrapT(vtkTextureObject::ClampToEdge);
  texture->SetWrapR(vtkTextureObject::ClampToEdge);
  texture->SetMinificationFilter(vtkTextureObject::Linear);
  texture->SetMagnificationFilter(vtkTextureObject::Linear);
  for (int i = 0; i < 16 && glGetError() != GL_NO_ERROR; ++i)
  {
    // errors of earlier GL calls are not this upload's
  }
  if (!texture->Create3DFromRaw(dimensions[0], dimensions[1], dimensions[2], components, VTK_FLOAT,
        const_cast<float*>(texels)) ||
    glGetError() == GL_OUT_OF_MEMORY)
  {
    texture->ReleaseGraphicsResources(window);
    return false;
  }
  return true;
}

bool UploadShCoefficients(vtkOpenGLRenderWindow* window, vtkTextureObject* const textures[3],
  const std::array<int, 3>& dimensions, const float* coefficients)
{
  const std::size_t points =
    static_cast<std::size_t>(dimensions[0]) * dimensions[1] * dimensions[2];
  std::vector<float> channel(4 * points);
  for (int c = 0; c < 3; ++c)
  {
    for (std::size_t i = 0; i < points; ++i)
    {
      for (int b = 0; b < 4; ++b)
      {
        channel[4 * i + b] = coefficients[12 * i + 4 * c + b];
      }
    }
    if (!UploadFloatTexture3D(window, textures[c], dimensions, 4, channel.data()))
    {
      for (int t = 0; t < 3; ++t)
      {
        textures[t]->ReleaseGraphicsResources(window);
      }
      return false;
    }
  }
  return true;
}

MultipleScatteringTexture::MultipleScatteringTexture() = default;
MultipleScatteringTexture::~MultipleScatteringTexture() = default;

DensityResamplePlan MultipleScatteringTexture::PlanGrid(
  vtkImageData* image, bool cellData, const Request& request)
{
  int pointDims[3];
  image->GetDimensions(pointDims);
  DensityResamplePlan plan;
  for (int k = 0; k < 3; ++k)
  {
    const int samples = cellData ? std::max(pointDims[k] - 1, 1) : pointDims[k];
    plan.InputDimensions[k] = samples;
    plan.Factors[k] =
      std::min(samples, std::max(1, request.Downsampling) * std::max(1, request.TextureFactors[k]));
    plan.OutputDimensions[k] = (samples + plan.Factors[k] - 1) / plan.Factors[k];
  }
  return plan;
}

vtkTextureObject* MultipleScatteringTexture::GetTexture(int channel) const
{
  return this->Textures[channel].GetPointer();
}

bool MultipleScatteringTexture::BuildGrid(vtkImageData* image, vtkDataArray* scalars, bool cellData,
  vtkMatrix4x4* dataToWorld, const Request& request, ExtinctionGrid& grid,
  std::array<int, 3>& factors, std::string& error)
{
  const DensityResamplePlan plan = PlanGrid(image, cellData, request);
  factors = plan.Factors;
  const ResampledDensity density = CloudDensityTexture::Resample(scalars, plan);
  grid.Dimensions = plan.OutputDimensions;
  grid.Extinction.resize(plan.OutputSize());
  const float* values = density.Data();
  for (std::size_t i = 0; i < grid.Extinction.size(); ++i)
  {
    grid.Extinction[i] = static_cast<float>(request.ExtinctionPerDensity * values[i]);
  }

  // Where grid point (i, j, k) sits: input sample position D i + (D - 1)/2 per axis
  // (cells: their centres), through the data -> world matrix, in metres.
  double origin[3], spacing[3];
  int extent[6];
  image->GetOrigin(origin);
  image->GetSpacing(spacing);
  image->GetExtent(extent);
  auto worldOf = [&](const double index[3])
  {
    double data[4] = { 0, 0, 0, 1 }, world[4];
    for (int k = 0; k < 3; ++k)
    {
      const double sample = factors[k] * index[k] + 0.5 * (factors[k] - 1) + (cellData ? 0.5 : 0.0);
      data[k] = origin[k] + (extent[2 * k] + sample) * spacing[k];
    }
    dataToWorld->MultiplyPoint(data, world);
    return Vector3{ { world[0] / world[3] * request.MetresPerUnit,
      world[1] / world[3] * request.MetresPerUnit, world[2] / world[3] * request.MetresPerUnit } };
  };
  const double zero[3] = { 0, 0, 0 };
  grid.Origin = worldOf(zero);
  for (int k = 0; k < 3; ++k)
  {
    double step[3] = { 0, 0, 0 };
    step[k] = 1.0;
    Vector3 axis = worldOf(step);
    for (int c = 0; c < 3; ++c)
    {
      axis[c] -= grid.Origin[c];
    }
    double length = Length(axis);
    if (!(length > 0.0) || !std::isfinite(length))
    {
      // A zero spacing: one metre (the axis is one sample thick, nothing travels it).
      axis = { { 0, 0, 0 } };
      axis[k] = 1.0;
      length = 1.0;
    }
    grid.Spacing[k] = length;
    grid.Axes[k] = { { axis[0] / length, axis[1] / length, axis[2] / length } };
  }
  for (int a = 0; a < 3; ++a)
  {
    for (int b = a + 1; b < 3; ++b)
    {
      if (std::abs(Dot(grid.Axes[a], grid.Axes[b])) > 1e-6)
      {
        error = "the volume's matrix shears the density grid; multiple scattering needs "
                "orthogonal axes";
        return false;
      }
    }
  }
  return true;
}

bool MultipleScatteringTexture::BuildEmission(vtkDataArray* scalars,
  const DensityResamplePlan& plan, const Request& request, std::vector<float>& emission,
  std::string& error)
{
  vtkDataArray* temperature = request.EmissionTemperature;
  const std::size_t samples = static_cast<std::size_t>(plan.InputDimensions[0]) *
    plan.InputDimensions[1] * plan.InputDimensions[2];
  if (!scalars || scalars->GetNumberOfComponents() != 1 ||
    temperature->GetNumberOfComponents() != 1 ||
    static_cast<std::size_t>(temperature->GetNumberOfTuples()) != samples ||
    static_cast<std::size_t>(scalars->GetNumberOfTuples()) != samples)
  {
    error = "the temperature array does not fit the density";
    return false;
  }
  std::vector<float> rho(samples), kelvin(samples);
  for (std::size_t i = 0; i < samples; ++i)
  {
    rho[i] = static_cast<float>(scalars->GetComponent(static_cast<vtkIdType>(i), 0));
    kelvin[i] = static_cast<float>(temperature->GetComponent(static_cast<vtkIdType>(i), 0));
  }
  try
  {
    static const SpectralSamples spectrum;
    const BlackbodyEmission blackbody(spectrum, request.EmissionReferenceKelvin);
    emission = ComputeEmissionTexels(rho.data(), kelvin.data(), plan.InputDimensions, plan.Factors,
      plan.OutputDimensions, blackbody);
  }
  catch (const std::invalid_argument& problem)
  {
    error = problem.what();
    return false;
  }
  // Linear sRGB of a red blackbody has negative channels; the shader clamps its texels
  // at 0 as well.
  for (float& e : emission)
  {
    e = static_cast<float>(std::min(request.EmissionRadiancePerMetre * std::max(e, 0.0f), 3.0e38));
  }
  return true;
}

bool MultipleScatteringTexture::FinerFirstScattering(const Request& request)
{
  return request.EmissionTemperature &&
    request.Options.Method == MultipleScatteringMethod::DiscreteDirections &&
    request.EmissionFirstScatteringDownsampling >= 1 &&
    request.EmissionFirstScatteringDownsampling < request.Downsampling;
}

namespace
{
// The 12 coefficients per point of `coarse` (grid points at input sample positions
// D i + (D - 1)/2 per axis, D = coarseFactors) interpolated trilinearly at the points
// of a grid of `fineDimensions` with factors `fineFactors` (clamped at the edges).
std::vector<float> Upsample(const std::vector<float>& coarse,
  const std::array<int, 3>& coarseDimensions, const std::array<int, 3>& coarseFactors,
  const std::array<int, 3>& fineDimensions, const std::array<int, 3>& fineFactors)
{
  std::array<std::vector<int>, 3> lower;
  std::array<std::vector<float>, 3> weight;
  for (int a = 0; a < 3; ++a)
  {
    for (int i = 0; i < fineDimensions[a]; ++i)
    {
      const double position = fineFactors[a] * i + 0.5 * (fineFactors[a] - 1);
      double u = (position - 0.5 * (coarseFactors[a] - 1)) / coarseFactors[a];
      u = std::min(std::max(u, 0.0), static_cast<double>(coarseDimensions[a] - 1));
      const int i0 = std::min(static_cast<int>(u), std::max(coarseDimensions[a] - 2, 0));
      lower[a].push_back(i0);
      weight[a].push_back(coarseDimensions[a] > 1 ? static_cast<float>(u - i0) : 0.0f);
    }
  }
  const std::size_t nx = coarseDimensions[0], ny = coarseDimensions[1];
  std::vector<float> fine(
    12 * static_cast<std::size_t>(fineDimensions[0]) * fineDimensions[1] * fineDimensions[2], 0.0f);
  std::size_t point = 0;
  for (int k = 0; k < fineDimensions[2]; ++k)
  {
    for (int j = 0; j < fineDimensions[1]; ++j)
    {
      for (int i = 0; i < fineDimensions[0]; ++i, ++point)
      {
        for (int corner = 0; corner < 8; ++corner)
        {
          const int bit[3] = { corner & 1, (corner >> 1) & 1, (corner >> 2) & 1 };
          const int idx[3] = { i, j, k };
          float w = 1.0f;
          std::size_t c[3];
          for (int a = 0; a < 3; ++a)
          {
            const float f = weight[a][idx[a]];
            w *= bit[a] ? f : 1.0f - f;
            c[a] = static_cast<std::size_t>(
              std::min(lower[a][idx[a]] + bit[a], coarseDimensions[a] - 1));
          }
          if (w == 0.0f)
          {
            continue;
          }
          const float* in = &coarse[12 * ((c[2] * ny + c[1]) * nx + c[0])];
          for (int q = 0; q < 12; ++q)
          {
            fine[12 * point + q] += w * in[q];
          }
        }
      }
    }
  }
  return fine;
}
} // namespace

bool MultipleScatteringTexture::AddFinerFirstScattering(vtkImageData* image, vtkDataArray* scalars,
  bool cellData, vtkMatrix4x4* dataToWorld, const Request& request,
  const std::array<int, 3>& coarseFactors, ExtinctionGrid& grid, std::array<int, 3>& factors,
  std::string& error)
{
  Request fineRequest = request;
  fineRequest.Downsampling = request.EmissionFirstScatteringDownsampling;
  ExtinctionGrid fine;
  std::array<int, 3> fineFactors{ { 1, 1, 1 } };
  std::vector<float> emission;
  if (!BuildGrid(image, scalars, cellData, dataToWorld, fineRequest, fine, fineFactors, error) ||
    !BuildEmission(scalars, PlanGrid(image, cellData, fineRequest), fineRequest, emission, error))
  {
    return false;
  }
  std::vector<float> coefficients = Upsample(
    this->Field.Coefficients, grid.Dimensions, coarseFactors, fine.Dimensions, fineFactors);
  const std::vector<float> first =
    EmissionFirstScattering(fine, request.Optics, emission, request.Options);
  for (std::size_t q = 0; q < coefficients.size(); ++q)
  {
    coefficients[q] += first[q];
  }
  this->Field.Coefficients = std::move(coefficients);
  this->Field.Dimensions = fine.Dimensions;
  grid = std::move(fine);
  factors = fineFactors;
  return true;
}

bool MultipleScatteringTexture::Update(vtkOpenGLRenderWindow* window, vtkImageData* image,
  vtkDataArray* scalars, bool cellData, vtkMatrix4x4* dataToWorld, double densityVersion,
  const Request& request, const std::function<void(double)>& progress, std::string& error)
{
  std::vector<double> key = request.Key;
  key.push_back(densityVersion);
  for (int k = 0; k < 16; ++k)
  {
    key.push_back(dataToWorld->GetData()[k]);
  }
  if (this->Valid && key == this->SolvedKey)
  {
    return true;
  }
  if (!this->Valid && key == this->FailedKey)
  {
    error = this->FailedError; // not tried again until something changes
    return false;
  }
  const bool ok =
    this->Solve(window, image, scalars, cellData, dataToWorld, request, key, progress, error);
  this->FailedKey = ok ? std::vector<double>() : key;
  this->FailedError = ok ? std::string() : error;
  return ok;
}

bool MultipleScatteringTexture::Solve(vtkOpenGLRenderWindow* window, vtkImageData* image,
  vtkDataArray* scalars, bool cellData, vtkMatrix4x4* dataToWorld, const Request& request,
  const std::vector<double>& key, const std::function<void(double)>& progress, std::string& error)
{
  this->Valid = false;
  this->Textured = false;
  this->SolvedKey.clear();
  const auto start = std::chrono::steady_clock::now();
  if (request.Options.Method == MultipleScatteringMethod::None)
  {
    this->Field = MultipleScatteringField();
    this->Valid = true;
    this->SolvedKey = key;
    return true;
  }

  ExtinctionGrid grid;
  std::array<int, 3> factors{ { 1, 1, 1 } };
  // The estimate before any allocation: the grid's own floats plus the solver's.
  {
    ExtinctionGrid shape;
    shape.Dimensions = PlanGrid(image, cellData, request).OutputDimensions;
    const double points =
      static_cast<double>(shape.Dimensions[0]) * shape.Dimensions[1] * shape.Dimensions[2];
    // The grid's extinction, and with a glow its emission (3 floats per point) and the
    // density and temperature as floats while it is built.
    this->LastEstimatedBytes =
      EstimateMultipleScatteringBytes(shape, request.Options) + 4.0 * points;
    if (request.EmissionTemperature)
    {
      this->LastEstimatedBytes +=
        12.0 * points + 8.0 * static_cast<double>(request.EmissionTemperature->GetNumberOfTuples());
    }
    if (FinerFirstScattering(request))
    {
      // The finer grid's extinction, emission, first scattering, the solve's J on it,
      // a source and a radiance (RGB each).
      Request fine = request;
      fine.Downsampling = request.EmissionFirstScatteringDownsampling;
      const auto d = PlanGrid(image, cellData, fine).OutputDimensions;
      this->LastEstimatedBytes +=
        (4.0 + 12.0 + 48.0 + 48.0 + 24.0) * static_cast<double>(d[0]) * d[1] * d[2];
    }
    if (request.BudgetBytes > 0.0 && this->LastEstimatedBytes > request.BudgetBytes)
    {
      std::ostringstream message;
      message << "Multiple scattering on a " << shape.Dimensions[0] << "x" << shape.Dimensions[1]
              << "x" << shape.Dimensions[2] << " grid: "
              << OverBudgetMessage("the solver", this->LastEstimatedBytes, request.BudgetBytes)
              << ". Raise the grid downsampling, use fewer directions or raise "
                 "MultipleScatteringMemoryBudgetMiB; the cloud is drawn without it.";
      error = message.str();
      return false;
    }
  }
  if (!BuildGrid(image, scalars, cellData, dataToWorld, request, grid, factors, error))
  {
    error = "Multiple scattering: " + error + "; the cloud is drawn without it.";
    return false;
  }
  CloudLighting lighting = request.Lighting;
  if (request.EmissionTemperature &&
    !BuildEmission(scalars, PlanGrid(image, cellData, request), request, lighting.Emission, error))
  {
    error = "Multiple scattering of the glow: " + error + "; the cloud is drawn without it.";
    return false;
  }
  MultipleScatteringOptions options = request.Options;
  options.EmissionFirstScatteringApart = FinerFirstScattering(request);
  try
  {
    this->Field = SolveMultipleScattering(grid, request.Optics, lighting, options, progress);
    if (options.EmissionFirstScatteringApart &&
      !this->AddFinerFirstScattering(
        image, scalars, cellData, dataToWorld, request, factors, grid, factors, error))
    {
      error = "Multiple scattering of the glow: " + error + "; the cloud is drawn without it.";
      return false;
    }
  }
  catch (const std::exception& problem)
  {
    error = std::string("Multiple scattering failed: ") + problem.what() +
      "; the cloud is drawn without it.";
    return false;
  }
  for (int k = 0; k < 3; ++k)
  {
    // Density texture coordinate u = (s + 0.5) / (n_tex f) for input sample
    // position s; this texture's v = (s + 0.5) / (n' D).
    this->TextureScale[k] = static_cast<double>(request.TextureDimensions[k]) *
      request.TextureFactors[k] / (static_cast<double>(grid.Dimensions[k]) * factors[k]);
  }
  bool any = false;
  for (float c : this->Field.Coefficients)
  {
    any = any || c != 0.0f;
  }
  if (any)
  {
    vtkTextureObject* textures[3] = { this->Textures[0], this->Textures[1], this->Textures[2] };
    if (!UploadShCoefficients(window, textures, grid.Dimensions, this->Field.Coefficients.data()))
    {
      error = "Could not upload the multiple-scattering texture (" +
        FormatBytes(48.0 * grid.NumberOfPoints()) +
        "; GL out of memory?); the cloud is drawn without it.";
      return false;
    }
    this->Textured = true;
  }
  ++this->Solves;
  this->Valid = true;
  this->SolvedKey = key;
  this->LastSeconds =
    std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return true;
}

void MultipleScatteringTexture::Release(vtkWindow* window)
{
  for (auto& t : this->Textures)
  {
    t->ReleaseGraphicsResources(window);
  }
  this->Valid = false;
  this->Textured = false;
  this->SolvedKey.clear();
}
} // namespace nimbus
