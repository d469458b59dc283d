#include "AtmosphereTable.h"

#include "Sky.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace nimbus
{

std::array<double, 3> AtmosphereTable::Lookup(int row, double z) const
{
  std::array<double, 3> value{ { 0.0, 0.0, 0.0 } };
  if (this->Samples < 2 || row < 0 || row >= kRows)
  {
    return value;
  }
  const double x =
    std::clamp((z - this->ZMin) / (this->ZMax - this->ZMin), 0.0, 1.0) * (this->Samples - 1);
  const int i0 = std::min(static_cast<int>(x), this->Samples - 2);
  const double f = x - i0;
  for (int c = 0; c < 3; ++c)
  {
    const float a = this->Data[(row * this->Samples + i0) * 4 + c];
    const float b = this->Data[(row * this->Samples + i0 + 1) * 4 + c];
    value[c] = (1.0 - f) * a + f * b;
  }
  return value;
}

AtmosphereTable BuildAtmosphereTable(const SunAndAir& sunAndAir, double zMin, double zMax,
  int samples, const SkyModel* multipleScattering)
{
  if (!std::isfinite(zMin) || !std::isfinite(zMax) || !(zMax > zMin) || samples < 2)
  {
    throw std::invalid_argument("atmosphere table needs zMax > zMin (finite) and >= 2 samples");
  }
  if (multipleScattering &&
    multipleScattering->GetSunIrradiance().size() != sunAndAir.GetSunIrradiance().size())
  {
    throw std::invalid_argument(
      "atmosphere table: the sky model must have the sun and air's wavelength count");
  }
  AtmosphereTable table;
  const std::vector<double>& sun = sunAndAir.GetSunIrradiance();
  const std::array<double, 3> sunTop = sunAndAir.ToLinearSrgb(sun);
  for (int c = 0; c < 3; ++c)
  {
    // Out of gamut (a cool sun) gives a negative channel: clipped, see put() below.
    table.SunIrradianceTop[c] = std::max(sunTop[c], 0.0);
  }
  table.Air = sunAndAir.GetSceneAtmosphere();
  if (!sunAndAir.HasAtmosphere())
  {
    return table;
  }
  table.HasAtmosphere = true;
  const SceneAtmosphere& air = table.Air;
  table.MieScatteringSeaLevel = sunAndAir.GetMieScatteringSeaLevel();
  table.MieExtinctionSeaLevel = sunAndAir.GetMieExtinctionSeaLevel();
  const std::vector<double>& betaR = sunAndAir.GetRayleighScatteringSeaLevel();
  const std::size_t n = sun.size();
  std::vector<double> spectrum(n);
  for (std::size_t k = 0; k < n; ++k)
  {
    spectrum[k] = betaR[k] * sun[k];
  }
  const std::array<double, 3> weightedBeta = sunAndAir.ToLinearSrgb(spectrum);
  for (int c = 0; c < 3; ++c)
  {
    table.RayleighExtinctionSeaLevel[c] =
      table.SunIrradianceTop[c] > 0.0 ? weightedBeta[c] / table.SunIrradianceTop[c] : 0.0;
  }

  table.Samples = samples;
  table.ZMin = zMin;
  table.ZMax = zMax;
  std::vector<double> transmittance, irradiance(n), rayleigh(n);
  const Atmosphere& atmosphere = *sunAndAir.GetAtmosphere();

  // Multiple scattering (rows 4, 5): the sky model's spectra in this table's sun
  // units, per wavelength (see the header).
  const SkyModel* sky = multipleScattering;
  std::vector<double> toTableSun(n, 0.0), meanRadiance(n), multiple(n);
  const double muS = sunAndAir.GetSunDirection()[2];
  if (sky)
  {
    const std::vector<double>& skySun = sky->GetSunIrradiance();
    for (std::size_t k = 0; k < n; ++k)
    {
      toTableSun[k] = skySun[k] > 0.0 ? sun[k] / skySun[k] : 0.0;
    }
    std::vector<double> groundSky(n);
    sky->LookupGroundSkyIrradiance(muS, groundSky.data());
    for (std::size_t k = 0; k < n; ++k)
    {
      groundSky[k] *= toTableSun[k];
    }
    const std::array<double, 3> groundRgb = sunAndAir.ToLinearSrgb(groundSky);
    for (int c = 0; c < 3; ++c)
    {
      table.GroundSkyIrradiance[c] = std::max(groundRgb[c], 0.0);
    }
    table.HasMultipleScattering = true;
  }
  table.Data.assign(static_cast<std::size_t>(AtmosphereTable::kRows) * samples * 4, 1.0f);
  for (int i = 0; i < samples; ++i)
  {
    const double z = zMin + (zMax - zMin) * i / (samples - 1);
    const double h = std::max(air.SceneAltitudeMetres + z, 0.0);
    const double rhoR = atmosphere.Density(h, air.RayleighScaleHeightMetres);
    const double rhoM = atmosphere.Density(h, air.MieScaleHeightMetres);
    sunAndAir.SunAtmosphereTransmittance({ { 0.0, 0.0, z } }, transmittance);
    for (std::size_t k = 0; k < n; ++k)
    {
      irradiance[k] = sun[k] * transmittance[k];
      rayleigh[k] = betaR[k] * rhoR * irradiance[k];
    }
    std::array<double, 3> multipleRgb{ { 0.0, 0.0, 0.0 } };
    if (sky)
    {
      // The sky model's own radius and densities: the same air (its key).
      sky->LookupMultipleScattering(air.EarthRadiusMetres + h, muS, meanRadiance.data());
      const double mieS = table.MieScatteringSeaLevel * rhoM;
      for (std::size_t k = 0; k < n; ++k)
      {
        multiple[k] = (betaR[k] * rhoR + mieS) * meanRadiance[k] * toTableSun[k];
      }
      multipleRgb = sunAndAir.ToLinearSrgb(multiple);
    }
    const std::array<double, 3> sunRgb = sunAndAir.ToLinearSrgb(irradiance);
    const std::array<double, 3> rayleighRgb = sunAndAir.ToLinearSrgb(rayleigh);
    // Radiance is >= 0: a negative linear-sRGB channel is only an out-of-gamut
    // colour (a sun reddened near the horizon, a 1000 K sun), and would make the
    // sums of the passes negative. Clipped at 0 per channel (gamut clipping of the
    // light, as SunIrradiance() in svsCommon.glsl clips row 0 already).
    auto put = [&](int row, int c, double value)
    {
      table.Data[(static_cast<std::size_t>(row) * samples + i) * 4 + c] =
        static_cast<float>(std::max(value, 0.0));
    };
    for (int c = 0; c < 3; ++c)
    {
      put(0, c, sunRgb[c]);
      put(1, c, rayleighRgb[c]);
      put(2, c, table.MieScatteringSeaLevel * rhoM * sunRgb[c]);
      put(3, c, table.RayleighExtinctionSeaLevel[c] * rhoR + table.MieExtinctionSeaLevel * rhoM);
      put(4, c, multipleRgb[c]);
      put(5, c, table.GroundSkyIrradiance[c]);
    }
  }
  return table;
}

} // namespace nimbus
