#include "MajorantGrid.h"

#include <algorithm>
#include <stdexcept>
#include <utility>

namespace nimbus
{

MajorantGrid::MajorantGrid(const DensityGrid& grid, int dilation, int blockVoxels)
{
  if (dilation < 0)
  {
    throw std::invalid_argument("nimbus::MajorantGrid: the dilation must be >= 0 points");
  }
  if (blockVoxels < 1)
  {
    throw std::invalid_argument("nimbus::MajorantGrid: a block must have >= 1 voxel per edge");
  }
  if (grid.IsEmpty())
  {
    return;
  }
  const std::array<int, 3>& n = grid.GetDimensions();
  std::array<std::vector<std::pair<int, int>>, 3> ranges; // point range per block
  for (int a = 0; a < 3; ++a)
  {
    this->Lower[a] = grid.GetLower()[a];
    if (n[a] == 1)
    {
      this->Blocks[a] = 1;
      this->BlockSize[a] = grid.GetUpper()[a] - grid.GetLower()[a];
      ranges[a].push_back({ 0, 0 });
      continue;
    }
    const int voxels = n[a] - 1;
    const int d = std::min(dilation, n[a]); // enough to reach every point
    this->Blocks[a] = (voxels + blockVoxels - 1) / blockVoxels;
    this->BlockSize[a] = blockVoxels * grid.GetSpacing()[a];
    for (int c = 0; c < this->Blocks[a]; ++c)
    {
      ranges[a].push_back(
        { std::max(0, c * blockVoxels - d), std::min(n[a] - 1, (c + 1) * blockVoxels + d) });
    }
  }
  // Separable running maximum: x, then y, then z.
  const std::vector<float>& f = grid.GetValues();
  const std::size_t nx = n[0], ny = n[1], nz = n[2];
  const std::size_t cx = this->Blocks[0], cy = this->Blocks[1], cz = this->Blocks[2];
  std::vector<float> ax(cx * ny * nz, 0.0f); // [c + cx * (j + ny * k)]
  for (std::size_t k = 0; k < nz; ++k)
  {
    for (std::size_t j = 0; j < ny; ++j)
    {
      const float* row = f.data() + nx * (j + ny * k);
      for (std::size_t c = 0; c < cx; ++c)
      {
        float m = 0.0f;
        for (int i = ranges[0][c].first; i <= ranges[0][c].second; ++i)
        {
          m = std::max(m, row[i]);
        }
        ax[c + cx * (j + ny * k)] = m;
      }
    }
  }
  std::vector<float> axy(cx * cy * nz, 0.0f); // [i + cx * (c + cy * k)]
  for (std::size_t k = 0; k < nz; ++k)
  {
    for (std::size_t c = 0; c < cy; ++c)
    {
      for (std::size_t i = 0; i < cx; ++i)
      {
        float m = 0.0f;
        for (int j = ranges[1][c].first; j <= ranges[1][c].second; ++j)
        {
          m = std::max(m, ax[i + cx * (j + ny * k)]);
        }
        axy[i + cx * (c + cy * k)] = m;
      }
    }
  }
  this->Maxima.assign(cx * cy * cz, 0.0f);
  for (std::size_t c = 0; c < cz; ++c)
  {
    for (std::size_t j = 0; j < cy; ++j)
    {
      for (std::size_t i = 0; i < cx; ++i)
      {
        float m = 0.0f;
        for (int k = ranges[2][c].first; k <= ranges[2][c].second; ++k)
        {
          m = std::max(m, axy[i + cx * (j + cy * k)]);
        }
        this->Maxima[i + cx * (j + cy * c)] = m;
      }
    }
  }
}

} // namespace nimbus
