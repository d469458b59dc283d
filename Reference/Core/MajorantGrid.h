// Block maxima of a DensityGrid, for the reference renderers' majorants (delta and
// ratio tracking in the path tracer) and empty-space skipping (single scattering).
//
// The grid's voxels are grouped into blocks of B^3 voxels (B = BlockVoxels = 4 unless
// the constructor is given another size): along an axis with n > 1 points, block c
// covers the voxels [Bc, Bc + B) (the last block fewer), i.e. the points
// [Bc, min(n - 1, Bc + B)]; an axis with one point has one block. A block's
// maximum is the largest density over its points widened by `dilation` points on
// every side (clipped to the grid). Trilinear interpolation never exceeds the values
// at the corners of its voxel, so the maximum bounds the density over the closed
// block and, with dilation d, over d voxels around it. Densities are >= 0
// (DensityGrid), so a maximum of 0 means that every point it covers is 0: with
// dilation 0 the density is then exactly 0 everywhere in the closed block.
//
// MajorantWalk visits the blocks a ray crosses, in order (a 3-D DDA).
#ifndef NimbusMajorantGrid_h
#define NimbusMajorantGrid_h

#include "DensityGrid.h"
#include "Math.h"
#include "NimbusReferenceModule.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

namespace nimbus
{

class NIMBUSREFERENCE_EXPORT MajorantGrid
{
public:
  using Vector3 = nimbus::Vector3;

  /// Voxels per block edge, by default.
  static constexpr int BlockVoxels = 4;

  /// No blocks.
  MajorantGrid() = default;
  /// The block maxima of grid with `dilation` >= 0 points added on every side of a
  /// block (clipped to the grid), blocks of `blockVoxels` >= 1 voxels per edge. An empty
  /// grid has no blocks. Throws std::invalid_argument for a negative dilation or a
  /// block size < 1.
  MajorantGrid(const DensityGrid& grid, int dilation, int blockVoxels = BlockVoxels);

  /// Blocks along x, y, z.
  const std::array<int, 3>& GetBlocks() const { return this->Blocks; }
  /// Lower corner of the grid's box (DensityGrid::GetLower), m.
  const Vector3& GetLower() const { return this->Lower; }
  /// Block edge, m: B spacings, or the box's thickness along an axis with one
  /// point. Block (i, j, k) starts at GetLower() + (i, j, k) * GetBlockSize(); the last
  /// block along an axis may end at the box.
  const Vector3& GetBlockSize() const { return this->BlockSize; }
  /// Linear index of block (i, j, k), x fastest.
  std::size_t GetIndex(int i, int j, int k) const
  {
    return static_cast<std::size_t>(i) +
      static_cast<std::size_t>(this->Blocks[0]) *
      (static_cast<std::size_t>(j) + static_cast<std::size_t>(this->Blocks[1]) * k);
  }
  /// Largest density over the points block `index` covers (dilation included).
  double GetMaximum(std::size_t index) const { return static_cast<double>(this->Maxima[index]); }
  /// True if every point block `index` covers has density 0.
  bool IsEmpty(std::size_t index) const { return this->Maxima[index] == 0.0f; }

private:
  std::array<int, 3> Blocks{ { 0, 0, 0 } };
  Vector3 Lower{ { 0.0, 0.0, 0.0 } };
  Vector3 BlockSize{ { 1.0, 1.0, 1.0 } };
  std::vector<float> Maxima; // [GetIndex(i, j, k)]
};

/// Incremental 3-D DDA over the blocks of a MajorantGrid along a ray (Amanatides & Woo,
/// "A Fast Voxel Traversal Algorithm", Eurographics 1987; pbrt-v4's DDAMajorantIterator
/// walks its majorant grid the same way): the block index and the distance at which the
/// ray leaves it are updated by one comparison and one addition per block, instead of
/// locating the block from the position at every piece. The block is always the one
/// whose interval [entry, Exit) holds the caller's t, so a block's maximum bounds the
/// density there without dilation (a point can lie outside the block only by rounding,
/// ~1e-12 of the coordinates). Distances t are along `direction` from `origin`, in units
/// of its length (m for a unit direction). Used by the path tracer (delta and ratio
/// tracking) and the single-scattering renderer (empty-space skipping).
class MajorantWalk
{
public:
  /// Whether the walk is in the grid: false before Start and once Advance left it.
  bool Active = false;
  /// Linear index of the current block (MajorantGrid::GetIndex).
  std::size_t Index = 0;

  /// Starts at the block holding origin + t direction (on a face, the block the ray
  /// enters; clamped to the grid).
  void Start(const MajorantGrid& grid, const Vector3& origin, const Vector3& direction, double t)
  {
    const Vector3 p = Along(origin, direction, t);
    const std::array<int, 3>& blocks = grid.GetBlocks();
    std::size_t stride = 1;
    this->Index = 0;
    for (int a = 0; a < 3; ++a)
    {
      const double size = grid.GetBlockSize()[a];
      const double lower = grid.GetLower()[a];
      this->Count[a] = blocks[a];
      const double x = (p[a] - lower) / size;
      // On a face, the block the ray enters.
      int c = static_cast<int>(std::floor(x));
      if (direction[a] < 0.0 && x == std::floor(x))
      {
        c -= 1;
      }
      c = std::min(blocks[a] - 1, std::max(0, c));
      this->Cell[a] = c;
      const double d = direction[a];
      if (d > 0.0)
      {
        this->Step[a] = 1;
        this->TMax[a] = (lower + (c + 1) * size - origin[a]) / d;
        this->TDelta[a] = size / d;
      }
      else if (d < 0.0)
      {
        this->Step[a] = -1;
        this->TMax[a] = (lower + c * size - origin[a]) / d;
        this->TDelta[a] = -size / d;
      }
      else
      {
        this->Step[a] = 0;
        this->TMax[a] = std::numeric_limits<double>::infinity();
        this->TDelta[a] = std::numeric_limits<double>::infinity();
      }
      this->Stride[a] = stride;
      this->Index += stride * static_cast<std::size_t>(c);
      stride *= static_cast<std::size_t>(blocks[a]);
    }
    this->Active = true;
  }
  /// Where the ray leaves the current block (infinity if it never does).
  double Exit() const { return std::min({ this->TMax[0], this->TMax[1], this->TMax[2] }); }
  /// To the next block; false when the ray leaves the grid.
  bool Advance()
  {
    const int a = this->TMax[0] < this->TMax[1] ? (this->TMax[0] < this->TMax[2] ? 0 : 2)
                                                : (this->TMax[1] < this->TMax[2] ? 1 : 2);
    const int c = this->Cell[a] + this->Step[a];
    if (c < 0 || c >= this->Count[a])
    {
      this->Active = false;
      return false;
    }
    this->Cell[a] = c;
    this->TMax[a] += this->TDelta[a];
    this->Index = this->Step[a] > 0 ? this->Index + this->Stride[a] : this->Index - this->Stride[a];
    return true;
  }

private:
  int Cell[3] = { 0, 0, 0 };
  int Step[3] = { 0, 0, 0 };
  int Count[3] = { 1, 1, 1 };
  double TMax[3] = { 0.0, 0.0, 0.0 };
  double TDelta[3] = { 0.0, 0.0, 0.0 };
  std::size_t Stride[3] = { 1, 1, 1 };
};

} // namespace nimbus

#endif
