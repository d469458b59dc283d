#include "CloudDensityTexture.h"
#include "MemoryBudget.h"

#include "vtkAOSDataArrayTemplate.h"
#include "vtkArrayDispatch.h"
#include "vtkDataArray.h"
#include "vtkDataArrayRange.h"
#include "vtkImageData.h"
#include "vtkMatrix4x4.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkTextureObject.h"
#include "vtk_glew.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace nimbus
{
namespace
{
// Typed reads of the first component: contiguous arrays through their pointer
// (DensityResample.h may borrow it), any other layout through its tuple range.
struct ResampleWorker
{
  const DensityResamplePlan& Plan;
  ResampledDensity Result;

  template <typename ValueType>
  void operator()(vtkAOSDataArrayTemplate<ValueType>* array)
  {
    this->Result =
      ResampleDensity<ValueType>(array->GetPointer(0), array->GetNumberOfComponents(), this->Plan);
  }

  template <typename ArrayType>
  void operator()(ArrayType* array)
  {
    const auto tuples = vtk::DataArrayTupleRange(array);
    this->Result = ResampleDensityWith([&tuples](std::size_t i)
      { return static_cast<double>(tuples[static_cast<vtkIdType>(i)][0]); },
      this->Plan);
  }
};

const char* NameOf(vtkDataArray* array)
{
  return array->GetName() ? array->GetName() : "(unnamed)";
}
}

CloudDensityTexture::CloudDensityTexture() = default;
CloudDensityTexture::~CloudDensityTexture() = default;

ResampledDensity CloudDensityTexture::Resample(
  vtkDataArray* scalars, const DensityResamplePlan& plan)
{
  ResampleWorker worker{ plan, ResampledDensity() };
  if (!vtkArrayDispatch::Dispatch::Execute(scalars, worker))
  {
    worker(scalars); // an array type outside the dispatch list: generic access
  }
  return std::move(worker.Result);
}

namespace
{
std::array<double, 12> GeometryOf(vtkImageData* image)
{
  std::array<double, 12> g{};
  int extent[6];
  image->GetExtent(extent);
  for (int k = 0; k < 6; ++k)
  {
    g[k] = extent[k];
  }
  image->GetOrigin(g.data() + 6);
  image->GetSpacing(g.data() + 9);
  return g;
}
} // namespace

bool CloudDensityTexture::NeedsUpload(
  vtkImageData* image, vtkDataArray* scalars, int maximumSize, double budgetBytes) const
{
  return !this->HasDensity || this->UploadedArray != scalars || this->UploadedImage != image ||
    scalars->GetMTime() > this->UploadTime || GeometryOf(image) != this->UploadedGeometry ||
    this->UploadedMaximumSize != maximumSize || this->UploadedBudgetBytes != budgetBytes ||
    (this->KeepTexels && this->Texels.empty());
}

bool CloudDensityTexture::Update(vtkOpenGLRenderWindow* window, vtkImageData* image,
  vtkDataArray* scalars, bool cellData, int maximumSize, double budgetBytes,
  std::vector<std::string>& warnings, std::string& error)
{
  if (!this->NeedsUpload(image, scalars, maximumSize, budgetBytes))
  {
    return true;
  }
  int pointDims[3];
  image->GetDimensions(pointDims);
  std::array<int, 3> dims;
  for (int k = 0; k < 3; ++k)
  {
    dims[k] = cellData ? std::max(pointDims[k] - 1, 1) : std::max(pointDims[k], 0);
  }
  std::ostringstream message;
  uint64_t needed = 0;
  const bool representable =
    CheckedProduct({ static_cast<uint64_t>(dims[0]), static_cast<uint64_t>(dims[1]),
                     static_cast<uint64_t>(dims[2]) },
      needed);
  if (!representable || needed != static_cast<uint64_t>(scalars->GetNumberOfTuples()))
  {
    message << "Array '" << NameOf(scalars) << "' has " << scalars->GetNumberOfTuples()
            << " values, but the image (" << dims[0] << "x" << dims[1] << "x" << dims[2]
            << ") needs ";
    if (representable)
    {
      message << needed;
    }
    else
    {
      message << "more than 2^64";
    }
    error = message.str();
    return false;
  }
  if (needed == 0)
  {
    error = "The image has no samples (an empty extent).";
    return false;
  }
  if (scalars->GetNumberOfComponents() != 1)
  {
    message << "Array '" << NameOf(scalars) << "' has " << scalars->GetNumberOfComponents()
            << " components; rendering its first as the density.";
    warnings.push_back(message.str());
    message.str("");
  }
  // The GL limit per side, then the memory budget: the texture and the converted
  // copy on the CPU, 8 bytes per texel.
  constexpr double kBytesPerTexel = 2.0 * sizeof(float);
  DensityResamplePlan plan = PlanDensityResample(dims, maximumSize);
  const DensityResamplePlan glPlan = plan;
  std::string overBudget =
    OverBudgetMessage("the density texture", kBytesPerTexel * plan.OutputSize(), budgetBytes);
  const std::string firstOverBudget = overBudget;
  int limit =
    std::max({ plan.OutputDimensions[0], plan.OutputDimensions[1], plan.OutputDimensions[2], 1 });
  while (!overBudget.empty() && limit > 1)
  {
    const double shrink = std::cbrt(budgetBytes / (kBytesPerTexel * plan.OutputSize()));
    limit = std::min(limit - 1, static_cast<int>(limit * (std::isfinite(shrink) ? shrink : 0.0)));
    limit = std::max(limit, 1);
    plan = PlanDensityResample(dims, limit);
    overBudget =
      OverBudgetMessage("the density texture", kBytesPerTexel * plan.OutputSize(), budgetBytes);
  }
  if (!overBudget.empty())
  {
    error = "Cannot render the density: " + overBudget + ".";
    return false;
  }
  const std::array<int, 3>& texDims = plan.OutputDimensions;
  if (glPlan.Downsamples())
  {
    message << "Density " << dims[0] << "x" << dims[1] << "x" << dims[2]
            << " exceeds the texture limit of " << maximumSize << " per side; downsampled to "
            << glPlan.OutputDimensions[0] << "x" << glPlan.OutputDimensions[1] << "x"
            << glPlan.OutputDimensions[2] << " by averaging.";
    warnings.push_back(message.str());
    message.str("");
  }
  if (!firstOverBudget.empty())
  {
    message << "Density " << dims[0] << "x" << dims[1] << "x" << dims[2] << ": " << firstOverBudget
            << "; downsampled to " << texDims[0] << "x" << texDims[1] << "x" << texDims[2]
            << " by averaging (raise TextureMemoryBudgetMiB to keep more detail).";
    warnings.push_back(message.str());
    message.str("");
  }
  const ResampledDensity density = Resample(scalars, plan);
  const bool newValues = this->ReportedArray != scalars || scalars->GetMTime() > this->ReportTime ||
    image->GetMTime() > this->ReportTime;
  if (newValues && (!density.Census.AllFiniteNonNegative() || density.TooLargeCount > 0))
  {
    message << "Density array '" << NameOf(scalars) << "': ";
    if (!density.Census.AllFiniteNonNegative())
    {
      message << DescribeCensus(density.Census) << " (NaN and infinite rendered as 0, negative "
              << "clamped to 0)";
    }
    if (density.TooLargeCount > 0)
    {
      message << (density.Census.AllFiniteNonNegative() ? "" : "; ") << density.TooLargeCount
              << " values above " << kMaximumDensity << " (clamped to it)";
    }
    message << ".";
    warnings.push_back(message.str());
    message.str("");
  }
  this->ReportedArray = scalars;
  this->ReportTime.Modified();
  this->Texture->SetContext(window);
  this->Texture->ReleaseGraphicsResources(window);
  this->Texture->SetWrapS(vtkTextureObject::ClampToEdge);
  this->Texture->SetWrapT(vtkTextureObject::ClampToEdge);
  this->Texture->SetWrapR(vtkTextureObject::ClampToEdge);
  this->Texture->SetMinificationFilter(vtkTextureObject::Linear);
  this->Texture->SetMagnificationFilter(vtkTextureObject::Linear);
  // GL copies the texels during the call; they are only read.
  for (int i = 0; i < 16 && glGetError() != GL_NO_ERROR; ++i)
  {
    // errors of earlier GL calls are not this upload's
  }
  const bool created = this->Texture->Create3DFromRaw(
    texDims[0], texDims[1], texDims[2], 1, VTK_FLOAT, const_cast<float*>(density.Data()));
  if (!created || glGetError() == GL_OUT_OF_MEMORY)
  {
    this->Texture->ReleaseGraphicsResources(window);
    this->HasDensity = false;
    message << "Could not upload the " << texDims[0] << "x" << texDims[1] << "x" << texDims[2]
            << " density texture (" << FormatBytes(4.0 * plan.OutputSize())
            << "; GL out of memory?). Lower MaximumTextureSize or TextureMemoryBudgetMiB.";
    error = message.str();
    return false;
  }
  this->SetBox(image, cellData, plan);
  this->Texels.clear();
  this->Texels.shrink_to_fit();
  if (this->KeepTexels)
  {
    this->Texels.assign(density.Data(), density.Data() + plan.OutputSize());
  }
  std::copy(texDims.begin(), texDims.end(), this->Dimensions);
  std::copy(plan.Factors.begin(), plan.Factors.end(), this->Factors);
  this->UploadedArray = scalars;
  this->UploadedImage = image;
  this->UploadedGeometry = GeometryOf(image);
  this->UploadedMaximumSize = maximumSize;
  this->UploadedBudgetBytes = budgetBytes;
  this->UploadTime.Modified();
  this->HasDensity = true;
  ++this->Uploads;
  return true;
}

void CloudDensityTexture::SetBox(
  vtkImageData* image, bool cellData, const DensityResamplePlan& plan)
{
  double origin[3], spacing[3];
  int extent[6];
  image->GetOrigin(origin);
  image->GetSpacing(spacing);
  image->GetExtent(extent);
  for (int k = 0; k < 3; ++k)
  {
    const int samples = plan.InputDimensions[k];
    const double first = origin[k] + extent[2 * k] * spacing[k];
    const int cells = cellData ? samples : std::max(samples - 1, 0);
    this->BoxOrigin[k] = first;
    this->BoxSize[k] = cells * spacing[k];
    const double texels = static_cast<double>(plan.OutputDimensions[k]) * plan.Factors[k];
    if (cellData)
    {
      this->BoxToTexScale[k] = samples / texels;
      this->BoxToTexOffset[k] = 0.0;
    }
    else
    {
      // Point sample j sits at the centre of input texel j: (j + 0.5) / texels.
      this->BoxToTexScale[k] = (samples - 1) / texels;
      this->BoxToTexOffset[k] = 0.5 / texels;
    }
    if (this->BoxSize[k] == 0.0)
    {
      // A single sample thick: give the box one spacing (or unit) of thickness around it.
      const double thickness = spacing[k] != 0.0 ? std::abs(spacing[k]) : 1.0;
      this->BoxOrigin[k] = first - 0.5 * thickness;
      this->BoxSize[k] = thickness;
      this->BoxToTexScale[k] = 0.0;
      this->BoxToTexOffset[k] = 0.5;
    }
  }
}

void CloudDensityTexture::GetDataToTexture(vtkMatrix4x4* matrix) const
{
  matrix->Identity();
  for (int k = 0; k < 3; ++k)
  {
    matrix->SetElement(k, k, this->BoxToTexScale[k] / this->BoxSize[k]);
    matrix->SetElement(k, 3,
      this->BoxToTexOffset[k] - this->BoxToTexScale[k] * this->BoxOrigin[k] / this->BoxSize[k]);
  }
}

void CloudDensityTexture::GetDataToBox(vtkMatrix4x4* matrix) const
{
  matrix->Identity();
  for (int k = 0; k < 3; ++k)
  {
    matrix->SetElement(k, k, 1.0 / this->BoxSize[k]);
    matrix->SetElement(k, 3, -this->BoxOrigin[k] / this->BoxSize[k]);
  }
}

void CloudDensityTexture::GetDimensions(int dimensions[3]) const
{
  std::copy(this->Dimensions, this->Dimensions + 3, dimensions);
}

void CloudDensityTexture::GetFactors(int factors[3]) const
{
  std::copy(this->Factors, this->Factors + 3, factors);
}

void CloudDensityTexture::Release(vtkWindow* window)
{
  this->Texture->ReleaseGraphicsResources(window);
  this->UploadedArray = nullptr;
  this->UploadedImage = nullptr;
  this->HasDensity = false;
  this->Texels.clear();
  this->Texels.shrink_to_fit();
}
} // namespace nimbus
