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

  try
  {
    this->Light = std::make_unique<SunAndAir>(scene.Sun, scene.Atmosphere, scene.SpectralSamples);
  }
  catch (const std::invalid_argument& error)
  {
    throw std::invalid_argument(std::string("scene: ") + error.what());
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
    this->GetWavelengths().size(), background.Type == "constant" ? background.Radiance : 0.0);

  Require(std::isfinite(scene.Ground.Height), "ground.height", "must be finite");
  Require(
    scene.Ground.Albedo >= 0.0 && scene.Ground.Albedo <= 1.0, "ground.albedo", "must be in [0, 1]");
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
