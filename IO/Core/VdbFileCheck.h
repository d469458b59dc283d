// VdbFileCheck: reads a whole .vdb file in a separate process before Nimbus trusts it.
//
// OpenVDB 10.0 trusts the sizes written in a file. A damaged chunk-size field makes
// io::bloscFromStream read up to the rest of the file into a buffer sized for one node
// (it checks the size only after the read: a heap-buffer overflow, found by the
// sanitizer build's fuzz test), and a size read from a truncated stream is uninitialised
// memory, which OpenVDB then tries to allocate (hundreds of terabytes, or 17.5 GB of a
// real machine). Nimbus cannot validate OpenVDB's tree encoding without re-implementing
// it, so it lets OpenVDB read the whole file (topology and voxel buffers) in a forked
// child with an address-space limit and a time limit first: a crash, an abort, an
// exception or an exhausted limit there becomes a clear error in the reader, and the
// process that holds the user's session (ParaView, Python) never runs OpenVDB on a file
// that did not read cleanly. The cost is a second read of the file (measured in
// docs/openvdb.md).
#ifndef NimbusVdbFileCheck_h
#define NimbusVdbFileCheck_h

#include <cstdint>
#include <string>

namespace nimbus
{
namespace vdb
{

struct FileCheck
{
  bool Passed = false;
  /// Why not, in words that name the file: empty when passed.
  std::string Message;
};

/// Reads every grid of `path` with OpenVDB in a child process limited to
/// `memoryLimitBytes` of address space (0: no limit; ignored under AddressSanitizer,
/// which needs terabytes of address space for its shadow memory) and `timeoutSeconds`.
FileCheck CheckFileInChildProcess(
  const std::string& path, uint64_t memoryLimitBytes, double timeoutSeconds);

} // namespace vdb
} // namespace nimbus

#endif
