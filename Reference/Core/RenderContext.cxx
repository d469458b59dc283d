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
  this->SetUpVersion4();
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
    if (d.Type == "point" || d.Type == "spot")
    {
      Require(std::isfinite(d.Intensity) && d.Intensity >= 0.0, field + ".intensity",
        "must be finite and >= 0");
      Require(IsFinite(d.Position), field + ".position", "must be finite");
      LightElement e;
      e.A = e.B = d.Position;
      e.Intensity = d.Intensity;
      e.Light = static_cast<int>(l);
      if (d.Type == "spot")
      {
        this->SetUpSpot(l, e);
      }
      if (e.Intensity > 0.0)
      {
        this->Lights.push_back(e);
      }
      continue;
    }
    Require(d.Type == "polyline", field + ".type", "must be point, polyline or spot");
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

void RenderContext::SetUpSpot(std::size_t index, LightElement& e) const
{
  // The context's own copy of the light: the element's map pointer stays valid as long
  // as the context (which is neither copied nor moved).
  const LightDescription& d = this->Scene.Lights[index];
  const std::string field = "lights[" + std::to_string(index) + "]";
  const Vector3& axis = d.Direction;
  const double length = std::hypot(std::hypot(axis[0], axis[1]), axis[2]);
  Require(IsFinite(axis) && length > 0.0 && std::isfinite(length), field + ".direction",
    "must be a finite, non-zero vector");
  Require(d.ConeAngleDegrees > 0.0 && d.ConeAngleDegrees < 90.0, field + ".cone_angle_degrees",
    "must be in (0, 90) (90 or more: use a point light)");
  Require(d.EdgeDegrees >= 0.0 && d.EdgeDegrees <= d.ConeAngleDegrees, field + ".edge_degrees",
    "must be in [0, cone_angle_degrees]");
  e.IsSpot = true;
  e.Spot.Axis = { { axis[0] / length, axis[1] / length, axis[2] / length } };
  e.Spot.ConeHalfAngleDegrees = d.ConeAngleDegrees;
  e.Spot.EdgeWidthDegrees = d.EdgeDegrees;
  const LightMapDescription& map = d.LightMap;
  if (map.Path.empty() && map.Luminance.empty())
  {
    return;
  }
  Require(!map.Luminance.empty(), field + ".light_map",
    "names an image the renderer was not given ('" + map.Path +
      "'; nimbus::LoadSceneAssets reads it)");
  Require(map.Width >= 1 && map.Height >= 1 &&
      map.Luminance.size() ==
        static_cast<std::size_t>(map.Width) * static_cast<std::size_t>(map.Height),
    field + ".light_map",
    "has " + std::to_string(map.Luminance.size()) + " values for " + std::to_string(map.Width) +
      " x " + std::to_string(map.Height) + " pixels");
  std::size_t bad = 0;
  for (float x : map.Luminance)
  {
    bad += std::isfinite(x) && x >= 0.0f ? 0 : 1;
  }
  Require(bad == 0, field + ".light_map",
    "has " + std::to_string(bad) + " NaN, infinite or negative luminance values");
  e.Map = &map;
}

void RenderContext::SetUpVersion4()
{
  const SceneDescription& scene = this->Scene;
  for (std::size_t i = 0; i < scene.Occluders.size(); ++i)
  {
    const OccluderDescription& o = scene.Occluders[i];
    const std::string field = "occluders[" + std::to_string(i) + "]";
    Require(o.Albedo >= 0.0 && o.Albedo <= 1.0, field + ".albedo", "must be in [0, 1]");
    if (o.Type == "box")
    {
      bool ordered = IsFinite(o.Min) && IsFinite(o.Max);
      for (int a = 0; a < 3; ++a)
      {
        ordered = ordered && o.Min[a] <= o.Max[a];
      }
      Require(ordered, field + ".max", "must be finite and >= min on every axis");
      this->Occluders.AddBox(o.Min, o.Max, o.Albedo);
      continue;
    }
    Require(o.Type == "mesh", field + ".type", "must be box or mesh");
    Require(std::isfinite(o.Scale) && o.Scale > 0.0, field + ".scale", "must be finite and > 0");
    Require(IsFinite(o.Translate), field + ".translate", "must be finite");
    Require(!o.TriangleVertices.empty(), field + ".path",
      "names a mesh whose triangles the renderer was not given ('" + o.Path +
        "'; nimbus::LoadSceneAssets reads it)");
    Require(o.TriangleVertices.size() % 3 == 0, field + ".path",
      "has " + std::to_string(o.TriangleVertices.size()) +
        " triangle vertices, not a multiple of 3");
    const std::size_t before = this->Occluders.GetNumberOfTriangles();
    for (std::size_t v = 0; v < o.TriangleVertices.size(); v += 3)
    {
      Vector3 corner[3];
      for (int k = 0; k < 3; ++k)
      {
        for (int a = 0; a < 3; ++a)
        {
          corner[k][a] = o.Scale * o.TriangleVertices[v + k][a] + o.Translate[a];
        }
        Require(IsFinite(corner[k]), field + ".path",
          "has a vertex that is not finite once scaled and translated (triangle " +
            std::to_string(v / 3) + ")");
      }
      this->Occluders.AddTriangle(corner[0], corner[1], corner[2], o.Albedo);
    }
    Require(this->Occluders.GetNumberOfTriangles() > before, field + ".path",
      "has no triangle of non-zero area ('" + o.Path + "')");
  }
  this->Occluders.Build();
}

double SampleLightMap(const LightMapDescription& map, double u, double v)
{
  if (!(u >= 0.0 && u <= 1.0 && v >= 0.0 && v <= 1.0) || map.Luminance.empty())
  {
    return 0.0;
  }
  // Pixel centres at (c + 0.5) / Width: x = u Width - 0.5 in [-0.5, Width - 0.5], clamped
  // to the edge pixels' centres.
  const double x = std::min(std::max(u * map.Width - 0.5, 0.0), map.Width - 1.0);
  // Row 0 is the picture's top (the file's first row), v = 0 its bottom.
  const double y = std::min(std::max((1.0 - v) * map.Height - 0.5, 0.0), map.Height - 1.0);
  const int c0 = std::min(static_cast<int>(x), map.Width - 1);
  const int r0 = std::min(static_cast<int>(y), map.Height - 1);
  const int c1 = std::min(c0 + 1, map.Width - 1), r1 = std::min(r0 + 1, map.Height - 1);
  const double fx = x - c0, fy = y - r0;
  auto at = [&map](int c, int r)
  { return static_cast<double>(map.Luminance[static_cast<std::size_t>(r) * map.Width + c]); };
  const double top = at(c0, r0) + fx * (at(c1, r0) - at(c0, r0));
  const double bottom = at(c0, r1) + fx * (at(c1, r1) - at(c0, r1));
  return top + fy * (bottom - top);
}

double LightElementFactor(const LightElement& light, const Vector3& w)
{
  if (!light.IsSpot)
  {
    return 1.0;
  }
  double factor = SpotFactor(light.Spot, w);
  if (factor > 0.0 && light.Map)
  {
    double u, v;
    factor *= SpotLightMapCoordinates(light.Spot, w, u, v) ? SampleLightMap(*light.Map, u, v) : 0.0;
  }
  return factor;
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
