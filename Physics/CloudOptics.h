// What the values of a density array mean: the extinction coefficient sigma_t [1/m] of a
// cloud from a scalar in the user's units (docs/density-units.md).
//
// Units: extinction in 1/m; liquid and ice water content in g/m^3; mixing ratio in kg/kg;
// effective radius in micrometres; droplet number concentration per cm^3; air density in
// kg/m^3; altitude in metres (geometric, above mean sea level).
//
// The water contents use geometric optics (extinction efficiency Q_ext = 2, droplets and
// crystals much larger than visible wavelengths; Hansen & Travis 1974, Stephens 1978):
//   sigma_t = 3 W / (2 rho_p r_e)
// with W the water content, rho_p the density of the particles' material and r_e the
// effective radius (third over second moment of the size distribution).
//
// Plain C++, no VTK; the ParaView representation calls these functions.
#ifndef nimbus_CloudOptics_h
#define nimbus_CloudOptics_h

#include "NimbusPhysicsExport.h" // for export macro

#include <string>

namespace nimbus
{

/// What the values of a density array mean. The integer values are those of the
/// VTK/ParaView property DensityUnits: keep them.
enum class DensityUnits : int
{
  Dimensionless = 0,          // sigma_t = ExtinctionPerDensity [1/m] * value
  ExtinctionPerMetre = 1,     // the value is sigma_t [1/m]
  LiquidWaterContent = 2,     // g/m^3
  LiquidWaterMixingRatio = 3, // kg/kg (kg of liquid water per kg of air); needs the air's density
  IceWaterContent = 4         // g/m^3, ice optics
};

/// True when value is one of DensityUnits' integer values (0..4).
NIMBUSPHYSICS_EXPORT bool IsDensityUnits(int value);

/// The units in words, for messages: "liquid water content (g/m^3)" etc.;
/// "unknown density units" for a value outside the enumeration.
NIMBUSPHYSICS_EXPORT std::string DensityUnitsName(DensityUnits units);

/// How droplet size is given for the liquid water contents (LiquidWaterContent,
/// LiquidWaterMixingRatio). Ice always uses the effective radius.
enum class DropletSize : int
{
  EffectiveRadius = 0,
  NumberConcentration = 1
};

/// True when value is one of DropletSize's integer values (0, 1).
NIMBUSPHYSICS_EXPORT bool IsDropletSize(int value);

/// Density of liquid water [kg/m^3].
constexpr double kLiquidWaterDensityKgPerCubicMetre = 1000.0;
/// Density of solid ice [kg/m^3] (ice Ih near 0 C).
constexpr double kIceDensityKgPerCubicMetre = 917.0;
/// k = (r_v / r_e)^3, r_v the volume-mean radius, of droplet spectra in maritime air
/// (Martin, Johnson & Spice 1994, J. Atmos. Sci. 51, 1823-1842; the same 0.80 at sea and
/// 0.67 over land are the Met Office Unified Model's KPARAM_SEA / KPARAM_LAND).
constexpr double kMaritimeDropletSpectrumK = 0.80;
/// The same ratio for continental air (Martin, Johnson & Spice 1994).
constexpr double kContinentalDropletSpectrumK = 0.67;

/// The ranges CheckCloudOptics accepts.
constexpr double kMaxEffectiveRadiusMicrometres = 1.0e4;
constexpr double kMaxNumberConcentrationPerCubicCentimetre = 1.0e6;
constexpr double kMaxExtinctionPerDensity = 1.0e6;

/// The optical thickness EstimateExtinctionPerDensity aims at by default: a cumulus of
/// about 450 m of LWC 0.3 g/m^3 and r_e 10 um (0.045 /m x 444 m = 20; docs/density-units.md
/// compares it with observed cumulus).
constexpr double kDefaultTargetOpticalThickness = 20.0;

struct NIMBUSPHYSICS_EXPORT CloudOpticsParameters
{
  DensityUnits Units = DensityUnits::Dimensionless;
  double ExtinctionPerDensity = 0.05; // 1/m per unit value (Dimensionless only)
  DropletSize Size = DropletSize::EffectiveRadius;
  double EffectiveRadiusMicrometres = 10.0; // liquid droplets, and ice crystals
  double NumberConcentrationPerCubicCentimetre = 100.0;
};

/// Validation: an empty string when valid, else a plain-words message naming the bad
/// value. Checks the values the chosen units use: Dimensionless its ExtinctionPerDensity
/// (finite, 0..1e6); the liquid water content and mixing ratio the droplet size choice and
/// then the effective radius (finite, > 0, <= 1e4 um) or the number concentration (finite,
/// > 0, <= 1e6 /cm^3); ice the effective radius; ExtinctionPerMetre nothing. Units or a
/// droplet size outside their enumerations are refused.
NIMBUSPHYSICS_EXPORT std::string CheckCloudOptics(const CloudOpticsParameters& parameters);

/// sigma_t = Coefficient * value^Exponent [1/m] for positive finite values: every choice of
/// units is such a power law (Exponent 1 except the liquid water with a number
/// concentration, 2/3), so a renderer can apply it per voxel (or on the GPU) after
/// computing it once. Coefficient is 0 for parameters CheckCloudOptics refuses (and for a
/// mixing ratio with a non-positive or non-finite air density).
struct NIMBUSPHYSICS_EXPORT ExtinctionLaw
{
  double Coefficient = 0.0; // 1/m per (unit value)^Exponent
  double Exponent = 1.0;
};
NIMBUSPHYSICS_EXPORT ExtinctionLaw ExtinctionLawOf(
  const CloudOpticsParameters& parameters, double airDensityKgPerCubicMetre);
/// The law applied to one value: NaN, +-Inf and values <= 0 give 0; the result is at most
/// the largest float (it goes into float textures).
NIMBUSPHYSICS_EXPORT double ApplyExtinctionLaw(const ExtinctionLaw& law, double value);

/// Extinction [1/m] of one value. airDensityKgPerCubicMetre is used by the mixing ratio
/// only. NaN/Inf in -> 0 out; negative values -> 0; always finite and >= 0.
NIMBUSPHYSICS_EXPORT double ExtinctionPerMetre(
  const CloudOpticsParameters& parameters, double value, double airDensityKgPerCubicMetre);

/// 3 LWC / (2 rho_w r_e): liquid water content [g/m^3], effective radius [um] -> [1/m];
/// rho_w = 1000 kg/m^3. With these units sigma_t = 1.5 LWC / r_e. 0 for LWC <= 0, for a
/// radius that is not > 0, and for non-finite arguments.
NIMBUSPHYSICS_EXPORT double ExtinctionFromLiquidWaterContent(
  double lwcGramsPerCubicMetre, double effectiveRadiusMicrometres);

/// Ice: 3 IWC / (2 rho_i r_e), rho_i = 917 kg/m^3; IWC [g/m^3], r_e [um] -> [1/m]
/// (sigma_t = 1.6358 IWC / r_e). Fu (1996, J. Climate 9, 2058-2082, Eq. 3.9a) fits
/// sigma_t = IWC (a0 + a1 / D_ge) to hexagonal-crystal optics, D_ge [um] his generalised
/// effective size; his 0.2-0.7 um band has a0 = -2.9172e-5 m^2/g, a1 = 2.5193 m^2 um/g
/// (as tabulated in the Fu-Liou radiation code, block data ice1new). With
/// D_ge = r_e / 0.64952 (ECMWF ecRad, radiation_ice_optics_fu.F90; 0.64952 = 3 sqrt(3)/8)
/// Fu's law is IWC (1.6363 / r_e - 2.9e-5): within 0.1 % of this one for r_e of
/// 5..70 um (TestCloudOptics checks it), 0.15 % at 100 um. Same 0-cases as the liquid water.
NIMBUSPHYSICS_EXPORT double ExtinctionFromIceWaterContent(
  double iwcGramsPerCubicMetre, double effectiveRadiusMicrometres);

/// Effective radius [um] from LWC [g/m^3] and droplet number concentration N [1/cm^3]:
/// r_e = (3 LWC / (4 pi rho_w k N))^(1/3), k = (r_v/r_e)^3 = 0.80, Martin, Johnson & Spice
/// 1994's value for maritime air (kMaritimeDropletSpectrumK). 0 for LWC <= 0, for N not
/// > 0 and for non-finite arguments. LWC 0.3 g/m^3, N 100 /cm^3 give 9.64 um.
NIMBUSPHYSICS_EXPORT double EffectiveRadiusFromNumberConcentration(
  double lwcGramsPerCubicMetre, double numberPerCubicCentimetre);

/// The liquid water's extinction with the radius of EffectiveRadiusFromNumberConcentration,
/// written without dividing by it: sigma_t = (3/2) (LWC/rho_w)^(2/3) (4 pi k N / 3)^(1/3)
/// [1/m] (0 where that function gives 0).
NIMBUSPHYSICS_EXPORT double ExtinctionFromLiquidWaterContentAndNumber(
  double lwcGramsPerCubicMetre, double numberPerCubicCentimetre);

/// Liquid water content [g/m^3] of a mixing ratio q [kg/kg] in air of density rho_air
/// [kg/m^3]: LWC = 1000 q rho_air. 0 for non-positive or non-finite arguments.
NIMBUSPHYSICS_EXPORT double LiquidWaterContentFromMixingRatio(
  double mixingRatioKgPerKg, double airDensityKgPerCubicMetre);

/// Temperature [K], pressure [Pa] and density [kg/m^3] of the U.S. Standard Atmosphere 1976
/// (NOAA-S/T 76-1562) at a geometric altitude [m]: its seven layers of constant lapse rate
/// in geopotential height H = r0 Z / (r0 + Z), r0 = 6356.766 km (bases 0, 11, 20, 32, 47,
/// 51, 71 km; lapse rates -6.5, 0, +1, +2.8, 0, -2.8, -2 K/km; 288.15 K and 101325 Pa at
/// sea level), hydrostatic pressure with g0 = 9.80665 m/s^2, M0 = 28.9644 g/mol,
/// R* = 8.31432 J/(mol K), and rho = P M0 / (R* T). The layer laws hold from 0 to 86 km
/// (H = 84.852 km); below 0 the first layer's law is continued down to -5 km (and held
/// there below); above 86 km the air is continued isothermally at 186.946 K (not the 1976
/// model's upper part: 3.4 % too dense at 100 km). A NaN altitude gives sea level.
struct NIMBUSPHYSICS_EXPORT StandardAtmosphereState
{
  double TemperatureKelvin = 288.15;
  double PressurePascals = 101325.0;
  double DensityKgPerCubicMetre = 1.225;
};
NIMBUSPHYSICS_EXPORT StandardAtmosphereState StandardAtmosphere(double altitudeMetres);

/// Dry-air density of the U.S. Standard Atmosphere 1976 [kg/m^3] at a geometric altitude
/// [m] (StandardAtmosphere's density): 1.2250 at 0, 0.73643 at 5 km, 0.36480 at 11 km,
/// 0.088910 at 20 km (the 1976 tables by geometric altitude).
NIMBUSPHYSICS_EXPORT double StandardAtmosphereAirDensity(double altitudeMetres);

/// The one-click estimate for data with no known units: the k [1/m per unit value] that
/// gives the cloud a typical optical thickness along the vertical. The median, over the
/// columns of a (nx, ny, nz) grid (x fastest, z up, spacing dzMetres between points along
/// z) whose column integral is > 0, of tau = k * integral(value dz) equals
/// targetOpticalThickness. The column integral is the trapezoid rule over the points, i.e.
/// the exact integral of the piecewise-linear (trilinearly interpolated) field the renderer
/// marches through. Non-finite and negative values count as 0. Returns 0 when no column has
/// any density (nz < 2 included) or for invalid arguments (null values, sizes < 1, dz or
/// the target not finite and > 0); the result is clamped to 0..kMaxExtinctionPerDensity,
/// the range CheckCloudOptics accepts. Runs on all cores (results independent of their
/// number).
NIMBUSPHYSICS_EXPORT double EstimateExtinctionPerDensity(const float* values, int nx, int ny,
  int nz, double dzMetres, double targetOpticalThickness = kDefaultTargetOpticalThickness);

} // namespace nimbus

#endif
