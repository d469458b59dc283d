// BlackbodyEmission (hot smoke and fire): the emission of hot smoke, relative to a reference
// temperature. Luminance 1 at the reference, the physics of Planck's law (Wien's
// approximation for the luminance ratios), colours from red to blue, the table against the
// exact values, and the extremes (0 K, NaN, infinite, absurd references).
#include "BlackbodyEmission.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

namespace
{
const nimbus::SpectralSamples& Samples()
{
  static const nimbus::SpectralSamples samples;
  return samples;
}
} // namespace

TEST(BlackbodyEmission, LuminanceRelativeToTheReference)
{
  const nimbus::BlackbodyEmission emission(Samples(), 1500.0);
  EXPECT_NEAR(emission.RelativeLuminance(1500.0), 1.0, 1e-12);
  double last = 0.0;
  for (double t = 300.0; t <= 12000.0; t += 100.0)
  {
    const double y = emission.RelativeLuminance(t);
    EXPECT_GT(y, last) << t; // hotter is brighter
    last = y;
  }
  // Wien's approximation at the luminance's weighted wavelength (~555 nm) gives the order:
  // exp(-c2 / lambda (1/T - 1/T_ref)), c2 = 1.4388e-2 m K.
  const double c2 = 1.4388e-2 / 555e-9;
  for (const double t : { 1000.0, 2000.0, 3000.0 })
  {
    const double wien = std::exp(-c2 * (1.0 / t - 1.0 / 1500.0));
    const double y = emission.RelativeLuminance(t);
    std::printf("T %.0f K: Y ratio %.4g (Wien at 555 nm: %.4g)\n", t, y, wien);
    // The luminance weights a band around 555 nm: within a factor 2 of the one-line guess.
    EXPECT_GT(y / wien, 0.5) << t;
    EXPECT_LT(y / wien, 2.0) << t;
  }
  // The figures BlackbodyEmission.h quotes (measured here).
  std::printf("600 K: %.3g\n", emission.RelativeLuminance(600.0));
  EXPECT_NEAR(emission.RelativeLuminance(1000.0), 3.5e-4, 0.1e-4);
  EXPECT_NEAR(emission.RelativeLuminance(2000.0), 60.0, 1.0);
  EXPECT_LT(emission.RelativeLuminance(600.0), 1e-10);
}

TEST(BlackbodyEmission, ColoursGoFromRedToBlue)
{
  const nimbus::BlackbodyEmission emission(Samples(), 1500.0);
  const auto warm = emission.RelativeRgb(1500.0);
  EXPECT_GT(warm[0], warm[1]);
  EXPECT_GT(warm[1], warm[2]);
  const auto hot = emission.RelativeRgb(12000.0);
  EXPECT_GT(hot[2], hot[0]);
  // The spectrum's linear sRGB against Y: a blackbody's sRGB luminance equals its Y.
  const auto rgb = emission.ExactRelativeRgb(1500.0);
  EXPECT_NEAR(0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2], 1.0, 1e-3);
}

TEST(BlackbodyEmission, TableMatchesExact)
{
  const nimbus::BlackbodyEmission emission(Samples(), 1500.0);
  double worst = 0.0;
  for (double t = 700.0; t < 25000.0; t *= 1.0137)
  {
    const auto a = emission.RelativeRgb(t);
    const auto b = emission.ExactRelativeRgb(t);
    const double scale = std::max({ std::abs(b[0]), std::abs(b[1]), std::abs(b[2]) });
    for (int c = 0; c < 3; ++c)
    {
      worst = std::max(worst, std::abs(a[c] - b[c]) / scale);
    }
  }
  std::printf("table: worst relative error %.3g\n", worst);
  EXPECT_LT(worst, 1e-3); // measured 2.3e-4
}

TEST(BlackbodyEmission, Extremes)
{
  const nimbus::BlackbodyEmission emission(Samples(), 1500.0);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  for (const double t : { 0.0, -5.0, nan, -inf, 1e-300, 5.0 })
  {
    const auto rgb = emission.RelativeRgb(t);
    for (int c = 0; c < 3; ++c)
    {
      EXPECT_EQ(rgb[c], 0.0) << t;
    }
    EXPECT_EQ(emission.RelativeLuminance(t), 0.0) << t;
  }
  for (const double t : { inf, 1e12, 20000.0, 19999.5 })
  {
    const auto rgb = emission.RelativeRgb(t);
    for (int c = 0; c < 3; ++c)
    {
      EXPECT_TRUE(std::isfinite(rgb[c])) << t;
    }
  }
  for (const double ref : { 0.0, 499.0, 60000.0, nan, inf, -1500.0 })
  {
    EXPECT_THROW(nimbus::BlackbodyEmission(Samples(), ref), std::invalid_argument) << ref;
  }
}
