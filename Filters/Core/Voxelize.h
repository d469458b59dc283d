// Solid cells from a closed triangulated surface (the smoke solver's obstacles given as
// polydata). Plain C++, no VTK.
//
// A cell is solid when its centre lies inside the surface: the parity of the surface's
// crossings along the vertical line through the centre (a scan-line fill, one column of
// cells at a time). Each triangle is projected on the xy plane; the columns whose centres
// fall inside the projection get the height of the crossing; a column's crossings,
// sorted, pair up as entry and exit, and the cells between them are solid. Column
// centres are moved by a fixed tiny offset (1e-7 h, not a multiple of any grid step) so a
// line never passes exactly through an edge or vertex shared by two triangles: each
// crossing is then counted once. Cost: the triangles' projected areas in columns plus the
// cells, O(columns covered + nx ny nz).
#ifndef nimbus_Voxelize_h
#define nimbus_Voxelize_h

#include "Math.h"

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace nimbus
{

/// One byte per cell of the grid nx x ny x nz (x fastest; cell (i, j, k) spans
/// origin + h [i, i+1] x [j, j+1] x [k, k+1], metres): 1 where the cell's centre is
/// inside the surface of `triangles` (indices into `points`, metres; coincident points
/// must be merged: closedness is read from shared indices). Returns false with `error` set
/// when an index is out of range, a coordinate is not finite, or the surface is not closed
/// (an edge shared by an odd number of triangles, or a column that crosses it an odd
/// number of times); `solid` is then empty.
bool VoxelizeClosedSurface(const std::vector<Vector3>& points,
  const std::vector<std::array<std::int64_t, 3>>& triangles, const std::array<int, 3>& dims,
  const Vector3& origin, double h, std::vector<std::uint8_t>& solid, std::string& error);

} // namespace nimbus

#endif
