// Sky model, look-up tables and aerial perspective (see Sky.h for the equations).
//
// Ray march (all rays): nodes t_i = D (i/N)^2 (dense near the observer, where an
// upward ray leaves the aerosol layer within H_M / mu; a ray whose closest approach
// to the earth lies inside it is split there, dense on both sides), and on each step the
// medium and the source are taken at the midpoint and the step is integrated
// exactly for that constant medium (the reference renderer's "exponential
// midpoint rule"):  A += T(t_a) J (1 - e^{-sigma dt}) / sigma,  T(t_b) = T(t_a) e^{-sigma dt}.
#include "Sky.h"
#include "Math.h"

#include "ParallelFor.h"
#include "PhaseFunctions.h"
#include "Quadrature.h"
#include "Sun.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>

namespace nimbus
{

namespace
{
double Clamp(double x, double lo, double hi)
{
  return std::min(hi, std::max(lo, x));
}

void Require(bool ok, const std::string& field, const std::string& what)
{
  if (!ok)
  {
    throw std::invalid_argument("nimbus::Sky: " + field + " " + what);
  }
}

/// Runs f(i) for i in [0, n) on `threads` threads (0 = hardware concurrency), one
/// index per chunk of ParallelFor.
template <class F>
void ForEachIndex(int n, int threads, const F& f)
{
  ParallelFor(static_cast<std::size_t>(std::max(0, n)), 1, threads,
    [&f](std::size_t begin, std::size_t end)
    {
      for (std::size_t i = begin; i < end; ++i)
      {
        f(static_cast<int>(i));
      }
    });
}

double MusToX(double mu)
{
  mu = Clamp(mu, -1.0, 1.0);
  return 0.5 + 0.5 * std::copysign(std::sqrt(std::abs(mu)), mu);
}

double XToMus(double x)
{
  const double y = 2.0 * (x - 0.5);
  return std::copysign(y * y, y);
}

/// Linear interpolation position: index i0 in [0, n-2] and weight f in [0, 1] of x in [0, 1].
void Locate(double x, int n, int& i0, double& f)
{
  const double u = Clamp(x, 0.0, 1.0) * (n - 1);
  i0 = std::min(n - 2, static_cast<int>(std::floor(u)));
  f = u - i0;
}
} // namespace

//------------------------------------------------------------------------------
double LinearSrgbLuminance(const std::array<double, 3>& rgb)
{
  return 0.2126729 * rgb[0] + 0.7151522 * rgb[1] + 0.0721750 * rgb[2];
}

//------------------------------------------------------------------------------
SkyModel::SkyModel(const SkyParameters& p)
  : Parameters(p)
{
  const auto start = std::chrono::steady_clock::now();
  Require(std::isfinite(p.GroundAlbedo) && p.GroundAlbedo >= 0.0 && p.GroundAlbedo <= 1.0,
    "GroundAlbedo", "must be in [0, 1]");
  Require(
    p.ScatteringOrders >= 1 && p.ScatteringOrders <= 50, "ScatteringOrders", "must be in [1, 50]");
  Require(p.Wavelengths >= 3 && p.Wavelengths <= 256, "Wavelengths", "must be in [3, 256]");
  Require(std::isfinite(p.SunTemperatureKelvin) && p.SunTemperatureKelvin >= 1000.0,
    "SunTemperatureKelvin", "must be >= 1000 K");
  Require(p.TransmittanceMuSize >= 2 && p.TransmittanceRSize >= 2, "TransmittanceMuSize/RSize",
    "must be >= 2");
  Require(
    p.ScatteringMuSSize >= 2 && p.ScatteringRSize >= 2, "ScatteringMuSSize/RSize", "must be >= 2");
  Require(p.ScatteringZenithDirections >= 2 && p.ScatteringAzimuthDirections >= 1,
    "ScatteringZenithDirections/AzimuthDirections", "must be >= 2 / >= 1");
  Require(p.ScatteringSteps >= 1 && p.ViewSteps >= 1, "ScatteringSteps/ViewSteps", "must be >= 1");
  try
  {
    this->Air = std::make_unique<Atmosphere>(p.Atmosphere);
  }
  catch (const std::invalid_argument& e)
  {
    throw std::invalid_argument(std::string("nimbus::Sky: Atmosphere: ") + e.what());
  }
  this->Spectrum = std::make_unique<SpectralSamples>(p.Wavelengths,
    p.Wavelengths >= 8 ? SpectralReconstruction::NaturalCubicSpline
                       : SpectralReconstruction::PiecewiseLinear);
  this->SunIrradiance = SunIrradianceSpectrum(*this->Spectrum, p.SunTemperatureKelvin, 1.0);
  for (double lambda : this->Spectrum->GetWavelengths())
  {
    this->BetaRayleigh.push_back(this->Air->RayleighScattering(lambda));
  }
  for (double lambda : this->Spectrum->GetWavelengths())
  {
    this->BetaMieScattering.push_back(this->Air->MieScattering(lambda));
    this->BetaMieExtinction.push_back(this->Air->MieExtinction(lambda));
    this->BetaOzone.push_back(
      p.Atmosphere.OzoneDobsonUnits > 0.0 ? this->Air->OzoneAbsorption(lambda) : 0.0);
  }

  this->BuildTransmittance();
  this->BuildMultipleScattering();
  this->BuildSeconds =
    std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

SkyModel::~SkyModel() = default;

double SkyModel::RayleighPhase(double nu) const
{
  return this->Air->RayleighPhase(nu);
}

double SkyModel::MiePhase(double nu) const
{
  return this->Air->MiePhase(nu);
}

//------------------------------------------------------------------------------
// Geometry (Bruneton 2017 §"Distance to the top/bottom atmosphere boundary").
double SkyModel::DistanceToTop(double r, double mu) const
{
  return DistanceToTopOfAtmosphere(r, mu, this->Parameters.Atmosphere.TopRadiusMetres);
}

double SkyModel::DistanceToGround(double r, double mu) const
{
  const double R = this->Parameters.Atmosphere.EarthRadiusMetres;
  const double disc = r * r * (mu * mu - 1.0) + R * R;
  return std::max(0.0, -r * mu - std::sqrt(std::max(0.0, disc)));
}

bool SkyModel::RayHitsGround(double r, double mu) const
{
  const double R = this->Parameters.Atmosphere.EarthRadiusMetres;
  r = std::max(r, R);
  return mu < 0.0 && r * r * (mu * mu - 1.0) + R * R >= 0.0;
}

double SkyModel::HorizonMu(double r) const
{
  const double R = this->Parameters.Atmosphere.EarthRadiusMetres;
  if (r <= R)
  {
    return 0.0;
  }
  const double q = R / r;
  return -std::sqrt(std::max(0.0, 1.0 - q * q));
}

//------------------------------------------------------------------------------
// Transmittance table: node (i, j) at x_mu = i/(n_mu-1), x_r = j/(n_r-1):
//   rho = H x_r, r = sqrt(rho^2 + R^2), d = d_min + x_mu (d_max - d_min),
//   mu = (H^2 - rho^2 - d^2) / (2 r d)   (Bruneton 2017, GetRMuFromTransmittanceTextureUv).
void SkyModel::BuildTransmittance()
{
  const int nmu = this->Parameters.TransmittanceMuSize, nr = this->Parameters.TransmittanceRSize;
  const double R = this->Parameters.Atmosphere.EarthRadiusMetres;
  const double top = this->Parameters.Atmosphere.TopRadiusMetres;
  const double H = std::sqrt(top * top - R * R);
  this->TransmittanceTable.assign(static_cast<std::size_t>(nmu) * nr * 3, 0.0f);
  ForEachIndex(nr, this->Parameters.Threads,
    [&](int j)
    {
      const double rho = H * j / (nr - 1.0);
      const double r = std::sqrt(rho * rho + R * R);
      const double dmin = top - r, dmax = rho + H;
      for (int i = 0; i < nmu; ++i)
      {
        const double d = dmin + (i / (nmu - 1.0)) * (dmax - dmin);
        const double mu =
          d <= 0.0 ? 1.0 : Clamp((H * H - rho * rho - d * d) / (2.0 * r * d), -1.0, 1.0);
        const std::array<double, 3> lengths = this->ExactOpticalLengths(r, mu);
        float* out = &this->TransmittanceTable[(static_cast<std::size_t>(j) * nmu + i) * 3];
        for (int c = 0; c < 3; ++c)
        {
          out[c] = static_cast<float>(lengths[c]);
        }
      }
    });
}

std::array<double, 3> SkyModel::ExactOpticalLengths(double r, double mu) const
{
  mu = Clamp(mu, -1.0, 1.0);
  const Vector3 p{ { 0.0, 0.0, r } };
  Vector3 d{ { std::sqrt(std::max(0.0, 1.0 - mu * mu)), 0.0, mu } };
  OpticalLengths lengths = this->Air->OpticalLengthsToTop(p, d);
  // The tangent ray (x_mu = 1) may round into the ground: tilt it up by ulps.
  for (int k = 0; k < 8 && lengths.HitsGround; ++k)
  {
    mu += 1e-12 * (1 << (2 * k));
    d = { { std::sqrt(std::max(0.0, 1.0 - mu * mu)), 0.0, mu } };
    lengths = this->Air->OpticalLengthsToTop(p, d);
  }
  return { { lengths.RayleighLengthMetres, lengths.MieLengthMetres, lengths.OzoneLengthMetres } };
}

std::array<double, 3> SkyModel::LookupOpticalLengths(double r, double mu) const
{
  const int nmu = this->Parameters.TransmittanceMuSize, nr = this->Parameters.TransmittanceRSize;
  const double R = this->Parameters.Atmosphere.EarthRadiusMetres;
  const double top = this->Parameters.Atmosphere.TopRadiusMetres;
  const double H = std::sqrt(top * top - R * R);
  r = Clamp(r, R, top);
  const double rho = std::sqrt(std::max(0.0, r * r - R * R));
  const double d = this->DistanceToTop(r, std::max(mu, this->HorizonMu(r)));
  const double dmin = top - r, dmax = rho + H;
  const double xmu = (d - dmin) / (dmax - dmin);
  int i0, j0;
  double fi, fj;
  Locate(xmu, nmu, i0, fi);
  Locate(rho / H, nr, j0, fj);
  std::array<double, 3> result{ { 0.0, 0.0, 0.0 } };
  for (int c = 0; c < 3; ++c)
  {
    auto at = [&](int j, int i)
    {
      return static_cast<double>(
        this->TransmittanceTable[(static_cast<std::size_t>(j) * nmu + i) * 3 + c]);
    };
    result[c] = (1.0 - fj) * ((1.0 - fi) * at(j0, i0) + fi * at(j0, i0 + 1)) +
      fj * ((1.0 - fi) * at(j0 + 1, i0) + fi * at(j0 + 1, i0 + 1));
  }
  return result;
}

void SkyModel::SunTransmittance(double r, double muS, double* T) const
{
  const int n = static_cast<int>(this->BetaRayleigh.size());
  if (this->RayHitsGround(r, muS))
  {
    std::fill(T, T + n, 0.0);
    return;
  }
  const std::array<double, 3> lengths = this->LookupOpticalLengths(r, muS);
  for (int i = 0; i < n; ++i)
  {
    T[i] = std::exp(-(this->BetaRayleigh[i] * lengths[0] + this->BetaMieExtinction[i] * lengths[1] +
      this->BetaOzone[i] * lengths[2]));
  }
}

//------------------------------------------------------------------------------
void SkyModel::LookupTable(const std::vector<float>& table, double r, double muS, double* out) const
{
  const int n = static_cast<int>(this->BetaRayleigh.size());
  const int nmus = this->Parameters.ScatteringMuSSize, nr = this->Parameters.ScatteringRSize;
  const double R = this->Parameters.Atmosphere.EarthRadiusMetres;
  const double top = this->Parameters.Atmosphere.TopRadiusMetres;
  const double H = std::sqrt(top * top - R * R);
  r = Clamp(r, R, top);
  const double rho = std::sqrt(std::max(0.0, r * r - R * R));
  int i0, j0;
  double fi, fj;
  Locate(MusToX(muS), nmus, i0, fi);
  Locate(rho / H, nr, j0, fj);
  const float* a = &table[(static_cast<std::size_t>(j0) * nmus + i0) * n];
  const float* b = a + n;
  const float* c = a + static_cast<std::size_t>(nmus) * n;
  const float* d = c + n;
  const double wa = (1 - fj) * (1 - fi), wb = (1 - fj) * fi, wc = fj * (1 - fi), wd = fj * fi;
  for (int l = 0; l < n; ++l)
  {
    out[l] = wa * a[l] + wb * b[l] + wc * c[l] + wd * d[l];
  }
}

void SkyModel::LookupGround(const std::vector<float>& table, double muS, double* out) const
{
  const int n = static_cast<int>(this->BetaRayleigh.size());
  const int nmus = this->Parameters.ScatteringMuSSize;
  int i0;
  double f;
  Locate(MusToX(muS), nmus, i0, f);
  const float* a = &table[static_cast<std::size_t>(i0) * n];
  for (int l = 0; l < n; ++l)
  {
    out[l] = (1 - f) * a[l] + f * a[l + n];
  }
}

void SkyModel::LookupMultipleScattering(double r, double muS, double* meanRadiance) const
{
  this->LookupTable(this->MultipleTable, r, muS, meanRadiance);
}

void SkyModel::LookupGroundSkyIrradiance(double muS, double* irradiance) const
{
  this->LookupGround(this->GroundSkyTable, muS, irradiance);
}

std::vector<double> SkyModel::OrderMeanRadiance(double muS) const
{
  std::vector<double> result;
  std::vector<double> spectrum(this->BetaRayleigh.size());
  for (const auto& order : this->OrderMeans)
  {
    std::vector<float> table(order.begin(), order.end());
    this->LookupGround(table, muS, spectrum.data());
    result.push_back(this->Spectrum->ToXyz(spectrum)[1]);
  }
  return result;
}

std::vector<float> SkyModel::GetMultipleScatteringTableRgb() const
{
  const std::size_t n = this->BetaRayleigh.size();
  const std::size_t nodes = this->MultipleTable.size() / n;
  std::vector<float> rgb(nodes * 3);
  std::vector<double> spectrum(n);
  for (std::size_t k = 0; k < nodes; ++k)
  {
    for (std::size_t l = 0; l < n; ++l)
    {
      spectrum[l] = this->MultipleTable[k * n + l];
    }
    const std::array<double, 3> c = this->Spectrum->ToLinearSrgb(spectrum);
    for (int i = 0; i < 3; ++i)
    {
      rgb[k * 3 + i] = static_cast<float>(c[i]);
    }
  }
  return rgb;
}

namespace
{
/// Moves the start of a march x (earth-centred, radius r) into the atmosphere: from below
/// the ground radially onto it, from above the top along w to where the ray enters
/// (offset: the distance skipped, m). False when the ray misses the atmosphere.
bool EnterAtmosphere(const Vector3& w, double R, double top, Vector3& x, double& r, double& offset)
{
  if (r < R)
  {
    // Below the ground: radially onto it (as Atmosphere::OpticalLengthsToTop).
    const double k = r > 0.0 ? R / r : 0.0;
    x = r > 0.0 ? Vector3{ { x[0] * k, x[1] * k, x[2] * k } } : Vector3{ { 0.0, 0.0, R } };
    r = R;
  }
  if (r > top)
  {
    const double b = Dot(x, w);
    const double disc = b * b - (r - top) * (r + top);
    if (b >= 0.0 || disc <= 0.0)
    {
      return false; // misses the atmosphere
    }
    offset = -b - std::sqrt(disc);
    x = { { x[0] + offset * w[0], x[1] + offset * w[1], x[2] + offset * w[2] } };
    r = top;
  }
  return true;
}

/// The march's step nodes along the ray (m from x, the entry point) up to D: steps per
/// interval between the distances recordAt (from the ray's origin, offset before x) when
/// given, with recordNode the node reached at each; else quadratically spaced.
std::vector<double> MarchNodes(const Vector3& x, const Vector3& w, double D, double offset,
  int steps, const std::vector<double>* recordAt, std::vector<std::size_t>& recordNode)
{
  std::vector<double> nodes;
  if (recordAt)
  {
    nodes.push_back(0.0);
    double previous = 0.0;
    for (double target : *recordAt)
    {
      const double t1 = Clamp(target - offset, 0.0, D);
      if (t1 > previous)
      {
        for (int k = 1; k <= steps; ++k)
        {
          nodes.push_back(previous + (t1 - previous) * k / steps);
        }
        previous = t1;
      }
      recordNode.push_back(nodes.size() - 1);
    }
  }
  else
  {
    // Dense near the observer; a ray that passes its closest approach to the earth
    // centre inside [0, D] (a grazing ray seen from altitude) is also dense around
    // that point, where the density along it peaks: half the steps on each side.
    const double closest = -Dot(x, w);
    if (closest > 0.0 && closest < D && steps >= 4)
    {
      const int first = steps / 2;
      for (int k = 0; k <= first; ++k)
      {
        const double u = 1.0 - static_cast<double>(k) / first;
        nodes.push_back(closest * (1.0 - u * u));
      }
      for (int k = 1; k <= steps - first; ++k)
      {
        const double u = static_cast<double>(k) / (steps - first);
        nodes.push_back(closest + (D - closest) * u * u);
      }
    }
    else
    {
      for (int k = 0; k <= steps; ++k)
      {
        const double u = static_cast<double>(k) / steps;
        nodes.push_back(D * u * u);
      }
    }
  }
  return nodes;
}
} // namespace

//------------------------------------------------------------------------------
SkySpectra SkyModel::March(
  const Vector3& x0, const Vector3& w, const Vector3& s, const MarchOptions& o) const
{
  const int n = static_cast<int>(this->BetaRayleigh.size());
  const AtmosphereParameters& a = this->Parameters.Atmosphere;
  const double R = a.EarthRadiusMetres, top = a.TopRadiusMetres;
  SkySpectra out;
  out.Rayleigh.assign(n, 0.0);
  out.Mie.assign(n, 0.0);
  out.Isotropic.assign(n, 0.0);
  out.Transmittance.assign(n, 1.0);
  auto record = [&](std::size_t count)
  {
    if (o.Records)
    {
      while (o.Records->size() < count)
      {
        o.Records->push_back(out);
      }
    }
  };

  Vector3 x = x0;
  double r = std::sqrt(Dot(x, x));
  if (!std::isfinite(r) || !std::isfinite(Dot(w, w)) || !std::isfinite(Dot(s, s)))
  {
    throw std::invalid_argument("nimbus::Sky: non-finite ray or sun direction");
  }
  double offset = 0.0; // distance skipped outside the atmosphere
  if (!EnterAtmosphere(w, R, top, x, r, offset))
  {
    record(o.RecordAt ? o.RecordAt->size() : 0);
    return out; // misses the atmosphere
  }
  const double mu = Clamp(Dot(x, w) / r, -1.0, 1.0);
  bool hits = this->RayHitsGround(r, mu);
  if (o.Ground == GroundMode::Hit)
  {
    hits = true;
  }
  else if (o.Ground == GroundMode::Miss)
  {
    hits = false;
  }
  double D = hits ? this->DistanceToGround(r, mu) : this->DistanceToTop(r, mu);
  bool groundTerm = hits;
  if (o.RecordAt && !o.RecordAt->empty())
  {
    D = std::max(0.0, o.RecordAt->back() - offset);
    groundTerm = false;
  }
  else if (o.MaxDistance >= 0.0 && o.MaxDistance - offset < D)
  {
    D = std::max(0.0, o.MaxDistance - offset);
    groundTerm = false;
  }

  // Step nodes.
  const int steps = o.Steps > 0 ? o.Steps : this->Parameters.ViewSteps;
  std::vector<std::size_t> recordNode; // node index reached at each record
  const std::vector<double> nodes = MarchNodes(x, w, D, offset, steps, o.RecordAt, recordNode);

  std::vector<double> Tsun(n), source(n, 0.0);
  std::vector<double>& T = out.Transmittance;
  std::size_t nextRecord = 0;
  auto flushRecords = [&](std::size_t node)
  {
    if (o.Records)
    {
      while (nextRecord < recordNode.size() && recordNode[nextRecord] <= node)
      {
        o.Records->push_back(out);
        ++nextRecord;
      }
    }
  };
  flushRecords(0);
  for (std::size_t k = 0; k + 1 < nodes.size(); ++k)
  {
    const double ta = nodes[k], tb = nodes[k + 1], dt = tb - ta;
    if (dt > 0.0)
    {
      const double tm = 0.5 * (ta + tb);
      const Vector3 p{ { x[0] + tm * w[0], x[1] + tm * w[1], x[2] + tm * w[2] } };
      const double rp = std::sqrt(Dot(p, p));
      const double h = rp - R;
      const double rhoR = this->Air->Density(h, a.RayleighScaleHeightMetres);
      const double rhoM = this->Air->Density(h, a.MieScaleHeightMetres);
      const double rhoO = this->Air->OzoneDensity(h);
      const double muS = Clamp(Dot(p, s) / rp, -1.0, 1.0);
      if (o.Single)
      {
        if (o.ExactSun)
        {
          for (int l = 0; l < n; ++l)
          {
            Tsun[l] = this->Air->TransmittanceToTop(p, s, this->Spectrum->GetWavelengths()[l]);
          }
        }
        else
        {
          this->SunTransmittance(rp, muS, Tsun.data());
        }
      }
      if (o.Source)
      {
        this->LookupTable(*o.Source, rp, muS, source.data());
      }
      for (int l = 0; l < n; ++l)
      {
        const double rayleigh = this->BetaRayleigh[l] * rhoR;
        const double mieS = this->BetaMieScattering[l] * rhoM;
        const double sigma =
          rayleigh + this->BetaMieExtinction[l] * rhoM + this->BetaOzone[l] * rhoO;
        const double x = sigma * dt;
        const double e = std::exp(-x);
        const double weight =
          T[l] * (x < 1e-4 ? dt * (1.0 - 0.5 * x + x * x / 6.0) : (1.0 - e) / sigma);
        if (o.Single)
        {
          const double sun = this->SunIrradiance[l] * Tsun[l] * weight;
          out.Rayleigh[l] += rayleigh * sun;
          out.Mie[l] += mieS * sun;
        }
        if (o.Source)
        {
          out.Isotropic[l] += weight * (rayleigh + mieS) * source[l];
        }
        T[l] *= e;
      }
    }
    flushRecords(k + 1);
  }
  if (groundTerm && this->Parameters.GroundAlbedo > 0.0)
  {
    const Vector3 g{ { x[0] + D * w[0], x[1] + D * w[1], x[2] + D * w[2] } };
    const double rg = std::sqrt(Dot(g, g));
    const double muS = Clamp(Dot(g, s) / rg, -1.0, 1.0);
    const double albedo = this->Parameters.GroundAlbedo / kPi;
    if (o.GroundDirect && muS > 0.0)
    {
      this->SunTransmittance(R, muS, Tsun.data());
      for (int l = 0; l < n; ++l)
      {
        out.Isotropic[l] += T[l] * albedo * this->SunIrradiance[l] * Tsun[l] * muS;
      }
    }
    if (o.GroundSky)
    {
      this->LookupGround(*o.GroundSky, muS, source.data());
      for (int l = 0; l < n; ++l)
      {
        out.Isotropic[l] += T[l] * albedo * source[l];
      }
    }
  }
  return out;
}

SkySpectra SkyModel::IntegrateRay(const Vector3& x, const Vector3& w, const Vector3& s,
  double maxDistance, int steps, bool includeMultiple, bool exactSun) const
{
  MarchOptions o;
  o.Steps = steps;
  o.MaxDistance = maxDistance;
  o.ExactSun = exactSun;
  if (includeMultiple && this->Parameters.ScatteringOrders > 1)
  {
    o.Source = &this->MultipleTable;
    o.GroundSky = &this->GroundSkyTable;
  }
  return this->March(x, w, s, o);
}

//------------------------------------------------------------------------------
// Iterated orders (Bruneton & Neyret 2008 §4 with an isotropic scattering density,
// see Sky.h): at node (r, mu_s) the observer sits at (0, 0, r) with the sun in the
// x-z plane; the sphere of directions is integrated with Gauss-Legendre in cos(zenith)
// and midpoint nodes in azimuth over [0, pi] (the field is symmetric about the sun's
// vertical plane).
void SkyModel::BuildMultipleScattering()
{
  const int n = static_cast<int>(this->BetaRayleigh.size());
  const int nmus = this->Parameters.ScatteringMuSSize, nr = this->Parameters.ScatteringRSize;
  const double R = this->Parameters.Atmosphere.EarthRadiusMetres;
  const double top = this->Parameters.Atmosphere.TopRadiusMetres;
  const double H = std::sqrt(top * top - R * R);
  const std::size_t tableSize = static_cast<std::size_t>(nr) * nmus * n;
  this->MultipleTable.assign(tableSize, 0.0f);
  this->GroundSkyTable.assign(static_cast<std::size_t>(nmus) * n, 0.0f);
  this->OrderMeans.clear();
  const int orders = this->Parameters.ScatteringOrders;
  if (orders <= 1)
  {
    return;
  }
  std::vector<double> gx, gw;
  GaussLegendre(this->Parameters.ScatteringZenithDirections, gx, gw);
  const int nphi = this->Parameters.ScatteringAzimuthDirections;

  std::vector<float> previous, previousGround; // order k-1 (empty for k = 1)
  std::vector<double> sumGround(static_cast<std::size_t>(nmus) * n, 0.0);
  std::vector<double> sumMean(tableSize, 0.0);
  for (int order = 1; order < orders; ++order)
  {
    std::vector<float> mean(tableSize, 0.0f), ground(static_cast<std::size_t>(nmus) * n, 0.0f);
    ForEachIndex(nr * nmus, this->Parameters.Threads,
      [&](int node)
      {
        const int j = node / nmus, i = node % nmus;
        const double rho = H * j / (nr - 1.0);
        const double r = std::sqrt(rho * rho + R * R);
        const double muS = XToMus(i / (nmus - 1.0));
        const Vector3 x{ { 0.0, 0.0, r } };
        const Vector3 s{ { std::sqrt(std::max(0.0, 1.0 - muS * muS)), 0.0, muS } };
        MarchOptions o;
        o.Steps = this->Parameters.ScatteringSteps;
        o.Single = order == 1;
        o.GroundDirect = order == 1;
        o.Source = order == 1 ? nullptr : &previous;
        o.GroundSky = order == 1 ? nullptr : &previousGround;
        std::vector<double> sphere(n, 0.0), up(n, 0.0);
        for (std::size_t a = 0; a < gx.size(); ++a)
        {
          const double mu = gx[a];
          const double sinTheta = std::sqrt(std::max(0.0, 1.0 - mu * mu));
          for (int b = 0; b < nphi; ++b)
          {
            const double phi = (b + 0.5) * kPi / nphi;
            const Vector3 w{ { sinTheta * std::cos(phi), sinTheta * std::sin(phi), mu } };
            const SkySpectra L = this->March(x, w, s, o);
            const double nu = Dot(w, s);
            const double pR = o.Single ? this->RayleighPhase(nu) : 0.0;
            const double pM = o.Single ? this->MiePhase(nu) : 0.0;
            // dw weight: Gauss weight x (pi / nphi) x 2 (the mirrored half).
            const double weight = gw[a] * (2.0 * kPi / nphi);
            for (int l = 0; l < n; ++l)
            {
              const double radiance = pR * L.Rayleigh[l] + pM * L.Mie[l] + L.Isotropic[l];
              sphere[l] += weight * radiance;
              if (mu > 0.0)
              {
                up[l] += weight * mu * radiance;
              }
            }
          }
        }
        for (int l = 0; l < n; ++l)
        {
          mean[(static_cast<std::size_t>(j) * nmus + i) * n + l] =
            static_cast<float>(sphere[l] / (4.0 * kPi));
          if (j == 0)
          {
            ground[static_cast<std::size_t>(i) * n + l] = static_cast<float>(up[l]);
          }
        }
      });
    for (std::size_t k = 0; k < tableSize; ++k)
    {
      sumMean[k] += mean[k];
    }
    for (std::size_t k = 0; k < sumGround.size(); ++k)
    {
      sumGround[k] += ground[k];
    }
    this->OrderMeans.emplace_back(
      mean.begin(), mean.begin() + static_cast<std::ptrdiff_t>(nmus) * n);
    previous = std::move(mean);
    previousGround = std::move(ground);
  }
  for (std::size_t k = 0; k < tableSize; ++k)
  {
    this->MultipleTable[k] = static_cast<float>(sumMean[k]);
  }
  for (std::size_t k = 0; k < sumGround.size(); ++k)
  {
    this->GroundSkyTable[k] = static_cast<float>(sumGround[k]);
  }
}

//------------------------------------------------------------------------------
SkyRgbParts SkyModel::ToRgb(const SkySpectra& spectra) const
{
  SkyRgbParts parts;
  parts.Rayleigh = this->Spectrum->ToLinearSrgb(spectra.Rayleigh);
  parts.Mie = this->Spectrum->ToLinearSrgb(spectra.Mie);
  parts.Isotropic = this->Spectrum->ToLinearSrgb(spectra.Isotropic);
  return parts;
}

std::array<double, 3> SkyModel::TransmittanceRgb(const std::vector<double>& transmittance) const
{
  std::vector<double> filtered(this->SunIrradiance.size());
  for (std::size_t l = 0; l < filtered.size(); ++l)
  {
    filtered[l] = this->SunIrradiance[l] * transmittance[l];
  }
  const std::array<double, 3> through = this->Spectrum->ToLinearSrgb(filtered);
  const std::array<double, 3> sun = this->Spectrum->ToLinearSrgb(this->SunIrradiance);
  std::array<double, 3> t;
  for (int c = 0; c < 3; ++c)
  {
    t[c] = sun[c] > 0.0 ? Clamp(through[c] / sun[c], 0.0, 1.0) : 0.0;
  }
  return t;
}

std::array<double, 3> SkyModel::Radiance(
  double altitude, const Vector3& w, const Vector3& s, bool includeMultiple, int steps) const
{
  const Vector3 x{ { 0.0, 0.0, this->Parameters.Atmosphere.EarthRadiusMetres + altitude } };
  const SkyRgbParts parts = this->ToRgb(this->IntegrateRay(x, w, s, -1.0, steps, includeMultiple));
  const double nu = Dot(w, s);
  const double pR = this->RayleighPhase(nu), pM = this->MiePhase(nu);
  std::array<double, 3> L;
  for (int c = 0; c < 3; ++c)
  {
    L[c] = pR * parts.Rayleigh[c] + pM * parts.Mie[c] + parts.Isotropic[c];
  }
  return L;
}

void SkyModel::AerialPerspective(const Vector3& p0, const Vector3& p1, const Vector3& s,
  std::array<double, 3>& transmittance, std::array<double, 3>& inscatter, int steps) const
{
  const Vector3 d{ { p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2] } };
  const double length = std::sqrt(Dot(d, d));
  if (!(length > 0.0))
  {
    transmittance = { { 1.0, 1.0, 1.0 } };
    inscatter = { { 0.0, 0.0, 0.0 } };
    return;
  }
  const Vector3 w{ { d[0] / length, d[1] / length, d[2] / length } };
  MarchOptions o;
  o.Steps = steps;
  o.MaxDistance = length;
  o.GroundDirect = false;
  o.Ground = GroundMode::Miss; // the segment ends at the point, whatever is beyond it
  if (this->Parameters.ScatteringOrders > 1)
  {
    o.Source = &this->MultipleTable;
  }
  const SkySpectra spectra = this->March(p0, w, s, o);
  const SkyRgbParts parts = this->ToRgb(spectra);
  const double nu = Dot(w, s);
  const double pR = this->RayleighPhase(nu), pM = this->MiePhase(nu);
  for (int c = 0; c < 3; ++c)
  {
    inscatter[c] = pR * parts.Rayleigh[c] + pM * parts.Mie[c] + parts.Isotropic[c];
  }
  transmittance = this->TransmittanceRgb(spectra.Transmittance);
}

//------------------------------------------------------------------------------
double SkyViewMapping::Row(double zenith) const
{
  const double th = this->HorizonZenith;
  if (zenith <= th)
  {
    const double a = Clamp((th - zenith) / th, 0.0, 1.0); // 1 at the zenith, 0 at the horizon
    return std::cbrt(a) * (this->AboveRows - 1);
  }
  const double b = Clamp((zenith - th) / (kPi - th), 0.0, 1.0);
  return this->AboveRows + std::cbrt(b) * (this->BelowRows - 1);
}

void SkyViewMapping::Texel(
  const Vector3& w, double sunAzimuthDegrees, double& column, double& row) const
{
  const double zenith = std::atan2(std::hypot(w[0], w[1]), w[2]);
  row = this->Row(zenith);
  double phi = 0.0;
  if (w[0] * w[0] + w[1] * w[1] > 0.0)
  {
    phi = std::atan2(w[0], w[1]) - sunAzimuthDegrees * kDegree;
    phi = std::remainder(phi, 2.0 * kPi);
    phi = std::abs(phi);
  }
  column = Clamp(phi / kPi, 0.0, 1.0) * (this->Width - 1);
}

double SkyViewMapping::ZenithOfRow(int row) const
{
  const double th = this->HorizonZenith;
  if (row < this->AboveRows)
  {
    const double s = static_cast<double>(row) / (this->AboveRows - 1);
    return th * (1.0 - s * s * s);
  }
  const double s = static_cast<double>(row - this->AboveRows) / (this->BelowRows - 1);
  return th + s * s * s * (kPi - th);
}

namespace
{
SkyViewMapping MakeMapping(const SkyModel& model, double altitude, int width, int above, int below)
{
  Require(
    width >= 2 && above >= 2 && below >= 2, "sky-view size", "must be >= 2 in every direction");
  Require(
    std::isfinite(altitude) && altitude >= 0.0, "observer altitude", "must be finite and >= 0");
  SkyViewMapping m;
  m.Width = width;
  m.AboveRows = above;
  m.BelowRows = below;
  m.HorizonZenith =
    std::acos(model.HorizonMu(model.GetParameters().Atmosphere.EarthRadiusMetres + altitude));
  return m;
}

/// Column (continuous, [0, width-1]) and row (continuous) of direction w for the sun azimuth.
/// Bilinear texel corners without crossing the horizon between the row halves.
void Corners(
  const SkyViewMapping& m, double col, double row, int& c0, double& fc, int& r0, double& fr)
{
  c0 = std::min(m.Width - 2, static_cast<int>(std::floor(col)));
  fc = col - c0;
  if (row < m.AboveRows)
  {
    r0 = std::min(m.AboveRows - 2, static_cast<int>(std::floor(row)));
  }
  else
  {
    r0 = std::max(m.AboveRows, std::min(m.Rows() - 2, static_cast<int>(std::floor(row))));
  }
  fr = Clamp(row - r0, 0.0, 1.0);
}
} // namespace

SkyViewLut::SkyViewLut(const SkyModel& model, double sunElevationDeg, double observerAltitude,
  int width, int aboveRows, int belowRows, bool includeMultiple)
  : Model(model)
  , Mapping(MakeMapping(model, observerAltitude, width, aboveRows, belowRows))
  , SunElevationDegrees(sunElevationDeg)
  , ObserverAltitude(observerAltitude)
{
  Require(std::isfinite(sunElevationDeg) && std::abs(sunElevationDeg) <= 90.0, "sun elevation",
    "must be in [-90, 90] degrees");
  const auto start = std::chrono::steady_clock::now();
  const int rows = this->Mapping.Rows(), cols = this->Mapping.Width;
  const std::size_t plane = static_cast<std::size_t>(rows) * cols * 3;
  this->Table.assign(plane * 3, 0.0f);
  const Vector3 s = SunDirection(sunElevationDeg, 0.0);
  const Vector3 x{ { 0.0, 0.0,
    model.GetParameters().Atmosphere.EarthRadiusMetres + observerAltitude } };
  ForEachIndex(rows, model.GetParameters().Threads,
    [&](int row)
    {
      const double zenith = this->Mapping.ZenithOfRow(row);
      SkyModel::MarchOptions o;
      o.Ground =
        row < this->Mapping.AboveRows ? SkyModel::GroundMode::Miss : SkyModel::GroundMode::Hit;
      if (includeMultiple && model.GetParameters().ScatteringOrders > 1)
      {
        o.Source = &model.GetMultipleScatteringTable();
        o.GroundSky = &model.GetGroundSkyTable();
      }
      for (int col = 0; col < cols; ++col)
      {
        const double phi = kPi * col / (cols - 1.0); // azimuth from the sun (sun at azimuth 0 = +y)
        const Vector3 w{ { std::sin(zenith) * std::sin(phi), std::sin(zenith) * std::cos(phi),
          std::cos(zenith) } };
        const SkySpectra spectra = model.March(x, w, s, o);
        const SkyRgbParts parts = model.ToRgb(spectra);
        const std::size_t at = (static_cast<std::size_t>(row) * cols + col) * 3;
        for (int c = 0; c < 3; ++c)
        {
          this->Table[at + c] = static_cast<float>(parts.Rayleigh[c]);
          this->Table[plane + at + c] = static_cast<float>(parts.Mie[c]);
          this->Table[2 * plane + at + c] = static_cast<float>(parts.Isotropic[c]);
        }
      }
    });
  this->BuildSeconds =
    std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

SkyRgbParts SkyViewLut::Parts(const Vector3& w, double sunAzimuthDeg) const
{
  double col, row;
  this->Mapping.Texel(w, sunAzimuthDeg, col, row);
  int c0, r0;
  double fc, fr;
  Corners(this->Mapping, col, row, c0, fc, r0, fr);
  const int cols = this->Mapping.Width;
  const std::size_t plane = static_cast<std::size_t>(this->Mapping.Rows()) * cols * 3;
  SkyRgbParts parts;
  std::array<double, 3>* out[3] = { &parts.Rayleigh, &parts.Mie, &parts.Isotropic };
  for (int k = 0; k < 3; ++k)
  {
    const float* t = &this->Table[k * plane];
    for (int c = 0; c < 3; ++c)
    {
      auto at = [&](int rr, int cc)
      { return static_cast<double>(t[(static_cast<std::size_t>(rr) * cols + cc) * 3 + c]); };
      (*out[k])[c] = (1 - fr) * ((1 - fc) * at(r0, c0) + fc * at(r0, c0 + 1)) +
        fr * ((1 - fc) * at(r0 + 1, c0) + fc * at(r0 + 1, c0 + 1));
    }
  }
  return parts;
}

std::array<double, 3> SkyViewLut::Radiance(const Vector3& w, double sunAzimuthDeg) const
{
  const SkyRgbParts parts = this->Parts(w, sunAzimuthDeg);
  const Vector3 s = SunDirection(this->SunElevationDegrees, sunAzimuthDeg);
  const double nu = Dot(w, s);
  const double pR = this->Model.RayleighPhase(nu), pM = this->Model.MiePhase(nu);
  std::array<double, 3> L;
  for (int c = 0; c < 3; ++c)
  {
    L[c] = pR * parts.Rayleigh[c] + pM * parts.Mie[c] + parts.Isotropic[c];
  }
  return L;
}

//------------------------------------------------------------------------------
AerialPerspectiveLut::AerialPerspectiveLut(const SkyModel& model, double sunElevationDeg,
  double cameraAltitude, double maxDistance, int width, int aboveRows, int belowRows, int slices)
  : Mapping(MakeMapping(model, cameraAltitude, width, aboveRows, belowRows))
  , Model(model)
  , Slices(slices)
  , MaxDistance(maxDistance)
  , SunElevationDegrees(sunElevationDeg)
{
  Require(slices >= 2, "aerial-perspective slices", "must be >= 2");
  Require(std::isfinite(maxDistance) && maxDistance > 0.0, "aerial-perspective max distance",
    "must be finite and > 0");
  const auto start = std::chrono::steady_clock::now();
  const int rows = this->Mapping.Rows(), cols = this->Mapping.Width;
  this->Table.assign(static_cast<std::size_t>(slices) * rows * cols * 12, 0.0f);
  std::vector<double> distances;
  for (int k = 0; k < slices; ++k)
  {
    const double u = static_cast<double>(k) / (slices - 1);
    distances.push_back(maxDistance * u * u);
  }
  const Vector3 s = SunDirection(sunElevationDeg, 0.0);
  const Vector3 x{ { 0.0, 0.0,
    model.GetParameters().Atmosphere.EarthRadiusMetres + cameraAltitude } };
  ForEachIndex(rows, model.GetParameters().Threads,
    [&](int row)
    {
      const double zenith = this->Mapping.ZenithOfRow(row);
      for (int col = 0; col < cols; ++col)
      {
        const double phi = kPi * col / (cols - 1.0);
        const Vector3 w{ { std::sin(zenith) * std::sin(phi), std::sin(zenith) * std::cos(phi),
          std::cos(zenith) } };
        SkyModel::MarchOptions o;
        o.Steps = 4; // per slice
        o.GroundDirect = false;
        o.Ground = SkyModel::GroundMode::Miss;
        if (model.GetParameters().ScatteringOrders > 1)
        {
          o.Source = &model.GetMultipleScatteringTable();
        }
        std::vector<SkySpectra> records;
        o.RecordAt = &distances;
        o.Records = &records;
        model.March(x, w, s, o);
        for (int k = 0; k < slices && k < static_cast<int>(records.size()); ++k)
        {
          const SkyRgbParts parts = model.ToRgb(records[k]);
          const std::array<double, 3> t = model.TransmittanceRgb(records[k].Transmittance);
          float* out = &this->Table[((static_cast<std::size_t>(k) * rows + row) * cols + col) * 12];
          for (int c = 0; c < 3; ++c)
          {
            out[c] = static_cast<float>(parts.Rayleigh[c]);
            out[3 + c] = static_cast<float>(parts.Mie[c]);
            out[6 + c] = static_cast<float>(parts.Isotropic[c]);
            out[9 + c] = static_cast<float>(t[c]);
          }
        }
      }
    });
  this->BuildSeconds =
    std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void AerialPerspectiveLut::Lookup(const Vector3& w, double distance, double sunAzimuthDeg,
  std::array<double, 3>& transmittance, std::array<double, 3>& inscatter) const
{
  double col, row;
  this->Mapping.Texel(w, sunAzimuthDeg, col, row);
  int c0, r0;
  double fc, fr;
  Corners(this->Mapping, col, row, c0, fc, r0, fr);
  // Slices are at d = D (k/(S-1))^2.
  const double u = std::sqrt(Clamp(distance / this->MaxDistance, 0.0, 1.0)) * (this->Slices - 1);
  const int k0 = std::min(this->Slices - 2, static_cast<int>(std::floor(u)));
  // Linear in the distance between the two slices (the in-scattering grows about
  // linearly with d; linear in u would not be, measured 7 % off at mid-slice).
  const double dk0 = this->MaxDistance * std::pow(k0 / (this->Slices - 1.0), 2.0);
  const double dk1 = this->MaxDistance * std::pow((k0 + 1) / (this->Slices - 1.0), 2.0);
  const double fk = Clamp((std::min(distance, this->MaxDistance) - dk0) / (dk1 - dk0), 0.0, 1.0);
  const int rows = this->Mapping.Rows(), cols = this->Mapping.Width;
  double v[12] = { 0 };
  for (int dk = 0; dk < 2; ++dk)
  {
    for (int dr = 0; dr < 2; ++dr)
    {
      for (int dc = 0; dc < 2; ++dc)
      {
        const double weight = (dk ? fk : 1 - fk) * (dr ? fr : 1 - fr) * (dc ? fc : 1 - fc);
        const float* t =
          &this
             ->Table[((static_cast<std::size_t>(k0 + dk) * rows + r0 + dr) * cols + c0 + dc) * 12];
        for (int i = 0; i < 12; ++i)
        {
          v[i] += weight * t[i];
        }
      }
    }
  }
  // The sun's elevation is in the table; the phase functions take the actual nu.
  const double nu = Dot(w, SunDirection(this->SunElevationDegrees, sunAzimuthDeg));
  const double pR = this->Model.RayleighPhase(nu), pM = this->Model.MiePhase(nu);
  for (int c = 0; c < 3; ++c)
  {
    transmittance[c] = v[9 + c];
    inscatter[c] = v[c] * pR + v[3 + c] * pM + v[6 + c];
  }
}

} // namespace nimbus
