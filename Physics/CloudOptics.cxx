// What the values of a density array mean (CloudOptics.h, docs/density-units.md).
#include "CloudOptics.h"

#include "ParallelFor.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <sstream>
#include <vector>

namespace nimbus
{
namespace
{

constexpr double kPi = 3.14159265358979323846;
constexpr double kMetresPerMicrometre = 1.0e-6;
constexpr double kKilogramsPerGram = 1.0e-3;
constexpr double kCubicMetresPerCubicCentimetre = 1.0e-6;
constexpr double kLargestFloat = static_cast<double>(std::numeric_limits<float>::max());

bool Positive(double x)
{
  return std::isfinite(x) && x > 0.0;
}

// x clamped to [0, largest float]; NaN -> 0.
double FiniteNonNegative(double x)
{
  if (!(x > 0.0))
  {
    return 0.0;
  }
  return std::min(x, kLargestFloat);
}

std::string Number(double x)
{
  std::ostringstream out;
  out << x;
  return out.str();
}

// Geometric optics: sigma_t = 3 W / (2 rho r_e) [1/m] with W in g/m^3 and r_e in um.
double GeometricOpticsExtinction(
  double waterGramsPerCubicMetre, double radiusMicrometres, double particleDensityKgPerCubicMetre)
{
  if (!Positive(waterGramsPerCubicMetre) || !Positive(radiusMicrometres))
  {
    return 0.0;
  }
  const double coefficient = 1.5 * kKilogramsPerGram /
    (particleDensityKgPerCubicMetre * radiusMicrometres * kMetresPerMicrometre);
  return FiniteNonNegative(coefficient * waterGramsPerCubicMetre);
}

// sigma_t [1/m] per (LWC [g/m^3])^(2/3) for N droplets per cm^3:
// (3/2) (1e-3 / rho_w)^(2/3) (4 pi k N 1e6 / 3)^(1/3).
double LiquidCoefficientFromNumber(double numberPerCubicCentimetre)
{
  if (!Positive(numberPerCubicCentimetre))
  {
    return 0.0;
  }
  const double perCubicMetre = numberPerCubicCentimetre / kCubicMetresPerCubicCentimetre;
  return 1.5 * std::cbrt(std::pow(kKilogramsPerGram / kLiquidWaterDensityKgPerCubicMetre, 2.0)) *
    std::cbrt(4.0 * kPi * kMaritimeDropletSpectrumK * perCubicMetre / 3.0);
}

// The law for liquid water given as a content in g/m^3.
ExtinctionLaw LiquidWaterLaw(const CloudOpticsParameters& parameters)
{
  ExtinctionLaw law;
  if (parameters.Size == DropletSize::NumberConcentration)
  {
    law.Exponent = 2.0 / 3.0;
    law.Coefficient = LiquidCoefficientFromNumber(parameters.NumberConcentrationPerCubicCentimetre);
  }
  else
  {
    law.Coefficient = ExtinctionFromLiquidWaterContent(1.0, parameters.EffectiveRadiusMicrometres);
  }
  return law;
}

std::string CheckRadius(double radiusMicrometres)
{
  if (!(std::isfinite(radiusMicrometres) && radiusMicrometres > 0.0 &&
        radiusMicrometres <= kMaxEffectiveRadiusMicrometres))
  {
    return "the effective radius must be a number greater than 0 and at most " +
      Number(kMaxEffectiveRadiusMicrometres) + " micrometres, not " + Number(radiusMicrometres);
  }
  return std::string();
}

std::string CheckDropletSize(const CloudOpticsParameters& parameters)
{
  if (!IsDropletSize(static_cast<int>(parameters.Size)))
  {
    return "the droplet size choice " + Number(static_cast<int>(parameters.Size)) +
      " is neither 0 (effective radius) nor 1 (number concentration)";
  }
  if (parameters.Size == DropletSize::EffectiveRadius)
  {
    return CheckRadius(parameters.EffectiveRadiusMicrometres);
  }
  const double n = parameters.NumberConcentrationPerCubicCentimetre;
  if (!(std::isfinite(n) && n > 0.0 && n <= kMaxNumberConcentrationPerCubicCentimetre))
  {
    return "the droplet number concentration must be a number greater than 0 and at most " +
      Number(kMaxNumberConcentrationPerCubicCentimetre) + " per cm^3, not " + Number(n);
  }
  return std::string();
}

// U.S. Standard Atmosphere 1976: constants and the seven layers below 84.852 km geopotential.
constexpr double kEarthRadiusMetres = 6356766.0;     // r0
constexpr double kStandardGravity = 9.80665;         // g0 [m/s^2]
constexpr double kAirMolarMass = 0.0289644;          // M0 [kg/mol]
constexpr double kGasConstant = 8.31432;             // R* [J/(mol K)]
constexpr double kTopGeopotentialMetres = 84852.0;   // H at Z = 86 km
constexpr double kLowestGeometricAltitude = -5000.0; // the first layer's law continued
struct AtmosphereLayer
{
  double BaseGeopotentialMetres;
  double LapseRateKelvinPerMetre;
};
constexpr AtmosphereLayer kLayers[] = { { 0.0, -0.0065 }, { 11000.0, 0.0 }, { 20000.0, 0.001 },
  { 32000.0, 0.0028 }, { 47000.0, 0.0 }, { 51000.0, -0.0028 }, { 71000.0, -0.002 } };
constexpr int kLayerCount = static_cast<int>(sizeof(kLayers) / sizeof(kLayers[0]));

// Temperature and pressure after rising dH in a layer of lapse rate L from (T, P):
// hydrostatic equilibrium of an ideal gas, dP/dH = -g0 M0 P / (R* T).
void RiseThroughLayer(double lapseRate, double dH, double& temperature, double& pressure)
{
  const double beta = kStandardGravity * kAirMolarMass / kGasConstant; // K/m
  if (lapseRate == 0.0)
  {
    pressure *= std::exp(-beta * dH / temperature);
    return;
  }
  const double top = temperature + lapseRate * dH;
  pressure *= std::pow(temperature / top, beta / lapseRate);
  temperature = top;
}

} // namespace

bool IsDensityUnits(int value)
{
  return value >= static_cast<int>(DensityUnits::Dimensionless) &&
    value <= static_cast<int>(DensityUnits::IceWaterContent);
}

std::string DensityUnitsName(DensityUnits units)
{
  switch (units)
  {
    case DensityUnits::Dimensionless:
      return "dimensionless density (times the extinction per density)";
    case DensityUnits::ExtinctionPerMetre:
      return "extinction coefficient (1/m)";
    case DensityUnits::LiquidWaterContent:
      return "liquid water content (g/m^3)";
    case DensityUnits::LiquidWaterMixingRatio:
      return "liquid water mixing ratio (kg/kg)";
    case DensityUnits::IceWaterContent:
      return "ice water content (g/m^3)";
  }
  return "unknown density units";
}

bool IsDropletSize(int value)
{
  return value == static_cast<int>(DropletSize::EffectiveRadius) ||
    value == static_cast<int>(DropletSize::NumberConcentration);
}

std::string CheckCloudOptics(const CloudOpticsParameters& parameters)
{
  switch (parameters.Units)
  {
    case DensityUnits::Dimensionless:
    {
      const double k = parameters.ExtinctionPerDensity;
      if (!(std::isfinite(k) && k >= 0.0 && k <= kMaxExtinctionPerDensity))
      {
        return "the extinction per density must be a number from 0 to " +
          Number(kMaxExtinctionPerDensity) + " per metre, not " + Number(k);
      }
      return std::string();
    }
    case DensityUnits::ExtinctionPerMetre:
      return std::string();
    case DensityUnits::LiquidWaterContent:
    case DensityUnits::LiquidWaterMixingRatio:
      return CheckDropletSize(parameters);
    case DensityUnits::IceWaterContent:
      return CheckRadius(parameters.EffectiveRadiusMicrometres);
  }
  return "the density units " + Number(static_cast<int>(parameters.Units)) +
    " are not one of 0 (dimensionless), 1 (extinction per metre), 2 (liquid water content), "
    "3 (liquid water mixing ratio), 4 (ice water content)";
}

ExtinctionLaw ExtinctionLawOf(
  const CloudOpticsParameters& parameters, double airDensityKgPerCubicMetre)
{
  ExtinctionLaw law;
  if (!CheckCloudOptics(parameters).empty())
  {
    return law; // Coefficient 0
  }
  switch (parameters.Units)
  {
    case DensityUnits::Dimensionless:
      law.Coefficient = parameters.ExtinctionPerDensity;
      break;
    case DensityUnits::ExtinctionPerMetre:
      law.Coefficient = 1.0;
      break;
    case DensityUnits::LiquidWaterContent:
      law = LiquidWaterLaw(parameters);
      break;
    case DensityUnits::LiquidWaterMixingRatio:
    {
      // LWC = 1000 q rho_air, so sigma_t = c (1000 rho_air)^e q^e.
      law = LiquidWaterLaw(parameters);
      const double gramsPerCubicMetrePerUnit =
        Positive(airDensityKgPerCubicMetre) ? 1.0e3 * airDensityKgPerCubicMetre : 0.0;
      law.Coefficient =
        FiniteNonNegative(law.Coefficient * std::pow(gramsPerCubicMetrePerUnit, law.Exponent));
      break;
    }
    case DensityUnits::IceWaterContent:
      law.Coefficient = ExtinctionFromIceWaterContent(1.0, parameters.EffectiveRadiusMicrometres);
      break;
  }
  return law;
}

double ApplyExtinctionLaw(const ExtinctionLaw& law, double value)
{
  if (!Positive(value) || !Positive(law.Coefficient))
  {
    return 0.0;
  }
  const double power = law.Exponent == 1.0 ? value : std::pow(value, law.Exponent);
  return FiniteNonNegative(law.Coefficient * power);
}

double ExtinctionPerMetre(
  const CloudOpticsParameters& parameters, double value, double airDensityKgPerCubicMetre)
{
  return ApplyExtinctionLaw(ExtinctionLawOf(parameters, airDensityKgPerCubicMetre), value);
}

double ExtinctionFromLiquidWaterContent(
  double lwcGramsPerCubicMetre, double effectiveRadiusMicrometres)
{
  return GeometricOpticsExtinction(
    lwcGramsPerCubicMetre, effectiveRadiusMicrometres, kLiquidWaterDensityKgPerCubicMetre);
}

double ExtinctionFromIceWaterContent(
  double iwcGramsPerCubicMetre, double effectiveRadiusMicrometres)
{
  return GeometricOpticsExtinction(
    iwcGramsPerCubicMetre, effectiveRadiusMicrometres, kIceDensityKgPerCubicMetre);
}

double EffectiveRadiusFromNumberConcentration(
  double lwcGramsPerCubicMetre, double numberPerCubicCentimetre)
{
  if (!Positive(lwcGramsPerCubicMetre) || !Positive(numberPerCubicCentimetre))
  {
    return 0.0;
  }
  // Volume of water per droplet [m^3] = (4/3) pi r_v^3 = (4/3) pi k r_e^3.
  const double waterVolumeFraction =
    lwcGramsPerCubicMetre * kKilogramsPerGram / kLiquidWaterDensityKgPerCubicMetre;
  const double perCubicMetre = numberPerCubicCentimetre / kCubicMetresPerCubicCentimetre;
  const double radiusMetres =
    std::cbrt(3.0 * waterVolumeFraction / (4.0 * kPi * kMaritimeDropletSpectrumK * perCubicMetre));
  return FiniteNonNegative(radiusMetres / kMetresPerMicrometre);
}

double ExtinctionFromLiquidWaterContentAndNumber(
  double lwcGramsPerCubicMetre, double numberPerCubicCentimetre)
{
  if (!Positive(lwcGramsPerCubicMetre))
  {
    return 0.0;
  }
  const double coefficient = LiquidCoefficientFromNumber(numberPerCubicCentimetre);
  return FiniteNonNegative(coefficient * std::cbrt(lwcGramsPerCubicMetre * lwcGramsPerCubicMetre));
}

double LiquidWaterContentFromMixingRatio(
  double mixingRatioKgPerKg, double airDensityKgPerCubicMetre)
{
  if (!Positive(mixingRatioKgPerKg) || !Positive(airDensityKgPerCubicMetre))
  {
    return 0.0;
  }
  return FiniteNonNegative(1.0e3 * mixingRatioKgPerKg * airDensityKgPerCubicMetre);
}

StandardAtmosphereState StandardAtmosphere(double altitudeMetres)
{
  StandardAtmosphereState state; // sea level
  if (std::isnan(altitudeMetres))
  {
    return state;
  }
  const double z = std::max(altitudeMetres, kLowestGeometricAltitude);
  // Geopotential height; r0 as Z -> +infinity.
  const double h =
    std::isinf(z) ? kEarthRadiusMetres : kEarthRadiusMetres * z / (kEarthRadiusMetres + z);
  double temperature = 288.15;
  double pressure = 101325.0;
  for (int i = 0; i < kLayerCount; ++i)
  {
    const double base = kLayers[i].BaseGeopotentialMetres;
    const double top =
      i + 1 < kLayerCount ? kLayers[i + 1].BaseGeopotentialMetres : kTopGeopotentialMetres;
    // The first layer also runs below its base (down to -5 km).
    const double end = std::min(h, top);
    RiseThroughLayer(kLayers[i].LapseRateKelvinPerMetre, end - base, temperature, pressure);
    if (h <= top)
    {
      break;
    }
  }
  if (h > kTopGeopotentialMetres)
  {
    RiseThroughLayer(0.0, h - kTopGeopotentialMetres, temperature, pressure);
  }
  state.TemperatureKelvin = temperature;
  state.PressurePascals = pressure;
  state.DensityKgPerCubicMetre = pressure * kAirMolarMass / (kGasConstant * temperature);
  return state;
}

double StandardAtmosphereAirDensity(double altitudeMetres)
{
  return StandardAtmosphere(altitudeMetres).DensityKgPerCubicMetre;
}

double EstimateExtinctionPerDensity(
  const float* values, int nx, int ny, int nz, double dzMetres, double targetOpticalThickness)
{
  if (values == nullptr || nx < 1 || ny < 1 || nz < 2 || !Positive(dzMetres) ||
    !Positive(targetOpticalThickness))
  {
    return 0.0;
  }
  const std::size_t rowLength = static_cast<std::size_t>(nx);
  const std::size_t sliceSize = rowLength * static_cast<std::size_t>(ny);
  // Column integrals by the trapezoid rule: weight dz inside, dz/2 at the two ends.
  std::vector<double> integrals(sliceSize, 0.0);
  const std::size_t rows = static_cast<std::size_t>(ny);
  const int threads = ResolveThreadCount(0);
  const std::size_t grain =
    std::max<std::size_t>(1, rows / (4 * static_cast<std::size_t>(threads)));
  ParallelFor(rows, grain, threads,
    [&](std::size_t begin, std::size_t end)
    {
      for (std::size_t j = begin; j < end; ++j)
      {
        double* column = integrals.data() + j * rowLength;
        for (int k = 0; k < nz; ++k)
        {
          const double weight = (k == 0 || k == nz - 1) ? 0.5 * dzMetres : dzMetres;
          const float* row = values + static_cast<std::size_t>(k) * sliceSize + j * rowLength;
          for (std::size_t i = 0; i < rowLength; ++i)
          {
            const double v = row[i];
            if (v > 0.0 && std::isfinite(v))
            {
              column[i] += weight * v;
            }
          }
        }
      }
    });
  std::vector<double> positive;
  for (const double integral : integrals)
  {
    if (integral > 0.0) // +Inf (float overflow) included: it counts as a very dense column
    {
      positive.push_back(integral);
    }
  }
  if (positive.empty())
  {
    return 0.0;
  }
  const std::size_t n = positive.size();
  const auto middle = positive.begin() + static_cast<std::ptrdiff_t>(n / 2);
  std::nth_element(positive.begin(), middle, positive.end());
  double median = *middle;
  if (n % 2 == 0)
  {
    median = 0.5 * (median + *std::max_element(positive.begin(), middle));
  }
  const double k = targetOpticalThickness / median;
  if (!(k > 0.0))
  {
    return 0.0; // median infinite
  }
  return std::min(k, kMaxExtinctionPerDensity);
}

} // namespace nimbus
