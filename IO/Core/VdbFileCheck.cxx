#include "VdbFileCheck.h"

#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>

#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstring>
#include <exception>
#include <mutex>
#include <new>
#include <poll.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#if defined(__SANITIZE_ADDRESS__)
#define NIMBUS_UNDER_ADDRESS_SANITIZER 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define NIMBUS_UNDER_ADDRESS_SANITIZER 1
#endif
#endif

namespace nimbus
{
namespace vdb
{
namespace
{

/// The child: read everything, report on the pipe, never return.
[[noreturn]] void ReadEverythingAndExit(const std::string& path, uint64_t memoryLimitBytes, int out)
{
#ifndef NIMBUS_UNDER_ADDRESS_SANITIZER
  if (memoryLimitBytes > 0)
  {
    rlimit limit{};
    getrlimit(RLIMIT_AS, &limit);
    if (limit.rlim_cur == RLIM_INFINITY || limit.rlim_cur > memoryLimitBytes)
    {
      limit.rlim_cur = static_cast<rlim_t>(memoryLimitBytes);
      setrlimit(RLIMIT_AS, &limit);
    }
  }
#else
  (void)memoryLimitBytes;
#endif
  // No core files from a damaged input.
  rlimit noCore{ 0, 0 };
  setrlimit(RLIMIT_CORE, &noCore);
  std::string message;
  int status = 0;
  try
  {
    openvdb::io::File file(path);
    file.open(/*delayLoad=*/false);
    const openvdb::GridPtrVecPtr grids = file.getGrids();
    file.close();
    status = grids ? 0 : 1;
    if (!grids)
    {
      message = "OpenVDB read no grids";
    }
  }
  catch (const std::bad_alloc&)
  {
    message = "OpenVDB asked for more memory than the limit while reading it";
    status = 2;
  }
  catch (const std::exception& error)
  {
    message = error.what();
    status = 1;
  }
  catch (...)
  {
    message = "OpenVDB failed with an unknown exception";
    status = 1;
  }
  if (!message.empty())
  {
    const ssize_t written = write(out, message.data(), message.size());
    (void)written;
  }
  _exit(status);
}

} // namespace

FileCheck CheckFileInChildProcess(
  const std::string& path, uint64_t memoryLimitBytes, double timeoutSeconds)
{
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });
  FileCheck result;
  const std::string file = "'" + path + "'";
  int pipeEnds[2];
  if (pipe(pipeEnds) != 0)
  {
    result.Message = "cannot check " + file + ": pipe failed: " + std::strerror(errno);
    return result;
  }
  std::fflush(nullptr);
  const pid_t child = fork();
  if (child < 0)
  {
    close(pipeEnds[0]);
    close(pipeEnds[1]);
    result.Message = "cannot check " + file + ": fork failed: " + std::strerror(errno);
    return result;
  }
  if (child == 0)
  {
    close(pipeEnds[0]);
    ReadEverythingAndExit(path, memoryLimitBytes, pipeEnds[1]);
  }
  close(pipeEnds[1]);

  // Collect the child's message until it closes the pipe (exits) or the time is up.
  std::string message;
  bool timedOut = false;
  const auto deadline = std::chrono::steady_clock::now() +
    std::chrono::milliseconds(static_cast<int64_t>(timeoutSeconds * 1000.0));
  for (;;)
  {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
      deadline - std::chrono::steady_clock::now())
                        .count();
    if (left <= 0)
    {
      timedOut = true;
      break;
    }
    pollfd wait{ pipeEnds[0], POLLIN, 0 };
    const int ready = poll(&wait, 1, static_cast<int>(std::min<int64_t>(left, 1000)));
    if (ready < 0 && errno == EINTR)
    {
      continue;
    }
    if (ready <= 0)
    {
      continue;
    }
    char buffer[512];
    const ssize_t got = read(pipeEnds[0], buffer, sizeof(buffer));
    if (got > 0)
    {
      message.append(buffer, static_cast<std::size_t>(got));
      continue;
    }
    if (got < 0 && errno == EINTR)
    {
      continue;
    }
    break; // end of file: the child exited
  }
  close(pipeEnds[0]);
  if (timedOut)
  {
    kill(child, SIGKILL);
  }
  int status = 0;
  while (waitpid(child, &status, 0) < 0 && errno == EINTR)
  {
  }
  if (timedOut)
  {
    result.Message = "reading " + file + " took longer than " +
      std::to_string(static_cast<int>(timeoutSeconds)) +
      " s in the check process; a damaged file can make OpenVDB loop (raise the check's "
      "time limit for a very large file)";
    return result;
  }
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0)
  {
    result.Passed = true;
    return result;
  }
  if (WIFEXITED(status) && WEXITSTATUS(status) == 2)
  {
    result.Message = file + " is damaged or too large: " + message;
  }
  else if (WIFEXITED(status) && WEXITSTATUS(status) == 1 && !message.empty())
  {
    result.Message = file + " is damaged: OpenVDB could not read it: " + message;
  }
  else if (WIFSIGNALED(status))
  {
    result.Message = file + " is damaged: reading it crashed OpenVDB (" +
      std::string(strsignal(WTERMSIG(status))) +
      ") in a separate check process, so it was not read here";
  }
  else
  {
    result.Message = file + " is damaged: reading it failed in a separate check process (exit " +
      std::to_string(WIFEXITED(status) ? WEXITSTATUS(status) : -1) + ")";
  }
  return result;
}

} // namespace vdb
} // namespace nimbus
