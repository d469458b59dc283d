// What the Cloud representation does to its input before the mapper sees it: any
// data set becomes one image (resampled, as ParaView's Volume representation
// resamples what is not an image), and the chosen density array becomes extinction
// in 1/m when the user said what its values mean (Physics/CloudOptics.h).
//
// VTK glue around Physics/CloudOptics (the units) and vtkPResampleToImage (the
// resampling); the numbers are tested in Physics/Testing/TestCloudOptics.cxx and
// through the representation in Testing/Python/TestPluginAnyGrid.py.
#ifndef nimbus_CloudInputImage_h
#define nimbus_CloudInputImage_h

#include "CloudOptics.h"
#include "UpAxis.h"
#include "vtkSmartPointer.h"

#include <string>

class vtkDataObject;
class vtkImageData;

namespace nimbus
{

/// DensityUnits of the representation: Physics' DensityUnits (0..4) and one more
/// choice, a typical cloud: the values scaled so that the cloud's median vertical
/// optical thickness is TargetOpticalThickness (EstimateExtinctionPerDensity).
constexpr int kEstimatedDensityUnits = 5;

struct CloudInputSettings
{
  // Points of the resampled image per axis; 0: automatic, the data's own resolution (a
  // rectilinear axis: its length over its finest spacing; other data: its points spread
  // evenly over its bounds), at most 256.
  int SamplingDimensions[3] = { 0, 0, 0 };
  double MemoryBudgetBytes = 0.0; // <= 0: DefaultMemoryBudgetBytes()
  int Units = 0;                  // 0..4 DensityUnits, 5 estimated
  CloudOpticsParameters Optics;   // radius, number concentration
  std::string AirDensityArray;    // kg/m^3; empty: standard atmosphere
  double TargetOpticalThickness = kDefaultTargetOpticalThickness;
  // The frame the altitudes of the mixing ratio's air and the estimate's columns
  // are taken in (the mapper's, Physics/UpAxis.h).
  UpAxis Up = UpAxis::PositiveZ;
  double MetresPerUnit = 1.0;
  double SceneAltitudeMetres = 0.0;
};

/// The input as one image: an image passes through (resampled = false); any other
/// data set or composite data set (rectilinear, structured, unstructured grids,
/// AMR, multiblock) is resampled on SamplingDimensions points over its bounds (all
/// ranks' bounds under MPI), its point and cell arrays becoming point arrays. Axes of
/// SamplingDimensions set to 0 take the data's own resolution.
/// Throws std::runtime_error with a plain-words message: no points, dimensions
/// below 1 or an image over the memory budget (checked before allocating).
vtkSmartPointer<vtkImageData> CloudImageOf(
  vtkDataObject* input, const CloudInputSettings& settings, bool& resampled);

/// The array a cloud shows when the user chose none: the point scalars, the cell
/// scalars, else the first one-component numeric point array, else cell array (not
/// VTK's own vtkValidPointMask or vtkGhostType). Empty when there is none.
std::string DefaultDensityArray(vtkImageData* image, bool& cellData);

/// A shallow copy of `image` whose array `name` (point data, or cell data when
/// `cellData`) holds extinction [1/m] as float, under the same name. With the
/// estimated units `estimate` receives the scale k found [1/m per unit value].
/// Throws std::runtime_error when the array is missing or the optics are invalid.
vtkSmartPointer<vtkImageData> WithExtinction(vtkImageData* image, const std::string& name,
  bool cellData, const CloudInputSettings& settings, double& estimate);

} // namespace nimbus

#endif
