// Phase functions for cloud and sky rendering.
//
// Conventions (all functions in this file):
//  - mu = cos(theta) = dot(incident propagation direction, scattered direction);
//    theta = 0 (mu = +1) is forward scattering, mu = -1 is back scattering.
//  - Every phase function p is normalised over the unit sphere:
//        integral p(mu) dOmega = 2*pi * integral_{-1}^{1} p(mu) dmu = 1,
//    so values are in 1/sr and p is directly the pdf (per steradian) of the
//    scattered direction.  The papers print Cornette-Shanks normalised to 4*pi
//    (000 Eq. 3, 004 Eq. 5); here it is divided by 4*pi.
//  - g is the asymmetry parameter.  |g| is clamped to kMaxAbsAsymmetry = 1 - 1e-6
//    because g = +-1 is a Dirac delta (no finite density); NaN g throws
//    std::invalid_argument.
//  - Samplers take uniforms u in [0,1) and return mu in [-1, 1].
#ifndef nimbus_PhaseFunctions_h
#define nimbus_PhaseFunctions_h

#include "NimbusPhysicsExport.h" // for export macro

#include <array>
#include <cstddef>
#include <vector>

namespace nimbus
{

/// Largest |g| accepted; larger values are clamped.  At |g| = 1 the phase
/// function degenerates to a delta distribution; 1 - 1e-6 keeps the forward
/// peak value HG(1) = (1+g)/(4 pi (1-g)^2) ~ 1.6e11 1/sr finite in double.
constexpr double kMaxAbsAsymmetry = 1.0 - 1e-6;

/// Returns g clamped to [-kMaxAbsAsymmetry, kMaxAbsAsymmetry].
/// Throws std::invalid_argument if g is NaN.
NIMBUSPHYSICS_EXPORT double ClampAsymmetry(double g);

//------------------------------------------------------------------------------
// Henyey-Greenstein:  p(mu) = (1 - g^2) / (4 pi (1 + g^2 - 2 g mu)^{3/2})   [1/sr]
//------------------------------------------------------------------------------
NIMBUSPHYSICS_EXPORT double HenyeyGreenstein(double mu, double g);
/// Analytic inversion of the HG cumulative distribution in mu; u in [0,1).
/// Exactly u = 0 -> mu = -1, u -> 1 -> mu -> 1.  One uniform per sample.
NIMBUSPHYSICS_EXPORT double SampleHenyeyGreenstein(double g, double u);
/// <mu> of HG = g.
NIMBUSPHYSICS_EXPORT double HenyeyGreensteinMeanCosine(double g);

//------------------------------------------------------------------------------
// Cornette-Shanks (000 Eq. 3, 004 Eq. 5), divided by 4 pi:
//   p(mu) = 3 (1 - g^2) / (2 (2 + g^2)) * (1 + mu^2) / (1 + g^2 - 2 g mu)^{3/2} / (4 pi)
// g = 0 gives the Rayleigh phase function.                                [1/sr]
//------------------------------------------------------------------------------
NIMBUSPHYSICS_EXPORT double CornetteShanks(double mu, double g);
/// <mu> of CS = 3 g (g^2 + 4) / (5 (g^2 + 2))  (from the HG Legendre moments
/// <P_n> = g^n; checked by quadrature in TestPhaseFunctions).
NIMBUSPHYSICS_EXPORT double CornetteShanksMeanCosine(double g);
/// Acceptance probability for one HG proposal mu: CS/HG / max(CS/HG) = (1 + mu^2)/2.
NIMBUSPHYSICS_EXPORT double CornetteShanksAcceptance(double mu);

/// Samples CS by rejection from HG with the same g.  `uniform` is any callable
/// returning a double in [0,1).  Each trial uses 2 uniforms and is accepted with
/// probability (2 + g^2)/3, so the expected number of uniforms per sample is
/// 6/(2 + g^2), i.e. between 2 (|g| -> 1) and 3 (g = 0).
template <class UniformGenerator>
double SampleCornetteShanks(double g, UniformGenerator&& uniform)
{
  g = ClampAsymmetry(g);
  for (;;)
  {
    const double mu = SampleHenyeyGreenstein(g, uniform());
    if (uniform() < CornetteShanksAcceptance(mu))
    {
      return mu;
    }
  }
}

//------------------------------------------------------------------------------
// Rayleigh:  p(mu) = 3 / (16 pi) (1 + mu^2)                                [1/sr]
//------------------------------------------------------------------------------
NIMBUSPHYSICS_EXPORT double Rayleigh(double mu);
/// Analytic inversion of the CDF (mu^3 + 3 mu + 4)/8 = u (Cardano); u in [0,1).
NIMBUSPHYSICS_EXPORT double SampleRayleigh(double u);
/// <mu> of Rayleigh = 0.
NIMBUSPHYSICS_EXPORT double RayleighMeanCosine();

//------------------------------------------------------------------------------
// Directions
//------------------------------------------------------------------------------
/// Unit direction making cos(theta) = mu with `incident` (normalised here), with
/// azimuth phi = 2 pi u2 about it.  Throws std::invalid_argument for a zero or
/// non-finite incident vector.
NIMBUSPHYSICS_EXPORT std::array<double, 3> DirectionFromCosine(
  const std::array<double, 3>& incident, double mu, double u2);
/// Scattered direction for HG: mu = SampleHenyeyGreenstein(g, u1), phi = 2 pi u2.
NIMBUSPHYSICS_EXPORT std::array<double, 3> SampleHenyeyGreensteinDirection(
  const std::array<double, 3>& incident, double g, double u1, double u2);

//------------------------------------------------------------------------------
// Weighted mixture (004 Eq. 4):  F(mu) = sum_i w_i F_i(mu), sum_i w_i = 1.
//------------------------------------------------------------------------------
enum class PhaseFunctionKind
{
  Isotropic,        // 1/(4 pi); g ignored
  Rayleigh,         // g ignored
  HenyeyGreenstein, // uses g
  CornetteShanks    // uses g
};

/// Evaluates one kind, normalised to 1 over the sphere [1/sr].
NIMBUSPHYSICS_EXPORT double EvaluatePhaseFunction(PhaseFunctionKind kind, double mu, double g);
/// <mu> of one kind.
NIMBUSPHYSICS_EXPORT double PhaseFunctionMeanCosine(PhaseFunctionKind kind, double g);

/// Samples mu for one kind; `uniform` returns doubles in [0,1).
template <class UniformGenerator>
double SamplePhaseFunction(PhaseFunctionKind kind, double g, UniformGenerator&& uniform)
{
  switch (kind)
  {
    case PhaseFunctionKind::Isotropic:
      return 2.0 * uniform() - 1.0;
    case PhaseFunctionKind::Rayleigh:
      return SampleRayleigh(uniform());
    case PhaseFunctionKind::HenyeyGreenstein:
      return SampleHenyeyGreenstein(g, uniform());
    case PhaseFunctionKind::CornetteShanks:
    default:
      return SampleCornetteShanks(g, uniform);
  }
}

/// Mixture of phase functions, 004 Eq. 4.  Weights must be >= 0 and finite and
/// are normalised internally (only their ratios matter).  Example for clouds,
/// 004 §3.3: AddComponent(0.05, Rayleigh); AddComponent(0.95, CornetteShanks, g).
class NIMBUSPHYSICS_EXPORT PhaseFunctionMixture
{
public:
  struct Component
  {
    double weight; // normalised weight w_i (sum = 1)
    PhaseFunctionKind kind;
    double g; // clamped asymmetry parameter
  };

  /// Throws std::invalid_argument for a negative / non-finite weight or NaN g.
  void AddComponent(double weight, PhaseFunctionKind kind, double g = 0.0);
  const std::vector<Component>& GetComponents() const { return this->Components; }
  bool IsEmpty() const { return this->Components.empty(); }

  /// F(mu) = sum_i w_i F_i(mu) [1/sr]; 0 for an empty mixture.
  double Evaluate(double mu) const;
  /// Pdf (per steradian) of Sample(); equal to Evaluate().
  double Pdf(double mu) const { return this->Evaluate(mu); }
  /// <mu> = sum_i w_i <mu>_i.
  double MeanCosine() const;
  /// Index of the component selected by u in [0,1) with probability w_i.
  /// Throws std::logic_error if no component has a positive weight.
  std::size_t SelectComponent(double u) const;

  /// Chooses component i with probability w_i (one uniform) and samples it.
  /// Throws std::logic_error if no component has a positive weight.
  template <class UniformGenerator>
  double Sample(UniformGenerator&& uniform) const
  {
    const Component& c = this->Components[this->SelectComponent(uniform())];
    return SamplePhaseFunction(c.kind, c.g, uniform);
  }

private:
  std::vector<Component> Components;
  std::vector<double> RawWeights;
};

} // namespace nimbus

#endif
