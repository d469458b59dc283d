// What the path tracer's light tests (TestLightsPathTracer, TestSpotLightsPathTracer)
// share: a dark one-pixel (or n x n) scene, fixed-sample settings, a light spectrum in
// linear sRGB, a pixel's agreement with a closed form within its standard error, and
// adaptive Simpson quadrature for the closed forms' 1-D integrals.
#ifndef NimbusLightsSceneTesting_h
#define NimbusLightsSceneTesting_h

#include "Math.h"
#include "PathTracer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <vector>

namespace nimbus_test
{

/// One pixel (or n x n) looking from `from` to `to`; nothing lit, nothing seen: no sun, no
/// atmosphere, no ground, a black background, an isotropic medium of zero extinction.
inline nimbus::SceneDescription DarkScene(
  const std::array<double, 3>& from, const std::array<double, 3>& to, int n = 1)
{
  using V = std::array<double, 3>;
  nimbus::SceneDescription scene;
  scene.Camera.Position = from;
  scene.Camera.FocalPoint = to;
  scene.Camera.ViewUp = std::abs(to[2] - from[2]) >
      0.9 * nimbus::Length(nimbus::Vector3{ { to[0] - from[0], to[1] - from[1], to[2] - from[2] } })
    ? V{ { 0.0, 1.0, 0.0 } }
    : V{ { 0.0, 0.0, 1.0 } };
  scene.Camera.ViewAngle = 1.0;
  scene.Camera.Width = n;
  scene.Camera.Height = n;
  scene.Atmosphere.Enabled = false;
  scene.Ground.Enabled = false;
  scene.Background.Type = "black";
  scene.Sun.Illuminance = 0.0;
  scene.Medium.ExtinctionPerDensity = 0.0;
  scene.Medium.SingleScatteringAlbedo = 1.0;
  scene.Medium.Phase = { { "isotropic", 0.0, 1.0 } };
  return scene;
}

/// Exactly n samples per pixel from `seed`, on 2 threads, no pixel jitter, scattering
/// orders up to maxOrder.
inline nimbus::PathTracingSettings Samples(int n, std::uint64_t seed, int maxOrder)
{
  nimbus::PathTracingSettings settings;
  settings.MinSamplesPerPixel = n;
  settings.MaxSamplesPerPixel = n;
  settings.Seed = seed;
  settings.Threads = 2;
  settings.PixelJitter = false;
  settings.MaxScatteringOrder = maxOrder;
  return settings;
}

/// Linear sRGB of `scalar` times a (luminance-1) spectrum, such as a light's.
inline std::array<double, 3> Rgb(
  const nimbus::RenderContext& context, const std::vector<double>& spectrum, double scalar)
{
  std::vector<double> s = spectrum;
  for (double& x : s)
  {
    x *= scalar;
  }
  return context.ToLinearSrgb(s);
}

/// Every channel of pixel (i, j) within 4 standard errors of truth; prints the green
/// channel and returns the largest |z|.
inline double ExpectPixel(const nimbus::PathTracingResult& r, int i, int j,
  const std::array<double, 3>& truth, const char* what)
{
  double worst = 0.0;
  for (int c = 0; c < 3; ++c)
  {
    const double mean = r.Image.At(i, j)[c], se = r.StandardError.At(i, j)[c];
    EXPECT_TRUE(std::isfinite(mean) && se > 0.0) << what;
    const double z = (mean - truth[c]) / se;
    worst = std::max(worst, std::abs(z));
    EXPECT_LT(std::abs(z), 4.0) << what << " channel " << c << ": " << mean << " +- " << se
                                << ", truth " << truth[c];
  }
  std::printf("%s: truth G %.6g, mean G %.6g +- %.2g (%.2f %%), max |z| %.2f\n", what, truth[1],
    r.Image.At(i, j)[1], r.StandardError.At(i, j)[1],
    100.0 * r.StandardError.At(i, j)[1] / truth[1], worst);
  return worst;
}

/// ExpectPixel of pixel (0, 0).
inline double ExpectPixel(
  const nimbus::PathTracingResult& r, const std::array<double, 3>& truth, const char* what)
{
  return ExpectPixel(r, 0, 0, truth, what);
}

/// Adaptive Simpson quadrature of f over [a, b] to absolute tolerance eps, halving at most
/// `depth` times.
inline double Simpson(
  const std::function<double(double)>& f, double a, double b, double eps, int depth = 40)
{
  std::function<double(double, double, double, double, double, double, double, int)> step =
    [&](double a0, double b0, double fa, double fm, double fb, double whole, double tol,
      int d) -> double
  {
    const double m = 0.5 * (a0 + b0), lm = 0.5 * (a0 + m), rm = 0.5 * (m + b0);
    const double flm = f(lm), frm = f(rm);
    const double left = (m - a0) / 6.0 * (fa + 4.0 * flm + fm);
    const double right = (b0 - m) / 6.0 * (fm + 4.0 * frm + fb);
    if (d <= 0 || std::abs(left + right - whole) <= 15.0 * tol)
    {
      return left + right + (left + right - whole) / 15.0;
    }
    return step(a0, m, fa, flm, fm, left, 0.5 * tol, d - 1) +
      step(m, b0, fm, frm, fb, right, 0.5 * tol, d - 1);
  };
  const double fa = f(a), fb = f(b), fm = f(0.5 * (a + b));
  return step(a, b, fa, fm, fb, (b - a) / 6.0 * (fa + 4.0 * fm + fb), eps, depth);
}

} // namespace nimbus_test

#endif
