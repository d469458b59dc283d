// The checks every grid source of Nimbus::Filters makes before it allocates: the memory
// budget, the dimensions and the bounds of the grid (Nimbus::Common; included by .cxx
// files only). Each returns the message of the first failure, empty when the values are
// valid; the caller reports it with vtkErrorMacro and produces nothing.
#ifndef nimbus_GridParameters_h
#define nimbus_GridParameters_h

#include "FiniteSetters.h" // AllFinite

#include <cmath>
#include <sstream>
#include <string>

namespace nimbus
{
/// MemoryBudgetMiB: finite and > 0 (MiB).
inline std::string CheckMemoryBudget(double memoryBudgetMiB)
{
  if (!std::isfinite(memoryBudgetMiB) || !(memoryBudgetMiB > 0.0))
  {
    std::ostringstream message;
    message << "MemoryBudgetMiB must be a finite number of MiB > 0, got " << memoryBudgetMiB << ".";
    return message.str();
  }
  return {};
}

/// Dimensions: >= 1 point along every axis. Bounds (xmin, xmax, ymin, ymax, zmin, zmax, in
/// m): finite, min < max on every axis, within +-maximumLength m.
inline std::string CheckGrid(const int dimensions[3], const double bounds[6], double maximumLength)
{
  std::ostringstream message;
  const int* d = dimensions;
  if (d[0] < 1 || d[1] < 1 || d[2] < 1)
  {
    message << "Dimensions must be >= 1 along every axis, got (" << d[0] << ", " << d[1] << ", "
            << d[2] << ").";
    return message.str();
  }
  if (!AllFinite(bounds, 6))
  {
    return "Bounds must be finite numbers.";
  }
  for (int a = 0; a < 3; ++a)
  {
    if (!(bounds[2 * a] < bounds[2 * a + 1]))
    {
      message << "Bounds must satisfy min < max on every axis; axis " << a << " has ("
              << bounds[2 * a] << ", " << bounds[2 * a + 1] << ").";
      return message.str();
    }
    if (std::abs(bounds[2 * a]) > maximumLength || std::abs(bounds[2 * a + 1]) > maximumLength)
    {
      message << "Bounds must lie within +-" << maximumLength << " m; axis " << a << " has ("
              << bounds[2 * a] << ", " << bounds[2 * a + 1] << ").";
      return message.str();
    }
  }
  return {};
}

/// Both checks, the memory budget first.
inline std::string CheckGridParameters(
  double memoryBudgetMiB, const int dimensions[3], const double bounds[6], double maximumLength)
{
  std::string message = CheckMemoryBudget(memoryBudgetMiB);
  return message.empty() ? CheckGrid(dimensions, bounds, maximumLength) : message;
}
}

#endif
