// Chunk-size checks that OpenVDB 10.0.1 lacks, as replacement definitions of its
// openvdb::io::bloscFromStream and openvdb::io::unzipFromStream.
//
// OpenVDB reads a leaf's values as a 64-bit chunk size followed by the chunk. A negative
// size means "uncompressed, -size bytes", and OpenVDB 10.0.1 reads those bytes into the
// leaf's buffer BEFORE comparing the size with the buffer's: one corrupt byte there makes
// it write past the buffer (a heap overflow, found by Testing/Cxx/TestOpenVDBFuzz.cxx:
// "double free or corruption" a little later). A Blosc chunk's own header is trusted as
// well. These definitions do the same reads with the checks first. libopenvdb calls both
// functions through its PLT (it is not linked with -Bsymbolic), and this library comes
// before libopenvdb in the dynamic linker's search order of every program that links it,
// so these definitions are the ones called, from this library, from OpenVDB's own code
// and from the tests (Testing/Cxx/TestOpenVDB.cxx, Guard.* tests, checks that they are).
// Only for the OpenVDB version they were written against (10.0.x); any other version keeps
// its own functions.
#include "VdbArchive.h"

#include <openvdb/Exceptions.h>
#include <openvdb/io/Compression.h>
#include <openvdb/version.h>

#include <blosc.h>
#include <zlib.h>

#include <cstdint>
#include <cstring>
#include <dlfcn.h>
#include <istream>
#include <limits>
#include <link.h>
#include <memory>

#if OPENVDB_LIBRARY_MAJOR_VERSION_NUMBER == 10 && OPENVDB_LIBRARY_MINOR_VERSION_NUMBER == 0
#define NIMBUS_COMPRESSION_GUARD 1
#endif

namespace
{
/// The position of each loaded object in the dynamic linker's list (load order).
struct LoadOrder
{
  const char* OwnPath = nullptr;
  int Own = -1;
  int OpenVDB = -1;
  int Index = 0;
};

int FindInLoadOrder(dl_phdr_info* info, size_t, void* data)
{
  auto* order = static_cast<LoadOrder*>(data);
  const char* name = info->dlpi_name ? info->dlpi_name : "";
  if (order->Own < 0 && order->OwnPath && std::strcmp(name, order->OwnPath) == 0)
  {
    order->Own = order->Index;
  }
  if (order->OpenVDB < 0 && std::strstr(name, "libopenvdb.so"))
  {
    order->OpenVDB = order->Index;
  }
  ++order->Index;
  return 0;
}
} // namespace

bool nimbus::vdb::CompressionGuardInEffect()
{
#ifdef NIMBUS_COMPRESSION_GUARD
  Dl_info own{};
  if (!dladdr(reinterpret_cast<void*>(&FindInLoadOrder), &own) || !own.dli_fname)
  {
    return false;
  }
  LoadOrder order;
  order.OwnPath = own.dli_fname;
  dl_iterate_phdr(&FindInLoadOrder, &order);
  // Linked statically into the program (the sanitizer build): the program's definitions
  // come first of all. Otherwise this library must precede libopenvdb.
  if (order.Own < 0)
  {
    order.Own = 0;
  }
  return order.OpenVDB < 0 || order.Own < order.OpenVDB;
#else
  return false;
#endif
}

#ifdef NIMBUS_COMPRESSION_GUARD

namespace
{
/// Bytes left in the stream when it reads a grid's own bytes (SpanBuf, FileRangeBuf); -1
/// otherwise.
int64_t Remaining(std::istream& is)
{
  const auto* span = dynamic_cast<const nimbus::vdb::BoundedBuf*>(is.rdbuf());
  return span ? span->Remaining() : -1;
}

/// The chunk size read from the stream, checked: a negative (uncompressed) size must be
/// exactly the buffer's size; any size must fit in the bytes left (when known).
uint64_t CheckedChunk(std::istream& is, int64_t size, size_t numBytes, bool& compressed)
{
  compressed = size > 0;
  const uint64_t bytes = size > 0
    ? uint64_t(size)
    : (size == std::numeric_limits<int64_t>::min() ? std::numeric_limits<uint64_t>::max()
                                                   : uint64_t(-size));
  if (!compressed && bytes != numBytes)
  {
    OPENVDB_THROW(openvdb::RuntimeError,
      "corrupt voxel data: an uncompressed chunk of " << bytes << " bytes where " << numBytes
                                                      << " are expected");
  }
  const int64_t left = Remaining(is);
  if (left >= 0 && bytes > uint64_t(left))
  {
    OPENVDB_THROW(openvdb::RuntimeError,
      "corrupt voxel data: a chunk of " << bytes << " bytes where only " << left
                                        << " are left in the grid");
  }
  return bytes;
}

/// What both chunk readers do first: read and check the chunk size, then skip the chunk
/// (no data wanted) or read an uncompressed one into `data`. Returns the size of a
/// compressed chunk still to be read and expanded, 0 when the chunk is done.
uint64_t ReadChunkUnlessCompressed(std::istream& is, char* data, size_t numBytes)
{
  int64_t size = 0;
  is.read(reinterpret_cast<char*>(&size), 8);
  bool compressed = false;
  const uint64_t bytes = CheckedChunk(is, size, numBytes, compressed);
  if (!data)
  {
    is.seekg(static_cast<std::streamoff>(bytes), std::ios_base::cur);
    return 0;
  }
  if (!compressed)
  {
    is.read(data, static_cast<std::streamsize>(bytes));
    return 0;
  }
  return bytes;
}
}

namespace openvdb
{
OPENVDB_USE_VERSION_NAMESPACE
namespace OPENVDB_VERSION_NAME
{
namespace io
{

void bloscFromStream(std::istream& is, char* data, size_t numBytes)
{
  const uint64_t bytes = ReadChunkUnlessCompressed(is, data, numBytes);
  if (bytes == 0)
  {
    return;
  }
  std::unique_ptr<char[]> chunk(new char[bytes]);
  is.read(chunk.get(), static_cast<std::streamsize>(bytes));
  size_t expanded = 0;
  if (blosc_cbuffer_validate(chunk.get(), bytes, &expanded) != 0 || expanded != numBytes)
  {
    OPENVDB_THROW(RuntimeError,
      "corrupt voxel data: a Blosc chunk that does not expand to " << numBytes << " bytes");
  }
  const int got = blosc_decompress_ctx(chunk.get(), data, numBytes, /*numthreads=*/1);
  if (got < 0 || size_t(got) != numBytes)
  {
    OPENVDB_THROW(
      RuntimeError, "Expected to decompress " << numBytes << " bytes, got " << got << " bytes");
  }
}

void unzipFromStream(std::istream& is, char* data, size_t numBytes)
{
  const uint64_t bytes = ReadChunkUnlessCompressed(is, data, numBytes);
  if (bytes == 0)
  {
    return;
  }
  std::unique_ptr<Bytef[]> chunk(new Bytef[bytes]);
  is.read(reinterpret_cast<char*>(chunk.get()), static_cast<std::streamsize>(bytes));
  uLongf unzipped = static_cast<uLongf>(numBytes);
  const int status =
    uncompress(reinterpret_cast<Bytef*>(data), &unzipped, chunk.get(), static_cast<uLong>(bytes));
  if (status != Z_OK || unzipped != numBytes)
  {
    OPENVDB_THROW(RuntimeError,
      "Expected to decompress " << numBytes << " bytes, got " << unzipped << " bytes (zlib "
                                << status << ")");
  }
}

} // namespace io
} // namespace OPENVDB_VERSION_NAME
} // namespace openvdb

#endif
