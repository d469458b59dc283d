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
#ifndef NimbusMajorantGrid_h
#define NimbusMajorantGrid_h

#include "DensityGrid.h"
#include "Math.h"
#include "NimbusReferenceModule.h"

#include <array>
#include <cstddef>
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

} // namespace nimbus

#endif
