// The one parallel-for (Physics/ParallelFor.h): every index visited exactly once for
// any count, grain and thread count; chunks in increasing order of at most `grain`
// items; exceptions stop new chunks and reach the caller after every thread stopped;
// progress only on the calling thread, non-decreasing, ending at count; results that
// do not depend on the thread count.
#include "ParallelFor.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

namespace
{
using nimbus::ParallelFor;
using nimbus::ResolveThreadCount;

const std::size_t kCounts[] = { 0, 1, 2, 3, 7, 64, 1001 };
const std::size_t kGrains[] = { 0, 1, 3, 64, 100000 };
const int kThreads[] = { 0, 1, 2, 3, 4, 5, 6, 7, 8 };

/// SplitMix64 finaliser: a value per index that takes some work to compute.
std::uint64_t Mix(std::uint64_t z)
{
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}
} // namespace

TEST(ParallelFor, ResolveThreadCount)
{
  EXPECT_EQ(ResolveThreadCount(1), 1);
  EXPECT_EQ(ResolveThreadCount(7), 7);
  const unsigned hardware = std::thread::hardware_concurrency();
  const int expected = hardware > 0 ? static_cast<int>(hardware) : 1;
  EXPECT_EQ(ResolveThreadCount(0), expected);
  EXPECT_EQ(ResolveThreadCount(-3), expected);
}

TEST(ParallelFor, EveryIndexExactlyOnce)
{
  for (const std::size_t count : kCounts)
  {
    for (const std::size_t grain : kGrains)
    {
      for (const int threads : kThreads)
      {
        std::vector<std::atomic<int>> visits(count);
        std::atomic<int> calls{ 0 }, badChunks{ 0 };
        const std::size_t resolved = static_cast<std::size_t>(ResolveThreadCount(threads));
        const std::size_t expectedGrain =
          grain > 0 ? grain : std::max<std::size_t>(1, (count + resolved - 1) / resolved);
        ParallelFor(count, grain, threads,
          [&](std::size_t begin, std::size_t end)
          {
            ++calls;
            // A chunk starts on a multiple of the grain and is full unless it is the last.
            if (!(begin < end && end <= count && begin % expectedGrain == 0 &&
                  (end - begin == expectedGrain || end == count) && end - begin <= expectedGrain))
            {
              ++badChunks;
            }
            for (std::size_t i = begin; i < end && i < count; ++i)
            {
              ++visits[i];
            }
          });
        const std::size_t chunks = count == 0 ? 0 : (count - 1) / expectedGrain + 1;
        EXPECT_EQ(calls.load(), static_cast<int>(chunks))
          << "count " << count << " grain " << grain << " threads " << threads;
        EXPECT_EQ(badChunks.load(), 0)
          << "count " << count << " grain " << grain << " threads " << threads;
        for (std::size_t i = 0; i < count; ++i)
        {
          ASSERT_EQ(visits[i].load(), 1)
            << "index " << i << " count " << count << " grain " << grain << " threads " << threads;
        }
      }
    }
  }
}

TEST(ParallelFor, ChunksAreHandedOutInIncreasingOrder)
{
  // One thread runs the chunks in order; with several, each thread gets its chunks
  // in increasing order.
  for (const int threads : { 1, 2, 4, 8 })
  {
    std::mutex mutex;
    std::vector<std::pair<std::thread::id, std::size_t>> starts;
    ParallelFor(300, 3, threads,
      [&](std::size_t begin, std::size_t)
      {
        std::lock_guard<std::mutex> lock(mutex);
        starts.push_back({ std::this_thread::get_id(), begin });
      });
    ASSERT_EQ(starts.size(), 100u);
    if (threads == 1)
    {
      for (std::size_t c = 0; c < 100; ++c)
      {
        EXPECT_EQ(starts[c].second, 3 * c);
      }
    }
    for (std::size_t a = 0; a < starts.size(); ++a)
    {
      for (std::size_t b = a + 1; b < starts.size(); ++b)
      {
        if (starts[a].first == starts[b].first)
        {
          EXPECT_LT(starts[a].second, starts[b].second) << threads << " threads";
        }
      }
    }
  }
}

TEST(ParallelFor, UsesAtMostTheRequestedThreadsIncludingTheCaller)
{
  for (const int threads : { 1, 2, 3, 4 })
  {
    std::mutex mutex;
    std::vector<std::thread::id> ids;
    std::atomic<bool> callerWorked{ false };
    const std::thread::id caller = std::this_thread::get_id();
    ParallelFor(64, 1, threads,
      [&](std::size_t, std::size_t)
      {
        const std::thread::id id = std::this_thread::get_id();
        if (id == caller)
        {
          callerWorked = true;
        }
        // The workers wait (up to 10 s) for the calling thread to take a chunk, so
        // that they cannot finish every chunk before it starts.
        for (int wait = 0; wait < 10000 && !callerWorked.load(); ++wait)
        {
          std::this_thread::sleep_for(std::chrono::milliseconds(1));
        }
        std::lock_guard<std::mutex> lock(mutex);
        if (std::find(ids.begin(), ids.end(), id) == ids.end())
        {
          ids.push_back(id);
        }
      });
    EXPECT_LE(ids.size(), static_cast<std::size_t>(threads));
    EXPECT_TRUE(callerWorked.load()) << threads << " threads";
  }
  // Never more threads than chunks.
  std::mutex mutex;
  std::vector<std::thread::id> ids;
  ParallelFor(2, 1, 8,
    [&](std::size_t, std::size_t)
    {
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
      std::lock_guard<std::mutex> lock(mutex);
      if (std::find(ids.begin(), ids.end(), std::this_thread::get_id()) == ids.end())
      {
        ids.push_back(std::this_thread::get_id());
      }
    });
  EXPECT_LE(ids.size(), 2u);
}

TEST(ParallelFor, ExceptionReachesTheCallerAfterEveryThreadStopped)
{
  const int count = 100;
  for (const int threads : { 1, 2, 4, 8 })
  {
    for (const int thrower : { 0, 5, count - 1 })
    {
      std::atomic<int> running{ 0 }, visited{ 0 };
      int stillRunningAtCatch = -1;
      try
      {
        ParallelFor(count, 1, threads,
          [&](std::size_t begin, std::size_t)
          {
            ++running;
            ++visited;
            if (static_cast<int>(begin) == thrower)
            {
              --running;
              throw std::runtime_error("chunk " + std::to_string(begin));
            }
            // Slow enough that the other threads are busy when the exception is thrown.
            std::this_thread::sleep_for(std::chrono::milliseconds(5));
            --running;
          });
        ADD_FAILURE() << "no exception, " << threads << " threads";
      }
      catch (const std::runtime_error& error)
      {
        stillRunningAtCatch = running.load();
        EXPECT_EQ(std::string(error.what()), "chunk " + std::to_string(thrower));
      }
      EXPECT_EQ(stillRunningAtCatch, 0) << threads << " threads";
      if (threads == 1)
      {
        EXPECT_EQ(visited.load(), thrower + 1); // nothing after the throwing chunk
      }
      else if (thrower == 0)
      {
        // The other threads stop after a chunk or so each, long before the end (the
        // other chunks take 0.5 s / (threads - 1)).
        EXPECT_LT(visited.load(), count / 2) << threads << " threads";
      }
      // Nothing runs on after the call returned.
      const int after = visited.load();
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
      EXPECT_EQ(visited.load(), after);
    }
  }
}

TEST(ParallelFor, FirstOfSeveralExceptionsIsRethrown)
{
  // Every chunk throws: exactly one exception reaches the caller, one of the chunks'.
  for (const int threads : { 1, 2, 4 })
  {
    try
    {
      ParallelFor(
        50, 1, threads, [&](std::size_t begin, std::size_t) { throw static_cast<int>(begin); });
      ADD_FAILURE() << "no exception";
    }
    catch (int chunk)
    {
      EXPECT_GE(chunk, 0);
      EXPECT_LT(chunk, 50);
      if (threads == 1)
      {
        EXPECT_EQ(chunk, 0);
      }
    }
  }
}

TEST(ParallelFor, ProgressOnTheCallingThreadOnlyMonotoneEndingAtCount)
{
  for (const std::size_t count : kCounts)
  {
    for (const std::size_t grain : { std::size_t(0), std::size_t(1), std::size_t(7) })
    {
      for (const int threads : { 0, 1, 2, 3, 8 })
      {
        const std::thread::id caller = std::this_thread::get_id();
        std::vector<std::size_t> reports;
        bool otherThread = false;
        ParallelFor(
          count, grain, threads,
          [&](std::size_t, std::size_t)
          { std::this_thread::sleep_for(std::chrono::microseconds(20)); },
          [&](std::size_t done)
          {
            otherThread = otherThread || std::this_thread::get_id() != caller;
            reports.push_back(done);
          });
        const std::string where = "count " + std::to_string(count) + " grain " +
          std::to_string(grain) + " threads " + std::to_string(threads);
        EXPECT_FALSE(otherThread) << where;
        if (count == 0)
        {
          EXPECT_TRUE(reports.empty()) << where;
          continue;
        }
        ASSERT_FALSE(reports.empty()) << where;
        EXPECT_TRUE(std::is_sorted(reports.begin(), reports.end())) << where;
        EXPECT_EQ(reports.back(), count) << where;
        EXPECT_GT(reports.front(), 0u) << where;
        // progress(count) comes once.
        EXPECT_EQ(std::count(reports.begin(), reports.end(), count), 1) << where;
      }
    }
  }
}

TEST(ParallelFor, ProgressExceptionStopsTheLoop)
{
  std::atomic<int> chunks{ 0 };
  EXPECT_THROW(ParallelFor(
                 100, 1, 1, [&](std::size_t, std::size_t) { ++chunks; },
                 [&](std::size_t done)
                 {
                   if (done == 10)
                   {
                     throw std::runtime_error("cancelled");
                   }
                 }),
    std::runtime_error);
  EXPECT_EQ(chunks.load(), 10);
}

TEST(ParallelFor, ResultDoesNotDependOnTheThreadCount)
{
  // Per-index values (each written by exactly one body call) and a reduction over
  // them in index order: bit-identical for every thread count and grain.
  const std::size_t count = 10007;
  auto compute = [&](int threads, std::size_t grain)
  {
    std::vector<double> values(count, 0.0);
    ParallelFor(count, grain, threads,
      [&](std::size_t begin, std::size_t end)
      {
        for (std::size_t i = begin; i < end; ++i)
        {
          double x = 0.0;
          for (std::uint64_t k = 0; k < 20; ++k)
          {
            x += std::sin(static_cast<double>(Mix(i * 31 + k) >> 11) * 0x1.0p-53 * 6.0);
          }
          values[i] = x;
        }
      });
    return values;
  };
  const std::vector<double> reference = compute(1, 1);
  double sum = 0.0;
  for (const double v : reference)
  {
    sum += v;
  }
  for (const int threads : { 0, 2, 3, 8 })
  {
    for (const std::size_t grain : { std::size_t(0), std::size_t(1), std::size_t(13) })
    {
      const std::vector<double> values = compute(threads, grain);
      EXPECT_EQ(values, reference) << threads << " threads, grain " << grain;
      double s = 0.0;
      for (const double v : values)
      {
        s += v;
      }
      EXPECT_EQ(s, sum);
    }
  }
}
