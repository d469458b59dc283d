// Spherical-earth clear-sky atmosphere: Rayleigh (molecules) + Mie (aerosols),
// each with an exponential density profile rho(h) = exp(-h/H) (002 sky model,
// 004 §4).  Optical quantities for the sky, sunlight attenuation and the
// atmosphere terms of 000 Eqs. 2, 6 and 7.
//
// Units: lengths and positions in metres, positions relative to the earth
// centre; scattering / extinction coefficients beta in 1/m; wavelength lambda in
// nanometres.  An "optical length" is the sea-level-equivalent column length
//     L = integral exp(-h(s)/H) ds          [m]
// so that the optical depth is tau(lambda) = beta_R(lambda) L_R + beta_M,ext L_M
// (dimensionless) and the transmittance is exp(-tau).
//
// Density is zero above the top of the atmosphere (r > topRadius): all paths are
// clipped to the atmosphere shell.
#ifndef nimbus_Atmosphere_h
#define nimbus_Atmosphere_h

#include "Math.h"
#include "NimbusPhysicsExport.h" // for export macro

#include <array>

namespace nimbus
{

/// The air: what every renderer, the sky and the scene format call the
/// atmosphere's parameters (names carry their units). Defaults: Nishita et al.
/// 1993 / Bruneton & Neyret 2008 values.
struct NIMBUSPHYSICS_EXPORT AtmosphereParameters
{
  double EarthRadiusMetres = 6360000.0;        // R_e
  double TopRadiusMetres = 6420000.0;          // R_top: a 60 km thick atmosphere
  double RayleighScaleHeightMetres = 8000.0;   // H_R
  double MieScaleHeightMetres = 1200.0;        // H_M
  double RayleighScatteringPerMetre = 13.5e-6; // beta_R at sea level and 550 nm (molecules
                                               // do not absorb: extinction = scattering)
  double MieScatteringPerMetre = 2.0e-5;       // beta_M,s at sea level, wavelength independent
  double MieAlbedo = 0.9;                      // beta_M,s / beta_M,ext of the aerosols
  double MieG = 0.76; // Cornette-Shanks asymmetry of the aerosol phase function
};

/// The air over a scene: the atmosphere, whether it is there at all, and where the
/// scene sits in it. Scene point p (metres) maps to the earth-centred frame as
/// (p.x, p.y, EarthRadiusMetres + SceneAltitudeMetres + p.z).
struct NIMBUSPHYSICS_EXPORT SceneAtmosphere : AtmosphereParameters
{
  bool Enabled = true;
  double SceneAltitudeMetres = 0.0; // altitude above sea level of the scene's z = 0
};

/// Optical lengths (sea-level-equivalent column lengths) along a ray.
struct NIMBUSPHYSICS_EXPORT OpticalLengths
{
  double RayleighLengthMetres = 0.0; // integral exp(-h/H_R) ds
  double MieLengthMetres = 0.0;      // integral exp(-h/H_M) ds
  bool HitsGround = false;           // the ray hits the earth; lengths are up to the hit point
};

/// Distance [m] from radius r (from the earth centre, m) along a direction with
/// zenith cosine mu to the sphere r = topRadius (the top of the atmosphere); 0 when
/// the ray misses it (only possible from above it). With b = r mu and
/// c = (r - top)(r + top): -b + sqrt(b^2 - c), at least 0.
NIMBUSPHYSICS_EXPORT double DistanceToTopOfAtmosphere(double r, double mu, double topRadius);

/// Sea-level-equivalent length [m] of one exponential layer (scale height H) along a
/// straight ray in a flat atmosphere: integral_0^d exp(-max(h0 + s cosZenith, 0)/H) ds
/// in closed form, with the density at the start taken at max(h0, 0):
///   exp(-max(h0, 0)/H) H (1 - exp(-x)) / cosZenith,  x = d cosZenith / H,
/// and its series d (1 - x/2 + x^2/6 - x^3/24) for |x| < 1e-2 (truncation error
/// below 1e-10 relative; no cancellation of 1 - exp(-x) in float either). The GPU
/// mapper's per-pixel view transmittance (000 Eq. 6 in closed form); its error
/// against the spherical earth (Atmosphere::OpticalLength) is measured in TestAtmosphere.
NIMBUSPHYSICS_EXPORT double FlatLayerOpticalLength(
  double altitudeMetres, double cosZenith, double distanceMetres, double scaleHeightMetres);

class NIMBUSPHYSICS_EXPORT Atmosphere
{
public:
  using Vector3 = nimbus::Vector3;

  /// Throws std::invalid_argument unless 0 < earthRadius < topRadius, scale heights
  /// > 0, coefficients >= 0, 0 < albedo <= 1 (all finite).
  explicit Atmosphere(const AtmosphereParameters& parameters = AtmosphereParameters());

  const AtmosphereParameters& GetParameters() const { return this->Parameters; }

  /// Altitude h = |p| - R_e [m] of p (relative to the earth centre).  Negative
  /// below the ground (not clamped here).
  double Altitude(const Vector3& p) const;

  /// Relative density rho(h) = exp(-max(h,0)/H) inside the atmosphere, 0 above it.
  double Density(double altitude, double scaleHeight) const;

  /// beta_R(lambda) = rayleighScattering550 * (550/lambda)^4 [1/m] (= extinction).
  double RayleighScattering(double lambdaNm) const;
  /// beta_M,s [1/m] (wavelength independent).
  double MieScattering(double lambdaNm) const;
  /// beta_M,ext = beta_M,s / albedo [1/m].
  double MieExtinction(double lambdaNm) const;
  /// Rayleigh phase function [1/sr], mu = cos(scattering angle).
  double RayleighPhase(double mu) const;
  /// Cornette-Shanks with g = mieG [1/sr] (000 Eq. 3 / 004 Eq. 5, divided by 4 pi).
  double MiePhase(double mu) const;

  /// L = integral over the straight segment p0 -> p1 of exp(-h/H) ds [m].  The
  /// parts of the segment above the top of the atmosphere contribute 0.  The
  /// segment is NOT tested against the earth: parts below the ground count with
  /// rho = 1 (h clamped to 0); use OpticalLengthsToTop for occlusion.
  /// Throws std::invalid_argument for non-finite input or scaleHeight <= 0.
  double OpticalLength(const Vector3& p0, const Vector3& p1, double scaleHeight) const;

  /// Optical lengths from p along direction d (need not be unit length) to the top
  /// of the atmosphere, for H_R and H_M.
  ///  - If the ray hits the earth, hitsGround = true and the lengths are
  ///    integrated only up to the ground hit (finite).  A ray from a point on the
  ///    ground hits it iff d points strictly downward (dot(p, d) < 0); exactly
  ///    horizontal rays graze the earth and are not blocked.
  ///  - p below the ground is clamped radially onto the ground first.
  ///  - p above the top: the lengths are those of the part of the ray inside the
  ///    atmosphere (0 if it misses or looks away).
  /// Throws std::invalid_argument for a zero or non-finite d or non-finite p.
  OpticalLengths OpticalLengthsToTop(const Vector3& p, const Vector3& d) const;

  /// tau(lambda) = beta_R(lambda) L_R + beta_M,ext L_M (dimensionless; ignores hitsGround).
  double OpticalDepth(const OpticalLengths& lengths, double lambdaNm) const;
  /// exp(-tau(lambda)); exactly 0 when lengths.HitsGround.
  double Transmittance(const OpticalLengths& lengths, double lambdaNm) const;
  /// Transmittance from p toward direction d to the top of the atmosphere (e.g.
  /// sunlight reaching p, with d toward the sun); 0 if the earth blocks the ray.
  double TransmittanceToTop(const Vector3& p, const Vector3& d, double lambdaNm) const;
  /// Transmittance along the segment p0 -> p1 (no ground test, see OpticalLength).
  double TransmittanceBetween(const Vector3& p0, const Vector3& p1, double lambdaNm) const;

private:
  AtmosphereParameters Parameters;
};

} // namespace nimbus

#endif
