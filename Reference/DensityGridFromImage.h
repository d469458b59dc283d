// The reference renderers' DensityGrid from a VTK image's point array: the one
// conversion vtkNimbusReferenceRenderer and the benchmarks use. Not wrapped (it returns
// a plain C++ type); VTK glue, so it lives beside the vtk classes, not in Core/.
#ifndef NimbusDensityGridFromImage_h
#define NimbusDensityGridFromImage_h

#include "DensityGrid.h"
#include "NimbusReferenceModule.h"

class vtkDataArray;
class vtkImageData;

namespace nimbus
{
/// The first component of `values` (one per point of `image`) as a float DensityGrid,
/// placed by the image's origin, spacing and extent (not its direction matrix: callers
/// refuse a rotated image first). Through double, so a double array's values beyond
/// float become +inf, which DensityGrid refuses (std::invalid_argument).
NIMBUSREFERENCE_EXPORT DensityGrid DensityGridFromImage(vtkImageData* image, vtkDataArray* values);
} // namespace nimbus

#endif
