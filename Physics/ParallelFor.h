// The one parallel-for of Nimbus: std::thread only (no TBB, no VTK), used by the sky
// tables, the cloud automaton and the reference renderers.
//
// ParallelFor(count, grain, threads, body) runs body(begin, end) on the chunks
// [0, g), [g, 2g), ... of [0, count) (g = grain, the last chunk shorter). Chunks are
// handed out dynamically in increasing order to min(threads, chunks) threads, the
// calling thread being one of them; each chunk is run by exactly one body call. So a
// body that writes only the outputs of its own items, from inputs that do not depend
// on the order of the calls, gives results that do not depend on the thread count
// (bit-identical). Scratch space that must not be shared is created by the body (per
// chunk) or indexed by item.
//
// Exceptions: once a body (or the progress callback) has thrown and the exception has
// been caught, no thread starts a new chunk (one claimed in the meantime may still
// run); chunks already running finish; after every thread has stopped, the first
// exception caught is rethrown on the calling thread.
//
// Progress: progress(itemsDone) is called on the calling thread only, never from a
// worker: after each chunk the calling thread finishes, with the number of items of
// all the chunks finished so far (non-decreasing), and, after every thread has
// stopped, with count unless the last call already had it. So the last call is
// progress(count); there is none when count is 0, and none at the end when a body threw.
#ifndef nimbus_ParallelFor_h
#define nimbus_ParallelFor_h

#include "NimbusPhysicsExport.h" // for export macro

#include <cstddef>
#include <functional>

namespace nimbus
{

/// The number of threads to use: threads if > 0, else std::thread::hardware_concurrency()
/// (1 if unknown). Always >= 1.
NIMBUSPHYSICS_EXPORT int ResolveThreadCount(int threads);

/// Runs body(begin, end) over [0, count) in chunks of at most `grain` items (0: one
/// chunk per thread, i.e. count / ResolveThreadCount(threads) rounded up) on
/// ResolveThreadCount(threads) threads at most, the calling thread included. See the
/// file comment for the order, exceptions and progress.
NIMBUSPHYSICS_EXPORT void ParallelFor(std::size_t count, std::size_t grain, int threads,
  const std::function<void(std::size_t begin, std::size_t end)>& body,
  const std::function<void(std::size_t itemsDone)>& progress = nullptr);

} // namespace nimbus

#endif
