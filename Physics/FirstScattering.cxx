// The first scattering of point sources on the medium's grid (see FirstScattering.h).
#include "FirstScattering.h"

#include "CellAverage.h"
#include "ParallelFor.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <map>
#include <sstream>
#include <stdexcept>

namespace nimbus
{
namespace
{
// Optical depth beyond which a source's light is dropped (T < 4e-18).
constexpr double kOpaque = 40.0;
// Sources merged to one grid point: their total intensity and intensity-weighted centre.
struct MergedSource
{
  std::array<int, 3> Point{ { 0, 0, 0 } }; // grid indices (may lie outside the grid)
  Vector3 Centre{ { 0, 0, 0 } };           // world [m]
  double Intensity = 0.0;
};

Vector3 IndexCoordinates(const ExtinctionGrid& grid, const Vector3& world)
{
  const Vector3 rel{ { world[0] - grid.Origin[0], world[1] - grid.Origin[1],
    world[2] - grid.Origin[2] } };
  return { { Dot(rel, grid.Axes[0]) / grid.Spacing[0], Dot(rel, grid.Axes[1]) / grid.Spacing[1],
    Dot(rel, grid.Axes[2]) / grid.Spacing[2] } };
}

std::vector<MergedSource> MergeByGridPoint(
  const ExtinctionGrid& grid, const std::vector<ScalarPointSource>& sources)
{
  std::map<std::array<int, 3>, MergedSource> merged;
  for (const ScalarPointSource& s : sources)
  {
    if (!(s.Intensity > 0.0))
    {
      continue;
    }
    const Vector3 index = IndexCoordinates(grid, s.Position);
    std::array<int, 3> point;
    for (int a = 0; a < 3; ++a)
    {
      // Far outside the grid the point only needs to be outside: clamp to keep ints sane.
      point[a] = static_cast<int>(std::lround(std::clamp(index[a], -1e6, 1e6)));
    }
    MergedSource& m = merged[point];
    m.Point = point;
    m.Intensity += s.Intensity;
    for (int c = 0; c < 3; ++c)
    {
      m.Centre[c] += s.Intensity * s.Position[c];
    }
  }
  std::vector<MergedSource> out;
  out.reserve(merged.size());
  for (auto& entry : merged)
  {
    MergedSource m = entry.second;
    for (int c = 0; c < 3; ++c)
    {
      m.Centre[c] /= m.Intensity;
    }
    out.push_back(m);
  }
  return out;
}

// The points whose field can be drawn: those with extinction and their 26 neighbours (a
// renderer interpolates between them); the others only carry tau.
std::vector<char> WantedPoints(const ExtinctionGrid& grid)
{
  const int nx = grid.Dimensions[0], ny = grid.Dimensions[1], nz = grid.Dimensions[2];
  std::vector<char> wanted(grid.NumberOfPoints(), 0);
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
      {
        if (!(grid.Extinction[grid.Index(i, j, k)] > 0.0f))
        {
          continue;
        }
        for (int c = std::max(0, k - 1); c <= std::min(nz - 1, k + 1); ++c)
          for (int b = std::max(0, j - 1); b <= std::min(ny - 1, j + 1); ++b)
            for (int a = std::max(0, i - 1); a <= std::min(nx - 1, i + 1); ++a)
            {
              wanted[grid.Index(a, b, c)] = 1;
            }
      }
  return wanted;
}

// One source's pass: tau carried outward shell by shell, E and F added to `sum`.
class SourcePass
{
public:
  SourcePass(const ExtinctionGrid& grid, const FirstScatteringForwardPeak& peak,
    const std::vector<char>& wanted, std::vector<float>& meanExtinction, std::vector<double>& sum)
    : Grid(grid)
    , Peak(peak.Fraction)
    , Reduced(1.0 - peak.Fraction * peak.Albedo)
    , Wanted(wanted)
    , MeanExtinction(meanExtinction)
    , Sum(sum)
  {
    for (int a = 0; a < 3; ++a)
    {
      this->Dims[a] = grid.Dimensions[a];
    }
  }

  void Run(const MergedSource& source)
  {
    this->Source = &source;
    this->CentreIndex = IndexCoordinates(this->Grid, source.Centre);
    // The eight octants about the source's point, each swept in raster order away from
    // it (a point's predecessor is at most one step closer on every axis, so it comes
    // earlier), the points on the source's planes in the octants on their + side, which
    // come first (every sign + before -).
    for (int octant = 0; octant < 8; ++octant)
    {
      int first[3], last[3], step[3];
      bool empty = false;
      for (int a = 0; a < 3; ++a)
      {
        const bool plus = ((octant >> (2 - a)) & 1) == 0; // z slowest: order (z, y, x)
        const int n = this->Dims[a];
        const int s = source.Point[a];
        first[a] = plus ? std::max(s, 0) : std::min(s - 1, n - 1);
        last[a] = plus ? n - 1 : 0;
        step[a] = plus ? 1 : -1;
        empty = empty || (plus ? first[a] > last[a] : first[a] < last[a]);
      }
      if (empty)
      {
        continue;
      }
      for (int k = first[2]; k != last[2] + step[2]; k += step[2])
      {
        for (int j = first[1]; j != last[1] + step[1]; j += step[1])
        {
          for (int i = first[0]; i != last[0] + step[0]; i += step[0])
          {
            this->Visit(i, j, k);
          }
        }
      }
    }
  }

private:
  std::size_t Index(int i, int j, int k) const
  {
    return (static_cast<std::size_t>(k) * this->Dims[1] + j) * this->Dims[0] + i;
  }

  // The mean extinction from the source and sigma at the point one step toward the source
  // from (i, j, k): on the layer `axis` +- 1, bilinear in the other two axes at the
  // fractional coordinates u, v. False when that point is outside the grid's box. (The mean
  // extinction tau / r, not tau, is interpolated: it is constant in a homogeneous medium,
  // where tau's growth with r would bend between the samples.)
  bool Layer(int axis, int layer, double u, double v, double& mean, double& sigma) const
  {
    const int b = (axis + 1) % 3, c = (axis + 2) % 3;
    if (layer < 0 || layer >= this->Dims[axis] || u < -1e-9 || v < -1e-9 ||
      u > this->Dims[b] - 1 + 1e-9 || v > this->Dims[c] - 1 + 1e-9)
    {
      return false;
    }
    u = std::clamp(u, 0.0, static_cast<double>(this->Dims[b] - 1));
    v = std::clamp(v, 0.0, static_cast<double>(this->Dims[c] - 1));
    const int u0 = std::min(static_cast<int>(u), std::max(0, this->Dims[b] - 2));
    const int v0 = std::min(static_cast<int>(v), std::max(0, this->Dims[c] - 2));
    const double fu = this->Dims[b] > 1 ? u - u0 : 0.0, fv = this->Dims[c] > 1 ? v - v0 : 0.0;
    std::array<int, 3> q;
    q[axis] = layer;
    const std::size_t strides[3] = { 1, static_cast<std::size_t>(this->Dims[0]),
      static_cast<std::size_t>(this->Dims[0]) * this->Dims[1] };
    q[b] = u0;
    q[c] = v0;
    const std::size_t i00 = q[0] * strides[0] + q[1] * strides[1] + q[2] * strides[2];
    const std::size_t du = fu > 0.0 ? strides[b] : 0, dv = fv > 0.0 ? strides[c] : 0;
    const float* m = this->MeanExtinction.data();
    const float* e = this->Grid.Extinction.data();
    const double w00 = (1 - fu) * (1 - fv), w10 = fu * (1 - fv), w01 = (1 - fu) * fv, w11 = fu * fv;
    mean = w00 * m[i00] + w10 * m[i00 + du] + w01 * m[i00 + dv] + w11 * m[i00 + du + dv];
    sigma = w00 * e[i00] + w10 * e[i00 + du] + w01 * e[i00 + dv] + w11 * e[i00 + du + dv];
    return true;
  }

  void Visit(int i, int j, int k)
  {
    const std::size_t index = this->Index(i, j, k);
    const std::array<int, 3>& s = this->Source->Point;
    const int d[3] = { s[0] - i, s[1] - j, s[2] - k };
    const int n = std::max({ std::abs(d[0]), std::abs(d[1]), std::abs(d[2]) });
    double tau = 0.0;
    if (n > 0)
    {
      // One step toward the source along the dominant axis (|d| = n there): the
      // predecessor lies in shell n - 1.
      const int axis = std::abs(d[0]) == n ? 0 : (std::abs(d[1]) == n ? 1 : 2);
      const int b = (axis + 1) % 3, c = (axis + 2) % 3;
      const int here[3] = { i, j, k };
      const double inverse = 1.0 / n;
      double meanBefore = 0.0, sigmaBefore = 0.0; // outside the box: 0 and 0
      this->Layer(axis, here[axis] + (d[axis] > 0 ? 1 : -1), here[b] + d[b] * inverse,
        here[c] + d[c] * inverse, meanBefore, sigmaBefore);
      const double step = this->StepLength(d, inverse); // [m]; the predecessor is n - 1 away
      tau = meanBefore * (n - 1) * step + 0.5 * (sigmaBefore + this->Grid.Extinction[index]) * step;
      this->MeanExtinction[index] = static_cast<float>(tau * inverse / step);
    }
    else
    {
      this->MeanExtinction[index] = 0.0f;
    }
    if (this->Reduced * tau < kOpaque && this->Wanted[index])
    {
      this->Add(index, i, j, k, n, this->Transmittance(tau));
    }
  }

  // T' = f exp(-tau) + (1 - f) exp(-(1 - f albedo) tau) (FirstScatteringForwardPeak).
  double Transmittance(double tau) const
  {
    const double plain = std::exp(-tau);
    return this->Peak > 0.0
      ? this->Peak * plain + (1.0 - this->Peak) * std::exp(-this->Reduced * tau)
      : plain;
  }

  double StepLength(const int d[3], double inverse) const
  {
    const double x = d[0] * inverse * this->Grid.Spacing[0];
    const double y = d[1] * inverse * this->Grid.Spacing[1];
    const double z = d[2] * inverse * this->Grid.Spacing[2];
    return std::sqrt(x * x + y * y + z * z);
  }

  // E and F of this source at point (i, j, k) with transmittance t.
  void Add(std::size_t index, int i, int j, int k, int n, double t)
  {
    double inverse2 = 0.0; // 1/r^2 [1/m^2]
    Vector3 flux{ { 0, 0, 0 } };
    if (n <= 1)
    {
      // The cell touches the source's: the average over it, transmittance included.
      this->CellAverage(i, j, k, this->Grid.Extinction[index], inverse2, flux);
      t = 1.0;
    }
    else
    {
      // In the grid's frame (its axes are orthonormal), F turned to world axes at the end.
      const double x = (i - this->CentreIndex[0]) * this->Grid.Spacing[0];
      const double y = (j - this->CentreIndex[1]) * this->Grid.Spacing[1];
      const double z = (k - this->CentreIndex[2]) * this->Grid.Spacing[2];
      const double r2 = x * x + y * y + z * z;
      inverse2 = 1.0 / r2;
      const double r3 = inverse2 / std::sqrt(r2);
      flux = { { x * r3, y * r3, z * r3 } };
      flux = this->ToWorld(flux);
    }
    const double e = this->Source->Intensity * t;
    double* out = &this->Sum[4 * index];
    out[0] += e * inverse2;
    out[1] += e * flux[0];
    out[2] += e * flux[1];
    out[3] += e * flux[2];
  }

  // The average over the point's cell (a box of one spacing per axis about it) of T/r^2
  // and of T w/r^2 from the source (CellAverage.h), the extinction taken as the point's,
  // constant from the source to the cell (the cells are the source's and its neighbours).
  void CellAverage(int i, int j, int k, double sigma, double& inverse2, Vector3& flux) const
  {
    const Vector3 centre = this->Grid.Position(i, j, k);
    const Vector3& c = this->Source->Centre;
    const Vector3 world{ { c[0] - centre[0], c[1] - centre[1], c[2] - centre[2] } };
    Vector3 origin, half;
    for (int a = 0; a < 3; ++a)
    {
      origin[a] = Dot(world, this->Grid.Axes[a]); // the source in the cell's frame [m]
      half[a] = 0.5 * this->Grid.Spacing[a];
    }
    BeamTransmittance beam;
    beam.Sigma = sigma;
    beam.PeakFraction = this->Peak;
    beam.Reduced = this->Reduced;
    const CellAverageOfSource average = AverageSourceOverCell(origin, half, beam);
    inverse2 = average.InverseSquare;
    flux = this->ToWorld(average.Flux);
  }

  Vector3 ToWorld(const Vector3& local) const
  {
    Vector3 world{ { 0, 0, 0 } };
    for (int a = 0; a < 3; ++a)
    {
      for (int c = 0; c < 3; ++c)
      {
        world[c] += local[a] * this->Grid.Axes[a][c];
      }
    }
    return world;
  }

  const ExtinctionGrid& Grid;
  const double Peak;                  // f
  const double Reduced;               // 1 - f albedo
  const std::vector<char>& Wanted;    // points whose E a renderer can use
  std::vector<float>& MeanExtinction; // tau / r from the source's grid point [1/m]
  Vector3 CentreIndex{ { 0, 0, 0 } }; // the source's centre in grid coordinates
  std::vector<double>& Sum;
  int Dims[3] = { 0, 0, 0 };
  const MergedSource* Source = nullptr;
};
} // namespace

std::string CheckFirstScatteringInput(const ExtinctionGrid& grid,
  const std::vector<ScalarPointSource>& sources, const FirstScatteringForwardPeak& peak)
{
  if (!(peak.Fraction >= 0.0 && peak.Fraction < 1.0) || !(peak.Albedo >= 0.0 && peak.Albedo <= 1.0))
  {
    return "the forward peak's fraction must be in [0, 1) and the albedo in [0, 1]";
  }
  CloudLighting none;
  none.HasSun = false;
  const std::string gridProblem =
    CheckMultipleScatteringInput(grid, CloudOptics(), none, MultipleScatteringOptions());
  if (!gridProblem.empty())
  {
    return gridProblem;
  }
  for (std::size_t k = 0; k < sources.size(); ++k)
  {
    if (!IsFinite(sources[k].Position) || !std::isfinite(sources[k].Intensity) ||
      sources[k].Intensity < 0.0)
    {
      std::ostringstream message;
      message << "point source " << k
              << " has a non-finite position or a negative or non-finite intensity";
      return message.str();
    }
  }
  return "";
}

FirstScatteringField ComputeFirstScattering(const ExtinctionGrid& grid,
  const std::vector<ScalarPointSource>& sources, int threads,
  const std::function<void(double)>& progress, const FirstScatteringForwardPeak& peak)
{
  const std::string problem = CheckFirstScatteringInput(grid, sources, peak);
  if (!problem.empty())
  {
    throw std::invalid_argument("nimbus::ComputeFirstScattering: " + problem);
  }
  const auto start = std::chrono::steady_clock::now();
  const std::vector<MergedSource> merged = MergeByGridPoint(grid, sources);
  const std::size_t n = grid.NumberOfPoints();
  FirstScatteringField field;
  field.Dimensions = grid.Dimensions;
  field.MergedSources = static_cast<int>(merged.size());

  // Each worker sums its share of the sources in its own buffer; batches of sources
  // between progress reports (on this thread, where the caller may stop the work).
  const std::vector<char> wanted = WantedPoints(grid);
  const std::size_t workers =
    std::max<std::size_t>(1, std::min<std::size_t>(ResolveThreadCount(threads), merged.size()));
  std::vector<std::vector<double>> sums(workers, std::vector<double>(4 * n, 0.0));
  std::vector<std::vector<float>> taus(workers, std::vector<float>(n, 0.0f));
  const std::size_t batch = 4 * workers;
  for (std::size_t first = 0; first < merged.size(); first += batch)
  {
    const std::size_t last = std::min(merged.size(), first + batch);
    ParallelFor(workers, 1, static_cast<int>(workers),
      [&](std::size_t begin, std::size_t end)
      {
        for (std::size_t w = begin; w < end; ++w)
        {
          SourcePass pass(grid, peak, wanted, taus[w], sums[w]);
          for (std::size_t s = first + w; s < last; s += workers)
          {
            pass.Run(merged[s]);
          }
        }
      });
    if (progress)
    {
      progress(static_cast<double>(last) / merged.size());
    }
  }
  field.Values.assign(4 * n, 0.0f);
  for (std::size_t i = 0; i < 4 * n; ++i)
  {
    double total = 0.0;
    for (const std::vector<double>& sum : sums)
    {
      total += sum[i];
    }
    field.Values[i] = static_cast<float>(total);
  }
  field.Seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return field;
}

FirstScatteringField CombineFirstScattering(
  const std::vector<const FirstScatteringField*>& fields, const std::vector<double>& weights)
{
  if (fields.size() != weights.size())
  {
    throw std::invalid_argument("nimbus::CombineFirstScattering: one weight per field");
  }
  FirstScatteringField out;
  if (fields.empty())
  {
    return out;
  }
  out.Dimensions = fields.front()->Dimensions;
  out.Values.assign(fields.front()->Values.size(), 0.0f);
  for (std::size_t f = 0; f < fields.size(); ++f)
  {
    if (fields[f]->Values.size() != out.Values.size() || fields[f]->Dimensions != out.Dimensions)
    {
      throw std::invalid_argument("nimbus::CombineFirstScattering: fields of different sizes");
    }
    const float w = static_cast<float>(weights[f]);
    for (std::size_t i = 0; i < out.Values.size(); ++i)
    {
      out.Values[i] += w * fields[f]->Values[i];
    }
    out.MergedSources += fields[f]->MergedSources;
    out.Seconds += fields[f]->Seconds;
  }
  return out;
}

double EvaluateFirstScattering(const float* values, const Vector3& w, double k1)
{
  const double e = values[0];
  const double f = values[1] * w[0] + values[2] * w[1] + values[3] * w[2];
  return std::max(0.0, (e + 3.0 * k1 * f) / (4.0 * kPi));
}

double DeltaMBeamMeanCosine(double plainE, double reducedE, double fraction, double peakLobeG)
{
  if (!(reducedE > 0.0) || !(fraction > 0.0) || !(peakLobeG > 0.0) || !std::isfinite(plainE))
  {
    return 1.0;
  }
  const double unscattered = std::max(plainE - (1.0 - fraction) * reducedE, 0.0) / fraction;
  const double ratio = std::min(unscattered / reducedE, 1.0);
  return std::pow(ratio, 1.0 - std::min(peakLobeG, 1.0));
}

} // namespace nimbus
