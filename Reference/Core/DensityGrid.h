// A density volume for the reference renderers: values at the points of a
// regular grid (VTK point data), trilinear in between, zero outside the grid.
// Positions in metres (scene frame). Plain C++: the VTK glue fills it from a
// vtkImageData.
#ifndef NimbusDensityGrid_h
#define NimbusDensityGrid_h

#include "Math.h"
#include "NimbusReferenceModule.h"

#include <array>
#include <cstddef>
#include <vector>

namespace nimbus
{

class NIMBUSREFERENCE_EXPORT DensityGrid
{
public:
  using Vector3 = nimbus::Vector3;

  DensityGrid() = default;
  /// values: dims[0]*dims[1]*dims[2] densities, x fastest. Throws
  /// std::invalid_argument for a size mismatch, non-positive dims or spacing, or
  /// a value that is NaN, infinite or negative (the message gives its index).
  DensityGrid(const std::array<int, 3>& dims, const Vector3& origin, const Vector3& spacing,
    std::vector<float> values);

  /// A grid of one constant density over the box [lo, hi] (2 points per axis).
  static DensityGrid Constant(const Vector3& lo, const Vector3& hi, float density);

  const std::array<int, 3>& GetDimensions() const { return this->Dimensions; }
  const Vector3& GetOrigin() const { return this->Origin; }
  const Vector3& GetSpacing() const { return this->Spacing; }
  const std::vector<float>& GetValues() const { return this->Values; }
  /// Bounding box corners (m). An axis with a single point gets the thickness of
  /// one spacing, centred on the point (so a one-voxel volume is a small box).
  Vector3 GetLower() const { return this->Lower; }
  Vector3 GetUpper() const { return this->Upper; }
  bool IsEmpty() const { return this->Values.empty(); }

  /// Largest value (the majorant for delta tracking).
  double GetMaximum() const { return this->Maximum; }

  /// Trilinear density at p; 0 outside the box.
  double Sample(const Vector3& p) const;

  /// Parametric interval [tNear, tFar] (t >= tMin) where origin + t*direction is
  /// inside the box; false if none. direction need not be unit length.
  bool IntersectRay(const Vector3& origin, const Vector3& direction, double tMin, double& tNear,
    double& tFar) const;

  /// Smallest spacing (m): the natural step scale.
  double GetMinimumSpacing() const;

private:
  std::array<int, 3> Dimensions{ { 0, 0, 0 } };
  Vector3 Origin{ { 0.0, 0.0, 0.0 } };
  Vector3 Spacing{ { 1.0, 1.0, 1.0 } };
  Vector3 Lower{ { 0.0, 0.0, 0.0 } };
  Vector3 Upper{ { 0.0, 0.0, 0.0 } };
  std::vector<float> Values;
  double Maximum = 0.0;
};

} // namespace nimbus

#endif
