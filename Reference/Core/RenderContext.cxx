#include "RenderContext.h"
#include "BlackbodyEmission.h"
#include "Math.h"

#include "Sun.h"

#include <algorithm>
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

RenderContext::RenderContext(const SceneDescription& scene, DensityGrid grid, SceneFields fields)
  : Scene(scene)
  , ViewCamera(scene.Camera)
  , Grid(std::move(grid))
  , Fields(std::move(fields))
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
  this->SetUpVersion3(scene);
}

namespace
{
PhaseFunctionMixture MakePhase(
  const std::vector<PhaseComponentDescription>& phase, const std::string& field)
{
  Require(!phase.empty(), field, "needs at least one component");
  PhaseFunctionMixture mixture;
  double total = 0.0;
  for (std::size_t i = 0; i < phase.size(); ++i)
  {
    const std::string component = field + "[" + std::to_string(i) + "]";
    Require(std::isfinite(phase[i].G) && std::abs(phase[i].G) <= 1.0, component + ".g",
      "must be in [-1, 1]");
    Require(std::isfinite(phase[i].Weight) && phase[i].Weight >= 0.0, component + ".weight",
      "must be finite and >= 0");
    mixture.AddComponent(
      phase[i].Weight, KindFromName(phase[i].Type, component + ".type"), phase[i].G);
    total += phase[i].Weight;
  }
  Require(total > 0.0, field, "weights must not all be zero");
  return mixture;
}

bool SameGeometry(const DensityGrid& a, const DensityGrid& b)
{
  return a.GetDimensions() == b.GetDimensions() && a.GetOrigin() == b.GetOrigin() &&
    a.GetSpacing() == b.GetSpacing();
}

std::string GeometryText(const DensityGrid& g)
{
  const auto& d = g.GetDimensions();
  const auto& o = g.GetOrigin();
  const auto& s = g.GetSpacing();
  return std::to_string(d[0]) + "x" + std::to_string(d[1]) + "x" + std::to_string(d[2]) +
    " points, origin (" + std::to_string(o[0]) + ", " + std::to_string(o[1]) + ", " +
    std::to_string(o[2]) + "), spacing (" + std::to_string(s[0]) + ", " + std::to_string(s[1]) +
    ", " + std::to_string(s[2]) + ")";
}
} // namespace

void RenderContext::SetUpVersion3(const SceneDescription& scene)
{
  const SpectralSamples& spectrum = this->GetSpectrum();
  auto requireGeometry = [this](const DensityGrid& g, const std::string& field)
  {
    Require(SameGeometry(g, this->Grid), field,
      "must be on the main density's grid (" + GeometryText(this->Grid) + "), got " +
        GeometryText(g));
  };
  auto emission = [&](MediumComponent& m, const EmissionDescription& e, const DensityGrid* array,
                    const std::string& field)
  {
    if (!e.Enabled)
    {
      return;
    }
    Require(std::isfinite(e.RadiancePerMetre) && e.RadiancePerMetre >= 0.0,
      field + ".radiance_per_metre", "must be finite and >= 0");
    Require(std::isfinite(e.TemperatureKelvin) && e.TemperatureKelvin > 0.0,
      field + ".temperature_kelvin", "must be finite and > 0");
    if (e.Source == "array")
    {
      Require(array && !array->IsEmpty(), field + ".array",
        "names a field the renderer was not given ('" + e.ArrayName + "')");
      requireGeometry(*array, field + ".array");
      m.EmissionField = array;
    }
    else if (e.Source == "blackbody")
    {
      Require(array && !array->IsEmpty(), field + ".array",
        "names a temperature field the renderer was not given ('" + e.ArrayName + "')");
      requireGeometry(*array, field + ".array");
      Require(e.TemperatureKelvin >= 500.0 && e.TemperatureKelvin <= 50000.0,
        field + ".temperature_kelvin", "must be in [500, 50000] K for \"blackbody\"");
      // Per voxel and wavelength, density_i B(lambda, T_i) / Y[B(T_ref)]
      // (Physics/BlackbodyEmission.h).
      const BlackbodyEmission blackbody(spectrum, e.TemperatureKelvin);
      const std::vector<float>& rho = m.Density->GetValues();
      const std::vector<float>& kelvin = array->GetValues();
      const std::size_t n = spectrum.GetNumberOfSamples();
      std::vector<std::vector<float>> channels(n, std::vector<float>(rho.size(), 0.0f));
      for (std::size_t v = 0; v < rho.size(); ++v)
      {
        if (rho[v] > 0.0f)
        {
          const std::vector<double> b = blackbody.RelativeSpectrum(kelvin[v]);
          for (std::size_t i = 0; i < n; ++i)
          {
            channels[i][v] = static_cast<float>(std::min(rho[v] * b[i], 1e30));
          }
        }
      }
      for (std::size_t i = 0; i < n; ++i)
      {
        m.BlackbodyEmission.emplace_back(m.Density->GetDimensions(), m.Density->GetOrigin(),
          m.Density->GetSpacing(), std::move(channels[i]));
      }
      m.EmissionField = m.Density;
      m.EmissionSpectrum.assign(n, 1.0);
    }
    else
    {
      Require(e.Source == "from_density", field + ".source", "must be from_density or array");
      m.EmissionField = m.Density;
    }
    m.EmissionScale = e.RadiancePerMetre;
    m.EmissionSpectrum = SunIrradianceSpectrum(spectrum, e.TemperatureKelvin, 1.0);
    m.Emits = m.EmissionScale > 0.0 && m.EmissionField->GetMaximum() > 0.0;
    this->AnyEmission = this->AnyEmission || m.Emits;
  };

  MediumComponent main;
  main.Density = &this->Grid;
  main.ExtinctionPerDensity = scene.Medium.ExtinctionPerDensity;
  main.Albedo = scene.Medium.SingleScatteringAlbedo;
  main.Phase = this->CloudPhase;
  emission(main, scene.Medium.Emission, &this->Fields.Emission, "medium.emission");
  this->Media.push_back(std::move(main));

  Require(scene.Media.size() <= 16, "media", "may hold at most 16 media");
  Require(this->Fields.MediaDensities.size() == scene.Media.size(), "media",
    "has " + std::to_string(scene.Media.size()) + " media but the renderer was given " +
      std::to_string(this->Fields.MediaDensities.size()) + " density grids for them");
  for (std::size_t i = 0; i < scene.Media.size(); ++i)
  {
    const AdditionalMediumDescription& d = scene.Media[i];
    const std::string field = "media[" + std::to_string(i) + "]";
    requireGeometry(this->Fields.MediaDensities[i], field + ".density");
    Require(std::isfinite(d.ExtinctionPerDensity) && d.ExtinctionPerDensity >= 0.0,
      field + ".extinction_per_density", "must be finite and >= 0");
    Require(d.SingleScatteringAlbedo >= 0.0 && d.SingleScatteringAlbedo <= 1.0,
      field + ".single_scattering_albedo", "must be in [0, 1]");
    MediumComponent m;
    m.Density = &this->Fields.MediaDensities[i];
    m.ExtinctionPerDensity = d.ExtinctionPerDensity;
    m.Albedo = d.SingleScatteringAlbedo;
    m.Phase = MakePhase(d.Phase, field + ".phase");
    const DensityGrid* array =
      i < this->Fields.MediaEmissions.size() ? &this->Fields.MediaEmissions[i] : nullptr;
    emission(m, d.Emission, array, field + ".emission");
    this->Media.push_back(std::move(m));
  }

  // sigma_t on the shared grid: the main density with its factor for one medium (as
  // before version 3), else the sum of k_i density_i with factor 1.
  this->ExtinctionScale = this->ExtinctionPerDensity;
  if (this->Media.size() > 1 && !this->Grid.IsEmpty())
  {
    std::vector<float> sum(this->Grid.GetValues().size(), 0.0f);
    for (std::size_t k = 0; k < sum.size(); ++k)
    {
      double s = 0.0;
      for (const MediumComponent& m : this->Media)
      {
        s += m.ExtinctionPerDensity * m.Density->GetValues()[k];
      }
      sum[k] = static_cast<float>(s);
    }
    this->SummedExtinction = DensityGrid(
      this->Grid.GetDimensions(), this->Grid.GetOrigin(), this->Grid.GetSpacing(), std::move(sum));
    this->ExtinctionScale = 1.0;
  }

  for (std::size_t l = 0; l < scene.Lights.size(); ++l)
  {
    const LightDescription& d = scene.Lights[l];
    const std::string field = "lights[" + std::to_string(l) + "]";
    Require(std::isfinite(d.TemperatureKelvin) && d.TemperatureKelvin > 0.0,
      field + ".temperature_kelvin", "must be finite and > 0");
    this->LightSpectra.push_back(SunIrradianceSpectrum(spectrum, d.TemperatureKelvin, 1.0));
    if (d.Type == "point")
    {
      Require(std::isfinite(d.Intensity) && d.Intensity >= 0.0, field + ".intensity",
        "must be finite and >= 0");
      LightElement e;
      e.A = e.B = d.Position;
      e.Intensity = d.Intensity;
      e.Light = static_cast<int>(l);
      if (e.Intensity > 0.0)
      {
        this->Lights.push_back(e);
      }
      continue;
    }
    Require(d.Type == "polyline", field + ".type", "must be point or polyline");
    Require(d.Vertices.size() >= 2, field + ".vertices", "needs at least 2 vertices");
    Require(std::isfinite(d.IntensityPerMetre) && d.IntensityPerMetre >= 0.0,
      field + ".intensity_per_metre", "must be finite and >= 0");
    for (std::size_t v = 0; v + 1 < d.Vertices.size(); ++v)
    {
      LightElement e;
      e.A = d.Vertices[v];
      e.B = d.Vertices[v + 1];
      const double length =
        std::hypot(e.B[0] - e.A[0], std::hypot(e.B[1] - e.A[1], e.B[2] - e.A[2]));
      e.Intensity = d.IntensityPerMetre * length;
      e.IsSegment = true;
      e.Light = static_cast<int>(l);
      if (e.Intensity > 0.0 && std::isfinite(e.Intensity))
      {
        this->Lights.push_back(e);
      }
    }
  }
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
