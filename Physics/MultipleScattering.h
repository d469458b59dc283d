// Multiple scattering in a cloud as a precompute for the GPU mapper: from a grid of
// extinction, the cloud's optics, the sun (or point lights), the sky and the ground,
// the radiance that the cloud's particles scatter at every grid point of orders >= 2
// (and of order 1 for the sky, the ground and the medium's own emission), as low-order
// spherical harmonics.
// The mapper adds it to its exact single scattering of the sun (000 Eq. 8).
//
// What is computed. At grid point x, for light leaving in direction w (the direction
// of propagation), the in-scattered radiance per unit scattering coefficient
//     J(x, w) = integral over w' of p(w . w') L(x, w') dw'            [radiance]
// (the cloud's source function is sigma_s J), without the single scattering of the
// direct sun, which the mapper computes exactly with its shadow-view slices. J is
// stored as real spherical harmonics of degree <= 1 per colour channel:
//     J(x, w) = sum_{lm} c_lm(x) Y_lm(w),  Y_00 = 0.282095, Y_1m = 0.488603 (w_y, w_z, w_x)
// (the order of `Coefficients`: c_00, c_1-1, c_10, c_11 for R, then G, then B).
//
// Methods (MultipleScatteringMethod), from the cheapest:
//  - Octaves (Wrenninge, Kulla & Lundqvist 2013, "Oz: the great and volumetric"): the
//    sun's orders >= 2 are approximated in the mapper's shader by extra single-
//    scattering terms with extinction, scattering and phase asymmetry scaled by
//    a^i, b^i, c^i; the solver computes only the sky and the ground light (order 1,
//    004 §3.5).
//  - ReferencePatterns (004 §3.4): orders 2..Orders of the sun by a 3-D filter of
//    contribution ratios built on a uniform-density sample space, with the paper's
//    stochastic selection of paths; sky and ground light of order 1 (004 §3.5).
//  - DiscreteDirections (003 Eq. 1, iterated): the radiance in NumberOfDirections
//    directions at every point of a downsampled grid, transported along each
//    direction and scattered between directions order after order (all orders: the
//    tail beyond Orders is summed as a geometric series). The sky and the ground
//    enter as radiance at the grid's boundary, so all their orders are included.
//    The cloud's forward peak is treated with the delta-M scaling (Wiscombe 1977):
//    a fraction f = k_2 of the scattering (the phase function's second Legendre
//    coefficient; g^2 for Henyey-Greenstein) is kept in the direction of travel, which
//    makes a few dozen directions enough; the light the peak carries along the sun's
//    direction is returned to the mapper as ForwardPeakFraction (see there).
//    The medium's own emission (CloudLighting::Emission, hot smoke and fire) is a
//    source of this method only: its light of every order enters J.
//
// Units: lengths in metres, extinction in 1/m, radiance and irradiance in the
// caller's units (the mapper's: relative to the sun, linear sRGB).
#ifndef nimbus_MultipleScattering_h
#define nimbus_MultipleScattering_h

#include "NimbusPhysicsExport.h" // for export macro

#include "Math.h"
#include "PhaseFunctions.h"
#include "SpotLight.h"

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace nimbus
{
using Rgb = std::array<double, 3>;

enum class MultipleScatteringMethod
{
  None = 0,              // nothing (the mapper's k_multi constant only)
  Octaves = 1,           // Wrenninge et al. 2013 in the shader + sky light (004 §3.5)
  ReferencePatterns = 2, // 004 §3.4 + sky light (004 §3.5)
  DiscreteDirections = 3 // 003 Eq. 1, all orders, sun, sky and ground
};

/// A regular grid of extinction sigma_t [1/m] at its points, x fastest. The grid's
/// axes are the unit world vectors Axes[0..2] (orthonormal); point (i, j, k) sits at
/// Origin + i Spacing[0] Axes[0] + j Spacing[1] Axes[1] + k Spacing[2] Axes[2].
struct NIMBUSPHYSICS_EXPORT ExtinctionGrid
{
  std::array<int, 3> Dimensions{ { 0, 0, 0 } };
  Vector3 Origin{ { 0, 0, 0 } };  // [m], world
  Vector3 Spacing{ { 1, 1, 1 } }; // [m]
  std::array<Vector3, 3> Axes{ { { { 1, 0, 0 } }, { { 0, 1, 0 } }, { { 0, 0, 1 } } } };
  std::vector<float> Extinction; // sigma_t [1/m]

  std::size_t NumberOfPoints() const
  {
    return static_cast<std::size_t>(this->Dimensions[0]) * this->Dimensions[1] *
      this->Dimensions[2];
  }
  std::size_t Index(int i, int j, int k) const
  {
    return (static_cast<std::size_t>(k) * this->Dimensions[1] + j) * this->Dimensions[0] + i;
  }
  Vector3 Position(double i, double j, double k) const;
};

/// The cloud's particles: single-scattering albedo and phase function.
struct NIMBUSPHYSICS_EXPORT CloudOptics
{
  double Albedo = 0.99;
  PhaseFunctionKind Phase = PhaseFunctionKind::CornetteShanks;
  double G = 0.85;
};

/// A light far away (the sun): the unit world direction toward it and its
/// irradiance on a surface facing it, as a function of the world height z [m] (the
/// air above dims it; nullptr: ConstantIrradiance everywhere).
struct NIMBUSPHYSICS_EXPORT DirectionalLight
{
  Vector3 ToLight{ { 0, 0, 1 } };
  Rgb ConstantIrradiance{ { 1, 1, 1 } };
  std::function<Rgb(double z)> Irradiance;
  Rgb IrradianceAt(double z) const
  {
    return this->Irradiance ? this->Irradiance(z) : this->ConstantIrradiance;
  }
};

/// A point light (a lightning stroke's sources, a view's point light or spotlight):
/// world position [m] and radiant intensity [radiance units x m^2] (irradiance
/// I / r^2 at distance r, before the cloud dims it), and its beam: the intensity
/// toward unit direction w (from the light) is I SpotFactor(Spot, w) (SpotLight.h;
/// Spot.Axis a world direction). The default profile is a point light (factor 1).
/// Built as {position, intensity} (a point light) or {position, intensity, spot}.
struct NIMBUSPHYSICS_EXPORT PointLight
{
  PointLight() = default;
  PointLight(const Vector3& position, const Rgb& intensity, const SpotProfile& spot = SpotProfile())
    : Position(position)
    , Intensity(intensity)
    , Spot(spot)
  {
  }
  Vector3 Position{ { 0, 0, 0 } };
  Rgb Intensity{ { 1, 1, 1 } };
  SpotProfile Spot;
};

/// Everything that lights the cloud from outside. `Sky(w)` is the radiance seen
/// looking toward unit world direction w from the cloud without the cloud: the sky
/// above the horizon, the ground and the air in front of it below (004 §3.5: the
/// ground's reflection as upward sky light). nullptr: black.
struct NIMBUSPHYSICS_EXPORT CloudLighting
{
  bool HasSun = true;
  DirectionalLight Sun;
  std::vector<PointLight> PointLights;
  std::function<Rgb(const Vector3& lookingToward)> Sky;
  /// Light the medium itself emits (hot smoke, fire): the emission coefficient eta
  /// [radiance units per metre] at every grid point, 3 floats (R, G, B) per point in
  /// the grid's order, the same in every direction; empty: none. It enters the
  /// radiative transfer equation as the source term:
  ///     dL/ds = -sigma_t L + sigma_s J + eta,
  /// so a homogeneous medium glowing everywhere holds L = eta / (sigma_t (1 - albedo))
  /// deep inside. DiscreteDirections takes it as order 0, like the sky's light: the
  /// emitted radiance travels (attenuated), is scattered and scattered again, and J
  /// holds its scattered light of orders >= 1 (J = integral p L over the emitted
  /// radiance of every order; the unscattered emission itself is the caller's to draw,
  /// as the mapper does). Where a point has no extinction its emission is not carried
  /// (the transport holds a source per unit extinction, eta / sigma_t). The delta-M
  /// forward peak of the emitted light stays in the radiance the solver carries (it is
  /// not returned apart, as the sun's is). Octaves and ReferencePatterns refuse it;
  /// None ignores it.
  std::vector<float> Emission;
};

struct NIMBUSPHYSICS_EXPORT MultipleScatteringOptions
{
  MultipleScatteringMethod Method = MultipleScatteringMethod::DiscreteDirections;
  /// Orders computed explicitly (>= 2). DiscreteDirections: the radiance scattered
  /// 1..Orders times (so J of orders 2..Orders + 1; the sky's and the ground's from
  /// order 1), stopping earlier when an order carries < 1e-5 of the total, the rest a
  /// geometric series when ExtrapolateHigherOrders; with it, orders go on past Orders
  /// (up to 4 x Orders) while the ratio of successive orders' energies still moves by
  /// more than 1e-4 of itself per order, since a tail from a ratio still moving counts
  /// too much light (a source deep in a cloud of low asymmetry) or too little (the
  /// sun). ReferencePatterns: J of orders
  /// 2..Orders (the paper: 3).
  int Orders = 32;
  bool ExtrapolateHigherOrders = true;
  /// Directions of the discrete-direction system and of the sky-light look-ups
  /// (>= 6): a spherical Fibonacci set of equal solid angles 4 pi / n.
  int NumberOfDirections = 26;
  /// Sky and ground light (004 §3.5); false: sun (and point lights) only.
  bool SkyLight = true;
  /// Octaves (Wrenninge et al. 2013): number N of terms including the single
  /// scattering (>= 1; 1 = none added), and the per-octave scales a (extinction),
  /// b (scattering), c (phase asymmetry), each in (0, 1].
  int Octaves = 4;
  double OctaveExtinctionScale = 0.5;
  double OctaveScatteringScale = 0.5;
  double OctaveAsymmetryScale = 0.5;
  /// Reference patterns (004 §3.4): half-width of the sample space in grid points
  /// (the paper: 30^3 -> 15), the share r of the total contribution the kept paths
  /// must reach (the paper: 0.8) and the fraction n1/n2 of the kept paths evaluated
  /// per point (stochastic selection; 1 = all), with a fixed seed.
  int PatternRadius = 6;
  double PatternContribution = 0.8;
  double PatternSelection = 0.25;
  std::uint64_t Seed = 1;
  /// Add the point lights' first scattering to J (their single scattering, which no
  /// renderer computes otherwise; DiscreteDirections only). Default off: J holds the
  /// orders the mapper does not compute (for the sun, orders >= 2).
  bool PointLightFirstScattering = false;
  /// Leave the emission's first scattering out of J (DiscreteDirections; the emission's
  /// light still seeds the higher orders): J then holds the glow's orders >= 2, for a
  /// caller that computes the first on a finer grid (EmissionFirstScattering) and adds
  /// it. Default off: J holds every order of the glow's scattered light.
  bool EmissionFirstScatteringApart = false;
  /// Threads (0: hardware concurrency). Results do not depend on it.
  int Threads = 0;
};

/// The solver's answer on the grid it was given.
struct NIMBUSPHYSICS_EXPORT MultipleScatteringField
{
  std::array<int, 3> Dimensions{ { 0, 0, 0 } };
  /// 12 floats per point (see the file comment): J's SH coefficients for R, G, B.
  std::vector<float> Coefficients;
  /// The fraction f of the cloud's scattering the solver moved into the forward
  /// direction (delta-M; 0 unless DiscreteDirections). The mapper adds the sun light
  /// that peak carries, sigma_s (1 - f) p(w . L) E (exp(-(1 - f albedo) tau) - exp(-tau)),
  /// tau the cloud's optical depth toward the sun, to its single scattering.
  double ForwardPeakFraction = 0.0;
  /// The asymmetry g' of the HG phase function that stands for the rest.
  double TruncatedG = 0.0;
  int OrdersComputed = 0;
  /// Per channel: the ratio of the last two orders' energies and the share of the
  /// total that the geometric tail added (DiscreteDirections).
  Rgb LastOrderRatio{ { 0, 0, 0 } };
  Rgb TailShare{ { 0, 0, 0 } };
  double Seconds = 0.0;
};

/// Bytes the solver would allocate for `grid` with `options` (the field, the
/// directional radiance, scratch). Compare with a memory budget before solving.
NIMBUSPHYSICS_EXPORT double EstimateMultipleScatteringBytes(
  const ExtinctionGrid& grid, const MultipleScatteringOptions& options);

/// The first message describing what is wrong with the input, or "" (dimensions
/// < 1, sizes that do not match, NaN, infinite or negative extinction or spacing,
/// axes not orthonormal, albedo outside [0, 1], NaN lighting, emission of the wrong
/// size, NaN, infinite or negative, or given to a method that does not take it,
/// options out of range).
NIMBUSPHYSICS_EXPORT std::string CheckMultipleScatteringInput(const ExtinctionGrid& grid,
  const CloudOptics& optics, const CloudLighting& lighting,
  const MultipleScatteringOptions& options);

/// Solves. Throws std::invalid_argument with CheckMultipleScatteringInput's message.
/// `progress(fraction)` is called on the calling thread with fractions in [0, 1]; it
/// may throw to stop the solve (the exception propagates).
NIMBUSPHYSICS_EXPORT MultipleScatteringField SolveMultipleScattering(const ExtinctionGrid& grid,
  const CloudOptics& optics, const CloudLighting& lighting,
  const MultipleScatteringOptions& options,
  const std::function<void(double fraction)>& progress = nullptr);

/// The first scattering of the medium's emission alone (CloudLighting::Emission, 3
/// floats per point): J1(x, w) = integral p(w . s) L0(x, s) ds, L0 the emitted radiance
/// attenuated on its way (through the delta-M scaled extinction, as the discrete-
/// direction solve carries it), as 12 SH coefficients per point like
/// MultipleScatteringField::Coefficients. With EmissionFirstScatteringApart, the solve's
/// J plus this is the solve's J without it (to float rounding), so the first scattering,
/// which holds most of the glow's scattered light next to a small hot source, can be
/// computed on a finer grid than the rest. Needs options.Method DiscreteDirections
/// (only NumberOfDirections counts). Throws std::invalid_argument as
/// SolveMultipleScattering.
NIMBUSPHYSICS_EXPORT std::vector<float> EmissionFirstScattering(const ExtinctionGrid& grid,
  const CloudOptics& optics, const std::vector<float>& emission,
  const MultipleScatteringOptions& options,
  const std::function<void(double fraction)>& progress = nullptr);

/// Evaluates J(w) from one point's 12 coefficients: RGB, clamped at 0.
NIMBUSPHYSICS_EXPORT Rgb EvaluateInScattering(const float* coefficients, const Vector3& w);

/// The Legendre coefficient k_l of a normalised phase function, the factor by which
/// convolving with it scales degree-l spherical harmonics: k_l = 2 pi integral of
/// p(mu) P_l(mu) dmu (k_0 = 1, k_1 = mean cosine). For l <= 2.
NIMBUSPHYSICS_EXPORT double PhaseLegendreCoefficient(const CloudOptics& optics, int l);

/// The forward peak that the delta-M truncation f = k_2 takes out of the phase function
/// (Wiscombe 1977; the solver's and the lightning view's truncation), as a Henyey-Greenstein
/// lobe of its own: the g whose HG(1; g) is the peak's forward value
/// [p(1) - (1 - f) HG(1; g')] / f, g' = (k_1 - k_2) / (1 - k_2), solved in closed form from
/// (1 + g) / (1 - g)^2 = 4 pi HG(1; g). For Cornette-Shanks g 0.85: 0.872 (half width 6 deg).
/// 0 when the phase function has no peak to truncate (k_2 <= 0, k_1 <= k_2 or k_2 >= 0.999,
/// as the mapper's delta-M view takes it).
NIMBUSPHYSICS_EXPORT double DeltaMPeakLobeG(const CloudOptics& optics);

/// A spherical Fibonacci set of n unit directions (equal solid angles 4 pi / n).
NIMBUSPHYSICS_EXPORT std::vector<Vector3> FibonacciDirections(int n);

/// Optical depth toward a directional light at every grid point (trapezoid rule on
/// marches of one grid step through the trilinear extinction; 0 outside).
NIMBUSPHYSICS_EXPORT std::vector<float> OpticalDepthToward(
  const ExtinctionGrid& grid, const Vector3& toLight, int threads);

/// Extinction at a point in grid coordinates (trilinear; 0 outside).
NIMBUSPHYSICS_EXPORT double ExtinctionAt(const ExtinctionGrid& grid, double i, double j, double k);
} // namespace nimbus

#endif
