// The average over one grid cell of a point source's unscattered light, T(r)/r^2 and
// T(r) w/r^2, for the cells next to the source, where the value at the cell's centre
// misses most of the power the cell takes (1/r^2 is far from linear there). Shared by
// the first scattering on the density's grid (FirstScattering.h) and the
// multiple-scattering solver's point lights (MultipleScattering.h). Plain C++, no VTK.
//
// In spherical coordinates about the source dV = r^2 dr dw, so
//     integral over the box of T(r)/r^2 dV = integral over directions w of the integral
//     of T(r) along the chord that the ray from the source along w cuts through the box,
// summed over 1024 Fibonacci directions and divided by the box's volume; w times each
// chord's integral gives the flux. T(r) = f exp(-sigma r) + (1 - f) exp(-s sigma r): a
// beam through a medium of constant extinction sigma [1/m], with the forward peak f of
// the delta-M scaling given back at the reduced extinction s sigma
// (FirstScatteringForwardPeak; f = 0: plain exp(-sigma r)).
//
// Accuracy: the power a homogeneous medium takes from a source, summed over a grid whose
// cells next to the source take this average and the others their centre's value, is
// 0.985-0.992 of the closed form 4 pi I (1 - exp(-sigma R)) for 0.2 to 1 mean free paths
// per grid step (TestFirstScattering, TestMultipleScattering); with the centre's value
// everywhere it is 0.78-0.93.
#ifndef nimbus_CellAverage_h
#define nimbus_CellAverage_h

#include "NimbusPhysicsExport.h" // for export macro

#include "Math.h" // Vector3

namespace nimbus
{

/// The transmittance along a beam: f exp(-sigma r) + (1 - f) exp(-Reduced sigma r).
struct NIMBUSPHYSICS_EXPORT BeamTransmittance
{
  double Sigma = 0.0;        // extinction [1/m], constant from the source through the cell
  double PeakFraction = 0.0; // f in [0, 1]
  double Reduced = 1.0;      // s, the reduced extinction's factor (1 - f albedo)
};

/// A cell's averages of T/r^2 [1/m^2] and of T w/r^2 (w the direction of travel from the
/// source, in the cell's frame).
struct NIMBUSPHYSICS_EXPORT CellAverageOfSource
{
  double InverseSquare = 0.0;
  Vector3 Flux{ { 0, 0, 0 } };
};

/// The averages over the box of half-widths `halfWidths` [m] (its axes the frame's) of a
/// source at `source` [m], relative to the box's centre in the box's frame.
NIMBUSPHYSICS_EXPORT CellAverageOfSource AverageSourceOverCell(
  const Vector3& source, const Vector3& halfWidths, const BeamTransmittance& transmittance);

} // namespace nimbus

#endif
