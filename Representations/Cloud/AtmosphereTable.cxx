#include "AtmosphereTable.h"

#include "RenderContext.h"

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

AtmosphereTable BuildAtmosphereTable(
  const SceneDescription& scene, double zMin, double zMax, int samples)
{
  if (!std::isfinite(zMin) || !std::isfinite(zMax) || !(zMax > zMin) || samples < 2)
  {
    throw std::invalid_argument("atmosphere table needs zMax > zMin (finite) and >= 2 samples");
  }
  // The reference's own context: same sun spectrum, atmosphere and colour conversion.
  const RenderContext context(
    scene, DensityGrid::Constant({ { 0.0, 0.0, 0.0 } }, { { 1.0, 1.0, 1.0 } }, 0.0f));
  AtmosphereTable table;
  const std::vector<double>& sun = context.GetSunIrradiance();
  table.SunIrradianceTop = context.ToLinearSrgb(sun);
  if (!context.HasAtmosphere())
  {
    return table;
  }
  table.HasAtmosphere = true;
  const AtmosphereDescription& air = scene.Atmosphere;
  table.RayleighScaleHeight = air.RayleighScaleHeight;
  table.MieScaleHeight = air.MieScaleHeight;
  table.SceneAltitude = air.SceneAltitude;
  table.EarthRadius = air.EarthRadius;
  table.TopRadius = air.TopRadius;
  table.MieScatteringSeaLevel = context.GetMieScatteringSeaLevel();
  table.MieExtinctionSeaLevel = context.GetMieExtinctionSeaLevel();
  const std::vector<double>& betaR = context.GetRayleighScatteringSeaLevel();
  const std::size_t n = sun.size();
  std::vector<double> spectrum(n);
  for (std::size_t k = 0; k < n; ++k)
  {
    spectrum[k] = betaR[k] * sun[k];
  }
  const std::array<double, 3> weightedBeta = context.ToLinearSrgb(spectrum);
  for (int c = 0; c < 3; ++c)
  {
    table.RayleighExtinctionSeaLevel[c] =
      table.SunIrradianceTop[c] > 0.0 ? weightedBeta[c] / table.SunIrradianceTop[c] : 0.0;
  }

  table.Samples = samples;
  table.ZMin = zMin;
  table.ZMax = zMax;
  table.Data.assign(static_cast<std::size_t>(AtmosphereTable::kRows) * samples * 4, 1.0f);
  std::vector<double> transmittance, irradiance(n), rayleigh(n);
  const Atmosphere& atmosphere = *context.GetAtmosphere();
  for (int i = 0; i < samples; ++i)
  {
    const double z = zMin + (zMax - zMin) * i / (samples - 1);
    const double h = std::max(air.SceneAltitude + z, 0.0);
    const double rhoR = atmosphere.Density(h, air.RayleighScaleHeight);
    const double rhoM = atmosphere.Density(h, air.MieScaleHeight);
    context.SunAtmosphereTransmittance({ { 0.0, 0.0, z } }, transmittance);
    for (std::size_t k = 0; k < n; ++k)
    {
      irradiance[k] = sun[k] * transmittance[k];
      rayleigh[k] = betaR[k] * rhoR * irradiance[k];
    }
    const std::array<double, 3> sunRgb = context.ToLinearSrgb(irradiance);
    const std::array<double, 3> rayleighRgb = context.ToLinearSrgb(rayleigh);
    auto put = [&](int row, int c, double value) {
      table.Data[(static_cast<std::size_t>(row) * samples + i) * 4 + c] = static_cast<float>(value);
    };
    for (int c = 0; c < 3; ++c)
    {
      put(0, c, sunRgb[c]);
      put(1, c, rayleighRgb[c]);
      put(2, c, table.MieScatteringSeaLevel * rhoM * sunRgb[c]);
      put(3, c, table.RayleighExtinctionSeaLevel[c] * rhoR + table.MieExtinctionSeaLevel * rhoM);
    }
  }
  return table;
}

} // namespace nimbus
