// Version-3 scenes in the path tracer (PathTracer.h): point lights and emitting
// polylines by next-event estimation, per-voxel emission, several media with their own
// albedo and phase. Each against a closed form (or a 1-D quadrature of one) with the
// estimator's own standard error: |mean - truth| <= 4 se per channel, and the z-scores
// printed. Scenes are a single pixel (or a few) seen along the pixel centre, with no
// sun, no atmosphere, a black background, so that only the feature under test lights
// the pixel.
#include "BlackbodyEmission.h"
#include "LightsSceneTesting.h"
#include "Math.h"
#include "MonteCarloAgreement.h"
#include "PathTracer.h"
#include "PhaseFunctions.h"
#include "SingleScatteringRenderer.h"
#include "Sun.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

namespace
{
using nimbus::DensityGrid;
using nimbus::kPi;
using nimbus::LightDescription;
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

LightDescription PointLight(const V& position, double intensity, double kelvin = 6500.0)
{
  LightDescription light;
  light.Type = "point";
  light.Position = position;
  light.Intensity = intensity;
  light.TemperatureKelvin = kelvin;
  return light;
}

LightDescription Polyline(const std::vector<V>& vertices, double perMetre)
{
  LightDescription light;
  light.Type = "polyline";
  light.Vertices = vertices;
  light.IntensityPerMetre = perMetre;
  light.TemperatureKelvin = 6500.0;
  return light;
}

/// Length of the segment [a, b] inside the box [lo, hi] (slab method).
double LengthInBox(const V& a, const V& b, const V& lo, const V& hi)
{
  double t0 = 0.0, t1 = 1.0;
  for (int k = 0; k < 3; ++k)
  {
    const double d = b[k] - a[k];
    if (d == 0.0)
    {
      if (a[k] < lo[k] || a[k] > hi[k])
      {
        return 0.0;
      }
      continue;
    }
    double u0 = (lo[k] - a[k]) / d, u1 = (hi[k] - a[k]) / d;
    if (u0 > u1)
    {
      std::swap(u0, u1);
    }
    t0 = std::max(t0, u0);
    t1 = std::min(t1, u1);
  }
  const V ab{ { b[0] - a[0], b[1] - a[1], b[2] - a[2] } };
  return t1 > t0 ? (t1 - t0) * nimbus::Length(ab) : 0.0;
}

double Distance(const V& a, const V& b)
{
  return std::sqrt(
    (a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}

double HenyeyGreenstein(double mu, double g)
{
  return (1.0 - g * g) / (4.0 * kPi * std::pow(1.0 + g * g - 2.0 * g * mu, 1.5));
}
} // namespace

//------------------------------------------------------------------------------
// (a) A Lambertian ground lit only by a point light through a purely absorbing box:
//   L = rho/pi I cos(theta) / d^2 exp(-sigma_t l_light) exp(-sigma_t l_camera),
// l the lengths of the light's and the camera's paths inside the box (single scattering:
// the ground vertex only, MaxScatteringOrder 1; the absorber scatters nothing anyway).
TEST(LightsPathTracer, PointLightOnGroundThroughAbsorber)
{
  const V camera{ { 0.0, 0.0, 200.0 } }, ground{ { 0.0, 0.0, 0.0 } };
  SceneDescription scene = DarkScene(camera, ground);
  scene.Ground.Enabled = true;
  scene.Ground.Albedo = 0.5;
  scene.Medium.ExtinctionPerDensity = 0.01; // 1/m: tau 0.5 over the 50 m box
  scene.Medium.SingleScatteringAlbedo = 0.0;
  const V light{ { 60.0, 20.0, 90.0 } };
  const double intensity = 2000.0;
  scene.Lights = { PointLight(light, intensity, 4000.0) };
  const V lo{ { -100.0, -100.0, 10.0 } }, hi{ { 100.0, 100.0, 60.0 } };
  const RenderContext context(scene, DensityGrid::Constant(lo, hi, 1.0f));
  const PathTracingResult r = nimbus::RenderPathTraced(context, Samples(200000, 3, 1));
  const double d = Distance(light, ground);
  const double scalar = 0.5 / kPi * intensity * (light[2] / d) / (d * d) *
    std::exp(-0.01 * LengthInBox(light, ground, lo, hi)) *
    std::exp(-0.01 * LengthInBox(camera, ground, lo, hi));
  ExpectPixel(r, 0, 0, Rgb(context, context.GetLightSpectra()[0], scalar),
    "point light on the ground through an absorber");
  // Nothing else lights the pixel: without the light it is black.
  scene.Lights.clear();
  const RenderContext dark(scene, DensityGrid::Constant(lo, hi, 1.0f));
  const PathTracingResult black = nimbus::RenderPathTraced(dark, Samples(1000, 3, 1));
  EXPECT_EQ(black.Image.At(0, 0)[1], 0.0f);
}

//------------------------------------------------------------------------------
// (b) Single-scattered light along a camera ray through a thin homogeneous medium lit by
// a point light inside it (MaxScatteringOrder 1: exact):
//   L = int_{t_n}^{t_f} sum_i sigma_s,i p_i(mu(t)) I exp(-sigma_t (t - t_n + d(t))) / d(t)^2 dt,
// mu = dot(toward the light, ray direction) (the light propagates from the light to x and
// leaves toward the camera), evaluated by adaptive Simpson quadrature. Henyey-Greenstein
// g = 0.6 makes the sign of mu matter (forward scattering toward the camera is brighter
// where the light is behind the scattering point). With two media of different albedos
// and phases (a second, isotropic, medium on the same grid), the same with the sum.
TEST(LightsPathTracer, PointLightInScatteringThinMedium)
{
  const V camera{ { 0.0, -2000.0, 500.0 } }, focus{ { 0.0, 0.0, 500.0 } };
  const V lo{ { -500.0, -500.0, 0.0 } }, hi{ { 500.0, 500.0, 1000.0 } };
  const V light{ { 80.0, 150.0, 530.0 } };
  const double intensity = 5.0e4;
  for (int media = 1; media <= 2; ++media)
  {
    SceneDescription scene = DarkScene(camera, focus);
    scene.Medium.ExtinctionPerDensity = 4.0e-4; // tau 0.4 across the box
    scene.Medium.SingleScatteringAlbedo = 0.9;
    scene.Medium.Phase = { { "henyey_greenstein", 0.6, 1.0 } };
    scene.Lights = { PointLight(light, intensity, 5000.0) };
    nimbus::SceneFields fields;
    const double s2 = 6.0e-4, a2 = 0.5;
    if (media == 2)
    {
      nimbus::AdditionalMediumDescription second;
      second.Density.Type = "file";
      second.ExtinctionPerDensity = s2;
      second.SingleScatteringAlbedo = a2;
      second.Phase = { { "isotropic", 0.0, 1.0 } };
      scene.Media = { second };
      fields.MediaDensities.push_back(DensityGrid::Constant(lo, hi, 1.0f));
    }
    const RenderContext context(scene, DensityGrid::Constant(lo, hi, 1.0f), std::move(fields));
    const PathTracingResult r = nimbus::RenderPathTraced(context, Samples(400000, 7, 1));
    const double sigmaT = 4.0e-4 + (media == 2 ? s2 : 0.0);
    const double tNear = 1500.0, tFar = 2500.0; // the ray crosses y in [-500, 500]
    auto integrand = [&](double t)
    {
      const V x{ { camera[0], camera[1] + t, camera[2] } };
      const double d = Distance(x, light);
      const double mu = (light[1] - x[1]) / d; // dot(toward the light, +y)
      double scattering = 0.9 * 4.0e-4 * HenyeyGreenstein(mu, 0.6);
      if (media == 2)
      {
        scattering += a2 * s2 / (4.0 * kPi);
      }
      return scattering * intensity * std::exp(-sigmaT * (t - tNear + d)) / (d * d);
    };
    const double scalar = Simpson(integrand, tNear, tFar, 1e-12);
    ExpectPixel(r, 0, 0, Rgb(context, context.GetLightSpectra()[0], scalar),
      media == 1 ? "point light in a thin HG medium (single scattering)"
                 : "point light in two media, HG and isotropic (single scattering)");
  }
}

//------------------------------------------------------------------------------
// Polylines (a lightning channel) on the Lambertian ground, no medium:
//   L = rho/pi int I_l z(l) / r(l)^3 dl (cos theta = z / r),
// by quadrature; a 1 m segment equals the point light of the same total intensity at
// its middle (far field: the difference is O((l/d)^2) ~ 1e-5, far below the noise); a
// channel of N collinear segments equals the same channel as one segment (two
// independent renders, z of their difference).
TEST(LightsPathTracer, PolylineLightsTheGround)
{
  const V camera{ { 0.0, 0.0, 100.0 } }, ground{ { 0.0, 0.0, 0.0 } };
  SceneDescription scene = DarkScene(camera, ground);
  scene.Ground.Enabled = true;
  scene.Ground.Albedo = 0.8;
  const V a{ { -150.0, 40.0, 300.0 } }, b{ { 120.0, -30.0, 60.0 } };
  const double perMetre = 500.0;
  scene.Lights = { Polyline({ a, b }, perMetre) };
  const RenderContext one(scene, DensityGrid());
  const PathTracingResult r1 = nimbus::RenderPathTraced(one, Samples(200000, 11, 1));
  const double length = Distance(a, b);
  auto integrand = [&](double u)
  {
    const V y{ { a[0] + u * (b[0] - a[0]), a[1] + u * (b[1] - a[1]), a[2] + u * (b[2] - a[2]) } };
    const double r = Distance(y, ground);
    return perMetre * length * y[2] / (r * r * r);
  };
  const double scalar = 0.8 / kPi * Simpson(integrand, 0.0, 1.0, 1e-12);
  ExpectPixel(r1, 0, 0, Rgb(one, one.GetLightSpectra()[0], scalar), "polyline on the ground");

  // The same channel in 5 collinear pieces of unequal lengths.
  std::vector<V> pieces;
  for (double u : { 0.0, 0.1, 0.35, 0.4, 0.8, 1.0 })
  {
    pieces.push_back(
      { { a[0] + u * (b[0] - a[0]), a[1] + u * (b[1] - a[1]), a[2] + u * (b[2] - a[2]) } });
  }
  scene.Lights = { Polyline(pieces, perMetre) };
  const RenderContext five(scene, DensityGrid());
  const PathTracingResult r5 = nimbus::RenderPathTraced(five, Samples(200000, 12, 1));
  ExpectPixel(
    r5, 0, 0, Rgb(five, five.GetLightSpectra()[0], scalar), "the polyline in 5 collinear pieces");
  const double difference = r5.Image.At(0, 0)[1] - r1.Image.At(0, 0)[1];
  const double se = std::hypot(r5.StandardError.At(0, 0)[1], r1.StandardError.At(0, 0)[1]);
  std::printf("5 pieces - 1 segment: z %.2f\n", difference / se);
  EXPECT_LT(std::abs(difference / se), 4.0);

  // A 1 m segment against a point light of its total intensity at its middle.
  const V m{ { 30.0, 10.0, 200.0 } };
  scene.Lights = { Polyline(
    { { { m[0] - 0.3, m[1], m[2] - 0.4 } }, { { m[0] + 0.3, m[1], m[2] + 0.4 } } }, 1000.0) };
  const RenderContext shortSegment(scene, DensityGrid());
  const PathTracingResult rs = nimbus::RenderPathTraced(shortSegment, Samples(20000, 13, 1));
  const double d = Distance(m, ground);
  const double pointScalar = 0.8 / kPi * 1000.0 * (m[2] / d) / (d * d);
  const double g = rs.Image.At(0, 0)[1];
  const double truth = Rgb(shortSegment, shortSegment.GetLightSpectra()[0], pointScalar)[1];
  const double relativeSe = rs.StandardError.At(0, 0)[1] / g;
  std::printf("1 m segment vs point light: relative difference %.2e (se %.1e)\n", g / truth - 1.0,
    relativeSe);
  // The segment's samples differ by ~0.6 % (its ends are 0.4 m nearer and farther): se
  // ~2.5e-5 relative at 20000 samples; the far-field difference is O((l/d)^2) ~ 1e-5.
  EXPECT_LT(std::abs(g / truth - 1.0), 4.0 * relativeSe + 2e-5);
}

//------------------------------------------------------------------------------
// Emission. A homogeneous, purely absorbing (albedo 0) box of sigma_a = k rho emitting
// eta = s rho (Y/(sr m), "from_density"), seen head on through its length D:
//   L = int_0^D eta exp(-sigma_a t) dt = (eta / sigma_a) (1 - exp(-sigma_a D)).
// And a field that emits without attenuating ("array" emission, extinction 0):
//   L = eta D (the majorant floor of the emitting blocks makes the estimator see it).
TEST(LightsPathTracer, EmittingAbsorbingBox)
{
  const V camera{ { 0.0, -300.0, 50.0 } }, focus{ { 0.0, 0.0, 50.0 } };
  const V lo{ { -100.0, -100.0, 0.0 } }, hi{ { 100.0, 100.0, 100.0 } };
  SceneDescription scene = DarkScene(camera, focus);
  scene.Medium.Density.Type = "file";
  scene.Medium.ExtinctionPerDensity = 0.005; // tau 1 over D = 200 m
  scene.Medium.SingleScatteringAlbedo = 0.0;
  scene.Medium.Emission = { true, "from_density", "", 0.02, 1800.0 };
  const float rho = 1.5f;
  {
    const RenderContext context(scene, DensityGrid::Constant(lo, hi, rho));
    const PathTracingResult r = nimbus::RenderPathTraced(context, Samples(100000, 17, 0));
    const double sigmaA = 0.005 * rho, eta = 0.02 * rho;
    const double scalar = eta / sigmaA * (1.0 - std::exp(-sigmaA * 200.0));
    ExpectPixel(r, 0, 0, Rgb(context, context.GetMedia()[0].EmissionSpectrum, scalar),
      "emitting absorbing box");
  }
  {
    SceneDescription glow = scene;
    glow.Medium.ExtinctionPerDensity = 0.0;
    glow.Medium.Emission = { true, "array", "heat", 0.02, 1800.0 };
    nimbus::SceneFields fields;
    fields.Emission = DensityGrid::Constant(lo, hi, 3.0f);
    const RenderContext context(glow, DensityGrid::Constant(lo, hi, rho), std::move(fields));
    const PathTracingResult r = nimbus::RenderPathTraced(context, Samples(100000, 19, 0));
    ExpectPixel(r, 0, 0, Rgb(context, context.GetMedia()[0].EmissionSpectrum, 0.02 * 3.0 * 200.0),
      "emitting field without extinction");
  }
}

//------------------------------------------------------------------------------
// "blackbody" emission (hot smoke, Planck's law): the same absorbing box with a temperature
// field T; eta(lambda) = s rho B(lambda, T) / Y[B(T_ref)] (Physics/BlackbodyEmission.h),
// so L = (eta / sigma_a)(1 - exp(-sigma_a D)) with the spectrum of B(T) scaled by its
// luminance ratio: at T = T_ref the luminance is that of "from_density" at T_ref, at
// 2000 K 60 times more (BlackbodyEmission's figure), bluer.
TEST(LightsPathTracer, BlackbodyEmittingBox)
{
  const V camera{ { 0.0, -300.0, 50.0 } }, focus{ { 0.0, 0.0, 50.0 } };
  const V lo{ { -100.0, -100.0, 0.0 } }, hi{ { 100.0, 100.0, 100.0 } };
  SceneDescription scene = DarkScene(camera, focus);
  scene.Medium.Density.Type = "file";
  scene.Medium.ExtinctionPerDensity = 0.005;
  scene.Medium.SingleScatteringAlbedo = 0.0;
  const float rho = 1.5f;
  const double sigmaA = 0.005 * rho;
  const double path = (1.0 - std::exp(-sigmaA * 200.0)) / sigmaA;
  for (const double kelvin : { 1500.0, 2000.0 })
  {
    scene.Medium.Emission = { true, "blackbody", "temperature", 0.02, 1500.0 };
    nimbus::SceneFields fields;
    fields.Emission = DensityGrid::Constant(lo, hi, static_cast<float>(kelvin));
    const RenderContext context(scene, DensityGrid::Constant(lo, hi, rho), std::move(fields));
    const PathTracingResult r = nimbus::RenderPathTraced(context, Samples(100000, 23, 0));
    const nimbus::BlackbodyEmission blackbody(context.GetSpectrum(), 1500.0);
    ExpectPixel(r, 0, 0, Rgb(context, blackbody.RelativeSpectrum(kelvin), 0.02 * rho * path),
      kelvin == 1500.0 ? "blackbody box at T_ref" : "blackbody box at 2000 K");
  }
  // A temperature field the renderer was not given, and a reference out of range: errors.
  scene.Medium.Emission = { true, "blackbody", "temperature", 0.02, 1500.0 };
  EXPECT_THROW(RenderContext(scene, DensityGrid::Constant(lo, hi, rho)), std::invalid_argument);
  scene.Medium.Emission = { true, "blackbody", "temperature", 0.02, 100000.0 };
  nimbus::SceneFields fields;
  fields.Emission = DensityGrid::Constant(lo, hi, 1500.0f);
  EXPECT_THROW(RenderContext(scene, DensityGrid::Constant(lo, hi, rho), std::move(fields)),
    std::invalid_argument);
}

//------------------------------------------------------------------------------
// Several media, full multiple scattering: media (s1, a1) and (s2, a2) with the same
// phase render as one medium of s1 + s2 and albedo (a1 s1 + a2 s2) / (s1 + s2) (z of the
// difference of two independent renders, per pixel and for the image sum); an additional
// medium of zero density changes nothing.
TEST(LightsPathTracer, TwoMediaEqualTheirMixture)
{
  const V lo{ { -100.0, -100.0, 0.0 } };
  SceneDescription base = DarkScene({ { 0.0, -600.0, 100.0 } }, { { 0.0, 0.0, 100.0 } }, 4);
  base.Camera.ViewAngle = 20.0; // every pixel sees the cloud
  base.Medium.Phase = { { "henyey_greenstein", 0.7, 1.0 } };
  base.Lights = { PointLight({ { 150.0, -250.0, 300.0 } }, 1.0e5) };
  // Heterogeneous densities on one grid: the mixture's albedo varies in space.
  std::vector<float> d1, d2;
  for (int k = 0; k < 5; ++k)
    for (int j = 0; j < 5; ++j)
      for (int i = 0; i < 5; ++i)
      {
        d1.push_back(static_cast<float>(0.5 + 0.1 * ((i + 2 * j + 3 * k) % 5)));
        d2.push_back(static_cast<float>(0.2 + 0.3 * ((3 * i + j + k) % 4)));
      }
  const std::array<int, 3> dims{ { 5, 5, 5 } };
  const V spacing{ { 50.0, 50.0, 50.0 } };
  const double s1 = 0.01, a1 = 0.95, s2 = 0.02, a2 = 0.6;
  SceneDescription two = base;
  two.Medium.ExtinctionPerDensity = s1;
  two.Medium.SingleScatteringAlbedo = a1;
  nimbus::AdditionalMediumDescription second;
  second.ExtinctionPerDensity = s2;
  second.SingleScatteringAlbedo = a2;
  second.Phase = base.Medium.Phase;
  two.Media = { second };
  nimbus::SceneFields fields;
  fields.MediaDensities.push_back(DensityGrid(dims, lo, spacing, d2));
  const RenderContext twoContext(two, DensityGrid(dims, lo, spacing, d1), std::move(fields));
  // For the equality, the second density proportional to the first (0.7 d1), so that the
  // mixture's albedo is the same everywhere and one medium can hold it.
  std::vector<float> d2p;
  for (float x : d1)
  {
    d2p.push_back(0.7f * x);
  }
  nimbus::SceneFields fieldsP;
  fieldsP.MediaDensities.push_back(DensityGrid(dims, lo, spacing, d2p));
  const RenderContext twoP(two, DensityGrid(dims, lo, spacing, d1), std::move(fieldsP));
  SceneDescription one = base;
  const double sigma1 = s1, sigma2 = 0.7 * s2;
  one.Medium.ExtinctionPerDensity = sigma1 + sigma2;
  one.Medium.SingleScatteringAlbedo = (a1 * sigma1 + a2 * sigma2) / (sigma1 + sigma2);
  const RenderContext oneContext(one, DensityGrid(dims, lo, spacing, d1));
  const PathTracingResult rTwo = nimbus::RenderPathTraced(twoP, Samples(20000, 21, 0));
  const PathTracingResult rOne = nimbus::RenderPathTraced(oneContext, Samples(20000, 22, 0));
  double worst = 0.0, sumDifference = 0.0, sumVariance = 0.0, sumOne = 0.0;
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 4; ++i)
    {
      const double a = rTwo.Image.At(i, j)[1], b = rOne.Image.At(i, j)[1];
      const double sa = rTwo.StandardError.At(i, j)[1], sb = rOne.StandardError.At(i, j)[1];
      const double z = (a - b) / std::hypot(sa, sb);
      worst = std::max(worst, std::abs(z));
      EXPECT_LT(std::abs(z), 4.0) << "pixel " << i << ", " << j << ": " << a << " vs " << b;
      sumDifference += a - b;
      sumVariance += sa * sa + sb * sb;
      sumOne += b;
    }
  const double zSum = sumDifference / std::sqrt(sumVariance);
  std::printf("two media vs their mixture: max pixel |z| %.2f, image-sum z %.2f (sum %.4g, "
              "relative se %.2f %%)\n",
    worst, zSum, sumOne, 100.0 * std::sqrt(sumVariance) / sumOne);
  EXPECT_LT(std::abs(zSum), 4.0);
  EXPECT_GT(sumOne, 0.0);

  // The heterogeneous pair renders finite, and a zero-density additional medium changes
  // nothing (statistically: choosing the scattering medium draws a random number, so
  // the paths differ).
  const PathTracingResult rHetero = nimbus::RenderPathTraced(twoContext, Samples(500, 23, 0));
  for (float x : rHetero.Image.Pixels)
  {
    EXPECT_TRUE(std::isfinite(x));
  }
  SceneDescription withEmpty = one;
  nimbus::AdditionalMediumDescription empty;
  empty.ExtinctionPerDensity = 0.5;
  empty.SingleScatteringAlbedo = 0.1;
  empty.Phase = { { "isotropic", 0.0, 1.0 } };
  withEmpty.Media = { empty };
  nimbus::SceneFields emptyFields;
  emptyFields.MediaDensities.push_back(
    DensityGrid(dims, lo, spacing, std::vector<float>(d1.size(), 0.0f)));
  const RenderContext emptyContext(
    withEmpty, DensityGrid(dims, lo, spacing, d1), std::move(emptyFields));
  const PathTracingResult rEmpty = nimbus::RenderPathTraced(emptyContext, Samples(20000, 25, 0));
  double worstEmpty = 0.0, emptyDifference = 0.0, emptyVariance = 0.0;
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 4; ++i)
    {
      const double a = rEmpty.Image.At(i, j)[1], b = rOne.Image.At(i, j)[1];
      const double se =
        std::hypot(rEmpty.StandardError.At(i, j)[1], rOne.StandardError.At(i, j)[1]);
      worstEmpty = std::max(worstEmpty, std::abs(a - b) / se);
      EXPECT_LT(std::abs(a - b) / se, 4.0) << "pixel " << i << ", " << j;
      emptyDifference += a - b;
      emptyVariance += se * se;
    }
  std::printf("zero-density additional medium: max pixel |z| %.2f, image-sum z %.2f\n", worstEmpty,
    emptyDifference / std::sqrt(sumVariance));
  EXPECT_LT(std::abs(emptyDifference / std::sqrt(sumVariance)), 4.0);
}

//------------------------------------------------------------------------------
// Extremes: a huge intensity, a light inside a dense cloud, a light at the camera, a
// light below the ground, a light exactly on a scattering point's ground plane: finite
// pixels (or exactly black where the ground hides the light); a grid with NaN (emission
// fields follow the density's policy: refused with the index); fields on another grid,
// and missing fields, are errors naming the key.
TEST(LightsPathTracer, ExtremesAreFiniteOrRefused)
{
  const V lo{ { -100.0, -100.0, 0.0 } }, hi{ { 100.0, 100.0, 200.0 } };
  SceneDescription scene = DarkScene({ { 0.0, -400.0, 100.0 } }, { { 0.0, 0.0, 100.0 } }, 3);
  scene.Camera.ViewAngle = 40.0;
  scene.Medium.ExtinctionPerDensity = 0.2; // tau 40 across
  scene.Medium.SingleScatteringAlbedo = 0.99;
  scene.Medium.Phase = { { "henyey_greenstein", 0.85, 1.0 } };
  scene.Ground.Enabled = true;
  auto finite = [](const PathTracingResult& r)
  {
    for (float x : r.Image.Pixels)
    {
      if (!std::isfinite(x) || x < 0.0f)
      {
        return false;
      }
    }
    return true;
  };
  for (const LightDescription& light :
    { PointLight({ { 0.0, 0.0, 100.0 } }, 1.0e12), PointLight({ { 0.0, -400.0, 100.0 } }, 1.0e6),
      Polyline(
        { { { 0.0, 0.0, 1000.0 } }, { { 0.0, 0.0, 100.0 } }, { { 10.0, 0.0, 0.0 } } }, 1.0e12) })
  {
    scene.Lights = { light };
    const RenderContext context(scene, DensityGrid::Constant(lo, hi, 1.0f));
    const PathTracingResult r = nimbus::RenderPathTraced(context, Samples(64, 29, 0));
    EXPECT_TRUE(finite(r)) << light.Type;
  }
  // Below the ground: the plane hides it from everything above it.
  scene.Lights = { PointLight({ { 0.0, 0.0, -10.0 } }, 1.0e6) };
  const RenderContext below(scene, DensityGrid::Constant(lo, hi, 1.0f));
  const PathTracingResult rb = nimbus::RenderPathTraced(below, Samples(64, 31, 0));
  for (float x : rb.Image.Pixels)
  {
    EXPECT_EQ(x, 0.0f);
  }
  // NaN in a field: refused by DensityGrid with its index, as densities are.
  std::vector<float> values(8, 1.0f);
  values[5] = std::nanf("");
  EXPECT_THROW(
    DensityGrid({ { 2, 2, 2 } }, lo, { { 200.0, 200.0, 200.0 } }, values), std::invalid_argument);
  // A field on another grid, or missing: errors naming the key.
  scene.Media = { nimbus::AdditionalMediumDescription{} };
  try
  {
    nimbus::SceneFields fields;
    fields.MediaDensities.push_back(DensityGrid::Constant(lo, { { 100.0, 100.0, 300.0 } }, 1.0f));
    const RenderContext wrong(scene, DensityGrid::Constant(lo, hi, 1.0f), std::move(fields));
    ADD_FAILURE() << "no error for a medium on another grid";
  }
  catch (const std::invalid_argument& error)
  {
    EXPECT_EQ(std::string(error.what())
                .rfind("scene: media[0].density must be on the main "
                       "density's grid (2x2x2 points",
                  0),
      0u)
      << error.what();
  }
  EXPECT_THROW(RenderContext(scene, DensityGrid::Constant(lo, hi, 1.0f)), std::invalid_argument);
  scene.Media.clear();
  scene.Medium.Emission = { true, "array", "heat", 1.0, 1500.0 };
  try
  {
    const RenderContext missing(scene, DensityGrid::Constant(lo, hi, 1.0f));
    ADD_FAILURE() << "no error for a missing emission field";
  }
  catch (const std::invalid_argument& error)
  {
    EXPECT_NE(std::string(error.what()).find("medium.emission.array"), std::string::npos)
      << error.what();
  }
}

// The single-scattering reference does not render the new features: it says so.
TEST(LightsPathTracer, SingleScatteringRefusesWhatItDoesNotRender)
{
  SceneDescription scene = DarkScene({ { 0.0, -400.0, 100.0 } }, { { 0.0, 0.0, 100.0 } });
  scene.Lights = { PointLight({ { 0.0, 0.0, 100.0 } }, 1.0) };
  const RenderContext context(scene, DensityGrid());
  try
  {
    nimbus::RenderSingleScattering(context, nimbus::SingleScatteringSettings{});
    ADD_FAILURE() << "no error";
  }
  catch (const std::invalid_argument& error)
  {
    EXPECT_NE(
      std::string(error.what()).find("point and polyline lights (scene.lights)"), std::string::npos)
      << error.what();
  }
}

//------------------------------------------------------------------------------
// The speed techniques (BlockTraversal, SunDepthRoulette, SunPeakSampling,
// TabulatedAirTransmittance, AdaptiveSampling) stay unbiased with every version-3
// feature at once: the sun behind a two-medium cloud (HG 0.85 and isotropic, different
// albedos, the second emitting), air and ground, a point light and a lightning channel.
// All on against all off, z of each pixel channel's difference and of the image sum.
TEST(LightsPathTracer, SpeedTechniquesStayUnbiasedWithVersion3Features)
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
        const double r2 = x * x + y * y + z * z;
        cloud.push_back(static_cast<float>(std::max(0.0, 1.0 - r2) * (1.0 + 0.5 * ((i + j) % 3))));
        smoke.push_back(
          static_cast<float>(1.5 * std::max(0.0, 0.8 - (x - 0.3) * (x - 0.3) - y * y)));
      }
  SceneDescription scene = DarkScene({ { 0.0, -2500.0, 1100.0 } }, { { 0.0, 0.0, 1100.0 } }, 12);
  scene.Camera.Height = 8;
  scene.Camera.ViewAngle = 25.0;
  scene.Atmosphere.Enabled = true;
  scene.Ground.Enabled = true;
  scene.Background.Type = "atmosphere";
  scene.Sun.Illuminance = 1.0;
  scene.Sun.AzimuthDegrees = 0.0; // behind the cloud
  scene.Sun.ElevationDegrees = 20.0;
  scene.SpectralSamples = 8;
  scene.Medium.ExtinctionPerDensity = 0.01;
  scene.Medium.SingleScatteringAlbedo = 0.99;
  scene.Medium.Phase = { { "henyey_greenstein", 0.85, 1.0 } };
  nimbus::AdditionalMediumDescription second;
  second.ExtinctionPerDensity = 0.02;
  second.SingleScatteringAlbedo = 0.95;
  second.Phase = { { "henyey_greenstein", -0.3, 1.0 } };
  second.Emission = { true, "from_density", "", 0.002, 1200.0 };
  scene.Media = { second };
  scene.Lights = { PointLight({ { -300.0, -600.0, 1200.0 } }, 2.0e5, 3000.0),
    Polyline(
      { { { 500.0, 200.0, 2500.0 } }, { { 450.0, 150.0, 1000.0 } }, { { 520.0, 180.0, 0.0 } } },
      100.0) };
  nimbus::SceneFields fields;
  fields.MediaDensities.push_back(DensityGrid(dims, lo, spacing, smoke));
  const RenderContext context(scene, DensityGrid(dims, lo, spacing, cloud), std::move(fields));
  auto render = [&](bool on, std::uint64_t seed, int samples)
  {
    PathTracingSettings settings;
    settings.MinSamplesPerPixel = settings.MaxSamplesPerPixel = samples;
    settings.Seed = seed;
    settings.Threads = 2;
    settings.SunPeakSampling = on;
    settings.SunDepthRoulette = on;
    settings.TabulatedAirTransmittance = on;
    settings.BlockTraversal = on;
    settings.AdaptiveSampling = on;
    return nimbus::RenderPathTraced(context, settings);
  };
  const PathTracingResult off = render(false, 41, 1024);
  const PathTracingResult on = render(true, 42, 1024);
  const nimbus_test::ImageAgreement agreement = nimbus_test::CompareMonteCarloImages(on, off);
  EXPECT_TRUE(agreement.Finite);
  const double rmsZ = agreement.RmsZ, imageZ = agreement.ImageSumZ;
  const int count = agreement.Count, outliers = agreement.Outliers;
  std::printf("version-3 scene, techniques on vs off: RMS z %.3f over %d pixel channels, %d "
              "beyond 4 sigma; image sum z %.2f, its relative se %.2f %% (%.1f s and %.1f s)\n",
    rmsZ, count, outliers, imageZ, 100.0 * agreement.ImageSumRelativeError, on.Seconds,
    off.Seconds);
  EXPECT_EQ(count, 3 * 12 * 8);
  EXPECT_LE(outliers, 2);
  EXPECT_LT(std::abs(imageZ), 4.0);
  EXPECT_GT(rmsZ, 0.75);
  EXPECT_LT(rmsZ, 1.3);
}

// Sun-peak sampling at a vertex of a medium whose phase differs from the main one: the
// vertex's f and p_A must be that medium's (docs/ground-truth.md). A backlit box of two
// media, a forward-peaked main one (HG 0.9) and a dominant isotropic one, where the
// camera's paths head sunward (where using the wrong phase would weigh most): sun-peak
// sampling on against off, z of the image sum and per pixel.
TEST(LightsPathTracer, SunPeakSamplingUsesTheScatteringMediumsPhase)
{
  const V lo{ { -200.0, -200.0, 800.0 } }, hi{ { 200.0, 200.0, 1200.0 } };
  SceneDescription scene = DarkScene({ { 0.0, -1500.0, 1000.0 } }, { { 0.0, 0.0, 1000.0 } }, 4);
  scene.Camera.ViewAngle = 12.0;
  scene.Sun.Illuminance = 1.0;
  scene.Sun.AzimuthDegrees = 0.0; // straight behind the box, 10 degrees up
  scene.Sun.ElevationDegrees = 10.0;
  scene.SpectralSamples = 4;
  scene.Medium.ExtinctionPerDensity = 0.004;
  scene.Medium.SingleScatteringAlbedo = 0.99;
  scene.Medium.Phase = { { "henyey_greenstein", 0.9, 1.0 } };
  nimbus::AdditionalMediumDescription second;
  second.ExtinctionPerDensity = 0.012;
  second.SingleScatteringAlbedo = 0.99;
  second.Phase = { { "isotropic", 0.0, 1.0 } };
  scene.Media = { second };
  nimbus::SceneFields fields;
  fields.MediaDensities.push_back(DensityGrid::Constant(lo, hi, 1.0f));
  const RenderContext context(scene, DensityGrid::Constant(lo, hi, 1.0f), std::move(fields));
  auto render = [&](bool peak, std::uint64_t seed)
  {
    PathTracingSettings settings = Samples(20000, seed, 0);
    settings.SunPeakSampling = peak;
    return nimbus::RenderPathTraced(context, settings);
  };
  const PathTracingResult on = render(true, 51), off = render(false, 52);
  double difference = 0.0, variance = 0.0, sum = 0.0, worst = 0.0;
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 4; ++i)
    {
      const double a = on.Image.At(i, j)[1], b = off.Image.At(i, j)[1];
      const double se = std::hypot(on.StandardError.At(i, j)[1], off.StandardError.At(i, j)[1]);
      worst = std::max(worst, std::abs(a - b) / se);
      EXPECT_LT(std::abs(a - b) / se, 4.0) << "pixel " << i << ", " << j;
      difference += a - b;
      variance += se * se;
      sum += b;
    }
  const double z = difference / std::sqrt(variance);
  std::printf("sun-peak sampling with two phases, on vs off: max pixel |z| %.2f, image sum z "
              "%.2f (relative se %.2f %%)\n",
    worst, z, 100.0 * std::sqrt(variance) / sum);
  EXPECT_LT(std::abs(z), 4.0);
}

//------------------------------------------------------------------------------
// Line lights (AngularLineLightSampling, docs/ground-truth.md "Line lights"). The sampler
// of a point of a segment uniform in the angle it subtends at p: its density in s
// integrates to 1 over the segment, its inverse (the sampled s at u) leaves the fraction
// u of the density below it, and 1 / (r^2 pdf) is the constant Delta theta / h it
// reports; the segments' weight lies within [2 / pi, 1] of I_l Delta theta / h. Points p
// off the line, 1e-4 of the length from it, 1e-6 m from its extension, and far.
TEST(LightsPathTracer, SegmentAngleSamplerIsNormalised)
{
  const nimbus::Vector3 a{ { 10.0, -4.0, 300.0 } };
  const nimbus::Vector3 toB{ { 30.0, 20.0, -40.0 } };
  const double length = nimbus::Length(toB);
  const nimbus::Vector3 axis{ { toB[0] / length, toB[1] / length, toB[2] / length } };
  const nimbus::Vector3 b = nimbus::Along(a, axis, length);
  const nimbus::Vector3 normal =
    nimbus::Normalized(nimbus::Cross(axis, nimbus::Vector3{ { 0.0, 0.0, 1.0 } }));
  std::vector<nimbus::Vector3> points = {
    { { 0.0, 0.0, 0.0 } },
    nimbus::Along(nimbus::Along(a, axis, 0.3 * length), normal, 1e-4 * length),
    nimbus::Along(nimbus::Along(a, axis, 1.5 * length), normal, 1e-6),
    nimbus::Along(nimbus::Along(a, axis, -0.2 * length), normal, 2.0),
    { { 5000.0, 7000.0, -3000.0 } },
  };
  for (const nimbus::Vector3& p : points)
  {
    auto pdf = [&](double s) { return nimbus::SegmentAngleDensity(p, a, axis, length, s); };
    // The density peaks at the foot of p (width h): split the quadrature there.
    const double foot = std::clamp(
      nimbus::Dot(nimbus::Vector3{ { p[0] - a[0], p[1] - a[1], p[2] - a[2] } }, axis), 0.0, length);
    auto integral = [&](double s)
    {
      const double cut = std::min(s, foot);
      return Simpson(pdf, 0.0, cut, 1e-12) + (s > foot ? Simpson(pdf, foot, s, 1e-12) : 0.0);
    };
    EXPECT_NEAR(integral(length), 1.0, 1e-8) << "p " << p[0] << " " << p[1] << " " << p[2];
    for (double u : { 0.01, 0.2, 0.5, 0.77, 0.999 })
    {
      nimbus::SegmentAngleSample sample;
      ASSERT_TRUE(nimbus::SampleSegmentByAngle(p, a, axis, length, u, sample));
      EXPECT_NEAR(integral(sample.Along), u, 1e-8);
      const nimbus::Vector3 r{ { sample.Point[0] - p[0], sample.Point[1] - p[1],
        sample.Point[2] - p[2] } };
      EXPECT_NEAR(sample.AngleOverDistance * nimbus::Dot(r, r) * pdf(sample.Along), 1.0, 1e-9);
      const double intensity = 7.0 * length; // 7 Y/(sr m)
      const double ratio =
        7.0 * sample.AngleOverDistance / nimbus::LineLightWeight(p, a, b, intensity);
      EXPECT_GE(ratio, 1.0 - 1e-9);
      EXPECT_LE(ratio, kPi / 2.0 + 1e-9);
    }
  }
  // On the line itself there is nothing to sample (a set of zero measure).
  nimbus::SegmentAngleSample sample;
  EXPECT_FALSE(nimbus::SampleSegmentByAngle(
    nimbus::Along(a, axis, 0.5 * length), a, axis, length, 0.5, sample));
}

// A horizontal segment 0.5 m from the Lambertian ground point the pixel sees (vacuum):
//   L = rho/pi I_l int z / r^3 ds = rho/pi I_l (z / h^2) [x / sqrt(h^2 + x^2)]_{x_a}^{x_b},
// x along the segment from the foot of the point, h = 0.5 m its distance to the line, z
// = 0.4 m the segment's height. Both samplers against the closed form; the angular one
// with a far smaller standard error (the uniform one's estimate reaches L_seg / h times
// the mean).
TEST(LightsPathTracer, NearSegmentLightsTheGround)
{
  const V camera{ { 0.0, 0.0, 100.0 } }, ground{ { 0.0, 0.0, 0.0 } };
  SceneDescription scene = DarkScene(camera, ground);
  scene.Ground.Enabled = true;
  scene.Ground.Albedo = 0.8;
  const double perMetre = 300.0, z = 0.4, h = 0.5, xa = -20.0, xb = 30.0;
  scene.Lights = { Polyline({ { { xa, 0.3, z } }, { { xb, 0.3, z } } }, perMetre) };
  const RenderContext context(scene, DensityGrid());
  const double scalar = 0.8 / kPi * perMetre * z / (h * h) *
    (xb / std::sqrt(h * h + xb * xb) - xa / std::sqrt(h * h + xa * xa));
  const std::array<double, 3> truth = Rgb(context, context.GetLightSpectra()[0], scalar);
  double se[2];
  for (int angular = 0; angular < 2; ++angular)
  {
    PathTracingSettings settings = Samples(200000, 21 + angular, 1);
    settings.AngularLineLightSampling = angular == 1;
    const PathTracingResult r = nimbus::RenderPathTraced(context, settings);
    ExpectPixel(r, truth,
      angular ? "segment 0.5 m from the ground point, angular sampler"
              : "segment 0.5 m from the ground point, uniform sampler");
    se[angular] = r.StandardError.At(0, 0)[1];
  }
  std::printf("standard error, angular / uniform: %.3f\n", se[1] / se[0]);
  EXPECT_LT(se[1], 0.2 * se[0]);
}

// Single-scattered light along a camera ray through a thin homogeneous HG medium from a
// 400 m vertical segment inside it that the ray passes 3 m from (MaxScatteringOrder 1):
//   L = int_{t_n}^{t_f} int_0^{L} sigma_s p(mu) I_l exp(-sigma_t (t - t_n + r)) / r^2 ds dt,
// r = |x(t) - y(s)|, mu = dot(toward y, ray direction), by nested adaptive Simpson split at
// the closest approach. Both samplers against it.
TEST(LightsPathTracer, SegmentInScatteringThinMedium)
{
  const V camera{ { 0.0, -2000.0, 500.0 } }, focus{ { 0.0, 0.0, 500.0 } };
  const V lo{ { -500.0, -500.0, 0.0 } }, hi{ { 500.0, 500.0, 1000.0 } };
  const V a{ { 3.0, 100.0, 300.0 } }, b{ { 3.0, 100.0, 700.0 } };
  const double perMetre = 200.0, sigmaT = 4.0e-4, albedo = 0.9, g = 0.6;
  SceneDescription scene = DarkScene(camera, focus);
  scene.Medium.ExtinctionPerDensity = sigmaT;
  scene.Medium.SingleScatteringAlbedo = albedo;
  scene.Medium.Phase = { { "henyey_greenstein", g, 1.0 } };
  scene.Lights = { Polyline({ a, b }, perMetre) };
  const RenderContext context(scene, DensityGrid::Constant(lo, hi, 1.0f));
  const double tNear = 1500.0, tFar = 2500.0, tClosest = 2100.0;
  auto inner = [&](double t)
  {
    const V x{ { camera[0], camera[1] + t, camera[2] } };
    auto f = [&](double s)
    {
      const V y{ { a[0], a[1], a[2] + s } };
      const double r = Distance(x, y);
      const double mu = (y[1] - x[1]) / r;
      return albedo * sigmaT * HenyeyGreenstein(mu, g) * std::exp(-sigmaT * (t - tNear + r)) /
        (r * r);
    };
    const double foot = x[2] - a[2]; // 200 m
    return Simpson(f, 0.0, foot, 1e-13) + Simpson(f, foot, b[2] - a[2], 1e-13);
  };
  const double scalar =
    perMetre * (Simpson(inner, tNear, tClosest, 1e-11) + Simpson(inner, tClosest, tFar, 1e-11));
  const std::array<double, 3> truth = Rgb(context, context.GetLightSpectra()[0], scalar);
  for (int angular = 0; angular < 2; ++angular)
  {
    PathTracingSettings settings = Samples(400000, 31 + angular, 1);
    settings.AngularLineLightSampling = angular == 1;
    const PathTracingResult r = nimbus::RenderPathTraced(context, settings);
    ExpectPixel(r, truth,
      angular ? "segment 3 m from the ray in a thin HG medium, angular sampler"
              : "segment 3 m from the ray in a thin HG medium, uniform sampler");
  }
}

// Multiple scattering from a channel of 24 segments inside an optically thick box (tau
// 6 across, albedo 0.99, HG 0.85): the angular sampler against the uniform one, image sum
// and per pixel (the estimators differ only in how they sample the same integral).
TEST(LightsPathTracer, LineLightSamplersAgreeInAThickMedium)
{
  const V lo{ { -100.0, -100.0, 900.0 } }, hi{ { 100.0, 100.0, 1100.0 } };
  SceneDescription scene = DarkScene({ { 0.0, -600.0, 1000.0 } }, { { 0.0, 0.0, 1000.0 } }, 4);
  scene.Camera.ViewAngle = 24.0;
  scene.Medium.ExtinctionPerDensity = 0.03;
  scene.Medium.SingleScatteringAlbedo = 0.99;
  scene.Medium.Phase = { { "henyey_greenstein", 0.85, 1.0 } };
  std::vector<V> channel;
  for (int i = 0; i <= 24; ++i)
  {
    const double s = i / 24.0;
    channel.push_back({ { 30.0 * std::sin(9.0 * s) + (i % 2 ? 6.0 : -6.0), 20.0 * std::cos(7.0 * s),
      1080.0 - 160.0 * s } });
  }
  scene.Lights = { Polyline(channel, 1000.0) };
  const RenderContext context(scene, DensityGrid::Constant(lo, hi, 1.0f));
  auto render = [&](bool angular, std::uint64_t seed)
  {
    PathTracingSettings settings = Samples(4096, seed, 0);
    settings.PixelJitter = true;
    settings.AngularLineLightSampling = angular;
    return nimbus::RenderPathTraced(context, settings);
  };
  const PathTracingResult angular = render(true, 61), uniform = render(false, 62);
  const nimbus_test::ImageAgreement agreement =
    nimbus_test::CompareMonteCarloImages(angular, uniform);
  EXPECT_TRUE(agreement.Finite);
  double seAngular = 0.0, seUniform = 0.0;
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 4; ++i)
    {
      seAngular += angular.StandardError.At(i, j)[1] / angular.Image.At(i, j)[1];
      seUniform += uniform.StandardError.At(i, j)[1] / uniform.Image.At(i, j)[1];
    }
  std::printf("line-light samplers in a thick medium, angular vs uniform: RMS z %.3f over %d "
              "pixel channels, %d beyond 4 sigma; image sum z %.2f; mean relative se %.2f %% vs "
              "%.2f %% (%.1f s vs %.1f s)\n",
    agreement.RmsZ, agreement.Count, agreement.Outliers, agreement.ImageSumZ,
    100.0 * seAngular / 16.0, 100.0 * seUniform / 16.0, angular.Seconds, uniform.Seconds);
  EXPECT_EQ(agreement.Count, 3 * 16);
  EXPECT_LE(agreement.Outliers, 1);
  EXPECT_LT(std::abs(agreement.ImageSumZ), 4.0);
}

//------------------------------------------------------------------------------
// Light tracing (PathTracingSettings::LightTracing): paths from the lights connected to the
// camera at every scattering vertex, against the camera path tracer on the same scene,
// pixel by pixel and image sum within their combined standard errors.
namespace
{
/// The light tracer on `context`: `batches` batches of `perBatch` light paths.
PathTracingResult LightTraced(
  const RenderContext& context, int batches, int perBatch, std::uint64_t seed, int threads = 2)
{
  const int pixels = context.GetCamera().GetWidth() * context.GetCamera().GetHeight();
  PathTracingSettings settings;
  settings.LightTracing = true;
  settings.LightPathsPerBatch = static_cast<std::uint64_t>(perBatch);
  settings.MinSamplesPerPixel = batches * perBatch / pixels;
  settings.MaxSamplesPerPixel = settings.MinSamplesPerPixel;
  settings.Seed = seed;
  settings.Threads = threads;
  return nimbus::RenderPathTraced(context, settings);
}

void ExpectAgreement(const PathTracingResult& light, const PathTracingResult& camera,
  int pixelChannels, const char* what)
{
  const nimbus_test::ImageAgreement agreement = nimbus_test::CompareMonteCarloImages(light, camera);
  std::printf("%s, light vs camera paths: RMS z %.3f over %d pixel channels, %d beyond 4 "
              "sigma; image sum z %.2f (its relative se %.2f %%); %.2f s vs %.2f s\n",
    what, agreement.RmsZ, agreement.Count, agreement.Outliers, agreement.ImageSumZ,
    100.0 * agreement.ImageSumRelativeError, light.Seconds, camera.Seconds);
  EXPECT_TRUE(agreement.Finite) << what;
  EXPECT_EQ(agreement.Count, pixelChannels) << what;
  EXPECT_LE(agreement.Outliers, 1) << what;
  EXPECT_LT(agreement.RmsZ, 1.5) << what;
  EXPECT_LT(std::abs(agreement.ImageSumZ), 4.0) << what;
  EXPECT_LT(agreement.ImageSumRelativeError, 0.05) << what;
}
} // namespace

// A point light off-centre in a homogeneous scattering box (tau 1 across, albedo 0.9,
// Henyey-Greenstein g = 0.5, so the phase function's direction convention matters), seen
// from outside on 6 x 6 pixels.
TEST(LightsPathTracer, LightTracingAgreesWithCameraPathsPointLight)
{
  const V lo{ { -50.0, -50.0, -50.0 } }, hi{ { 50.0, 50.0, 50.0 } };
  SceneDescription scene = DarkScene({ { 30.0, -300.0, 20.0 } }, { { 0.0, 0.0, 0.0 } }, 6);
  scene.Camera.ViewAngle = 26.0;
  scene.Medium.ExtinctionPerDensity = 0.01;
  scene.Medium.SingleScatteringAlbedo = 0.9;
  scene.Medium.Phase = { { "henyey_greenstein", 0.5, 1.0 } };
  scene.Lights = { PointLight({ { 15.0, 10.0, -20.0 } }, 5000.0, 4000.0) };
  const RenderContext context(scene, DensityGrid::Constant(lo, hi, 1.0f));
  PathTracingSettings settings = Samples(32768, 71, 0);
  settings.PixelJitter = true;
  const PathTracingResult camera = nimbus::RenderPathTraced(context, settings);
  const PathTracingResult light = LightTraced(context, 512, 4096, 72);
  ExpectAgreement(light, camera, 3 * 36, "point light in a scattering box");
  // Per seed, whatever the thread count.
  const PathTracingResult one = LightTraced(context, 4, 1024, 73, 1);
  const PathTracingResult two = LightTraced(context, 4, 1024, 73, 3);
  EXPECT_EQ(one.Image.Pixels, two.Image.Pixels);
  EXPECT_EQ(one.StandardError.Pixels, two.StandardError.Pixels);
  EXPECT_DOUBLE_EQ(one.MeanSamplesPerPixel, 4.0 * 1024.0 / 36.0);
}

// A spot light (cone 40 degrees, soft edge 10 degrees) in the same box: the light paths'
// directions drawn in the cone, weighted by the beam's profile.
TEST(LightsPathTracer, LightTracingAgreesWithCameraPathsSpotLight)
{
  const V lo{ { -50.0, -50.0, -50.0 } }, hi{ { 50.0, 50.0, 50.0 } };
  SceneDescription scene = DarkScene({ { 30.0, -300.0, 20.0 } }, { { 0.0, 0.0, 0.0 } }, 4);
  scene.Camera.ViewAngle = 26.0;
  scene.Medium.ExtinctionPerDensity = 0.01;
  scene.Medium.SingleScatteringAlbedo = 0.9;
  scene.Medium.Phase = { { "henyey_greenstein", 0.5, 1.0 } };
  LightDescription spot = PointLight({ { 15.0, 10.0, -20.0 } }, 5000.0, 4000.0);
  spot.Type = "spot";
  spot.Direction = { { -0.3, -1.0, 0.5 } };
  spot.ConeAngleDegrees = 40.0;
  spot.EdgeDegrees = 10.0;
  scene.Lights = { spot };
  const RenderContext context(scene, DensityGrid::Constant(lo, hi, 1.0f));
  PathTracingSettings settings = Samples(16384, 75, 0);
  settings.PixelJitter = true;
  const PathTracingResult camera = nimbus::RenderPathTraced(context, settings);
  const PathTracingResult light = LightTraced(context, 256, 4096, 76);
  ExpectAgreement(light, camera, 3 * 16, "spot light in a scattering box");
}

// A polyline light of two segments in an optically thick box (tau 8 across, albedo 0.99,
// Cornette-Shanks g = 0.85): multiple scattering of high orders, the camera connections'
// ratio tracking through the thick medium with its roulette. The medium keeps 10 m clear
// of the channel (a grid of 5 m spacing, 0 at its points within 10 m) so that the camera
// paths' estimate of the light stays bounded and their standard error can be trusted.
TEST(LightsPathTracer, LightTracingAgreesWithCameraPathsSegmentInThickBox)
{
  const V lo{ { -50.0, -50.0, -50.0 } }, hi{ { 50.0, 50.0, 50.0 } };
  SceneDescription scene = DarkScene({ { 0.0, -300.0, 0.0 } }, { { 0.0, 0.0, 0.0 } }, 4);
  scene.Camera.ViewAngle = 24.0;
  scene.Medium.ExtinctionPerDensity = 0.08;
  scene.Medium.SingleScatteringAlbedo = 0.99;
  scene.Medium.Phase = { { "cornette_shanks", 0.85, 1.0 } };
  const std::vector<V> channel{ { { -20.0, 5.0, 30.0 } }, { { 0.0, -10.0, 0.0 } },
    { { 15.0, 0.0, -35.0 } } };
  scene.Lights = { Polyline(channel, 40.0) };
  auto toChannel = [&channel](const V& x)
  {
    double nearest = 1e300;
    for (std::size_t k = 0; k + 1 < channel.size(); ++k)
    {
      const V& a = channel[k];
      const V ab{ { channel[k + 1][0] - a[0], channel[k + 1][1] - a[1],
        channel[k + 1][2] - a[2] } };
      const V ax{ { x[0] - a[0], x[1] - a[1], x[2] - a[2] } };
      const double s = std::clamp(nimbus::Dot(ax, ab) / nimbus::Dot(ab, ab), 0.0, 1.0);
      nearest = std::min(
        nearest, Distance(x, { { a[0] + s * ab[0], a[1] + s * ab[1], a[2] + s * ab[2] } }));
    }
    return nearest;
  };
  std::vector<float> density;
  for (int k = 0; k <= 20; ++k)
    for (int j = 0; j <= 20; ++j)
      for (int i = 0; i <= 20; ++i)
      {
        const V x{ { -50.0 + 5.0 * i, -50.0 + 5.0 * j, -50.0 + 5.0 * k } };
        density.push_back(toChannel(x) < 10.0 ? 0.0f : 1.0f);
      }
  const RenderContext context(
    scene, DensityGrid({ { 21, 21, 21 } }, lo, { { 5.0, 5.0, 5.0 } }, density));
  PathTracingSettings settings = Samples(16384, 81, 0);
  settings.PixelJitter = true;
  const PathTracingResult camera = nimbus::RenderPathTraced(context, settings);
  const PathTracingResult light = LightTraced(context, 256, 4096, 82);
  ExpectAgreement(light, camera, 3 * 16, "segment light in a thick box");
}

// What light tracing does not render is refused with a message that names it.
TEST(LightsPathTracer, LightTracingRefusesWhatItDoesNotRender)
{
  const V lo{ { -50.0, -50.0, -50.0 } }, hi{ { 50.0, 50.0, 50.0 } };
  SceneDescription base = DarkScene({ { 0.0, -300.0, 0.0 } }, { { 0.0, 0.0, 0.0 } }, 2);
  base.Medium.ExtinctionPerDensity = 0.01;
  base.Lights = { PointLight({ { 0.0, 0.0, 0.0 } }, 100.0) };
  auto refusal = [&](const SceneDescription& scene) -> std::string
  {
    const RenderContext context(scene, DensityGrid::Constant(lo, hi, 1.0f));
    EXPECT_EQ(nimbus::LightTracingUnsupported(context).empty(), false);
    try
    {
      LightTraced(context, 2, 64, 1);
    }
    catch (const std::invalid_argument& error)
    {
      return error.what();
    }
    return "(no error)";
  };
  {
    const RenderContext context(base, DensityGrid::Constant(lo, hi, 1.0f));
    EXPECT_EQ(nimbus::LightTracingUnsupported(context), "");
  }
  SceneDescription sun = base;
  sun.Sun.Illuminance = 1.0;
  EXPECT_NE(refusal(sun).find("a sun of illuminance > 0"), std::string::npos);
  SceneDescription background = base;
  background.Background.Type = "constant";
  background.Background.Radiance = 0.5;
  EXPECT_NE(refusal(background).find("a background radiance > 0"), std::string::npos);
  SceneDescription ground = base;
  ground.Ground.Enabled = true;
  ground.Ground.Height = -100.0;
  EXPECT_NE(refusal(ground).find("the ground"), std::string::npos);
  SceneDescription air = base;
  air.Atmosphere.Enabled = true;
  air.Background.Type = "black";
  EXPECT_NE(refusal(air).find("the atmosphere"), std::string::npos);
  SceneDescription occluded = base;
  nimbus::OccluderDescription box;
  box.Min = { { 60.0, 60.0, 60.0 } };
  box.Max = { { 70.0, 70.0, 70.0 } };
  box.Albedo = 0.5;
  occluded.Occluders = { box };
  EXPECT_NE(refusal(occluded).find("occluders"), std::string::npos);
  SceneDescription emitting = base;
  emitting.Medium.Emission.Enabled = true;
  emitting.Medium.Emission.RadiancePerMetre = 1.0;
  EXPECT_NE(refusal(emitting).find("emitting media"), std::string::npos);
  SceneDescription dark = base;
  dark.Lights.clear();
  const std::string both = [&]
  {
    SceneDescription s = dark;
    s.Ground.Enabled = true;
    s.Ground.Height = -100.0;
    return refusal(s);
  }();
  std::printf("light tracing's refusal: %s\n", both.c_str());
  EXPECT_NE(both.find("no light of positive intensity and the ground"), std::string::npos);
}
