#include "CloudInputImage.h"

#include "MemoryBudget.h"

#include "vtkCellData.h"
#include "vtkCompositeDataIterator.h"
#include "vtkCompositeDataSet.h"
#include "vtkDataArray.h"
#include "vtkDataSet.h"
#include "vtkDataSetAttributes.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkNew.h"
#include "vtkPResampleToImage.h"
#include "vtkPointData.h"
#include "vtkRectilinearGrid.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace nimbus
{
namespace
{
// Bytes per point of the resampled image: every point and cell array of the input
// becomes a point array of its own type, plus the one-byte valid-point mask.
double BytesPerResampledPoint(vtkDataObject* input)
{
  double bytes = 1.0;
  auto addArrays = [&bytes](vtkDataSetAttributes* attributes)
  {
    for (int a = 0; attributes && a < attributes->GetNumberOfArrays(); ++a)
    {
      if (vtkDataArray* array = attributes->GetArray(a))
      {
        bytes += static_cast<double>(array->GetNumberOfComponents()) * array->GetDataTypeSize();
      }
    }
  };
  if (auto* dataSet = vtkDataSet::SafeDownCast(input))
  {
    addArrays(dataSet->GetPointData());
    addArrays(dataSet->GetCellData());
  }
  else if (auto* composite = vtkCompositeDataSet::SafeDownCast(input))
  {
    // The first leaf stands for all (a composite's leaves share their arrays).
    auto iterator = vtkSmartPointer<vtkCompositeDataIterator>::Take(composite->NewIterator());
    iterator->InitTraversal();
    if (!iterator->IsDoneWithTraversal())
    {
      if (auto* leaf = vtkDataSet::SafeDownCast(iterator->GetCurrentDataObject()))
      {
        addArrays(leaf->GetPointData());
        addArrays(leaf->GetCellData());
      }
    }
  }
  return bytes;
}

// For each axis of the up frame: the image axis it runs along and its sign.
struct UpFrameAxes
{
  int Source[3];
  int Sign[3];
};

UpFrameAxes AxesOf(UpAxis up)
{
  const auto r = WorldToUpFrame(up);
  UpFrameAxes axes{};
  for (int a = 0; a < 3; ++a)
  {
    for (int j = 0; j < 3; ++j)
    {
      if (r[a][j] != 0)
      {
        axes.Source[a] = j;
        axes.Sign[a] = r[a][j];
      }
    }
  }
  return axes;
}

// The values of a (point or cell) array of an axis-aligned grid of `dims` samples
// (x fastest) copied into the up frame's order, z up: EstimateExtinctionPerDensity's
// layout. `turned` receives the up frame's dimensions.
std::vector<float> InUpFrameOrder(vtkDataArray* values, const int dims[3], UpAxis up, int turned[3])
{
  const UpFrameAxes axes = AxesOf(up);
  for (int a = 0; a < 3; ++a)
  {
    turned[a] = dims[axes.Source[a]];
  }
  std::vector<float> out(static_cast<std::size_t>(turned[0]) * turned[1] * turned[2]);
  std::size_t n = 0;
  int ijk[3];
  for (int k = 0; k < turned[2]; ++k)
  {
    for (int j = 0; j < turned[1]; ++j)
    {
      for (int i = 0; i < turned[0]; ++i)
      {
        const int u[3] = { i, j, k };
        for (int a = 0; a < 3; ++a)
        {
          const int s = axes.Source[a];
          ijk[s] = axes.Sign[a] > 0 ? u[a] : dims[s] - 1 - u[a];
        }
        const vtkIdType id = ijk[0] +
          static_cast<vtkIdType>(dims[0]) * (ijk[1] + static_cast<vtkIdType>(dims[1]) * ijk[2]);
        out[n++] = static_cast<float>(values->GetComponent(id, 0));
      }
    }
  }
  return out;
}

void SampleDimensions(vtkImageData* image, bool cellData, int dims[3])
{
  image->GetDimensions(dims);
  if (cellData)
  {
    for (int a = 0; a < 3; ++a)
    {
      dims[a] = std::max(dims[a] - 1, 1);
    }
  }
}

// The scale k of the estimated units: the median column of the cloud along the up
// axis has optical thickness TargetOpticalThickness.
double EstimateScale(
  vtkImageData* image, vtkDataArray* values, bool cellData, const CloudInputSettings& settings)
{
  int dims[3];
  SampleDimensions(image, cellData, dims);
  int turned[3];
  const std::vector<float> ordered = InUpFrameOrder(values, dims, settings.Up, turned);
  const int upSource = AxesOf(settings.Up).Source[2];
  const double dzMetres = image->GetSpacing()[upSource] * settings.MetresPerUnit;
  return EstimateExtinctionPerDensity(
    ordered.data(), turned[0], turned[1], turned[2], dzMetres, settings.TargetOpticalThickness);
}

// Altitude above sea level [m] of sample `id`: the up frame's z of its position.
double AltitudeOf(vtkImageData* image, vtkIdType id, const int dims[3], bool cellData,
  const CloudInputSettings& settings)
{
  const double offset = cellData ? 0.5 : 0.0;
  const double i = static_cast<double>(id % dims[0]) + offset;
  const double j = static_cast<double>((id / dims[0]) % dims[1]) + offset;
  const double k = static_cast<double>(id / (static_cast<vtkIdType>(dims[0]) * dims[1])) + offset;
  const int* extent = image->GetExtent();
  double world[3];
  image->TransformContinuousIndexToPhysicalPoint(
    extent[0] + i, extent[2] + j, extent[4] + k, world);
  const double z = ToUpFrame(settings.Up, { { world[0], world[1], world[2] } })[2];
  return settings.SceneAltitudeMetres + z * settings.MetresPerUnit;
}
// Points of a rectilinear axis: its length over its finest spacing, + 1 (a stretched LES
// level keeps its finest layer).
int AxisPointsOf(vtkDataArray* coordinates)
{
  const vtkIdType n = coordinates ? coordinates->GetNumberOfTuples() : 0;
  if (n < 2)
  {
    return 1;
  }
  double finest = std::numeric_limits<double>::infinity();
  for (vtkIdType i = 1; i < n; ++i)
  {
    const double step =
      std::abs(coordinates->GetComponent(i, 0) - coordinates->GetComponent(i - 1, 0));
    if (step > 0.0)
    {
      finest = std::min(finest, step);
    }
  }
  const double length =
    std::abs(coordinates->GetComponent(n - 1, 0) - coordinates->GetComponent(0, 0));
  return std::isfinite(finest) && length > 0.0
    ? static_cast<int>(std::ceil(length / finest - 1e-9)) + 1
    : 1;
}

// Automatic sampling: the data's own resolution, at most kMaxAutomaticPoints a side.
constexpr int kMaxAutomaticPoints = 256;

void AutomaticDimensions(vtkDataObject* input, int dims[3])
{
  int automatic[3] = { 1, 1, 1 };
  if (auto* grid = vtkRectilinearGrid::SafeDownCast(input))
  {
    automatic[0] = AxisPointsOf(grid->GetXCoordinates());
    automatic[1] = AxisPointsOf(grid->GetYCoordinates());
    automatic[2] = AxisPointsOf(grid->GetZCoordinates());
  }
  else
  {
    // As many points as the data has, spread evenly over its bounds.
    double bounds[6] = { 0, -1, 0, -1, 0, -1 };
    vtkIdType points = 0;
    if (auto* dataSet = vtkDataSet::SafeDownCast(input))
    {
      dataSet->GetBounds(bounds);
      points = dataSet->GetNumberOfPoints();
    }
    else if (auto* composite = vtkCompositeDataSet::SafeDownCast(input))
    {
      composite->GetBounds(bounds);
      points = composite->GetNumberOfPoints();
    }
    double volume = 1.0;
    int extended = 0;
    for (int a = 0; a < 3; ++a)
    {
      const double length = bounds[2 * a + 1] - bounds[2 * a];
      if (length > 0.0)
      {
        volume *= length;
        ++extended;
      }
    }
    const double spacing =
      extended > 0 && points > 0 ? std::pow(volume / points, 1.0 / extended) : 0.0;
    for (int a = 0; a < 3; ++a)
    {
      const double length = bounds[2 * a + 1] - bounds[2 * a];
      automatic[a] =
        length > 0.0 && spacing > 0.0 ? static_cast<int>(std::lround(length / spacing)) + 1 : 1;
    }
  }
  for (int a = 0; a < 3; ++a)
  {
    if (dims[a] == 0)
    {
      dims[a] = std::min(std::max(automatic[a], 1), kMaxAutomaticPoints);
    }
  }
}
} // namespace

vtkSmartPointer<vtkImageData> CloudImageOf(
  vtkDataObject* input, const CloudInputSettings& settings, bool& resampled)
{
  resampled = false;
  if (auto* image = vtkImageData::SafeDownCast(input))
  {
    return image;
  }
  int dims[3] = { settings.SamplingDimensions[0], settings.SamplingDimensions[1],
    settings.SamplingDimensions[2] };
  AutomaticDimensions(input, dims); // the axes set to 0
  if (dims[0] < 1 || dims[1] < 1 || dims[2] < 1)
  {
    std::ostringstream message;
    message << "Sampling Dimensions " << dims[0] << " x " << dims[1] << " x " << dims[2]
            << ": each must be at least 1.";
    throw std::runtime_error(message.str());
  }
  uint64_t points = 0;
  if (!CheckedProduct({ static_cast<uint64_t>(dims[0]), static_cast<uint64_t>(dims[1]),
                        static_cast<uint64_t>(dims[2]) },
        points))
  {
    throw std::runtime_error("Sampling Dimensions: too many points.");
  }
  const double budget = settings.MemoryBudgetBytes > 0.0
    ? settings.MemoryBudgetBytes
    : static_cast<double>(DefaultMemoryBudgetBytes());
  const std::string over =
    OverBudgetMessage("Resampling the data to an image of " + std::to_string(dims[0]) + " x " +
        std::to_string(dims[1]) + " x " + std::to_string(dims[2]) + " points",
      static_cast<double>(points) * BytesPerResampledPoint(input), budget);
  if (!over.empty())
  {
    throw std::runtime_error(over + "; lower the Sampling Dimensions or raise the budget.");
  }
  vtkNew<vtkPResampleToImage> resample;
  resample->SetInputDataObject(input);
  resample->SetUseInputBounds(true);
  resample->SetSamplingDimensions(dims[0], dims[1], dims[2]);
  resample->Update();
  vtkSmartPointer<vtkImageData> image = resample->GetOutput();
  if (!image || image->GetNumberOfPoints() == 0)
  {
    throw std::runtime_error("The data has no points to resample.");
  }
  resampled = true;
  return image;
}

std::string DefaultDensityArray(vtkImageData* image, bool& cellData)
{
  cellData = false;
  vtkDataSetAttributes* both[2] = { image->GetPointData(), image->GetCellData() };
  for (int c = 0; c < 2; ++c)
  {
    if (vtkDataArray* scalars = both[c]->GetScalars())
    {
      if (scalars->GetName() && scalars->GetName()[0])
      {
        cellData = c == 1;
        return scalars->GetName();
      }
    }
  }
  for (int c = 0; c < 2; ++c)
  {
    for (int a = 0; a < both[c]->GetNumberOfArrays(); ++a)
    {
      vtkDataArray* array = both[c]->GetArray(a);
      const std::string name = array && array->GetName() ? array->GetName() : "";
      if (array && array->GetNumberOfComponents() == 1 && !name.empty() &&
        name != "vtkValidPointMask" && name != vtkDataSetAttributes::GhostArrayName())
      {
        cellData = c == 1;
        return name;
      }
    }
  }
  return std::string();
}

vtkSmartPointer<vtkImageData> WithExtinction(vtkImageData* image, const std::string& name,
  bool cellData, const CloudInputSettings& settings, double& estimate)
{
  estimate = 0.0;
  vtkDataSetAttributes* attributes = cellData
    ? static_cast<vtkDataSetAttributes*>(image->GetCellData())
    : static_cast<vtkDataSetAttributes*>(image->GetPointData());
  vtkDataArray* values = attributes->GetArray(name.c_str());
  if (!values)
  {
    throw std::runtime_error("The density array '" + name + "' is not in the data.");
  }
  CloudOpticsParameters optics = settings.Optics;
  if (settings.Units == kEstimatedDensityUnits)
  {
    estimate = EstimateScale(image, values, cellData, settings);
    optics.Units = DensityUnits::Dimensionless;
    optics.ExtinctionPerDensity = estimate;
  }
  else
  {
    optics.Units = static_cast<DensityUnits>(settings.Units);
  }
  const std::string problem = CheckCloudOptics(optics);
  if (!problem.empty())
  {
    throw std::runtime_error(problem);
  }
  vtkDataArray* air = nullptr;
  if (optics.Units == DensityUnits::LiquidWaterMixingRatio && !settings.AirDensityArray.empty())
  {
    air = attributes->GetArray(settings.AirDensityArray.c_str());
    if (!air)
    {
      throw std::runtime_error("The air density array '" + settings.AirDensityArray +
        "' is not in the data (it must be a " + (cellData ? "cell" : "point") +
        " array like the density).");
    }
  }
  int dims[3];
  SampleDimensions(image, cellData, dims);
  const vtkIdType n = values->GetNumberOfTuples();
  vtkNew<vtkFloatArray> extinction;
  extinction->SetName(name.c_str());
  extinction->SetNumberOfTuples(n);
  const bool mixing = optics.Units == DensityUnits::LiquidWaterMixingRatio;
  for (vtkIdType id = 0; id < n; ++id)
  {
    double airDensity = 0.0;
    if (mixing)
    {
      airDensity = air
        ? air->GetComponent(id, 0)
        : StandardAtmosphereAirDensity(AltitudeOf(image, id, dims, cellData, settings));
    }
    extinction->SetValue(
      id, static_cast<float>(ExtinctionPerMetre(optics, values->GetComponent(id, 0), airDensity)));
  }
  auto copy = vtkSmartPointer<vtkImageData>::New();
  copy->ShallowCopy(image);
  vtkDataSetAttributes* target = cellData
    ? static_cast<vtkDataSetAttributes*>(copy->GetCellData())
    : static_cast<vtkDataSetAttributes*>(copy->GetPointData());
  const bool wasScalars = target->GetScalars() == values;
  target->RemoveArray(name.c_str());
  target->AddArray(extinction);
  if (wasScalars)
  {
    target->SetActiveScalars(name.c_str());
  }
  return copy;
}

} // namespace nimbus
