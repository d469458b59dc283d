// Gauss-Legendre quadrature, shared by the sky's multiple-scattering integral
// (Sky.cxx) and the reference slab solver (Reference/Core/SlabSolver.cxx).
#ifndef NimbusQuadrature_h
#define NimbusQuadrature_h

#include "NimbusPhysicsExport.h"

#include <vector>

namespace nimbus
{

/// Gauss-Legendre nodes (descending, in (-1, 1)) and weights (summing to 2) for n >= 1
/// points on [-1, 1]: Newton iteration on P_n from Tricomi's initial guesses.
NIMBUSPHYSICS_EXPORT void GaussLegendre(int n, std::vector<double>& x, std::vector<double>& w);

} // namespace nimbus

#endif
