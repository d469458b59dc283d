#include "ParallelFor.h"

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <system_error>
#include <thread>
#include <vector>

namespace nimbus
{

int ResolveThreadCount(int threads)
{
  if (threads > 0)
  {
    return threads;
  }
  const unsigned hardware = std::thread::hardware_concurrency();
  return hardware > 0 ? static_cast<int>(hardware) : 1;
}

void ParallelFor(std::size_t count, std::size_t grain, int threads,
  const std::function<void(std::size_t begin, std::size_t end)>& body,
  const std::function<void(std::size_t itemsDone)>& progress)
{
  if (count == 0)
  {
    return;
  }
  const std::size_t resolved = static_cast<std::size_t>(ResolveThreadCount(threads));
  if (grain == 0)
  {
    grain = count / resolved + (count % resolved != 0 ? 1 : 0);
  }
  const std::size_t chunks = (count - 1) / grain + 1;
  const std::size_t used = std::min(resolved, chunks);

  std::atomic<std::size_t> next{ 0 }; // next chunk to hand out
  std::atomic<std::size_t> done{ 0 }; // items of the finished chunks
  std::atomic<bool> failed{ false };
  std::exception_ptr failure;
  std::mutex failureMutex;
  std::size_t reported = 0; // the calling thread's last progress value

  auto work = [&](bool caller)
  {
    try
    {
      while (!failed.load())
      {
        const std::size_t chunk = next.fetch_add(1);
        if (chunk >= chunks || failed.load())
        {
          break;
        }
        const std::size_t begin = chunk * grain;
        const std::size_t end = begin + std::min(grain, count - begin);
        body(begin, end);
        const std::size_t finished = done.fetch_add(end - begin) + (end - begin);
        if (caller && progress)
        {
          reported = finished;
          progress(finished);
        }
      }
    }
    catch (...)
    {
      std::lock_guard<std::mutex> lock(failureMutex);
      if (!failure)
      {
        failure = std::current_exception();
      }
      failed.store(true);
    }
  };

  std::vector<std::thread> pool;
  try
  {
    pool.reserve(used - 1);
    for (std::size_t t = 1; t < used; ++t)
    {
      pool.emplace_back(work, false);
    }
  }
  catch (const std::system_error&)
  {
    // No more threads to be had: the ones started (and the calling thread) do the work.
  }
  work(true); // the calling thread works too and is the only one to report progress
  for (std::thread& thread : pool)
  {
    thread.join();
  }
  if (failure)
  {
    std::rethrow_exception(failure);
  }
  if (progress && reported != count)
  {
    progress(count);
  }
}

} // namespace nimbus
