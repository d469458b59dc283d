// VdbArchive: the byte-level side of Nimbus's .vdb reader and writer, in plain C++ (no VTK,
// no OpenVDB in this header).
//
//  * ScanFile checks a .vdb file's layout BEFORE OpenVDB reads it: the header, the file
//    metadata, every grid descriptor and its byte offsets (GridDescriptor's grid, block and
//    end positions) against the file's size, and every length field of each grid's metadata
//    against the grid's own bytes. A truncated file (an interrupted download or copy) is
//    reported with the byte where it ends and the byte its header promised; a corrupted
//    length or count is refused before anything of that size is allocated.
//  * WriteFileAtomically writes bytes to a temporary file beside the target, checks every
//    write and the size written, fsyncs, keeps the target's permission bits and renames it
//    over the target (through a symbolic link: over the link's target file), so that a
//    failed write (a full disk, a file-size limit) leaves the old file byte for byte.
//
// Errors are thrown as nimbus::vdb::Error (VdbGrids.h) with a message naming the file.
#ifndef NimbusVdbArchive_h
#define NimbusVdbArchive_h

#include <cstdint>
#include <map>
#include <streambuf>
#include <string>
#include <vector>

namespace nimbus
{
namespace vdb
{

/// Where one grid lies in a .vdb file (OpenVDB's GridDescriptor), checked by ScanFile.
struct GridLayout
{
  std::string UniqueName; // as stored: duplicates carry OpenVDB's suffix "\x1e<n>"
  std::string StoredName; // the grid's name (suffix stripped; may repeat, may be empty)
  std::string TypeName;   // e.g. "Tree_float_5_4_3" (without "_HalfFloat")
  std::string ParentName; // instance parent's unique name; empty unless an instance
  bool HalfFloat = false;
  int64_t DescriptorPos = 0; // first byte of the descriptor
  int64_t GridPos = 0;       // metadata, transform and topology start here
  int64_t BlockPos = 0;      // voxel buffers start here
  int64_t EndPos = 0;        // one past the grid's last byte
};

struct FileLayout
{
  uint64_t FileSize = 0;
  uint32_t FormatVersion = 0;
  uint32_t LibraryMajor = 0;
  uint32_t LibraryMinor = 0;
  int64_t HeaderEnd = 0; // one past the file header (magic .. UUID)
  std::vector<GridLayout> Grids;
  /// Distinct names, one per grid, in file order: the stored name; a repeated name gets
  /// OpenVDB's own "name[1]", "name[2]"...; an unnamed grid is "unnamed" (then "unnamed[1]"...).
  std::vector<std::string> DistinctNames;
  /// The file-level metadata entries of type "string" (up to 4096 bytes each), as stored:
  /// e.g. "creator" (Houdini, Nimbus's writer) and "up_axis" (Nimbus's writer).
  std::map<std::string, std::string> FileStrings;
};

/// A stream buffer that knows how many bytes are left before the end of its range (the
/// chunk-size checks of VdbCompressionGuard.cxx ask).
class BoundedBuf : public std::streambuf
{
public:
  virtual int64_t Remaining() const = 0;
};

/// A stream buffer over bytes [base, base + size) of a file held in memory: reads and seeks
/// outside that range fail (with the stream's exceptions on: throw), so OpenVDB cannot read
/// past a grid's end, or past the end of a truncated file, without noticing. Remaining()
/// tells the chunk-size checks of VdbCompressionGuard.cxx how many bytes are left.
class SpanBuf : public BoundedBuf
{
public:
  SpanBuf(std::vector<char>& bytes, int64_t base);
  int64_t Remaining() const override { return this->egptr() - this->gptr(); }

protected:
  pos_type seekoff(
    off_type off, std::ios_base::seekdir dir, std::ios_base::openmode which) override;
  pos_type seekpos(pos_type pos, std::ios_base::openmode which) override;

private:
  int64_t Base;
};

/// The same bounds over bytes [begin, end) of a file read as they are asked for, through a
/// window of at most `window` bytes: seeking over bytes does not read them, so a grid's
/// clipped read (OpenVDB skips the buffers of the leaves outside its box) reads from the
/// file only the leaves it keeps. A file that ends before `end` (it shrank since ScanFile)
/// makes the read fail.
class FileRangeBuf : public BoundedBuf
{
public:
  FileRangeBuf(const std::string& path, int64_t begin, int64_t end, int64_t window = 1 << 20);
  ~FileRangeBuf() override;
  FileRangeBuf(const FileRangeBuf&) = delete;
  FileRangeBuf& operator=(const FileRangeBuf&) = delete;
  int64_t Remaining() const override { return this->End - this->Position(); }
  /// Bytes read from the file so far.
  int64_t BytesRead() const { return this->Read; }

protected:
  int_type underflow() override;
  pos_type seekoff(
    off_type off, std::ios_base::seekdir dir, std::ios_base::openmode which) override;
  pos_type seekpos(pos_type pos, std::ios_base::openmode which) override;

private:
  int64_t Position() const { return this->WindowStart + (this->gptr() - this->eback()); }
  int Descriptor = -1;
  int64_t Begin, End;
  int64_t WindowStart;
  int64_t Read = 0;
  std::vector<char> Window;
};

/// Checks the layout of `path` (see above). Throws Error with a message that says what is
/// wrong and where: "'x.vdb': the file ends at byte N but its grid 'density' needs bytes up
/// to M: the file is truncated (an interrupted download or copy?)".
FileLayout ScanFile(const std::string& path);

/// True when OpenVDB's chunk readers in this process are the checked ones of
/// VdbCompressionGuard.cxx: OpenVDB 10.0.x, and this library was loaded before libopenvdb
/// (so libopenvdb's own calls bind to them). False when another module loaded libopenvdb
/// first (e.g. `import pyopenvdb` before Nimbus in one Python process) or for another
/// OpenVDB version; the reader then lets a separate process read each file first
/// (VdbFileCheck.h).
bool CompressionGuardInEffect();

/// Writes `bytes` to `path` atomically (see above). Throws Error on failure, leaving an
/// existing file untouched; the message names the cause ("No space left on device", "File
/// too large", "Permission denied"). A target whose permission bits grant no write access
/// (chmod a-w), or that this user may not write, is refused as vtkXMLWriter refuses it (its
/// ofstream cannot open it), also when running as root. `notes` receives what a caller
/// should warn about (a target with other hard links: they keep the old content).
/// `errorNumber` receives errno of the failure (0 when the failure has none).
void WriteFileAtomically(const std::string& path, const std::string& bytes,
  std::vector<std::string>* notes = nullptr, int* errorNumber = nullptr);

} // namespace vdb
} // namespace nimbus

#endif
