// The first scattering of point sources inside a medium, on the medium's own grid: for a
// lightning channel's sources (003 §3's point sources) the light that the cloud scatters
// once, computed where the density is sampled rather than on the multiple-scattering
// solver's coarse grid. A source inside a cloud lights a few mean free paths around it
// (50 m in a cumulus), which a solver grid of 60-90 m cells holds at half a cell and
// spreads; here every grid point gets its own transmittance and 1/r^2, and the points
// next to a source the cell average of T/r^2. Plain C++, no VTK.
//
// What is computed. At grid point x, the unscattered irradiance from all sources and its
// direction-weighted sum (the net flux of the sources' light):
//     E(x) = sum_k I_k T(x, s_k) / r_k^2                          [intensity units / m^2]
//     F(x) = sum_k I_k T(x, s_k) / r_k^2 w_k,  w_k = (x - s_k) / r_k (direction of travel)
// (T with the solver's forward peak given back: FirstScatteringForwardPeak below), so
// that the in-scattered radiance per unit scattering coefficient of the first order,
//     J1(x, w) = sum_k E_k p(w . w_k)                               (003 Eq. 1's first term)
// is, in degree-1 spherical harmonics as the solver keeps J (MultipleScattering.h),
//     J1(w) = (E + 3 k_1 F . w) / (4 pi),  k_1 the phase function's mean cosine.
// (A lobe |F| p(w . F/|F|) + (E - |F|) / (4 pi), exact for one point source, was measured
// darker than the path tracer next to a lightning channel, whose light arrives in a fan of
// directions: docs/lightning.md.) The cloud's scattering coefficient sigma_s multiplies
// it where it is drawn.
//
// Transmittance T(x, s) = exp(-tau): tau is carried outward from the grid point nearest
// the source: a point's tau is its predecessor's, one grid step toward the source along
// the dominant axis (the axis of the largest index difference), plus the trapezoid of the
// extinction between them. The predecessor's tau is its mean extinction tau / r
// bilinearly interpolated in its layer, times its distance (the mean, unlike tau, is
// constant in a homogeneous medium, so there the result is exact). The predecessor is at
// most one step closer to the source on every axis, so sweeping each of the eight octants
// about the source in raster order away from it meets it first: one pass per source costs
// O(points), with the smoothing of one bilinear interpolation per step. A predecessor
// outside the grid's box adds nothing: the box is convex, so the rest of the way
// to the source is outside the medium. Sources in the same grid cell share the pass
// (merged by grid point, their intensities summed): the source's own cell is the grid's
// resolution. The points whose cell touches a source's take the cell average of T/r^2
// (over 1024 directions from the source, the extinction taken as the point's), so that the
// power the medium takes next to the source is kept: a source in a homogeneous cube gives
// 0.987-0.991 of the closed form with mean free paths of 1 to 4 grid steps.
//
// E and F are computed where the medium has extinction and at the points next to it (a
// renderer interpolates between them); elsewhere they are 0 (tau is still carried there).
//
// Cost: sources (merged per grid point) x grid points, each a few loads and an exp (0.3 s
// for a 3.5 km flash on 48 x 48 x 32 points, 4.7 s on 96 x 96 x 64, 2 cores); memory: 4
// doubles and a float per grid point per thread, and the 4 floats per point returned.
#ifndef nimbus_FirstScattering_h
#define nimbus_FirstScattering_h

#include "NimbusPhysicsExport.h" // for export macro

#include "MultipleScattering.h" // ExtinctionGrid

#include <functional>
#include <string>
#include <vector>

namespace nimbus
{

/// A point source of one colour: world position [m] and radiant intensity (any units; the
/// field is in the same units per m^2).
struct NIMBUSPHYSICS_EXPORT ScalarPointSource
{
  Vector3 Position{ { 0, 0, 0 } };
  double Intensity = 0.0;
};

/// The forward peak the multiple-scattering solver folds into the direction of travel
/// (delta-M, Wiscombe 1977; MultipleScatteringField::ForwardPeakFraction): a fraction f of
/// the scattering stays in the beam, so the solver's orders >= 2 start from the beam
/// through the reduced extinction (1 - f albedo) sigma_t. The first scattering that goes
/// with them is then the one the mapper draws for the sun (cloudLight.glsl,
/// SunMultipleScattering): sigma_s p(mu) E with the transmittance
///     T' = f exp(-tau) + (1 - f) exp(-(1 - f albedo) tau)
/// in place of exp(-tau), the light scattered once into the peak and then out of the beam
/// (f = 0: the plain first scattering).
struct NIMBUSPHYSICS_EXPORT FirstScatteringForwardPeak
{
  double Fraction = 0.0; // f in [0, 1)
  double Albedo = 1.0;   // the medium's single-scattering albedo
};

/// The sources' unscattered irradiance on the grid (see the file comment).
struct NIMBUSPHYSICS_EXPORT FirstScatteringField
{
  std::array<int, 3> Dimensions{ { 0, 0, 0 } };
  /// 4 floats per grid point (x fastest): E, then F's world x, y, z.
  std::vector<float> Values;
  /// Distinct grid points the sources were merged to (one propagation pass each).
  int MergedSources = 0;
  double Seconds = 0.0;
};

/// "" or what is wrong: a bad grid (the solver's checks), sources with non-finite
/// positions or negative or non-finite intensity, a forward peak outside [0, 1) or an
/// albedo outside [0, 1].
NIMBUSPHYSICS_EXPORT std::string CheckFirstScatteringInput(const ExtinctionGrid& grid,
  const std::vector<ScalarPointSource>& sources,
  const FirstScatteringForwardPeak& peak = FirstScatteringForwardPeak());

/// Computes the field. Throws std::invalid_argument with CheckFirstScatteringInput's
/// message. `progress(fraction)` is called on the calling thread; it may throw to stop.
/// Threads: 0 for the hardware's; the result does not depend on it (each thread sums
/// its sources in its own buffer, then the buffers are added in a fixed order: results
/// agree to float rounding across thread counts).
NIMBUSPHYSICS_EXPORT FirstScatteringField ComputeFirstScattering(const ExtinctionGrid& grid,
  const std::vector<ScalarPointSource>& sources, int threads = 0,
  const std::function<void(double)>& progress = nullptr,
  const FirstScatteringForwardPeak& peak = FirstScatteringForwardPeak());

/// Sum of the fields' values weighted per field (same dimensions; an empty list gives an
/// empty field). Throws std::invalid_argument when the sizes differ.
NIMBUSPHYSICS_EXPORT FirstScatteringField CombineFirstScattering(
  const std::vector<const FirstScatteringField*>& fields, const std::vector<double>& weights);

/// The mean cosine, about the sources' directions, of the delta-M beam at a point:
/// E' = I exp(-(1 - f albedo) tau) / r^2 (the field through the reduced extinction) holds
/// the unscattered light E = I exp(-tau) / r^2 and the light that scattered only inside
/// the truncated forward peak, n times with probability Poisson(f albedo tau). Each peak
/// scattering through an HG lobe of `peakLobeG` (DeltaMPeakLobeG) multiplies the mean
/// cosine by it (HG lobes fold by multiplying g), so the beam's is
///     sum_n P(n) g^n = exp(-f albedo tau (1 - g)) = (E / E')^(1 - g).
/// E from the two fields at the point: `plainE` with T' = f exp(-tau) + (1 - f) E'/I r^2
/// (FirstScatteringForwardPeak), E = (plainE - (1 - f) reducedE) / f. With several
/// sources it is the ratio of the sums. 1 where reducedE <= 0, f <= 0 or peakLobeG <= 0;
/// in [0, 1].
NIMBUSPHYSICS_EXPORT double DeltaMBeamMeanCosine(
  double plainE, double reducedE, double fraction, double peakLobeG);

/// J1(w) for one point's 4 values in degree-1 spherical harmonics (the file comment), w a
/// direction of propagation, k1 the phase function's mean cosine; clamped at 0.
NIMBUSPHYSICS_EXPORT double EvaluateFirstScattering(
  const float* values, const Vector3& w, double k1);

} // namespace nimbus

#endif
