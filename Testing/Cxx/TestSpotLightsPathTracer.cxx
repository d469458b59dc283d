// Version-4 scenes in the path tracer (PathTracer.h): spot lights (soft-edged cones, light
// maps) by next-event estimation, and opaque occluders (boxes, meshes in a bounding volume
// hierarchy) that stop rays, cast shadows into the haze and reflect as grey Lambertian
// surfaces. Each against a closed form (Physics/Airlight.h), a 1-D quadrature of one or
// an exact value, with the estimator's own standard error: |mean - truth| <= 4 se per
// channel (z printed); where the estimator has no variance (one deterministic vertex) to
// 1e-6 relative. Scenes are one pixel seen along its centre, with no sun, no air, a black
// background unless said, so that only the feature under test lights the pixel.
#include "Airlight.h"
#include "LightsSceneTesting.h"
#include "Math.h"
#include "MonteCarloAgreement.h"
#include "Occluders.h"
#include "PathTracer.h"
#include "SingleScatteringRenderer.h"
#include "SpotLight.h"
#include "Sun.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <limits>
#include <memory>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

namespace
{
using nimbus::DensityGrid;
using nimbus::kDegree;
using nimbus::kPi;
using nimbus::LightDescription;
using nimbus::OccluderDescription;
using nimbus::PathTracingResult;
using nimbus::PathTracingSettings;
using nimbus::RenderContext;
using nimbus::SceneDescription;
using V = std::array<double, 3>;
using nimbus_test::DarkScene;
using nimbus_test::ExpectPixel;
using nimbus_test::Rgb;
using nimbus_test::Samples;
using nimbus_test::Simpson;

V Sub(const V& a, const V& b)
{
  return { { a[0] - b[0], a[1] - b[1], a[2] - b[2] } };
}

V Unit(const V& a)
{
  return nimbus::Normalized(a);
}

LightDescription PointLight(const V& position, double intensity)
{
  LightDescription light;
  light.Type = "point";
  light.Position = position;
  light.Intensity = intensity;
  light.TemperatureKelvin = 4000.0;
  return light;
}

LightDescription Spot(
  const V& position, const V& direction, double cone, double edge, double intensity)
{
  LightDescription light;
  light.Type = "spot";
  light.Position = position;
  light.Direction = direction;
  light.ConeAngleDegrees = cone;
  light.EdgeDegrees = edge;
  light.Intensity = intensity;
  light.TemperatureKelvin = 3000.0;
  return light;
}

OccluderDescription Box(const V& lo, const V& hi, double albedo)
{
  OccluderDescription box;
  box.Type = "box";
  box.Min = lo;
  box.Max = hi;
  box.Albedo = albedo;
  return box;
}

/// Every channel within `relative` of truth (estimators without variance).
void ExpectExact(
  const PathTracingResult& r, const std::array<double, 3>& truth, const char* what, double relative)
{
  double worst = 0.0;
  for (int c = 0; c < 3; ++c)
  {
    const double mean = r.Image.At(0, 0)[c];
    const double error = std::abs(mean / truth[c] - 1.0);
    worst = std::max(worst, error);
    EXPECT_LT(error, relative) << what << " channel " << c << ": " << mean << " vs " << truth[c];
  }
  std::printf("%s: truth G %.8g, image G %.8g, largest relative difference %.1e (se %.1e)\n", what,
    truth[1], r.Image.At(0, 0)[1], worst, r.StandardError.At(0, 0)[1]);
}

/// The scene at 1024 samples per pixel from `seed` on 2 threads, with the path tracer's
/// variance-reducing techniques all on or all off: sun-peak sampling, sun-depth roulette,
/// the tabulated air transmittance and block traversal, and where `lightTechniques` also
/// adaptive sampling and equi-angular light sampling (otherwise those at their defaults).
PathTracingResult RenderWithTechniques(
  const RenderContext& context, bool on, std::uint64_t seed, bool lightTechniques)
{
  PathTracingSettings settings;
  settings.MinSamplesPerPixel = settings.MaxSamplesPerPixel = 1024;
  settings.Seed = seed;
  settings.Threads = 2;
  settings.SunPeakSampling = on;
  settings.SunDepthRoulette = on;
  settings.TabulatedAirTransmittance = on;
  settings.BlockTraversal = on;
  if (lightTechniques)
  {
    settings.AdaptiveSampling = on;
    settings.EquiAngularLightSampling = on;
  }
  return nimbus::RenderPathTraced(context, settings);
}

/// A function of the ray's parameter and the levels where the integrand has a kink or a
/// step.
using Crossings = std::pair<std::function<double(double)>, std::vector<double>>;

/// Simpson over [a, b] split where each g(t) crosses each of its levels (found on a grid
/// of 20000 steps and refined by bisection): an integrand with kinks or steps there.
double PiecewiseSimpson(const std::function<double(double)>& f,
  const std::vector<Crossings>& crossings, double a, double b, double eps)
{
  std::vector<double> cuts = { a, b };
  const int n = 20000;
  for (const Crossings& crossing : crossings)
    for (double level : crossing.second)
    {
      const std::function<double(double)>& g = crossing.first;
      for (int i = 0; i < n; ++i)
      {
        double lo = a + (b - a) * i / n, hi = a + (b - a) * (i + 1) / n;
        if ((g(lo) - level) * (g(hi) - level) > 0.0)
        {
          continue;
        }
        for (int k = 0; k < 100; ++k)
        {
          const double mid = 0.5 * (lo + hi);
          ((g(lo) - level) * (g(mid) - level) <= 0.0 ? hi : lo) = mid;
        }
        cuts.push_back(0.5 * (lo + hi));
      }
    }
  std::sort(cuts.begin(), cuts.end());
  double sum = 0.0;
  for (std::size_t i = 0; i + 1 < cuts.size(); ++i)
  {
    if (cuts[i + 1] > cuts[i])
    {
      sum += Simpson(f, cuts[i], cuts[i + 1], eps);
    }
  }
  return sum;
}

double HenyeyGreenstein(double mu, double g)
{
  return (1.0 - g * g) / (4.0 * kPi * std::pow(1.0 + g * g - 2.0 * g * mu, 1.5));
}

/// The beam's factor as the scene format defines it (Physics/SpotLight.h), written again
/// here: 1 within cone - edge of the axis, 0 beyond the cone, a smoothstep of the angle
/// between.
double Beam(const V& axis, const V& w, double cone, double edge)
{
  const double angle = std::acos(std::clamp(nimbus::Dot(Unit(axis), w), -1.0, 1.0)) / kDegree;
  if (angle >= cone)
  {
    return 0.0;
  }
  if (angle <= cone - edge)
  {
    return 1.0;
  }
  const double t = (cone - angle) / edge;
  return t * t * (3.0 - 2.0 * t);
}

double AngleFromAxis(const V& axis, const V& w)
{
  return std::acos(std::clamp(nimbus::Dot(Unit(axis), w), -1.0, 1.0)) / kDegree;
}

/// A homogeneous medium filling the box, of extinction sigmaT and albedo, in `scene`.
void Haze(SceneDescription& scene, double sigmaT, double albedo, double g)
{
  scene.Medium.ExtinctionPerDensity = sigmaT;
  scene.Medium.SingleScatteringAlbedo = albedo;
  scene.Medium.Phase = { { g == 0.0 ? "isotropic" : "henyey_greenstein", g, 1.0 } };
}

/// The single-scattered airlight integrand along a camera ray from `camera` along `d` in
/// a homogeneous medium: sigma_s p(mu) I factor(w) exp(-sigma_t (t + r)) / r^2.
std::function<double(double)> Airlight(const V& camera, const V& d, const V& light,
  double intensity, double sigmaS, double sigmaT, double g,
  const std::function<double(const V&)>& factor)
{
  return [=](double t)
  {
    const V x = nimbus::Along(camera, d, t);
    const V toLight = Sub(light, x);
    const double r = nimbus::Length(toLight);
    const V w{ { -toLight[0] / r, -toLight[1] / r, -toLight[2] / r } }; // from the light
    const double mu = -nimbus::Dot(w, d);
    const double phase = g == 0.0 ? 1.0 / (4.0 * kPi) : HenyeyGreenstein(mu, g);
    return sigmaS * phase * intensity * factor(w) * std::exp(-sigmaT * (t + r)) / (r * r);
  };
}

const V kLo{ { -3000.0, -3000.0, -3000.0 } }, kHi{ { 3000.0, 3000.0, 3000.0 } };
} // namespace

//------------------------------------------------------------------------------
// A point light in a homogeneous isotropic haze, single scattering (MaxScatteringOrder
// 1): the airlight along the pixel's ray is Sun et al.'s closed form (Physics/Airlight.h)
// over the ray's length inside the haze (the camera and the light are inside it).
TEST(SpotLightsPathTracer, PointLightAirlightIsTheClosedForm)
{
  const V camera{ { 0.0, -2000.0, 0.0 } }, light{ { 0.0, 300.0, 60.0 } };
  const double sigmaT = 5.0e-4, albedo = 0.8, intensity = 1.0e5;
  SceneDescription scene = DarkScene(camera, { { 0.0, 0.0, 0.0 } });
  Haze(scene, sigmaT, albedo, 0.0);
  scene.Lights = { PointLight(light, intensity) };
  const RenderContext context(scene, DensityGrid::Constant(kLo, kHi, 1.0f));
  const PathTracingResult r = nimbus::RenderPathTraced(context, Samples(200000, 101, 1));
  const double rayLength = kHi[1] - camera[1];
  const nimbus::AirlightMedium medium{ albedo * sigmaT, sigmaT };
  const double closed = nimbus::PointLightAirlight(
    medium, intensity, Sub(light, camera), { { 0.0, 1.0, 0.0 } }, rayLength);
  const double quadrature = Simpson(Airlight(camera, { { 0.0, 1.0, 0.0 } }, light, intensity,
                                      albedo * sigmaT, sigmaT, 0.0, [](const V&) { return 1.0; }),
    0.0, rayLength, 1e-14);
  std::printf("closed form %.12g, Simpson quadrature %.12g (relative difference %.1e)\n", closed,
    quadrature, quadrature / closed - 1.0);
  EXPECT_NEAR(quadrature / closed, 1.0, 1e-9);
  ExpectPixel(r, Rgb(context, context.GetLightSpectra()[0], closed),
    "point light airlight, closed form (Sun et al. 2005)");
}

//------------------------------------------------------------------------------
// A spot whose cone the pixel's ray crosses, in a forward-scattering haze (HG 0.5), single
// scattering: the quadrature of sigma_s p(mu) I SpotFactor(w) e^(-sigma_t (t + r)) / r^2,
// split where the ray crosses the soft edge's two cones. A ray behind the spot, outside
// its cone, stays exactly black.
TEST(SpotLightsPathTracer, SpotAirlightAcrossTheCone)
{
  const V camera{ { 0.0, -2000.0, 0.0 } };
  const V position{ { -300.0, 500.0, 40.0 } }, axis{ { 1.0, 0.2, 0.0 } };
  const double cone = 20.0, edge = 6.0, intensity = 1.0e6;
  const double sigmaT = 5.0e-4, albedo = 0.8, g = 0.5;
  SceneDescription scene = DarkScene(camera, { { 0.0, 0.0, 0.0 } });
  Haze(scene, sigmaT, albedo, g);
  scene.Lights = { Spot(position, axis, cone, edge, intensity) };
  const RenderContext context(scene, DensityGrid::Constant(kLo, kHi, 1.0f));
  const PathTracingResult r = nimbus::RenderPathTraced(context, Samples(200000, 102, 1));
  const V d{ { 0.0, 1.0, 0.0 } };
  auto factor = [&](const V& w) { return Beam(axis, w, cone, edge); };
  auto angle = [&](double t)
  { return AngleFromAxis(axis, Unit(Sub(nimbus::Along(camera, d, t), position))); };
  const double truth =
    PiecewiseSimpson(Airlight(camera, d, position, intensity, albedo * sigmaT, sigmaT, g, factor),
      { { angle, { cone - edge, cone } } }, 0.0, kHi[1] - camera[1], 1e-14);
  ExpectPixel(r, Rgb(context, context.GetLightSpectra()[0], truth),
    "spot airlight across a soft-edged cone (HG 0.5)");
  // The same spot's beam never reaches a ray behind it.
  SceneDescription behind = scene;
  behind.Camera.Position = { { -600.0, -2000.0, 0.0 } };
  behind.Camera.FocalPoint = { { -600.0, 0.0, 0.0 } };
  const RenderContext behindContext(behind, DensityGrid::Constant(kLo, kHi, 1.0f));
  const PathTracingResult black = nimbus::RenderPathTraced(behindContext, Samples(2000, 103, 1));
  EXPECT_EQ(black.Image.At(0, 0)[1], 0.0f);
}

//------------------------------------------------------------------------------
// A shadowed half space: a point light below an opaque half plane (z = 0, x < 0; a flat box)
// or below a huge box filling x < 0, z < 0, in a haze that fills both sides. The plane
// through the light and the edge (x = 0, z = 0) is the shadow's boundary: a ray at z = 300
// along +x is lit only beyond x = -150. Single scattering: the closed form over the lit
// part only, A(3500) - A(1350) (the closed form is an integral from the camera). A ray
// wholly in the shadow: exactly 0 with single scattering, more with multiple scattering.
TEST(SpotLightsPathTracer, OccluderShadowsHalfTheHaze)
{
  const V lo{ { -2000.0, -2000.0, -1000.0 } }, hi{ { 2000.0, 2000.0, 1000.0 } };
  const V light{ { 100.0, 0.0, -200.0 } }, camera{ { -1500.0, 0.0, 300.0 } };
  const double sigmaT = 5.0e-4, albedo = 0.8, intensity = 1.0e5;
  const nimbus::AirlightMedium medium{ albedo * sigmaT, sigmaT };
  const V d{ { 1.0, 0.0, 0.0 } };
  const double lit = nimbus::PointLightAirlight(medium, intensity, Sub(light, camera), d, 3500.0) -
    nimbus::PointLightAirlight(medium, intensity, Sub(light, camera), d, 1350.0);
  const double whole = nimbus::PointLightAirlight(medium, intensity, Sub(light, camera), d, 3500.0);
  std::printf("the lit part is %.1f %% of the unshadowed airlight\n", 100.0 * lit / whole);
  const std::vector<std::pair<const char*, OccluderDescription>> occluders = {
    { "a black half plane (flat box)",
      Box({ { -5000.0, -5000.0, 0.0 } }, { { 0.0, 5000.0, 0.0 } }, 0.0) },
    { "a black box filling x < 0, z < 0",
      Box({ { -5000.0, -5000.0, -5000.0 } }, { { 0.0, 5000.0, 0.0 } }, 0.0) },
  };
  std::uint64_t seed = 110;
  for (const auto& occluder : occluders)
  {
    SceneDescription scene = DarkScene(camera, { { 0.0, 0.0, 300.0 } });
    Haze(scene, sigmaT, albedo, 0.0);
    scene.Lights = { PointLight(light, intensity) };
    scene.Occluders = { occluder.second };
    const RenderContext context(scene, DensityGrid::Constant(lo, hi, 1.0f));
    const PathTracingResult r = nimbus::RenderPathTraced(context, Samples(200000, ++seed, 1));
    ExpectPixel(r, Rgb(context, context.GetLightSpectra()[0], lit),
      (std::string("the lit part of a ray through the shadow's edge, ") + occluder.first).c_str());
    // A ray in the shadow: every point's segment to the light crosses z = 0 at x < 0.
    SceneDescription dark = scene;
    dark.Camera.Position = { { -800.0, -1500.0, 300.0 } };
    dark.Camera.FocalPoint = { { -800.0, 0.0, 300.0 } };
    dark.Camera.ViewUp = { { 0.0, 0.0, 1.0 } };
    const RenderContext darkContext(dark, DensityGrid::Constant(lo, hi, 1.0f));
    const PathTracingResult single =
      nimbus::RenderPathTraced(darkContext, Samples(20000, ++seed, 1));
    EXPECT_EQ(single.Image.At(0, 0)[1], 0.0f) << occluder.first;
    const PathTracingResult multiple =
      nimbus::RenderPathTraced(darkContext, Samples(200000, ++seed, 0));
    EXPECT_GT(multiple.Image.At(0, 0)[1], 4.0f * multiple.StandardError.At(0, 0)[1]);
    std::printf("  a ray in the shadow: single scattering %g, multiple scattering %.4g +- %.2g "
                "(%.2f %% of the lit ray)\n",
      single.Image.At(0, 0)[1], multiple.Image.At(0, 0)[1], multiple.StandardError.At(0, 0)[1],
      100.0 * multiple.Image.At(0, 0)[1] / r.Image.At(0, 0)[1]);
  }
}

//------------------------------------------------------------------------------
// A light map (gobo) black on its left half (columns u < 0.5 of a 64 x 64 map) and, in a
// second map, on its top half (the file's first rows, v > 0.5: row r is at
// v = 1 - (r + 0.5)/64). Spot at the origin aiming north (+y): the light map is thrown like
// a slide projector's picture, upright and unmirrored to someone behind the light looking
// north, so its frame (Physics/SpotLight.h) is e1 = +x (east, that person's right),
// e2 = +z (up): the picture's right half (u > 0.5) lands east, its top (v > 0.5) up. A ray
// along +x crossing the beam 600 m north: the quadrature of the airlight times the hard
// cone times the map, bilinear between the columns 31 (0) and 32 (1):
// clamp(64 u - 31.5, 0, 1). Vertical rays: the west half stays exactly black, the east half
// is lit. With the second map only the lower half of the beam is lit: a vertical ray
// through the axis against the quadrature of its v ramp, and rays along +x above the axis
// (exactly black) and below it (lit).
TEST(SpotLightsPathTracer, LightMapLightsOnlyItsBrightHalf)
{
  const V position{ { 0.0, 0.0, 0.0 } }, axis{ { 0.0, 1.0, 0.0 } };
  const double cone = 25.0, intensity = 1.0e6, sigmaT = 5.0e-4, albedo = 0.8;
  nimbus::Vector3 e1, e2;
  nimbus::SpotLightMapFrame(axis, e1, e2);
  ASSERT_EQ(e1, (V{ { 1.0, 0.0, 0.0 } })); // east: the right of someone looking north
  ASSERT_EQ(e2, (V{ { 0.0, 0.0, 1.0 } })); // up
  LightDescription spot = Spot(position, axis, cone, 0.0, intensity);
  spot.LightMap.Path = "left-half-black";
  spot.LightMap.Width = spot.LightMap.Height = 64;
  spot.LightMap.Luminance.assign(64 * 64, 0.0f);
  for (int row = 0; row < 64; ++row)
  {
    for (int column = 32; column < 64; ++column)
    {
      spot.LightMap.Luminance[row * 64 + column] = 1.0f;
    }
  }
  const double spread = std::tan(cone * kDegree);
  auto u = [&](const V& w)
  { return 0.5 + 0.5 * (nimbus::Dot(w, e1) / nimbus::Dot(w, axis)) / spread; };
  auto v = [&](const V& w)
  { return 0.5 + 0.5 * (nimbus::Dot(w, e2) / nimbus::Dot(w, axis)) / spread; };
  auto ramp = [](double x) { return std::clamp(64.0 * x - 31.5, 0.0, 1.0); };
  auto render =
    [&](const LightDescription& light, const V& from, const V& to, std::uint64_t seed, int samples)
  {
    SceneDescription scene = DarkScene(from, to);
    Haze(scene, sigmaT, albedo, 0.0);
    scene.Lights = { light };
    auto context = std::make_unique<RenderContext>(scene, DensityGrid::Constant(kLo, kHi, 1.0f));
    PathTracingResult r = nimbus::RenderPathTraced(*context, Samples(samples, seed, 1));
    return std::make_pair(std::move(context), std::move(r));
  };
  // Across the beam, west to east.
  {
    const V camera{ { -1000.0, 600.0, 0.0 } }, d{ { 1.0, 0.0, 0.0 } };
    auto factor = [&](const V& w) { return AngleFromAxis(axis, w) < cone ? ramp(u(w)) : 0.0; };
    auto along = [&](double t) { return Unit(Sub(nimbus::Along(camera, d, t), position)); };
    // Steps at the cone's edges (x = +-280 m), kinks at the ends of the map's ramp.
    const double truth = PiecewiseSimpson(
      Airlight(camera, d, position, intensity, albedo * sigmaT, sigmaT, 0.0, factor),
      { { [&](double t) { return AngleFromAxis(axis, along(t)); }, { cone } },
        { [&](double t) { return 64.0 * u(along(t)); }, { 31.5, 32.5 } } },
      0.0, 4000.0, 1e-14);
    const auto result = render(spot, camera, { { 0.0, 600.0, 0.0 } }, 120, 200000);
    ExpectPixel(result.second, Rgb(*result.first, result.first->GetLightSpectra()[0], truth),
      "a ray across a beam whose light map is black on its left half");
  }
  // Vertical rays 100 m west and east of the axis: west (u < 0.5, the picture's black left
  // half as seen from behind the light) is black, east is lit.
  {
    const auto west =
      render(spot, { { -100.0, 600.0, -1000.0 } }, { { -100.0, 600.0, 0.0 } }, 121, 20000);
    const auto east =
      render(spot, { { 100.0, 600.0, -1000.0 } }, { { 100.0, 600.0, 0.0 } }, 122, 20000);
    EXPECT_EQ(west.second.Image.At(0, 0)[1], 0.0f);
    EXPECT_GT(east.second.Image.At(0, 0)[1], 0.0f);
    std::printf("vertical rays 100 m west and east of the axis: %g and %.4g\n",
      west.second.Image.At(0, 0)[1], east.second.Image.At(0, 0)[1]);
  }
  // The second map: its first 32 rows (the top of the picture, thrown up: v > 0.5) black,
  // so only v < 0.5, below the axis, is lit. Bilinear between the rows 32 (1, at
  // v = 31.5/64) and 31 (0, at v = 32.5/64): clamp(64 (1 - v) - 31.5, 0, 1).
  LightDescription topBlack = spot;
  for (int row = 0; row < 64; ++row)
  {
    for (int column = 0; column < 64; ++column)
    {
      topBlack.LightMap.Luminance[row * 64 + column] = row < 32 ? 0.0f : 1.0f;
    }
  }
  {
    const V camera{ { 0.0, 600.0, -1000.0 } }, d{ { 0.0, 0.0, 1.0 } };
    auto factor = [&](const V& w)
    { return AngleFromAxis(axis, w) < cone ? ramp(1.0 - v(w)) : 0.0; };
    auto along = [&](double t) { return Unit(Sub(nimbus::Along(camera, d, t), position)); };
    const double truth = PiecewiseSimpson(
      Airlight(camera, d, position, intensity, albedo * sigmaT, sigmaT, 0.0, factor),
      { { [&](double t) { return AngleFromAxis(axis, along(t)); }, { cone } },
        { [&](double t) { return 64.0 * v(along(t)); }, { 31.5, 32.5 } } },
      0.0, 4000.0, 1e-14);
    const auto result = render(topBlack, camera, { { 0.0, 600.0, 0.0 } }, 123, 200000);
    ExpectPixel(result.second, Rgb(*result.first, result.first->GetLightSpectra()[0], truth),
      "a vertical ray through a beam whose light map is black on its top half");
  }
  // Rays along +x 100 m above and below the axis: above (v > 0.5, the picture's black top)
  // is black, below is lit.
  {
    const auto above =
      render(topBlack, { { -1000.0, 600.0, 100.0 } }, { { 0.0, 600.0, 100.0 } }, 124, 20000);
    const auto below =
      render(topBlack, { { -1000.0, 600.0, -100.0 } }, { { 0.0, 600.0, -100.0 } }, 125, 20000);
    EXPECT_EQ(above.second.Image.At(0, 0)[1], 0.0f);
    EXPECT_GT(below.second.Image.At(0, 0)[1], 0.0f);
    std::printf("rays along +x 100 m above and below the axis: %g and %.4g\n",
      above.second.Image.At(0, 0)[1], below.second.Image.At(0, 0)[1]);
  }
}

//------------------------------------------------------------------------------
// Lambertian occluders without a medium. A box's top face lit by a point light:
// rho/pi I cos(theta) / d^2; by the sun: rho/pi E sin(elevation) (one vertex, no variance:
// 1e-6). A mesh of the box's 12 triangles gives the same pixels. A box's shadow on the
// ground is exactly black at single scattering; the lit ground is rho/pi E sin(elevation).
TEST(SpotLightsPathTracer, LambertianOccludersByLightsAndSun)
{
  const V lo{ { -50.0, -50.0, -10.0 } }, hi{ { 50.0, 50.0, 0.0 } };
  const V point{ { 10.0, 5.0, 0.0 } }, camera{ { 0.0, -30.0, 80.0 } };
  const V light{ { -20.0, 30.0, 40.0 } };
  const double rho = 0.6, intensity = 5000.0;
  // The box as 12 triangles (two per face).
  std::vector<V> triangles;
  {
    auto corner = [&](int i) {
      return V{ { i & 1 ? hi[0] : lo[0], i & 2 ? hi[1] : lo[1], i & 4 ? hi[2] : lo[2] } };
    };
    const int faces[6][4] = { { 0, 1, 3, 2 }, { 4, 5, 7, 6 }, { 0, 1, 5, 4 }, { 2, 3, 7, 6 },
      { 0, 2, 6, 4 }, { 1, 3, 7, 5 } };
    for (const auto& f : faces)
    {
      for (int k : { f[0], f[1], f[2], f[0], f[2], f[3] })
      {
        triangles.push_back(corner(k));
      }
    }
  }
  OccluderDescription mesh;
  mesh.Type = "mesh";
  mesh.Path = "box-as-triangles";
  mesh.Albedo = rho;
  // In the file's units (cm) and placed by scale and translate.
  mesh.Scale = 0.01;
  mesh.Translate = { { 1.0, 2.0, 3.0 } };
  for (const V& x : triangles)
  {
    mesh.TriangleVertices.push_back(
      { { (x[0] - 1.0) / 0.01, (x[1] - 2.0) / 0.01, (x[2] - 3.0) / 0.01 } });
  }
  for (int asMesh = 0; asMesh < 2; ++asMesh)
  {
    SceneDescription scene = DarkScene(camera, point);
    scene.Occluders = { asMesh ? mesh : Box(lo, hi, rho) };
    scene.Lights = { PointLight(light, intensity) };
    const RenderContext context(scene, DensityGrid());
    const double d = nimbus::Length(Sub(light, point));
    const double byLight = rho / kPi * intensity * (light[2] - point[2]) / d / (d * d);
    ExpectExact(nimbus::RenderPathTraced(context, Samples(64, 130, 0)),
      Rgb(context, context.GetLightSpectra()[0], byLight),
      asMesh ? "the mesh's top lit by a point light" : "a box's top lit by a point light", 1e-6);
    scene.Lights.clear();
    scene.Sun.Illuminance = 1.0;
    scene.Sun.ElevationDegrees = 40.0;
    scene.Sun.AzimuthDegrees = 200.0;
    const RenderContext sunlit(scene, DensityGrid());
    std::vector<double> e = sunlit.GetSunIrradiance();
    ExpectExact(nimbus::RenderPathTraced(sunlit, Samples(64, 131, 0)),
      Rgb(sunlit, e, rho / kPi * std::sin(40.0 * kDegree)),
      asMesh ? "the mesh's top lit by the sun" : "a box's top lit by the sun", 1e-6);
  }
  // A box above the ground casts its shadow toward the south (sun due north, 60 degrees).
  SceneDescription scene =
    DarkScene({ { 0.0, -60.0, 100.0 } }, { { 0.0, -25.0 / std::tan(60.0 * kDegree), 0.0 } });
  scene.Ground.Enabled = true;
  scene.Ground.Albedo = 0.5;
  scene.Sun.Illuminance = 1.0;
  scene.Sun.ElevationDegrees = 60.0;
  scene.Sun.AzimuthDegrees = 0.0;
  scene.Occluders = { Box({ { -10.0, -10.0, 20.0 } }, { { 10.0, 10.0, 30.0 } }, 0.7) };
  const RenderContext shadow(scene, DensityGrid());
  EXPECT_EQ(nimbus::RenderPathTraced(shadow, Samples(64, 132, 1)).Image.At(0, 0)[1], 0.0f);
  const PathTracingResult bounced = nimbus::RenderPathTraced(shadow, Samples(4000, 133, 0));
  EXPECT_GT(bounced.Image.At(0, 0)[1], 0.0f); // the box's underside, lit by the ground
  scene.Camera.FocalPoint = { { 0.0, 45.0, 0.0 } };
  const RenderContext open(scene, DensityGrid());
  ExpectExact(nimbus::RenderPathTraced(open, Samples(64, 134, 1)),
    Rgb(open, open.GetSunIrradiance(), 0.5 / kPi * std::sin(60.0 * kDegree)),
    "the ground beside the shadow", 1e-6);
}

//------------------------------------------------------------------------------
// Light that bounces off the ground onto an occluder (MaxScatteringOrder 2): a 1 m plate
// 50 m above an infinite ground of albedo rho_g lit by the sun, seen from below. The
// ground has radiance rho_g E sin(e) / pi, so the plate's lower side has radiance
// rho_p rho_g E sin(e) / pi [(1 + cos(tilt)) / 2 - F]: the view factor of the ground from
// a surface tilted by `tilt` from facing straight down, less F, the form factor to the
// plate's own shadow on the ground (Lambert's polygon formula; ~1e-4 here). A flat box
// (horizontal) and a mesh of two triangles tilted by 60 degrees toward the south, where
// the sampling of directions about the normal decides how much of the ground is seen.
TEST(SpotLightsPathTracer, PlateLitByTheGroundBelowIt)
{
  const double rhoP = 0.7, rhoG = 0.4, elevation = 50.0 * kDegree, height = 50.0;
  const V sun{ { 0.0, std::cos(elevation), std::sin(elevation) } }; // azimuth 0
  std::uint64_t seed = 140;
  for (const double tilt : { 0.0, 60.0 * kDegree })
  {
    // The plate: centre c, edges ex and ey, the seen side's normal n (down, and south).
    const V c{ { 0.0, 0.0, height } }, ex{ { 1.0, 0.0, 0.0 } };
    const V ey{ { 0.0, std::cos(tilt), -std::sin(tilt) } };
    const V n{ { 0.0, -std::sin(tilt), -std::cos(tilt) } };
    std::vector<V> corners;
    for (const auto& k : { std::make_pair(-0.5, -0.5), std::make_pair(0.5, -0.5),
           std::make_pair(0.5, 0.5), std::make_pair(-0.5, 0.5) })
    {
      corners.push_back({ { c[0] + k.first * ex[0] + k.second * ey[0],
        c[1] + k.first * ex[1] + k.second * ey[1], c[2] + k.first * ex[2] + k.second * ey[2] } });
    }
    const V seen = nimbus::Along(nimbus::Along(c, ex, 0.1), ey, 0.15);
    SceneDescription scene = DarkScene(nimbus::Along(seen, n, 40.0), seen);
    scene.Ground.Enabled = true;
    scene.Ground.Albedo = rhoG;
    scene.Sun.Illuminance = 1.0;
    scene.Sun.ElevationDegrees = 50.0;
    scene.Sun.AzimuthDegrees = 0.0;
    if (tilt == 0.0)
    {
      scene.Occluders = { Box({ { -0.5, -0.5, height } }, { { 0.5, 0.5, height } }, rhoP) };
    }
    else
    {
      OccluderDescription plate;
      plate.Type = "mesh";
      plate.Path = "tilted-plate";
      plate.Albedo = rhoP;
      plate.TriangleVertices = { corners[0], corners[1], corners[2], corners[0], corners[2],
        corners[3] };
      scene.Occluders = { plate };
    }
    const RenderContext context(scene, DensityGrid());
    // The shadow: each corner moved along -s to the ground.
    std::vector<V> shadow;
    for (const V& x : corners)
    {
      shadow.push_back(nimbus::Along(x, sun, -x[2] / sun[2]));
    }
    // Point-to-polygon form factor: F = 1/(2 pi) |sum_i angle_i n . unit(r_i x r_i+1)|.
    double sum = 0.0;
    for (std::size_t i = 0; i < shadow.size(); ++i)
    {
      const V a = Unit(Sub(shadow[i], seen)), b = Unit(Sub(shadow[(i + 1) % shadow.size()], seen));
      EXPECT_GT(nimbus::Dot(a, n), 0.0); // the whole shadow is in front of the seen side
      sum += std::acos(nimbus::Dot(a, b)) * nimbus::Dot(n, Unit(nimbus::Cross(a, b)));
    }
    const double form = std::abs(sum) / (2.0 * kPi);
    const double view = 0.5 * (1.0 + std::cos(tilt));
    const double scalar = rhoP * rhoG * std::sin(elevation) / kPi * (view - form);
    std::printf("plate tilted %.0f degrees: ground view factor %.4f, form factor to its shadow "
                "%.3g\n",
      tilt / kDegree, view, form);
    const PathTracingResult r = nimbus::RenderPathTraced(context, Samples(400000, ++seed, 2));
    ExpectPixel(r, Rgb(context, context.GetSunIrradiance(), scalar),
      tilt == 0.0 ? "a flat box's underside lit by the sunlit ground (one bounce)"
                  : "a tilted two-triangle plate lit by the sunlit ground (one bounce)");
  }
}

//------------------------------------------------------------------------------
// The bounding volume hierarchy finds what testing every primitive finds: the same
// nearest distance and normal for 20000 random rays among 3000 random triangles and 24
// boxes (flat ones, and rays starting inside boxes), and shadow rays agree.
TEST(SpotLightsPathTracer, HierarchyAgreesWithBruteForce)
{
  std::mt19937_64 random(7);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  auto point = [&](double scale)
  {
    return V{ { scale * (2 * unit(random) - 1), scale * (2 * unit(random) - 1),
      scale * (2 * unit(random) - 1) } };
  };
  nimbus::OccluderSet set;
  for (int i = 0; i < 3000; ++i)
  {
    const V a = point(100.0);
    set.AddTriangle(a, nimbus::Along(a, point(1.0), 5.0), nimbus::Along(a, point(1.0), 5.0), 0.5);
  }
  for (int i = 0; i < 24; ++i)
  {
    V a = point(100.0),
      b = nimbus::Along(a, { { unit(random), unit(random), unit(random) } }, 20.0);
    if (i % 4 == 0)
    {
      b[i % 3] = a[i % 3]; // flat
    }
    set.AddBox(a, b, 0.25);
  }
  set.Build();
  EXPECT_EQ(set.GetNumberOfTriangles(), 3000u);
  EXPECT_EQ(set.GetNumberOfBoxes(), 24u);
  int hits = 0, mismatches = 0;
  for (int i = 0; i < 20000; ++i)
  {
    const V origin = point(120.0), direction = Unit(point(1.0));
    const double tMax = i % 3 == 0 ? 50.0 : std::numeric_limits<double>::infinity();
    nimbus::OccluderHit fast, slow;
    const bool a = set.Intersect(origin, direction, tMax, fast);
    const bool b = set.IntersectBruteForce(origin, direction, tMax, slow);
    const bool shadowed = set.Occluded(origin, direction, tMax);
    hits += a ? 1 : 0;
    const bool same = a == b && shadowed == b &&
      (!a || (fast.T == slow.T && fast.Normal == slow.Normal && fast.Albedo == slow.Albedo));
    mismatches += same ? 0 : 1;
    if (a)
    {
      EXPECT_LE(nimbus::Dot(fast.Normal, direction), 0.0); // faces the ray's origin
    }
  }
  std::printf("hierarchy of %zu nodes: %d of 20000 rays hit, %d differ from brute force\n",
    set.GetNumberOfNodes(), hits, mismatches);
  EXPECT_EQ(mismatches, 0);
  EXPECT_GT(hits, 2000);
  // From inside a box: its far face, facing the origin.
  nimbus::OccluderSet box;
  box.AddBox({ { -1.0, -1.0, -1.0 } }, { { 1.0, 1.0, 1.0 } }, 0.5);
  box.Build();
  nimbus::OccluderHit hit;
  ASSERT_TRUE(box.Intersect({ { 0.0, 0.0, 0.0 } }, { { 0.0, 0.0, 1.0 } }, 10.0, hit));
  EXPECT_EQ(hit.T, 1.0);
  EXPECT_EQ(hit.Normal, (V{ { 0.0, 0.0, -1.0 } }));
  // Offset off a surface, a ray leaving it does not hit it again.
  ASSERT_TRUE(box.Intersect({ { 0.3, 0.2, 5.0 } }, { { 0.0, 0.0, -1.0 } }, 10.0, hit));
  const V off = nimbus::OffsetFromSurface({ { 0.3, 0.2, 5.0 - hit.T } }, hit.Normal);
  EXPECT_FALSE(box.Occluded(off, Unit({ { 1.0, 1.0, 0.001 } }), 100.0));
}

//------------------------------------------------------------------------------
// What the renderers refuse: a light map or a mesh named but not read, light maps whose
// pixels do not fit their size or are NaN, an empty mesh; the single-scattering renderer
// refuses spots and occluders by name. SampleLightMap's conventions.
TEST(SpotLightsPathTracer, MissingAssetsAndSingleScatteringAreRefused)
{
  auto expectError = [](const SceneDescription& scene, const std::string& text)
  {
    try
    {
      const RenderContext context(scene, DensityGrid());
      ADD_FAILURE() << "no error; expected " << text;
    }
    catch (const std::invalid_argument& error)
    {
      EXPECT_NE(std::string(error.what()).find(text), std::string::npos) << error.what();
    }
  };
  SceneDescription scene = DarkScene({ { 0.0, -10.0, 0.0 } }, { { 0.0, 0.0, 0.0 } });
  LightDescription spot = Spot({ { 0.0, 0.0, 5.0 } }, { { 0.0, 0.0, -1.0 } }, 30.0, 5.0, 100.0);
  spot.LightMap.Path = "/nowhere/gobo.png";
  scene.Lights = { spot };
  expectError(scene,
    "scene: lights[0].light_map names an image the renderer was not given ('/nowhere/gobo.png'");
  scene.Lights[0].LightMap.Width = 2;
  scene.Lights[0].LightMap.Height = 2;
  scene.Lights[0].LightMap.Luminance = { 1.0f, 1.0f, 1.0f };
  expectError(scene, "scene: lights[0].light_map has 3 values for 2 x 2 pixels");
  scene.Lights[0].LightMap.Luminance = { 1.0f, std::nanf(""), -1.0f, 0.5f };
  expectError(scene, "scene: lights[0].light_map has 2 NaN, infinite or negative luminance values");
  scene.Lights[0].LightMap = {};
  scene.Lights[0].Direction = { { 0.0, 0.0, 0.0 } };
  expectError(scene, "scene: lights[0].direction must be a finite, non-zero vector");
  scene.Lights[0].Direction = { { 0.0, 0.0, -1.0 } };
  scene.Lights[0].ConeAngleDegrees = 90.0;
  expectError(scene, "scene: lights[0].cone_angle_degrees must be in (0, 90)");
  scene.Lights[0].ConeAngleDegrees = 30.0;
  OccluderDescription mesh;
  mesh.Type = "mesh";
  mesh.Path = "/nowhere/post.ply";
  scene.Occluders = { mesh };
  expectError(
    scene, "scene: occluders[0].path names a mesh whose triangles the renderer was not given");
  scene.Occluders[0].TriangleVertices = { { { 0, 0, 0 } }, { { 1, 0, 0 } }, { { 2, 0, 0 } } };
  expectError(scene, "scene: occluders[0].path has no triangle of non-zero area");
  scene.Occluders[0].TriangleVertices = { { { 0, 0, 0 } }, { { 1, 0, 0 } } };
  expectError(scene, "scene: occluders[0].path has 2 triangle vertices, not a multiple of 3");
  scene.Occluders = { Box({ { 0, 0, 0 } }, { { 1, -1, 1 } }, 0.5) };
  expectError(scene, "scene: occluders[0].max must be finite and >= min on every axis");
  // The single-scattering renderer names what it does not render.
  scene.Occluders = { Box({ { -1, -1, -1 } }, { { 1, 1, 1 } }, 0.5) };
  const RenderContext context(scene, DensityGrid());
  try
  {
    nimbus::RenderSingleScattering(context, nimbus::SingleScatteringSettings{});
    ADD_FAILURE() << "no error";
  }
  catch (const std::invalid_argument& error)
  {
    EXPECT_NE(std::string(error.what())
                .find("the single-scattering renderer does not render point, polyline and spot "
                      "lights (scene.lights), occluders (scene.occluders); render this scene "
                      "with the path tracer"),
      std::string::npos)
      << error.what();
  }
  // Light map sampling: pixel centres, bilinear between them, clamped to the edge pixels
  // inside [0, 1]^2, 0 outside; row 0 (the file's first row, the picture's top) at
  // v = 1 - 0.5 / Height, the last row at v = 0.5 / Height; column 0 at u = 0.5 / Width.
  nimbus::LightMapDescription map;
  map.Width = 2;
  map.Height = 2;
  map.Luminance = { 0.0f, 1.0f, 2.0f, 3.0f }; // row 0 (top, v = 0.75): 0 1; row 1: 2 3
  EXPECT_DOUBLE_EQ(nimbus::SampleLightMap(map, 0.25, 0.25), 2.0); // bottom left: row 1
  EXPECT_DOUBLE_EQ(nimbus::SampleLightMap(map, 0.75, 0.25), 3.0); // bottom right: row 1
  EXPECT_DOUBLE_EQ(nimbus::SampleLightMap(map, 0.25, 0.75), 0.0); // top left: row 0
  EXPECT_DOUBLE_EQ(nimbus::SampleLightMap(map, 0.75, 0.75), 1.0); // top right: row 0
  EXPECT_DOUBLE_EQ(nimbus::SampleLightMap(map, 0.5, 0.5), 1.5);
  EXPECT_DOUBLE_EQ(nimbus::SampleLightMap(map, 0.0, 0.0), 2.0); // the bottom-left corner
  EXPECT_DOUBLE_EQ(nimbus::SampleLightMap(map, 1.0, 1.0), 1.0); // the top-right corner
  // A quarter of the way from row 0 (mean 0.5) down to row 1 (mean 2.5).
  EXPECT_DOUBLE_EQ(nimbus::SampleLightMap(map, 0.5, 0.625), 1.0);
  EXPECT_DOUBLE_EQ(nimbus::SampleLightMap(map, 0.9, 0.5), 2.0);
  EXPECT_EQ(nimbus::SampleLightMap(map, 1.0001, 0.5), 0.0);
  EXPECT_EQ(nimbus::SampleLightMap(map, 0.5, -0.0001), 0.0);
}

//------------------------------------------------------------------------------
// The speed techniques (BlockTraversal, SunDepthRoulette, SunPeakSampling,
// TabulatedAirTransmittance, AdaptiveSampling, EquiAngularLightSampling) stay unbiased with
// every version-4 feature:
// a cloud lit by the sun and by a searchlight from below through a light map, a
// streetlight's spot, a box and a mesh (a post) casting shadows, air and ground. All on
// against all off: z of each pixel channel's difference and of the image sum.
TEST(SpotLightsPathTracer, SpeedTechniquesStayUnbiasedWithVersion4Features)
{
  const V lo{ { -400.0, -400.0, 800.0 } };
  const std::array<int, 3> dims{ { 9, 9, 7 } };
  const V spacing{ { 100.0, 100.0, 100.0 } };
  std::vector<float> cloud;
  for (int k = 0; k < 7; ++k)
    for (int j = 0; j < 9; ++j)
      for (int i = 0; i < 9; ++i)
      {
        const double x = (i - 4) / 4.0, y = (j - 4) / 4.0, z = (k - 3) / 3.0;
        cloud.push_back(static_cast<float>(
          std::max(0.0, 1.0 - x * x - y * y - z * z) * (1.0 + 0.5 * ((i + j) % 3))));
      }
  SceneDescription scene = DarkScene({ { 0.0, -2500.0, 600.0 } }, { { 0.0, 0.0, 900.0 } });
  scene.Camera.Width = 12;
  scene.Camera.Height = 8;
  scene.Camera.ViewAngle = 40.0;
  scene.Atmosphere.Enabled = true;
  scene.Atmosphere.MieScatteringPerMetre = 1e-4;
  scene.Ground.Enabled = true;
  scene.Background.Type = "atmosphere";
  scene.Sun.Illuminance = 0.2;
  scene.Sun.AzimuthDegrees = 30.0;
  scene.Sun.ElevationDegrees = 15.0;
  scene.SpectralSamples = 8;
  scene.Medium.ExtinctionPerDensity = 0.01;
  scene.Medium.SingleScatteringAlbedo = 0.99;
  scene.Medium.Phase = { { "henyey_greenstein", 0.85, 1.0 } };
  LightDescription searchlight =
    Spot({ { 100.0, -300.0, 5.0 } }, { { 0.0, 0.3, 1.0 } }, 4.0, 1.0, 5.0e7);
  searchlight.LightMap.Width = 3;
  searchlight.LightMap.Height = 2;
  searchlight.LightMap.Luminance = { 1.0f, 0.2f, 0.0f, 0.5f, 1.0f, 0.7f };
  scene.Lights = { searchlight,
    Spot({ { -200.0, -1500.0, 12.0 } }, { { 0.2, 0.1, -1.0 } }, 40.0, 10.0, 2.0e5),
    PointLight({ { 300.0, -1200.0, 30.0 } }, 1.0e5) };
  OccluderDescription post;
  post.Type = "mesh";
  post.Albedo = 0.3;
  post.Translate = { { -230.0, -1540.0, 0.0 } };
  for (const V& x :
    std::vector<V>{ { { 0, 0, 0 } }, { { 3, 0, 0 } }, { { 0, 0, 15 } }, { { 3, 0, 0 } },
      { { 3, 0, 15 } }, { { 0, 0, 15 } }, { { 0, 0, 0 } }, { { 0, 3, 0 } }, { { 0, 0, 15 } } })
  {
    post.TriangleVertices.push_back(x);
  }
  scene.Occluders = { post, Box({ { 150.0, -1000.0, 0.0 } }, { { 260.0, -900.0, 80.0 } }, 0.5),
    // A black plate over the east half of the searchlight's beam.
    Box({ { 100.0, -320.0, 10.0 } }, { { 140.0, -280.0, 10.0 } }, 0.0) };
  const RenderContext context(scene, DensityGrid(dims, lo, spacing, cloud));
  const PathTracingResult off = RenderWithTechniques(context, false, 151, true);
  const PathTracingResult on = RenderWithTechniques(context, true, 152, true);
  const nimbus_test::ImageAgreement agreement = nimbus_test::CompareMonteCarloImages(on, off);
  EXPECT_TRUE(agreement.Finite);
  std::printf("version-4 scene, techniques on vs off: RMS z %.3f over %d pixel channels, %d "
              "beyond 4 sigma; image sum z %.2f, its relative se %.2f %% (%.1f s and %.1f s)\n",
    agreement.RmsZ, agreement.Count, agreement.Outliers, agreement.ImageSumZ,
    100.0 * agreement.ImageSumRelativeError, on.Seconds, off.Seconds);
  EXPECT_EQ(agreement.Count, 3 * 12 * 8);
  EXPECT_LE(agreement.Outliers, 2);
  EXPECT_LT(std::abs(agreement.ImageSumZ), 4.0);
  EXPECT_GT(agreement.RmsZ, 0.75);
  EXPECT_LT(agreement.RmsZ, 1.3);
}

//------------------------------------------------------------------------------
// A point light in the exponential atmosphere (the haze of the project's night scenes is
// its aerosols): single scattering along a nearly horizontal ray 10 m above sea level,
// per wavelength sample the quadrature of
//   I S(lambda) [beta_R(lambda) rho_R p_R(mu) + beta_M rho_M p_M(mu)] T(camera, x) T(x, light) /
//   d^2,
// the transmittances from Atmosphere::OpticalLength (adaptive Gauss-Kronrod), the path
// tracer's toward the light from its 8-point Gauss-Legendre rule (LightAirTransmittance).
TEST(SpotLightsPathTracer, PointLightInTheAir)
{
  const V camera{ { 0.0, -100.0, 10.0 } }, light{ { 15.0, 40.0, 25.0 } };
  const double intensity = 1.0e4;
  SceneDescription scene = DarkScene(camera, { { 0.0, 0.0, 10.0 } });
  scene.Atmosphere.Enabled = true;
  scene.Atmosphere.MieScatteringPerMetre = 2.0e-3; // a haze of 2 km visibility
  scene.Lights = { PointLight(light, intensity) };
  const RenderContext context(scene, DensityGrid());
  const PathTracingResult r = nimbus::RenderPathTraced(context, Samples(200000, 160, 1));
  const nimbus::Atmosphere& air = *context.GetAtmosphere();
  const nimbus::AtmosphereParameters& a = air.GetParameters();
  const std::vector<double>& lambda = context.GetWavelengths();
  const std::vector<double>& betaR = context.GetRayleighScatteringSeaLevel();
  const double betaM = context.GetMieScatteringSeaLevel();
  const V d{ { 0.0, 1.0, 0.0 } };
  auto lengths = [&](const V& from, const V& to)
  {
    nimbus::OpticalLengths l;
    const V q0 = context.EarthCentred(from), q1 = context.EarthCentred(to);
    l.RayleighLengthMetres = air.OpticalLength(q0, q1, a.RayleighScaleHeightMetres);
    l.MieLengthMetres = air.OpticalLength(q0, q1, a.MieScaleHeightMetres);
    return l;
  };
  std::vector<double> spectrum(lambda.size(), 0.0);
  for (std::size_t i = 0; i < lambda.size(); ++i)
  {
    auto integrand = [&](double t)
    {
      const V x = nimbus::Along(camera, d, t);
      const V toLight = Sub(light, x);
      const double r2 = nimbus::Dot(toLight, toLight);
      const double mu = toLight[1] / std::sqrt(r2);
      const double h = air.Altitude(context.EarthCentred(x));
      const double scattering =
        betaR[i] * air.Density(h, a.RayleighScaleHeightMetres) * air.RayleighPhase(mu) +
        betaM * air.Density(h, a.MieScaleHeightMetres) * air.MiePhase(mu);
      return scattering * air.Transmittance(lengths(camera, x), lambda[i]) *
        air.Transmittance(lengths(x, light), lambda[i]) / r2;
    };
    // Beyond 30 km the haze's optical depth (60) leaves nothing.
    spectrum[i] = intensity * context.GetLightSpectra()[0][i] *
      (Simpson(integrand, 0.0, 140.0, 1e-13) + Simpson(integrand, 140.0, 1000.0, 1e-13) +
        Simpson(integrand, 1000.0, 30000.0, 1e-13));
  }
  ExpectPixel(r, context.ToLinearSrgb(spectrum),
    "a point light in hazy air, quadrature with the exact optical lengths");
}

//------------------------------------------------------------------------------
// Twilight: the sun 2 degrees below the horizon lights a cloud's upper part (above ~3.9 km
// the earth no longer hides it) and not its lower part, where the tracer skips the sun's
// estimate and the sun-peak strategy (SunHidden). All speed techniques on against all off.
TEST(SpotLightsPathTracer, TwilightCloudTechniquesAgree)
{
  const V lo{ { -1000.0, -1000.0, 3000.0 } };
  const std::array<int, 3> dims{ { 9, 9, 7 } };
  const V spacing{ { 250.0, 250.0, 300.0 } };
  std::vector<float> cloud;
  for (int k = 0; k < 7; ++k)
    for (int j = 0; j < 9; ++j)
      for (int i = 0; i < 9; ++i)
      {
        const double x = (i - 4) / 4.0, y = (j - 4) / 4.0, z = (k - 3) / 3.0;
        cloud.push_back(static_cast<float>(std::max(0.0, 1.0 - x * x - y * y - z * z)));
      }
  SceneDescription scene = DarkScene({ { 0.0, -9000.0, 3500.0 } }, { { 0.0, 0.0, 3900.0 } });
  scene.Camera.Width = 12;
  scene.Camera.Height = 8;
  scene.Camera.ViewAngle = 25.0;
  scene.Atmosphere.Enabled = true;
  scene.Ground.Enabled = true;
  scene.Background.Type = "atmosphere";
  scene.Sun.Illuminance = 1.0;
  scene.Sun.AzimuthDegrees = 10.0;
  scene.Sun.ElevationDegrees = -2.0;
  scene.SpectralSamples = 8;
  scene.Medium.ExtinctionPerDensity = 0.004;
  scene.Medium.SingleScatteringAlbedo = 0.99;
  scene.Medium.Phase = { { "henyey_greenstein", 0.85, 1.0 } };
  const RenderContext context(scene, DensityGrid(dims, lo, spacing, cloud));
  const PathTracingResult off = RenderWithTechniques(context, false, 171, false);
  const PathTracingResult on = RenderWithTechniques(context, true, 172, false);
  const nimbus_test::ImageAgreement agreement = nimbus_test::CompareMonteCarloImages(on, off);
  double sum = 0.0;
  for (float x : on.Image.Pixels)
  {
    sum += x;
  }
  std::printf("twilight cloud, techniques on vs off: RMS z %.3f over %d pixel channels, %d "
              "beyond 4 sigma; image sum %.4g, z %.2f, its relative se %.2f %%\n",
    agreement.RmsZ, agreement.Count, agreement.Outliers, sum, agreement.ImageSumZ,
    100.0 * agreement.ImageSumRelativeError);
  EXPECT_GT(sum, 0.0);
  EXPECT_EQ(agreement.Count, 3 * 12 * 8);
  EXPECT_LE(agreement.Outliers, 2);
  EXPECT_LT(std::abs(agreement.ImageSumZ), 4.0);
  EXPECT_GT(agreement.RmsZ, 0.75);
  EXPECT_LT(agreement.RmsZ, 1.3);
}

//------------------------------------------------------------------------------
// Equi-angular sampling of the lights, combined with the collisions' estimate by the
// balance heuristic, against the collisions alone: lights beside a heterogeneous two-medium
// cloud in hazy air (a point light 300 m from it, a spot through a light map aimed at it,
// a lightning channel through it, which the equi-angular strategy leaves to the
// collisions), at full multiple scattering; 8 x 6 pixels, z of each pixel channel's
// difference and of the image sum, and their RMS standard errors. (A point light inside a
// forward-scattering cloud is a poor test: the collisions' estimate on segments heading
// straight at the light keeps its 1/d^2 tail, which no sampling along the segment
// removes, and a few such samples decide both images' errors.)
TEST(SpotLightsPathTracer, EquiAngularSamplingAgreesWithCollisionsAlone)
{
  const V lo{ { -400.0, -400.0, 800.0 } };
  const std::array<int, 3> dims{ { 9, 9, 7 } };
  const V spacing{ { 100.0, 100.0, 100.0 } };
  std::vector<float> cloud, smoke;
  for (int k = 0; k < 7; ++k)
    for (int j = 0; j < 9; ++j)
      for (int i = 0; i < 9; ++i)
      {
        const double x = (i - 4) / 4.0, y = (j - 4) / 4.0, z = (k - 3) / 3.0;
        cloud.push_back(static_cast<float>(std::max(0.0, 1.0 - x * x - y * y - z * z)));
        smoke.push_back(
          static_cast<float>(0.5 * std::max(0.0, 0.8 - (x - 0.3) * (x - 0.3) - y * y)));
      }
  SceneDescription scene = DarkScene({ { 0.0, -2500.0, 1100.0 } }, { { 0.0, 0.0, 1100.0 } });
  scene.Camera.Width = 8;
  scene.Camera.Height = 6;
  scene.Camera.ViewAngle = 25.0;
  scene.Atmosphere.Enabled = true;
  scene.Atmosphere.MieScatteringPerMetre = 3e-4;
  scene.Ground.Enabled = true;
  scene.SpectralSamples = 6;
  scene.Medium.ExtinctionPerDensity = 0.01;
  scene.Medium.SingleScatteringAlbedo = 0.97;
  scene.Medium.Phase = { { "henyey_greenstein", 0.8, 1.0 } };
  nimbus::AdditionalMediumDescription second;
  second.ExtinctionPerDensity = 0.02;
  second.SingleScatteringAlbedo = 0.6;
  second.Phase = { { "isotropic", 0.0, 1.0 } };
  scene.Media = { second };
  LightDescription spot =
    Spot({ { -300.0, -900.0, 300.0 } }, { { 0.3, 0.9, 0.8 } }, 8.0, 2.0, 4.0e6);
  spot.LightMap.Width = spot.LightMap.Height = 2;
  spot.LightMap.Luminance = { 1.0f, 0.1f, 0.5f, 1.0f };
  LightDescription channel;
  channel.Type = "polyline";
  channel.Vertices = { { { 200.0, 100.0, 2200.0 } }, { { 150.0, 50.0, 1000.0 } },
    { { 250.0, 80.0, 0.0 } } };
  channel.IntensityPerMetre = 200.0;
  channel.TemperatureKelvin = 20000.0;
  scene.Lights = { PointLight({ { -100.0, -700.0, 1000.0 } }, 2.0e5), spot, channel };
  nimbus::SceneFields fields;
  fields.MediaDensities.push_back(DensityGrid(dims, lo, spacing, smoke));
  const RenderContext context(scene, DensityGrid(dims, lo, spacing, cloud), std::move(fields));
  auto render = [&](bool equiAngular, std::uint64_t seed)
  {
    PathTracingSettings settings = Samples(4096, seed, 0);
    settings.EquiAngularLightSampling = equiAngular;
    return nimbus::RenderPathTraced(context, settings);
  };
  const PathTracingResult with = render(true, 181), without = render(false, 182);
  const nimbus_test::ImageAgreement agreement = nimbus_test::CompareMonteCarloImages(with, without);
  double seWith = 0.0, seWithout = 0.0;
  for (std::size_t i = 0; i < with.StandardError.Pixels.size(); ++i)
  {
    seWith += with.StandardError.Pixels[i] * with.StandardError.Pixels[i];
    seWithout += without.StandardError.Pixels[i] * without.StandardError.Pixels[i];
  }
  std::printf("equi-angular and collisions vs collisions alone: RMS z %.3f over %d pixel "
              "channels, %d beyond 4 sigma; image sum z %.2f (relative se %.2f %%); RMS "
              "standard error %.3g vs %.3g (%.1f s and %.1f s)\n",
    agreement.RmsZ, agreement.Count, agreement.Outliers, agreement.ImageSumZ,
    100.0 * agreement.ImageSumRelativeError, std::sqrt(seWith), std::sqrt(seWithout), with.Seconds,
    without.Seconds);
  EXPECT_TRUE(agreement.Finite);
  EXPECT_EQ(agreement.Count, 3 * 8 * 6);
  EXPECT_LE(agreement.Outliers, 2);
  EXPECT_LT(std::abs(agreement.ImageSumZ), 4.0);
  EXPECT_GT(agreement.RmsZ, 0.7);
  EXPECT_LT(agreement.RmsZ, 1.3);
}
