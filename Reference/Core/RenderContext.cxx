#include "RenderContext.h"
#include "Math.h"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace nimbus
{

namespace
{
void Require(bool condition, const std::string& field, const std::string& what)
{
  if (!condition)
  {
    throw std::invalid_argument("scene: " + field + " " + what);
  }
}

PhaseFunctionKind KindFromName(const std::string& name, const std::string& field)
{
  if (name == "isotropic")
  {
    return PhaseFunctionKind::Isotropic;
  }
  if (name == "rayleigh")
  {
    return PhaseFunctionKind::Rayleigh;
  }
  if (name == "henyey_greenstein")
  {
    return PhaseFunctionKind::HenyeyGreenstein;
  }
  if (name == "cornette_shanks")
  {
    return PhaseFunctionKind::CornetteShanks;
  }
  throw std::invalid_argument("scene: " + field + " has unknown phase function type '" + name +
    "' (isotropic, rayleigh, henyey_greenstein, cornette_shanks)");
}

AtmosphereParameters ToAtmosphereParameters(const AtmosphereDescription& d)
{
  AtmosphereParameters p;
  p.earthRadius = d.EarthRadius;
  p.topRadius = d.TopRadius;
  p.rayleighScaleHeight = d.RayleighScaleHeight;
  p.mieScaleHeight = d.MieScaleHeight;
  p.rayleighScattering550 = d.RayleighScattering550;
  p.mieScattering = d.MieScattering;
  p.mieSingleScatteringAlbedo = d.MieAlbedo;
  p.mieG = d.MieG;
  return p;
}
}

RenderContext::RenderContext(const SceneDescription& scene, DensityGrid grid)
  : Scene(scene)
  , ViewCamera(scene.Camera)
  , Grid(std::move(grid))
{
  const MediumDescription& medium = scene.Medium;
  Require(std::isfinite(medium.ExtinctionPerDensity) && medium.ExtinctionPerDensity >= 0.0,
    "medium.extinction_per_density", "must be finite and >= 0");
  Require(medium.SingleScatteringAlbedo >= 0.0 && medium.SingleScatteringAlbedo <= 1.0,
    "medium.single_scattering_albedo", "must be in [0, 1]");
  Require(!medium.Phase.empty(), "medium.phase", "needs at least one component");
  for (std::size_t i = 0; i < medium.Phase.size(); ++i)
  {
    const std::string field = "medium.phase[" + std::to_string(i) + "]";
    Require(std::isfinite(medium.Phase[i].G) && std::abs(medium.Phase[i].G) <= 1.0, field + ".g",
      "must be in [-1, 1]");
    Require(std::isfinite(medium.Phase[i].Weight) && medium.Phase[i].Weight >= 0.0,
      field + ".weight", "must be finite and >= 0");
    this->CloudPhase.AddComponent(medium.Phase[i].Weight,
      KindFromName(medium.Phase[i].Type, field + ".type"), medium.Phase[i].G);
  }
  double totalWeight = 0.0;
  for (const auto& component : medium.Phase)
  {
    totalWeight += component.Weight;
  }
  Require(totalWeight > 0.0, "medium.phase", "weights must not all be zero");
  this->ExtinctionPerDensity = medium.ExtinctionPerDensity;

  Require(scene.SpectralSamples >= 3 && scene.SpectralSamples <= 256, "spectral_samples",
    "must be in [3, 256]");
  // Spline reconstruction overshoots below 8 samples (Physics/README.md): linear there.
  this->Spectrum = std::make_unique<SpectralSamples>(scene.SpectralSamples,
    scene.SpectralSamples >= 8 ? SpectralReconstruction::NaturalCubicSpline
                               : SpectralReconstruction::PiecewiseLinear);
  this->Wavelengths = this->Spectrum->GetWavelengths();

  const SunDescription& sun = scene.Sun;
  Require(std::isfinite(sun.Azimuth), "sun.azimuth", "must be finite");
  Require(std::isfinite(sun.Elevation) && std::abs(sun.Elevation) <= 90.0, "sun.elevation",
    "must be in [-90, 90] degrees");
  Require(std::isfinite(sun.Illuminance) && sun.Illuminance >= 0.0, "sun.illuminance",
    "must be finite and >= 0");
  Require(std::isfinite(sun.Temperature) && sun.Temperature >= 1000.0, "sun.temperature",
    "must be >= 1000 K");
  const double elevation = sun.Elevation * kDegree, azimuth = sun.Azimuth * kDegree;
  this->SunDirection = { { std::cos(elevation) * std::sin(azimuth),
    std::cos(elevation) * std::cos(azimuth), std::sin(elevation) } };
  const double temperature = sun.Temperature;
  this->SunIrradiance = this->Spectrum->Sample(
    [temperature](double lambda) { return PlanckSpectralRadiance(lambda, temperature); });
  const double luminance = this->Spectrum->ToXyz(this->SunIrradiance)[1];
  for (double& e : this->SunIrradiance)
  {
    e *= sun.Illuminance / luminance;
  }

  if (scene.Atmosphere.Enabled)
  {
    Require(std::isfinite(scene.Atmosphere.SceneAltitude) && scene.Atmosphere.SceneAltitude >= 0.0,
      "atmosphere.scene_altitude", "must be finite and >= 0");
    try
    {
      this->Air = std::make_unique<Atmosphere>(ToAtmosphereParameters(scene.Atmosphere));
    }
    catch (const std::invalid_argument& error)
    {
      throw std::invalid_argument(std::string("scene: atmosphere: ") + error.what());
    }
    for (double lambda : this->Wavelengths)
    {
      this->BetaRayleigh.push_back(this->Air->RayleighScattering(lambda));
    }
    // Mie is grey: its coefficients do not depend on the wavelength.
    this->BetaMieScattering = this->Air->MieScattering(550.0);
    this->BetaMieExtinction = this->Air->MieExtinction(550.0);
  }

  const BackgroundDescription& background = scene.Background;
  Require(
    background.Type == "black" || background.Type == "constant" || background.Type == "atmosphere",
    "background.type", "must be black, constant or atmosphere");
  Require(background.Type != "atmosphere" || scene.Atmosphere.Enabled, "background.type",
    "'atmosphere' needs atmosphere.enabled");
  Require(std::isfinite(background.Radiance) && background.Radiance >= 0.0, "background.radiance",
    "must be finite and >= 0");
  // A flat spectrum of 1 has Y = 1 (SpectralColor.h).
  this->BackgroundRadiance.assign(
    this->Wavelengths.size(), background.Type == "constant" ? background.Radiance : 0.0);

  Require(std::isfinite(scene.Ground.Height), "ground.height", "must be finite");
  Require(
    scene.Ground.Albedo >= 0.0 && scene.Ground.Albedo <= 1.0, "ground.albedo", "must be in [0, 1]");
}

std::array<double, 3> RenderContext::ToLinearSrgb(const std::vector<double>& spectralRadiance) const
{
  return this->Spectrum->ToLinearSrgb(spectralRadiance);
}

RenderContext::Vector3 RenderContext::EarthCentred(const Vector3& p) const
{
  const double base = this->Scene.Atmosphere.EarthRadius + this->Scene.Atmosphere.SceneAltitude;
  return { { p[0], p[1], base + p[2] } };
}

void RenderContext::AtmosphereCoefficients(const Vector3& p,
  std::vector<double>& rayleighScattering, double& mieScattering, double& mieExtinction) const
{
  rayleighScattering.assign(this->Wavelengths.size(), 0.0);
  mieScattering = mieExtinction = 0.0;
  if (!this->Air)
  {
    return;
  }
  const AtmosphereParameters& a = this->Air->GetParameters();
  const double altitude = this->Air->Altitude(this->EarthCentred(p));
  const double rhoR = this->Air->Density(altitude, a.rayleighScaleHeight);
  const double rhoM = this->Air->Density(altitude, a.mieScaleHeight);
  for (std::size_t i = 0; i < this->Wavelengths.size(); ++i)
  {
    rayleighScattering[i] = this->BetaRayleigh[i] * rhoR;
  }
  mieScattering = this->BetaMieScattering * rhoM;
  mieExtinction = this->BetaMieExtinction * rhoM;
}

void RenderContext::SunAtmosphereTransmittance(
  const Vector3& p, std::vector<double>& transmittance) const
{
  transmittance.assign(this->Wavelengths.size(), 1.0);
  if (!this->Air)
  {
    return;
  }
  const OpticalLengths lengths =
    this->Air->OpticalLengthsToTop(this->EarthCentred(p), this->SunDirection);
  for (std::size_t i = 0; i < this->Wavelengths.size(); ++i)
  {
    transmittance[i] = this->Air->Transmittance(lengths, this->Wavelengths[i]);
  }
}

void RenderContext::AtmosphereTransmittanceBetween(
  const Vector3& p0, const Vector3& p1, std::vector<double>& transmittance) const
{
  transmittance.assign(this->Wavelengths.size(), 1.0);
  if (!this->Air)
  {
    return;
  }
  const Vector3 q0 = this->EarthCentred(p0), q1 = this->EarthCentred(p1);
  const AtmosphereParameters& a = this->Air->GetParameters();
  OpticalLengths lengths;
  lengths.rayleighLength = this->Air->OpticalLength(q0, q1, a.rayleighScaleHeight);
  lengths.mieLength = this->Air->OpticalLength(q0, q1, a.mieScaleHeight);
  for (std::size_t i = 0; i < this->Wavelengths.size(); ++i)
  {
    transmittance[i] = this->Air->Transmittance(lengths, this->Wavelengths[i]);
  }
}

double RenderContext::DistanceToTopOfAtmosphere(
  const Vector3& origin, const Vector3& direction) const
{
  if (!this->Air)
  {
    return std::numeric_limits<double>::infinity();
  }
  const Vector3 o = this->EarthCentred(origin);
  const double top = this->Air->GetParameters().topRadius;
  const double b = o[0] * direction[0] + o[1] * direction[1] + o[2] * direction[2];
  const double c = (o[0] * o[0] + o[1] * o[1] + o[2] * o[2]) - top * top;
  const double disc = b * b - c;
  if (disc < 0.0)
  {
    return 0.0;
  }
  return std::max(0.0, -b + std::sqrt(disc));
}

double RenderContext::IntersectGround(
  const Vector3& origin, const Vector3& direction, double tMin) const
{
  if (!this->Scene.Ground.Enabled || direction[2] >= 0.0)
  {
    return std::numeric_limits<double>::infinity();
  }
  const double t = (this->Scene.Ground.Height - origin[2]) / direction[2];
  return t > tMin ? t : std::numeric_limits<double>::infinity();
}

} // namespace nimbus
