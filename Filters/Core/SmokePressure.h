// The smoke solver's pressure solve (SmokeSolver.h, step 4): Poisson's equation on the
// fluid cells of a grid with a solid mask, solved by conjugate gradients preconditioned
// with one geometric multigrid V-cycle (MGPCG, McAdams, Sifakis & Teran 2010, "A
// parallel multigrid Poisson solver for fluids simulation on large grids"). Plain C++,
// no VTK, no Eigen.
//
// The matrix (level 0): per fluid cell, the number of non-solid neighbours (fluid, or
// the open top beyond the last layer: pressure 0 there; with open sides, also the air
// beyond the first and last x and y columns: pressure 0 there too) on the diagonal, -1
// per fluid neighbour; the bottom wall, the side walls (when the sides are not open) and
// solid cells close their faces (Neumann). A fluid cell with no open neighbour at all
// gets a diagonal of 1. (An open face adds 1 to the diagonal and no coupling, so level
// 0's codes hold it as they hold the open top: a diagonal of at most 6.)
//
// The hierarchy: each coarse cell aggregates the 2 x 2 x 2 cells below it (fewer on the
// last layer of an odd axis); it is fluid when any of them is. The coarse matrix is
// half the Galerkin product P^T A P of the piecewise-constant prolongation P: the
// coupling of two coarse cells is half the sum of the fine couplings across their
// interface, the open faces' (top and open sides) likewise: a coarse cell's open
// coupling is half the sum of its children's (so obstacles, the open top and the open
// sides carry to every level exactly; the half is the scale of a Laplacian on cells
// twice as large). The
// V-cycle: red-black Gauss-Seidel (red then black) before the restriction (R = P^T),
// black then red after the prolongation, the same number of sweeps each side, and the
// coarsest level (at most ~100 cells) smoothed to convergence by a symmetric sequence of
// sweeps: the preconditioner is symmetric positive definite, as CG needs.
//
// Stopping rule (Eigen's ConjugateGradient's): the relative residual ||b - A x|| / ||b||
// (2-norm) below the tolerance, or the iteration cap; started from the given x.
//
// Threads: every value is written by one thread; sums are taken per z-layer and added
// in layer order; the decomposition does not depend on the thread count, so the result
// is bit-identical for any number of threads.
#ifndef nimbus_SmokePressure_h
#define nimbus_SmokePressure_h

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace nimbus
{

class SmokePressure
{
public:
  /// dims: cells per axis (each >= 1), x fastest; solid: one byte per cell (non-zero:
  /// solid) or empty (all fluid). threads: as ParallelFor's (0: hardware concurrency).
  /// openSides: the x and y faces of the box are open (pressure 0 beyond them) instead
  /// of walls; the top is always open, the bottom always a wall.
  SmokePressure(const std::array<int, 3>& dims, const std::vector<std::uint8_t>& solid,
    int threads = 0, int smoothingSweeps = 2, bool openSides = false);

  struct Result
  {
    int Iterations = 0;
    double Residual = 0.0; // ||b - A x|| / ||b||, 0 when b is 0
  };

  /// Solves A x = b on the fluid cells (arrays over all cells; b's solid entries are
  /// ignored, x's are set to 0); x is the first guess on entry, the solution on exit.
  Result Solve(const std::vector<double>& b, std::vector<double>& x, double tolerance,
    int maxIterations) const;

  /// y = A x (solid entries of y: 0).
  void Apply(const std::vector<double>& x, std::vector<double>& y) const;

  /// One V-cycle: z = M^-1 r (for tests: M^-1 must be symmetric).
  void Precondition(const std::vector<double>& r, std::vector<double>& z) const;

  std::size_t NumberOfLevels() const { return this->Levels.size(); }
  std::array<int, 3> LevelDimensions(std::size_t level) const { return this->Levels[level].Dims; }

private:
  struct Level
  {
    std::array<int, 3> Dims{ { 0, 0, 0 } };
    std::size_t Cells = 0;
    // Per cell: the diagonal, its inverse (0 for solid cells), the couplings to the +x,
    // +y and +z neighbours (0 across walls, to solids and out of the grid).
    std::vector<double> Diagonal, InverseDiagonal;
    std::vector<float> Cx, Cy, Cz;
    // Level 0 (Unit): every coupling between two fluid cells is 1 and the solver's
    // vectors are 0 on solid cells, so a cell needs only its diagonal: Code 0 (solid),
    // 1 to 6 (the diagonal), 7 (shut in: diagonal 1); Cx, Cy, Cz are then left empty
    // (a third of the memory traffic of the smoothing).
    bool Unit = false;
    std::vector<std::uint8_t> Code;
    // Scratch for the V-cycle: right-hand side, correction, A times the correction.
    mutable std::vector<double> B, X, R;
    int Threads = 1; // 1 on the small levels (no thread start-up cost)
  };

  void VCycle(std::size_t level) const;
  double ApplyLayer(const Level& l, int k, const double* x, double* y) const;
  void Sweep(const Level& l, const double* b, double* x, int colour) const;

  std::vector<Level> Levels;
  int SmoothingSweeps = 2;
  int CoarsestSweeps = 30;
  mutable std::vector<double> P, Q;    // CG scratch
  mutable std::vector<double> Partial; // per z-layer sums
  std::vector<double> Zero;            // a row of zeros (beyond the walls)
};

} // namespace nimbus

#endif
