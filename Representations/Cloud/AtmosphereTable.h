// The "atmosphere texture" of 000 §3/§4.1: per height, the atmosphere's density
// rho_atm(h) and the sun attenuation g_sun_atm(h), here folded with the sun's
// spectrum and converted to linear sRGB once on the CPU, so the GPU shaders work
// in RGB with the same physics as the spectral reference: both take the sun, the
// air and the colour conversion from nimbus::SunAndAir (Physics/SunAndAir.h).
//
// Rows (each `Samples` heights, z from ZMin to ZMax in scene metres, linear):
//   0 SunIrradiance   E_sun(z)        = rgb(E(l) T_sun,atm(l, z))                      000 Eq. 7
//   1 RayleighSource  beta_R rho_R E  = rgb(beta_R(l) rho_R(h) E(l) T(l, z))    [1/m]  000 Eq. 5
//   2 MieSource       beta_M rho_M E  = beta_M,s rho_M(h) E_sun(z)              [1/m]  000 Eq. 5
//   3 Extinction      k_atm rho_atm   = beta_R,eff rho_R(h) + beta_M,ext rho_M(h) [1/m] 000 Eq. 6
//   4 AirMultipleSource   = rgb((beta_R(l) rho_R(h) + beta_M,s rho_M(h)) M_ms(l; r, mu_s)) [1/m]
//   5 GroundSkyIrradiance = rgb(E_sky(l; mu_s)), the same in every column
// with h = SceneAltitudeMetres + z. The sun transmittance is that of the spherical
// atmosphere at the point (0, 0, z) (the horizontal offset of a scene of tens of
// km changes the local sun elevation by < 0.5 deg; ignored).
//
// Rows 4 and 5 come from a nimbus::SkyModel of the same air (Physics/Sky.h) and are
// zero without one: M_ms is its isotropic radiance of the scattering orders >= 2
// (Hillaire 2020 §5.5; the mean radiance of orders 1..K-1, which the air scatters
// once more), per unit solid angle, so row 4 is a source per metre with the
// isotropic phase already in it (added without a phase factor, as the sky's own
// view table adds its "Isotropic" part). E_sky is the sky's irradiance on a
// horizontal ground at sea level (r = R), for the ground's radiance a/pi E_sky.
// mu_s is the sun's zenith cosine at (0, 0, z), r = R + SceneAltitudeMetres + z.
// Units: the SkyModel's sun has luminance 1 (its own Planck spectrum
// at SkyParameters::SunTemperatureKelvin); its spectra are scaled per wavelength
// by E_SunAndAir(l) / E_SkyModel(l) (a constant, the sun's illuminance, when the
// temperatures agree) before the same spectrum -> linear sRGB map as rows 0-3.
//
// RGB extinction: the per-channel Rayleigh coefficient is the sun-weighted mean
// beta_R,eff,c = rgb(beta_R E)_c / rgb(E)_c at the top of the atmosphere. This is
// the one RGB approximation of the GPU path; its error is part of the measured
// error against the spectral reference.
#ifndef nimbus_AtmosphereTable_h
#define nimbus_AtmosphereTable_h

#include "NimbusRepresentationsModule.h"
#include "SunAndAir.h"

#include <array>
#include <vector>

namespace nimbus
{
class SkyModel;

struct NIMBUSREPRESENTATIONS_EXPORT AtmosphereTable
{
  static constexpr int kRows = 6;
  int Samples = 0;
  double ZMin = 0.0, ZMax = 0.0; // scene z of the first and last sample [m]
  /// Row-major float RGBA texels: Data[(row * Samples + i) * 4 + c]; alpha = 1.
  std::vector<float> Data;
  /// Sun irradiance above the atmosphere in linear sRGB (used without atmosphere).
  std::array<double, 3> SunIrradianceTop{ { 0.0, 0.0, 0.0 } };
  /// Sea-level coefficients for the analytic view transmittance [1/m].
  std::array<double, 3> RayleighExtinctionSeaLevel{ { 0.0, 0.0, 0.0 } };
  double MieExtinctionSeaLevel = 0.0;
  double MieScatteringSeaLevel = 0.0;
  /// The air the table was built for (scale heights, radii, the scene's altitude).
  SceneAtmosphere Air;
  bool HasAtmosphere = false;
  /// Rows 4 and 5 were filled from a sky model (else they are 0).
  bool HasMultipleScattering = false;
  /// Row 5's value: the sky's irradiance on the ground, linear sRGB (0 without it).
  std::array<double, 3> GroundSkyIrradiance{ { 0.0, 0.0, 0.0 } };

  /// Linear interpolation in z of one row (clamped at the ends), like the GPU's
  /// linear texture filter.
  std::array<double, 3> Lookup(int row, double z) const;
};

/// Builds the table for the sun and air of `sunAndAir` over z in [zMin, zMax] with
/// `samples` >= 2 heights. Without an atmosphere only SunIrradianceTop is filled
/// (Samples = 0). With `multipleScattering` (a sky model of the same air and sun
/// temperature, with the same number of wavelengths as sunAndAir) rows 4 and 5 hold
/// the air's multiple-scattering source and the ground's sky irradiance; without
/// it they are 0. Throws std::invalid_argument for a bad range or sample count or
/// a sky model of another wavelength count.
NIMBUSREPRESENTATIONS_EXPORT AtmosphereTable BuildAtmosphereTable(const SunAndAir& sunAndAir,
  double zMin, double zMax, int samples, const SkyModel* multipleScattering = nullptr);
} // namespace nimbus

#endif
