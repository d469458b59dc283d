// The independent slab solver (Reference/Core/SlabSolver.h): energy conservation,
// the semi-infinite limit against Chandrasekhar's H-function, the H-function against its
// closed-form integral and published constants, the thin-slab (single-scattering) limit,
// DISORT's test problems 1 and 3 (van de Hulst 1980 Tables 12 and 35), the thick
// conservative slab's asymptotic transmission, convergence in N and in the starting
// thickness, bad input, and the table of R and T printed for the path-tracer check.
//
// Tolerances are a few times the differences measured when this test was written
// (stated at each check); every check compares against a value computed another way, so
// it fails when the solver's physics or normalisation is wrong.
#include "PhaseFunctions.h"
#include "SlabSolver.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

namespace
{
using nimbus::slab::IsotropicHFunction;
using nimbus::slab::Phase;
using nimbus::slab::Problem;
using nimbus::slab::Result;
using nimbus::slab::Solve;

constexpr double kPi = 3.14159265358979323846;

Problem Slab(double tau, double omega, Phase phase, double g, double mu0, int n = 32)
{
  Problem p;
  p.OpticalThickness = tau;
  p.SingleScatteringAlbedo = omega;
  p.PhaseFunction = phase;
  p.Asymmetry = g;
  p.Mu0 = mu0;
  p.QuadraturePoints = n;
  return p;
}

// Composite Gauss-Legendre integral of f over [a, b] split at the given interior points.
template <class F>
double Integrate(F f, std::vector<double> edges, int points = 32)
{
  std::vector<double> x, w;
  nimbus::slab::GaussLegendre01(points, x, w);
  double sum = 0.0;
  for (std::size_t k = 0; k + 1 < edges.size(); ++k)
  {
    const double a = edges[k];
    const double b = edges[k + 1];
    for (int i = 0; i < points; ++i)
    {
      sum += (b - a) * w[i] * f(a + (b - a) * x[i]);
    }
  }
  return sum;
}

// Chandrasekhar 1960 ("Radiative Transfer", ch. V), the explicit integral for isotropic
// scattering: ln H(mu) = -(mu/pi) int_0^{pi/2} ln(1 - omega theta cot theta) /
// (cos^2 theta + mu^2 sin^2 theta) dtheta. Independent of the iteration in SlabSolver.cxx.
// For omega = 1 the log is singular (like 2 ln theta) at 0: geometric intervals.
double HFromIntegral(double mu, double omega)
{
  std::vector<double> edges{ 0.0 };
  for (int k = -14; k <= -1; ++k)
  {
    edges.push_back(std::pow(10.0, k));
  }
  edges.push_back(0.5);
  // Near pi/2 the denominator has a peak of width ~mu: geometric intervals there too.
  for (int k = 0; k >= -10; --k)
  {
    edges.push_back(kPi / 2 - std::pow(10.0, k));
  }
  edges.push_back(kPi / 2);
  const auto f = [&](double theta)
  {
    // 1 - theta cot theta, by its series near 0 to avoid cancellation.
    const double tc = theta < 1e-3 ? 1.0 - theta * theta / 3.0 - std::pow(theta, 4) / 45.0
                                   : theta * std::cos(theta) / std::sin(theta);
    const double c = std::cos(theta);
    const double s = std::sin(theta);
    const double arg = omega == 1.0 && theta < 1e-3
      ? theta * theta / 3.0 + std::pow(theta, 4) / 45.0
      : 1.0 - omega * tc;
    return std::log(arg) / (c * c + mu * mu * s * s);
  };
  return std::exp(-mu / kPi * Integrate(f, edges));
}

// The backscattered fraction of single scattering for a beam at mu0, integrated from the
// full (untruncated) Henyey-Greenstein function of Physics/PhaseFunctions.h:
//   beta(mu0) = int_0^1 dmu int_0^{2 pi} dphi p(cos Theta),  cos Theta = -mu mu0 + s s0 cos phi
// (p normalised to 1 over the sphere). Isotropic: 1/2.
double BackscatterFraction(double g, double mu0)
{
  const double s0 = std::sqrt(1.0 - mu0 * mu0);
  const int phiSteps = 2048; // periodic trapezoid rule: spectrally accurate
  const auto inner = [&](double mu)
  {
    const double s = std::sqrt(1.0 - mu * mu);
    double sum = 0.0;
    for (int k = 0; k < phiSteps; ++k)
    {
      const double phi = 2.0 * kPi * (k + 0.5) / phiSteps;
      sum += nimbus::HenyeyGreenstein(-mu * mu0 + s * s0 * std::cos(phi), g);
    }
    return sum * 2.0 * kPi / phiSteps;
  };
  return Integrate(inner, { 0.0, 0.25, 0.5, 0.75, 1.0 }, 48);
}

} // namespace

// 1. omega = 1: everything that enters leaves. Measured |R + T + direct - 1| <= 4.1e-14
// (N = 32; 1.1e-13 with N = 8 at tau = 100): rounding only, because the diamond start and the
// Legendre series truncated at 2N - 1 conserve energy exactly on the grid.
TEST(SlabSolver, ConservativeSlabsConserveEnergy)
{
  double worst = 0.0;
  for (const Phase phase : { Phase::Isotropic, Phase::HenyeyGreenstein })
  {
    for (const double tau : { 1.0, 10.0, 100.0 })
    {
      for (const double mu0 : { 1.0, 0.5, 0.1 })
      {
        const Result r = Solve(Slab(tau, 1.0, phase, 0.85, mu0));
        const double sum = r.Reflectance + r.DiffuseTransmittance + r.DirectTransmittance;
        worst = std::max(worst, std::fabs(sum - 1.0));
        EXPECT_NEAR(sum, 1.0, 1e-12) << "tau " << tau << " mu0 " << mu0;
        EXPECT_NEAR(r.SphericalAlbedo + r.DiffuseIncidenceTransmittance, 1.0, 1e-12);
        EXPECT_NEAR(r.DirectTransmittance, std::exp(-tau / mu0), 1e-15);
        // Absorption: omega < 1 must lose energy (about (1 - omega) x path length).
        const Result a = Solve(Slab(tau, 0.99, phase, 0.85, mu0));
        EXPECT_LT(a.Reflectance + a.DiffuseTransmittance + a.DirectTransmittance, 1.0 - 1e-3);
      }
    }
  }
  std::printf("omega = 1: max |R + T + direct - 1| = %.2e\n", worst);
}

// 2. Semi-infinite, isotropic: plane albedo r(mu0) = 1 - H(mu0) sqrt(1 - omega)
// (Chandrasekhar 1960; van de Hulst 1980, semi-infinite media). Measured max difference 4.7e-10
// (N = 32, mu0 = 0.1: the discrete-ordinate error), so 2e-9. The reflected radiances at the
// nodes: measured relative 9e-9 for mu >= 0.01 (tolerance 3e-8), 3.1e-5 at the grazing nodes
// mu < 0.01 (tolerance 1e-4), where N-point discrete ordinates are least accurate (N = 64
// halves the first node and gives 8e-6 there).
TEST(SlabSolver, SemiInfiniteMatchesHFunction)
{
  double worstRadiance = 0.0; // nodes mu >= 0.01
  double worstGrazing = 0.0;  // the two nodes below (0.0014, 0.0072 for N = 32)
  for (const double omega : { 0.5, 0.9, 0.99, 0.999 })
  {
    const IsotropicHFunction h(omega);
    for (const double mu0 : { 0.1, 0.3, 0.5, 0.8, 1.0 })
    {
      const Result r =
        Solve(Slab(std::numeric_limits<double>::infinity(), omega, Phase::Isotropic, 0.0, mu0));
      EXPECT_NEAR(r.Reflectance, 1.0 - h(mu0) * std::sqrt(1.0 - omega), 2e-9)
        << "omega " << omega << " mu0 " << mu0;
      EXPECT_EQ(r.DirectTransmittance, 0.0);
      EXPECT_LT(r.DiffuseTransmittance, 1e-14);
      // The radiances: I(mu) = mu0 R(mu, mu0), R = (omega/4) H(mu) H(mu0) / (mu + mu0)
      // (Chandrasekhar 1960 ch. IV, isotropic scattering).
      for (std::size_t i = 0; i < r.Mu.size(); ++i)
      {
        const double expected = mu0 * 0.25 * omega * h(r.Mu[i]) * h(mu0) / (r.Mu[i] + mu0);
        const double difference = std::fabs(r.ReflectedRadiance[i] / expected - 1.0);
        double& worst = r.Mu[i] >= 0.01 ? worstRadiance : worstGrazing;
        worst = std::max(worst, difference);
      }
    }
  }
  std::printf("semi-infinite radiances vs H: max relative difference %.2e (mu >= 0.01), %.2e "
              "(mu < 0.01)\n",
    worstRadiance, worstGrazing);
  EXPECT_LT(worstRadiance, 3e-8);
  EXPECT_LT(worstGrazing, 1e-4);
}

// 3a. The H-function against published constants for omega = 1: H(1) = 2.90781
// (Chandrasekhar 1960, table of H for omega0 = 1), alpha_1 = 2/sqrt(3) exactly, and the Hopf
// constant q(inf) = (sqrt(3)/2) alpha_2 = 0.710446089598 (Milne problem; Chandrasekhar 1960
// ch. IV). For all omega: H(0) = 1 and alpha_0 = 2 (1 - sqrt(1 - omega)) / omega, both exact
// consequences of the equation, here checks of the quadrature (measured errors <= 2e-15).
TEST(SlabSolver, HFunctionPublishedValues)
{
  const IsotropicHFunction h(1.0);
  EXPECT_NEAR(h(1.0), 2.90781, 5e-6); // table value, 5 decimals
  EXPECT_NEAR(h.Moment(1), 2.0 / std::sqrt(3.0), 1e-13);
  EXPECT_NEAR(std::sqrt(3.0) / 2.0 * h.Moment(2), 0.710446089598, 1e-11);
  std::printf("H(1) - 2.90781 = %.2e, alpha1 - 2/sqrt(3) = %.2e, q - 0.710446089598 = %.2e\n",
    h(1.0) - 2.90781, h.Moment(1) - 2.0 / std::sqrt(3.0),
    std::sqrt(3.0) / 2.0 * h.Moment(2) - 0.710446089598);
  std::printf("H(mu), omega = 1:");
  for (const double mu : { 0.0, 0.1, 0.2, 0.5, 1.0 })
  {
    std::printf("  H(%.1f) = %.6f", mu, h(mu));
  }
  std::printf("\n");
  for (const double omega : { 0.0, 0.3, 0.5, 0.9, 0.99, 0.999, 1.0 })
  {
    const IsotropicHFunction hw(omega);
    EXPECT_NEAR(hw(0.0), 1.0, 1e-13) << omega;
    const double alpha0 = omega == 0.0 ? 1.0 : 2.0 * (1.0 - std::sqrt(1.0 - omega)) / omega;
    EXPECT_NEAR(hw.Moment(0), alpha0, 1e-13) << omega;
    EXPECT_LT(hw.Iterations(), 200);
  }
}

// 3b. The iterated H against Chandrasekhar's explicit integral (computed here by its own
// quadrature). Measured max difference 3.6e-14; tolerance 1e-12.
TEST(SlabSolver, HFunctionMatchesExplicitIntegral)
{
  double worst = 0.0;
  for (const double omega : { 0.5, 0.9, 0.99, 1.0 })
  {
    const IsotropicHFunction h(omega);
    for (const double mu : { 0.01, 0.1, 0.5, 1.0 })
    {
      const double explicitH = HFromIntegral(mu, omega);
      worst = std::max(worst, std::fabs(h(mu) - explicitH));
      EXPECT_NEAR(h(mu), explicitH, 1e-12) << "omega " << omega << " mu " << mu;
    }
  }
  std::printf("H iterated vs explicit integral: max difference %.2e\n", worst);
}

// 3c. Thin slab, first order in tau (single scattering, van de Hulst 1980, thin layers):
//   R = omega tau beta(mu0) / mu0,   T_diffuse = omega tau (1 - beta(mu0)) / mu0,
// beta the backscattered fraction (1/2 for isotropic; for HG integrated from the full HG
// function, not from the solver's truncated series). The neglected terms are relative
// O(tau (1 + mu0 ln(1/tau)) / mu0) (the exact single-scattering integral) and O(omega tau)
// (multiple scattering): measured <= 1.5e-6 at tau = 1e-6; tolerance 5e-6. At tau = 1e-4 the
// difference must be about 100 times larger (so it is the O(tau) term, not noise). N = 64:
// single scattering sees the truncated series directly, and at N = 32 (degree 63) it shifts
// the HG backscatter at mu0 = 1 by 4e-5 relative (N = 64: 1e-8; multiple scattering smooths
// this, see the convergence test).
TEST(SlabSolver, ThinSlabMatchesSingleScattering)
{
  for (const Phase phase : { Phase::Isotropic, Phase::HenyeyGreenstein })
  {
    for (const double mu0 : { 1.0, 0.5 })
    {
      const double g = 0.85;
      const double beta = phase == Phase::Isotropic ? 0.5 : BackscatterFraction(g, mu0);
      const double omega = 0.9;
      double previous = 0.0;
      for (const double tau : { 1e-6, 1e-4 })
      {
        const Result r = Solve(Slab(tau, omega, phase, g, mu0, 64));
        const double rFirst = omega * tau * beta / mu0;
        const double tFirst = omega * tau * (1.0 - beta) / mu0;
        const double dr = std::fabs(r.Reflectance / rFirst - 1.0);
        const double dt = std::fabs(r.DiffuseTransmittance / tFirst - 1.0);
        std::printf("thin slab %s mu0 %.1f tau %g: beta %.8f  R/R1 - 1 = %.2e  T/T1 - 1 = %.2e\n",
          phase == Phase::Isotropic ? "iso" : "HG0.85", mu0, tau, beta, r.Reflectance / rFirst - 1,
          r.DiffuseTransmittance / tFirst - 1);
        if (tau == 1e-6)
        {
          EXPECT_LT(dr, 5e-6);
          EXPECT_LT(dt, 5e-6);
          previous = std::max(dr, dt);
        }
        else
        {
          EXPECT_GT(std::max(dr, dt), 20.0 * previous);
        }
      }
    }
  }
}

// 3d. DISORT's test problem 1 (Stamnes et al. 1988; DISOTEST, "compare to van de Hulst 1980
// Table 12"): isotropic, mu0 = 0.1, incident flux pi, black ground; its 16-stream results
// (8 per hemisphere), printed to 6 digits. The same discrete-ordinate problem with N = 8
// must agree to the printed digits (relative 1e-5; measured <= 1.6e-6, within the rounding
// of the 6th digit). Cases C and F are
// isotropic diffuse incidence of radiance 1.
TEST(SlabSolver, DisortTestProblem1)
{
  struct Case
  {
    double Tau, Omega;
    bool Beam;
    double Up, Down; // flux up at the top, diffuse flux down at the bottom
  };
  const Case cases[] = { { 0.03125, 0.2, true, 7.99451e-02, 7.94108e-02 },
    { 0.03125, 1.0, true, 4.22922e-01, 4.20233e-01 },
    { 0.03125, 0.99, false, 9.06556e-02, 3.04897e+00 }, { 32.0, 0.2, true, 2.59686e-01, 0.0 },
    { 32.0, 1.0, true, 3.07390e+00, 6.76954e-02 },
    { 32.0, 0.99, false, 2.49618e+00, 4.60048e-03 } };
  for (const Case& c : cases)
  {
    for (const int n : { 8, 32 })
    {
      const Result r = Solve(Slab(c.Tau, c.Omega, Phase::Isotropic, 0.0, 0.1, n));
      // Beam: flux pi mu0 F0 with pi F0 = pi / mu0, i.e. pi; diffuse: flux pi. DISORT's
      // downward flux for diffuse incidence includes the directly transmitted part.
      const double up = kPi * (c.Beam ? r.Reflectance : r.SphericalAlbedo);
      const double down = kPi * (c.Beam ? r.DiffuseTransmittance : r.DiffuseIncidenceTransmittance);
      std::printf("DISORT 1: tau %g omega %g %s N %2d: up %.6e (DISORT %.5e) down %.6e "
                  "(DISORT %.5e)\n",
        c.Tau, c.Omega, c.Beam ? "beam" : "diffuse", n, up, c.Up, down, c.Down);
      if (n == 8)
      {
        EXPECT_NEAR(up, c.Up, 1e-5 * c.Up);
        EXPECT_NEAR(down, c.Down, 1e-5 * c.Down + 1e-12);
      }
    }
  }
}

// 3e. DISORT's test problem 3 (HG g = 0.75, mu0 = 0.1, "compare to van de Hulst 1980 Table
// 35"), which DISORT solves with 16 streams and delta-M scaling, an approximation: our
// converged (N = 32, full series) fluxes agree to relative 9e-4 for the beam (measured;
// tolerance 2e-3) and 2e-6 for diffuse incidence (tolerance 2e-5).
TEST(SlabSolver, DisortTestProblem3)
{
  struct Case
  {
    double Tau, Omega;
    bool Beam;
    double Up, Down;
  };
  const Case cases[] = { { 1.0, 0.2, true, 1.69951e-01, 4.70303e-02 },
    { 1.0, 1.0, true, 1.82690e+00, 1.31455e+00 }, { 1.0, 0.99, false, 5.83122e-01, 2.49660e+00 },
    { 8.0, 0.2, true, 1.70062e-01, 1.99813e-05 }, { 8.0, 1.0, true, 2.54962e+00, 5.91973e-01 },
    { 8.0, 0.99, false, 1.68750e+00, 1.01167e+00 } };
  for (const Case& c : cases)
  {
    const Result r = Solve(Slab(c.Tau, c.Omega, Phase::HenyeyGreenstein, 0.75, 0.1));
    const double up = kPi * (c.Beam ? r.Reflectance : r.SphericalAlbedo);
    const double down = kPi * (c.Beam ? r.DiffuseTransmittance : r.DiffuseIncidenceTransmittance);
    std::printf("DISORT 3: tau %g omega %g %s: up %.6e (DISORT %.5e) down %.6e (DISORT %.5e)\n",
      c.Tau, c.Omega, c.Beam ? "beam" : "diffuse", up, c.Up, down, c.Down);
    const double tolerance = c.Beam ? 2e-3 : 2e-5;
    EXPECT_NEAR(up, c.Up, tolerance * c.Up);
    EXPECT_NEAR(down, c.Down, tolerance * c.Down);
  }
}

// 3f. Thick conservative isotropic slab (van de Hulst 1980, asymptotic theory of thick layers):
// total transmission t(mu0) = 4 K(mu0) / (3 (tau + 2 q0)), with the escape function
// K(mu) = (sqrt(3)/4) H(mu) and q0 = 0.710446 the Hopf constant; the corrections decay
// like exp(-tau), so at tau = 100 the formula is exact to rounding. Measured relative
// difference 1.6e-9 at mu0 = 0.1, 3e-10 at mu0 = 0.5 and 1 (N = 32: the same
// discrete-ordinate error as in the semi-infinite check); tolerance 5e-9.
TEST(SlabSolver, ThickConservativeSlabMatchesAsymptotics)
{
  const IsotropicHFunction h(1.0);
  const double q0 = std::sqrt(3.0) / 2.0 * h.Moment(2);
  const double tau = 100.0;
  for (const double mu0 : { 0.1, 0.5, 1.0 })
  {
    const Result r = Solve(Slab(tau, 1.0, Phase::Isotropic, 0.0, mu0));
    const double expected = std::sqrt(3.0) * h(mu0) / (3.0 * (tau + 2.0 * q0));
    const double total = r.DiffuseTransmittance + r.DirectTransmittance;
    std::printf("thick tau 100 mu0 %.1f: T %.12f asymptotic %.12f\n", mu0, total, expected);
    EXPECT_NEAR(total / expected, 1.0, 5e-9);
  }
}

// 4. Convergence in N (quadrature points per hemisphere) and in the starting thickness.
// Measured: isotropic changes N 32 -> 64 <= 1e-10, HG g = 0.85 <= 7.8e-9 (mu0 = 1, tau = 1;
// its truncated series converges like g^{2N}); starting thickness 1e-6 -> 1e-7 -> 1e-8
// <= 3e-14. Tolerances: 3e-8 in N, 1e-10 in the start thickness.
TEST(SlabSolver, ConvergesInQuadratureAndStartThickness)
{
  std::printf("Convergence (omega 0.99): R and T against N (start 1e-7)\n");
  std::printf("%-7s %5s %4s %4s %16s %16s\n", "phase", "tau", "mu0", "N", "R", "T diffuse");
  for (const Phase phase : { Phase::Isotropic, Phase::HenyeyGreenstein })
  {
    for (const double tau : { 1.0, 10.0, 100.0 })
    {
      for (const double mu0 : { 1.0, 0.5 })
      {
        double lastR = 0.0;
        double lastT = 0.0;
        for (const int n : { 8, 16, 32, 64 })
        {
          const Result r = Solve(Slab(tau, 0.99, phase, 0.85, mu0, n));
          std::printf("%-7s %5g %4.1f %4d %16.12f %16.12f\n",
            phase == Phase::Isotropic ? "iso" : "HG0.85", tau, mu0, n, r.Reflectance,
            r.DiffuseTransmittance);
          if (n == 64)
          {
            EXPECT_NEAR(r.Reflectance, lastR, 3e-8);
            EXPECT_NEAR(r.DiffuseTransmittance, lastT, 3e-8);
          }
          lastR = r.Reflectance;
          lastT = r.DiffuseTransmittance;
        }
      }
    }
  }
  std::printf("Start thickness (HG 0.85, tau 10, omega 0.99, mu0 0.5, N 32)\n");
  std::vector<double> reflectances;
  for (const double start : { 1e-4, 1e-5, 1e-6, 1e-7, 1e-8 })
  {
    Problem p = Slab(10.0, 0.99, Phase::HenyeyGreenstein, 0.85, 0.5);
    p.InitialThickness = start;
    const Result r = Solve(p);
    std::printf("start <= %g: tau0 %.3e, %d doublings, R %.14f T %.14f\n", start, r.StartThickness,
      r.Doublings, r.Reflectance, r.DiffuseTransmittance);
    reflectances.push_back(r.Reflectance);
  }
  EXPECT_NEAR(reflectances[3], reflectances[4], 1e-10);
  EXPECT_NEAR(reflectances[2], reflectances[3], 1e-10);
}

// 5. Bad input: clear std::invalid_argument messages.
TEST(SlabSolver, BadInputThrows)
{
  const auto expectMessage = [](const Problem& p, const std::string& part)
  {
    try
    {
      Solve(p);
      ADD_FAILURE() << "no exception for " << part;
    }
    catch (const std::invalid_argument& e)
    {
      EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
    }
  };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const Problem good = Slab(1.0, 0.9, Phase::HenyeyGreenstein, 0.5, 0.5);
  Problem p = good;
  p.OpticalThickness = nan;
  expectMessage(p, "optical thickness");
  p.OpticalThickness = -1.0;
  expectMessage(p, "optical thickness");
  p = good;
  p.SingleScatteringAlbedo = 1.0 + 1e-12;
  expectMessage(p, "albedo");
  p.SingleScatteringAlbedo = -0.1;
  expectMessage(p, "albedo");
  p.SingleScatteringAlbedo = nan;
  expectMessage(p, "albedo");
  p = good;
  for (const double g : { 1.0, -1.0, nan })
  {
    p.Asymmetry = g;
    expectMessage(p, "asymmetry");
  }
  p = good;
  for (const double mu0 : { 0.0, -0.5, 1.5, nan })
  {
    p.Mu0 = mu0;
    expectMessage(p, "mu0");
  }
  p = good;
  p.QuadraturePoints = 0;
  expectMessage(p, "quadrature points");
  p = good;
  p.InitialThickness = 0.0;
  expectMessage(p, "initial layer");
  p = Slab(std::numeric_limits<double>::infinity(), 1.0, Phase::Isotropic, 0.0, 0.5);
  expectMessage(p, "semi-infinite");
  EXPECT_THROW(IsotropicHFunction{ 1.5 }, std::invalid_argument);
  EXPECT_THROW(IsotropicHFunction{ nan }, std::invalid_argument);
  EXPECT_THROW(IsotropicHFunction(0.5)(-0.1), std::invalid_argument);
  // g = +-1 is refused, but g is ignored (and may be anything) for isotropic scattering.
  p = Slab(1.0, 0.9, Phase::Isotropic, 1.0, 0.5);
  EXPECT_NO_THROW(Solve(p));
  // tau = 0: nothing scatters.
  const Result empty = Solve(Slab(0.0, 0.9, Phase::Isotropic, 0.0, 0.5));
  EXPECT_EQ(empty.Reflectance, 0.0);
  EXPECT_EQ(empty.DirectTransmittance, 1.0);
}

// The table for the path-tracer check (docs/ground-truth.md): plane albedo R and diffuse
// transmittance T, fractions of the incident flux; direct = exp(-tau/mu0). N = 32.
// Also checks that R and T are in [0, 1] and R rises with omega.
TEST(SlabSolver, PrintsReferenceTable)
{
  std::printf("| phase | omega | tau | mu0 | R | T diffuse | direct |\n");
  std::printf("|---|---|---|---|---|---|---|\n");
  for (const Phase phase : { Phase::Isotropic, Phase::HenyeyGreenstein })
  {
    for (const double omega : { 0.5, 0.9, 0.99, 0.999 })
    {
      for (const double tau : { 1.0, 10.0, 100.0 })
      {
        for (const double mu0 : { 1.0, 0.5 })
        {
          const Result r = Solve(Slab(tau, omega, phase, 0.85, mu0));
          std::printf("| %s | %g | %g | %g | %.8g | %.8g | %.4e |\n",
            phase == Phase::Isotropic ? "isotropic" : "HG g=0.85", omega, tau, mu0, r.Reflectance,
            r.DiffuseTransmittance, r.DirectTransmittance);
          EXPECT_GT(r.Reflectance, 0.0);
          EXPECT_GT(r.DiffuseTransmittance, 0.0);
          EXPECT_LT(r.Reflectance + r.DiffuseTransmittance + r.DirectTransmittance, 1.0);
        }
      }
    }
  }
}
