// The sky: radiance of the clear sky in any direction for a given sun, from
// Rayleigh (molecules) and Mie (aerosols) scattering over a spherical earth with
// exponential densities (002 §2 Eqs. 1-2, 004 §3.5) and ozone absorption, spectral,
// then linear sRGB. The air is by default ClearSkyAtmosphere(T) (Atmosphere.h): the
// aerosol amount from the turbidity T (Preetham et al. 1999), Angstrom exponent 1.3,
// the phase function fitted to the measured aerosol asymmetry, ozone 300 DU; the
// extinction in every equation below is sigma_t = beta_R(lambda) rho_R +
// beta_M,ext(lambda) rho_M + beta_O3(lambda) rho_O3 [1/m]. Validated against Preetham
// et al. 1999 (PreethamSky.h) and the CIE clear sky in TestSky, docs/sky.md.
// Single scattering as in 002 Eq. 1 plus multiple scattering from an iterated
// precomputation in the manner of Bruneton & Neyret 2008 ("Precomputed
// Atmospheric Scattering", EGSR 2008, §4: scattering density -> radiance ->
// next scattering density, order by order), with one stated approximation: the
// scattering density of orders >= 2 is taken isotropic (its angular mean), as
// in Hillaire 2020 ("A Scalable and Production Ready Sky and Atmosphere
// Rendering Technique", EGSR 2020, §5.5). Under that approximation the density
// J_k of every order k >= 2 depends only on (r, mu_s) by the spherical
// symmetry of the atmosphere about the earth-sun axis, so each order is a 2-D
// table instead of Bruneton's 4-D one.
//
// Equations (all spectral, lambda in nm; radiance relative to the sun: the
// top-of-atmosphere solar irradiance E(lambda) is a 5778 K Planck spectrum
// scaled to luminance Y = 1, as in the reference renderer's default scene):
//
//   L(x, w) = p_R(nu) A_R(x, w) + p_M(nu) A_M(x, w) + A_I(x, w)
//   A_R = integral_0^D T(x, x_t) beta_R(lambda) rho_R(h_t) E T_sun(x_t) dt        (002 Eq. 1)
//   A_M = integral_0^D T(x, x_t) beta_M,s rho_M(h_t) E T_sun(x_t) dt              (Mie analogue)
//   A_I = integral_0^D T(x, x_t) sigma_s(x_t, lambda) M_ms(r_t, mu_s,t) dt        (orders >= 2)
//       + T(x, x_g) (a/pi) [E T_sun(x_g) max(0, mu_s,g) + E_sky(mu_s,g)]         (ground, if hit)
//   T(x, y) = exp(-integral sigma_t ds)                                            (002 Eq. 2)
//   nu = dot(w, s) (cosine of the scattering angle, the reference renderer's
//   convention), p_R / p_M the Rayleigh / Cornette-Shanks phase functions (1/sr).
//
// The phase functions do not depend on the wavelength and nu is constant along
// a straight ray (sun at infinity), so p_R and p_M factor out of the integrals
// and out of the linear spectrum -> sRGB map: the LUTs store the smooth A_R,
// A_M, A_I (no Mie peak to resolve) and the phase is applied per pixel, exactly.
//
// Multiple scattering (orders 2..K, K = ScatteringOrders):
//   M_k(r, mu_s) = (1/4 pi) integral_sphere L_k(x, w) dw       (mean radiance of order k)
//   E_k(mu_s)    = integral_upper L_k(x_ground, w) cos dw      (sky irradiance of the ground)
//   L_1 = single scattering + sun reflected by the ground;
//   L_k = integral T sigma_s M_{k-1} dt + T_g (a/pi) E_{k-1}   (k >= 2)
//   M_ms = sum_{k=1}^{K-1} M_k, E_sky = sum_{k=1}^{K-1} E_k.
//
// Look-up tables (all node-centred: node i of n sits at x = i/(n-1)):
//  - transmittance: optical lengths L_R, L_M, L_O (m, wavelength independent, so any
//    wavelength count shares it) to the top of the atmosphere by (x_mu, x_r),
//    Bruneton 2017's horizon-aware parametrisation (x_r = rho/H,
//    x_mu = (d - d_min)/(d_max - d_min)); valid for rays that do not hit the ground.
//  - multiple scattering: M_ms(lambda) by (x_r, x_mus), x_mus = 0.5 + 0.5 sign(mu_s) sqrt|mu_s|.
//  - sky view (per sun elevation and observer altitude): A_R, A_M, A_I in linear
//    sRGB by (azimuth from the sun in [0, pi], view zenith angle), the rows split
//    at the observer's horizon (no row straddles it, so no interpolation across
//    it); above it row s in [0,1] has zenith theta_h (1 - s^3) (rows crowd at the
//    horizon, where the sky changes fastest: measured better than s^2), below it
//    theta_h + s^3 (pi - theta_h).
//  - aerial perspective (per sun elevation and camera altitude): A_R, A_M, A_I and
//    the transmittance (rgb) from the camera to distance d, same directions, d sqrt-spaced.
//
// Units: metres, 1/m, nm; positions relative to the earth centre unless stated.
#ifndef nimbus_Sky_h
#define nimbus_Sky_h

#include "Math.h"
#include "NimbusPhysicsExport.h" // for export macro

#include "Atmosphere.h"
#include "PreethamSky.h" // PreethamZenithLuminance (declared here before)
#include "SpectralColor.h"
#include "Sun.h"

#include <array>
#include <memory>
#include <vector>

namespace nimbus
{

struct NIMBUSPHYSICS_EXPORT SkyParameters
{
  /// The air: by default the clear sky of turbidity kDefaultTurbidity (Atmosphere.h,
  /// ClearSkyAtmosphere: aerosol from the turbidity with Angstrom exponent 1.3, the
  /// measured-aerosol phase function, ozone 300 DU).
  AtmosphereParameters Atmosphere = ClearSkyAtmosphere(kDefaultTurbidity);
  double GroundAlbedo = 0.3;            // grey Lambertian albedo of the earth's surface, [0, 1]
  int ScatteringOrders = 4;             // K >= 1; 1 = single scattering only
  int Wavelengths = 16;                 // spectral samples (SpectralSamples; >= 8 uses the spline)
  double SunTemperatureKelvin = 5778.0; // blackbody spectrum of the sun
  // Table sizes (nodes).
  int TransmittanceMuSize = 256;
  int TransmittanceRSize = 64;
  int ScatteringMuSSize = 32;
  int ScatteringRSize = 16;
  int ScatteringZenithDirections = 16; // Gauss-Legendre nodes in cos(zenith)
  int ScatteringAzimuthDirections = 8; // midpoint nodes in azimuth over [0, pi]
  int ScatteringSteps = 24;            // ray-march steps of the multiple-scattering rays
  int ViewSteps = 64;                  // ray-march steps of sky-view rays
  int Threads = 0;                     // 0 = hardware concurrency
};

/// Spectral radiance parts along one ray (size = number of wavelengths); the
/// radiance is p_R(nu) Rayleigh + p_M(nu) Mie + Isotropic.
struct NIMBUSPHYSICS_EXPORT SkySpectra
{
  std::vector<double> Rayleigh, Mie, Isotropic;
  std::vector<double> Transmittance; // T(x, end of the ray) (to the ground point if it hits it)
};

/// Linear-sRGB radiance parts (same meaning as SkySpectra, after the spectrum -> sRGB map).
struct NIMBUSPHYSICS_EXPORT SkyRgbParts
{
  std::array<double, 3> Rayleigh{ { 0, 0, 0 } }, Mie{ { 0, 0, 0 } }, Isotropic{ { 0, 0, 0 } };
};

/// The atmosphere-dependent tables: transmittance and multiple scattering. They do
/// not depend on the sun or the observer; build once per atmosphere.
class NIMBUSPHYSICS_EXPORT SkyModel
{
public:
  using Vector3 = nimbus::Vector3;

  /// Builds the tables. Throws std::invalid_argument for bad parameters (message
  /// names the field).
  explicit SkyModel(const SkyParameters& parameters = SkyParameters());
  ~SkyModel();
  SkyModel(const SkyModel&) = delete;
  SkyModel& operator=(const SkyModel&) = delete;

  const SkyParameters& GetParameters() const { return this->Parameters; }
  const Atmosphere& GetAtmosphere() const { return *this->Air; }
  const SpectralSamples& GetSpectrum() const { return *this->Spectrum; }
  /// E(lambda) at the wavelength samples (Y = 1).
  const std::vector<double>& GetSunIrradiance() const { return this->SunIrradiance; }
  /// Seconds spent building the tables.
  double GetBuildSeconds() const { return this->BuildSeconds; }

  // --- geometry (r: distance to the earth centre, mu: cos of the zenith angle)
  double DistanceToTop(double r, double mu) const;
  double DistanceToGround(double r, double mu) const;
  bool RayHitsGround(double r, double mu) const;
  /// cos of the zenith angle of the horizon seen from r (<= 0; 0 at r <= R).
  double HorizonMu(double r) const;

  // --- transmittance table
  /// Optical lengths (L_R, L_M, L_O: Rayleigh, Mie, ozone) in m to the top of the
  /// atmosphere from radius r along a direction with zenith cosine mu, bilinear in
  /// the table (r clamped to [R, R_top]; mu clamped to the horizon from above).
  std::array<double, 3> LookupOpticalLengths(double r, double mu) const;
  /// The same, exact (Atmosphere::OpticalLengthsToTop), for tests.
  std::array<double, 3> ExactOpticalLengths(double r, double mu) const;
  /// Spectral transmittance toward the sun from radius r, sun zenith cosine mu_s
  /// (0 where the earth blocks it).
  void SunTransmittance(double r, double muS, double* transmittance) const;
  int GetTransmittanceMuSize() const { return this->Parameters.TransmittanceMuSize; }
  int GetTransmittanceRSize() const { return this->Parameters.TransmittanceRSize; }
  /// [x_r][x_mu][3] (L_R, L_M, L_O in m), node-centred.
  const std::vector<float>& GetTransmittanceTable() const { return this->TransmittanceTable; }

  // --- multiple-scattering table
  /// M_ms(r, mu_s) per wavelength (mean radiance of orders 1..K-1), bilinear.
  void LookupMultipleScattering(double r, double muS, double* meanRadiance) const;
  /// E_sky(mu_s) per wavelength: sky irradiance of the ground (orders 1..K-1).
  void LookupGroundSkyIrradiance(double muS, double* irradiance) const;
  /// Per order k = 1..K-1: the spectrally averaged mean radiance M_k at (R, mu_s) [tests].
  std::vector<double> OrderMeanRadiance(double muS) const;
  int GetScatteringMuSSize() const { return this->Parameters.ScatteringMuSSize; }
  int GetScatteringRSize() const { return this->Parameters.ScatteringRSize; }
  /// [x_r][x_mus][wavelength] spectral M_ms, node-centred.
  const std::vector<float>& GetMultipleScatteringTable() const { return this->MultipleTable; }
  /// [x_mus][wavelength] spectral E_sky at the ground, node-centred.
  const std::vector<float>& GetGroundSkyTable() const { return this->GroundSkyTable; }
  /// Same table converted to linear sRGB: [x_r][x_mus][3] (for RGB GPU code).
  std::vector<float> GetMultipleScatteringTableRgb() const;

  // --- radiance along rays
  /// Integrates the parts of L along the ray from x (earth-centred) in unit
  /// direction w for the sun direction s (unit), up to the top of the atmosphere
  /// or the ground, or up to maxDistance (m) if smaller (then no ground term).
  /// steps: ray-march steps (0 = ViewSteps). includeMultiple: add the orders >= 2
  /// and the ground's sky-lit term (else single scattering and the sunlit ground).
  /// exactSunTransmittance: use Atmosphere's exact optical lengths instead of the
  /// table (tests).
  SkySpectra IntegrateRay(const Vector3& x, const Vector3& w, const Vector3& s, double maxDistance,
    int steps, bool includeMultiple, bool exactSunTransmittance = false) const;
  /// Linear sRGB radiance toward an observer at altitude h (m) looking along the
  /// unit direction w (local frame: z up), sun direction s (local frame).
  std::array<double, 3> Radiance(double altitude, const Vector3& w, const Vector3& s,
    bool includeMultiple = true, int steps = 0) const;
  /// Spectral -> linear sRGB of the parts.
  SkyRgbParts ToRgb(const SkySpectra& spectra) const;
  /// Transmittance "colour": linear sRGB of E T divided per channel by that of E
  /// (the sun's spectrum through the path), dimensionless.
  std::array<double, 3> TransmittanceRgb(const std::vector<double>& transmittance) const;

  /// Aerial perspective between p0 (camera) and p1 (point), earth-centred, sun
  /// direction s: transmittance (rgb, see TransmittanceRgb) and in-scattered
  /// radiance (rgb, all orders) along the segment. steps = 0: ViewSteps.
  void AerialPerspective(const Vector3& p0, const Vector3& p1, const Vector3& s,
    std::array<double, 3>& transmittance, std::array<double, 3>& inscatter, int steps = 0) const;

  /// 002 Eq. 1 / Rayleigh + Cornette-Shanks phase.
  double RayleighPhase(double nu) const;
  double MiePhase(double nu) const;

  /// How a ray treats the ground: decide from the geometry, or force (the sky-view
  /// rows at the exact horizon are tangent rays and must stay on their side).
  enum class GroundMode
  {
    Automatic,
    Miss,
    Hit
  };
  /// What a march integrates (internal, public for the LUT builders).
  struct MarchOptions
  {
    int Steps = 0;                                 // 0 = ViewSteps
    double MaxDistance = -1.0;                     // < 0: to the end of the ray
    bool Single = true;                            // Rayleigh and Mie parts of single scattering
    bool GroundDirect = true;                      // sunlit ground (order 1)
    const std::vector<float>* Source = nullptr;    // isotropic source table [x_r][x_mus][lambda]
    const std::vector<float>* GroundSky = nullptr; // ground sky irradiance [x_mus][lambda]
    bool ExactSun = false;
    GroundMode Ground = GroundMode::Automatic;
    /// Called after each step with (distance reached, accumulated spectra) when set.
    const std::vector<double>* RecordAt = nullptr; // sorted distances to record at
    std::vector<SkySpectra>* Records = nullptr;
  };
  SkySpectra March(
    const Vector3& x, const Vector3& w, const Vector3& s, const MarchOptions& options) const;

private:
  void BuildTransmittance();
  void BuildMultipleScattering();
  void LookupTable(const std::vector<float>& table, double r, double muS, double* out) const;
  void LookupGround(const std::vector<float>& table, double muS, double* out) const;

  SkyParameters Parameters;
  std::unique_ptr<Atmosphere> Air;
  std::unique_ptr<SpectralSamples> Spectrum;
  std::vector<double> SunIrradiance;
  std::vector<double> BetaRayleigh; // per wavelength, 1/m
  // Per wavelength, 1/m at sea level (Mie) or at the ozone layer's peak (ozone).
  std::vector<double> BetaMieScattering, BetaMieExtinction, BetaOzone;
  std::vector<float> TransmittanceTable;
  std::vector<float> MultipleTable;            // M_ms
  std::vector<float> GroundSkyTable;           // E_sky by x_mus (r = R)
  std::vector<std::vector<double>> OrderMeans; // per order: spectral mean of M_k at r = R by x_mus
  double BuildSeconds = 0.0;
};

/// Maps of the sky-view rows: view zenith angle <-> row coordinate, split at the horizon.
struct NIMBUSPHYSICS_EXPORT SkyViewMapping
{
  int Width = 64;             // azimuth nodes over [0, pi]
  int AboveRows = 64;         // rows from the horizon (row 0) up to the zenith
  int BelowRows = 32;         // rows from the horizon down to the nadir
  double HorizonZenith = 0.0; // zenith angle of the horizon [rad], >= pi/2

  /// Continuous row coordinate in [0, AboveRows - 1] (above) or
  /// [AboveRows, AboveRows + BelowRows - 1] (below) of a view zenith angle.
  double Row(double zenith) const;
  double ZenithOfRow(int row) const;
  int Rows() const { return this->AboveRows + this->BelowRows; }
  /// Continuous (column, row) of unit view direction w (local frame) when the sun
  /// is at azimuth sunAzimuthDegrees: the column is the azimuth from the sun in
  /// [0, pi] over [0, Width - 1], the row Row(zenith).
  void Texel(const Vector3& w, double sunAzimuthDegrees, double& column, double& row) const;
};

/// Sky radiance parts for one sun elevation and one observer altitude, by view
/// direction relative to the sun (002 §2's look-up table). Rebuild when the sun's
/// elevation, the altitude or the atmosphere change; the sun's azimuth only rotates it.
class NIMBUSPHYSICS_EXPORT SkyViewLut
{
public:
  using Vector3 = nimbus::Vector3;
  /// Default size 128 x (64 + 32): measured against the reference renderer, see TestSky
  /// and docs/sky.md (64 columns double the twilight error at the earth's shadow edge).
  SkyViewLut(const SkyModel& model, double sunElevationDeg, double observerAltitude,
    int width = 128, int aboveRows = 64, int belowRows = 32, bool includeMultiple = true);

  /// Linear sRGB radiance for unit view direction w, local frame with the sun at
  /// azimuth sunAzimuthDeg (bilinear in the table, phase applied exactly).
  std::array<double, 3> Radiance(const Vector3& w, double sunAzimuthDeg) const;
  /// Parts for w (same frame).
  SkyRgbParts Parts(const Vector3& w, double sunAzimuthDeg) const;

  const SkyViewMapping& GetMapping() const { return this->Mapping; }
  double GetSunElevationDegrees() const { return this->SunElevationDegrees; }
  double GetObserverAltitude() const { return this->ObserverAltitude; }
  /// [component (Rayleigh, Mie, Isotropic)][row][column][rgb], linear sRGB floats.
  const std::vector<float>& GetTable() const { return this->Table; }
  double GetBuildSeconds() const { return this->BuildSeconds; }

private:
  const SkyModel& Model;
  SkyViewMapping Mapping;
  double SunElevationDegrees;
  double ObserverAltitude;
  std::vector<float> Table;
  double BuildSeconds = 0.0;
};

/// Aerial perspective for a camera at one altitude and one sun elevation: the
/// parts of the in-scattered radiance and the transmittance from the camera to
/// distance d along every direction (Hillaire 2020's aerial-perspective volume,
/// but in world directions, so moving the camera horizontally or turning it does
/// not rebuild it).
class NIMBUSPHYSICS_EXPORT AerialPerspectiveLut
{
public:
  using Vector3 = nimbus::Vector3;
  AerialPerspectiveLut(const SkyModel& model, double sunElevationDeg, double cameraAltitude,
    double maxDistance = 100000.0, int width = 32, int aboveRows = 32, int belowRows = 32,
    int slices = 32);

  /// For unit direction w (local frame, sun azimuth sunAzimuthDeg) and distance d
  /// (m, clamped to the table's range): transmittance rgb and in-scattered rgb.
  void Lookup(const Vector3& w, double distance, double sunAzimuthDeg,
    std::array<double, 3>& transmittance, std::array<double, 3>& inscatter) const;

  const SkyViewMapping& GetMapping() const { return this->Mapping; }
  int GetSlices() const { return this->Slices; }
  double GetMaxDistance() const { return this->MaxDistance; }
  /// [slice][row][column][12] = Rayleigh rgb, Mie rgb, Isotropic rgb, transmittance rgb.
  const std::vector<float>& GetTable() const { return this->Table; }
  double GetBuildSeconds() const { return this->BuildSeconds; }

private:
  SkyViewMapping Mapping;
  const SkyModel& Model;
  int Slices;
  double MaxDistance;
  double SunElevationDegrees;
  std::vector<float> Table;
  double BuildSeconds = 0.0;
};

/// Relative luminance Y of linear sRGB (row 2 of the sRGB -> XYZ matrix).
NIMBUSPHYSICS_EXPORT double LinearSrgbLuminance(const std::array<double, 3>& rgb);

} // namespace nimbus

#endif
