#include "SmokeSolver.h"

#include "ParallelFor.h"
#include "SmokePressure.h"

#include <Eigen/IterativeLinearSolvers>
#include <Eigen/SparseCore>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <thread>

namespace nimbus
{
namespace
{
constexpr std::size_t kMaxCells = std::size_t(1) << 27;

int ThreadCount(int requested)
{
  return requested > 0 ? requested
                       : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
}

// Runs body(k) for k in [first, last) (the layers of a grid), one layer per chunk;
// the body must write only the values of its own layer.
template <typename Body>
void ForLayers(int first, int last, int threads, const Body& body)
{
  if (last <= first)
  {
    return;
  }
  ParallelFor(static_cast<std::size_t>(last - first), 1, threads,
    [&](std::size_t begin, std::size_t end)
    {
      for (std::size_t k = begin; k < end; ++k)
      {
        body(first + static_cast<int>(k));
      }
    });
}

bool Finite(const Vector3& v)
{
  return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]);
}

// A field on the grid's samples: dims per axis and where sample (0, 0, 0) sits in cell
// coordinates (cell i's centre at i + 0.5): cell centres (0.5, 0.5, 0.5), u faces
// (0, 0.5, 0.5), v (0.5, 0, 0.5), w (0.5, 0.5, 0). With Open (the box's sides open), a
// layer of ghost samples holding Outside lies one sample beyond each end in x and y (the
// air outside: the wind's velocity component, no smoke, the ambient temperature), points
// farther out clamped to it; z is clamped to the samples as without.
struct FieldView
{
  const float* Data;
  std::array<int, 3> Dims;
  std::array<double, 3> Offset;
  bool Open = false;
  double Outside = 0.0;

  std::size_t Index(int a, int b, int c) const
  {
    return (static_cast<std::size_t>(c) * this->Dims[1] + b) * this->Dims[0] + a;
  }
  // Trilinear at position x (cell coordinates), clamped to the samples' box (with Open:
  // to the ghosts' in x and y).
  double Sample(const std::array<double, 3>& x) const
  {
    if (this->Open)
    {
      return this->SampleOpen(x);
    }
    int i0[3];
    double f[3];
    for (int k = 0; k < 3; ++k)
    {
      const double g =
        std::clamp(x[k] - this->Offset[k], 0.0, static_cast<double>(this->Dims[k] - 1));
      i0[k] = std::min(static_cast<int>(g), this->Dims[k] - 2 < 0 ? 0 : this->Dims[k] - 2);
      f[k] = g - i0[k];
      if (this->Dims[k] == 1)
      {
        i0[k] = 0;
        f[k] = 0.0;
      }
    }
    const int i1 = std::min(i0[0] + 1, this->Dims[0] - 1),
              j1 = std::min(i0[1] + 1, this->Dims[1] - 1),
              k1 = std::min(i0[2] + 1, this->Dims[2] - 1);
    const double c00 = (1 - f[0]) * this->Data[this->Index(i0[0], i0[1], i0[2])] +
      f[0] * this->Data[this->Index(i1, i0[1], i0[2])];
    const double c10 = (1 - f[0]) * this->Data[this->Index(i0[0], j1, i0[2])] +
      f[0] * this->Data[this->Index(i1, j1, i0[2])];
    const double c01 = (1 - f[0]) * this->Data[this->Index(i0[0], i0[1], k1)] +
      f[0] * this->Data[this->Index(i1, i0[1], k1)];
    const double c11 = (1 - f[0]) * this->Data[this->Index(i0[0], j1, k1)] +
      f[0] * this->Data[this->Index(i1, j1, k1)];
    const double c0 = (1 - f[1]) * c00 + f[1] * c10;
    const double c1 = (1 - f[1]) * c01 + f[1] * c11;
    return (1 - f[2]) * c0 + f[2] * c1;
  }
  // The smallest and largest of the 8 samples around x (MacCormack's clamp).
  void Range(const std::array<double, 3>& x, double& low, double& high) const
  {
    if (this->Open)
    {
      this->RangeOpen(x, low, high);
      return;
    }
    int i0[3];
    for (int k = 0; k < 3; ++k)
    {
      const double g =
        std::clamp(x[k] - this->Offset[k], 0.0, static_cast<double>(this->Dims[k] - 1));
      i0[k] = std::min(static_cast<int>(g), std::max(this->Dims[k] - 2, 0));
    }
    low = 1e300;
    high = -1e300;
    for (int c = 0; c < 2; ++c)
      for (int b = 0; b < 2; ++b)
        for (int a = 0; a < 2; ++a)
        {
          const double v = this->Data[this->Index(std::min(i0[0] + a, this->Dims[0] - 1),
            std::min(i0[1] + b, this->Dims[1] - 1), std::min(i0[2] + c, this->Dims[2] - 1))];
          low = std::min(low, v);
          high = std::max(high, v);
        }
  }

  // With Open: sample (a, b, c), Outside beyond the ends in x and y.
  double At(int a, int b, int c) const
  {
    if (a < 0 || a >= this->Dims[0] || b < 0 || b >= this->Dims[1])
    {
      return this->Outside;
    }
    return this->Data[this->Index(a, b, std::min(c, this->Dims[2] - 1))];
  }
  // With Open: the lower corner of the samples around x (x and y from -1, the ghosts,
  // to Dims - 1) and the weights of the upper ones.
  void LocateOpen(const std::array<double, 3>& x, int i0[3], double f[3]) const
  {
    for (int k = 0; k < 2; ++k)
    {
      const double g = std::clamp(x[k] - this->Offset[k], -1.0, static_cast<double>(this->Dims[k]));
      i0[k] = std::min(static_cast<int>(std::floor(g)), this->Dims[k] - 1);
      f[k] = g - i0[k];
    }
    const double g =
      std::clamp(x[2] - this->Offset[2], 0.0, static_cast<double>(this->Dims[2] - 1));
    i0[2] = std::min(static_cast<int>(g), std::max(this->Dims[2] - 2, 0));
    f[2] = this->Dims[2] == 1 ? 0.0 : g - i0[2];
  }
  double SampleOpen(const std::array<double, 3>& x) const
  {
    int i0[3];
    double f[3];
    this->LocateOpen(x, i0, f);
    const int i1 = i0[0] + 1, j1 = i0[1] + 1, k1 = i0[2] + 1;
    const double c00 =
      (1 - f[0]) * this->At(i0[0], i0[1], i0[2]) + f[0] * this->At(i1, i0[1], i0[2]);
    const double c10 = (1 - f[0]) * this->At(i0[0], j1, i0[2]) + f[0] * this->At(i1, j1, i0[2]);
    const double c01 = (1 - f[0]) * this->At(i0[0], i0[1], k1) + f[0] * this->At(i1, i0[1], k1);
    const double c11 = (1 - f[0]) * this->At(i0[0], j1, k1) + f[0] * this->At(i1, j1, k1);
    const double c0 = (1 - f[1]) * c00 + f[1] * c10;
    const double c1 = (1 - f[1]) * c01 + f[1] * c11;
    return (1 - f[2]) * c0 + f[2] * c1;
  }
  void RangeOpen(const std::array<double, 3>& x, double& low, double& high) const
  {
    int i0[3];
    double f[3];
    this->LocateOpen(x, i0, f);
    low = 1e300;
    high = -1e300;
    for (int c = 0; c < 2; ++c)
      for (int b = 0; b < 2; ++b)
        for (int a = 0; a < 2; ++a)
        {
          const double v = this->At(i0[0] + a, i0[1] + b, i0[2] + c);
          low = std::min(low, v);
          high = std::max(high, v);
        }
  }
};
} // namespace

std::string CheckSmokeParameters(const SmokeParameters& p)
{
  std::ostringstream why;
  std::size_t cells = 1;
  for (int k = 0; k < 3; ++k)
  {
    if (p.Dimensions[k] < 2 || p.Dimensions[k] > 1024)
    {
      why << "the grid needs 2 to 1024 cells per axis (" << p.Dimensions[0] << " x "
          << p.Dimensions[1] << " x " << p.Dimensions[2] << ")";
      return why.str();
    }
    cells *= static_cast<std::size_t>(p.Dimensions[k]);
  }
  if (cells > kMaxCells)
  {
    why << "the grid has " << cells << " cells, more than " << kMaxCells;
    return why.str();
  }
  if (!(p.CellSizeMetres > 0.0) || !std::isfinite(p.CellSizeMetres) || p.CellSizeMetres > 1e6)
  {
    return "the cell size must be in (0, 1e6] metres";
  }
  if (!Finite(p.Origin) || !Finite(p.Wind))
  {
    return "the origin and the wind must be finite";
  }
  const double nonNegative[] = { p.AmbientTemperatureKelvin, p.Gravity, p.DensityWeight,
    p.CoolingPerSecond, p.DissipationPerSecond, p.EddyViscosity, p.SmagorinskyConstant,
    p.VorticityConfinement, p.WindCoupling };
  const char* names[] = { "AmbientTemperatureKelvin", "Gravity", "DensityWeight",
    "CoolingPerSecond", "DissipationPerSecond", "EddyViscosity", "SmagorinskyConstant",
    "VorticityConfinement", "WindCoupling" };
  for (int k = 0; k < 9; ++k)
  {
    if (!(nonNegative[k] >= 0.0) || !std::isfinite(nonNegative[k]) || nonNegative[k] > 1e9)
    {
      why << names[k] << " must be finite, >= 0 and <= 1e9 (" << nonNegative[k] << ")";
      return why.str();
    }
  }
  if (!(p.AmbientTemperatureKelvin > 0.0))
  {
    return "AmbientTemperatureKelvin must be > 0";
  }
  if (!(p.MaxCfl > 0.0) || !std::isfinite(p.MaxCfl) || p.MaxCfl > 100.0)
  {
    return "MaxCfl must be in (0, 100]";
  }
  if (p.MaxSubsteps < 1 || p.MaxSubsteps > 100000)
  {
    return "MaxSubsteps must be in [1, 100000]";
  }
  if (!(p.PressureTolerance > 0.0) || p.PressureTolerance >= 1.0 || p.PressureMaxIterations < 1)
  {
    return "the pressure tolerance must be in (0, 1) and the iterations >= 1";
  }
  if (p.PressureSolver != SmokePressureSolver::Multigrid &&
    p.PressureSolver != SmokePressureSolver::IncompleteCholesky)
  {
    return "PressureSolver must be Multigrid or IncompleteCholesky";
  }
  if (p.SideBoundaries != SmokeSideBoundaries::Automatic &&
    p.SideBoundaries != SmokeSideBoundaries::Walls && p.SideBoundaries != SmokeSideBoundaries::Open)
  {
    return "SideBoundaries must be Automatic, Walls or Open";
  }
  for (std::size_t e = 0; e < p.Emitters.size(); ++e)
  {
    const SmokeEmitter& m = p.Emitters[e];
    if (!Finite(m.Centre) || !Finite(m.Velocity) || !(m.RadiusMetres > 0.0) ||
      !std::isfinite(m.RadiusMetres) || !(m.DensityPerSecond >= 0.0) ||
      !std::isfinite(m.DensityPerSecond) || !(m.TemperatureKelvin > 0.0) ||
      !std::isfinite(m.TemperatureKelvin))
    {
      why << "emitter " << e
          << ": the centre and velocity must be finite, the radius > 0, the rate >= 0 and the "
             "temperature > 0 K";
      return why.str();
    }
  }
  if (!p.Obstacles.empty())
  {
    if (p.Obstacles.size() != cells)
    {
      why << "the obstacle mask has " << p.Obstacles.size() << " values for " << cells << " cells";
      return why.str();
    }
    if (std::all_of(p.Obstacles.begin(), p.Obstacles.end(), [](std::uint8_t s) { return s != 0; }))
    {
      return "the obstacles cover every cell: there is no air to simulate";
    }
  }
  return "";
}

bool SmokeSidesOpen(const SmokeParameters& p)
{
  switch (p.SideBoundaries)
  {
    case SmokeSideBoundaries::Walls:
      return false;
    case SmokeSideBoundaries::Open:
      return true;
    default:
      return p.WindCoupling > 0.0 && Length(p.Wind) > 0.0;
  }
}

// The pressure equation on the fluid cells (see the file comment) and its solver, set
// up once: the multigrid hierarchy, or the matrix and its incomplete Cholesky factor.
struct SmokeSolver::Pressure
{
  std::vector<int> Unknown; // per cell: its row, or -1 (solid)
  int Rows = 0;
  std::unique_ptr<SmokePressure> Multigrid;
  Eigen::SparseMatrix<double> A;
  Eigen::ConjugateGradient<Eigen::SparseMatrix<double>, Eigen::Lower | Eigen::Upper,
    Eigen::IncompleteCholesky<double, Eigen::Lower, Eigen::NaturalOrdering<int>>>
    Cg;
  std::vector<double> Phi; // per cell (0 in solids): the last solution, the next guess
  std::vector<double> B;   // per cell: the right-hand side (scratch)
};

SmokeSolver::SmokeSolver(const SmokeParameters& parameters)
  : Parameters(parameters)
{
  const std::string why = CheckSmokeParameters(parameters);
  if (!why.empty())
  {
    throw std::invalid_argument("nimbus::SmokeSolver: " + why);
  }
  this->SidesOpen = SmokeSidesOpen(this->Parameters);
  const auto& n = this->Parameters.Dimensions;
  const std::size_t cells = this->NumberOfCells();
  this->Density.assign(cells, 0.0f);
  this->Temperature.assign(cells, static_cast<float>(this->Parameters.AmbientTemperatureKelvin));
  this->U.assign(static_cast<std::size_t>(n[0] + 1) * n[1] * n[2], 0.0f);
  this->V.assign(static_cast<std::size_t>(n[0]) * (n[1] + 1) * n[2], 0.0f);
  this->W.assign(static_cast<std::size_t>(n[0]) * n[1] * (n[2] + 1), 0.0f);
  this->Solid = this->Parameters.Obstacles.empty() ? std::vector<std::uint8_t>(cells, 0)
                                                   : this->Parameters.Obstacles;
  for (std::uint8_t& s : this->Solid)
  {
    s = s ? 1 : 0;
  }

  // The pressure matrix: per fluid cell, the number of non-solid neighbours (fluid, the
  // open top, open sides) on the diagonal, -1 per fluid neighbour.
  this->PressureSolver.reset(new Pressure);
  Pressure& ps = *this->PressureSolver;
  ps.Unknown.assign(cells, -1);
  int rows = 0;
  for (std::size_t c = 0; c < cells; ++c)
  {
    if (!this->Solid[c])
    {
      ps.Unknown[c] = rows++;
    }
  }
  ps.Rows = rows;
  ps.Phi.assign(cells, 0.0);
  ps.B.assign(cells, 0.0);
  if (this->Parameters.PressureSolver == SmokePressureSolver::Multigrid)
  {
    ps.Multigrid.reset(
      new SmokePressure(n, this->Solid, ThreadCount(this->Parameters.Threads), 2, this->SidesOpen));
    this->EnforceSolidFaces();
    return;
  }
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(static_cast<std::size_t>(rows) * 7);
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i)
      {
        const std::size_t c = this->CellIndex(i, j, k);
        const int row = ps.Unknown[c];
        if (row < 0)
        {
          continue;
        }
        double diagonal = 0.0;
        const int offsets[6][3] = { { -1, 0, 0 }, { 1, 0, 0 }, { 0, -1, 0 }, { 0, 1, 0 },
          { 0, 0, -1 }, { 0, 0, 1 } };
        for (const auto& o : offsets)
        {
          const int a = i + o[0], b = j + o[1], d = k + o[2];
          if (d == n[2])
          {
            diagonal += 1.0; // the open top: pressure 0 beyond it
            continue;
          }
          if (a < 0 || a >= n[0] || b < 0 || b >= n[1] || d < 0)
          {
            if (this->SidesOpen && d >= 0)
            {
              diagonal += 1.0; // an open side: pressure 0 beyond it
            }
            continue; // else a wall
          }
          const int neighbour = ps.Unknown[this->CellIndex(a, b, d)];
          if (neighbour >= 0)
          {
            diagonal += 1.0;
            entries.emplace_back(row, neighbour, -1.0);
          }
        }
        // A cell with no open neighbour at all (enclosed by obstacles) gets a diagonal
        // of 1 so the matrix stays definite; its right-hand side is 0, so its pressure.
        entries.emplace_back(row, row, diagonal > 0.0 ? diagonal : 1.0);
      }
  ps.A.resize(rows, rows);
  ps.A.setFromTriplets(entries.begin(), entries.end());
  ps.Cg.setTolerance(this->Parameters.PressureTolerance);
  ps.Cg.setMaxIterations(this->Parameters.PressureMaxIterations);
  ps.Cg.compute(ps.A);
  this->EnforceSolidFaces();
}

SmokeSolver::~SmokeSolver() = default;

std::size_t SmokeSolver::NumberOfCells() const
{
  const auto& n = this->Parameters.Dimensions;
  return static_cast<std::size_t>(n[0]) * n[1] * n[2];
}

void SmokeSolver::EnforceSolidFaces()
{
  const auto& n = this->Parameters.Dimensions;
  const auto solid = [&](int i, int j, int k)
  { return this->Solid[this->CellIndex(i, j, k)] != 0; };
  // The side faces: walls (zeroed), or open (free unless their cell is solid).
  const bool walls = !this->SidesOpen;
  ForLayers(0, n[2], ThreadCount(this->Parameters.Threads),
    [&](int k)
    {
      for (int j = 0; j < n[1]; ++j)
        for (int i = 0; i <= n[0]; ++i)
        {
          const bool closed = i == 0 ? walls || solid(0, j, k)
            : i == n[0]              ? walls || solid(n[0] - 1, j, k)
                                     : solid(i - 1, j, k) || solid(i, j, k);
          if (closed)
          {
            this->U[(static_cast<std::size_t>(k) * n[1] + j) * (n[0] + 1) + i] = 0.0f;
          }
        }
    });
  ForLayers(0, n[2], ThreadCount(this->Parameters.Threads),
    [&](int k)
    {
      for (int j = 0; j <= n[1]; ++j)
        for (int i = 0; i < n[0]; ++i)
        {
          const bool closed = j == 0 ? walls || solid(i, 0, k)
            : j == n[1]              ? walls || solid(i, n[1] - 1, k)
                                     : solid(i, j - 1, k) || solid(i, j, k);
          if (closed)
          {
            this->V[(static_cast<std::size_t>(k) * (n[1] + 1) + j) * n[0] + i] = 0.0f;
          }
        }
    });
  ForLayers(0, n[2] + 1, ThreadCount(this->Parameters.Threads),
    [&](int k)
    {
      for (int j = 0; j < n[1]; ++j)
        for (int i = 0; i < n[0]; ++i)
        {
          // The bottom is a wall; the top is open (only a solid cell below closes it).
          if (k == 0 || (k < n[2] && solid(i, j, k)) || solid(i, j, k - 1))
          {
            this->W[(static_cast<std::size_t>(k) * n[1] + j) * n[0] + i] = 0.0f;
          }
        }
    });
}

double SmokeSolver::MaxSpeed() const
{
  double speed = 0.0;
  for (const std::vector<float>* f : { &this->U, &this->V, &this->W })
  {
    for (float x : *f)
    {
      speed = std::max(speed, static_cast<double>(std::abs(x)));
    }
  }
  for (const SmokeEmitter& e : this->Parameters.Emitters)
  {
    speed = std::max(speed, Length(e.Velocity));
  }
  return speed;
}

SmokeStepReport SmokeSolver::Step(double dt)
{
  if (!(dt > 0.0) || !std::isfinite(dt) || dt > 1e6)
  {
    throw std::invalid_argument("nimbus::SmokeSolver::Step: dt must be in (0, 1e6] seconds");
  }
  const double h = this->Parameters.CellSizeMetres;
  // Sub-steps by the CFL number: a sample travels at most MaxCfl cells per sub-step.
  const double cells = dt * this->MaxSpeed() / h;
  const int substeps = std::max(1, static_cast<int>(std::ceil(cells / this->Parameters.MaxCfl)));
  if (substeps > this->Parameters.MaxSubsteps)
  {
    std::ostringstream why;
    why << "nimbus::SmokeSolver::Step: dt = " << dt << " s would need " << substeps
        << " sub-steps (the flow crosses " << cells << " cells), more than MaxSubsteps "
        << this->Parameters.MaxSubsteps;
    throw std::runtime_error(why.str());
  }
  // The state before, restored if a value becomes non-finite.
  const std::vector<float> density = this->Density, temperature = this->Temperature, u = this->U,
                           v = this->V, w = this->W;
  const double time = this->Time;
  SmokeStepReport report;
  report.Substeps = substeps;
  for (int s = 0; s < substeps; ++s)
  {
    this->Substep(dt / substeps, report);
  }
  bool finite = true;
  for (const std::vector<float>* f :
    { &this->Density, &this->Temperature, &this->U, &this->V, &this->W })
  {
    for (float x : *f)
    {
      finite = finite && std::isfinite(x);
    }
  }
  if (!finite)
  {
    this->Density = density;
    this->Temperature = temperature;
    this->U = u;
    this->V = v;
    this->W = w;
    this->Time = time;
    throw std::runtime_error("nimbus::SmokeSolver::Step: the flow became non-finite; the step "
                             "was undone (lower dt or the emitters' speeds)");
  }
  report.MaxSpeed = this->MaxSpeed();
  return report;
}

void SmokeSolver::Substep(double dt, SmokeStepReport& report)
{
  this->Emit(dt);
  this->Advect(dt);
  this->Decay(dt);
  this->AddForces(dt);
  this->Diffuse(dt);
  this->Project(dt, report);
  this->Time += dt;
}

void SmokeSolver::Emit(double dt)
{
  const auto& n = this->Parameters.Dimensions;
  const double h = this->Parameters.CellSizeMetres;
  const Vector3& o = this->Parameters.Origin;
  for (const SmokeEmitter& e : this->Parameters.Emitters)
  {
    const double r2 = e.RadiusMetres * e.RadiusMetres;
    const auto inside = [&](double x, double y, double z)
    {
      const double dx = o[0] + h * x - e.Centre[0], dy = o[1] + h * y - e.Centre[1],
                   dz = o[2] + h * z - e.Centre[2];
      return dx * dx + dy * dy + dz * dz <= r2;
    };
    for (int k = 0; k < n[2]; ++k)
      for (int j = 0; j < n[1]; ++j)
        for (int i = 0; i < n[0]; ++i)
        {
          const std::size_t c = this->CellIndex(i, j, k);
          if (!this->Solid[c] && inside(i + 0.5, j + 0.5, k + 0.5))
          {
            this->Density[c] += static_cast<float>(e.DensityPerSecond * dt);
            this->Temperature[c] =
              std::max(this->Temperature[c], static_cast<float>(e.TemperatureKelvin));
          }
        }
    if (!(Length(e.Velocity) > 0.0))
    {
      continue; // no velocity of its own: the air around carries the smoke
    }
    for (int k = 0; k < n[2]; ++k)
      for (int j = 0; j < n[1]; ++j)
        for (int i = 1; i < n[0]; ++i)
        {
          if (inside(i, j + 0.5, k + 0.5))
          {
            this->U[(static_cast<std::size_t>(k) * n[1] + j) * (n[0] + 1) + i] =
              static_cast<float>(e.Velocity[0]);
          }
        }
    for (int k = 0; k < n[2]; ++k)
      for (int j = 1; j < n[1]; ++j)
        for (int i = 0; i < n[0]; ++i)
        {
          if (inside(i + 0.5, j, k + 0.5))
          {
            this->V[(static_cast<std::size_t>(k) * (n[1] + 1) + j) * n[0] + i] =
              static_cast<float>(e.Velocity[1]);
          }
        }
    for (int k = 1; k <= n[2]; ++k)
      for (int j = 0; j < n[1]; ++j)
        for (int i = 0; i < n[0]; ++i)
        {
          if (inside(i + 0.5, j + 0.5, k))
          {
            this->W[(static_cast<std::size_t>(k) * n[1] + j) * n[0] + i] =
              static_cast<float>(e.Velocity[2]);
          }
        }
  }
  this->EnforceSolidFaces();
}

void SmokeSolver::AddForces(double dt)
{
  const SmokeParameters& p = this->Parameters;
  const auto& n = p.Dimensions;
  const double h = p.CellSizeMetres;
  // Buoyancy (Boussinesq) on the interior and top w faces: the mean of the cells on
  // either side (the top face: its cell alone).
  ForLayers(1, n[2] + 1, ThreadCount(this->Parameters.Threads),
    [&](int k)
    {
      for (int j = 0; j < n[1]; ++j)
        for (int i = 0; i < n[0]; ++i)
        {
          const std::size_t below = this->CellIndex(i, j, k - 1);
          const std::size_t above = k < n[2] ? this->CellIndex(i, j, k) : below;
          const double t = 0.5 * (this->Temperature[below] + this->Temperature[above]);
          const double rho = 0.5 * (this->Density[below] + this->Density[above]);
          const double a = p.Gravity *
            ((t - p.AmbientTemperatureKelvin) / p.AmbientTemperatureKelvin - p.DensityWeight * rho);
          this->W[(static_cast<std::size_t>(k) * n[1] + j) * n[0] + i] +=
            static_cast<float>(a * dt);
        }
    });
  // Wind: a drag toward the wind's velocity.
  if (p.WindCoupling > 0.0)
  {
    const float keep = static_cast<float>(std::exp(-p.WindCoupling * dt));
    std::vector<float>* fields[3] = { &this->U, &this->V, &this->W };
    for (int a = 0; a < 3; ++a)
    {
      const float target = static_cast<float>(p.Wind[a]);
      for (float& x : *fields[a])
      {
        x = target + (x - target) * keep;
      }
    }
  }
  // Vorticity confinement: f = eps h (N x omega), N = grad|omega| / |grad|omega||.
  if (p.VorticityConfinement > 0.0)
  {
    const std::vector<float> velocity = this->CellVelocities();
    const std::size_t cells = this->NumberOfCells();
    std::vector<double> omega(3 * cells, 0.0), magnitude(cells, 0.0);
    const auto vel = [&](int i, int j, int k, int a)
    {
      i = std::clamp(i, 0, n[0] - 1);
      j = std::clamp(j, 0, n[1] - 1);
      k = std::clamp(k, 0, n[2] - 1);
      return static_cast<double>(velocity[3 * this->CellIndex(i, j, k) + a]);
    };
    ForLayers(0, n[2], ThreadCount(this->Parameters.Threads),
      [&](int k)
      {
        for (int j = 0; j < n[1]; ++j)
          for (int i = 0; i < n[0]; ++i)
          {
            const std::size_t c = this->CellIndex(i, j, k);
            const double dwdy = (vel(i, j + 1, k, 2) - vel(i, j - 1, k, 2)) / (2 * h);
            const double dvdz = (vel(i, j, k + 1, 1) - vel(i, j, k - 1, 1)) / (2 * h);
            const double dudz = (vel(i, j, k + 1, 0) - vel(i, j, k - 1, 0)) / (2 * h);
            const double dwdx = (vel(i + 1, j, k, 2) - vel(i - 1, j, k, 2)) / (2 * h);
            const double dvdx = (vel(i + 1, j, k, 1) - vel(i - 1, j, k, 1)) / (2 * h);
            const double dudy = (vel(i, j + 1, k, 0) - vel(i, j - 1, k, 0)) / (2 * h);
            omega[3 * c] = dwdy - dvdz;
            omega[3 * c + 1] = dudz - dwdx;
            omega[3 * c + 2] = dvdx - dudy;
            magnitude[c] = std::sqrt(omega[3 * c] * omega[3 * c] +
              omega[3 * c + 1] * omega[3 * c + 1] + omega[3 * c + 2] * omega[3 * c + 2]);
          }
      });
    std::vector<double> force(3 * cells, 0.0);
    const auto mag = [&](int i, int j, int k)
    {
      return magnitude[this->CellIndex(
        std::clamp(i, 0, n[0] - 1), std::clamp(j, 0, n[1] - 1), std::clamp(k, 0, n[2] - 1))];
    };
    ForLayers(0, n[2], ThreadCount(this->Parameters.Threads),
      [&](int k)
      {
        for (int j = 0; j < n[1]; ++j)
          for (int i = 0; i < n[0]; ++i)
          {
            const std::size_t c = this->CellIndex(i, j, k);
            double g[3] = { (mag(i + 1, j, k) - mag(i - 1, j, k)) / (2 * h),
              (mag(i, j + 1, k) - mag(i, j - 1, k)) / (2 * h),
              (mag(i, j, k + 1) - mag(i, j, k - 1)) / (2 * h) };
            const double length = std::sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
            if (!(length > 1e-20))
            {
              continue;
            }
            for (double& x : g)
            {
              x /= length;
            }
            const double* w = &omega[3 * c];
            const double scale = p.VorticityConfinement * h;
            force[3 * c] = scale * (g[1] * w[2] - g[2] * w[1]);
            force[3 * c + 1] = scale * (g[2] * w[0] - g[0] * w[2]);
            force[3 * c + 2] = scale * (g[0] * w[1] - g[1] * w[0]);
          }
      });
    ForLayers(0, n[2], ThreadCount(this->Parameters.Threads),
      [&](int k)
      {
        for (int j = 0; j < n[1]; ++j)
          for (int i = 1; i < n[0]; ++i)
          {
            this->U[(static_cast<std::size_t>(k) * n[1] + j) * (n[0] + 1) + i] +=
              static_cast<float>(0.5 * dt *
                (force[3 * this->CellIndex(i - 1, j, k)] + force[3 * this->CellIndex(i, j, k)]));
          }
      });
    ForLayers(0, n[2], ThreadCount(this->Parameters.Threads),
      [&](int k)
      {
        for (int j = 1; j < n[1]; ++j)
          for (int i = 0; i < n[0]; ++i)
          {
            this->V[(static_cast<std::size_t>(k) * (n[1] + 1) + j) * n[0] + i] +=
              static_cast<float>(0.5 * dt *
                (force[3 * this->CellIndex(i, j - 1, k) + 1] +
                  force[3 * this->CellIndex(i, j, k) + 1]));
          }
      });
    ForLayers(1, n[2], ThreadCount(this->Parameters.Threads),
      [&](int k)
      {
        for (int j = 0; j < n[1]; ++j)
          for (int i = 0; i < n[0]; ++i)
          {
            this->W[(static_cast<std::size_t>(k) * n[1] + j) * n[0] + i] +=
              static_cast<float>(0.5 * dt *
                (force[3 * this->CellIndex(i, j, k - 1) + 2] +
                  force[3 * this->CellIndex(i, j, k) + 2]));
          }
      });
  }
  this->EnforceSolidFaces();
}

void SmokeSolver::Diffuse(double dt)
{
  const SmokeParameters& p = this->Parameters;
  if (p.EddyViscosity <= 0.0 && p.SmagorinskyConstant <= 0.0)
  {
    return;
  }
  const auto& n = p.Dimensions;
  const double h = p.CellSizeMetres;
  const std::size_t cells = this->NumberOfCells();
  // nu_t per cell: constant, or Smagorinsky's (C_s h)^2 |S| with |S| = sqrt(2 S_ij S_ij).
  std::vector<double> nu(cells, p.EddyViscosity);
  if (p.SmagorinskyConstant > 0.0)
  {
    const std::vector<float> velocity = this->CellVelocities();
    const auto vel = [&](int i, int j, int k, int a)
    {
      return static_cast<double>(velocity[3 *
          this->CellIndex(
            std::clamp(i, 0, n[0] - 1), std::clamp(j, 0, n[1] - 1), std::clamp(k, 0, n[2] - 1)) +
        a]);
    };
    const double cs = p.SmagorinskyConstant * h;
    ForLayers(0, n[2], ThreadCount(this->Parameters.Threads),
      [&](int k)
      {
        for (int j = 0; j < n[1]; ++j)
          for (int i = 0; i < n[0]; ++i)
          {
            double grad[3][3];
            for (int a = 0; a < 3; ++a)
            {
              grad[a][0] = (vel(i + 1, j, k, a) - vel(i - 1, j, k, a)) / (2 * h);
              grad[a][1] = (vel(i, j + 1, k, a) - vel(i, j - 1, k, a)) / (2 * h);
              grad[a][2] = (vel(i, j, k + 1, a) - vel(i, j, k - 1, a)) / (2 * h);
            }
            double s2 = 0.0;
            for (int a = 0; a < 3; ++a)
              for (int b = 0; b < 3; ++b)
              {
                const double s = 0.5 * (grad[a][b] + grad[b][a]);
                s2 += s * s;
              }
            nu[this->CellIndex(i, j, k)] = cs * cs * std::sqrt(2.0 * s2);
          }
      });
  }
  const double largest = *std::max_element(nu.begin(), nu.end());
  if (!(largest > 0.0))
  {
    return;
  }
  // Explicit, sub-stepped so that nu dt / h^2 <= 1/6 (stable).
  const int steps = std::max(1, static_cast<int>(std::ceil(6.0 * largest * dt / (h * h))));
  const double tau = dt / steps;
  struct Face
  {
    std::vector<float>* Field;
    std::array<int, 3> Dims;
  };
  const Face faces[3] = { { &this->U, { { n[0] + 1, n[1], n[2] } } },
    { &this->V, { { n[0], n[1] + 1, n[2] } } }, { &this->W, { { n[0], n[1], n[2] + 1 } } } };
  for (int s = 0; s < steps; ++s)
  {
    for (int a = 0; a < 3; ++a)
    {
      const std::vector<float> old = *faces[a].Field;
      const auto& d = faces[a].Dims;
      const auto at = [&](int i, int j, int k)
      {
        return old[(static_cast<std::size_t>(std::clamp(k, 0, d[2] - 1)) * d[1] +
                     std::clamp(j, 0, d[1] - 1)) *
            d[0] +
          std::clamp(i, 0, d[0] - 1)];
      };
      ForLayers(0, d[2], ThreadCount(this->Parameters.Threads),
        [&](int k)
        {
          for (int j = 0; j < d[1]; ++j)
            for (int i = 0; i < d[0]; ++i)
            {
              // nu at the face: the nearest cell's.
              const int ci = std::min(i, n[0] - 1), cj = std::min(j, n[1] - 1),
                        ck = std::min(k, n[2] - 1);
              const double viscosity = nu[this->CellIndex(ci, cj, ck)];
              const double laplacian =
                (at(i + 1, j, k) + at(i - 1, j, k) + at(i, j + 1, k) + at(i, j - 1, k) +
                  at(i, j, k + 1) + at(i, j, k - 1) - 6.0 * at(i, j, k)) /
                (h * h);
              (*faces[a].Field)[(static_cast<std::size_t>(k) * d[1] + j) * d[0] + i] =
                static_cast<float>(at(i, j, k) + tau * viscosity * laplacian);
            }
        });
    }
    this->EnforceSolidFaces();
  }
}

void SmokeSolver::Project(double, SmokeStepReport& report)
{
  const auto& n = this->Parameters.Dimensions;
  const double h = this->Parameters.CellSizeMetres;
  const int threads = ThreadCount(this->Parameters.Threads);
  Pressure& ps = *this->PressureSolver;
  const std::vector<double> divergence = this->Divergence();
  double before = 0.0;
  int fluid = 0;
  for (std::size_t c = 0; c < divergence.size(); ++c)
  {
    ps.B[c] = -h * h * divergence[c]; // 0 in solid cells
    if (ps.Unknown[c] >= 0)
    {
      before += divergence[c] * divergence[c];
      ++fluid;
    }
  }
  report.DivergenceBefore = std::sqrt(before / std::max(fluid, 1));
  if (before > 0.0 && ps.Multigrid)
  {
    const SmokePressure::Result result = ps.Multigrid->Solve(
      ps.B, ps.Phi, this->Parameters.PressureTolerance, this->Parameters.PressureMaxIterations);
    report.PressureIterations = result.Iterations;
    report.PressureResidual = result.Residual;
  }
  else if (before > 0.0)
  {
    Eigen::VectorXd b(ps.Rows), guess(ps.Rows);
    for (std::size_t c = 0; c < divergence.size(); ++c)
    {
      if (ps.Unknown[c] >= 0)
      {
        b[ps.Unknown[c]] = ps.B[c];
        guess[ps.Unknown[c]] = ps.Phi[c];
      }
    }
    const Eigen::VectorXd phi = ps.Cg.solveWithGuess(b, guess);
    for (std::size_t c = 0; c < divergence.size(); ++c)
    {
      ps.Phi[c] = ps.Unknown[c] >= 0 ? phi[ps.Unknown[c]] : 0.0;
    }
    report.PressureIterations = static_cast<int>(ps.Cg.iterations());
    report.PressureResidual = ps.Cg.error();
  }
  else
  {
    std::fill(ps.Phi.begin(), ps.Phi.end(), 0.0);
    report.PressureIterations = 0;
    report.PressureResidual = 0.0;
  }
  const double* phi = ps.Phi.data(); // 0 in solid cells
  const std::size_t nxy = static_cast<std::size_t>(n[0]) * n[1];
  // u -= grad phi on the faces between two fluid cells, on the open top and on open
  // sides (pressure 0 beyond them; faces next to a solid are zeroed below); each layer of
  // faces written by one thread.
  const bool open = this->SidesOpen;
  ParallelFor(static_cast<std::size_t>(n[2]) + 1, 1, threads,
    [&](std::size_t begin, std::size_t end)
    {
      for (std::size_t kk = begin; kk < end; ++kk)
      {
        const int k = static_cast<int>(kk);
        for (int j = 0; j < n[1] && k < n[2]; ++j)
        {
          const std::size_t c0 =
            static_cast<std::size_t>(k) * nxy + static_cast<std::size_t>(j) * n[0];
          float* u = &this->U[(static_cast<std::size_t>(k) * n[1] + j) * (n[0] + 1)];
          for (int i = 1; i < n[0]; ++i)
          {
            u[i] -= static_cast<float>((phi[c0 + i] - phi[c0 + i - 1]) / h);
          }
          if (open)
          {
            u[0] -= static_cast<float>(phi[c0] / h);
            u[n[0]] += static_cast<float>(phi[c0 + n[0] - 1] / h);
          }
        }
        for (int j = 1; j < n[1] && k < n[2]; ++j)
        {
          const std::size_t c0 =
            static_cast<std::size_t>(k) * nxy + static_cast<std::size_t>(j) * n[0];
          float* v = &this->V[(static_cast<std::size_t>(k) * (n[1] + 1) + j) * n[0]];
          for (int i = 0; i < n[0]; ++i)
          {
            v[i] -= static_cast<float>((phi[c0 + i] - phi[c0 + i - n[0]]) / h);
          }
        }
        if (open && k < n[2])
        {
          // The first and last rows of v faces: pressure 0 beyond them.
          const std::size_t first = static_cast<std::size_t>(k) * nxy;
          const std::size_t last = first + static_cast<std::size_t>(n[1] - 1) * n[0];
          float* v0 = &this->V[static_cast<std::size_t>(k) * (n[1] + 1) * n[0]];
          float* v1 = v0 + static_cast<std::size_t>(n[1]) * n[0];
          for (int i = 0; i < n[0]; ++i)
          {
            v0[i] -= static_cast<float>(phi[first + i] / h);
            v1[i] += static_cast<float>(phi[last + i] / h);
          }
        }
        if (k >= 1)
        {
          for (int j = 0; j < n[1]; ++j)
          {
            const std::size_t c0 =
              static_cast<std::size_t>(k - 1) * nxy + static_cast<std::size_t>(j) * n[0];
            float* w = &this->W[(static_cast<std::size_t>(k) * n[1] + j) * n[0]];
            for (int i = 0; i < n[0]; ++i)
            {
              const double above = k < n[2] ? phi[c0 + nxy + i] : 0.0;
              w[i] -= static_cast<float>((above - phi[c0 + i]) / h);
            }
          }
        }
      }
    });
  this->EnforceSolidFaces();
  const std::vector<double> after = this->Divergence();
  double sum = 0.0;
  for (std::size_t c = 0; c < after.size(); ++c)
  {
    sum += after[c] * after[c];
  }
  report.DivergenceAfter = std::sqrt(sum / std::max(fluid, 1));
}

void SmokeSolver::Advect(double dt)
{
  const SmokeParameters& p = this->Parameters;
  const auto& n = p.Dimensions;
  const double h = p.CellSizeMetres;
  // The velocity the samples move with: this (projected) one, in cells per second; with
  // open sides, beyond them the wind's.
  const bool open = this->SidesOpen;
  const std::vector<float> u = this->U, v = this->V, w = this->W;
  const FieldView uView{ u.data(), { { n[0] + 1, n[1], n[2] } }, { { 0.0, 0.5, 0.5 } }, open,
    p.Wind[0] };
  const FieldView vView{ v.data(), { { n[0], n[1] + 1, n[2] } }, { { 0.5, 0.0, 0.5 } }, open,
    p.Wind[1] };
  const FieldView wView{ w.data(), { { n[0], n[1], n[2] + 1 } }, { { 0.5, 0.5, 0.0 } }, open,
    p.Wind[2] };
  const auto velocity = [&](const std::array<double, 3>& x)
  {
    return std::array<double, 3>{ { uView.Sample(x) / h, vView.Sample(x) / h,
      wView.Sample(x) / h } };
  };
  // Second-order backtrace (midpoint) over `step` seconds (negative: forward).
  const auto backtrace = [&](const std::array<double, 3>& x, double step)
  {
    const auto v0 = velocity(x);
    const std::array<double, 3> mid{ { x[0] - 0.5 * step * v0[0], x[1] - 0.5 * step * v0[1],
      x[2] - 0.5 * step * v0[2] } };
    const auto v1 = velocity(mid);
    return std::array<double, 3>{ { x[0] - step * v1[0], x[1] - step * v1[1],
      x[2] - step * v1[2] } };
  };
  const int threads = ThreadCount(p.Threads);
  // Advects the fields that share one layout of samples (dims, offset) together: each
  // backtrace is computed once for all of them, and MacCormack's clamp reuses the
  // first pass's (the same numbers as tracing each field on its own). outside: per
  // field, its value in the air beyond open sides (the inflow).
  const auto advect = [&](const std::vector<std::vector<float>*>& fields,
                        const std::array<int, 3>& dims, const std::array<double, 3>& offset,
                        const std::vector<double>& outside)
  {
    const std::size_t count = fields.size();
    std::vector<std::vector<float>> old(count), forward(count);
    for (std::size_t f = 0; f < count; ++f)
    {
      old[f] = *fields[f];
      forward[f].resize(old[f].size());
    }
    const FieldView layout{ nullptr, dims, offset, false, 0.0 };
    const std::size_t rows = static_cast<std::size_t>(dims[1]) * dims[2];
    const bool mac = p.Advection == SmokeAdvection::MacCormack;
    // Where each sample came from (MacCormack's clamp needs it again).
    std::vector<std::array<double, 3>> from(mac ? old[0].size() : 0);
    // Semi-Lagrangian pass.
    ParallelFor(rows, 4, threads,
      [&](std::size_t begin, std::size_t end)
      {
        for (std::size_t r = begin; r < end; ++r)
        {
          const int j = static_cast<int>(r % dims[1]), k = static_cast<int>(r / dims[1]);
          for (int i = 0; i < dims[0]; ++i)
          {
            const std::array<double, 3> x{ { i + offset[0], j + offset[1], k + offset[2] } };
            const std::array<double, 3> y = backtrace(x, dt);
            const std::size_t index = layout.Index(i, j, k);
            for (std::size_t f = 0; f < count; ++f)
            {
              const FieldView oldView{ old[f].data(), dims, offset, open, outside[f] };
              forward[f][index] = static_cast<float>(oldView.Sample(y));
            }
            if (mac)
            {
              from[index] = y;
            }
          }
        }
      });
    if (!mac)
    {
      for (std::size_t f = 0; f < count; ++f)
      {
        fields[f]->swap(forward[f]);
      }
      return;
    }
    // MacCormack: back again, half the error corrected, clamped to the neighbourhood of
    // the backtraced point (else the semi-Lagrangian value).
    ParallelFor(rows, 4, threads,
      [&](std::size_t begin, std::size_t end)
      {
        for (std::size_t r = begin; r < end; ++r)
        {
          const int j = static_cast<int>(r % dims[1]), k = static_cast<int>(r / dims[1]);
          for (int i = 0; i < dims[0]; ++i)
          {
            const std::array<double, 3> x{ { i + offset[0], j + offset[1], k + offset[2] } };
            const std::size_t index = layout.Index(i, j, k);
            const std::array<double, 3> y = backtrace(x, -dt);
            for (std::size_t f = 0; f < count; ++f)
            {
              const FieldView oldView{ old[f].data(), dims, offset, open, outside[f] };
              const FieldView forwardView{ forward[f].data(), dims, offset, open, outside[f] };
              const double back = forwardView.Sample(y);
              double value = forward[f][index] + 0.5 * (old[f][index] - back);
              double low, high;
              oldView.Range(from[index], low, high);
              if (value < low || value > high)
              {
                value = forward[f][index];
              }
              (*fields[f])[index] = static_cast<float>(value);
            }
          }
        }
      });
  };
  advect({ &this->U }, { { n[0] + 1, n[1], n[2] } }, { { 0.0, 0.5, 0.5 } }, { p.Wind[0] });
  advect({ &this->V }, { { n[0], n[1] + 1, n[2] } }, { { 0.5, 0.0, 0.5 } }, { p.Wind[1] });
  advect({ &this->W }, { { n[0], n[1], n[2] + 1 } }, { { 0.5, 0.5, 0.0 } }, { p.Wind[2] });
  // Beyond open sides: no smoke, the ambient temperature.
  advect({ &this->Density, &this->Temperature }, { { n[0], n[1], n[2] } }, { { 0.5, 0.5, 0.5 } },
    { 0.0, p.AmbientTemperatureKelvin });
  for (std::size_t c = 0; c < this->Solid.size(); ++c)
  {
    if (this->Solid[c])
    {
      this->Density[c] = 0.0f;
      this->Temperature[c] = static_cast<float>(p.AmbientTemperatureKelvin);
    }
  }
  this->EnforceSolidFaces();
}

void SmokeSolver::Decay(double dt)
{
  const SmokeParameters& p = this->Parameters;
  const float cool = static_cast<float>(std::exp(-p.CoolingPerSecond * dt));
  const float fade = static_cast<float>(std::exp(-p.DissipationPerSecond * dt));
  const float ambient = static_cast<float>(p.AmbientTemperatureKelvin);
  for (std::size_t c = 0; c < this->Density.size(); ++c)
  {
    this->Temperature[c] = ambient + (this->Temperature[c] - ambient) * cool;
    this->Density[c] = std::max(0.0f, this->Density[c] * fade);
  }
}

Vector3 SmokeSolver::VelocityAt(const Vector3& positionMetres) const
{
  const SmokeParameters& p = this->Parameters;
  const auto& n = p.Dimensions;
  std::array<double, 3> x;
  for (int a = 0; a < 3; ++a)
  {
    if (std::isnan(positionMetres[a]))
    {
      throw std::invalid_argument("nimbus::SmokeSolver::VelocityAt: the position is NaN");
    }
    x[a] = (positionMetres[a] - p.Origin[a]) / p.CellSizeMetres; // cell coordinates
  }
  // The same views of the faces as Advect's, clamped (no wind beyond open sides).
  const FieldView uView{ this->U.data(), { { n[0] + 1, n[1], n[2] } }, { { 0.0, 0.5, 0.5 } }, false,
    0.0 };
  const FieldView vView{ this->V.data(), { { n[0], n[1] + 1, n[2] } }, { { 0.5, 0.0, 0.5 } }, false,
    0.0 };
  const FieldView wView{ this->W.data(), { { n[0], n[1], n[2] + 1 } }, { { 0.5, 0.5, 0.0 } }, false,
    0.0 };
  return { { uView.Sample(x), vView.Sample(x), wView.Sample(x) } };
}

std::vector<float> SmokeSolver::CellVelocities() const
{
  const auto& n = this->Parameters.Dimensions;
  std::vector<float> out(3 * this->NumberOfCells());
  ForLayers(0, n[2], ThreadCount(this->Parameters.Threads),
    [&](int k)
    {
      for (int j = 0; j < n[1]; ++j)
        for (int i = 0; i < n[0]; ++i)
        {
          const std::size_t c = this->CellIndex(i, j, k);
          const std::size_t u0 = (static_cast<std::size_t>(k) * n[1] + j) * (n[0] + 1) + i;
          const std::size_t v0 = (static_cast<std::size_t>(k) * (n[1] + 1) + j) * n[0] + i;
          const std::size_t w0 = (static_cast<std::size_t>(k) * n[1] + j) * n[0] + i;
          out[3 * c] = 0.5f * (this->U[u0] + this->U[u0 + 1]);
          out[3 * c + 1] = 0.5f * (this->V[v0] + this->V[v0 + n[0]]);
          out[3 * c + 2] =
            0.5f * (this->W[w0] + this->W[w0 + static_cast<std::size_t>(n[0]) * n[1]]);
        }
    });
  return out;
}

std::vector<double> SmokeSolver::Divergence() const
{
  const auto& n = this->Parameters.Dimensions;
  const double h = this->Parameters.CellSizeMetres;
  std::vector<double> out(this->NumberOfCells(), 0.0);
  ParallelFor(static_cast<std::size_t>(n[2]), 1, ThreadCount(this->Parameters.Threads),
    [&](std::size_t begin, std::size_t end)
    {
      for (int k = static_cast<int>(begin); k < static_cast<int>(end); ++k)
        for (int j = 0; j < n[1]; ++j)
          for (int i = 0; i < n[0]; ++i)
          {
            const std::size_t c = this->CellIndex(i, j, k);
            if (this->Solid[c])
            {
              continue;
            }
            const std::size_t u0 = (static_cast<std::size_t>(k) * n[1] + j) * (n[0] + 1) + i;
            const std::size_t v0 = (static_cast<std::size_t>(k) * (n[1] + 1) + j) * n[0] + i;
            const std::size_t w0 = (static_cast<std::size_t>(k) * n[1] + j) * n[0] + i;
            out[c] =
              (static_cast<double>(this->U[u0 + 1]) - this->U[u0] + this->V[v0 + n[0]] -
                this->V[v0] + this->W[w0 + static_cast<std::size_t>(n[0]) * n[1]] - this->W[w0]) /
              h;
          }
    });
  return out;
}

double SmokeSolver::TotalSmoke() const
{
  double sum = 0.0;
  for (float d : this->Density)
  {
    sum += d;
  }
  const double h = this->Parameters.CellSizeMetres;
  return sum * h * h * h;
}

std::vector<double> SmokeSolver::GetPressureGuess() const
{
  // One value per fluid cell, in cell order (the rows of the pressure equation).
  const Pressure& ps = *this->PressureSolver;
  std::vector<double> guess(static_cast<std::size_t>(ps.Rows));
  for (std::size_t c = 0; c < ps.Unknown.size(); ++c)
  {
    if (ps.Unknown[c] >= 0)
    {
      guess[static_cast<std::size_t>(ps.Unknown[c])] = ps.Phi[c];
    }
  }
  return guess;
}

void SmokeSolver::SetPressureGuess(const std::vector<double>& guess)
{
  Pressure& ps = *this->PressureSolver;
  if (guess.size() != static_cast<std::size_t>(ps.Rows))
  {
    throw std::invalid_argument("nimbus::SmokeSolver::SetPressureGuess: size does not match");
  }
  for (std::size_t c = 0; c < ps.Unknown.size(); ++c)
  {
    ps.Phi[c] = ps.Unknown[c] >= 0 ? guess[static_cast<std::size_t>(ps.Unknown[c])] : 0.0;
  }
}

void SmokeSolver::SetState(double time, const std::vector<float>& density,
  const std::vector<float>& temperature, const std::vector<float>& u, const std::vector<float>& v,
  const std::vector<float>& w)
{
  if (density.size() != this->Density.size() || temperature.size() != this->Temperature.size() ||
    u.size() != this->U.size() || v.size() != this->V.size() || w.size() != this->W.size() ||
    !std::isfinite(time))
  {
    throw std::invalid_argument("nimbus::SmokeSolver::SetState: sizes do not match the grid");
  }
  this->Time = time;
  this->Density = density;
  this->Temperature = temperature;
  this->U = u;
  this->V = v;
  this->W = w;
  this->EnforceSolidFaces();
}

} // namespace nimbus
