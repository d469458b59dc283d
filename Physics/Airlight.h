// Airlight: the light an isotropic point light scatters once toward a viewer in a
// homogeneous medium, along a finite or infinite view ray, in closed form.
//
// Sun, Ramamoorthi, Narasimhan & Nayar 2005, "A practical analytic single scattering
// model for real time rendering", ACM Transactions on Graphics 24(3) (SIGGRAPH 2005),
// §3 (airlight). The paper's integral, for a light of intensity I at distance D from
// the viewer, seen at angle gamma from the view ray, a point at distance x along the
// ray being at distance d(x) = sqrt(D^2 + x^2 - 2 x D cos gamma) from the light:
//
//     L_a = integral over x in [0, t_end] of
//           sigma_s p I exp(-sigma_t d(x)) / d(x)^2 exp(-sigma_t x) dx,      p = 1/(4 pi)
//
// and its closed form (the paper writes beta for both coefficients, T = beta x):
//
//     L_a = A0 [F(A1, v1) - F(A1, v0)],
//     A0  = sigma_s I exp(-T_sv cos gamma) / (2 pi D sin gamma),   A1 = T_sv sin gamma,
//     v0  = gamma / 2,   v1 = pi/4 + (1/2) arctan((t_end - D cos gamma) / (D sin gamma)),
//     F(u, v) = integral over xi in [0, v] of exp(-u tan xi) dxi,
//
// T_sv = sigma_t D. The paper's infinite ray has v1 = pi/2. Derivation of the finite
// limits: with h = D sin gamma (the ray's closest approach to the light) substitute
// x - D cos gamma = h tan(phi), so d = h / cos(phi), dx / d^2 = dphi / h and
// d + x = D cos gamma + h (tan phi + sec phi) = D cos gamma + h tan(pi/4 + phi/2);
// then xi = pi/4 + phi/2 runs from gamma/2 (x = 0: tan phi = -cot gamma) to
// pi/4 + arctan((t_end - D cos gamma) / h) / 2 (x = t_end), and to pi/2 as t_end -> inf.
//
// How it is evaluated. The difference F(A1, v1) - F(A1, v0) and the factor
// exp(-T_sv cos gamma) (which overflows behind the viewer, gamma > pi/2, where F is
// tiny) are evaluated as one integral in beta = pi/2 - xi,
//     L_a = sigma_s I / (2 pi h) integral over beta in [beta1, beta0] of
//           exp(-sigma_t (D cos gamma + h cot beta)) dbeta,
//     beta(x) = (1/2) atan2(h, x - D cos gamma),
// whose exponent is sigma_t (d + x) >= sigma_t D (no overflow, no cancellation), whose
// limits come from atan2 (accurate as gamma -> 0 or pi), and whose width is
// beta0 - beta1 = (1/2) atan2(h t_end, D (D - t_end cos gamma)) without subtraction.
// The integral is an adaptive Gauss-Kronrod (7, 15) quadrature to a relative tolerance
// of 1e-13. Measured: against the brute-force quadrature of the integral over x
// (PointLightAirlightByQuadrature) the largest relative difference on a grid of 630
// cases, sigma_t D in [0, 30], gamma in [1e-6, pi - 1e-6], t_end / D in [1e-3, inf],
// is 1.2e-14 with the quadrature at 1e-14 (3.9e-13 at 1e-13, as TestAirlight runs it:
// the quadrature's own error); against 40-digit values (mpmath) of F and of the
// integral, 1.8e-16 and 1.4e-15. The paper's formula written literally loses up
// to 1.9e-6 relative (F1 - F0 cancels behind the viewer at T_sv = 10); this one does not.
// It costs about 2 microseconds a call (-O2); for tables, not per pixel.
//
// Extremes:
//  - sigma_t = 0 (vacuum): L_a = sigma_s I / (4 pi h) atan2(h t_end, D (D - t_end cos gamma)),
//    i.e. sigma_s I (xi1 - xi0) / (2 pi D sin gamma), the angle the segment subtends
//    at the light over the closest approach.
//  - The ray passes through the light (h = 0 with 0 <= D cos gamma <= t_end, which
//    includes D = 0): the integral diverges (1/d^2 is not integrable through d = 0);
//    the functions return +inf. Near it (h small but > 0) they return the large finite
//    value, which grows as 1/h.
//  - h = 0 with the light ahead beyond the segment's end (gamma = 0, t_end < D):
//    sigma_s I / (4 pi) exp(-sigma_t D) t_end / (D (D - t_end)) exactly.
//  - h = 0 with the light behind (gamma = pi from direction vectors): the limit of the
//    integral in beta, sigma_s I / (2 pi) integral over eta in [1/(2(D + t_end)), 1/(2D)]
//    of exp(-sigma_t (1/eta - D)) deta (beta = h eta).
//  - t_end = 0 or sigma_s I = 0: 0.
//
// Units: lengths [m], coefficients [1/m], the intensity I [radiance units x m^2] (its
// irradiance is I / d^2 at distance d in vacuum), the result in radiance units.
// Invalid input (NaN, negative coefficients, distance or t_end, gamma outside [0, pi],
// a non-finite intensity, a zero ray direction) throws std::invalid_argument.
#ifndef nimbus_Airlight_h
#define nimbus_Airlight_h

#include "Math.h"
#include "NimbusPhysicsExport.h" // for export macro

namespace nimbus
{

/// A homogeneous medium with an isotropic phase function 1/(4 pi).
struct NIMBUSPHYSICS_EXPORT AirlightMedium
{
  double ScatteringPerMetre = 0.0; // sigma_s [1/m]
  double ExtinctionPerMetre = 0.0; // sigma_t [1/m], >= sigma_s for a physical medium
};

/// The paper's special function F(u, v) = integral over xi in [0, v] of exp(-u tan xi)
/// dxi, for u >= 0 and v in [0, pi/2] (adaptive Gauss-Kronrod, relative tolerance
/// 1e-13; F(0, v) = v exactly). Throws std::invalid_argument outside that domain.
NIMBUSPHYSICS_EXPORT double AirlightF(double u, double v);

/// The airlight L_a [radiance units] of a point light of intensity I [radiance units
/// x m^2] at distance D [m] from the viewer, at angle gamma [rad, in [0, pi]] between
/// the view ray and the direction toward the light, along the ray's first rayLength
/// metres (+inf: the whole ray). Closed form of the file comment; +inf where the ray
/// passes through the light.
NIMBUSPHYSICS_EXPORT double PointLightAirlight(const AirlightMedium& medium, double intensity,
  double distanceToLight, double gamma, double rayLength);

/// The same from vectors: the light's position relative to the viewer [m] and the
/// ray's direction (any non-zero length). Exact for a light on the ray's line (h = 0).
NIMBUSPHYSICS_EXPORT double PointLightAirlight(const AirlightMedium& medium, double intensity,
  const Vector3& lightFromViewer, const Vector3& rayDirection, double rayLength);

/// The reference the closed form is tested against: the airlight integral over x
/// itself (the file comment's first formula), by adaptive Gauss-Kronrod (7, 15)
/// quadrature to relative tolerance `relativeTolerance`, split at the closest
/// approach, the infinite tail mapped onto [0, 1). Slow; for tests.
NIMBUSPHYSICS_EXPORT double PointLightAirlightByQuadrature(const AirlightMedium& medium,
  double intensity, double distanceToLight, double gamma, double rayLength,
  double relativeTolerance = 1e-12);

} // namespace nimbus

#endif
