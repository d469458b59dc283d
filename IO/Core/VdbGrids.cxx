// VdbGrids: every OpenVDB call of Nimbus's .vdb reader and writer (see VdbGrids.h).
#include "VdbGrids.h"

#include "VdbArchive.h"
#include "VdbClippedRead.h"
#include "VdbFileCheck.h"

#include "MemoryBudget.h"

#include <openvdb/io/Archive.h>
#include <openvdb/io/File.h>
#include <openvdb/io/GridDescriptor.h>
#include <openvdb/io/io.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/Dense.h>
#include <openvdb/tools/Interpolation.h>

#include <blosc.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <dlfcn.h>
#include <fstream>
#include <limits>
#include <mutex>
#include <sstream>
#include <sys/stat.h>
#include <unistd.h>

namespace nimbus
{
namespace vdb
{
namespace
{

/// OpenVDB's registries as far as Nimbus's grids need them (RegisterOpenVdbTypes).
void Initialize()
{
  RegisterOpenVdbTypes();
}

template <typename MetadataT>
void RegisterMetadata()
{
  if (!MetadataT::isRegisteredType())
  {
    MetadataT::registerType();
  }
}

template <typename MapT>
void RegisterMap()
{
  if (!MapT::isRegistered())
  {
    MapT::registerMap();
  }
}

template <typename GridT>
void RegisterGrid()
{
  if (!GridT::isRegistered())
  {
    GridT::registerGrid();
  }
}

/// What openvdb::initialize() registers, in its order, less what RegisterOpenVdbTypes leaves
/// out. Only the grid types this file instantiates anyway: another one would add its whole
/// tree's code to this library.
void RegisterCommonTypes()
{
  // Once (openvdb::uninitialize() leaves them): OpenVDB's logging as openvdb::initialize() sets
  // it up (warnings to the console) where the library was built with it (the headers do not
  // say; the function is then exported); Blosc with LZ4 (blosc_init does nothing when Blosc is
  // initialised).
  static std::once_flag once;
  std::call_once(once,
    []
    {
      const std::string space = OPENVDB_PREPROC_STRINGIFY(OPENVDB_VERSION_NAME);
      const std::string logging =
        "_ZN7openvdb" + std::to_string(space.size()) + space + "7logging10initializeEb";
      using LoggingInit = void (*)(bool);
      if (const auto init = reinterpret_cast<LoggingInit>(dlsym(RTLD_DEFAULT, logging.c_str())))
      {
        init(true);
      }
      blosc_init();
      blosc_set_compressor("lz4");
    });
  RegisterMetadata<openvdb::BoolMetadata>();
  RegisterMetadata<openvdb::DoubleMetadata>();
  RegisterMetadata<openvdb::FloatMetadata>();
  RegisterMetadata<openvdb::Int32Metadata>();
  RegisterMetadata<openvdb::Int64Metadata>();
  RegisterMetadata<openvdb::StringMetadata>();
  RegisterMetadata<openvdb::Vec2IMetadata>();
  RegisterMetadata<openvdb::Vec2SMetadata>();
  RegisterMetadata<openvdb::Vec2DMetadata>();
  RegisterMetadata<openvdb::Vec3IMetadata>();
  RegisterMetadata<openvdb::Vec3SMetadata>();
  RegisterMetadata<openvdb::Vec3DMetadata>();
  RegisterMetadata<openvdb::Vec4IMetadata>();
  RegisterMetadata<openvdb::Vec4SMetadata>();
  RegisterMetadata<openvdb::Vec4DMetadata>();
  RegisterMetadata<openvdb::Mat4SMetadata>();
  RegisterMetadata<openvdb::Mat4DMetadata>();
  RegisterMap<openvdb::math::AffineMap>();
  RegisterMap<openvdb::math::UnitaryMap>();
  RegisterMap<openvdb::math::ScaleMap>();
  RegisterMap<openvdb::math::UniformScaleMap>();
  RegisterMap<openvdb::math::TranslationMap>();
  RegisterMap<openvdb::math::ScaleTranslateMap>();
  RegisterMap<openvdb::math::UniformScaleTranslateMap>();
  RegisterMap<openvdb::math::NonlinearFrustumMap>();
  RegisterGrid<openvdb::FloatGrid>();
  RegisterGrid<openvdb::DoubleGrid>();
  RegisterGrid<openvdb::Vec3SGrid>();
  RegisterGrid<openvdb::Vec3DGrid>();
  const std::string index32 = openvdb::typeNameAsString<openvdb::PointIndex32>();
  if (!openvdb::Metadata::isRegisteredType(index32))
  {
    openvdb::Metadata::registerType(index32, openvdb::Int32Metadata::createMetadata);
  }
  const std::string index64 = openvdb::typeNameAsString<openvdb::PointIndex64>();
  if (!openvdb::Metadata::isRegisteredType(index64))
  {
    openvdb::Metadata::registerType(index64, openvdb::Int64Metadata::createMetadata);
  }
}

std::string Quote(const std::string& s)
{
  return "'" + s + "'";
}

std::string Vec3String(const std::array<double, 3>& v)
{
  std::ostringstream out;
  out.precision(9);
  out << "(" << v[0] << ", " << v[1] << ", " << v[2] << ")";
  return out.str();
}

/// Fails with a clear message when `path` cannot be read as a regular file.
/// Where OpenVDB's chunk readers are not the checked ones (CompressionGuardInEffect),
/// a separate process reads the whole file first, once per file version (path, size,
/// modification time), so that a damaged chunk crashes that process, not this one.
void CheckInChildProcessUnlessGuarded(const std::string& path)
{
  if (CompressionGuardInEffect())
  {
    return;
  }
  struct stat st;
  if (::stat(path.c_str(), &st) != 0)
  {
    return; // CheckReadable reports it
  }
  const std::string key = path + "|" + std::to_string(st.st_size) + "|" +
    std::to_string(st.st_mtim.tv_sec) + "." + std::to_string(st.st_mtim.tv_nsec);
  static std::mutex mutex;
  static std::vector<std::string> checked;
  {
    std::lock_guard<std::mutex> lock(mutex);
    if (std::find(checked.begin(), checked.end(), key) != checked.end())
    {
      return;
    }
  }
  // 60 s, plus 1 s per 20 MB for the read itself.
  const double timeoutSeconds = 60.0 + static_cast<double>(st.st_size) / 20.0e6;
  const FileCheck check =
    CheckFileInChildProcess(path, nimbus::DefaultMemoryBudgetBytes(), timeoutSeconds);
  if (!check.Passed)
  {
    throw Error(check.Message);
  }
  std::lock_guard<std::mutex> lock(mutex);
  checked.push_back(key);
}

void CheckReadable(const std::string& path)
{
  struct stat st;
  if (path.empty())
  {
    throw Error("no file name given");
  }
  if (::stat(path.c_str(), &st) != 0)
  {
    throw Error("cannot open " + Quote(path) + ": " + std::strerror(errno));
  }
  if (!S_ISREG(st.st_mode))
  {
    throw Error(Quote(path) + " is not a regular file");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in)
  {
    throw Error("cannot open " + Quote(path) + " for reading: " + std::strerror(errno));
  }
  // OpenVDB files start with the 64-bit magic number 0x56444220 ("VDB " little-endian).
  unsigned char magic[8] = { 0 };
  in.read(reinterpret_cast<char*>(magic), 8);
  if (in.gcount() < 8 || magic[0] != 0x20 || magic[1] != 0x42 || magic[2] != 0x44 ||
    magic[3] != 0x56)
  {
    throw Error(Quote(path) + " is not an OpenVDB file (no 'VDB' magic number at its start)");
  }
}

ValueKind KindOf(const openvdb::GridBase& grid)
{
  if (grid.isType<openvdb::FloatGrid>())
  {
    return ValueKind::Float;
  }
  if (grid.isType<openvdb::DoubleGrid>())
  {
    return ValueKind::Double;
  }
  if (grid.isType<openvdb::Vec3SGrid>())
  {
    return ValueKind::Vec3Float;
  }
  if (grid.isType<openvdb::Vec3DGrid>())
  {
    return ValueKind::Vec3Double;
  }
  return ValueKind::Unsupported;
}

int ComponentsOf(ValueKind kind)
{
  switch (kind)
  {
    case ValueKind::Float:
    case ValueKind::Double:
      return 1;
    case ValueKind::Vec3Float:
    case ValueKind::Vec3Double:
      return 3;
    default:
      return 0;
  }
}

openvdb::CoordBBox ToCoordBox(const IndexBox& box)
{
  for (int c = 0; c < 3; ++c)
  {
    if (box.Min[c] < std::numeric_limits<int32_t>::min() ||
      box.Max[c] > std::numeric_limits<int32_t>::max())
    {
      throw Error("index box outside OpenVDB's 32-bit coordinate range");
    }
  }
  return openvdb::CoordBBox(openvdb::Coord(static_cast<int32_t>(box.Min[0]),
                              static_cast<int32_t>(box.Min[1]), static_cast<int32_t>(box.Min[2])),
    openvdb::Coord(static_cast<int32_t>(box.Max[0]), static_cast<int32_t>(box.Max[1]),
      static_cast<int32_t>(box.Max[2])));
}

IndexBox FromCoordBox(const openvdb::CoordBBox& bbox)
{
  IndexBox box;
  if (bbox.empty())
  {
    return box;
  }
  for (int c = 0; c < 3; ++c)
  {
    box.Min[c] = bbox.min()[c];
    box.Max[c] = bbox.max()[c];
  }
  return box;
}

/// The grid's transform as TransformInfo; non-linear maps are linearised at `at` (index).
TransformInfo AnalyseTransform(const openvdb::math::Transform& transform, const openvdb::Vec3d& at)
{
  std::array<std::array<double, 4>, 4> m{};
  if (transform.isLinear())
  {
    const openvdb::Mat4d mat = transform.baseMap()->getAffineMap()->getMat4();
    for (int r = 0; r < 4; ++r)
    {
      for (int c = 0; c < 4; ++c)
      {
        m[r][c] = mat(r, c);
      }
    }
    return AnalyseLinearMatrix(m);
  }
  // Frustum (or other non-linear) map: its Jacobian at `at` gives the local index axes.
  const auto map = transform.baseMap();
  const openvdb::Vec3d centre = map->applyMap(at);
  openvdb::Vec3d origin = centre;
  for (int r = 0; r < 3; ++r)
  {
    openvdb::Vec3d axis(0.0);
    axis[r] = 1.0;
    const openvdb::Vec3d row = map->applyJacobian(axis, at);
    for (int c = 0; c < 3; ++c)
    {
      m[r][c] = row[c];
    }
    origin -= row * at[r];
  }
  for (int c = 0; c < 3; ++c)
  {
    m[3][c] = origin[c];
  }
  m[3][3] = 1.0;
  TransformInfo info = AnalyseLinearMatrix(m);
  info.Linear = false;
  std::ostringstream note;
  note << "non-linear (" << map->type()
       << ") transform: linearised at the centre of the active voxels, index "
       << Vec3String({ { at[0], at[1], at[2] } }) << "; positions away from there are approximate";
  info.Note = note.str() + (info.Note.empty() ? "" : "; " + info.Note);
  return info;
}

std::array<double, 3> IndexToWorld(const TransformInfo& t, const std::array<double, 3>& ijk)
{
  std::array<double, 3> w = t.Origin;
  for (int r = 0; r < 3; ++r)
  {
    for (int c = 0; c < 3; ++c)
    {
      w[r] += t.Direction[3 * c + r] * t.Spacing[c] * ijk[c];
    }
  }
  return w;
}

std::array<double, 3> WorldToIndex(const TransformInfo& t, const std::array<double, 3>& w)
{
  // Direction is orthonormal (or the identity when sheared), so its inverse is its transpose.
  std::array<double, 3> d{ { w[0] - t.Origin[0], w[1] - t.Origin[1], w[2] - t.Origin[2] } };
  std::array<double, 3> ijk{};
  for (int c = 0; c < 3; ++c)
  {
    double v = 0.0;
    for (int r = 0; r < 3; ++r)
    {
      v += t.Direction[3 * c + r] * d[r];
    }
    ijk[c] = v / t.Spacing[c];
  }
  return ijk;
}

template <typename GridT, typename DenseValueT>
void CopyToDense(const GridT& grid, const openvdb::CoordBBox& bbox, float* target)
{
  openvdb::tools::Dense<DenseValueT, openvdb::tools::LayoutXYZ> dense(
    bbox, reinterpret_cast<DenseValueT*>(target));
  openvdb::tools::copyToDense(grid, dense, /*serial=*/false);
}

inline float Element(float v, int)
{
  return v;
}
inline float Element(double v, int)
{
  return static_cast<float>(v);
}
template <typename T>
inline float Element(const openvdb::math::Vec3<T>& v, int c)
{
  return static_cast<float>(v[c]);
}

/// Trilinear resampling of `grid` at the world positions of `reference`'s voxels in `box`.
template <typename GridT>
void ResampleToDense(
  const GridT& grid, const TransformInfo& reference, const IndexBox& box, float* target)
{
  using ValueT = typename GridT::ValueType;
  constexpr int components = openvdb::VecTraits<ValueT>::Size;
  const int64_t nx = box.Max[0] - box.Min[0] + 1;
  const int64_t ny = box.Max[1] - box.Min[1] + 1;
  const int64_t nz = box.Max[2] - box.Min[2] + 1;
  tbb::parallel_for(tbb::blocked_range<int64_t>(0, nz),
    [&](const tbb::blocked_range<int64_t>& r)
    {
      openvdb::tools::GridSampler<GridT, openvdb::tools::BoxSampler> sampler(grid);
      for (int64_t k = r.begin(); k != r.end(); ++k)
      {
        for (int64_t j = 0; j < ny; ++j)
        {
          float* out = target + components * (nx * (j + ny * k));
          for (int64_t i = 0; i < nx; ++i)
          {
            const auto w = IndexToWorld(reference,
              { { double(box.Min[0] + i), double(box.Min[1] + j), double(box.Min[2] + k) } });
            const ValueT v = sampler.wsSample(openvdb::Vec3d(w[0], w[1], w[2]));
            for (int c = 0; c < components; ++c)
            {
              out[components * i + c] = Element(v, c);
            }
          }
        }
      }
    });
}

template <typename GridT, typename DenseValueT>
void Extract(const openvdb::GridBase::Ptr& base, const TransformInfo& reference,
  const IndexBox& box, float* target, bool& resampled, TransformInfo& own)
{
  const auto grid = openvdb::gridPtrCast<GridT>(base);
  const auto bbox = grid->evalActiveVoxelBoundingBox();
  const openvdb::Vec3d centre = bbox.empty() ? openvdb::Vec3d(0.0) : bbox.getCenter();
  own = AnalyseTransform(grid->transform(), centre);
  if (own.SameAs(reference))
  {
    CopyToDense<GridT, DenseValueT>(*grid, ToCoordBox(box), target);
    resampled = false;
  }
  else
  {
    ResampleToDense(*grid, reference, box, target);
    resampled = true;
  }
}

void CheckTransformForWrite(const TransformInfo& t, const std::string& name)
{
  for (int c = 0; c < 3; ++c)
  {
    if (!(t.Spacing[c] > 0.0) || !std::isfinite(t.Spacing[c]) || !std::isfinite(t.Origin[c]))
    {
      throw Error("field " + Quote(name) + ": spacing " + Vec3String(t.Spacing) + " and origin " +
        Vec3String(t.Origin) + " must be finite with spacing > 0");
    }
  }
}

openvdb::math::Transform::Ptr ToVdbTransform(const TransformInfo& t)
{
  const openvdb::Vec3d origin(t.Origin[0], t.Origin[1], t.Origin[2]);
  const openvdb::Vec3d spacing(t.Spacing[0], t.Spacing[1], t.Spacing[2]);
  bool identity = true;
  for (int i = 0; i < 9; ++i)
  {
    identity = identity && t.Direction[i] == (i % 4 == 0 ? 1.0 : 0.0);
  }
  if (identity)
  {
    // Axis-aligned: built from a unit uniform scale map by postScale and postTranslate,
    // which keep origin and spacing bit-exact (the Transform(MapBase) constructor and
    // createLinearTransform(Mat4) simplify through an affine map and lose the last bit).
    auto transform = openvdb::math::Transform::createLinearTransform(1.0);
    if (spacing[0] == spacing[1] && spacing[1] == spacing[2])
    {
      transform = openvdb::math::Transform::createLinearTransform(spacing[0]);
    }
    else
    {
      transform->postScale(spacing);
    }
    transform->postTranslate(origin);
    return transform;
  }
  openvdb::Mat4d m = openvdb::Mat4d::identity();
  for (int r = 0; r < 3; ++r) // row r = world image of index axis r
  {
    for (int c = 0; c < 3; ++c)
    {
      m(r, c) = t.Direction[3 * r + c] * t.Spacing[r];
    }
    m(3, r) = t.Origin[r];
  }
  return openvdb::math::Transform::createLinearTransform(m);
}

template <typename GridT>
typename GridT::Ptr BuildGrid(const FieldToWrite& field)
{
  using ValueT = typename GridT::ValueType;
  const ValueT background(field.Background);
  const ValueT tolerance(field.Tolerance);
  auto grid = GridT::create(background);
  openvdb::tools::Dense<ValueT, openvdb::tools::LayoutXYZ> dense(
    ToCoordBox(field.Box), reinterpret_cast<ValueT*>(const_cast<float*>(field.Values)));
  openvdb::tools::copyFromDense(dense, *grid, tolerance, /*serial=*/false);
  grid->setName(field.Name);
  grid->setTransform(ToVdbTransform(field.Transform));
  grid->setSaveFloatAsHalf(false);
  return grid;
}

/// OpenVDB's own grid reading (Archive::readGrid), fed one grid at a time from the grid's own
/// bytes through a FileRangeBuf (reads outside them fail), after ScanFile has checked the
/// layout. OpenVDB's File reads from an ifstream whose failed reads it does not check, which
/// is how a truncated file gave uninitialised values and a corrupt count unbounded
/// allocations. With a clip box, the grid is a ClippedGrid (VdbClippedRead.h): it keeps only
/// the topology that touches the box and reads only the voxel buffers of the leaves that touch
/// it, seeking over the others; with `values` it writes the box's values there and keeps no
/// tree. A piece's read holds and reads only the piece's voxels.
class ArchiveReader : public openvdb::io::Archive
{
public:
  ArchiveReader(const std::string& path, const FileLayout& layout)
    : Path(path)
    , Layout(layout)
  {
    std::vector<char> header;
    Load(0, layout.HeaderEnd, header);
    SpanBuf buf(header, 0);
    std::istream is(&buf);
    is.exceptions(std::ios::failbit | std::ios::badbit);
    this->readHeader(is);
  }

  openvdb::io::Archive::Ptr copy() const override { return openvdb::io::Archive::Ptr(); }
  void write(const openvdb::GridCPtrVec&, const openvdb::MetaMap&) const override
  {
    throw Error("ArchiveReader cannot write");
  }

  /// Grid `i` of the layout: metadata and transform only, or the whole grid, or (with
  /// `clip`) the grid's voxels in that index box and nothing outside it; with `values` too,
  /// those voxels' values written there (floats over `clip`, x fastest) and `*filled` true,
  /// else (a file older than node-mask compression) the clipped tree and `*filled` false.
  openvdb::GridBase::Ptr Read(size_t i, bool metadataOnly, int depth = 0,
    const openvdb::CoordBBox* clip = nullptr, float* values = nullptr, bool* filled = nullptr)
  {
    if (filled)
    {
      *filled = false;
    }
    const GridLayout& g = this->Layout.Grids[i];
    FileRangeBuf buf(this->Path, g.DescriptorPos, metadataOnly ? g.BlockPos : g.EndPos,
      metadataOnly ? 64 << 10 : 128 << 10);
    buf.pubseekpos(g.DescriptorPos, std::ios_base::in);
    std::istream is(&buf);
    is.exceptions(std::ios::failbit | std::ios::badbit);
    auto meta = std::make_shared<openvdb::io::StreamMetadata>();
    meta->setSeekable(true);
    openvdb::io::setStreamMetadataPtr(is, meta, /*transfer=*/false);
    this->setFormatVersion(is);
    this->setLibraryVersion(is);
    this->setDataCompression(is);
    openvdb::io::GridDescriptor gd;
    openvdb::GridBase::Ptr grid = gd.read(is);
    if (!grid)
    {
      throw Error("cannot create grid " + Quote(this->Layout.DistinctNames[i]) + " of type " +
        Quote(g.TypeName));
    }
    is.seekg(gd.getGridPos(), std::ios_base::beg);
    if (metadataOnly && this->fileVersion() >= openvdb::OPENVDB_FILE_VERSION_GRID_INSTANCING)
    {
      Archive::readGridCompression(is);
      grid->readMeta(is);
      grid->readTransform(is);
      return grid;
    }
    if (clip)
    {
      // Read only the topology that touches the box (VdbClippedRead.h) where the grid's type
      // and the file's version allow; else OpenVDB's clipped read, which parses it all.
      if (!gd.isInstance())
      {
        if (auto clipped = MakeClippedGrid(*grid, this->Layout.FormatVersion, *clip, values))
        {
          grid = clipped;
          if (filled)
          {
            *filled = values != nullptr;
          }
        }
      }
      Archive::readGrid(grid, gd, is, *clip);
    }
    else
    {
      Archive::readGrid(grid, gd, is);
    }
    if (gd.isInstance())
    {
      size_t parent = this->Layout.Grids.size();
      for (size_t p = 0; p < this->Layout.Grids.size(); ++p)
      {
        if (this->Layout.Grids[p].UniqueName == gd.instanceParentName() && p != i)
        {
          parent = p;
        }
      }
      if (parent == this->Layout.Grids.size() || depth > 0)
      {
        throw Error("grid " + Quote(this->Layout.DistinctNames[i]) +
          " is an instance of a grid that is missing or itself an instance");
      }
      grid->setTree(this->Read(parent, false, depth + 1, clip, values, filled)->baseTreePtr());
    }
    return grid;
  }

private:
  /// Bytes [pos, pos + n) of the file (ScanFile checked they exist; a file that shrank
  /// since is an error).
  void Load(int64_t pos, int64_t n, std::vector<char>& bytes) const
  {
    std::ifstream in(this->Path, std::ios::binary);
    bytes.resize(static_cast<size_t>(n));
    in.seekg(pos);
    in.read(bytes.data(), n);
    if (!in || in.gcount() != n)
    {
      throw Error("cannot read bytes " + std::to_string(pos) + " to " + std::to_string(pos + n) +
        " of " + Quote(this->Path) + " (did the file change while it was read?)");
    }
  }

  std::string Path;
  const FileLayout& Layout;
};

/// OpenVDB's seekable archive writing (with grid offsets, as File writes) into any stream.
class ArchiveWriter : public openvdb::io::Archive
{
public:
  openvdb::io::Archive::Ptr copy() const override { return openvdb::io::Archive::Ptr(); }
  void write(const openvdb::GridCPtrVec&, const openvdb::MetaMap&) const override
  {
    throw Error("ArchiveWriter writes with WriteTo");
  }
  void WriteTo(std::ostream& os, const openvdb::GridPtrVec& grids, const openvdb::MetaMap& meta)
  {
    this->Archive::write(os, grids, /*seekable=*/true, meta);
  }
};

/// The message for an exception OpenVDB (or the stream) threw while reading `grid`.
std::string ReadFailure(const std::string& path, const std::string& grid, const std::exception& e)
{
  if (dynamic_cast<const std::ios_base::failure*>(&e))
  {
    return "cannot read grid " + Quote(grid) + " of OpenVDB file " + Quote(path) +
      ": its data is corrupt (OpenVDB read past the grid's end; truncated or corrupt?)";
  }
  if (dynamic_cast<const std::bad_alloc*>(&e) || dynamic_cast<const std::length_error*>(&e))
  {
    return "cannot read grid " + Quote(grid) + " of OpenVDB file " + Quote(path) +
      ": out of memory (" + e.what() + "); the file may be corrupt";
  }
  return "cannot read grid " + Quote(grid) + " of OpenVDB file " + Quote(path) +
    " (truncated or corrupt?): " + e.what();
}

/// Values of one clipped read in ReadDense (a slab of the box): 32 MiB.
constexpr int64_t SlabBytes = int64_t(32) << 20;

/// The index box of grid `index` to read for `box` of the reference's index space: the box
/// itself when the grid has the reference's transform (its voxels are copied), the box's
/// corners in the grid's index space grown by 2 voxels when it is resampled (trilinear
/// sampling reads the 8 voxels around each point). False (read the whole grid) for files older
/// than grid instancing, whose metadata cannot be read apart, and for non-linear transforms,
/// whose linearisation depends on the whole grid's active box.
/// `copied` (when given) says whether the grid has the reference's transform.
bool ClipBox(ArchiveReader& archive, const FileLayout& layout, size_t index,
  const TransformInfo& reference, const IndexBox& box, openvdb::CoordBBox& clip,
  bool* copied = nullptr)
{
  if (copied)
  {
    *copied = false;
  }
  if (layout.FormatVersion < openvdb::OPENVDB_FILE_VERSION_GRID_INSTANCING || !reference.Linear ||
    box.Empty())
  {
    return false;
  }
  const auto meta = archive.Read(index, /*metadataOnly=*/true);
  const openvdb::math::Transform& transform = meta->transform();
  if (!transform.isLinear())
  {
    return false;
  }
  if (AnalyseTransform(transform, openvdb::Vec3d(0.0)).SameAs(reference))
  {
    clip = ToCoordBox(box);
    if (copied)
    {
      *copied = true;
    }
    return true;
  }
  openvdb::Vec3d lo(std::numeric_limits<double>::max()), hi(-std::numeric_limits<double>::max());
  for (int corner = 0; corner < 8; ++corner)
  {
    std::array<double, 3> ijk{};
    for (int c = 0; c < 3; ++c)
    {
      ijk[c] = double((corner >> c) & 1 ? box.Max[c] : box.Min[c]);
    }
    const auto w = IndexToWorld(reference, ijk);
    const openvdb::Vec3d g = transform.worldToIndex(openvdb::Vec3d(w[0], w[1], w[2]));
    lo = openvdb::math::minComponent(lo, g);
    hi = openvdb::math::maxComponent(hi, g);
  }
  const double limit = double(std::numeric_limits<int32_t>::max() / 2);
  for (int c = 0; c < 3; ++c)
  {
    if (!(std::abs(lo[c]) < limit && std::abs(hi[c]) < limit))
    {
      return false;
    }
  }
  clip = openvdb::CoordBBox(openvdb::Coord(int(std::floor(lo[0])) - 2, int(std::floor(lo[1])) - 2,
                              int(std::floor(lo[2])) - 2),
    openvdb::Coord(
      int(std::ceil(hi[0])) + 2, int(std::ceil(hi[1])) + 2, int(std::ceil(hi[2])) + 2));
  return true;
}

/// Fills `target` (zeros first: every value is set even if a copy stops half-way) with the
/// grid's values over `box` of the reference's index space, copied or resampled by its type.
void ExtractAny(const openvdb::GridBase::Ptr& base, const TransformInfo& reference,
  const IndexBox& box, float* target, bool& resampled, TransformInfo& own)
{
  const ValueKind kind = KindOf(*base);
  std::fill(target, target + box.VoxelCount() * uint64_t(ComponentsOf(kind)), 0.0f);
  switch (kind)
  {
    case ValueKind::Float:
      Extract<openvdb::FloatGrid, float>(base, reference, box, target, resampled, own);
      break;
    case ValueKind::Double:
      Extract<openvdb::DoubleGrid, float>(base, reference, box, target, resampled, own);
      break;
    case ValueKind::Vec3Float:
      Extract<openvdb::Vec3SGrid, openvdb::Vec3s>(base, reference, box, target, resampled, own);
      break;
    case ValueKind::Vec3Double:
      Extract<openvdb::Vec3DGrid, openvdb::Vec3s>(base, reference, box, target, resampled, own);
      break;
    default:
      throw Error("grid " + Quote(base->getName()) + " has unsupported value type " +
        Quote(base->valueType()));
  }
}

/// Grid `index`'s values over `box` into `target` (ReadDense). A grid with the reference's
/// transform is read once, straight into the target (ClippedGrid with values: no tree held
/// but one lower node's leaves). A resampled grid is read in slabs of whole leaves along z
/// (multiples of 8 voxels, about SlabBytes of values each, at most 4 slabs: each read parses
/// the grid's topology again), its clipped tree resampled slab by slab: the tree held at once
/// is one slab's leaves, not the box's. One read of the whole grid where a clipped read is not
/// possible (ClipBox).
void ReadGrid(ArchiveReader& archive, const FileLayout& layout, size_t index,
  const TransformInfo& reference, const IndexBox& box, float* target, bool& resampled,
  TransformInfo& own)
{
  openvdb::CoordBBox clip;
  bool copied = false;
  const bool clipped = ClipBox(archive, layout, index, reference, box, clip, &copied);
  if (clipped && copied)
  {
    int components = 0;
    {
      const auto meta = archive.Read(index, /*metadataOnly=*/true);
      components = ComponentsOf(KindOf(*meta));
      if (components == 0)
      {
        throw Error("grid " + Quote(layout.DistinctNames[index]) + " has unsupported value type " +
          Quote(meta->valueType()));
      }
    }
    std::fill(target, target + box.VoxelCount() * uint64_t(components), 0.0f);
    bool filled = false;
    const auto base = archive.Read(index, false, 0, &clip, target, &filled);
    if (filled)
    {
      own = AnalyseTransform(base->transform(), openvdb::Vec3d(0.0));
      resampled = false;
      return;
    }
    ExtractAny(base, reference, box, target, resampled, own);
    return;
  }
  const int64_t nx = box.Max[0] - box.Min[0] + 1, ny = box.Max[1] - box.Min[1] + 1;
  const int64_t nz = box.Max[2] - box.Min[2] + 1;
  const int64_t thickness = std::max<int64_t>(
    { 8, SlabBytes / std::max<int64_t>(1, 12 * nx * ny) / 8 * 8, (nz + 31) / 32 * 8 });
  for (int64_t z0 = box.Min[2]; z0 <= box.Max[2];)
  {
    IndexBox slab = box;
    if (clipped)
    {
      const int64_t end = z0 + thickness;
      slab.Min[2] = z0;
      slab.Max[2] = std::min(box.Max[2], end - (((end % 8) + 8) % 8) - 1);
      ClipBox(archive, layout, index, reference, slab, clip);
    }
    const auto base = archive.Read(index, false, 0, clipped ? &clip : nullptr);
    const uint64_t offset =
      uint64_t(slab.Min[2] - box.Min[2]) * nx * ny * uint64_t(ComponentsOf(KindOf(*base)));
    ExtractAny(base, reference, slab, target + offset, resampled, own);
    z0 = slab.Max[2] + 1;
  }
}

} // namespace

void RegisterOpenVdbTypes(bool everyGridType)
{
  // The look-ups each time: openvdb::uninitialize() may have cleared the registries since.
  static std::mutex mutex;
  std::lock_guard<std::mutex> lock(mutex);
  if (everyGridType)
  {
    // Does nothing after its first time. That first time it empties and refills OpenVDB's
    // registries: a read running in another thread just then could miss a type (the reader's
    // reads run in the pipeline's thread).
    openvdb::initialize();
  }
  RegisterCommonTypes();
}

uint64_t IndexBox::VoxelCount() const
{
  if (Empty())
  {
    return 0;
  }
  uint64_t n = 1;
  for (int c = 0; c < 3; ++c)
  {
    const uint64_t d = static_cast<uint64_t>(Max[c] - Min[c]) + 1;
    if (d != 0 && n > std::numeric_limits<uint64_t>::max() / d)
    {
      return std::numeric_limits<uint64_t>::max();
    }
    n *= d;
  }
  return n;
}

IndexBox IndexBox::Union(const IndexBox& other) const
{
  if (Empty())
  {
    return other;
  }
  if (other.Empty())
  {
    return *this;
  }
  IndexBox u;
  for (int c = 0; c < 3; ++c)
  {
    u.Min[c] = std::min(Min[c], other.Min[c]);
    u.Max[c] = std::max(Max[c], other.Max[c]);
  }
  return u;
}

IndexBox IndexBox::Intersection(const IndexBox& other) const
{
  IndexBox u;
  if (Empty() || other.Empty())
  {
    return u;
  }
  for (int c = 0; c < 3; ++c)
  {
    u.Min[c] = std::max(Min[c], other.Min[c]);
    u.Max[c] = std::min(Max[c], other.Max[c]);
  }
  return u.Empty() ? IndexBox() : u;
}

bool TransformInfo::SameAs(const TransformInfo& other) const
{
  const double scale = std::max({ Spacing[0], Spacing[1], Spacing[2] });
  const double eps = 1e-9 * scale;
  for (int c = 0; c < 3; ++c)
  {
    if (std::abs(Spacing[c] - other.Spacing[c]) > eps ||
      std::abs(Origin[c] - other.Origin[c]) > eps * std::max(1.0, std::abs(Origin[c]) / scale))
    {
      return false;
    }
  }
  for (int i = 0; i < 9; ++i)
  {
    if (std::abs(Direction[i] - other.Direction[i]) > 1e-9)
    {
      return false;
    }
  }
  return Linear == other.Linear;
}

TransformInfo AnalyseLinearMatrix(const std::array<std::array<double, 4>, 4>& m)
{
  TransformInfo info;
  std::array<std::array<double, 3>, 3> axis{};
  for (int r = 0; r < 3; ++r)
  {
    const double len = std::sqrt(m[r][0] * m[r][0] + m[r][1] * m[r][1] + m[r][2] * m[r][2]);
    if (!(len > 0.0) || !std::isfinite(len))
    {
      throw Error("degenerate transform: index axis " + std::to_string(r) + " has world length " +
        std::to_string(len));
    }
    info.Spacing[r] = len;
    info.Origin[r] = m[3][r];
    for (int c = 0; c < 3; ++c)
    {
      axis[r][c] = m[r][c] / len;
    }
  }
  for (int c = 0; c < 3; ++c)
  {
    if (!std::isfinite(info.Origin[c]))
    {
      throw Error("transform with a non-finite translation");
    }
  }
  // Orthogonality of the index axes in world space (cosine of the angle between them).
  const double tol = 1e-6;
  for (int a = 0; a < 3; ++a)
  {
    for (int b = a + 1; b < 3; ++b)
    {
      const double cosine =
        axis[a][0] * axis[b][0] + axis[a][1] * axis[b][1] + axis[a][2] * axis[b][2];
      if (std::abs(cosine) > tol)
      {
        info.Sheared = true;
      }
    }
  }
  std::vector<std::string> notes;
  if (info.Sheared)
  {
    notes.push_back("index axes are not orthogonal in world space (sheared transform), which an "
                    "image cannot represent: the image is axis-aligned with origin = world "
                    "position of index (0,0,0) " +
      Vec3String(info.Origin) + " and spacing = world lengths of the index axes " +
      Vec3String(info.Spacing) + "; the shear and any rotation are dropped");
  }
  else
  {
    for (int c = 0; c < 3; ++c)
    {
      for (int r = 0; r < 3; ++r)
      {
        info.Direction[3 * c + r] = axis[c][r];
        if (std::abs(axis[c][r] - (r == c ? 1.0 : 0.0)) > 1e-12)
        {
          info.Rotated = true;
        }
      }
    }
    if (info.Rotated)
    {
      std::ostringstream s;
      s.precision(9);
      s << "rotated (or mirrored) transform: kept exactly as the image's direction matrix [";
      for (int r = 0; r < 3; ++r)
      {
        s << (r ? "; " : "") << info.Direction[r] << " " << info.Direction[3 + r] << " "
          << info.Direction[6 + r];
      }
      s << "], origin " << Vec3String(info.Origin) << ", spacing " << Vec3String(info.Spacing)
        << " (ParaView filters and mappers that ignore the direction matrix show it "
           "axis-aligned)";
      notes.push_back(s.str());
    }
  }
  const double smin = std::min({ info.Spacing[0], info.Spacing[1], info.Spacing[2] });
  const double smax = std::max({ info.Spacing[0], info.Spacing[1], info.Spacing[2] });
  if (smax - smin > 1e-9 * smax)
  {
    info.Anisotropic = true;
    notes.push_back("non-uniform voxel size " + Vec3String(info.Spacing) +
      ": kept exactly as the image's per-axis spacing");
  }
  for (size_t i = 0; i < notes.size(); ++i)
  {
    info.Note += (i ? "; " : "") + notes[i];
  }
  return info;
}

std::string LibraryVersion()
{
  return openvdb::getLibraryVersionString();
}

std::vector<GridInfo> ReadFileInfo(
  const std::string& path, std::map<std::string, std::string>* fileStrings)
{
  Initialize();
  CheckReadable(path);
  const FileLayout layout = ScanFile(path);
  if (fileStrings)
  {
    *fileStrings = layout.FileStrings;
  }
  CheckInChildProcessUnlessGuarded(path);
  std::vector<GridInfo> result;
  std::string current;
  try
  {
    ArchiveReader archive(path, layout);
    for (size_t i = 0; i < layout.Grids.size(); ++i)
    {
      GridInfo info;
      info.Name = layout.DistinctNames[i];
      info.StoredName = layout.Grids[i].StoredName;
      info.Index = static_cast<int>(i);
      info.TypeName = layout.Grids[i].TypeName;
      info.FileBytes = layout.Grids[i].EndPos - layout.Grids[i].DescriptorPos;
      current = info.Name;
      if (!openvdb::GridBase::isRegistered(layout.Grids[i].TypeName))
      {
        info.ValueType = "unknown type " + Quote(layout.Grids[i].TypeName);
        result.push_back(std::move(info));
        continue;
      }
      const openvdb::GridBase::Ptr grid = archive.Read(i, /*metadataOnly=*/true);
      info.ValueType = grid->valueType();
      info.Kind = KindOf(*grid);
      info.Components = ComponentsOf(info.Kind);
      info.GridClass = openvdb::GridBase::gridClassToString(grid->getGridClass());
      if (const auto creator =
            grid->getMetadata<openvdb::StringMetadata>(openvdb::GridBase::META_GRID_CREATOR))
      {
        info.Creator = creator->value();
      }
      const auto bmin =
        grid->getMetadata<openvdb::Vec3IMetadata>(openvdb::GridBase::META_FILE_BBOX_MIN);
      const auto bmax =
        grid->getMetadata<openvdb::Vec3IMetadata>(openvdb::GridBase::META_FILE_BBOX_MAX);
      const auto count =
        grid->getMetadata<openvdb::Int64Metadata>(openvdb::GridBase::META_FILE_VOXEL_COUNT);
      if (bmin && bmax && info.Supported())
      {
        for (int c = 0; c < 3; ++c)
        {
          info.ActiveBox.Min[c] = bmin->value()[c];
          info.ActiveBox.Max[c] = bmax->value()[c];
        }
        if (info.ActiveBox.Empty())
        {
          info.ActiveBox = IndexBox();
        }
        info.ActiveVoxelCount = count ? count->value() : -1;
      }
      else if (info.Supported())
      {
        // No statistics metadata: read this grid's tree to find its active box.
        const auto full = archive.Read(i, /*metadataOnly=*/false);
        info.ActiveBox = FromCoordBox(full->evalActiveVoxelBoundingBox());
        info.ActiveVoxelCount = static_cast<int64_t>(full->activeVoxelCount());
        info.TreeRead = true;
      }
      if (info.ActiveVoxelCount == 0)
      {
        info.ActiveBox = IndexBox();
      }
      const openvdb::Vec3d centre = info.ActiveBox.Empty()
        ? openvdb::Vec3d(0.0)
        : openvdb::Vec3d(0.5 * double(info.ActiveBox.Min[0] + info.ActiveBox.Max[0]),
            0.5 * double(info.ActiveBox.Min[1] + info.ActiveBox.Max[1]),
            0.5 * double(info.ActiveBox.Min[2] + info.ActiveBox.Max[2]));
      if (info.Supported())
      {
        try
        {
          info.Transform = AnalyseTransform(grid->transform(), centre);
        }
        catch (const Error& e)
        {
          throw Error("grid " + Quote(info.Name) + " of " + Quote(path) + ": " + e.what());
        }
      }
      result.push_back(std::move(info));
    }
  }
  catch (const Error&)
  {
    throw;
  }
  catch (const std::exception& e)
  {
    throw Error(ReadFailure(path, current, e));
  }
  return result;
}

IndexBox BoxInReference(const GridInfo& info, const TransformInfo& reference)
{
  if (info.ActiveBox.Empty() || info.Transform.SameAs(reference))
  {
    return info.ActiveBox;
  }
  IndexBox box;
  std::array<double, 3> lo{ { std::numeric_limits<double>::max(),
    std::numeric_limits<double>::max(), std::numeric_limits<double>::max() } };
  std::array<double, 3> hi{ { -lo[0], -lo[1], -lo[2] } };
  for (int corner = 0; corner < 8; ++corner)
  {
    std::array<double, 3> ijk{};
    for (int c = 0; c < 3; ++c)
    {
      ijk[c] = double((corner >> c) & 1 ? info.ActiveBox.Max[c] : info.ActiveBox.Min[c]);
    }
    const auto r = WorldToIndex(reference, IndexToWorld(info.Transform, ijk));
    for (int c = 0; c < 3; ++c)
    {
      lo[c] = std::min(lo[c], r[c]);
      hi[c] = std::max(hi[c], r[c]);
    }
  }
  for (int c = 0; c < 3; ++c)
  {
    const double limit = double(std::numeric_limits<int32_t>::max() / 2);
    if (!(std::abs(lo[c]) < limit && std::abs(hi[c]) < limit))
    {
      throw Error(
        "grid " + Quote(info.Name) + " lies outside the 32-bit index range of the reference grid");
    }
    box.Min[c] = static_cast<int64_t>(std::floor(lo[c] + 1e-6));
    box.Max[c] = static_cast<int64_t>(std::ceil(hi[c] - 1e-6));
  }
  return box;
}

void ReadDense(const std::string& path, const std::vector<std::string>& names,
  const TransformInfo& reference, const IndexBox& box, const std::vector<float*>& target,
  std::vector<std::string>* resampled, const Progress& progress, TransformInfo* exact)
{
  Initialize();
  bool haveExact = false;
  CheckReadable(path);
  if (target.size() != names.size())
  {
    throw Error("ReadDense: one target buffer per grid name is needed");
  }
  if (box.Empty())
  {
    throw Error("ReadDense: empty index box");
  }
  const FileLayout layout = ScanFile(path);
  CheckInChildProcessUnlessGuarded(path);
  std::string current;
  try
  {
    ArchiveReader archive(path, layout);
    for (size_t g = 0; g < names.size(); ++g)
    {
      current = names[g];
      const auto found =
        std::find(layout.DistinctNames.begin(), layout.DistinctNames.end(), names[g]);
      if (found == layout.DistinctNames.end())
      {
        throw Error("no grid named " + Quote(names[g]) + " in " + Quote(path));
      }
      const size_t index = size_t(found - layout.DistinctNames.begin());
      bool wasResampled = false;
      TransformInfo own;
      ReadGrid(archive, layout, index, reference, box, target[g], wasResampled, own);
      if (wasResampled && resampled)
      {
        resampled->push_back(names[g]);
      }
      if (!wasResampled && exact && !haveExact)
      {
        *exact = own;
        haveExact = true;
      }
      if (progress)
      {
        progress(double(g + 1) / double(names.size()));
      }
    }
  }
  catch (const Error&)
  {
    throw;
  }
  catch (const std::exception& e)
  {
    throw Error(ReadFailure(path, current, e));
  }
}

uint64_t WriteFields(const std::string& path, const std::vector<FieldToWrite>& fields,
  bool compress, const Progress& progress, std::vector<std::string>* notes, int* errorNumber)
{
  Initialize();
  if (errorNumber)
  {
    *errorNumber = 0;
  }
  if (path.empty())
  {
    throw Error("no file name given");
  }
  if (fields.empty())
  {
    throw Error("nothing to write: no float point or cell arrays with 1 or 3 components");
  }
  openvdb::GridPtrVec grids;
  uint64_t active = 0;
  for (size_t f = 0; f < fields.size(); ++f)
  {
    const FieldToWrite& field = fields[f];
    if (field.Box.Empty() || !field.Values)
    {
      throw Error("field " + Quote(field.Name) + " is empty");
    }
    if (!(field.Tolerance >= 0.0f))
    {
      throw Error("tolerance must be >= 0 (got " + std::to_string(field.Tolerance) + ")");
    }
    if (!std::isfinite(field.Background))
    {
      throw Error("the background must be a finite number (got " +
        std::to_string(field.Background) + "): it is the value of every inactive voxel");
    }
    // NaN compares unequal to everything, so OpenVDB's tolerance test would make NaN voxels
    // inactive, i.e. silently background; infinities are no density either. Refused.
    const uint64_t count = field.Box.VoxelCount() * uint64_t(field.Components);
    uint64_t nan = 0, inf = 0, first = count;
    for (uint64_t i = 0; i < count; ++i)
    {
      const float v = field.Values[i];
      if (std::isnan(v))
      {
        ++nan;
        first = std::min(first, i);
      }
      else if (std::isinf(v))
      {
        ++inf;
        first = std::min(first, i);
      }
    }
    if (nan || inf)
    {
      throw Error("array " + Quote(field.Name) + " has " +
        (nan ? std::to_string(nan) + " NaN" : std::string()) + (nan && inf ? " and " : "") +
        (inf ? std::to_string(inf) + " infinite" : std::string()) +
        " values (the first at value index " + std::to_string(first) +
        "): a .vdb grid cannot hold them faithfully (NaN would become inactive background), so "
        "nothing was written; replace them first (e.g. with a Calculator or Threshold filter)");
    }
    CheckTransformForWrite(field.Transform, field.Name);
    openvdb::GridBase::Ptr grid;
    if (field.Components == 1)
    {
      grid = BuildGrid<openvdb::FloatGrid>(field);
    }
    else if (field.Components == 3)
    {
      grid = BuildGrid<openvdb::Vec3SGrid>(field);
    }
    else
    {
      throw Error("field " + Quote(field.Name) + " has " + std::to_string(field.Components) +
        " components; only 1 (FloatGrid) and 3 (Vec3SGrid) are written");
    }
    if (field.FogVolume)
    {
      grid->setGridClass(openvdb::GRID_FOG_VOLUME);
    }
    grid->setCreator("Nimbus (vtkNimbusOpenVDBWriter)");
    active += grid->activeVoxelCount();
    grids.push_back(grid);
    if (progress)
    {
      progress(0.7 * double(f + 1) / double(fields.size()));
    }
  }

  // Serialise in memory (OpenVDB's File writes through an ofstream whose failures it does
  // not check), then write the bytes with every system call checked.
  std::string bytes;
  try
  {
    ArchiveWriter archive;
    archive.setCompression(compress
        ? (openvdb::io::COMPRESS_BLOSC | openvdb::io::COMPRESS_ACTIVE_MASK)
        : openvdb::io::COMPRESS_ACTIVE_MASK);
    openvdb::MetaMap meta;
    meta.insertMeta("creator", openvdb::StringMetadata("Nimbus vtkNimbusOpenVDBWriter"));
    // Nimbus's data is z up (x east, y north, z up: Physics/UpAxis.h); the reader's Auto
    // up axis reads this key first (VdbUpAxis.h), so a written file reads back as it was.
    meta.insertMeta("up_axis", openvdb::StringMetadata("+Z"));
    std::ostringstream os(std::ios::out | std::ios::binary);
    archive.WriteTo(os, grids, meta);
    if (!os)
    {
      throw Error("cannot write " + Quote(path) + ": serialising the grids failed");
    }
    bytes = os.str();
  }
  catch (const Error&)
  {
    throw;
  }
  catch (const std::exception& e)
  {
    throw Error("cannot write " + Quote(path) + ": " + e.what());
  }
  if (progress)
  {
    progress(0.8);
  }
  WriteFileAtomically(path, bytes, notes, errorNumber);
  if (progress)
  {
    progress(1.0);
  }
  return active;
}

} // namespace vdb
} // namespace nimbus
