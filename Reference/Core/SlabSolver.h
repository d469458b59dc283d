// An independent plane-parallel slab radiative-transfer solver (adding-doubling) and
// Chandrasekhar's H-function for isotropic scattering. Plain C++, no VTK, no Monte Carlo:
// it exists to judge the path tracer on homogeneous slabs.
//
// The slab: homogeneous, optical thickness tau (dimensionless), single-scattering albedo
// omega, phase function isotropic or Henyey-Greenstein (g), black (non-reflecting) lower
// boundary, no emission. It is lit from above by a collimated beam of cosine mu0.
//
// Normalisation (van de Hulst 1980 "Multiple Light Scattering"; Hansen & Travis 1974
// "Light scattering in planetary atmospheres" §3): the beam carries flux pi*F0 per unit
// area normal to it, F0 = 1, i.e. pi*mu0 per unit horizontal area. A radiance I is in units
// of F0 (1/sr per unit F0), so I(mu) = mu0 * R(mu, mu0) with R van de Hulst's reflection
// function; a white Lambertian ground would have I = mu0. Fluxes are reported as fractions
// of the incident flux pi*mu0.
//
// Method (SlabSolver.cxx has the equations): the azimuth-averaged (m = 0) radiance on a
// double-Gauss grid of N cosines per hemisphere (Gauss-Legendre on [0, 1]; the discrete
// ordinates of Chandrasekhar 1960 ch. II with the double-Gauss split of Sykes 1951). A starting
// layer of thickness tau / 2^n <= InitialThickness is solved by the diamond-difference
// initialisation of Wiscombe 1976 (JQSRT 16, 637) and doubled n times with the
// adding-doubling equations of Hansen & Travis 1974 §3, here in matrix-operator form
// (Plass, Kattawar & Catchings 1973, Appl. Opt. 12, 314). Direct (unscattered) light is carried
// exactly (exp(-tau/mu)) and never enters the diffuse matrices; the beam at mu0 is one extra column
// (source term solved explicitly), so mu0 need not be a quadrature node.
#ifndef NimbusSlabSolver_h
#define NimbusSlabSolver_h

#include "NimbusReferenceModule.h"

#include <vector>

namespace nimbus
{
namespace slab
{

enum class Phase
{
  Isotropic,       // p = 1/(4 pi); Asymmetry ignored
  HenyeyGreenstein // Legendre coefficients chi_l = g^l (van de Hulst 1980)
};

struct NIMBUSREFERENCE_EXPORT Problem
{
  /// tau >= 0 (dimensionless). +infinity: a semi-infinite slab (doubled until the
  /// reflection has converged; needs omega < 1 since for omega = 1 it converges as 1/tau).
  double OpticalThickness = 1.0;
  /// omega in [0, 1].
  double SingleScatteringAlbedo = 1.0;
  Phase PhaseFunction = Phase::Isotropic;
  /// g in (-1, 1), Henyey-Greenstein only.
  double Asymmetry = 0.0;
  /// Cosine of the beam's zenith angle, in (0, 1].
  double Mu0 = 1.0;
  /// Gauss points per hemisphere, 1 ... 512. The phase function's Legendre series is
  /// truncated at degree 2N - 1, the largest the grid integrates exactly (so omega = 1
  /// conserves energy to rounding); no delta-M scaling.
  int QuadraturePoints = 32;
  /// Largest optical thickness of the starting layer, in (0, 1e-2]. The default keeps
  /// tau0 / mu_min <= 2e-4 for N = 32 (measured effect on fluxes below 1e-10).
  double InitialThickness = 1.0e-7;
};

struct NIMBUSREFERENCE_EXPORT Result
{
  /// Diffuse reflectance (plane albedo): reflected flux / (pi mu0).
  double Reflectance = 0.0;
  /// Diffuse transmittance: diffusely transmitted flux / (pi mu0), without the direct beam.
  double DiffuseTransmittance = 0.0;
  /// Direct (unscattered) beam transmittance exp(-tau/mu0).
  double DirectTransmittance = 0.0;
  /// For isotropic diffuse incidence (radiance 1 from the whole upper hemisphere, flux pi):
  /// the spherical albedo (reflected flux / pi) and the total transmittance (diffuse +
  /// direct, / pi).
  double SphericalAlbedo = 0.0;
  double DiffuseIncidenceTransmittance = 0.0;
  /// Quadrature cosines mu_i in (0, 1) (ascending) and weights w_i (sum 1).
  std::vector<double> Mu;
  std::vector<double> Weights;
  /// Azimuth-averaged reflected radiance at the top, I(-mu_i), and diffusely transmitted
  /// radiance at the bottom, I(+mu_i), in units of F0 (see above). Reflectance =
  /// 2 sum_i w_i mu_i ReflectedRadiance[i] / mu0.
  std::vector<double> ReflectedRadiance;
  std::vector<double> TransmittedRadiance;
  /// Thickness of the starting layer and the number of doublings from it.
  double StartThickness = 0.0;
  int Doublings = 0;
};

/// Solves the slab. Throws std::invalid_argument (message naming the bad value) for tau
/// NaN or negative, omega outside [0, 1] or NaN, |g| >= 1 or NaN (HG), mu0 outside (0, 1]
/// or NaN, N outside 1 ... 512, InitialThickness outside (0, 1e-2], or a semi-infinite slab
/// with omega = 1.
NIMBUSREFERENCE_EXPORT Result Solve(const Problem& problem);

/// Gauss-Legendre nodes and weights on [0, 1] (n >= 1), nodes ascending, weights sum 1.
NIMBUSREFERENCE_EXPORT void GaussLegendre01(
  int n, std::vector<double>& nodes, std::vector<double>& weights);

/// Chandrasekhar's H-function for isotropic scattering with albedo omega in [0, 1]
/// (Chandrasekhar 1960 "Radiative Transfer" ch. IV-V, characteristic function omega/2).
/// Solved from the equivalent form (Chandrasekhar 1960 ch. V; Bosma & de Rooij 1983,
/// A&A 126, 283, who recommend it for its convergence)
///   1/H(mu) = sqrt(1 - omega) + (omega/2) int_0^1 mu' H(mu') / (mu + mu') dmu'
/// by fixed-point iteration on a graded composite Gauss rule (geometric intervals from
/// 1e-12 to 1, 24 points each), independent of the slab solver's grid.
class NIMBUSREFERENCE_EXPORT IsotropicHFunction
{
public:
  /// Throws std::invalid_argument for omega outside [0, 1] or NaN.
  explicit IsotropicHFunction(double omega);
  /// H(mu) for mu >= 0 (the Nystrom extension of the solution); throws
  /// std::invalid_argument for a negative or NaN mu.
  double operator()(double mu) const;
  /// The moment alpha_k = int_0^1 H(mu) mu^k dmu (Chandrasekhar 1960 ch. V).
  double Moment(int k) const;
  int Iterations() const { return this->IterationCount; }
  /// max |H_{k+1} - H_k| at the last iteration.
  double LastChange() const { return this->FinalChange; }

private:
  double Omega;
  std::vector<double> Nodes;
  std::vector<double> Weights;
  std::vector<double> Values;
  int IterationCount = 0;
  double FinalChange = 0.0;
};

} // namespace slab
} // namespace nimbus

#endif
