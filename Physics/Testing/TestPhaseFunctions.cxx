// Tests for PhaseFunctions.h: normalisation (by quadrature, not by the samplers),
// sampling vs pdf (chi-square), mean cosines, and finiteness at the extremes.
#include "Math.h"
#include "PhaseFunctions.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <limits>
#include <memory>
#include <random>
#include <stdexcept>
#include <vector>

namespace
{
using nimbus::kPi;
using nimbus::PhaseFunctionKind;

// Uniform in [0,1) from the top 53 bits, independent of <random>'s distributions.
double Uniform01(std::mt19937_64& rng)
{
  return static_cast<double>(rng() >> 11) * 0x1.0p-53;
}

using Pdf = std::function<double(double)>; // per steradian, argument mu

// integral_{a}^{b} p(mu) dmu with mu = s (1 - e^x) (s = +1 resolves a peak at
// mu = +1, s = -1 at mu = -1), composite Simpson in x with n intervals.  The part
// within 1e-16 of the peak is dropped (mass < 1e-16 / (1 - |g|)^2).
double IntegrateMu(const Pdf& p, double a, double b, double s, int n)
{
  const double xMin = std::log(1e-16);
  // x range mapping to [a, b]: 1 - e^x = s mu  =>  x = log(1 - s mu).
  double x0 = std::log(std::max(1e-300, 1.0 - s * b));
  double x1 = std::log(std::max(1e-300, 1.0 - s * a));
  if (s < 0.0)
  {
    std::swap(x0, x1);
  }
  x0 = std::max(x0, xMin);
  x1 = std::max(x1, xMin);
  if (!(x1 > x0))
  {
    return 0.0;
  }
  const double h = (x1 - x0) / n;
  double sum = 0.0;
  for (int k = 0; k <= n; ++k)
  {
    const double x = x0 + k * h;
    const double w = (k == 0 || k == n) ? 1.0 : (k % 2 == 1 ? 4.0 : 2.0);
    const double ex = std::exp(x);
    sum += w * p(s * (1.0 - ex)) * ex;
  }
  return sum * h / 3.0;
}

// 2 pi integral_{-1}^{1} p(mu) dmu (should be 1).
double SphereIntegral(const Pdf& p, double g)
{
  return 2.0 * kPi * IntegrateMu(p, -1.0, 1.0, g >= 0.0 ? 1.0 : -1.0, 40000);
}

// <mu> = 2 pi integral mu p(mu) dmu by the same quadrature.
double MeanCosineByQuadrature(const Pdf& p, double g)
{
  return SphereIntegral([&](double mu) { return mu * p(mu); }, g);
}

// Regularized upper incomplete gamma Q(a, x) (Numerical Recipes gser / gcf).
double GammaQ(double a, double x)
{
  const double gln = std::lgamma(a);
  if (x < a + 1.0)
  {
    double ap = a, sum = 1.0 / a, del = sum;
    for (int n = 0; n < 1000; ++n)
    {
      ap += 1.0;
      del *= x / ap;
      sum += del;
      if (std::abs(del) < std::abs(sum) * 1e-15)
        break;
    }
    return 1.0 - sum * std::exp(-x + a * std::log(x) - gln);
  }
  double b = x + 1.0 - a, c = 1.0 / 1e-300, d = 1.0 / b, h = d;
  for (int i = 1; i < 1000; ++i)
  {
    const double an = -i * (i - a);
    b += 2.0;
    d = an * d + b;
    if (std::abs(d) < 1e-300)
      d = 1e-300;
    c = b + an / c;
    if (std::abs(c) < 1e-300)
      c = 1e-300;
    d = 1.0 / d;
    const double del = d * c;
    h *= del;
    if (std::abs(del - 1.0) < 1e-15)
      break;
  }
  return std::exp(-x + a * std::log(x) - gln) * h;
}

constexpr int kBins = 32;                     // chi-square degrees of freedom = 31
constexpr double kChiSquareCritical = 61.098; // chi^2_{31} at p = 0.001
constexpr int kSamples = 200000;

struct ChiSquareResult
{
  double chi2;
  double pValue;
  double sampleMean;
  double standardError;
};

// Chi-square of samples of mu against pdf p on kBins bins of (approximately)
// equal probability; the expected probabilities are computed by quadrature of p
// over the actual bin edges, so the edge placement need not be exact.
ChiSquareResult ChiSquare(const Pdf& p, double g, const std::function<double()>& sample)
{
  const double s = g >= 0.0 ? 1.0 : -1.0;
  // Cumulative mass from the peak side on a fine grid of mu, then quantile edges.
  const int grid = 4000;
  std::vector<double> muGrid(grid + 1), cdf(grid + 1, 0.0);
  const double xMin = std::log(1e-16), xMax = std::log(2.0);
  for (int k = 0; k <= grid; ++k)
  {
    const double x = xMax - (xMax - xMin) * k / grid; // from the far side to the peak
    muGrid[k] = s * (1.0 - std::exp(x));
  }
  for (int k = 1; k <= grid; ++k)
  {
    const double a = std::min(muGrid[k - 1], muGrid[k]), b = std::max(muGrid[k - 1], muGrid[k]);
    cdf[k] = cdf[k - 1] + 2.0 * kPi * IntegrateMu(p, a, b, s, 16);
  }
  std::vector<double> edges{ muGrid[0] };
  for (int j = 1; j < kBins; ++j)
  {
    const double target = cdf[grid] * j / kBins;
    const int k = static_cast<int>(std::lower_bound(cdf.begin(), cdf.end(), target) - cdf.begin());
    const double t = (target - cdf[k - 1]) / (cdf[k] - cdf[k - 1]);
    edges.push_back(muGrid[k - 1] + t * (muGrid[k] - muGrid[k - 1]));
  }
  edges.push_back(s);
  if (s < 0.0)
  {
    std::reverse(edges.begin(), edges.end());
  }
  edges.front() = -1.0;
  edges.back() = 1.0;
  std::vector<double> expected(kBins);
  for (int j = 0; j < kBins; ++j)
  {
    expected[j] = 2.0 * kPi * IntegrateMu(p, edges[j], edges[j + 1], s, 4000) * kSamples;
  }
  std::vector<double> observed(kBins, 0.0);
  double sum = 0.0, sum2 = 0.0;
  for (int i = 0; i < kSamples; ++i)
  {
    const double mu = sample();
    EXPECT_TRUE(mu >= -1.0 && mu <= 1.0) << mu;
    const int j = static_cast<int>(
      std::upper_bound(edges.begin() + 1, edges.end() - 1, mu) - (edges.begin() + 1));
    observed[j] += 1.0;
    sum += mu;
    sum2 += mu * mu;
  }
  double chi2 = 0.0;
  for (int j = 0; j < kBins; ++j)
  {
    EXPECT_GT(expected[j], 5.0);
    chi2 += (observed[j] - expected[j]) * (observed[j] - expected[j]) / expected[j];
  }
  const double mean = sum / kSamples;
  const double var = sum2 / kSamples - mean * mean;
  return { chi2, GammaQ(0.5 * (kBins - 1), 0.5 * chi2), mean, std::sqrt(var / kSamples) };
}

nimbus::PhaseFunctionMixture CloudMixture(double g)
{
  // 004 §3.3: 5 % Rayleigh + 95 % Cornette-Shanks.
  nimbus::PhaseFunctionMixture m;
  m.AddComponent(0.05, PhaseFunctionKind::Rayleigh);
  m.AddComponent(0.95, PhaseFunctionKind::CornetteShanks, g);
  return m;
}

const double kGs[] = { -0.99, -0.5, 0.0, 0.5, 0.9, 0.99, 0.999 };
} // namespace

//------------------------------------------------------------------------------
TEST(PhaseFunctions, NormalisedOverSphere)
{
  double worst = 0.0;
  for (double g : kGs)
  {
    const nimbus::PhaseFunctionMixture mix = CloudMixture(g);
    const double hg = SphereIntegral([g](double mu) { return nimbus::HenyeyGreenstein(mu, g); }, g);
    const double cs = SphereIntegral([g](double mu) { return nimbus::CornetteShanks(mu, g); }, g);
    const double ray = SphereIntegral([](double mu) { return nimbus::Rayleigh(mu); }, g);
    const double mx = SphereIntegral([&](double mu) { return mix.Evaluate(mu); }, g);
    std::printf("g=%7.3f  integral-1: HG %+.2e  CS %+.2e  Rayleigh %+.2e  mix %+.2e\n", g, hg - 1,
      cs - 1, ray - 1, mx - 1);
    for (double v : { hg, cs, ray, mx })
    {
      EXPECT_NEAR(v, 1.0, 1e-4) << "g=" << g;
      worst = std::max(worst, std::abs(v - 1.0));
    }
  }
  std::printf("max |integral - 1| = %.2e\n", worst);
}

TEST(PhaseFunctions, MeanCosineClosedForms)
{
  for (double g : kGs)
  {
    const double hg =
      MeanCosineByQuadrature([g](double mu) { return nimbus::HenyeyGreenstein(mu, g); }, g);
    const double cs =
      MeanCosineByQuadrature([g](double mu) { return nimbus::CornetteShanks(mu, g); }, g);
    EXPECT_NEAR(hg, nimbus::HenyeyGreensteinMeanCosine(g), 1e-8) << g;
    EXPECT_NEAR(cs, nimbus::CornetteShanksMeanCosine(g), 1e-8) << g;
    const nimbus::PhaseFunctionMixture mix = CloudMixture(g);
    EXPECT_NEAR(MeanCosineByQuadrature([&](double mu) { return mix.Evaluate(mu); }, g),
      mix.MeanCosine(), 1e-8);
  }
  EXPECT_NEAR(MeanCosineByQuadrature([](double mu) { return nimbus::Rayleigh(mu); }, 0.0),
    nimbus::RayleighMeanCosine(), 1e-12);
}

TEST(PhaseFunctions, CornetteShanksIsRayleighAtZeroG)
{
  for (double mu = -1.0; mu <= 1.0; mu += 0.125)
  {
    EXPECT_NEAR(nimbus::CornetteShanks(mu, 0.0), nimbus::Rayleigh(mu), 1e-15);
  }
}

// Chi-square goodness of fit: 32 bins of (nearly) equal expected probability,
// 2e5 samples, fixed seed; the statistic must stay below chi^2_{31}(p=0.001) =
// 61.098.  The sample mean of mu must match the analytic <mu> within 5 standard errors.
TEST(PhaseFunctions, SamplersMatchPdf)
{
  struct Case
  {
    const char* name;
    double g;
    Pdf pdf;
    std::function<double(std::mt19937_64&)> sample;
    double mean;
  };
  std::vector<Case> cases;
  for (double g : { -0.5, 0.0, 0.5, 0.9, 0.99 })
  {
    cases.push_back({ "HG", g, [g](double mu) { return nimbus::HenyeyGreenstein(mu, g); },
      [g](std::mt19937_64& r) { return nimbus::SampleHenyeyGreenstein(g, Uniform01(r)); },
      nimbus::HenyeyGreensteinMeanCosine(g) });
    cases.push_back({ "CS", g, [g](double mu) { return nimbus::CornetteShanks(mu, g); },
      [g](std::mt19937_64& r)
      { return nimbus::SampleCornetteShanks(g, [&r] { return Uniform01(r); }); },
      nimbus::CornetteShanksMeanCosine(g) });
  }
  cases.push_back({ "Rayleigh", 0.0, [](double mu) { return nimbus::Rayleigh(mu); },
    [](std::mt19937_64& r) { return nimbus::SampleRayleigh(Uniform01(r)); }, 0.0 });
  for (double g : { 0.76, 0.99 })
  {
    const auto mix = std::make_shared<nimbus::PhaseFunctionMixture>(CloudMixture(g));
    cases.push_back({ "5%R+95%CS", g, [mix](double mu) { return mix->Pdf(mu); },
      [mix](std::mt19937_64& r) { return mix->Sample([&r] { return Uniform01(r); }); },
      mix->MeanCosine() });
  }
  std::uint64_t seed = 20240611;
  for (const Case& c : cases)
  {
    std::mt19937_64 rng(seed++);
    const ChiSquareResult r = ChiSquare(c.pdf, c.g, [&] { return c.sample(rng); });
    std::printf("%-10s g=%5.2f  chi2=%6.2f (df=31, crit 61.10)  p=%.3f  <mu> sample %.5f "
                "analytic %.5f  (%.2f SE)\n",
      c.name, c.g, r.chi2, r.pValue, r.sampleMean, c.mean,
      (r.sampleMean - c.mean) / r.standardError);
    EXPECT_LT(r.chi2, kChiSquareCritical) << c.name << " g=" << c.g;
    EXPECT_LT(std::abs(r.sampleMean - c.mean), 5.0 * r.standardError) << c.name << " g=" << c.g;
  }
}

TEST(PhaseFunctions, CornetteShanksRejectionCost)
{
  for (double g : { 0.0, 0.5, 0.9 })
  {
    std::mt19937_64 rng(7);
    long draws = 0;
    const int n = 100000;
    for (int i = 0; i < n; ++i)
    {
      nimbus::SampleCornetteShanks(g,
        [&]
        {
          ++draws;
          return Uniform01(rng);
        });
    }
    const double perSample = static_cast<double>(draws) / n;
    EXPECT_NEAR(perSample, 6.0 / (2.0 + g * g), 0.02) << g; // documented expectation
  }
}

TEST(PhaseFunctions, FiniteAtExtremes)
{
  const double uMax = std::nextafter(1.0, 0.0);
  for (double g : { -0.9999, 0.9999, -1.0, 1.0, -0.999999999, 0.999999999, -1e-12, 1e-12, 0.0 })
  {
    for (double mu : { -1.0, 0.0, 1.0 })
    {
      for (double v : { nimbus::HenyeyGreenstein(mu, g), nimbus::CornetteShanks(mu, g) })
      {
        EXPECT_TRUE(std::isfinite(v)) << g << " " << mu;
        EXPECT_GT(v, 0.0);
      }
    }
    for (double u : { 0.0, 1e-300, 0.5, uMax, 1.0 })
    {
      const double mu = nimbus::SampleHenyeyGreenstein(g, u);
      EXPECT_TRUE(std::isfinite(mu) && mu >= -1.0 && mu <= 1.0) << g << " " << u;
      const auto d = nimbus::SampleHenyeyGreensteinDirection({ 0.0, 0.0, -2.0 }, g, u, u);
      EXPECT_NEAR(d[0] * d[0] + d[1] * d[1] + d[2] * d[2], 1.0, 1e-12);
    }
    EXPECT_DOUBLE_EQ(nimbus::SampleHenyeyGreenstein(g, 0.0), -1.0);
    // Near u = 1, 1 - mu ~ (1 - u) / (2 pi p(1)): tiny for g > 0, ~1e-9 for g -> -1.
    const double slack =
      2.0 * (1.0 - uMax) / (2.0 * kPi * nimbus::HenyeyGreenstein(1.0, g)) + 1e-15;
    EXPECT_NEAR(nimbus::SampleHenyeyGreenstein(g, uMax), 1.0, slack) << g;
    // CS proposals with u = 0 and u -> 1 (acceptance uniform 0, so accepted).
    EXPECT_DOUBLE_EQ(nimbus::SampleCornetteShanks(g, [] { return 0.0; }), -1.0);
    int call = 0;
    EXPECT_NEAR(
      nimbus::SampleCornetteShanks(g, [&] { return (call++ % 2 == 0) ? uMax : 0.0; }), 1.0, slack);
  }
  for (double u : { 0.0, 0.5, uMax })
  {
    EXPECT_TRUE(std::isfinite(nimbus::SampleRayleigh(u)));
  }
  EXPECT_DOUBLE_EQ(nimbus::SampleRayleigh(0.0), -1.0);
  EXPECT_NEAR(nimbus::SampleRayleigh(0.5), 0.0, 1e-15);
  EXPECT_NEAR(nimbus::SampleRayleigh(uMax), 1.0, 1e-12);
  // Peak value at the clamp: (1 + g)/(4 pi (1 - g)^2) with 1 - g = 1e-6.
  EXPECT_NEAR(nimbus::HenyeyGreenstein(1.0, 1.0), (2.0 - 1e-6) / (4.0 * kPi * 1e-12), 1e3);
}

TEST(PhaseFunctions, InvalidArguments)
{
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(nimbus::HenyeyGreenstein(0.0, nan), std::invalid_argument);
  EXPECT_THROW(nimbus::CornetteShanks(0.0, nan), std::invalid_argument);
  EXPECT_THROW(nimbus::SampleHenyeyGreenstein(nan, 0.5), std::invalid_argument);
  EXPECT_THROW(
    nimbus::SampleHenyeyGreensteinDirection({ 0, 0, 0 }, 0.5, 0.5, 0.5), std::invalid_argument);
  nimbus::PhaseFunctionMixture m;
  EXPECT_THROW(m.AddComponent(-1.0, PhaseFunctionKind::Rayleigh), std::invalid_argument);
  EXPECT_THROW(m.AddComponent(1.0, PhaseFunctionKind::CornetteShanks, nan), std::invalid_argument);
  EXPECT_THROW(m.Sample([] { return 0.5; }), std::logic_error);
  EXPECT_EQ(m.Evaluate(0.3), 0.0);
}

TEST(PhaseFunctions, MixtureWeightsNormalised)
{
  nimbus::PhaseFunctionMixture m;
  m.AddComponent(1.0, PhaseFunctionKind::Rayleigh);
  m.AddComponent(19.0, PhaseFunctionKind::CornetteShanks, 0.8);
  ASSERT_EQ(m.GetComponents().size(), 2u);
  EXPECT_DOUBLE_EQ(m.GetComponents()[0].weight, 0.05);
  EXPECT_DOUBLE_EQ(m.GetComponents()[1].weight, 0.95);
  for (double mu : { -1.0, -0.3, 0.0, 0.7, 1.0 })
  {
    const double expected = 0.05 * nimbus::Rayleigh(mu) + 0.95 * nimbus::CornetteShanks(mu, 0.8);
    EXPECT_NEAR(m.Evaluate(mu), expected, 1e-14 * expected);
    EXPECT_EQ(m.Pdf(mu), m.Evaluate(mu));
  }
  EXPECT_EQ(m.SelectComponent(0.0), 0u);
  EXPECT_EQ(m.SelectComponent(0.049), 0u);
  EXPECT_EQ(m.SelectComponent(0.051), 1u);
  EXPECT_EQ(m.SelectComponent(std::nextafter(1.0, 0.0)), 1u);
}

TEST(PhaseFunctions, DirectionHasRequestedCosine)
{
  std::mt19937_64 rng(3);
  const std::array<std::array<double, 3>, 4> incidents = { { { 0, 0, 1 }, { 0, 0, -1 }, { 1, 2, 3 },
    { -0.3, 0.1, -5 } } };
  for (const auto& w : incidents)
  {
    const double len = std::sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
    for (int i = 0; i < 1000; ++i)
    {
      const double u1 = Uniform01(rng), u2 = Uniform01(rng);
      const auto d = nimbus::SampleHenyeyGreensteinDirection(w, 0.7, u1, u2);
      const double mu = (d[0] * w[0] + d[1] * w[1] + d[2] * w[2]) / len;
      EXPECT_NEAR(d[0] * d[0] + d[1] * d[1] + d[2] * d[2], 1.0, 1e-12);
      EXPECT_NEAR(mu, nimbus::SampleHenyeyGreenstein(0.7, u1), 1e-12);
    }
  }
}
