// VdbArchive: layout checks of .vdb files and atomic writes (see VdbArchive.h).
#include "VdbArchive.h"

#include "VdbGrids.h"

#include <openvdb/Metadata.h>
#include <openvdb/openvdb.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <climits>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <fstream>
#include <map>
#include <memory>
#include <set>
#include <sys/stat.h>
#include <unistd.h>

namespace nimbus
{
namespace vdb
{
namespace
{

std::string Quote(const std::string& s)
{
  return "'" + s + "'";
}

/// Printable form of a name read from a file (control bytes as \xNN, at most 80 bytes).
std::string Printable(const std::string& s)
{
  std::string out;
  for (size_t i = 0; i < s.size() && i < 80; ++i)
  {
    const unsigned char c = static_cast<unsigned char>(s[i]);
    if (c < 32 || c >= 127)
    {
      char hex[8];
      std::snprintf(hex, sizeof(hex), "\\x%02x", c);
      out += hex;
    }
    else
    {
      out += static_cast<char>(c);
    }
  }
  return s.size() > 80 ? out + "..." : out;
}

/// Bounded reads of a file: every read is checked against the file's size (and, for
/// lengths read from the file, against the end of the section they belong to).
class ByteReader
{
public:
  ByteReader(const std::string& path, uint64_t size)
    : Path(path)
    , Size(size)
    , In(path, std::ios::binary)
  {
    if (!this->In)
    {
      throw Error("cannot open " + Quote(path) + " for reading: " + std::strerror(errno));
    }
  }

  uint64_t Pos = 0;

  /// `what` names the part being read, for the message ("its header", "its grid 'x'").
  void Read(void* out, uint64_t n, const std::string& what)
  {
    this->Need(n, what);
    this->In.seekg(static_cast<std::streamoff>(this->Pos));
    this->In.read(static_cast<char*>(out), static_cast<std::streamsize>(n));
    if (static_cast<uint64_t>(this->In.gcount()) != n)
    {
      throw Error("cannot read " + Quote(this->Path) + " at byte " + std::to_string(this->Pos) +
        ": " + std::strerror(errno));
    }
    this->Pos += n;
  }

  void Need(uint64_t n, const std::string& what) const
  {
    if (n > this->Size || this->Pos > this->Size - n)
    {
      throw Error(this->Truncated(this->Pos + n, what));
    }
  }

  std::string Truncated(uint64_t needed, const std::string& what) const
  {
    return Quote(this->Path) + ": the file ends at byte " + std::to_string(this->Size) + " but " +
      what + " needs bytes up to " + std::to_string(needed) +
      ": the file is truncated (an interrupted download or copy?)";
  }

  template <typename T>
  T Value(const std::string& what)
  {
    T v{};
    this->Read(&v, sizeof(T), what);
    return v;
  }

  /// OpenVDB's string: a 32-bit length and the bytes, which must end by `sectionEnd`.
  std::string String(const std::string& what, uint64_t sectionEnd)
  {
    const uint32_t n = this->Value<uint32_t>(what);
    if (this->Pos + n > sectionEnd && sectionEnd < this->Size)
    {
      throw Error(Quote(this->Path) + " is corrupt: a text of " + std::to_string(n) +
        " bytes at byte " + std::to_string(this->Pos - 4) + " in " + what +
        " runs past its end (byte " + std::to_string(sectionEnd) + ")");
    }
    std::string s(n, '\0');
    if (n > 0)
    {
      this->Read(&s[0], n, what);
    }
    return s;
  }

  /// Skips `n` bytes that must end by `sectionEnd`.
  void Skip(uint64_t n, const std::string& what, uint64_t sectionEnd)
  {
    if (n > sectionEnd || this->Pos > sectionEnd - n)
    {
      if (sectionEnd >= this->Size)
      {
        throw Error(this->Truncated(this->Pos + n, what));
      }
      throw Error(Quote(this->Path) + " is corrupt: " + std::to_string(n) + " bytes at byte " +
        std::to_string(this->Pos) + " in " + what + " run past its end (byte " +
        std::to_string(sectionEnd) + ")");
    }
    this->Pos += n;
  }

  const std::string Path;
  const uint64_t Size;

private:
  std::ifstream In;
};

/// A MetaMap (count, then name, type name, byte count and value per entry), every length
/// checked against `end`. With `checkSizes`, values of registered fixed-size types must
/// have exactly their type's size (OpenVDB reads sizeof(T) whatever the count says, so a
/// wrong count would make it read something else than this scan checked). `strings`, when
/// given, receives the entries of type "string" of at most 4096 bytes.
void SkipMetaMap(ByteReader& r, const std::string& what, uint64_t end, bool checkSizes,
  std::map<std::string, std::string>* strings = nullptr)
{
  const uint32_t count = r.Value<uint32_t>(what);
  // Each entry takes at least 12 bytes (three 32-bit lengths).
  if (count > (end - std::min<uint64_t>(end, r.Pos)) / 12)
  {
    if (end >= r.Size)
    {
      throw Error(r.Truncated(r.Pos + uint64_t(count) * 12, what));
    }
    throw Error(Quote(r.Path) + " is corrupt: " + what + " claims " + std::to_string(count) +
      " metadata entries, more than its " + std::to_string(end - r.Pos) + " bytes can hold");
  }
  for (uint32_t i = 0; i < count; ++i)
  {
    const std::string name = r.String(what, end);
    const std::string type = r.String(what, end);
    const uint32_t bytes = r.Value<uint32_t>(what);
    if (checkSizes && type != openvdb::StringMetadata::staticTypeName() &&
      openvdb::Metadata::isRegisteredType(type))
    {
      const openvdb::Metadata::Ptr meta = openvdb::Metadata::createMetadata(type);
      // Variable-size types (string, delayed-load tables) have size 0 when empty.
      if (meta && meta->size() > 0 && meta->size() != bytes)
      {
        throw Error(Quote(r.Path) + " is corrupt: metadata " + Quote(Printable(name)) + " of " +
          what + " has type " + Quote(type) + " (" + std::to_string(meta->size()) +
          " bytes) but says " + std::to_string(bytes) + " bytes");
      }
    }
    const uint64_t valuePos = r.Pos;
    r.Skip(bytes, what, end);
    if (strings && type == openvdb::StringMetadata::staticTypeName() && bytes <= 4096)
    {
      std::string value(bytes, '\0');
      const uint64_t after = r.Pos;
      r.Pos = valuePos;
      if (bytes > 0)
      {
        r.Read(&value[0], bytes, what);
      }
      r.Pos = after;
      (*strings)[name] = value;
    }
  }
}

bool IsUuid(const char* s)
{
  for (int i = 0; i < 36; ++i)
  {
    const bool hyphen = i == 8 || i == 13 || i == 18 || i == 23;
    if (hyphen ? s[i] != '-' : !std::isxdigit(static_cast<unsigned char>(s[i])))
    {
      return false;
    }
  }
  return true;
}

std::string ErrnoText(int e)
{
  return std::strerror(e);
}

} // namespace

SpanBuf::SpanBuf(std::vector<char>& bytes, int64_t base)
  : Base(base)
{
  this->setg(bytes.data(), bytes.data(), bytes.data() + bytes.size());
}

SpanBuf::pos_type SpanBuf::seekoff(
  off_type off, std::ios_base::seekdir dir, std::ios_base::openmode which)
{
  if (!(which & std::ios_base::in))
  {
    return pos_type(off_type(-1));
  }
  const off_type size = this->egptr() - this->eback();
  off_type at = 0;
  if (dir == std::ios_base::beg)
  {
    at = off - this->Base;
  }
  else if (dir == std::ios_base::cur)
  {
    at = (this->gptr() - this->eback()) + off;
  }
  else
  {
    at = size + off;
  }
  if (at < 0 || at > size)
  {
    return pos_type(off_type(-1));
  }
  this->setg(this->eback(), this->eback() + at, this->egptr());
  return pos_type(at + this->Base);
}

SpanBuf::pos_type SpanBuf::seekpos(pos_type pos, std::ios_base::openmode which)
{
  return this->seekoff(off_type(pos), std::ios_base::beg, which);
}

FileRangeBuf::FileRangeBuf(const std::string& path, int64_t begin, int64_t end, int64_t window)
  : Begin(begin)
  , End(end)
  , WindowStart(begin)
  , Window(static_cast<size_t>(std::max<int64_t>(4096, window)))
{
  this->Descriptor = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (this->Descriptor < 0)
  {
    throw Error("cannot open " + Quote(path) + " for reading: " + std::strerror(errno));
  }
  this->setg(this->Window.data(), this->Window.data(), this->Window.data());
}

FileRangeBuf::~FileRangeBuf()
{
  if (this->Descriptor >= 0)
  {
    ::close(this->Descriptor);
  }
}

FileRangeBuf::int_type FileRangeBuf::underflow()
{
  if (this->gptr() < this->egptr())
  {
    return traits_type::to_int_type(*this->gptr());
  }
  const int64_t at = this->Position();
  const int64_t n = std::min<int64_t>(this->End - at, static_cast<int64_t>(this->Window.size()));
  if (n <= 0)
  {
    return traits_type::eof();
  }
  int64_t got = 0;
  while (got < n)
  {
    const ssize_t r = ::pread(this->Descriptor, this->Window.data() + got,
      static_cast<size_t>(n - got), static_cast<off_t>(at + got));
    if (r < 0 && errno == EINTR)
    {
      continue;
    }
    if (r <= 0)
    {
      break; // the file ended early (it shrank): the stream's read fails
    }
    got += r;
  }
  this->Read += got;
  this->WindowStart = at;
  this->setg(this->Window.data(), this->Window.data(), this->Window.data() + got);
  return got > 0 ? traits_type::to_int_type(*this->gptr()) : traits_type::eof();
}

FileRangeBuf::pos_type FileRangeBuf::seekoff(
  off_type off, std::ios_base::seekdir dir, std::ios_base::openmode which)
{
  if (!(which & std::ios_base::in))
  {
    return pos_type(off_type(-1));
  }
  int64_t at = 0;
  if (dir == std::ios_base::beg)
  {
    at = off;
  }
  else if (dir == std::ios_base::cur)
  {
    at = this->Position() + off;
  }
  else
  {
    at = this->End + off;
  }
  if (at < this->Begin || at > this->End)
  {
    return pos_type(off_type(-1));
  }
  const int64_t loaded = this->egptr() - this->eback();
  if (at >= this->WindowStart && at <= this->WindowStart + loaded)
  {
    this->setg(this->eback(), this->eback() + (at - this->WindowStart), this->egptr());
  }
  else
  {
    // Outside the window: nothing read until the next read.
    this->WindowStart = at;
    this->setg(this->Window.data(), this->Window.data(), this->Window.data());
  }
  return pos_type(at);
}

FileRangeBuf::pos_type FileRangeBuf::seekpos(pos_type pos, std::ios_base::openmode which)
{
  return this->seekoff(off_type(pos), std::ios_base::beg, which);
}

FileLayout ScanFile(const std::string& path)
{
  RegisterOpenVdbTypes();
  struct stat st;
  if (::stat(path.c_str(), &st) != 0)
  {
    throw Error("cannot open " + Quote(path) + ": " + std::strerror(errno));
  }
  FileLayout layout;
  layout.FileSize = static_cast<uint64_t>(st.st_size);
  ByteReader r(path, layout.FileSize);
  const std::string header = "its header";
  const int64_t magic = r.Value<int64_t>(header);
  if (magic != openvdb::OPENVDB_MAGIC)
  {
    throw Error(Quote(path) + " is not an OpenVDB file (no 'VDB' magic number at its start)");
  }
  layout.FormatVersion = r.Value<uint32_t>(header);
  const uint32_t v = layout.FormatVersion;
  if (v > openvdb::OPENVDB_FILE_VERSION || v < openvdb::OPENVDB_FILE_VERSION_ROOTNODE_MAP)
  {
    throw Error(Quote(path) + " has OpenVDB file format version " + std::to_string(v) +
      ", which this reader does not read (it reads versions " +
      std::to_string(openvdb::OPENVDB_FILE_VERSION_ROOTNODE_MAP) + " to " +
      std::to_string(openvdb::OPENVDB_FILE_VERSION) + ", OpenVDB " + LibraryVersion() +
      "); the header may be corrupt");
  }
  layout.LibraryMajor = r.Value<uint32_t>(header);
  layout.LibraryMinor = r.Value<uint32_t>(header);
  const char hasOffsets = r.Value<char>(header);
  if (!hasOffsets)
  {
    throw Error(Quote(path) +
      " was written as a stream without grid offsets (openvdb::io::Stream), which this reader "
      "does not read: it checks each grid's byte range before reading it; save it again as a "
      "file (openvdb::io::File, pyopenvdb.write)");
  }
  if (v >= openvdb::OPENVDB_FILE_VERSION_SELECTIVE_COMPRESSION &&
    v < openvdb::OPENVDB_FILE_VERSION_NODE_MASK_COMPRESSION)
  {
    r.Value<char>(header);
  }
  if (v >= openvdb::OPENVDB_FILE_VERSION_BOOST_UUID)
  {
    char uuid[36];
    r.Read(uuid, 36, header);
    if (!IsUuid(uuid))
    {
      throw Error(Quote(path) + " is corrupt: its header's UUID is not valid");
    }
  }
  else
  {
    char uuid[16];
    r.Read(uuid, 16, header);
  }
  layout.HeaderEnd = static_cast<int64_t>(r.Pos);
  SkipMetaMap(
    r, "its header (file metadata)", layout.FileSize, /*checkSizes=*/false, &layout.FileStrings);
  const int32_t count = r.Value<int32_t>("its header (grid count)");
  // A descriptor takes at least 3 lengths and 3 offsets: 36 bytes.
  if (count < 0 || uint64_t(count) > (layout.FileSize - r.Pos) / 36)
  {
    if (count > 0)
    {
      throw Error(r.Truncated(r.Pos + uint64_t(count) * 36,
        "its header (which lists " + std::to_string(count) + " grids)"));
    }
    throw Error(
      Quote(path) + " is corrupt: its header gives a grid count of " + std::to_string(count));
  }
  for (int32_t i = 0; i < count; ++i)
  {
    GridLayout g;
    g.DescriptorPos = static_cast<int64_t>(r.Pos);
    const std::string what = "the description of its grid #" + std::to_string(i + 1) + " of " +
      std::to_string(count) + " (at byte " + std::to_string(r.Pos) + ")";
    g.UniqueName = r.String(what, layout.FileSize);
    g.StoredName = g.UniqueName.substr(0, g.UniqueName.find('\x1e'));
    g.TypeName = r.String(what, layout.FileSize);
    const std::string half = "_HalfFloat";
    if (g.TypeName.size() > half.size() &&
      g.TypeName.compare(g.TypeName.size() - half.size(), half.size(), half) == 0)
    {
      g.HalfFloat = true;
      g.TypeName.resize(g.TypeName.size() - half.size());
    }
    if (!openvdb::GridBase::isRegistered(g.TypeName))
    {
      RegisterOpenVdbTypes(/*everyGridType=*/true); // to list it with its value type
    }
    if (v >= openvdb::OPENVDB_FILE_VERSION_GRID_INSTANCING)
    {
      g.ParentName = r.String(what, layout.FileSize);
    }
    g.GridPos = r.Value<int64_t>(what);
    g.BlockPos = r.Value<int64_t>(what);
    g.EndPos = r.Value<int64_t>(what);
    const std::string grid = "its grid " + Quote(Printable(g.StoredName));
    if (g.GridPos != static_cast<int64_t>(r.Pos) || g.BlockPos < g.GridPos || g.EndPos < g.BlockPos)
    {
      throw Error(Quote(path) + " is corrupt: " + grid + " has inconsistent byte offsets (grid " +
        std::to_string(g.GridPos) + ", voxels " + std::to_string(g.BlockPos) + ", end " +
        std::to_string(g.EndPos) + "; its description ends at byte " + std::to_string(r.Pos) + ")");
    }
    if (static_cast<uint64_t>(g.EndPos) > layout.FileSize)
    {
      throw Error(r.Truncated(static_cast<uint64_t>(g.EndPos), grid));
    }
    // The grid's own header: compression flags, metadata, transform type name.
    const uint64_t blockPos = static_cast<uint64_t>(g.BlockPos);
    if (v >= openvdb::OPENVDB_FILE_VERSION_NODE_MASK_COMPRESSION)
    {
      r.Skip(4, grid, blockPos);
    }
    SkipMetaMap(r, grid + " (metadata)", blockPos, /*checkSizes=*/true);
    if (v >= openvdb::OPENVDB_FILE_VERSION_GRID_INSTANCING)
    {
      const std::string map = r.String(grid + " (transform)", blockPos);
      if (!openvdb::math::MapRegistry::isRegistered(map))
      {
        throw Error(Quote(path) + " is corrupt: " + grid + " has an unknown transform type " +
          Quote(Printable(map)));
      }
    }
    r.Pos = static_cast<uint64_t>(g.EndPos);
    layout.Grids.push_back(std::move(g));
  }
  // Distinct names (OpenVDB's own "name[n]" for repeated names).
  std::set<std::string> taken;
  for (const auto& g : layout.Grids)
  {
    std::string name = g.StoredName.empty() ? std::string("unnamed") : g.StoredName;
    const std::string base = name;
    for (int n = 1; !taken.insert(name).second; ++n)
    {
      name = base + "[" + std::to_string(n) + "]";
    }
    layout.DistinctNames.push_back(name);
  }
  return layout;
}

void WriteFileAtomically(const std::string& path, const std::string& bytes,
  std::vector<std::string>* notes, int* errorNumber)
{
  if (errorNumber)
  {
    *errorNumber = 0;
  }
  auto fail = [&](const std::string& message, int e)
  {
    if (errorNumber)
    {
      *errorNumber = e;
    }
    throw Error(message);
  };
  if (path.empty())
  {
    fail("no file name given", 0);
  }
  // The file to replace: through a symbolic link, the link's target (the link stays).
  std::string target = path;
  struct stat lst;
  struct stat st;
  bool exists = false;
  if (::lstat(path.c_str(), &lst) == 0)
  {
    if (S_ISLNK(lst.st_mode))
    {
      char resolved[PATH_MAX];
      if (!::realpath(path.c_str(), resolved))
      {
        const int e = errno;
        fail("cannot write " + Quote(path) +
            ": it is a symbolic link whose target cannot be "
            "resolved (" +
            ErrnoText(e) + ")",
          e);
      }
      target = resolved;
    }
    if (::stat(target.c_str(), &st) == 0)
    {
      exists = true;
      if (S_ISDIR(st.st_mode))
      {
        fail("cannot write " + Quote(path) + ": it is a directory", EISDIR);
      }
      if (!S_ISREG(st.st_mode))
      {
        fail("cannot write " + Quote(path) + ": it is not a regular file", EINVAL);
      }
      if ((st.st_mode & (S_IWUSR | S_IWGRP | S_IWOTH)) == 0 || ::access(target.c_str(), W_OK) != 0)
      {
        fail("cannot write " + Quote(path) + ": " + ErrnoText(EACCES) +
            " (the file is read-only; it was left as it is)",
          EACCES);
      }
    }
  }
  const std::string tmp = target + ".tmp-" + std::to_string(::getpid());
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
  if (fd < 0)
  {
    const int e = errno;
    fail("cannot write " + Quote(path) + " (temporary " + Quote(tmp) + "): " + ErrnoText(e), e);
  }
  auto abandon = [&](const std::string& what, int e)
  {
    ::close(fd);
    ::unlink(tmp.c_str());
    fail("cannot write " + Quote(path) + ": " + what + ": " + ErrnoText(e) +
        (exists ? " (the existing file was left as it was)" : ""),
      e);
  };
  size_t written = 0;
  while (written < bytes.size())
  {
    const ssize_t n = ::write(fd, bytes.data() + written, bytes.size() - written);
    if (n < 0)
    {
      if (errno == EINTR)
      {
        continue;
      }
      const int e = errno;
      abandon("writing byte " + std::to_string(written) + " of " + std::to_string(bytes.size()), e);
    }
    if (n == 0)
    {
      abandon(
        "writing byte " + std::to_string(written) + " of " + std::to_string(bytes.size()), ENOSPC);
    }
    written += static_cast<size_t>(n);
  }
  if (exists && ::fchmod(fd, st.st_mode & 07777) != 0)
  {
    const int e = errno;
    abandon("keeping the permissions of the existing file", e);
  }
  if (::fsync(fd) != 0)
  {
    const int e = errno;
    abandon("flushing to disk (fsync)", e);
  }
  struct stat tst;
  if (::fstat(fd, &tst) != 0 || static_cast<uint64_t>(tst.st_size) != bytes.size())
  {
    abandon("the temporary file has " + std::to_string(tst.st_size) + " bytes instead of " +
        std::to_string(bytes.size()),
      EIO);
  }
  if (::close(fd) != 0)
  {
    const int e = errno;
    ::unlink(tmp.c_str());
    fail("cannot write " + Quote(path) + ": closing the temporary file: " + ErrnoText(e), e);
  }
  if (exists && st.st_nlink > 1 && notes)
  {
    notes->push_back(Quote(path) + " had " + std::to_string(st.st_nlink) +
      " hard links: the new file replaces this name only; the other names keep the old content");
  }
  if (std::rename(tmp.c_str(), target.c_str()) != 0)
  {
    const int e = errno;
    ::unlink(tmp.c_str());
    fail("cannot rename the written temporary " + Quote(tmp) + " to " + Quote(target) + ": " +
        ErrnoText(e),
      e);
  }
  // Make the rename itself durable (best effort: some file systems refuse fsync on a directory).
  const std::string dir = target.find('/') == std::string::npos
    ? std::string(".")
    : (target.rfind('/') == 0 ? std::string("/") : target.substr(0, target.rfind('/')));
  const int dfd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dfd >= 0)
  {
    ::fsync(dfd);
    ::close(dfd);
  }
}

} // namespace vdb
} // namespace nimbus
