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
  // Angstrom exponent alpha of the aerosols (Angstrom 1929): their scattering and
  // extinction scale as (550 nm / lambda)^alpha around the 550 nm values above.
  // 0 = grey (wavelength independent), the default of the scene format and the mapper;
  // the sky uses 1.3 (ClearSkyAtmosphere).
  double MieAngstromExponent = 0.0;
  // Total ozone column [Dobson units, 1 DU = 2.687e20 molecules/m^2] in a layer from
  // 10 to 40 km peaking at 25 km (OzoneDensity); ozone only absorbs (the Chappuis band,
  // 500-700 nm). 0 = no ozone (the scene format's and the mapper's default); the sky
  // uses 300 DU.
  double OzoneDobsonUnits = 0.0;
};

/// The range of the turbidity T that the sky accepts, and its default (a clear day).
/// Preetham et al. and Hosek & Wilkie fit T in [2, 10] (Hosek-Wilkie from 1); T = 1 is
/// air without aerosol.
constexpr double kMinTurbidity = 1.0;
constexpr double kMaxTurbidity = 10.0;
constexpr double kDefaultTurbidity = 2.0;

/// How much aerosol a turbidity T means: the vertical aerosol optical depth at 550 nm
///   tau_A(550) = kAerosolOpticalDepthPerTurbidity (T - 1),
/// T = 1 air without aerosol. The slope is calibrated (one number) so that the sky of T
/// is the clear sky that Hosek & Wilkie 2012 (and Preetham et al. 1999) call T: against
/// Hosek-Wilkie over sun elevations 1..90 deg and T = 2..5 (TestSky
/// ValidationAgainstHosekWilkie, docs/sky.md) slopes 0.015..0.025 keep every luminance
/// shape within 10 % and every chromaticity within 0.02; 0.03 already misses 3 of 40 and
/// Preetham's own relation (Appendix A.1, beta = 0.04608 T - 0.04586 at 1 um, i.e. about
/// 0.1 (T - 1) at 550 nm) gives a sky 0.03..0.04 paler in chromaticity than both models
/// at high sun. Measured skies agree with a small slope: Bruneton 2016 ("A Qualitative
/// and Quantitative Evaluation of 8 Clear Sky Models", IEEE TVCG 23(12)) fits the sky
/// measured by Kider et al. 2014 with Preetham and Hosek-Wilkie at T = 2.53 and with
/// libRadtran at the aerosol optical depth 0.064 (Angstrom alpha 0.8, beta 0.04):
/// slope 0.042.
constexpr double kAerosolOpticalDepthPerTurbidity = 0.025;
NIMBUSPHYSICS_EXPORT double AerosolOpticalDepthFromTurbidity(double turbidity);

/// Sea-level aerosol scattering coefficient beta_M,s(550 nm) [1/m] of turbidity T for
/// the given atmosphere's aerosol scale height H_M and albedo: the vertical optical
/// depth tau_A(550) equals the extinction column beta_M,ext(550) H_M of the exponential
/// layer (its part above the top of the atmosphere, exp(-60 km / H_M), neglected), so
///   beta_M,s(550) = albedo tau_A(550) / H_M   (the Angstrom exponent scales the other
/// wavelengths around 550 nm). Throws std::invalid_argument for a non-finite T or T < 1.
NIMBUSPHYSICS_EXPORT double MieScatteringFromTurbidity(
  double turbidity, const AtmosphereParameters& atmosphere);
/// Its inverse: the turbidity T of a sea-level aerosol scattering coefficient [1/m] (>= 0).
NIMBUSPHYSICS_EXPORT double TurbidityFromMieScattering(
  double mieScatteringPerMetre, const AtmosphereParameters& atmosphere);

/// The clear-sky atmosphere of turbidity T (Preetham et al. 1999's haze measure; 2 = very
/// clear, 3 = clear, 5 = light haze, 10 = hazy) that the sky uses
/// (SkyParameters default: T = kDefaultTurbidity):
///  - the aerosol amount from T (AerosolOpticalDepthFromTurbidity);
///  - Angstrom exponent 1.3 (Angstrom 1929's continental mean, Preetham's Appendix A.1);
///  - the aerosol phase function: Cornette-Shanks whose mean cosine (asymmetry factor)
///    is 0.70, the mean of the AERONET sky-radiometer retrievals of continental and urban
///    aerosol at 440-670 nm (Dubovik et al. 2002, "Variability of absorption and optical
///    properties of key aerosol types observed in worldwide locations", J. Atmos. Sci. 59,
///    Table 1: 0.59-0.75), i.e. g_CS = 0.637 (CornetteShanksMeanCosine); the earlier
///    g = 0.76 has mean cosine 0.81, brighter than measured aerosol around the sun;
///  - ozone 300 DU (the global mean column);
///  - everything else as AtmosphereParameters' defaults.
/// Throws std::invalid_argument for T non-finite or outside [kMinTurbidity, kMaxTurbidity].
NIMBUSPHYSICS_EXPORT AtmosphereParameters ClearSkyAtmosphere(double turbidity);

/// Absorption cross-section of ozone [m^2 per molecule] at lambda [nm]: Serdyuchenko et
/// al. 2014 ("High spectral resolution ozone absorption cross-sections", Atmos. Meas.
/// Tech. 7, 625; the IUP Bremen O3 spectra 2011, 233 K), averaged over 10-nm bins
/// 360-830 nm as tabulated by Bruneton 2017 (precomputed_atmospheric_scattering), linear
/// between the bin centres, clamped outside. Chappuis peak 5.0e-25 m^2 at 605 nm.
NIMBUSPHYSICS_EXPORT double OzoneCrossSection(double lambdaNm);

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
  double OzoneLengthMetres = 0.0;    // integral OzoneDensity(h) ds (0 without ozone)
  bool HitsGround = false;           // the ray hits the earth; lengths are up to the hit point
};

/// Distance [m] from radius r (from the earth centre, m) along a direction with
/// zenith cosine mu to the sphere r = topRadius (the top of the atmosphere); 0 when
/// the ray misses it (only possible from above it). With b = r mu and
/// c = (r - top)(r + top): -b + sqrt(b^2 - c), at least 0.
NIMBUSPHYSICS_EXPORT double DistanceToTopOfAtmosphere(double r, double mu, double topRadius);

/// Sea-level-equivalent length [m] of one exponential layer (scale height H) along a
/// straight ray in a flat atmosphere: integral_0^d exp(-max(h0 + s cosZenith, 0)/H) ds
/// in closed form. The density is constant (1) below sea level, as in
/// Atmosphere::Density, so the path splits where it crosses h = 0: the part below
/// counts its length, the part above from altitude h >= 0 is
///   exp(-h/H) H (1 - exp(-x)) / cosZenith,  x = l cosZenith / H (l its length),
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
  /// beta_M,s(lambda) = beta_M,s(550) (550/lambda)^alpha [1/m] (Angstrom 1929;
  /// wavelength independent for alpha = 0).
  double MieScattering(double lambdaNm) const;
  /// beta_M,ext = beta_M,s / albedo [1/m].
  double MieExtinction(double lambdaNm) const;
  /// Ozone absorption at the layer's peak, n_max sigma_O3(lambda) [1/m], with
  /// n_max = OzoneDobsonUnits 2.687e20 / 15000 m (the profile's column is 15 km x peak).
  double OzoneAbsorption(double lambdaNm) const;
  /// Relative ozone density at altitude h [m] (Bruneton 2017's profile): 0 below 10 km
  /// and above 40 km, rising linearly to 1 at 25 km and falling linearly; 0 without ozone.
  double OzoneDensity(double altitude) const;
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

  /// Ozone length integral OzoneDensity(h) ds [m] over the segment (as OpticalLength);
  /// 0 without ozone.
  double OzoneOpticalLength(const Vector3& p0, const Vector3& p1) const;

  /// tau(lambda) = beta_R(lambda) L_R + beta_M,ext(lambda) L_M + OzoneAbsorption(lambda) L_O
  /// (dimensionless; ignores hitsGround).
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
