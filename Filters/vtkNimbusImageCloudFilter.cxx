#include "vtkNimbusImageCloudFilter.h"

#include "ImageClouds.h"

#include "vtkDataArray.h"
#include "vtkDataSetAttributes.h"
#include "vtkDoubleArray.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkStreamingDemandDrivenPipeline.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

vtkStandardNewMacro(vtkNimbusImageCloudFilter);

vtkNimbusImageCloudFilter::vtkNimbusImageCloudFilter()
{
  this->SetNumberOfInputPorts(1);
  this->SetNumberOfOutputPorts(2);
  this->SetInputArrayToProcess(
    0, 0, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, vtkDataSetAttributes::SCALARS);
  this->IntensityRange[0] = 0.0;
  this->IntensityRange[1] = 255.0;
  this->MappingType = LINEAR;
  const nimbus::OpticalDepthMapping mapping;
  this->ClearIntensity = mapping.ClearIntensity;
  this->WhiteIntensity = mapping.WhiteIntensity;
  this->Gamma = mapping.Gamma;
  this->MaximumOpticalDepth = mapping.MaximumOpticalDepth;
  this->AsymmetryParameter = mapping.AsymmetryParameter;
  const nimbus::ImageCloudParameters p;
  this->PixelSize = p.PixelSize;
  this->VerticalSpacing = p.VerticalSpacing;
  this->ExtinctionCoefficient = p.ExtinctionCoefficient;
  this->NominalDensity = p.NominalDensity;
  this->BaseHeight = p.BaseHeight;
  this->BaseTransitionThickness = p.BaseTransitionThickness;
  this->BallSpacing = p.BallSpacing;
  this->BallRadiusFactor = p.BallRadiusFactor;
  this->TopRoughness = p.TopRoughness;
  this->Iterations = p.Iterations;
  this->Seed = 1;
}

vtkNimbusImageCloudFilter::~vtkNimbusImageCloudFilter() = default;

vtkImageData* vtkNimbusImageCloudFilter::GetOpticalDepthMap()
{
  return vtkImageData::SafeDownCast(this->GetOutputDataObject(1));
}

int vtkNimbusImageCloudFilter::FillInputPortInformation(int, vtkInformation* info)
{
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkImageData");
  return 1;
}

int vtkNimbusImageCloudFilter::FillOutputPortInformation(int, vtkInformation* info)
{
  info->Set(vtkDataObject::DATA_TYPE_NAME(), "vtkImageData");
  return 1;
}

namespace
{
nimbus::ImageCloudParameters MakeParameters(const vtkNimbusImageCloudFilter* self)
{
  auto* f = const_cast<vtkNimbusImageCloudFilter*>(self);
  nimbus::ImageCloudParameters p;
  p.PixelSize = f->GetPixelSize();
  p.VerticalSpacing = f->GetVerticalSpacing();
  p.ExtinctionCoefficient = f->GetExtinctionCoefficient();
  p.NominalDensity = f->GetNominalDensity();
  p.BaseHeight = f->GetBaseHeight();
  p.BaseTransitionThickness = f->GetBaseTransitionThickness();
  p.BallSpacing = f->GetBallSpacing();
  p.BallRadiusFactor = f->GetBallRadiusFactor();
  p.TopRoughness = f->GetTopRoughness();
  p.Iterations = f->GetIterations();
  p.Seed = static_cast<std::uint64_t>(static_cast<std::uint32_t>(f->GetSeed()));
  // The grid's height depends on the mapping's maximum, not on the data, so that
  // RequestInformation knows it.
  p.GridOpticalDepth = f->GetMaximumOpticalDepth();
  return p;
}

void SetGeometry(
  vtkInformation* info, const nimbus::GridGeometry& grid, bool map, double baseHeight)
{
  int extent[6] = { 0, grid.Dimensions[0] - 1, 0, grid.Dimensions[1] - 1, 0,
    map ? 0 : grid.Dimensions[2] - 1 };
  double origin[3] = { grid.Origin[0], grid.Origin[1], map ? baseHeight : grid.Origin[2] };
  info->Set(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), extent, 6);
  info->Set(vtkDataObject::ORIGIN(), origin, 3);
  info->Set(vtkDataObject::SPACING(), grid.Spacing.data(), 3);
}
}

int vtkNimbusImageCloudFilter::RequestInformation(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkInformation* inInfo = inputVector[0]->GetInformationObject(0);
  int inExtent[6];
  inInfo->Get(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), inExtent);
  const int nx = inExtent[1] - inExtent[0] + 1;
  const int ny = inExtent[3] - inExtent[2] + 1;
  const int nz = inExtent[5] - inExtent[4] + 1;
  const int empty[6] = { 0, -1, 0, -1, 0, -1 };
  for (int port = 0; port < 2; ++port)
  {
    vtkInformation* outInfo = outputVector->GetInformationObject(port);
    outInfo->Set(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), empty, 6);
    if (nx >= 1 && ny >= 1 && nz == 1)
    {
      try
      {
        const nimbus::GridGeometry grid =
          nimbus::ImageCloudGrid(nx, ny, this->MaximumOpticalDepth, MakeParameters(this));
        SetGeometry(outInfo, grid, port == 1, this->BaseHeight);
      }
      catch (const std::exception&)
      {
        // RequestData reports the error.
      }
    }
    vtkDataObject::SetPointDataActiveScalarInfo(outInfo, VTK_FLOAT, 1);
  }
  return 1;
}

int vtkNimbusImageCloudFilter::RequestUpdateExtent(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector*)
{
  vtkInformation* inInfo = inputVector[0]->GetInformationObject(0);
  int wholeExtent[6];
  inInfo->Get(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), wholeExtent);
  inInfo->Set(vtkStreamingDemandDrivenPipeline::UPDATE_EXTENT(), wholeExtent, 6);
  return 1;
}

int vtkNimbusImageCloudFilter::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkImageData* input = vtkImageData::GetData(inputVector[0], 0);
  vtkImageData* output = vtkImageData::GetData(outputVector, 0);
  vtkImageData* map = vtkImageData::GetData(outputVector, 1);
  output->Initialize();
  map->Initialize();
  if (!input)
  {
    vtkErrorMacro(<< "No input image.");
    return 1;
  }
  int dims[3];
  input->GetDimensions(dims);
  if (dims[2] != 1 || dims[0] < 1 || dims[1] < 1)
  {
    vtkErrorMacro(<< "The input must be a 2-D image (nx x ny x 1 points, in the xy plane); got "
                  << dims[0] << " x " << dims[1] << " x " << dims[2] << ".");
    return 1;
  }
  vtkDataArray* intensity = this->GetInputArrayToProcess(0, inputVector);
  vtkInformation* arrayInfo = this->GetInputArrayInformation(0);
  const char* arrayName = arrayInfo->Has(vtkDataObject::FIELD_NAME())
    ? arrayInfo->Get(vtkDataObject::FIELD_NAME())
    : nullptr;
  if (!intensity && (!arrayName || !*arrayName))
  {
    // No array chosen (an empty name, as ParaView may send before its domain is filled):
    // the active scalars, else the first point array.
    intensity = input->GetPointData()->GetScalars();
    if (!intensity && input->GetPointData()->GetNumberOfArrays() > 0)
    {
      intensity = input->GetPointData()->GetArray(0);
    }
  }
  if (!intensity)
  {
    vtkErrorMacro(<< "The input image has no point array "
                  << (arrayName && *arrayName ? std::string("\"") + arrayName + "\"" : "")
                  << " to read intensities from (choose one with SetInputArrayToProcess).");
    return 1;
  }
  if (!(this->IntensityRange[1] > this->IntensityRange[0]) ||
    !std::isfinite(this->IntensityRange[0]) || !std::isfinite(this->IntensityRange[1]))
  {
    vtkErrorMacro(<< "IntensityRange must be finite with min < max, got ("
                  << this->IntensityRange[0] << ", " << this->IntensityRange[1] << ").");
    return 1;
  }
  if (!(this->WhiteIntensity > this->ClearIntensity))
  {
    vtkErrorMacro(<< "WhiteIntensity (" << this->WhiteIntensity
                  << ") must be greater than ClearIntensity (" << this->ClearIntensity << ").");
    return 1;
  }

  // Intensity -> optical depth (OpticalDepthMapping).
  nimbus::OpticalDepthMapping mapping;
  mapping.Type = this->MappingType == TWO_STREAM ? nimbus::OpticalDepthMapping::Kind::TwoStream
                                                 : nimbus::OpticalDepthMapping::Kind::Linear;
  mapping.ClearIntensity = this->ClearIntensity;
  mapping.WhiteIntensity = this->WhiteIntensity;
  mapping.Gamma = this->Gamma;
  mapping.MaximumOpticalDepth = this->MaximumOpticalDepth;
  mapping.AsymmetryParameter = this->AsymmetryParameter;
  const int components = intensity->GetNumberOfComponents();
  const vtkIdType pixels = static_cast<vtkIdType>(dims[0]) * dims[1];
  std::vector<double> tau(static_cast<std::size_t>(pixels));
  const double scale = 1.0 / (this->IntensityRange[1] - this->IntensityRange[0]);
  for (vtkIdType i = 0; i < pixels; ++i)
  {
    double value = intensity->GetComponent(i, 0);
    if (components >= 3)
    {
      value = 0.2126 * value + 0.7152 * intensity->GetComponent(i, 1) +
        0.0722 * intensity->GetComponent(i, 2); // Rec. 709 luminance
    }
    tau[i] = nimbus::IntensityToOpticalDepth((value - this->IntensityRange[0]) * scale, mapping);
  }

  this->UpdateProgress(0.1);
  nimbus::ImageCloud cloud;
  try
  {
    cloud = nimbus::BuildImageCloud(tau, dims[0], dims[1], MakeParameters(this));
  }
  catch (const std::exception& error)
  {
    vtkErrorMacro(<< error.what());
    return 1;
  }
  this->UpdateProgress(0.9);

  const nimbus::GridGeometry& grid = cloud.Grid;
  output->SetExtent(
    0, grid.Dimensions[0] - 1, 0, grid.Dimensions[1] - 1, 0, grid.Dimensions[2] - 1);
  output->SetOrigin(grid.Origin.data());
  output->SetSpacing(grid.Spacing.data());
  vtkNew<vtkFloatArray> density;
  density->SetName("density");
  density->SetNumberOfTuples(static_cast<vtkIdType>(cloud.Density.size()));
  std::copy(cloud.Density.begin(), cloud.Density.end(), density->GetPointer(0));
  output->GetPointData()->SetScalars(density);

  map->SetExtent(0, grid.Dimensions[0] - 1, 0, grid.Dimensions[1] - 1, 0, 0);
  map->SetOrigin(grid.Origin[0], grid.Origin[1], this->BaseHeight);
  map->SetSpacing(grid.Spacing.data());
  vtkNew<vtkFloatArray> target, achieved;
  target->SetName("optical_depth");
  achieved->SetName("column_optical_depth");
  target->SetNumberOfTuples(pixels);
  achieved->SetNumberOfTuples(pixels);
  for (vtkIdType i = 0; i < pixels; ++i)
  {
    target->SetValue(i, static_cast<float>(tau[i]));
    achieved->SetValue(i, static_cast<float>(cloud.ColumnOpticalDepth[i]));
  }
  map->GetPointData()->SetScalars(target);
  map->GetPointData()->AddArray(achieved);
  this->UpdateProgress(1.0);
  return 1;
}

void vtkNimbusImageCloudFilter::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "IntensityRange: " << this->IntensityRange[0] << " " << this->IntensityRange[1]
     << "\n";
  os << indent << "MappingType: " << (this->MappingType == TWO_STREAM ? "TwoStream" : "Linear")
     << "\n";
  os << indent << "ClearIntensity: " << this->ClearIntensity << "\n";
  os << indent << "WhiteIntensity: " << this->WhiteIntensity << "\n";
  os << indent << "Gamma: " << this->Gamma << "\n";
  os << indent << "MaximumOpticalDepth: " << this->MaximumOpticalDepth << "\n";
  os << indent << "AsymmetryParameter: " << this->AsymmetryParameter << "\n";
  os << indent << "PixelSize: " << this->PixelSize << "\n";
  os << indent << "VerticalSpacing: " << this->VerticalSpacing << "\n";
  os << indent << "ExtinctionCoefficient: " << this->ExtinctionCoefficient << "\n";
  os << indent << "NominalDensity: " << this->NominalDensity << "\n";
  os << indent << "BaseHeight: " << this->BaseHeight << "\n";
  os << indent << "BaseTransitionThickness: " << this->BaseTransitionThickness << "\n";
  os << indent << "BallSpacing: " << this->BallSpacing << "\n";
  os << indent << "BallRadiusFactor: " << this->BallRadiusFactor << "\n";
  os << indent << "TopRoughness: " << this->TopRoughness << "\n";
  os << indent << "Iterations: " << this->Iterations << "\n";
  os << indent << "Seed: " << this->Seed << "\n";
}
