#include "DensityGridFromImage.h"

#include "vtkDataArray.h"
#include "vtkImageData.h"

#include <array>
#include <vector>

namespace nimbus
{
DensityGrid DensityGridFromImage(vtkImageData* image, vtkDataArray* values)
{
  int extent[6];
  image->GetExtent(extent);
  double origin[3], spacing[3];
  image->GetOrigin(origin);
  image->GetSpacing(spacing);
  std::array<int, 3> dims;
  DensityGrid::Vector3 first, step;
  for (int a = 0; a < 3; ++a)
  {
    dims[a] = extent[2 * a + 1] - extent[2 * a] + 1;
    first[a] = origin[a] + extent[2 * a] * spacing[a];
    step[a] = spacing[a];
  }
  std::vector<float> density(static_cast<std::size_t>(values->GetNumberOfTuples()));
  for (vtkIdType i = 0; i < values->GetNumberOfTuples(); ++i)
  {
    density[static_cast<std::size_t>(i)] = static_cast<float>(values->GetComponent(i, 0));
  }
  return DensityGrid(dims, first, step, std::move(density));
}
} // namespace nimbus
