// Fuzz test of the OpenVDB reader (IO/): a small valid .vdb (four grids, a few KB) is read
// cut at EVERY length, and with random byte flips (fixed seed). Each mutant must end in a
// clean error (an error message, status 0, an empty output) or a valid output (status 0
// errors, the dimensions of the extent, every array complete, non-finite values reported
// in a warning): never a crash, an abort, a hang or unbounded memory.
//
// The mutants are read in child processes (fork), a batch per child, each child under an
// address-space limit (RLIMIT_AS, 2 GiB: a corrupt count that made OpenVDB allocate 17.5 GB
// ends in std::bad_alloc, caught by the reader) and a time bound (alarm). A child writes
// "start <i>" before and "<outcome> <i>" after each mutant to a log, so a crash names the
// mutant that caused it.
#include "vtkNimbusOpenVDBReader.h"

#include "vtkCallbackCommand.h"
#include "vtkCommand.h"
#include "vtkDataArray.h"
#include "vtkExecutive.h"
#include "vtkImageData.h"
#include "vtkNew.h"
#include "vtkPointData.h"

#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>

#include "MessageCatcher.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>
#include <vector>

namespace
{
using nimbus::testing::MessageCatcher;

constexpr uint64_t AddressSpaceLimit = uint64_t(2) << 30; // 2 GiB
constexpr unsigned SecondsPerChild = 60;                  // time bound of one batch
constexpr int FlipMutants = 400;
constexpr uint32_t Seed = 20261128;

std::string TempDir()
{
  static std::string dir;
  if (dir.empty())
  {
    char pattern[] = "/tmp/nimbus-vdb-fuzz-XXXXXX";
    dir = mkdtemp(pattern);
  }
  return dir;
}

/// Mutant files live in memory (/dev/shm) when it exists: they are rewritten thousands of times.
std::string MutantDir()
{
  struct stat st;
  static const std::string dir = (::stat("/dev/shm", &st) == 0 && S_ISDIR(st.st_mode))
    ? std::string(
        mkdtemp(const_cast<char*>(std::string("/dev/shm/nimbus-vdb-fuzz-XXXXXX").c_str())))
    : TempDir();
  return dir;
}

std::vector<char> ReadBytes(const std::string& path)
{
  std::ifstream in(path, std::ios::binary);
  return std::vector<char>((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

void WriteBytes(const std::string& path, const std::vector<char>& bytes, size_t n)
{
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(n));
}

/// The seed file: a fog-volume float grid (a 6^3 block), a Vec3s grid, a double grid with
/// a background of -3 and a bool grid (unsupported: skipped with a warning), Blosc-compressed
/// as OpenVDB writes by default.
std::string MakeSeedFile()
{
  openvdb::initialize();
  auto density = openvdb::FloatGrid::create(0.0f);
  density->setName("density");
  density->setGridClass(openvdb::GRID_FOG_VOLUME);
  density->setTransform(openvdb::math::Transform::createLinearTransform(0.5));
  for (int k = 0; k < 6; ++k)
    for (int j = 0; j < 6; ++j)
      for (int i = 0; i < 6; ++i)
        density->tree().setValue(openvdb::Coord(i, j, k), 0.1f * float(1 + (i * j + k) % 7));
  auto velocity = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
  velocity->setName("velocity");
  velocity->setTransform(openvdb::math::Transform::createLinearTransform(0.5));
  for (int i = 0; i < 5; ++i)
    velocity->tree().setValue(
      openvdb::Coord(i, 2 * i % 5, 3), openvdb::Vec3s(float(i), -1.0f, 2.5f));
  auto temperature = openvdb::DoubleGrid::create(-3.0);
  temperature->setName("temperature");
  temperature->setTransform(openvdb::math::Transform::createLinearTransform(0.5));
  temperature->tree().setValue(openvdb::Coord(1, 1, 1), 280.5);
  temperature->tree().setValue(openvdb::Coord(4, 0, 2), 290.25);
  auto mask = openvdb::BoolGrid::create(false);
  mask->setName("mask");
  mask->tree().setValue(openvdb::Coord(2, 2, 2), true);
  const std::string path = TempDir() + "/seed.vdb";
  openvdb::io::File file(path);
  file.write(openvdb::GridPtrVec{ density, velocity, temperature, mask });
  file.close();
  return path;
}

/// Reads `path` and classifies the outcome: "error" (clean error), "valid" (clean output)
/// or "BAD: <why>".
std::string Classify(const std::string& path)
{
  vtkNew<vtkNimbusOpenVDBReader> reader;
  reader->SetFileName(path.c_str());
  MessageCatcher catcher(reader);
  reader->GetExecutive()->AddObserver(vtkCommand::ErrorEvent, vtkNew<vtkCallbackCommand>());
  const int status = reader->GetExecutive()->Update();
  vtkImageData* out = reader->GetOutput();
  const vtkIdType points = out ? out->GetNumberOfPoints() : 0;
  if (!catcher.Errors.empty())
  {
    // An error: the output must be empty. (Update() reports the failure of
    // RequestInformation or RequestData with status 0.)
    if (status != 0)
    {
      return "BAD: error reported but Update() returned 1: " + catcher.Errors.front();
    }
    if (points != 0 || (out && out->GetPointData()->GetNumberOfArrays() != 0))
    {
      return "BAD: error reported but the output is not empty: " + catcher.Errors.front();
    }
    return "error";
  }
  if (status == 0)
  {
    return "BAD: Update() failed without an error message";
  }
  int extent[6];
  out->GetExtent(extent);
  vtkIdType expected = 1;
  for (int c = 0; c < 3; ++c)
  {
    if (extent[2 * c + 1] < extent[2 * c])
    {
      return "BAD: valid output with an empty extent";
    }
    expected *= vtkIdType(extent[2 * c + 1]) - extent[2 * c] + 1;
  }
  if (points != expected || points == 0)
  {
    return "BAD: " + std::to_string(points) + " points for an extent of " +
      std::to_string(expected);
  }
  if (out->GetPointData()->GetNumberOfArrays() == 0)
  {
    return "BAD: valid output without arrays";
  }
  for (int a = 0; a < out->GetPointData()->GetNumberOfArrays(); ++a)
  {
    vtkDataArray* array = out->GetPointData()->GetArray(a);
    if (!array || array->GetNumberOfTuples() != points)
    {
      return "BAD: an array of the wrong length";
    }
    bool finite = true;
    for (vtkIdType i = 0; i < array->GetNumberOfValues() && finite; ++i)
    {
      finite = std::isfinite(array->GetComponent(
        i / array->GetNumberOfComponents(), static_cast<int>(i % array->GetNumberOfComponents())));
    }
    const std::string warnings = catcher.AllWarnings();
    if (!finite && warnings.find("NaN") == std::string::npos &&
      warnings.find("infinite") == std::string::npos)
    {
      return std::string("BAD: non-finite values in '") + array->GetName() + "' not reported";
    }
  }
  return "valid";
}

/// A truncation (Cut >= 0: the first Cut bytes) or a set of byte flips (Cut < 0).
struct Mutant
{
  std::string Kind; // "cut at N" or "flip <byte>^<mask> ..."
  long Cut = -1;
  std::vector<std::pair<size_t, char>> Flips;
};

/// Makes `path` hold mutant `m` of `seed`. Truncations are made by truncate(2) when the
/// file already holds a longer prefix of the seed (the cuts run from long to short), so
/// that 40 000 of them do not write 40 000 files.
void MakeMutant(
  const std::string& path, const std::vector<char>& seed, const Mutant& m, long& prefix)
{
  if (m.Cut >= 0)
  {
    if (prefix < m.Cut)
    {
      WriteBytes(path, seed, seed.size());
    }
    if (::truncate(path.c_str(), m.Cut) != 0)
    {
      std::perror("truncate");
      std::_Exit(3);
    }
    prefix = m.Cut;
    return;
  }
  std::vector<char> bytes = seed;
  for (const auto& flip : m.Flips)
  {
    bytes[flip.first] ^= flip.second;
  }
  WriteBytes(path, bytes, bytes.size());
  prefix = -1;
}

/// Reads mutants [begin, end) in a child process; returns per-mutant outcomes, or a
/// failure text for the mutant that crashed / hung the child.
std::map<int, std::string> RunBatch(const std::vector<char>& seed,
  const std::vector<Mutant>& mutants, int begin, int end, std::string& childFailure, int& last)
{
  const std::string log = TempDir() + "/batch-" + std::to_string(begin) + ".log";
  std::fflush(nullptr);
  const pid_t pid = ::fork();
  if (pid == 0)
  {
    struct rlimit limit;
    limit.rlim_cur = limit.rlim_max = AddressSpaceLimit;
    ::setrlimit(RLIMIT_AS, &limit);
    ::alarm(SecondsPerChild);
    std::FILE* out = std::fopen(log.c_str(), "w");
    const std::string path = MutantDir() + "/mutant.vdb";
    long prefix = -1;
    for (int i = begin; i < end; ++i)
    {
      MakeMutant(path, seed, mutants[i], prefix);
      std::fprintf(out, "start %d\n", i);
      std::fflush(out);
      std::string outcome = Classify(path);
      for (char& c : outcome)
      {
        c = c == '\n' ? ' ' : c;
      }
      std::fprintf(out, "done %d %s\n", i, outcome.c_str());
      std::fflush(out);
    }
    std::fclose(out);
    std::_Exit(0);
  }
  int status = 0;
  ::waitpid(pid, &status, 0);
  std::map<int, std::string> outcomes;
  std::ifstream in(log);
  std::string word;
  last = -1;
  std::string line;
  while (std::getline(in, line))
  {
    std::istringstream fields(line);
    int i = -1;
    fields >> word >> i;
    if (word == "start")
    {
      last = i;
    }
    else if (word == "done")
    {
      std::string rest;
      std::getline(fields, rest);
      outcomes[i] = rest.empty() ? rest : rest.substr(1);
    }
  }
  childFailure.clear();
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
  {
    std::ostringstream why;
    why << "child reading mutants " << begin << ".." << end - 1 << " ";
    if (WIFSIGNALED(status))
    {
      why << "died of signal " << WTERMSIG(status) << " (" << strsignal(WTERMSIG(status)) << ")";
    }
    else
    {
      why << "exited with " << WEXITSTATUS(status);
    }
    why << " while reading mutant " << last << " (" << (last >= 0 ? mutants[last].Kind : "?")
        << ")";
    childFailure = why.str();
  }
  return outcomes;
}

} // namespace

TEST(Fuzz, EveryTruncationAndRandomFlipsEndCleanly)
{
  const auto start = std::chrono::steady_clock::now();
  const std::string seedPath = MakeSeedFile();
  const std::vector<char> seed = ReadBytes(seedPath);
  ASSERT_GT(seed.size(), 500u);
  ASSERT_LT(seed.size(), 65536u) << "the seed file should be small";
  // The seed itself reads.
  ASSERT_EQ(Classify(seedPath), "valid");

  // Every truncation, longest first (see MakeMutant), then the flips.
  std::vector<Mutant> mutants;
  for (long n = static_cast<long>(seed.size()) - 1; n >= 0; --n)
  {
    Mutant cut;
    cut.Kind = "cut at " + std::to_string(n);
    cut.Cut = n;
    mutants.push_back(cut);
  }
  // FUZZ_SEED and FUZZ_FLIPS override the seed and the number of flip mutants (longer
  // runs by hand; FUZZ_FLIPS_ONLY=1 skips the truncations).
  const uint32_t seedNumber =
    std::getenv("FUZZ_SEED") ? uint32_t(std::atol(std::getenv("FUZZ_SEED"))) : Seed;
  const int flipMutants =
    std::getenv("FUZZ_FLIPS") ? std::atoi(std::getenv("FUZZ_FLIPS")) : FlipMutants;
  if (std::getenv("FUZZ_FLIPS_ONLY"))
  {
    mutants.clear();
  }
  const int cuts = static_cast<int>(mutants.size());
  std::mt19937 random(seedNumber);
  for (int m = 0; m < flipMutants; ++m)
  {
    Mutant mutant;
    mutant.Kind = "flip";
    const int flips = 1 + static_cast<int>(random() % 4);
    for (int f = 0; f < flips; ++f)
    {
      // Half the flips in the first 400 bytes (header, descriptors, grid metadata), where
      // one byte changes counts, sizes and offsets; half anywhere.
      const size_t at =
        (random() % 2) ? random() % std::min<size_t>(400, seed.size()) : random() % seed.size();
      const char mask = static_cast<char>(1 + random() % 255);
      mutant.Flips.emplace_back(at, mask);
      mutant.Kind +=
        " " + std::to_string(at) + "^" + std::to_string(int(static_cast<unsigned char>(mask)));
    }
    mutants.push_back(std::move(mutant));
  }
  // FUZZ_ONLY=<index>: read that one mutant here, in this process (for a debugger).
  if (const char* only = std::getenv("FUZZ_ONLY"))
  {
    const int i = std::atoi(only);
    const std::string path = TempDir() + "/only.vdb";
    long prefix = -1;
    MakeMutant(path, seed, mutants[i], prefix);
    std::cout << mutants[i].Kind << ": " << Classify(path) << "\n";
    return;
  }

  const int batch = 5000;
  std::map<std::string, int> tally;
  int bad = 0;
  std::map<int, std::string> outcomes;
  for (int begin = 0; begin < static_cast<int>(mutants.size());)
  {
    const int end = std::min<int>(begin + batch, static_cast<int>(mutants.size()));
    std::string failure;
    int last = -1;
    const auto some = RunBatch(seed, mutants, begin, end, failure, last);
    outcomes.insert(some.begin(), some.end());
    if (!failure.empty())
    {
      // The child died on mutant `last`: that one is bad, the batch goes on after it.
      outcomes[last] = "BAD: " + failure;
      begin = std::max(last + 1, begin + 1);
      continue;
    }
    begin = end;
  }
  for (int i = 0; i < static_cast<int>(mutants.size()); ++i)
  {
    const auto found = outcomes.find(i);
    const std::string outcome = found == outcomes.end() ? "BAD: no outcome" : found->second;
    const std::string kind = i < cuts ? "cut" : "flip";
    if (outcome.compare(0, 3, "BAD") == 0)
    {
      ++bad;
      ADD_FAILURE() << "mutant " << i << ", " << mutants[i].Kind << ": " << outcome;
      ++tally[kind + " bad"];
    }
    else
    {
      ++tally[kind + " " + outcome];
    }
  }
  const double seconds =
    std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::cout << "seed " << seed.size() << " bytes; " << cuts << " truncations, " << flipMutants
            << " flip mutants (seed " << seedNumber << "); address-space limit "
            << (AddressSpaceLimit >> 20) << " MiB; " << seconds << " s\n";
  for (const auto& t : tally)
  {
    std::cout << "  " << t.first << ": " << t.second << "\n";
  }
  EXPECT_EQ(bad, 0);
  // Every truncation is an error (a cut file must never read as valid).
  EXPECT_EQ(tally["cut valid"], 0);
  EXPECT_EQ(tally["cut error"], cuts);
  EXPECT_EQ(tally["flip error"] + tally["flip valid"], flipMutants);
}
