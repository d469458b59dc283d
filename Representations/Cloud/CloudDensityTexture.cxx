#include "CloudDensityTexture.h"

#include "vtkAOSDataArrayTemplate.h"
#include "vtkArrayDispatch.h"
#include "vtkDataArray.h"
#include "vtkDataArrayRange.h"
#include "vtkImageData.h"
#include "vtkMatrix4x4.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkTextureObject.h"

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

bool CloudDensityTexture::NeedsUpload(
  vtkImageData* image, vtkDataArray* scalars, int maximumSize) const
{
  return !this->HasDensity || this->UploadedArray != scalars || this->UploadedImage != image ||
    scalars->GetMTime() > this->UploadTime || image->GetMTime() > this->UploadTime ||
    this->UploadedMaximumSize != maximumSize;
}

bool CloudDensityTexture::Update(vtkOpenGLRenderWindow* window, vtkImageData* image,
  vtkDataArray* scalars, bool cellData, int maximumSize, std::vector<std::string>& warnings,
  std::string& error)
{
  if (!this->NeedsUpload(image, scalars, maximumSize))
  {
    return true;
  }
  int pointDims[3];
  image->GetDimensions(pointDims);
  std::array<int, 3> dims;
  for (int k = 0; k < 3; ++k)
  {
    dims[k] = cellData ? std::max(pointDims[k] - 1, 1) : pointDims[k];
  }
  std::ostringstream message;
  if (static_cast<vtkIdType>(dims[0]) * dims[1] * dims[2] != scalars->GetNumberOfTuples())
  {
    message << "Array '" << NameOf(scalars) << "' has " << scalars->GetNumberOfTuples()
            << " values, but the image needs " << dims[0] * dims[1] * dims[2];
    error = message.str();
    return false;
  }
  if (scalars->GetNumberOfComponents() != 1)
  {
    message << "Array '" << NameOf(scalars) << "' has " << scalars->GetNumberOfComponents()
            << " components; rendering its first as the density.";
    warnings.push_back(message.str());
    message.str("");
  }
  const DensityResamplePlan plan = PlanDensityResample(dims, maximumSize);
  const std::array<int, 3>& texDims = plan.OutputDimensions;
  if (plan.Downsamples())
  {
    message << "Density " << dims[0] << "x" << dims[1] << "x" << dims[2]
            << " exceeds the texture limit of " << maximumSize << " per side; downsampled to "
            << texDims[0] << "x" << texDims[1] << "x" << texDims[2] << " by averaging.";
    warnings.push_back(message.str());
    message.str("");
  }
  const ResampledDensity density = Resample(scalars, plan);
  if (density.NonFiniteCount > 0)
  {
    message << density.NonFiniteCount << " density values are NaN or infinite; rendered as 0.";
    warnings.push_back(message.str());
    message.str("");
  }
  this->Texture->SetContext(window);
  this->Texture->ReleaseGraphicsResources(window);
  this->Texture->SetWrapS(vtkTextureObject::ClampToEdge);
  this->Texture->SetWrapT(vtkTextureObject::ClampToEdge);
  this->Texture->SetWrapR(vtkTextureObject::ClampToEdge);
  this->Texture->SetMinificationFilter(vtkTextureObject::Linear);
  this->Texture->SetMagnificationFilter(vtkTextureObject::Linear);
  // GL copies the texels during the call; they are only read.
  if (!this->Texture->Create3DFromRaw(
        texDims[0], texDims[1], texDims[2], 1, VTK_FLOAT, const_cast<float*>(density.Data())))
  {
    message << "Could not upload the " << texDims[0] << "x" << texDims[1] << "x" << texDims[2]
            << " density texture.";
    error = message.str();
    return false;
  }
  this->SetBox(image, cellData, plan);
  std::copy(texDims.begin(), texDims.end(), this->Dimensions);
  this->UploadedArray = scalars;
  this->UploadedImage = image;
  this->UploadedMaximumSize = maximumSize;
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

void CloudDensityTexture::Release(vtkWindow* window)
{
  this->Texture->ReleaseGraphicsResources(window);
  this->UploadedArray = nullptr;
  this->UploadedImage = nullptr;
  this->HasDensity = false;
}
} // namespace nimbus
