// 004 §3.4's reference patterns for MultipleScattering.cxx (internal header, not
// installed): the sun's orders 2..options.Orders at every grid point, added to
// `coefficients` (12 floats per point, the layout of MultipleScatteringField).
#ifndef nimbus_MultipleScatteringPatterns_h
#define nimbus_MultipleScatteringPatterns_h

#include "MultipleScattering.h"

namespace nimbus
{
/// sunDepth: the cloud's optical depth toward the sun at every grid point
/// (OpticalDepthToward). `progress(fraction)` as in SolveMultipleScattering (fractions
/// of this call's work, ending at 1). The result does not depend on options.Threads.
/// Throws std::invalid_argument when sunDepth, coefficients or grid.Extinction do not
/// match the grid. Method, the cost and how it departs from the paper: the .cxx file.
void AddReferencePatternOrders(const ExtinctionGrid& grid, const CloudOptics& optics,
  const DirectionalLight& sun, const MultipleScatteringOptions& options,
  const std::vector<float>& sunDepth, std::vector<float>& coefficients,
  const std::function<void(double fraction)>& progress);
} // namespace nimbus

#endif
