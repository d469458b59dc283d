// VdbFileCheck: reads a whole .vdb file in a separate process, so that a crash of
// OpenVDB on a damaged file ends that process, not the user's session.
//
// OpenVDB 10.0 trusts the sizes written in a file: a damaged chunk-size field makes
// io::bloscFromStream / unzipFromStream read up to the rest of the file into a buffer
// sized for one node (the size is checked only after the read: a heap-buffer overflow,
// found by the fuzz tests). VdbCompressionGuard.cxx replaces both functions with checked
// ones, which libopenvdb calls when this library was loaded before it. Where that is not
// so (CompressionGuardInEffect() is false: `import pyopenvdb` before Nimbus in one Python
// process, or another OpenVDB version), the reader lets OpenVDB read each file version in
// a forked child first, under an address-space limit and a time limit: a crash, an abort,
// an exception or an exhausted limit there becomes a clear error, and the reading process
// never runs OpenVDB on a file that did not read cleanly. This is not a validation (the
// layout scan, VdbArchive's ScanFile, is): it absorbs crashes. Cost: a second read.
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
