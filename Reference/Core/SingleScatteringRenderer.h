// The deterministic single-scattering reference renderer: the ground truth that
// every fast renderer (SVS slices, splatting, ...) is compared against.
//
// Per ray it integrates 000 Eq. 1 (with 000 Eq. 2 for the attenuations; the
// cloud part is 004 §3.2 Eqs. 1-2), generalised to a spectral cloud + Rayleigh +
// Mie medium, with the k_multi term of 000 Eq. 1 when the scene sets
// medium.multiple_scattering_constant (0 by default: single scattering only;
// p_cl below then reads p_cl + k_multi/(4 pi)):
//
//   L(λ) = L_b(λ) T_v(t_end, λ)
//        + ∫_0^t_end T_v(t, λ) [σ_s,cl(x) p_cl(μ) + β_R(λ, x) p_R(μ) + β_M,s(x) p_M(μ)]
//                   E_sun(λ) T_sun(x, λ) dt
//        (+ ground: A/π E_sun(λ) T_sun(x_g, λ) max(0, s_z) T_v(t_g, λ))
//
//   T_v(t, λ)  = exp(-∫_0^t [σ_t,cl + β_R(λ) + β_M,ext] dt')          (000 Eq. 2, g_view)
//   T_sun(x,λ) = exp(-∫ σ_t,cl toward the sun inside the grid box)
//                × RenderContext::SunAtmosphereTransmittance(x)          (000 Eq. 2, g_sun;
//                                                                         004 §3.2 Eq. 2)
//   μ = dot(sunDirection, viewDirection): light propagates along -s and leaves
//       toward the camera along -v, so cos θ = dot(-s, -v) = dot(s, v); μ = +1 is
//       forward scattering (sun behind the cloud as seen from the camera).
//
// Units: metres, 1/m, nm; radiance in the scene's relative units (SceneDescription.h).
// Pixel values are RenderContext::ToLinearSrgb(spectral radiance); one ray per
// pixel centre (Camera::RayDirection(i + 0.5, j + 0.5), row 0 at the bottom): the
// reference resolves the integral along each ray, not the pixel footprint
// (no anti-aliasing; renderers under test must sample pixel centres too).
//
// Discretisation (documented in detail in SingleScatteringRenderer.cxx):
//  - cloud box: uniform steps h = stepScale × grid minimum spacing (last step the
//    remainder); per step the extinction and source are taken at the midpoint and
//    the step is integrated exactly for that constant medium
//    (∫ T e^{-σ τ} dτ = T (1 - e^{-σ h})/σ): "exponential midpoint rule",
//    second order (error O(h²)) for smooth media, exact for homogeneous extinction,
//    and well behaved for optically thick steps (σ h >> 1).
//  - sun march: same rule and step h from the sample toward the sun until it
//    leaves the grid box; stops (T_sun,cloud := 0) once the optical depth exceeds
//    -ln(1e-7) ≈ 16.12 (transmittance < 1e-7). Exact empty-space skipping over
//    all-zero 4³-cell blocks. Inside the box the (weak) air source uses the cloud
//    shadow interpolated between marches at every 8th view node.
//  - atmosphere sun transmittance: exact optical lengths at knots along the ray,
//    log-linear interpolation with an altitude correction (|ΔT| <= 2.5e-5).
//  - atmosphere outside the box: geometrically growing steps (s·(g0 + 0.1 d), d the
//    distance from the box or camera), nested when stepScale halves, up to the
//    ground plane, the earth sphere or the top of the atmosphere.
//  - view march stops once the largest spectral view transmittance is < 1e-7.
#ifndef NimbusSingleScatteringRenderer_h
#define NimbusSingleScatteringRenderer_h

#include "NimbusReferenceModule.h"

#include "FloatImage.h"
#include "RenderContext.h"

#include <array>
#include <functional>
#include <vector>

namespace nimbus
{

struct NIMBUSREFERENCE_EXPORT SingleScatteringSettings
{
  double StepScale = 0.5;          // cloud step = StepScale × grid min spacing (m), first pass
  double RelativeTolerance = 1e-3; // stop when the estimated relative RMS error is below this
  int MaxRefinements = 6;          // at most this many step halvings (MaxRefinements + 1 passes)
  int Threads = 0;                 // 0 = hardware concurrency
  /// Bytes the render may allocate (two images of Width x Height x 3 floats); 0 =
  /// nimbus::DefaultMemoryBudgetBytes() (Physics/MemoryBudget.h).
  double MemoryBudgetBytes = 0.0;
};

struct NIMBUSREFERENCE_EXPORT SingleScatteringResult
{
  FloatImage Image;              // finest pass, linear sRGB
  double EstimatedRelativeError; // Richardson estimate of Image's relative RMS error
                                 // (+infinity when only one pass was rendered)
  double FinalStepScale;         // step scale of Image
  int Passes;                    // passes rendered
  double Seconds;                // wall-clock time
};

/// One image at a fixed step (stepScale × grid min spacing, m). Threads: 0 =
/// hardware concurrency; the result does not depend on the thread count (each
/// pixel is computed independently by the same code). progress(fraction in
/// [0, 1]) is called from the calling thread. Throws std::invalid_argument for
/// stepScale <= 0 or non-finite.
NIMBUSREFERENCE_EXPORT FloatImage RenderSingleScatteringPass(const RenderContext& context,
  double stepScale, int threads, const std::function<void(double)>& progress = {});

/// Renders passes at StepScale, StepScale/2, StepScale/4, ... until the Richardson
/// estimate of the finest pass's error is below RelativeTolerance or MaxRefinements
/// halvings were made. Estimator (the rule is O(h²)): for successive passes I_h and
/// I_{h/2}, I_h - I_{h/2} ≈ C h² (1 - 1/4), so the error of I_{h/2} is
///   ε ≈ RMS(I_{h/2} - I_h) / (2² - 1) / RMS(I_{h/2}),
/// RMS over all pixels and the three linear sRGB channels (0 if both images are 0).
/// Returns the finest image (not the extrapolated one, which need not be >= 0).
/// progress is monotonic and reaches 1 at the end; it may throw to stop the render
/// (e.g. on a user's abort): the exception propagates once the rows being rendered
/// are done. Throws std::length_error, before allocating, when the images would
/// need more than MemoryBudgetBytes, and std::range_error when the image has a
/// NaN or infinite pixel component (NonFiniteMessage, FloatImage.h).
NIMBUSREFERENCE_EXPORT SingleScatteringResult RenderSingleScattering(const RenderContext& context,
  const SingleScatteringSettings& settings, const std::function<void(double)>& progress = {});

/// Spectral radiance (one value per context wavelength sample) arriving at origin
/// from unitDirection, i.e. along the ray origin + t·unitDirection, t >= 0 (the
/// camera ray convention). Throws std::invalid_argument for stepScale <= 0 or a
/// non-finite origin / direction.
NIMBUSREFERENCE_EXPORT std::vector<double> SingleScatteringRadiance(const RenderContext& context,
  const std::array<double, 3>& origin, const std::array<double, 3>& unitDirection,
  double stepScale);

namespace detail
{
/// Test hook: the atmosphere's sun transmittance per wavelength sample at
/// origin + t·unitDirection (0 <= t <= tEnd) as the renderer evaluates it along a
/// ray ending at tEnd: exact optical lengths (Atmosphere::OpticalLengthsToTop) at
/// knots along the ray, log-linear interpolation between them.
NIMBUSREFERENCE_EXPORT std::vector<double> InterpolatedSunAtmosphereTransmittance(
  const RenderContext& context, const std::array<double, 3>& origin,
  const std::array<double, 3>& unitDirection, double tEnd, double t);
/// The knot spacing (m) used for this context's sun direction.
NIMBUSREFERENCE_EXPORT double SunAtmosphereKnotSpacing(const RenderContext& context);
}

} // namespace nimbus

#endif
