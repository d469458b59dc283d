// Deterministic single-scattering reference renderer (see the header for the
// equation, 000 Eqs. 1-2 generalised, and the conventions).
//
// Numerical scheme, per ray origin o, unit direction v, samples x(t) = o + t v:
//
// 1. End of the ray t_end = min(ground plane hit, earth sphere hit, top of the
//    atmosphere); without atmosphere and ground, +infinity (only the cloud box
//    matters then). With the atmosphere, a ray that reaches the earth sphere
//    without meeting the ground plane (ground disabled) ends there with no
//    radiance (the earth is black), instead of crossing the planet.
//
// 2. The ray is split into (a) air from the camera to the cloud box, (b) the
//    box interval [t0, t1] and (c) air from the box to t_end. Each piece is a
//    sequence of steps [t_a, t_b] (length Δ); on each step the extinction σ(λ)
//    and the source J(λ) = E_sun(λ) T_sun(x_m, λ) [σ_s,cl p_cl + β_R p_R + β_M,s p_M]
//    are evaluated at the midpoint x_m and the step is integrated exactly for that
//    constant medium (exponential midpoint rule):
//        L += T(t_a) J Δ φ(σΔ),  φ(x) = (1 - e^{-x})/x,   T(t_b) = T(t_a) e^{-σΔ}.
//    For a smooth medium the error is O(Δ²) (second order), it is exact for
//    homogeneous extinction with constant source, and for an optically thick step
//    (σΔ >> 1) it tends to the correct surface value J/σ (a plain midpoint rule
//    would give T J Δ e^{-σΔ/2} -> 0).
//    (b) uses uniform steps h = stepScale × grid minimum spacing from t0, the last
//        step being the remainder (so halving stepScale nests the nodes).
//    (a), (c) contain only air (the cloud density is 0 outside the grid box); the
//        steps grow geometrically away from the box (or from the camera when the
//        ray misses the box): nodes d_k = (g0/α)(e^{α k s} - 1) with s = stepScale,
//        g0 = grid minimum spacing, α = 0.1, i.e. a step of s (g0 + α d) at
//        distance d — the same as the cloud step next to the box, ~0.05 d far away
//        (the sky over hundreds of km takes ~130 steps at s = 0.5), nested when s
//        halves, so the whole ray converges as O(s²).
// 3. T_sun(x, λ) = T_cloud(x) T_atm(x, λ):
//    - T_cloud: march from x toward the sun (step h, same rule: midpoint
//      extinction × step length, exact in homogeneous media) until it leaves the
//      grid box; stops with T_cloud = 0 as soon as the optical depth exceeds
//      -ln(1e-7) = 16.12 (the truncated light is < 1e-7 of the unshadowed sun).
//      Every cloud sample and every air sample outside the box (light shafts) gets
//      its own march. Inside the box the air term (β ~ 1e-5 /m) uses T_cloud
//      interpolated linearly between exact marches at every 8th node of the view
//      march (O((8h)²), seen by the Richardson estimate); this removes most marches
//      from the empty parts of the box.
//      Without atmosphere (no earth sphere), the ground plane, when enabled, blocks
//      a sun below the horizon (s_z < 0) for every point above it; with the
//      atmosphere the spherical earth blocks it (twilight reaches the upper air).
//    - Empty-space skipping (exact): macro blocks of 4³ grid cells whose grid points
//      are all 0 have zero trilinear density everywhere inside; marches jump over
//      the midpoints that fall inside such a block (same nodes, same sums).
//    - T_atm: RenderContext::SunAtmosphereTransmittance would cost ~3 µs per
//      sample (adaptive Gauss-Kronrod); instead the exact optical lengths
//      (Atmosphere::OpticalLengthsToTop, Rayleigh and Mie) are computed at knots
//      t_k = min(k Δ_knot, t_end) along the ray and interpolated as
//        ln(L + L0)(t) = lerp_t(ln(L + L0)) - (h(t) - lerp_t(h)) / H,
//      h the exact altitude. For a plane-parallel exponential atmosphere clipped at
//      the top, L + L0 with L0 = (H/μ_s) e^{-h_top/H} is exactly ∝ e^{-h/H}, so this
//      is exact; the altitude term removes the earth's curvature along the ray
//      (d²h/dt² ≈ 1/R), which dominates otherwise. What remains is the change of the
//      local sun zenith angle over the horizontal distance δ, δθ = δ/R, with
//      d²ln L/dθ² ≈ 1/μ_s² (at most ~R/H_M near the horizon):
//      Δ_knot = R sqrt(8e-5 / min(1/μ_s², R/H_M)) bounds that error by ~1e-5,
//      clamped to [200 m, 50 km] (~40 km at μ_s = 0.7, 5 km at 5°, 0.8 km at the
//      horizon), and at most 8 km of altitude change between knots (L must stay
//      >> L0). Measured |ΔT| <= 2.5e-5 for sun elevations 60…-5°. An interval whose
//      knot is blocked by the earth is evaluated exactly per sample. Checked in
//      TestSingleScattering (SunAtmosphereKnots).
// 4. The view march stops once max_λ T(λ) < 1e-7 (nothing behind can contribute more
//    than 1e-7 of its own radiance), including the ground / background term.
// 5. Ground (plane z = height, grey Lambertian albedo A):
//    L += A/π E_sun(λ) T_sun(x_g, λ) max(0, s_z) T(t_g, λ), T_atm(x_g) exact.
//    Background (rays that leave): L += L_b(λ) T(t_end, λ).
//
// Cost: per view sample in the cloud, one sun march of up to (box extent / h)
// trilinear look-ups (fewer with early termination), so a pass costs
// O(pixels × (N/s)²) for an N³ grid; halving the step quadruples the cloud cost.
#include "SingleScatteringRenderer.h"
#include "MajorantGrid.h"
#include "Math.h"
#include "MemoryBudget.h"
#include "ParallelFor.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>

namespace nimbus
{

namespace
{
// Sun march stops when T_cloud < 1e-7, i.e. optical depth > -ln(1e-7).
constexpr double kSunCutoffDepth = 16.11809565095832;
// View march stops when every spectral view transmittance is < 1e-7.
constexpr double kViewCutoff = 1e-7;
// Growth rate of the air steps with distance (dimensionless: step = s (g0 + α d)).
constexpr double kAirGrowth = 0.1;
// Largest spacing (m) of the exact sun optical-length knots along a ray.
constexpr double kMaxKnotSpacing = 50000.0;
// Largest altitude change (m) between two knots.
constexpr double kMaxKnotRise = 8000.0;
// Edge (grid cells) of the macro blocks used to skip empty space.
constexpr int kBlockCells = MajorantGrid::BlockVoxels;
// Air shadow knots inside the cloud box: every K-th cloud step (see CloudSegmentSpectral).
constexpr long long kAirShadowKnotSteps = 8;

/// φ(x) = (1 - e^{-x}) / x for x = σΔ >= 0, given e = e^{-x}; series below 1e-4
/// (no cancellation; error < x³/24 < 1e-13).
inline double ExpWeight(double x, double e)
{
  if (x < 1e-4)
  {
    return 1.0 - 0.5 * x + x * x / 6.0;
  }
  return (1.0 - e) / x;
}

void CheckStepScale(double stepScale)
{
  if (!(stepScale > 0.0) || !std::isfinite(stepScale))
  {
    throw std::invalid_argument("nimbus::SingleScattering: stepScale must be finite and > 0");
  }
}

/// The version-3 and version-4 features (docs/scene-format.md) this renderer does not
/// render: an error naming them, rather than an image without them. Lights of every kind
/// (point, polyline, spot) and occluders are the path tracer's: every scene with
/// occluders that the project compares renderers on is lit by lights, which this
/// renderer does not render anyway.
void RefuseVersion3Features(const SceneDescription& scene)
{
  std::string missing;
  auto add = [&missing](const std::string& what)
  { missing += (missing.empty() ? "" : ", ") + what; };
  if (!scene.Lights.empty())
  {
    const bool spots = std::any_of(scene.Lights.begin(), scene.Lights.end(),
      [](const LightDescription& light) { return light.Type == "spot"; });
    add(spots ? "point, polyline and spot lights (scene.lights)"
              : "point and polyline lights (scene.lights)");
  }
  bool emission = scene.Medium.Emission.Enabled;
  for (const auto& m : scene.Media)
  {
    emission = emission || m.Emission.Enabled;
  }
  if (emission)
  {
    add("emission (scene.medium.emission, scene.media[i].emission)");
  }
  if (!scene.Media.empty())
  {
    add("additional media (scene.media)");
  }
  if (!scene.Occluders.empty())
  {
    add("occluders (scene.occluders)");
  }
  if (!missing.empty())
  {
    throw std::invalid_argument("the single-scattering renderer does not render " + missing +
      "; render this scene with the path tracer");
  }
}

/// Everything a ray needs that depends only on the context and the step; shared
/// (read-only) by the threads.
class Integrator
{
public:
  Integrator(const RenderContext& context, double stepScale)
    : Ctx(context)
    , Grid(context.GetGrid())
    , StepScale(stepScale)
    , Sun(context.GetSunDirection())
    , N(context.GetNumberOfWavelengths())
  {
    CheckStepScale(stepScale);
    RefuseVersion3Features(context.GetScene());
    this->HasGrid = !this->Grid.IsEmpty() && this->Ctx.CloudMajorant() > 0.0;
    const double spacing = this->Grid.IsEmpty() ? 100.0 : this->Grid.GetMinimumSpacing();
    this->Step = stepScale * spacing; // m
    this->AirFirstStep = spacing;     // g0, m (times s)
    this->Albedo = this->Ctx.GetCloudAlbedo();
    this->MultipleScattering = this->Ctx.GetScene().Medium.MultipleScatteringConstant;
    this->E = this->Ctx.GetSunIrradiance();
    this->Background = this->Ctx.GetBackgroundRadiance();
    this->BuildEmptyBlocks();
    this->Air = this->Ctx.GetAtmosphere();
    // Without atmosphere there is no earth sphere: the ground plane blocks a sun
    // below the horizon. With it, the spherical earth does (RenderContext).
    this->GroundBlocksSun = !this->Air && this->Ctx.HasGround() && this->Sun[2] < 0.0;
    if (this->Air)
    {
      const AtmosphereParameters& a = this->Air->GetParameters();
      this->BetaR = this->Ctx.GetRayleighScatteringSeaLevel();
      this->BetaMs = this->Ctx.GetMieScatteringSeaLevel();
      this->BetaMext = this->Ctx.GetMieExtinctionSeaLevel();
      this->HR = a.RayleighScaleHeightMetres;
      this->HM = a.MieScaleHeightMetres;
      this->EarthRadius = a.EarthRadiusMetres;
      this->KnotSpacing = KnotSpacingFor(this->Sun[2], a.EarthRadiusMetres, a.MieScaleHeightMetres);
      // Offsets L0 of the interpolated ln(L + L0): in a plane-parallel atmosphere
      // clipped at the top, L = (H/μ_s)(e^{-h/H} - e^{-h_top/H}), so L + (H/μ_s) e^{-h_top/H}
      // is exactly log-linear in h; also keeps the log finite where L = 0. μ_s clamped to
      // >= 0.1 (only the order of magnitude matters); L0 >= 1e-6 m.
      const double mu = std::max(0.1, this->Sun[2]);
      const double top = a.TopRadiusMetres - a.EarthRadiusMetres;
      this->OffsetR = std::max(1e-6, this->HR * std::exp(-top / this->HR) / mu);
      this->OffsetM = std::max(1e-6, this->HM * std::exp(-top / this->HM) / mu);
    }
  }

  static double KnotSpacingFor(double sunZ, double earthRadius, double mieScaleHeight)
  {
    const double mu2 = std::max(sunZ * sunZ, 1e-30);
    const double curvature = std::min(1.0 / mu2, earthRadius / mieScaleHeight);
    const double spacing = earthRadius * std::sqrt(8e-5 / curvature);
    return std::min(kMaxKnotSpacing, std::max(200.0, spacing));
  }

  struct Workspace
  {
    std::vector<double> T, L, Tsun;
  };

  /// Ray-local cache of the atmosphere's sun optical lengths at knots.
  class SunKnots
  {
  public:
    SunKnots(const Integrator& integrator, const Vector3& o, const Vector3& d, double tEnd)
      : I(integrator)
      , O(o)
      , D(d)
      , TEnd(tEnd)
    {
      // At most kMaxKnotRise of altitude between knots: ln(L + L0) is log-linear in
      // h only while L >> L0 (the Mie offset is tiny), so long climbs are split.
      this->Spacing =
        std::min(integrator.KnotSpacing, kMaxKnotRise / std::max(1e-9, std::abs(d[2])));
      this->Intervals = std::max<long long>(
        1, static_cast<long long>(std::ceil(std::min(tEnd / this->Spacing, 1e12))));
    }

    /// T_atm(x(t), λ) into T (size N).
    void Evaluate(double t, const Vector3& x, double* T)
    {
      long long k = static_cast<long long>(std::floor(std::max(0.0, t) / this->Spacing));
      k = std::min(k, this->Intervals - 1);
      if (k != this->K)
      {
        if (k == this->K + 1)
        {
          this->Knot[0] = this->Knot[1];
        }
        else
        {
          this->Knot[0] = this->ComputeKnot(k);
        }
        this->Knot[1] = this->ComputeKnot(k + 1);
        this->K = k;
      }
      const KnotValue& a = this->Knot[0];
      const KnotValue& b = this->Knot[1];
      double lr, lm;
      if (a.Blocked || b.Blocked)
      {
        const OpticalLengths exact =
          this->I.Air->OpticalLengthsToTop(this->I.Ctx.EarthCentred(x), this->I.Sun);
        if (exact.HitsGround)
        {
          std::fill(T, T + this->I.N, 0.0);
          return;
        }
        lr = exact.RayleighLengthMetres;
        lm = exact.MieLengthMetres;
      }
      else
      {
        // ln L linear in t, corrected for the altitude's departure from linear
        // (the earth's curvature: d²h/dt² ≈ (1 - v_z²)/R), with ∂ln L/∂h = -1/H.
        const double w = b.T > a.T ? std::min(1.0, std::max(0.0, (t - a.T) / (b.T - a.T))) : 0.0;
        const double dh = this->I.Air->Altitude(this->I.Ctx.EarthCentred(x)) -
          (a.Altitude + w * (b.Altitude - a.Altitude));
        lr = std::max(
          0.0, std::exp(a.LogR + w * (b.LogR - a.LogR) - dh / this->I.HR) - this->I.OffsetR);
        lm = std::max(
          0.0, std::exp(a.LogM + w * (b.LogM - a.LogM) - dh / this->I.HM) - this->I.OffsetM);
      }
      const double mie = this->I.BetaMext * lm;
      for (int i = 0; i < this->I.N; ++i)
      {
        T[i] = std::exp(-(this->I.BetaR[i] * lr + mie));
      }
    }

  private:
    struct KnotValue
    {
      double T = 0.0, Altitude = 0.0, LogR = 0.0, LogM = 0.0;
      bool Blocked = false;
    };
    KnotValue ComputeKnot(long long k) const
    {
      KnotValue v;
      v.T = std::min(static_cast<double>(k) * this->Spacing, this->TEnd);
      const Vector3 p = this->I.Ctx.EarthCentred(Along(this->O, this->D, v.T));
      v.Altitude = this->I.Air->Altitude(p);
      const OpticalLengths lengths = this->I.Air->OpticalLengthsToTop(p, this->I.Sun);
      v.Blocked = lengths.HitsGround;
      v.LogR = std::log(lengths.RayleighLengthMetres + this->I.OffsetR);
      v.LogM = std::log(lengths.MieLengthMetres + this->I.OffsetM);
      return v;
    }

    const Integrator& I;
    Vector3 O, D;
    double TEnd;
    double Spacing = 1000.0;
    long long Intervals = 1;
    long long K = -2;
    KnotValue Knot[2];
  };

  /// Cloud transmittance from x toward the sun (1e-7 cut-off; 0 if the ground plane blocks).
  double SunCloudTransmittance(const Vector3& x) const
  {
    if (this->GroundBlocksSun && x[2] >= this->Ctx.GetGroundHeight())
    {
      return 0.0;
    }
    if (!this->HasGrid)
    {
      return 1.0;
    }
    double tNear, tFar;
    if (!this->Grid.IntersectRay(x, this->Sun, 0.0, tNear, tFar))
    {
      return 1.0;
    }
    const double begin = std::max(0.0, tNear);
    const double h = this->Step;
    const long long last = LastStep(tFar - begin, h);
    double tau = 0.0;
    for (long long k = 0; k <= last; ++k)
    {
      const double ta = begin + static_cast<double>(k) * h;
      const double tb = k == last ? tFar : std::min(ta + h, tFar);
      const double tm = 0.5 * (ta + tb);
      const Vector3 p = Along(x, this->Sun, tm);
      const double sigma = this->Ctx.CloudExtinction(p);
      if (sigma > 0.0)
      {
        tau += sigma * (tb - ta);
        if (tau > kSunCutoffDepth)
        {
          return 0.0;
        }
      }
      else
      {
        k = this->SkipEmpty(p, this->Sun, tm, begin, h, k, last);
      }
    }
    return std::exp(-tau);
  }

  /// Index of the last step of a march of `length` with step h (the remainder step).
  static long long LastStep(double length, double h)
  {
    if (!(length > 0.0))
    {
      return -1;
    }
    const double count = std::ceil(length / h);
    return static_cast<long long>(std::max(1.0, std::min(count, 4e18))) - 1;
  }

  /// Empty-space skipping (exact): if the macro block containing p (the midpoint
  /// of step k at parameter tm of a march from `begin` with step h along dir) has
  /// only zero densities, the trilinear density is 0 in the whole closed block, so
  /// every later midpoint inside the block contributes nothing: returns the index
  /// of the step before the first midpoint that may lie outside (never beyond
  /// last - 1, so the remainder step is always evaluated). Otherwise returns k.
  long long SkipEmpty(const Vector3& p, const Vector3& dir, double tm, double begin, double h,
    long long k, long long last) const
  {
    // The block holding p (on a face, the one the ray enters) and where the ray leaves it.
    MajorantWalk block;
    block.Start(this->Blocks, p, dir, 0.0);
    if (!this->Blocks.IsEmpty(block.Index))
    {
      return k;
    }
    const double exit = block.Exit();
    // Midpoints strictly before tm + exit (less a rounding margin) are in the block.
    const double limit = tm + std::max(0.0, exit) - 1e-9 * (h + this->BlockDiagonal);
    const double first = std::ceil((limit - begin) / h - 0.5); // first midpoint >= limit
    // The last block along an axis may end at the grid's box, before its Exit: the cap at
    // last - 1 keeps the remainder step, and a step at or past it is never skipped back.
    if (!(first - 1.0 > static_cast<double>(k)) || k >= last - 1)
    {
      return k;
    }
    return std::min(static_cast<long long>(std::min(first, 4e18)) - 1, last - 1);
  }

  void Radiance(const Vector3& o, const Vector3& d, Workspace& w, std::vector<double>& out) const
  {
    const int n = this->N;
    w.T.assign(n, 1.0);
    w.L.assign(n, 0.0);
    w.Tsun.assign(n, 1.0);

    // Scattering angle: light propagates along -s, leaves toward the camera along -v.
    const double mu = std::max(-1.0, std::min(1.0, Dot(this->Sun, d)));
    const double cloudPhase = this->Ctx.GetCloudPhase().Evaluate(mu);
    // 000 Eq. 1: (beta_cl + k_multi) with beta 4pi-normalised -> p + k_multi/(4 pi) here.
    const double cloudScatterPerExtinction =
      this->Albedo * (cloudPhase + this->MultipleScattering / (4.0 * kPi)); // σ_s p / σ_t, 1/sr
    double rayleighPhase = 0.0, miePhase = 0.0;
    if (this->Air)
    {
      rayleighPhase = this->Air->RayleighPhase(mu);
      miePhase = this->Air->MiePhase(mu);
    }

    // End of the ray.
    enum class End
    {
      Background,
      Ground,
      Earth
    };
    End end = End::Background;
    double tEnd = std::numeric_limits<double>::infinity();
    const double tGround = this->Ctx.IntersectGround(o, d, 0.0);
    if (tGround < tEnd)
    {
      tEnd = tGround;
      end = End::Ground;
    }
    if (this->Air)
    {
      const double tTop = this->Ctx.DistanceToTopOfAtmosphere(o, d);
      if (tTop < tEnd)
      {
        tEnd = tTop;
        end = End::Background;
      }
      const double tEarth = this->EarthHit(o, d);
      if (tEarth < tEnd)
      {
        tEnd = tEarth;
        end = End::Earth;
      }
    }

    double t0 = 0.0, t1 = 0.0;
    bool box = this->HasGrid && this->Grid.IntersectRay(o, d, 0.0, t0, t1) && t0 < tEnd;
    if (box)
    {
      t1 = std::min(t1, tEnd);
      box = t1 > t0;
    }

    std::unique_ptr<SunKnots> knots;
    if (this->Air && tEnd > 0.0)
    {
      knots = std::make_unique<SunKnots>(*this, o, d, tEnd);
    }

    bool alive = true;
    double scalarT = 1.0, scalarS = 0.0; // no-atmosphere path (wavelength independent)
    if (this->Air)
    {
      if (box)
      {
        alive = this->AirSegment(
          o, d, 0.0, t0, /*gradeFromStart=*/false, rayleighPhase, miePhase, *knots, w);
        if (alive)
        {
          alive = this->CloudSegmentSpectral(
            o, d, t0, t1, cloudScatterPerExtinction, rayleighPhase, miePhase, *knots, w);
        }
        if (alive && tEnd > t1)
        {
          alive = this->AirSegment(o, d, t1, tEnd, true, rayleighPhase, miePhase, *knots, w);
        }
      }
      else if (tEnd > 0.0)
      {
        alive = this->AirSegment(o, d, 0.0, tEnd, true, rayleighPhase, miePhase, *knots, w);
      }
    }
    else if (box)
    {
      alive = this->CloudSegmentScalar(o, d, t0, t1, cloudScatterPerExtinction, scalarT, scalarS);
    }

    if (!this->Air)
    {
      for (int i = 0; i < n; ++i)
      {
        w.L[i] = this->E[i] * scalarS;
        w.T[i] = scalarT;
      }
    }

    if (alive)
    {
      if (end == End::Ground)
      {
        const Vector3 xg = Along(o, d, tEnd);
        const double cosSun = std::max(0.0, this->Sun[2]);
        const double tCloud = cosSun > 0.0 ? this->SunCloudTransmittance(xg) : 0.0;
        if (tCloud > 0.0)
        {
          this->Ctx.SunAtmosphereTransmittance(xg, w.Tsun); // exact, once per ray
          const double f = this->Ctx.GetGroundAlbedo() / kPi * cosSun * tCloud;
          for (int i = 0; i < n; ++i)
          {
            w.L[i] += f * this->E[i] * w.Tsun[i] * w.T[i];
          }
        }
      }
      else if (end == End::Background)
      {
        for (int i = 0; i < n; ++i)
        {
          w.L[i] += this->Background[i] * w.T[i];
        }
      }
    }
    out.assign(w.L.begin(), w.L.end());
  }

private:
  /// Flags the macro blocks (kBlockCells³ grid cells) whose grid points are all 0
  /// (MajorantGrid without dilation: maximum 0).
  void BuildEmptyBlocks()
  {
    if (this->Grid.IsEmpty())
    {
      return;
    }
    // A block's diagonal (kBlockCells cells an edge), m: the scale of SkipEmpty's
    // rounding margin.
    const std::array<int, 3>& dims = this->Grid.GetDimensions();
    const Vector3 lower = this->Grid.GetLower(), upper = this->Grid.GetUpper();
    double diagonal2 = 0.0;
    for (int a = 0; a < 3; ++a)
    {
      const double cellSize = (upper[a] - lower[a]) / std::max(1, dims[a] - 1);
      diagonal2 += std::pow(kBlockCells * cellSize, 2);
    }
    this->BlockDiagonal = std::sqrt(diagonal2);
    this->Blocks = MajorantGrid(this->Grid, 0);
  }

  /// Distance to the earth sphere (radius R_e, earth-centred frame), or infinity.
  double EarthHit(const Vector3& o, const Vector3& d) const
  {
    const Vector3 p = this->Ctx.EarthCentred(o);
    const double r = std::sqrt(Dot(p, p));
    const double b = Dot(p, d);
    const double c = (r - this->EarthRadius) * (r + this->EarthRadius);
    if (!(c > 0.0) || b >= 0.0)
    {
      return std::numeric_limits<double>::infinity();
    }
    const double disc = b * b - c;
    if (!(disc > 0.0))
    {
      return std::numeric_limits<double>::infinity();
    }
    return c / (-b + std::sqrt(disc));
  }

  /// Cloud box without atmosphere: scalar transmittance and scalar source
  /// (E(λ) factored out). Returns false once T < cutoff.
  bool CloudSegmentScalar(const Vector3& o, const Vector3& d, double a, double b,
    double scatterPerExtinction, double& T, double& S) const
  {
    const double h = this->Step;
    const long long last = LastStep(b - a, h);
    for (long long k = 0; k <= last; ++k)
    {
      const double ta = a + static_cast<double>(k) * h;
      const double tb = k == last ? b : std::min(ta + h, b);
      const double dt = tb - ta;
      const double tm = 0.5 * (ta + tb);
      const Vector3 x = Along(o, d, tm);
      const double sigma = this->Ctx.CloudExtinction(x);
      if (sigma <= 0.0)
      {
        k = this->SkipEmpty(x, d, tm, a, h, k, last);
        continue;
      }
      const double source = sigma * scatterPerExtinction; // σ_s p, 1/(m sr)
      const double J = source > 0.0 ? source * this->SunCloudTransmittance(x) : 0.0;
      const double xo = sigma * dt;
      const double e = std::exp(-xo);
      S += T * J * dt * ExpWeight(xo, e);
      T *= e;
      if (T < kViewCutoff)
      {
        return false;
      }
    }
    return true;
  }

  /// One step [ta, tb] of the spectral march with cloud extinction sigmaC at the
  /// midpoint x. Returns false once every T(λ) < cutoff.
  bool SpectralStep(const Vector3& x, double tm, double dt, double sigmaC,
    double scatterPerExtinction, double cloudSunT, double airSunT, double rayleighPhase,
    double miePhase, SunKnots& knots, Workspace& w) const
  {
    const double altitude = this->Air->Altitude(this->Ctx.EarthCentred(x));
    const double rhoR = this->Air->Density(altitude, this->HR);
    const double rhoM = this->Air->Density(altitude, this->HM);
    const bool lit = cloudSunT > 0.0 || airSunT > 0.0;
    if (lit)
    {
      knots.Evaluate(tm, x, w.Tsun.data());
    }
    const double cloudSource = sigmaC * scatterPerExtinction;
    const double mieSource = this->BetaMs * rhoM * miePhase;
    const double mieExt = this->BetaMext * rhoM;
    double maxT = 0.0;
    for (int i = 0; i < this->N; ++i)
    {
      const double betaR = this->BetaR[i] * rhoR;
      const double sigma = sigmaC + betaR + mieExt;
      const double J = lit ? this->E[i] * w.Tsun[i] *
          (cloudSunT * cloudSource + airSunT * (betaR * rayleighPhase + mieSource))
                           : 0.0;
      const double xo = sigma * dt;
      const double e = std::exp(-xo);
      w.L[i] += w.T[i] * J * dt * ExpWeight(xo, e);
      w.T[i] *= e;
      maxT = std::max(maxT, w.T[i]);
    }
    return maxT >= kViewCutoff;
  }

  /// Cloud box with atmosphere. The cloud source uses the exact sun march at each
  /// midpoint; the air source (β ~ 1e-5 /m, 1e-3 of a cloud's) uses the cloud
  /// transmittance interpolated linearly between exact marches at every
  /// kAirShadowKnotSteps-th node (and at b): O((K h)²) like the rest, and K times
  /// fewer marches through the empty parts of the box.
  bool CloudSegmentSpectral(const Vector3& o, const Vector3& d, double a, double b,
    double scatterPerExtinction, double rayleighPhase, double miePhase, SunKnots& knots,
    Workspace& w) const
  {
    const double h = this->Step;
    const long long last = LastStep(b - a, h);
    long long knot = -1;
    double tLeft = a, tRight = a, shadowLeft = 1.0, shadowRight = 1.0;
    for (long long k = 0; k <= last; ++k)
    {
      const double ta = a + static_cast<double>(k) * h;
      const double tb = k == last ? b : std::min(ta + h, b);
      const double tm = 0.5 * (ta + tb);
      const Vector3 x = Along(o, d, tm);
      const long long j = k / kAirShadowKnotSteps;
      if (j != knot)
      {
        if (j == knot + 1 && knot >= 0)
        {
          tLeft = tRight;
          shadowLeft = shadowRight;
        }
        else
        {
          tLeft = a + static_cast<double>(j * kAirShadowKnotSteps) * h;
          shadowLeft = this->SunCloudTransmittance(Along(o, d, tLeft));
        }
        tRight = std::min(b, a + static_cast<double>((j + 1) * kAirShadowKnotSteps) * h);
        if ((j + 1) * kAirShadowKnotSteps > last)
        {
          tRight = b;
        }
        shadowRight = this->SunCloudTransmittance(Along(o, d, tRight));
        knot = j;
      }
      const double wRight = tRight > tLeft ? (tm - tLeft) / (tRight - tLeft) : 0.0;
      const double airSunT = shadowLeft + wRight * (shadowRight - shadowLeft);
      const double sigmaC = this->Ctx.CloudExtinction(x);
      const double cloudSunT =
        sigmaC * scatterPerExtinction > 0.0 ? this->SunCloudTransmittance(x) : 0.0;
      if (!this->SpectralStep(x, tm, tb - ta, sigmaC, scatterPerExtinction, cloudSunT, airSunT,
            rayleighPhase, miePhase, knots, w))
      {
        return false;
      }
    }
    return true;
  }

  /// Air only on [a, b], geometrically growing steps away from a (gradeFromStart)
  /// or from b.
  bool AirSegment(const Vector3& o, const Vector3& d, double a, double b, bool gradeFromStart,
    double rayleighPhase, double miePhase, SunKnots& knots, Workspace& w) const
  {
    const double length = b - a;
    if (!(length > 0.0))
    {
      return true;
    }
    const double g0 = this->AirFirstStep, alpha = kAirGrowth, s = this->StepScale;
    const double uTotal = std::log1p(alpha * length / g0) / alpha;
    const long long steps = std::max<long long>(1, static_cast<long long>(std::ceil(uTotal / s)));
    auto distance = [&](long long k)
    { return k >= steps ? length : std::min(length, g0 / alpha * std::expm1(alpha * k * s)); };
    for (long long k = 0; k < steps; ++k)
    {
      double ta, tb;
      if (gradeFromStart)
      {
        ta = a + distance(k);
        tb = a + distance(k + 1);
      }
      else
      {
        ta = b - distance(steps - k);
        tb = b - distance(steps - k - 1);
      }
      if (!(tb > ta))
      {
        continue;
      }
      const double tm = 0.5 * (ta + tb);
      const Vector3 x = Along(o, d, tm);
      if (!this->SpectralStep(x, tm, tb - ta, 0.0, 0.0, 0.0, this->SunCloudTransmittance(x),
            rayleighPhase, miePhase, knots, w))
      {
        return false;
      }
    }
    return true;
  }

  const RenderContext& Ctx;
  const DensityGrid& Grid;
  double StepScale;
  Vector3 Sun;
  int N;
  bool HasGrid = false;
  double Step = 1.0;
  double AirFirstStep = 1.0;
  double Albedo = 0.0;
  double MultipleScattering = 0.0; // k_multi (000 Eq. 1)
  std::vector<double> E, Background;
  bool GroundBlocksSun = false;
  const Atmosphere* Air = nullptr;
  std::vector<double> BetaR;
  double BetaMs = 0.0, BetaMext = 0.0, HR = 1.0, HM = 1.0, EarthRadius = 0.0;
  double KnotSpacing = 1000.0;
  double OffsetR = 1e-6, OffsetM = 1e-6; // m
  // Empty-space skipping: macro blocks of kBlockCells³ grid cells.
  MajorantGrid Blocks;
  double BlockDiagonal = 0.0;
};

void CheckRay(const Vector3& origin, const Vector3& direction)
{
  for (int a = 0; a < 3; ++a)
  {
    if (!std::isfinite(origin[a]) || !std::isfinite(direction[a]))
    {
      throw std::invalid_argument("nimbus::SingleScatteringRadiance: non-finite ray");
    }
  }
  const double norm2 = Dot(direction, direction);
  if (!(std::abs(norm2 - 1.0) < 1e-6))
  {
    throw std::invalid_argument("nimbus::SingleScatteringRadiance: direction must be unit length");
  }
}
} // namespace

std::vector<double> SingleScatteringRadiance(const RenderContext& context,
  const std::array<double, 3>& origin, const std::array<double, 3>& unitDirection, double stepScale)
{
  CheckRay(origin, unitDirection);
  const Integrator integrator(context, stepScale);
  Integrator::Workspace workspace;
  std::vector<double> radiance;
  integrator.Radiance(origin, unitDirection, workspace, radiance);
  return radiance;
}

FloatImage RenderSingleScatteringPass(const RenderContext& context, double stepScale, int threads,
  const std::function<void(double)>& progress)
{
  const Integrator integrator(context, stepScale);
  const Camera& camera = context.GetCamera();
  const int width = camera.GetWidth(), height = camera.GetHeight();
  FloatImage image(width, height);

  // Rows are handed out dynamically; progress comes from the calling thread only.
  std::function<void(std::size_t)> rowsDone;
  if (progress)
  {
    rowsDone = [&](std::size_t done) { progress(static_cast<double>(done) / height); };
  }
  ParallelFor(
    static_cast<std::size_t>(std::max(0, height)), 1, threads,
    [&](std::size_t begin, std::size_t end)
    {
      Integrator::Workspace workspace;
      std::vector<double> radiance;
      for (int j = static_cast<int>(begin); j < static_cast<int>(end); ++j)
      {
        for (int i = 0; i < width; ++i)
        {
          const Vector3 direction = camera.RayDirection(i + 0.5, j + 0.5);
          integrator.Radiance(camera.GetPosition(), direction, workspace, radiance);
          const std::array<double, 3> rgb = context.ToLinearSrgb(radiance);
          float* pixel = image.At(i, j);
          for (int c = 0; c < 3; ++c)
          {
            pixel[c] = static_cast<float>(rgb[c]);
          }
        }
      }
    },
    rowsDone);
  if (progress)
  {
    progress(1.0);
  }
  return image;
}

SingleScatteringResult RenderSingleScattering(const RenderContext& context,
  const SingleScatteringSettings& settings, const std::function<void(double)>& progress)
{
  CheckStepScale(settings.StepScale);
  {
    // Two images (the previous pass and this one) of 3 floats per pixel.
    const Camera& camera = context.GetCamera();
    const double bytes = 2.0 * 3.0 * sizeof(float) * static_cast<double>(camera.GetWidth()) *
      static_cast<double>(camera.GetHeight());
    const double budget = settings.MemoryBudgetBytes > 0.0
      ? settings.MemoryBudgetBytes
      : static_cast<double>(DefaultMemoryBudgetBytes());
    const std::string message =
      OverBudgetMessage("the single-scattering images (" + std::to_string(camera.GetWidth()) + "x" +
          std::to_string(camera.GetHeight()) + " pixels, 2 x 3 floats each)",
        bytes, budget);
    if (!message.empty())
    {
      throw std::length_error(message);
    }
  }
  const auto start = std::chrono::steady_clock::now();
  const int maxRefinements = std::max(0, settings.MaxRefinements);
  const int maxPasses = maxRefinements + 1;

  // Progress: pass k costs ~4^k (view and sun steps both halve). The expected number
  // of passes is updated from the error trend (ε falls ~4× per halving); reported
  // fractions are kept monotonic.
  double reported = 0.0;
  int expectedPasses = std::min(2, maxPasses);
  auto weight = [](int passes) { return (std::pow(4.0, passes) - 1.0) / 3.0; };
  auto report = [&](int pass, double fraction)
  {
    if (!progress)
    {
      return;
    }
    const double value =
      (weight(pass) + fraction * std::pow(4.0, pass)) / weight(std::max(expectedPasses, pass + 1));
    reported = std::max(reported, std::min(1.0, value));
    progress(reported);
  };

  SingleScatteringResult result;
  result.EstimatedRelativeError = std::numeric_limits<double>::infinity();
  double stepScale = settings.StepScale;
  FloatImage previous;
  for (int pass = 0; pass < maxPasses; ++pass)
  {
    FloatImage image = RenderSingleScatteringPass(
      context, stepScale, settings.Threads, [&](double f) { report(pass, f); });
    result.Passes = pass + 1;
    result.FinalStepScale = stepScale;
    if (pass > 0)
    {
      // Richardson: the rule is O(h²), so I_{h/2} - I = (I_h - I_{h/2}) / (2² - 1).
      double diff2 = 0.0, value2 = 0.0;
      for (std::size_t i = 0; i < image.Pixels.size(); ++i)
      {
        const double delta = static_cast<double>(image.Pixels[i]) - previous.Pixels[i];
        diff2 += delta * delta;
        value2 += static_cast<double>(image.Pixels[i]) * image.Pixels[i];
      }
      result.EstimatedRelativeError =
        value2 > 0.0 ? std::sqrt(diff2 / value2) / 3.0 : (diff2 > 0.0 ? 1.0 : 0.0);
    }
    previous = std::move(image);
    if (result.EstimatedRelativeError < settings.RelativeTolerance)
    {
      break;
    }
    if (pass > 0 && result.EstimatedRelativeError > 0.0 && settings.RelativeTolerance > 0.0)
    {
      const double halvings = std::ceil(
        std::log(result.EstimatedRelativeError / settings.RelativeTolerance) / std::log(4.0));
      expectedPasses = std::min(maxPasses, pass + 1 + static_cast<int>(std::max(1.0, halvings)));
    }
    else
    {
      expectedPasses = std::min(maxPasses, pass + 2);
    }
    stepScale *= 0.5;
  }
  result.Image = std::move(previous);
  // Never a silent NaN or infinity (a scene the reader accepts should not make one).
  const std::string nonFinite = NonFiniteMessage(result.Image);
  if (!nonFinite.empty())
  {
    throw std::range_error("RenderSingleScattering: the image has " + nonFinite);
  }
  result.Seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (progress)
  {
    progress(1.0);
  }
  return result;
}

namespace detail
{
std::vector<double> InterpolatedSunAtmosphereTransmittance(const RenderContext& context,
  const std::array<double, 3>& origin, const std::array<double, 3>& unitDirection, double tEnd,
  double t)
{
  std::vector<double> T(context.GetNumberOfWavelengths(), 1.0);
  if (!context.HasAtmosphere())
  {
    return T;
  }
  const Integrator integrator(context, 1.0);
  Integrator::SunKnots knots(integrator, origin, unitDirection, tEnd);
  knots.Evaluate(t, Along(origin, unitDirection, t), T.data());
  return T;
}

double SunAtmosphereKnotSpacing(const RenderContext& context)
{
  if (!context.HasAtmosphere())
  {
    return 0.0;
  }
  const AtmosphereParameters& a = context.GetAtmosphere()->GetParameters();
  return Integrator::KnotSpacingFor(
    context.GetSunDirection()[2], a.EarthRadiusMetres, a.MieScaleHeightMetres);
}
} // namespace detail

} // namespace nimbus
