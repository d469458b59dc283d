#include "vtkNimbusImageCloudFilter.h"

#include "FiniteSetters.h"
#include "ImageClouds.h"
#include "MemoryBudget.h"
#include "PieceExtent.h"

#include "vtkCellData.h"
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
#include <new>
#include <sstream>
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
  // Defaults that look right on a satellite picture: clear sea and land are dark but not
  // black (the sample's reach 0.2 of the range), clouds bright; bright pixels read as the
  // reflectance of a non-absorbing cloud (TwoStream), not as a fraction of the thickest.
  this->MappingType = TWO_STREAM;
  const nimbus::OpticalDepthMapping mapping;
  this->ClearIntensity = 0.25;
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
  this->MemoryBudgetMiB = nimbus::DefaultMemoryBudgetMiB();
  this->MemoryBudgetRangeMiB[0] = 1.0;
  this->MemoryBudgetRangeMiB[1] = this->MemoryBudgetMiB;
}

vtkNimbusImageCloudFilter::~vtkNimbusImageCloudFilter() = default;

nimbusDefineFiniteSetter(vtkNimbusImageCloudFilter, Gamma)

  nimbusDefineFiniteSetter(vtkNimbusImageCloudFilter, MaximumOpticalDepth)

    nimbusDefineFiniteSetter(vtkNimbusImageCloudFilter, AsymmetryParameter)

      nimbusDefineFiniteSetter(vtkNimbusImageCloudFilter, BallRadiusFactor)

        nimbusDefineFiniteSetter(vtkNimbusImageCloudFilter, TopRoughness)

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

constexpr double MaximumWork = 2.0e11; // grid-point updates (minutes)
constexpr double MiB = 1048576.0;

std::string Number(double value)
{
  std::ostringstream text;
  text.precision(3);
  text << value;
  return text.str();
}

// "\"gray\" (1 component), an unnamed array (3 components)" -- what the input offers.
std::string DescribeArrays(vtkDataSetAttributes* attributes)
{
  std::ostringstream text;
  for (int i = 0; i < attributes->GetNumberOfArrays(); ++i)
  {
    vtkAbstractArray* array = attributes->GetAbstractArray(i);
    text << (i > 0 ? ", " : "");
    if (array->GetName() && *array->GetName())
    {
      text << "\"" << array->GetName() << "\"";
    }
    else
    {
      text << "an unnamed array";
    }
    text << " (" << array->GetNumberOfComponents() << " component"
         << (array->GetNumberOfComponents() == 1 ? "" : "s")
         << (vtkDataArray::SafeDownCast(array) ? "" : ", not numeric") << ")";
  }
  return text.str();
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
    // Pieces: built from the whole image, cropped to the requested extent (see Generate).
    outInfo->Set(CAN_PRODUCE_SUB_EXTENT(), 1);
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
  nimbus::RequestWholeInput(inInfo); // every piece uses the whole input
  return 1;
}

int vtkNimbusImageCloudFilter::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkImageData* output = vtkImageData::GetData(outputVector, 0);
  vtkImageData* map = vtkImageData::GetData(outputVector, 1);
  output->Initialize();
  map->Initialize();
  static bool warnedRanks = false; // once per process
  const int pieces = outputVector->GetInformationObject(0)->Get(
    vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_PIECES());
  if (pieces > 1 && !warnedRanks)
  {
    warnedRanks = true;
    vtkWarningMacro(<< "Image cloud on " << pieces
                    << " ranks (pieces): every rank builds the whole cloud (each column's fit "
                       "depends on its neighbours and on the map's maximum) and keeps its "
                       "piece; more ranks make it neither faster nor smaller per rank.");
  }
  try
  {
    return this->Generate(inputVector, outputVector);
  }
  catch (const std::bad_alloc&)
  {
    vtkErrorMacro(<< "Out of memory while building the image cloud; shrink the image, raise "
                     "VerticalSpacing, or lower MemoryBudgetMiB.");
  }
  catch (const std::length_error& error)
  {
    vtkErrorMacro(<< "The image cloud is too large (" << error.what() << "); shrink the image.");
  }
  catch (const std::exception& error)
  {
    vtkErrorMacro(<< error.what());
  }
  output->Initialize();
  map->Initialize();
  return 1;
}

// The array the intensities are read from, and how.
struct vtkNimbusImageCloudFilter::IntensityInput
{
  vtkDataArray* Array = nullptr;
  std::string Name;       // "\"gray\"" or "(unnamed)", for the messages
  bool CellArray = false; // pixels as cells: each point the mean of the cells around it
};

int vtkNimbusImageCloudFilter::Generate(
  vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkImageData* input = vtkImageData::GetData(inputVector[0], 0);
  vtkImageData* output = vtkImageData::GetData(outputVector, 0);
  vtkImageData* map = vtkImageData::GetData(outputVector, 1);
  auto aborted = [output, map]()
  {
    output->Initialize();
    map->Initialize();
    return 1;
  };
  if (!input)
  {
    vtkErrorMacro(<< "No input image.");
    return 1;
  }
  if (!std::isfinite(this->MemoryBudgetMiB) || !(this->MemoryBudgetMiB > 0.0))
  {
    vtkErrorMacro(<< "MemoryBudgetMiB must be a finite number of MiB > 0, got "
                  << this->MemoryBudgetMiB << ".");
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
  IntensityInput intensity;
  if (!this->FindIntensityArray(inputVector, input, dims, intensity) ||
    !this->CheckMappingParameters())
  {
    return 1;
  }
  const nimbus::ImageCloudParameters parameters = MakeParameters(this);
  if (!this->CheckCloudSize(dims, parameters))
  {
    return 1;
  }
  std::vector<double> tau;
  if (!this->ComputeOpticalDepths(intensity, dims, tau))
  {
    return aborted();
  }

  this->UpdateProgress(0.1);
  if (this->CheckAbort())
  {
    return aborted();
  }
  const nimbus::ImageCloud cloud = nimbus::BuildImageCloud(tau, dims[0], dims[1], parameters,
    [this](double fraction)
    {
      this->UpdateProgress(0.1 + 0.8 * std::clamp(fraction, 0.0, 1.0));
      return !this->CheckAbort();
    });
  if (!cloud.Complete)
  {
    return aborted();
  }
  this->UpdateProgress(0.9);
  const nimbus::ValueCensus densityCensus =
    nimbus::TakeCensus(cloud.Density.data(), cloud.Density.size());
  if (!densityCensus.AllFiniteNonNegative())
  {
    vtkErrorMacro(<< "The density has " << nimbus::DescribeCensus(densityCensus)
                  << "; the output is withheld.");
    return aborted();
  }
  this->FillOutputs(cloud, tau, output, map);
  // Pieces: the fit rescales each column's balls by its optical depth, which its neighbours'
  // balls change, for Iterations rounds; the dependency region of a point grows with every
  // round and the normalisation uses the whole map's maximum. So the cloud is built from the
  // whole image (requested whole in RequestUpdateExtent) and each output cropped to its
  // requested extent: exact, but the work is not divided between ranks.
  nimbus::CropToRequestedExtent(output, outputVector->GetInformationObject(0));
  nimbus::CropToRequestedExtent(map, outputVector->GetInformationObject(1));
  this->UpdateProgress(1.0);
  return 1;
}

bool vtkNimbusImageCloudFilter::FindIntensityArray(
  vtkInformationVector** inputVector, vtkImageData* input, const int dims[3], IntensityInput& found)
{
  vtkDataArray* intensity = this->GetInputArrayToProcess(0, inputVector);
  vtkInformation* arrayInfo = this->GetInputArrayInformation(0);
  const char* arrayName = arrayInfo->Has(vtkDataObject::FIELD_NAME())
    ? arrayInfo->Get(vtkDataObject::FIELD_NAME())
    : nullptr;
  const bool named = arrayName && *arrayName;
  vtkPointData* pointData = input->GetPointData();
  vtkCellData* cellData = input->GetCellData();
  if (!intensity && !named)
  {
    // No array chosen (an empty name, as ParaView may send before its domain is filled):
    // the active point scalars, else the first numeric point array (named or not), else the
    // same among the cell arrays (ParaView's default reader for PNG, TIFF and JPEG files,
    // GDAL's, gives the pixels as cell data).
    for (vtkDataSetAttributes* attributes : { static_cast<vtkDataSetAttributes*>(pointData),
           static_cast<vtkDataSetAttributes*>(cellData) })
    {
      intensity = intensity ? intensity : attributes->GetScalars();
      for (int i = 0; !intensity && i < attributes->GetNumberOfArrays(); ++i)
      {
        intensity = attributes->GetArray(i);
      }
    }
  }
  if (!intensity)
  {
    if (pointData->GetNumberOfArrays() == 0 && cellData->GetNumberOfArrays() == 0)
    {
      vtkErrorMacro(<< "The input image has no point or cell arrays to read intensities from.");
    }
    else if (named)
    {
      vtkErrorMacro(<< "The input image has no numeric array \"" << arrayName
                    << "\"; its point arrays are " << DescribeArrays(pointData)
                    << " and its cell arrays " << DescribeArrays(cellData)
                    << " (choose one with SetInputArrayToProcess).");
    }
    else
    {
      vtkErrorMacro(<< "The input image has no numeric array to read intensities from; "
                       "its point arrays are "
                    << DescribeArrays(pointData) << " and its cell arrays "
                    << DescribeArrays(cellData) << ".");
    }
    return false;
  }
  const vtkIdType pixels = static_cast<vtkIdType>(dims[0]) * dims[1];
  const std::string intensityName = intensity->GetName() && *intensity->GetName()
    ? std::string("\"") + intensity->GetName() + "\""
    : std::string("(unnamed)");
  // Pixels as cells (GDAL's reader: nx x ny pixels on (nx + 1) x (ny + 1) points): each
  // point takes the mean of the cells around it, as ParaView's Cell Data to Point Data does.
  const vtkIdType cellPixels =
    static_cast<vtkIdType>(std::max(dims[0] - 1, 1)) * std::max(dims[1] - 1, 1);
  bool inCellData = false;
  for (int i = 0; i < cellData->GetNumberOfArrays(); ++i)
  {
    inCellData = inCellData || cellData->GetAbstractArray(i) == intensity;
  }
  const bool cellArray = inCellData && intensity->GetNumberOfTuples() != pixels &&
    intensity->GetNumberOfTuples() == cellPixels;
  if (intensity->GetNumberOfTuples() != pixels && !cellArray)
  {
    vtkErrorMacro(<< "The intensity array " << intensityName << " has "
                  << intensity->GetNumberOfTuples() << " values for " << dims[0] << " x " << dims[1]
                  << " = " << pixels << " points (or " << cellPixels << " cells).");
    return false;
  }
  found.Array = intensity;
  found.Name = intensityName;
  found.CellArray = cellArray;
  return true;
}

bool vtkNimbusImageCloudFilter::CheckMappingParameters()
{
  if (!(this->IntensityRange[1] > this->IntensityRange[0]) ||
    !std::isfinite(this->IntensityRange[1] - this->IntensityRange[0]))
  {
    vtkErrorMacro(<< "IntensityRange must be finite with min < max, got ("
                  << this->IntensityRange[0] << ", " << this->IntensityRange[1] << ").");
    return false;
  }
  if (!std::isfinite(this->ClearIntensity) || !std::isfinite(this->WhiteIntensity))
  {
    vtkErrorMacro(<< "ClearIntensity and WhiteIntensity must be finite (normalised intensities, "
                     "usually in [0, 1]); got "
                  << this->ClearIntensity << " and " << this->WhiteIntensity << ".");
    return false;
  }
  if (!(this->WhiteIntensity > this->ClearIntensity) ||
    !std::isfinite(this->WhiteIntensity - this->ClearIntensity))
  {
    vtkErrorMacro(<< "WhiteIntensity (" << this->WhiteIntensity
                  << ") must be greater than ClearIntensity (" << this->ClearIntensity << ").");
    return false;
  }
  // The clamping setters keep NaN and infinities: name them here, not deep in the core.
  const struct
  {
    const char* Name;
    double Value;
  } clamped[] = { { "Gamma", this->Gamma }, { "MaximumOpticalDepth", this->MaximumOpticalDepth },
    { "AsymmetryParameter", this->AsymmetryParameter },
    { "BallRadiusFactor", this->BallRadiusFactor }, { "TopRoughness", this->TopRoughness } };
  for (const auto& parameter : clamped)
  {
    if (!std::isfinite(parameter.Value))
    {
      vtkErrorMacro(<< parameter.Name << " is " << parameter.Value
                    << "; it must be a finite number (finite values are clamped to its range).");
      return false;
    }
  }
  return true;
}

bool vtkNimbusImageCloudFilter::CheckCloudSize(
  const int dims[3], const nimbus::ImageCloudParameters& parameters)
{
  // Size, memory and work, from the parameters alone, before anything is allocated.
  const vtkIdType pixels = static_cast<vtkIdType>(dims[0]) * dims[1];
  const nimbus::GridGeometry grid =
    nimbus::ImageCloudGrid(dims[0], dims[1], this->MaximumOpticalDepth, parameters);
  const double points = static_cast<double>(grid.NumberOfPoints());
  const double balls =
    nimbus::MaximumImageCloudBalls(dims[0], dims[1], this->MaximumOpticalDepth, parameters);
  // Floats: the density and its output copy; doubles per pixel: tau, the achieved column
  // optical depths (twice while resampling); floats per pixel: the two maps; the balls.
  const double bytes = 8.0 * points + 28.0 * static_cast<double>(pixels) + 48.0 * balls;
  std::ostringstream what;
  what << "the image cloud (" << grid.Dimensions[0] << " x " << grid.Dimensions[1] << " x "
       << grid.Dimensions[2] << " points)";
  const std::string overBudget =
    nimbus::OverBudgetMessage(what.str(), bytes, this->MemoryBudgetMiB * MiB);
  if (!overBudget.empty())
  {
    vtkErrorMacro(<< overBudget
                  << " (MemoryBudgetMiB); shrink the image, raise VerticalSpacing, or raise "
                     "MemoryBudgetMiB.");
    return false;
  }
  const double radius =
    this->BallRadiusFactor * this->BallSpacing * this->PixelSize * (1.0 + this->TopRoughness);
  const double work =
    (this->Iterations + 1.0) * (3.0 * points + balls * nimbus::MetaballBoxPoints(radius, grid));
  if (!(work <= MaximumWork))
  {
    vtkErrorMacro(<< "The image cloud would need about " << Number(work) << " grid-point updates ("
                  << grid.Dimensions[0] << " x " << grid.Dimensions[1] << " x "
                  << grid.Dimensions[2] << " points, up to " << Number(balls) << " balls, "
                  << this->Iterations + 1 << " samplings), more than the limit of "
                  << Number(MaximumWork)
                  << " (minutes of work); shrink the image, lower Iterations or "
                     "BallRadiusFactor, or raise BallSpacing.");
    return false;
  }
  return true;
}

bool vtkNimbusImageCloudFilter::ComputeOpticalDepths(
  const IntensityInput& input, const int dims[3], std::vector<double>& tau)
{
  // Intensity -> optical depth (OpticalDepthMapping).
  nimbus::OpticalDepthMapping mapping;
  mapping.Type = this->MappingType == TWO_STREAM ? nimbus::OpticalDepthMapping::Kind::TwoStream
                                                 : nimbus::OpticalDepthMapping::Kind::Linear;
  mapping.ClearIntensity = this->ClearIntensity;
  mapping.WhiteIntensity = this->WhiteIntensity;
  mapping.Gamma = this->Gamma;
  mapping.MaximumOpticalDepth = this->MaximumOpticalDepth;
  mapping.AsymmetryParameter = this->AsymmetryParameter;
  nimbus::IntensityToOpticalDepth(0.0, mapping); // throws now for a bad mapping
  vtkDataArray* intensity = input.Array;
  const int components = intensity->GetNumberOfComponents();
  const vtkIdType pixels = static_cast<vtkIdType>(dims[0]) * dims[1];
  tau.assign(static_cast<std::size_t>(pixels), 0.0);
  const double scale = 1.0 / (this->IntensityRange[1] - this->IntensityRange[0]);
  nimbus::ValueCensus census;
  auto luminance = [intensity, components](vtkIdType t)
  {
    double value = intensity->GetComponent(t, 0);
    if (components >= 3)
    {
      value = 0.2126 * value + 0.7152 * intensity->GetComponent(t, 1) +
        0.0722 * intensity->GetComponent(t, 2); // Rec. 709 luminance
    }
    return value;
  };
  const int cellsX = std::max(dims[0] - 1, 1);
  const int cellsY = std::max(dims[1] - 1, 1);
  for (vtkIdType i = 0; i < pixels; ++i)
  {
    double value = 0.0;
    if (input.CellArray)
    {
      const int x = static_cast<int>(i % dims[0]);
      const int y = static_cast<int>(i / dims[0]);
      int count = 0;
      for (int cy = std::max(y - 1, 0); cy <= std::min(y, cellsY - 1); ++cy)
      {
        for (int cx = std::max(x - 1, 0); cx <= std::min(x, cellsX - 1); ++cx)
        {
          value += luminance(static_cast<vtkIdType>(cx) + static_cast<vtkIdType>(cellsX) * cy);
          ++count;
        }
      }
      value /= count;
    }
    else
    {
      value = luminance(i);
    }
    census.NaN += std::isnan(value) ? 1 : 0;
    census.Infinite += std::isinf(value) ? 1 : 0;
    census.Negative += std::isfinite(value) && value < 0.0 ? 1 : 0;
    tau[i] = nimbus::IntensityToOpticalDepth((value - this->IntensityRange[0]) * scale, mapping);
    if ((i & 0xFFFFF) == 0xFFFFF)
    {
      this->UpdateProgress(0.1 * static_cast<double>(i) / static_cast<double>(pixels));
      if (this->CheckAbort())
      {
        return false;
      }
    }
  }
  if (this->IntensityRange[0] < 0.0)
  {
    census.Negative = 0; // negative intensities are part of the chosen range
  }
  if (!census.AllFiniteNonNegative())
  {
    vtkWarningMacro(<< "The intensity array " << input.Name << " has "
                    << nimbus::DescribeCensus(census)
                    << ": NaN pixels are read as clear sky, infinite and negative ones as the "
                       "ends of IntensityRange.");
  }
  return true;
}

void vtkNimbusImageCloudFilter::FillOutputs(const nimbus::ImageCloud& cloud,
  const std::vector<double>& tau, vtkImageData* output, vtkImageData* map)
{
  output->SetExtent(0, cloud.Grid.Dimensions[0] - 1, 0, cloud.Grid.Dimensions[1] - 1, 0,
    cloud.Grid.Dimensions[2] - 1);
  output->SetOrigin(cloud.Grid.Origin.data());
  output->SetSpacing(cloud.Grid.Spacing.data());
  vtkNew<vtkFloatArray> density;
  density->SetName("density");
  density->SetNumberOfTuples(static_cast<vtkIdType>(cloud.Density.size()));
  std::copy(cloud.Density.begin(), cloud.Density.end(), density->GetPointer(0));
  output->GetPointData()->SetScalars(density);

  map->SetExtent(0, cloud.Grid.Dimensions[0] - 1, 0, cloud.Grid.Dimensions[1] - 1, 0, 0);
  map->SetOrigin(cloud.Grid.Origin[0], cloud.Grid.Origin[1], this->BaseHeight);
  map->SetSpacing(cloud.Grid.Spacing.data());
  const vtkIdType pixels = static_cast<vtkIdType>(tau.size());
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
  os << indent << "MemoryBudgetMiB: " << this->MemoryBudgetMiB << "\n";
}
