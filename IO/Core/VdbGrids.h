// VdbGrids: the OpenVDB side of Nimbus's .vdb reader and writer, in plain C++ (no VTK).
//
// The header does not include OpenVDB: the VTK classes and the tests see only these
// plain structs; VdbGrids.cxx holds every OpenVDB call. Mapping rules (docs/openvdb.md):
//
//  * Index space. VDB voxel (i, j, k) is a grid POINT of the image (value at the point,
//    as OpenVDB samples voxel values at integer index coordinates). An index box
//    [min, max] (inclusive) is the image extent [min0, max0, min1, max1, min2, max2].
//  * Transform. A linear VDB transform maps index to world as
//      world = i * row0 + j * row1 + k * row2 + row3      (OpenVDB's row-vector Mat4)
//    so origin = row3, spacing_c = |row_c| and the image direction column c = row_c /
//    spacing_c. Rows that are not mutually orthogonal (shear) cannot be an image
//    transform; see TransformInfo for what is done then.
//  * Values. float grids -> 1 float component; double grids -> float; Vec3s/Vec3d grids ->
//    3 float components. Inactive voxels keep their tree value (the background for fog
//    volumes; -background inside level sets), as OpenVDB's copyToDense gives it.
//  * Errors are thrown as nimbus::vdb::Error with a message naming the file and grid.
#ifndef NimbusVdbGrids_h
#define NimbusVdbGrids_h

#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

namespace nimbus
{
namespace vdb
{

/// A user-facing error (missing file, not a VDB, truncated, limits...).
class Error : public std::runtime_error
{
public:
  using std::runtime_error::runtime_error;
};

/// Inclusive integer index box; empty when any max < min.
struct IndexBox
{
  std::array<int64_t, 3> Min{ { 0, 0, 0 } };
  std::array<int64_t, 3> Max{ { -1, -1, -1 } };

  bool Empty() const { return Max[0] < Min[0] || Max[1] < Min[1] || Max[2] < Min[2]; }
  /// Number of voxels (0 when empty); exact up to 2^63.
  uint64_t VoxelCount() const;
  /// Smallest box containing both (an empty box is the identity).
  IndexBox Union(const IndexBox& other) const;
  IndexBox Intersection(const IndexBox& other) const;
  bool operator==(const IndexBox& o) const { return Min == o.Min && Max == o.Max; }
};

/// What an index->world transform becomes in a vtkImageData.
struct TransformInfo
{
  std::array<double, 3> Origin{ { 0, 0, 0 } };  // world position of index (0,0,0)
  std::array<double, 3> Spacing{ { 1, 1, 1 } }; // world length of one index step per axis
  /// Column-major rotation (image direction matrix, VTK's convention: column c is the
  /// world direction of index axis c). Identity when axis-aligned.
  std::array<double, 9> Direction{ { 1, 0, 0, 0, 1, 0, 0, 0, 1 } };

  bool Linear = true;       // false for frustum / non-linear maps (linearised, see Note)
  bool Rotated = false;     // direction is not the identity
  bool Sheared = false;     // index axes not orthogonal in world space: direction dropped
  bool Anisotropic = false; // spacing differs between axes (exact in vtkImageData)
  /// What was done, for a warning; empty when the mapping is exact and axis-aligned
  /// with equal spacing.
  std::string Note;

  /// Same mapping within a relative tolerance (1e-9 of the spacing).
  bool SameAs(const TransformInfo& other) const;
};

/// Analyses a linear index->world 4x4 matrix in OpenVDB's row-vector convention
/// (m[row][col], translation in row 3). Exposed for tests.
TransformInfo AnalyseLinearMatrix(const std::array<std::array<double, 4>, 4>& m);

enum class ValueKind
{
  Float,
  Double,
  Vec3Float,
  Vec3Double,
  Unsupported
};

/// A grid as described by the file's metadata (no voxels read).
struct GridInfo
{
  /// The grid's name, made distinct: a name that repeats in the file gets OpenVDB's own
  /// suffix ("density", "density[1]"), an unnamed grid is "unnamed" (FileLayout).
  std::string Name;
  std::string StoredName; // the name as stored (may repeat or be empty)
  int Index = -1;         // position in the file (0 = first grid)
  int64_t FileBytes = 0;  // the grid's bytes in the file (descriptor to end)
  std::string TypeName;   // OpenVDB's type name, e.g. "Tree_float_5_4_3"
  std::string ValueType;  // "float", "double", "vec3s", "bool", ...
  ValueKind Kind = ValueKind::Unsupported;
  int Components = 0;    // 1 or 3 when supported
  std::string GridClass; // "fog volume", "level set", "staggered", "unknown"
  /// Active-voxel index box from the file's statistics metadata (file_bbox_min/max),
  /// or computed from the tree when the file has none (then TreeRead is true).
  IndexBox ActiveBox;
  int64_t ActiveVoxelCount = -1; // -1 when unknown
  bool TreeRead = false;
  std::array<double, 3> Background{ { 0, 0, 0 } };
  TransformInfo Transform;
  std::string Creator; // the grid's "creator" metadata (empty when it has none)
  bool Supported() const { return Kind != ValueKind::Unsupported; }
};

/// Registers with OpenVDB what Nimbus's reader and writer need, as openvdb::initialize() does
/// but without what they do not use, whose registration faults in about 2 MiB of OpenVDB's
/// code and tables in every process that reads a file: the point-data registries (attribute
/// arrays and their codecs) and the grid types other than float, double, Vec3s and Vec3d.
/// Registered: OpenVDB's logging, every metadata type and transform map openvdb::initialize()
/// registers except the per-leaf table of OpenVDB's delayed loading ("__delayedload":
/// unregistered, OpenVDB's metadata reader reads its bytes and drops them instead of decoding
/// 9 bytes per leaf of the grid, up to three times per read; nothing here loads lazily), the
/// four grid types, Blosc with its LZ4 compressor. Registers only what is not registered yet
/// and clears nothing, so it agrees with openvdb::initialize() run before it. With
/// `everyGridType` (ScanFile, for a file that holds a grid of another type: it is listed with
/// its value type), openvdb::initialize() itself, which registers everything anew. Thread-safe.
void RegisterOpenVdbTypes(bool everyGridType = false);

/// Reads every grid's descriptor, metadata and transform (no voxel data unless a grid
/// lacks bounding-box statistics), after ScanFile (VdbArchive.h) has checked the file's
/// layout. Throws Error for a missing/unreadable file, a file that is not a VDB, a
/// truncated or corrupt file. Grids of types OpenVDB does not know are listed as
/// unsupported (ValueType "unknown type '<type name>'"). `fileStrings`, when given, receives
/// the file-level string metadata (FileLayout::FileStrings: "creator", "up_axis", ...).
std::vector<GridInfo> ReadFileInfo(
  const std::string& path, std::map<std::string, std::string>* fileStrings = nullptr);

/// A dense float array over an index box, x fastest (VTK's point order).
struct DenseField
{
  std::string Name;
  int Components = 1;
  std::vector<float> Values; // box.VoxelCount() * Components
};

/// Progress callback: fraction in [0, 1].
using Progress = std::function<void(double)>;

/// Reads the named grids (GridInfo::Name, the distinct names) into dense arrays over `box`
/// of the reference grid's index space. Each grid's bytes are checked (ScanFile) and read
/// from the file through a stream that fails, instead of returning garbage, on any read
/// outside the grid's own bytes; only the leaves that touch `box` (grown by 2 voxels for a
/// resampled grid) are read and held, the others skipped in the file (OpenVDB's clipped read;
/// the whole grid for files older than grid instancing and non-linear transforms). Every
/// target value is set (filled with 0 first). `target` points
/// at caller-allocated storage of box.VoxelCount()*components floats per grid (the VTK array's
/// buffer), in the order of `names`. Grids whose transform differs from `reference` are resampled
/// trilinearly at the reference's voxel positions (`resampled` receives their names). `exact`
/// receives the transform of the first grid copied without resampling, as read with its voxels:
/// OpenVDB's metadata-only read (ReadFileInfo) can differ from it in the last bit of the voxel
/// size. Throws Error on read failure.
void ReadDense(const std::string& path, const std::vector<std::string>& names,
  const TransformInfo& reference, const IndexBox& box, const std::vector<float*>& target,
  std::vector<std::string>* resampled = nullptr, const Progress& progress = nullptr,
  TransformInfo* exact = nullptr);

/// The index box of grid `info` expressed in the index space of `reference` (the box of
/// reference voxels whose points lie inside info's world-space active box, rounded out).
IndexBox BoxInReference(const GridInfo& info, const TransformInfo& reference);

/// One field to write: `components` floats per point over `box`, x fastest.
struct FieldToWrite
{
  std::string Name;
  int Components = 1;
  const float* Values = nullptr;
  IndexBox Box;
  TransformInfo Transform; // origin, spacing, direction (must be orthogonal)
  float Background = 0.0f;
  /// Voxels whose value differs from the background by at most this (per component)
  /// are inactive and not stored.
  float Tolerance = 0.0f;
  bool FogVolume = false; // grid class GRID_FOG_VOLUME (density-like, >= 0)
};

/// Writes the fields as FloatGrid / Vec3SGrid to `path`, with the file metadata "creator"
/// ("Nimbus vtkNimbusOpenVDBWriter") and "up_axis" ("+Z": the fields are z-up Nimbus data). The
/// file is serialised in memory, then written by WriteFileAtomically (VdbArchive.h): temporary file
/// beside the target, every write checked, fsync, rename; a failure leaves an existing file byte
/// for byte and the message names the cause. Non-finite values (NaN, +-Inf) and a non-finite
/// background are refused (OpenVDB's tolerance test would silently make NaN voxels inactive).
/// `compress` selects Blosc (else no compression beyond OpenVDB's active-mask encoding). Throws
/// Error on failure. Returns the number of active voxels written.
uint64_t WriteFields(const std::string& path, const std::vector<FieldToWrite>& fields,
  bool compress = true, const Progress& progress = nullptr,
  std::vector<std::string>* notes = nullptr, int* errorNumber = nullptr);

/// OpenVDB's version string, e.g. "10.0.1".
std::string LibraryVersion();

} // namespace vdb
} // namespace nimbus

#endif
