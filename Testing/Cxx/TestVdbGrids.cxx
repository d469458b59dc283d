// IO/Core/VdbGrids and VdbFileCheck without VTK, built by the sanitizer build
// (Testing/Sanitizers): a round trip of two fields, then truncated and byte-flipped
// copies of the file, each read as the reader reads it (layout scan, then OpenVDB with
// the checked chunk readers) inside a child process whose stderr is kept, so that
// AddressSanitizer and UndefinedBehaviorSanitizer watch every OpenVDB call Nimbus makes
// on damaged input. Each read must end in a clean error or in a read of the right size;
// any sanitizer report fails the test. Then the separate-process check that the reader
// falls back on where the chunk readers are not the checked ones.
#include "VdbArchive.h"
#include "VdbFileCheck.h"
#include "VdbGrids.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <sys/wait.h>
#include <unistd.h>
#include <vector>

namespace
{
using nimbus::vdb::FieldToWrite;
using nimbus::vdb::IndexBox;

std::string TemporaryPath(const std::string& name)
{
  return ::testing::TempDir() + "nimbus_vdbgrids_" + std::to_string(getpid()) + "_" + name;
}

std::vector<char> ReadBytes(const std::string& path)
{
  std::ifstream in(path, std::ios::binary);
  return std::vector<char>(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void WriteBytes(const std::string& path, const std::vector<char>& bytes, std::size_t length)
{
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(length));
}

/// A 12x10x8 density (a ball, zero outside) and a velocity field on the same box.
struct SmallFile
{
  IndexBox Box;
  std::vector<float> Density;
  std::vector<float> Velocity;

  SmallFile()
  {
    Box.Min = { { -3, 0, 2 } };
    Box.Max = { { 8, 9, 9 } };
    const uint64_t n = Box.VoxelCount();
    Density.assign(n, 0.0f);
    Velocity.assign(3 * n, 0.0f);
    uint64_t index = 0;
    for (int64_t k = Box.Min[2]; k <= Box.Max[2]; ++k)
    {
      for (int64_t j = Box.Min[1]; j <= Box.Max[1]; ++j)
      {
        for (int64_t i = Box.Min[0]; i <= Box.Max[0]; ++i, ++index)
        {
          const double r2 = (i - 2.5) * (i - 2.5) + (j - 4.5) * (j - 4.5) + (k - 6.0) * (k - 6.0);
          Density[index] = r2 < 16.0 ? static_cast<float>(1.0 - r2 / 16.0) : 0.0f;
          Velocity[3 * index] = static_cast<float>(i);
          Velocity[3 * index + 1] = static_cast<float>(j);
          Velocity[3 * index + 2] = Density[index];
        }
      }
    }
  }

  std::vector<FieldToWrite> Fields() const
  {
    FieldToWrite density;
    density.Name = "density";
    density.Values = Density.data();
    density.Box = Box;
    density.Transform.Spacing = { { 0.5, 0.5, 0.5 } };
    density.FogVolume = true;
    FieldToWrite velocity = density;
    velocity.Name = "vel";
    velocity.Components = 3;
    velocity.Values = Velocity.data();
    velocity.FogVolume = false;
    return { density, velocity };
  }
};

/// Reads every supported grid of `path` as the reader does; returns false when the read
/// ended in nimbus::vdb::Error. Sizes above 2^24 voxels are not allocated here: a
/// damaged header may promise any size, and the reader's budget is tested elsewhere.
bool ReadAll(const std::string& path, std::string& message)
{
  try
  {
    const auto infos = nimbus::vdb::ReadFileInfo(path);
    for (const auto& info : infos)
    {
      if (!info.Supported() || info.ActiveBox.Empty())
      {
        continue;
      }
      const uint64_t voxels = info.ActiveBox.VoxelCount();
      if (voxels == 0 || voxels > (uint64_t(1) << 24))
      {
        continue;
      }
      std::vector<float> values(voxels * info.Components, -7.0f);
      nimbus::vdb::ReadDense(
        path, { info.Name }, info.Transform, info.ActiveBox, { values.data() });
    }
    return true;
  }
  catch (const nimbus::vdb::Error& error)
  {
    message = error.what();
    return false;
  }
}

enum class Outcome
{
  Read,
  Error,
  Failure
};

/// Reads `path` in a child process; `report` receives the child's stderr on failure.
Outcome ReadInChild(const std::string& path, const std::string& stderrPath, std::string& report)
{
  std::fflush(nullptr);
  const pid_t child = fork();
  if (child == 0)
  {
    if (!std::freopen(stderrPath.c_str(), "w", stderr))
    {
      _exit(4);
    }
    std::string message;
    const bool read = ReadAll(path, message);
    std::fprintf(stderr, "%s\n", message.c_str());
    std::fflush(nullptr);
    _exit(read ? 0 : 3);
  }
  int status = 0;
  waitpid(child, &status, 0);
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0)
  {
    return Outcome::Read;
  }
  if (WIFEXITED(status) && WEXITSTATUS(status) == 3)
  {
    return Outcome::Error;
  }
  std::ifstream in(stderrPath);
  report.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  return Outcome::Failure;
}

TEST(VdbGrids, RoundTripIsExact)
{
  const SmallFile file;
  const std::string path = TemporaryPath("roundtrip.vdb");
  nimbus::vdb::WriteFields(path, file.Fields(), /*compress=*/false);
  const auto infos = nimbus::vdb::ReadFileInfo(path);
  ASSERT_EQ(infos.size(), 2u);
  for (const auto& info : infos)
  {
    const bool isDensity = info.Name == "density";
    const std::vector<float>& expected = isDensity ? file.Density : file.Velocity;
    std::vector<float> values(file.Box.VoxelCount() * info.Components, -7.0f);
    nimbus::vdb::ReadDense(path, { info.Name }, info.Transform, file.Box, { values.data() });
    ASSERT_EQ(values.size(), expected.size()) << info.Name;
    for (std::size_t i = 0; i < values.size(); ++i)
    {
      ASSERT_EQ(values[i], expected[i]) << info.Name << " value " << i;
    }
  }
  std::remove(path.c_str());
}

TEST(VdbGrids, DamagedCopiesEndInErrorsNotCrashes)
{
  const SmallFile file;
  const std::string original = TemporaryPath("original.vdb");
  nimbus::vdb::WriteFields(original, file.Fields(), /*compress=*/true);
  const std::vector<char> bytes = ReadBytes(original);
  ASSERT_GT(bytes.size(), 200u);
  const std::string damaged = TemporaryPath("damaged.vdb");

  const std::string childStderr = TemporaryPath("child.stderr");
  int counts[3] = { 0, 0, 0 };
  const auto readOne = [&](const std::string& what)
  {
    std::string report;
    const Outcome outcome = ReadInChild(damaged, childStderr, report);
    ++counts[static_cast<int>(outcome)];
    EXPECT_NE(outcome, Outcome::Failure) << what << ":\n" << report;
  };
  // 100 truncation lengths spread over the file (every length is the main build's fuzz
  // test's job; here a read in a child costs about 0.1 s).
  for (std::size_t step = 0; step < 100; ++step)
  {
    const std::size_t length = bytes.size() * step / 100 + step % 7;
    WriteBytes(damaged, bytes, length);
    readOne("the file cut to " + std::to_string(length) + " bytes");
  }
  // Byte flips with a fixed seed.
  std::mt19937 random(20261128);
  for (int mutant = 0; mutant < 100; ++mutant)
  {
    std::vector<char> copy = bytes;
    const int flips = 1 + mutant % 4;
    for (int f = 0; f < flips; ++f)
    {
      const std::size_t at = random() % copy.size();
      copy[at] = static_cast<char>(copy[at] ^ (1 << (random() % 8)));
    }
    WriteBytes(damaged, copy, copy.size());
    readOne("mutant " + std::to_string(mutant));
  }
  std::printf("damaged copies: %d read, %d ended in an error\n", counts[0], counts[1]);
  EXPECT_GT(counts[1], 0);
  std::remove(childStderr.c_str());
  std::remove(damaged.c_str());
  std::remove(original.c_str());
}

TEST(VdbGrids, CheckedChunkReadersAreInEffect)
{
  // Linked statically into this program, the checked definitions come first.
  EXPECT_TRUE(nimbus::vdb::CompressionGuardInEffect());
}

TEST(VdbGrids, SeparateProcessCheckPassesValidFilesAndStopsDamagedOnes)
{
  const SmallFile file;
  const std::string original = TemporaryPath("checked.vdb");
  nimbus::vdb::WriteFields(original, file.Fields(), /*compress=*/true);
  const nimbus::vdb::FileCheck valid =
    nimbus::vdb::CheckFileInChildProcess(original, uint64_t(2) << 30, 30.0);
  EXPECT_TRUE(valid.Passed) << valid.Message;
  EXPECT_EQ(valid.Message, "");

  const std::vector<char> bytes = ReadBytes(original);
  const std::string damaged = TemporaryPath("checked_damaged.vdb");
  // (The check is not a validation: a 10-byte stub passes it, as OpenVDB reads no grid
  // from it without failing; the layout scan before it is what refuses such files.)
  for (const std::size_t length : { std::size_t(0), bytes.size() / 2, bytes.size() - 100 })
  {
    WriteBytes(damaged, bytes, length);
    const nimbus::vdb::FileCheck check =
      nimbus::vdb::CheckFileInChildProcess(damaged, uint64_t(2) << 30, 30.0);
    EXPECT_FALSE(check.Passed) << "cut to " << length << " bytes";
    EXPECT_NE(check.Message.find("is damaged"), std::string::npos) << check.Message;
    EXPECT_NE(check.Message.find(damaged), std::string::npos) << check.Message;
  }
  const nimbus::vdb::FileCheck missing =
    nimbus::vdb::CheckFileInChildProcess(damaged + ".missing", uint64_t(2) << 30, 30.0);
  EXPECT_FALSE(missing.Passed);
  std::remove(damaged.c_str());
  std::remove(original.c_str());
}

} // namespace
