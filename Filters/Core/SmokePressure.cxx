#include "SmokePressure.h"

#include "ParallelFor.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace nimbus
{
namespace
{
// Levels with fewer cells run on the calling thread only (a thread's start costs more).
constexpr std::size_t kParallelCells = 65536;
// Coarsening stops at this many cells (the coarsest level, smoothed to convergence).
constexpr std::size_t kCoarsestCells = 100;
// Level 0's diagonal and its inverse by the cell's code (SmokePressure::Level::Code).
// (A fluid cell shut in on every side has the diagonal 1: code 1.)
constexpr double kUnitDiagonal[8] = { 0, 1, 2, 3, 4, 5, 6, 0 };
constexpr double kUnitInverse[8] = { 0, 1, 1.0 / 2, 1.0 / 3, 1.0 / 4, 1.0 / 5, 1.0 / 6, 0 };

// Runs body(k) for every z-layer k of a level (layers handed out one at a time).
template <typename Body>
void ForLayers(int layers, int threads, const Body& body)
{
  if (threads <= 1 || layers <= 1)
  {
    for (int k = 0; k < layers; ++k)
    {
      body(k);
    }
    return;
  }
  ParallelFor(static_cast<std::size_t>(layers), 1, threads,
    [&](std::size_t begin, std::size_t end)
    {
      for (std::size_t k = begin; k < end; ++k)
      {
        body(static_cast<int>(k));
      }
    });
}

// start + the coupled neighbours of cell c = (i, j, k) on a level with couplings per face
// (cx[c]: the face toward +x of cell c; cy, cz likewise), added in a fixed order (the
// operator and the smoother give the same sums whatever the thread).
inline double AddNeighbours(double start, const float* cx, const float* cy, const float* cz,
  const double* x, std::size_t c, int i, int nx, std::size_t nxy, bool south, bool north, bool down,
  bool up)
{
  double s = start;
  if (i + 1 < nx)
  {
    s += cx[c] * x[c + 1];
  }
  if (i > 0)
  {
    s += cx[c - 1] * x[c - 1];
  }
  if (north)
  {
    s += cy[c] * x[c + nx];
  }
  if (south)
  {
    s += cy[c - nx] * x[c - nx];
  }
  if (up)
  {
    s += cz[c] * x[c + nxy];
  }
  if (down)
  {
    s += cz[c - nxy] * x[c - nxy];
  }
  return s;
}

// The sum of per-layer partial sums, in layer order (independent of the threads).
double SumInOrder(const std::vector<double>& partial, int layers)
{
  double sum = 0.0;
  for (int k = 0; k < layers; ++k)
  {
    sum += partial[static_cast<std::size_t>(k)];
  }
  return sum;
}
} // namespace

SmokePressure::SmokePressure(const std::array<int, 3>& dims, const std::vector<std::uint8_t>& solid,
  int threads, int smoothingSweeps, bool openSides)
  : SmoothingSweeps(std::max(1, smoothingSweeps))
{
  for (int a = 0; a < 3; ++a)
  {
    if (dims[a] < 1)
    {
      throw std::invalid_argument("nimbus::SmokePressure: dimensions must be >= 1");
    }
  }
  const std::size_t cells = static_cast<std::size_t>(dims[0]) * dims[1] * dims[2];
  if (!solid.empty() && solid.size() != cells)
  {
    throw std::invalid_argument("nimbus::SmokePressure: the solid mask's size does not match");
  }
  const int resolved = ResolveThreadCount(threads);

  // Level 0: couplings 1 between fluid neighbours, the open top 1, each open side 1.
  std::vector<double> open; // per cell of the current level: the open faces' coupling
  std::vector<std::uint8_t> fluidMask(cells, 1); // per cell of the current level
  for (std::size_t c = 0; c < cells && !solid.empty(); ++c)
  {
    fluidMask[c] = solid[c] == 0 ? 1 : 0;
  }
  {
    Level l;
    l.Dims = dims;
    l.Cells = cells;
    const int nx = dims[0], ny = dims[1], nz = dims[2];
    const auto fluid = [&](std::size_t c) { return solid.empty() || solid[c] == 0; };
    l.Cx.assign(cells, 0.0f);
    l.Cy.assign(cells, 0.0f);
    l.Cz.assign(cells, 0.0f);
    open.assign(cells, 0.0);
    for (int k = 0; k < nz; ++k)
      for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i)
        {
          const std::size_t c = (static_cast<std::size_t>(k) * ny + j) * nx + i;
          if (!fluid(c))
          {
            continue;
          }
          if (i + 1 < nx && fluid(c + 1))
          {
            l.Cx[c] = 1.0f;
          }
          if (j + 1 < ny && fluid(c + nx))
          {
            l.Cy[c] = 1.0f;
          }
          if (k + 1 < nz)
          {
            if (fluid(c + static_cast<std::size_t>(nx) * ny))
            {
              l.Cz[c] = 1.0f;
            }
          }
          else
          {
            open[c] = 1.0;
          }
          if (openSides)
          {
            // Pressure 0 beyond the first and last columns in x and y.
            open[c] += (i == 0 ? 1.0 : 0.0) + (i + 1 == nx ? 1.0 : 0.0) + (j == 0 ? 1.0 : 0.0) +
              (j + 1 == ny ? 1.0 : 0.0);
          }
        }
    this->Levels.push_back(std::move(l));
  }

  for (;;)
  {
    Level& l = this->Levels.back();
    const int nx = l.Dims[0], ny = l.Dims[1], nz = l.Dims[2];
    const std::size_t nxy = static_cast<std::size_t>(nx) * ny;
    // The diagonal: the sum of the couplings and the open faces (1 when none: a cell shut
    // in on every side; 0 for a solid cell, whose couplings are all 0 too); a coarse
    // cell is solid when all its children are.
    l.Diagonal.assign(l.Cells, 0.0);
    l.InverseDiagonal.assign(l.Cells, 0.0);
    for (int k = 0; k < nz; ++k)
      for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i)
        {
          const std::size_t c = (static_cast<std::size_t>(k) * ny + j) * nx + i;
          double d = open[c] + l.Cx[c] + l.Cy[c] + l.Cz[c];
          d += i > 0 ? l.Cx[c - 1] : 0.0f;
          d += j > 0 ? l.Cy[c - nx] : 0.0f;
          d += k > 0 ? l.Cz[c - nxy] : 0.0f;
          l.Diagonal[c] = !fluidMask[c] ? 0.0 : (d > 0.0 ? d : 1.0);
          l.InverseDiagonal[c] = l.Diagonal[c] > 0.0 ? 1.0 / l.Diagonal[c] : 0.0;
        }
    l.Threads = l.Cells >= kParallelCells ? resolved : 1;
    l.B.assign(l.Cells, 0.0);
    l.X.assign(l.Cells, 0.0);
    l.R.assign(l.Cells, 0.0);
    if (l.Cells <= kCoarsestCells)
    {
      break;
    }

    // The next level: half the Galerkin product of the aggregation.
    Level c;
    c.Dims = { { (nx + 1) / 2, (ny + 1) / 2, (nz + 1) / 2 } };
    c.Cells = static_cast<std::size_t>(c.Dims[0]) * c.Dims[1] * c.Dims[2];
    c.Cx.assign(c.Cells, 0.0f);
    c.Cy.assign(c.Cells, 0.0f);
    c.Cz.assign(c.Cells, 0.0f);
    std::vector<double> coarseOpen(c.Cells, 0.0);
    std::vector<std::uint8_t> coarseFluid(c.Cells, 0); // any child fluid
    for (int k = 0; k < nz; ++k)
      for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i)
        {
          const std::size_t f = (static_cast<std::size_t>(k) * ny + j) * nx + i;
          const std::size_t p =
            (static_cast<std::size_t>(k / 2) * c.Dims[1] + j / 2) * c.Dims[0] + i / 2;
          coarseFluid[p] = static_cast<std::uint8_t>(coarseFluid[p] | fluidMask[f]);
          coarseOpen[p] += 0.5 * open[f];
          // The fine couplings across a coarse interface: from an odd index to the next.
          if (i % 2 == 1)
          {
            c.Cx[p] += 0.5f * l.Cx[f];
          }
          if (j % 2 == 1)
          {
            c.Cy[p] += 0.5f * l.Cy[f];
          }
          if (k % 2 == 1)
          {
            c.Cz[p] += 0.5f * l.Cz[f];
          }
        }
    open.swap(coarseOpen);
    fluidMask.swap(coarseFluid);
    this->Levels.push_back(std::move(c));
  }
  // Level 0 by codes (see Level::Unit).
  {
    Level& l = this->Levels[0];
    l.Unit = true;
    l.Code.assign(l.Cells, 0);
    for (std::size_t c = 0; c < l.Cells; ++c)
    {
      l.Code[c] = static_cast<std::uint8_t>(l.Diagonal[c]); // 0 (solid) to 6
    }
    l.InverseDiagonal = std::vector<double>(); // kUnitInverse by code instead
    l.Cx = std::vector<float>();
    l.Cy = std::vector<float>();
    l.Cz = std::vector<float>();
  }
  const std::size_t fine = this->Levels[0].Cells;
  this->Zero.assign(static_cast<std::size_t>(dims[0]), 0.0);
  this->P.assign(fine, 0.0);
  this->Q.assign(fine, 0.0);
  this->Partial.assign(static_cast<std::size_t>(dims[2]), 0.0);
}

// y = A x over z-layer k of level l; returns sum(x y) over the layer.
double SmokePressure::ApplyLayer(const Level& l, int k, const double* x, double* y) const
{
  const int nx = l.Dims[0], ny = l.Dims[1], nz = l.Dims[2];
  const std::size_t nxy = static_cast<std::size_t>(nx) * ny;
  const float* cxs = l.Cx.data();
  const float* cys = l.Cy.data();
  const float* czs = l.Cz.data();
  const double* diagonal = l.Diagonal.data();
  const bool down = k > 0, up = k + 1 < nz;
  double sum = 0.0;
  if (l.Unit)
  {
    // Neighbours beyond the walls read a row of zeros; solids hold 0 already.
    const double* zero = this->Zero.data();
    for (int j = 0; j < ny; ++j)
    {
      const std::size_t row = (static_cast<std::size_t>(k) * ny + j) * nx;
      const double* xc = x + row;
      const double* xs = j > 0 ? xc - nx : zero;
      const double* xn = j + 1 < ny ? xc + nx : zero;
      const double* xd = down ? xc - nxy : zero;
      const double* xu = up ? xc + nxy : zero;
      const std::uint8_t* code = l.Code.data() + row;
      double* yc = y + row;
      for (int i = 0; i < nx; ++i)
      {
        const double left = i > 0 ? xc[i - 1] : 0.0;
        const double right = i + 1 < nx ? xc[i + 1] : 0.0;
        const double v =
          kUnitDiagonal[code[i]] * xc[i] - (left + right + xs[i] + xn[i] + xd[i] + xu[i]);
        yc[i] = code[i] ? v : 0.0;
        sum += xc[i] * yc[i];
      }
    }
    return sum;
  }
  for (int j = 0; j < ny; ++j)
  {
    const std::size_t row = (static_cast<std::size_t>(k) * ny + j) * nx;
    const bool south = j > 0, north = j + 1 < ny;
    for (int i = 0; i < nx; ++i)
    {
      const std::size_t c = row + i;
      const double s = AddNeighbours(0.0, cxs, cys, czs, x, c, i, nx, nxy, south, north, down, up);
      y[c] = diagonal[c] * x[c] - s;
      sum += x[c] * y[c];
    }
  }
  return sum;
}

void SmokePressure::Apply(const std::vector<double>& x, std::vector<double>& y) const
{
  const Level& l = this->Levels[0];
  if (x.size() != l.Cells)
  {
    throw std::invalid_argument("nimbus::SmokePressure::Apply: size does not match");
  }
  y.assign(l.Cells, 0.0);
  ForLayers(l.Dims[2], l.Threads, [&](int k) { this->ApplyLayer(l, k, x.data(), y.data()); });
}

// One Gauss-Seidel half-sweep over the cells of one colour ((i + j + k) % 2): each cell
// takes the value that zeroes its residual given its neighbours (of the other colour).
void SmokePressure::Sweep(const Level& l, const double* b, double* x, int colour) const
{
  const int nx = l.Dims[0], ny = l.Dims[1], nz = l.Dims[2];
  const std::size_t nxy = static_cast<std::size_t>(nx) * ny;
  const float* cxs = l.Cx.data();
  const float* cys = l.Cy.data();
  const float* czs = l.Cz.data();
  const double* inv = l.InverseDiagonal.data();
  if (l.Unit)
  {
    const double* zero = this->Zero.data();
    ForLayers(nz, l.Threads,
      [&](int k)
      {
        for (int j = 0; j < ny; ++j)
        {
          const std::size_t row = (static_cast<std::size_t>(k) * ny + j) * nx;
          double* xc = x + row;
          const double* bc = b + row;
          const double* xs = j > 0 ? xc - nx : zero;
          const double* xn = j + 1 < ny ? xc + nx : zero;
          const double* xd = k > 0 ? xc - nxy : zero;
          const double* xu = k + 1 < nz ? xc + nxy : zero;
          const std::uint8_t* code = l.Code.data() + row;
          const auto cell = [&](int i, double left, double right) {
            xc[i] = kUnitInverse[code[i]] * (bc[i] + left + right + xs[i] + xn[i] + xd[i] + xu[i]);
          };
          int i = (colour + j + k) & 1;
          if (i == 0)
          {
            cell(0, 0.0, nx > 1 ? xc[1] : 0.0);
            i = 2;
          }
          for (; i + 1 < nx; i += 2)
          {
            cell(i, xc[i - 1], xc[i + 1]);
          }
          if (i == nx - 1)
          {
            cell(i, xc[i - 1], 0.0);
          }
        }
      });
    return;
  }
  ForLayers(nz, l.Threads,
    [&](int k)
    {
      const bool down = k > 0, up = k + 1 < nz;
      for (int j = 0; j < ny; ++j)
      {
        const std::size_t row = (static_cast<std::size_t>(k) * ny + j) * nx;
        const bool south = j > 0, north = j + 1 < ny;
        for (int i = (colour + j + k) & 1; i < nx; i += 2)
        {
          const std::size_t c = row + i;
          const double s =
            AddNeighbours(b[c], cxs, cys, czs, x, c, i, nx, nxy, south, north, down, up);
          x[c] = inv[c] * s;
        }
      }
    });
}

// The V-cycle on level `level`: X = M^-1 B (X starts at 0).
void SmokePressure::VCycle(std::size_t level) const
{
  const Level& l = this->Levels[level];
  const double* b = l.B.data();
  double* x = l.X.data();
  std::fill(l.X.begin(), l.X.end(), 0.0);
  if (level + 1 == this->Levels.size())
  {
    // The coarsest level: forward sweeps, then as many backward ones (symmetric).
    for (int s = 0; s < this->CoarsestSweeps; ++s)
    {
      this->Sweep(l, b, x, 0);
      this->Sweep(l, b, x, 1);
    }
    for (int s = 0; s < this->CoarsestSweeps; ++s)
    {
      this->Sweep(l, b, x, 1);
      this->Sweep(l, b, x, 0);
    }
    return;
  }
  for (int s = 0; s < this->SmoothingSweeps; ++s)
  {
    this->Sweep(l, b, x, 0);
    this->Sweep(l, b, x, 1);
  }
  // The residual, summed over each coarse cell's children (R = P^T); each coarse layer
  // written by one thread.
  const Level& c = this->Levels[level + 1];
  const int nx = l.Dims[0], ny = l.Dims[1], nz = l.Dims[2];
  const int cx = c.Dims[0], cy = c.Dims[1];
  const std::size_t nxy = static_cast<std::size_t>(nx) * ny;
  double* cb = c.B.data();
  double* r = l.R.data();
  ForLayers(c.Dims[2], l.Threads,
    [&](int K)
    {
      double* layer = cb + static_cast<std::size_t>(K) * cx * cy;
      std::fill(layer, layer + static_cast<std::size_t>(cx) * cy, 0.0);
      for (int k = 2 * K; k < std::min(2 * K + 2, nz); ++k)
      {
        this->ApplyLayer(l, k, x, r);
        for (int j = 0; j < ny; ++j)
        {
          const std::size_t row =
            static_cast<std::size_t>(k) * nxy + static_cast<std::size_t>(j) * nx;
          double* coarseRow = layer + static_cast<std::size_t>(j / 2) * cx;
          for (int i = 0; i < nx; ++i)
          {
            const std::size_t f = row + i;
            coarseRow[i / 2] += l.Diagonal[f] > 0.0 ? b[f] - r[f] : 0.0;
          }
        }
      }
    });
  this->VCycle(level + 1);
  // Prolongation (piecewise constant) onto the fluid cells.
  const double* xc = c.X.data();
  ForLayers(nz, l.Threads,
    [&](int k)
    {
      for (int j = 0; j < ny; ++j)
      {
        const std::size_t row =
          static_cast<std::size_t>(k) * nxy + static_cast<std::size_t>(j) * nx;
        const double* coarseRow = xc + (static_cast<std::size_t>(k / 2) * cy + j / 2) * cx;
        for (int i = 0; i < nx; ++i)
        {
          if (l.Diagonal[row + i] > 0.0)
          {
            x[row + i] += coarseRow[i / 2];
          }
        }
      }
    });
  for (int s = 0; s < this->SmoothingSweeps; ++s)
  {
    this->Sweep(l, b, x, 1);
    this->Sweep(l, b, x, 0);
  }
}

void SmokePressure::Precondition(const std::vector<double>& r, std::vector<double>& z) const
{
  const Level& l = this->Levels[0];
  if (r.size() != l.Cells)
  {
    throw std::invalid_argument("nimbus::SmokePressure::Precondition: size does not match");
  }
  for (std::size_t c = 0; c < l.Cells; ++c)
  {
    l.B[c] = l.Diagonal[c] > 0.0 ? r[c] : 0.0;
  }
  this->VCycle(0);
  z = l.X;
}

SmokePressure::Result SmokePressure::Solve(
  const std::vector<double>& b, std::vector<double>& x, double tolerance, int maxIterations) const
{
  const Level& l = this->Levels[0];
  if (b.size() != l.Cells || x.size() != l.Cells)
  {
    throw std::invalid_argument("nimbus::SmokePressure::Solve: sizes do not match the grid");
  }
  const int nz = l.Dims[2];
  const std::size_t nxy = static_cast<std::size_t>(l.Dims[0]) * l.Dims[1];
  const int threads = l.Threads;
  double* partial = this->Partial.data();
  double* xs = x.data();
  double* r = l.B.data(); // the residual is the V-cycle's right-hand side
  double* z = l.X.data(); // and its result the preconditioned residual
  double* p = this->P.data();
  double* q = this->Q.data();
  const double* bs = b.data();
  const double* diagonal = l.Diagonal.data();
  const auto sum = [&]() { return SumInOrder(this->Partial, nz); };

  // x: 0 on solid cells; r = b - A x; ||b||^2.
  std::vector<double> bNorm(static_cast<std::size_t>(nz), 0.0);
  ForLayers(nz, threads,
    [&](int k)
    {
      const std::size_t begin = static_cast<std::size_t>(k) * nxy, end = begin + nxy;
      for (std::size_t c = begin; c < end; ++c)
      {
        if (!(diagonal[c] > 0.0))
        {
          xs[c] = 0.0;
        }
      }
    });
  ForLayers(nz, threads,
    [&](int k)
    {
      this->ApplyLayer(l, k, xs, q);
      const std::size_t begin = static_cast<std::size_t>(k) * nxy, end = begin + nxy;
      double rr = 0.0, bb = 0.0;
      for (std::size_t c = begin; c < end; ++c)
      {
        const double bc = diagonal[c] > 0.0 ? bs[c] : 0.0;
        r[c] = bc - q[c];
        rr += r[c] * r[c];
        bb += bc * bc;
      }
      partial[k] = rr;
      bNorm[static_cast<std::size_t>(k)] = bb;
    });
  Result result;
  const double rhsNorm2 = SumInOrder(bNorm, nz);
  if (rhsNorm2 == 0.0)
  {
    std::fill(x.begin(), x.end(), 0.0);
    return result;
  }
  const double threshold = tolerance * tolerance * rhsNorm2;
  double residualNorm2 = sum();
  if (residualNorm2 < threshold)
  {
    result.Residual = std::sqrt(residualNorm2 / rhsNorm2);
    return result;
  }
  this->VCycle(0); // z = M^-1 r
  ForLayers(nz, threads,
    [&](int k)
    {
      const std::size_t begin = static_cast<std::size_t>(k) * nxy, end = begin + nxy;
      double rz = 0.0;
      for (std::size_t c = begin; c < end; ++c)
      {
        p[c] = z[c];
        rz += r[c] * z[c];
      }
      partial[k] = rz;
    });
  double absNew = sum();
  int iteration = 0;
  while (iteration < maxIterations)
  {
    ForLayers(nz, threads, [&](int k) { partial[k] = this->ApplyLayer(l, k, p, q); });
    const double pq = sum();
    if (!(pq > 0.0))
    {
      break; // nothing left to reduce (a direction A does not see)
    }
    const double alpha = absNew / pq;
    ForLayers(nz, threads,
      [&](int k)
      {
        const std::size_t begin = static_cast<std::size_t>(k) * nxy, end = begin + nxy;
        double rr = 0.0;
        for (std::size_t c = begin; c < end; ++c)
        {
          xs[c] += alpha * p[c];
          r[c] -= alpha * q[c];
          rr += r[c] * r[c];
        }
        partial[k] = rr;
      });
    residualNorm2 = sum();
    ++iteration;
    if (residualNorm2 < threshold)
    {
      break;
    }
    this->VCycle(0);
    ForLayers(nz, threads,
      [&](int k)
      {
        const std::size_t begin = static_cast<std::size_t>(k) * nxy, end = begin + nxy;
        double rz = 0.0;
        for (std::size_t c = begin; c < end; ++c)
        {
          rz += r[c] * z[c];
        }
        partial[k] = rz;
      });
    const double absOld = absNew;
    absNew = sum();
    const double beta = absNew / absOld;
    ForLayers(nz, threads,
      [&](int k)
      {
        const std::size_t begin = static_cast<std::size_t>(k) * nxy, end = begin + nxy;
        for (std::size_t c = begin; c < end; ++c)
        {
          p[c] = z[c] + beta * p[c];
        }
      });
  }
  result.Iterations = iteration;
  result.Residual = std::sqrt(residualNorm2 / rhsNorm2);
  return result;
}

} // namespace nimbus
