// Fuzzing the scene reader and the reference renderer: a few hundred mutants of the
// project's scenes (Data/Scenes), made with a fixed seed, each either refused with a
// clean message (std::invalid_argument starting with the key path, "scene...") or
// accepted and rendered by vtkNimbusReferenceRenderer (8x6 pixels, a 16^3 density
// grid; single scattering, one pass, then path tracing, one path per pixel) to
// finite pixels. Every mutant runs in a forked child under an address-space limit
// (RLIMIT_AS, 3 GiB) and a time limit (alarm, 20 s): a crash, an abort, an escaping
// exception, a hang, a non-finite pixel or a valid scene that fails to render fails
// the test.
//
// One more base scene adds version 3's lights (point, polyline) and emission to the first
// project scene, and another version 4's spot lights (one through a light map) and
// occluders (a box, a mesh), so that their mutants carry bad values of the new keys. A
// valid mutant whose light map or mesh cannot be read (a mutated path) is refused by the
// renderer with a message naming the key: that counts as a clean refusal.
//
// Mutations: a number scaled by 0, -1, 1e-308 ... 1e300 (often still valid), a value
// replaced by an extreme (0, -1, +-1e308, 1e-308, huge integers,
// 1e400, NaN-ish strings and bare words, wrong types), several values at once, a
// deleted key, a duplicated key, deep nesting (up to 100 000 levels), truncated
// text, random byte flips.
#include "MessageCatcher.h"
#include "SceneJson.h"
#include "vtkNimbusReferenceRenderer.h"

#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkLogger.h"
#include "vtkNew.h"
#include "vtkOutputWindow.h"
#include "vtkPointData.h"
#include "vtkStringOutputWindow.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <regex>
#include <string>
#include <vector>

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#ifndef NIMBUS_SCENES_DIR
#error "NIMBUS_SCENES_DIR must name Data/Scenes"
#endif

namespace
{
namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

constexpr int kMutantsPerScene = 120;
constexpr std::uint64_t kSeed = 20261128;
constexpr unsigned long long kAddressSpaceLimit = 3ull << 30; // 3 GiB
constexpr unsigned kSecondsPerMutant = 20;

enum class Outcome : char
{
  Refused = 'R',    // clean message from the reader
  Rendered = 'P',   // valid, rendered to finite pixels
  OverBudget = 'B', // valid, refused by the renderer's memory budget (a clean message)
  BadMessage = 'M', // refused, but not with a key-path message
  RenderFailed = 'F',
  NonFinite = 'N',
  Escaped = 'E', // an exception left the renderer
  Crashed = 'C', // signal, abort
  TimedOut = 'T',
};

const char* Name(Outcome o)
{
  switch (o)
  {
    case Outcome::Refused:
      return "refused with a message";
    case Outcome::Rendered:
      return "rendered, finite";
    case Outcome::OverBudget:
      return "refused by the memory budget";
    case Outcome::BadMessage:
      return "BAD MESSAGE";
    case Outcome::RenderFailed:
      return "VALID BUT NOT RENDERED";
    case Outcome::NonFinite:
      return "NON-FINITE PIXELS";
    case Outcome::Escaped:
      return "EXCEPTION ESCAPED";
    case Outcome::Crashed:
      return "CRASHED";
    case Outcome::TimedOut:
      return "TIMED OUT";
  }
  return "?";
}

/// The text and the kind of one mutant.
struct Mutant
{
  std::string Kind;
  std::string Text;
};

class Mutator
{
public:
  explicit Mutator(std::uint64_t seed)
    : Random(seed)
  {
  }

  Mutant Make(const Json& base, int index)
  {
    switch (index % 8)
    {
      case 7:
        return { "scale a number", this->Scale(base) };
      case 0:
        return { "replace", this->Replace(base, 1) };
      case 1:
        return { "replace several", this->Replace(base, 2 + this->Below(3)) };
      case 2:
        return { "delete key", this->Delete(base) };
      case 3:
        return { "duplicate key", this->Duplicate(base) };
      case 4:
        return { "deep nesting", this->Nest(base) };
      case 5:
        return { "truncate", this->Truncate(base) };
      default:
        return { "byte flips", this->Flip(base) };
    }
  }

private:
  std::size_t Below(std::size_t n) { return static_cast<std::size_t>(this->Random() % n); }

  /// JSON pointers of every node below the root.
  static void Collect(
    const Json& node, const Json::json_pointer& at, std::vector<Json::json_pointer>& out)
  {
    if (node.is_object())
    {
      for (const auto& item : node.items())
      {
        out.push_back(at / item.key());
        Collect(item.value(), at / item.key(), out);
      }
    }
    else if (node.is_array())
    {
      for (std::size_t i = 0; i < node.size(); ++i)
      {
        out.push_back(at / i);
        Collect(node[i], at / i, out);
      }
    }
  }

  /// Any node below the root; a number every other time (most of a scene's nodes
  /// are numbers, but strings and containers would otherwise take a third).
  Json::json_pointer AnyNode(const Json& j)
  {
    std::vector<Json::json_pointer> nodes;
    Collect(j, Json::json_pointer(), nodes);
    if (this->Below(2) == 0)
    {
      return nodes[this->Below(nodes.size())];
    }
    return AnyNumber(j, nodes);
  }

  Json::json_pointer AnyNumber(const Json& j, const std::vector<Json::json_pointer>& nodes)
  {
    std::vector<Json::json_pointer> numbers;
    for (const auto& p : nodes)
    {
      if (j.at(p).is_number())
      {
        numbers.push_back(p);
      }
    }
    return numbers[this->Below(numbers.size())];
  }

  Json::json_pointer AnyMember(const Json& j)
  {
    std::vector<Json::json_pointer> nodes;
    Collect(j, Json::json_pointer(), nodes);
    std::vector<Json::json_pointer> members;
    for (const auto& p : nodes)
    {
      if (j.at(p.parent_pointer()).is_object())
      {
        members.push_back(p);
      }
    }
    return members[this->Below(members.size())];
  }

  static std::string Substitute(std::string text, const std::string& from, const std::string& to)
  {
    for (std::size_t at = text.find(from); at != std::string::npos;
         at = text.find(from, at + to.size()))
    {
      text.replace(at, from.size(), to);
    }
    return text;
  }

  std::string Extreme()
  {
    static const std::vector<std::string> tokens = { "0", "-1", "1e308", "-1e308", "1e-308",
      "-1e-308", "-0", "4294967296", "2147483648", "9223372036854775807", "18446744073709551615",
      "-9223372036854775809", "123456789012345678901234567890", "1e400", "-1e400", "NaN",
      "Infinity", "-Infinity", "nan", "\"NaN\"", "\"inf\"", "\"-Infinity\"", "\"1e308\"", "true",
      "false", "null", "[]", "{}", "\"\"", "\"text\"", "[1e308, 1e308, 1e308]", "[0, 0, 0]",
      "[-1e308, 1e308, -1e308, 1e308, -1e308, 1e308]", "{\"type\": \"file\"}",
      "[{\"type\": \"henyey_greenstein\", \"g\": 1, \"weight\": 1e308}]" };
    return tokens[this->Below(tokens.size())];
  }

  std::string Replace(const Json& base, std::size_t count)
  {
    Json j = base;
    std::vector<std::string> tokens;
    for (std::size_t k = 0; k < count; ++k)
    {
      const std::string marker = "@@MUTANT" + std::to_string(k) + "@@";
      const Json::json_pointer p = this->AnyNode(j);
      if (j.contains(p)) // an earlier replacement may have removed it
      {
        j[p] = marker;
        tokens.push_back(this->Extreme());
      }
    }
    std::string text = j.dump(2);
    for (std::size_t k = 0; k < tokens.size(); ++k)
    {
      text = Substitute(text, "\"@@MUTANT" + std::to_string(k) + "@@\"", tokens[k]);
    }
    return text;
  }

  /// A number times 0, -1, 1e-308, 1e-3, 1e3, 1e6, 1e9 or 1e300: often still valid,
  /// so the renderer sees extreme but accepted values.
  std::string Scale(const Json& base)
  {
    static const double factors[] = { 0.0, -1.0, 1e-308, 1e-3, 1e3, 1e6, 1e9, 1e300 };
    Json j = base;
    std::vector<Json::json_pointer> nodes;
    Collect(j, Json::json_pointer(), nodes);
    const Json::json_pointer p = this->AnyNumber(j, nodes);
    j[p] = j[p].get<double>() * factors[this->Below(std::size(factors))];
    return j.dump(2);
  }

  std::string Delete(const Json& base)
  {
    Json j = base;
    const Json::json_pointer p = this->AnyMember(j);
    j[p.parent_pointer()].erase(p.back());
    return j.dump(2);
  }

  std::string Duplicate(const Json& base)
  {
    Json j = base;
    const Json::json_pointer p = this->AnyMember(j);
    const std::string key = p.back();
    // The same value or an extreme one, under the same key, after the original.
    j[p.parent_pointer()]["@@DUPLICATE@@"] = this->Below(2) ? j[p] : Json("@@VALUE@@");
    std::string text = j.dump(2);
    text = Substitute(text, "\"@@DUPLICATE@@\"", Json(key).dump());
    return Substitute(text, "\"@@VALUE@@\"", this->Extreme());
  }

  std::string Nest(const Json& base)
  {
    static const std::size_t depths[] = { 2, 30, 62, 63, 64, 65, 1000, 100000 };
    const std::size_t depth = depths[this->Below(std::size(depths))];
    Json j = base;
    j[this->AnyNode(j)] = "@@NEST@@";
    const bool objects = this->Below(2) == 0;
    std::string nested;
    for (std::size_t i = 0; i < depth; ++i)
    {
      nested += objects ? "{\"a\": " : "[";
    }
    nested += "1";
    for (std::size_t i = 0; i < depth; ++i)
    {
      nested += objects ? "}" : "]";
    }
    return Substitute(j.dump(2), "\"@@NEST@@\"", nested);
  }

  std::string Truncate(const Json& base)
  {
    const std::string text = base.dump(2);
    return text.substr(0, this->Below(text.size()));
  }

  std::string Flip(const Json& base)
  {
    std::string text = base.dump(2);
    const std::size_t flips = 1 + this->Below(8);
    for (std::size_t k = 0; k < flips; ++k)
    {
      text[this->Below(text.size())] = static_cast<char>(this->Below(256));
    }
    return text;
  }

  std::mt19937_64 Random;
};

/// A project scene made cheap to render: 8x6 pixels, a 16^3 density grid.
Json Cheap(const fs::path& file)
{
  std::ifstream in(file);
  Json j = Json::parse(in);
  j["camera"]["width"] = 8;
  j["camera"]["height"] = 6;
  Json& parameters = j["medium"]["density"]["parameters"];
  if (parameters.is_object())
  {
    parameters["Dimensions"] = Json::array({ 16, 16, 16 });
  }
  return j;
}

/// A version-3 scene from a project scene: a point light inside the cloud, a lightning
/// channel (polyline) through it to the ground, emission from the density, and emitting
/// smoke as a second medium on the cloud's grid. Its
/// mutants reach the new keys (and bad values of them) as the others reach the old ones.
Json WithVersion3Features(Json j)
{
  j["nimbus_scene"] = 3;
  j["name"] = j["name"].get<std::string>() + "_lit";
  j["medium"]["emission"] = Json::parse(
    R"({"source": "from_density", "radiance_per_metre": 0.001, "temperature_kelvin": 1200})");
  // Smoke: another metaball cloud on the same grid, emitting, with its own phase.
  Json smoke = Json::parse(R"({"density": {"type": "metaball_cloud"}, "extinction_per_density":
    0.02, "single_scattering_albedo": 0.4, "phase": {"type": "henyey_greenstein", "g": 0.3},
    "emission": {"source": "from_density", "radiance_per_metre": 0.002}})");
  smoke["density"]["parameters"] = j["medium"]["density"]["parameters"];
  smoke["density"]["parameters"]["Seed"] = 99;
  j["media"] = Json::array({ smoke });
  j["lights"] = Json::parse(R"([
    {"type": "point", "position": [0, 0, 1500], "intensity": 1e5, "temperature_kelvin": 3000},
    {"type": "polyline", "vertices": [[200, 0, 2500], [150, 40, 1200], [260, 10, 0]],
     "intensity_per_metre": 1000, "temperature_kelvin": 25000}
  ])");
  return j;
}

/// A version-4 scene from a project scene: a searchlight below the cloud through a light
/// map (a 4 x 4 PGM), a streetlight's spot, a box and a mesh (an OBJ post) in their beams.
/// The files are written to `work`, and the scene names them by absolute path.
Json WithVersion4Features(Json j, const fs::path& work)
{
  const fs::path gobo = work / "gobo.pgm", post = work / "post.obj";
  {
    std::ofstream out(gobo, std::ios::binary);
    out << "P5\n4 4\n255\n";
    const unsigned char pixels[16] = { 0, 255, 255, 0, 255, 0, 0, 255, 128, 128, 64, 64, 0, 0, 255,
      255 };
    out.write(reinterpret_cast<const char*>(pixels), sizeof(pixels));
  }
  std::ofstream(post) << "v 0 0 0\nv 30 0 0\nv 30 0 900\nv 0 0 900\nv 0 30 0\nf 1 2 3 4\nf 1 4 5\n";
  j["nimbus_scene"] = 4;
  j["name"] = j["name"].get<std::string>() + "_spots";
  j["lights"] = Json::parse(R"([
    {"type": "spot", "position": [0, -200, 10], "direction": [0, 0.2, 1],
     "cone_angle_degrees": 6, "edge_degrees": 1, "intensity": 1e9, "temperature_kelvin": 5000},
    {"type": "spot", "position": [-300, -2000, 12], "direction": [0, 0, -1],
     "cone_angle_degrees": 40, "intensity": 1e5}
  ])");
  j["lights"][0]["light_map"] = gobo.string();
  j["occluders"] = Json::parse(R"([
    {"type": "box", "min": [-50, -250, 30], "max": [0, -150, 30], "albedo": 0},
    {"type": "mesh", "translate": [-320, -2020, 0], "scale": 0.01, "albedo": 0.4}
  ])");
  j["occluders"][1]["path"] = post.string();
  return j;
}

/// A renderer's error about a file the scene names (a light map or a mesh), which names
/// the scene key ("scene.lights[0].light_map: cannot read ..." from the reader,
/// "scene: occluders[1].path has ..." from the renderer): a clean refusal of a mutant whose
/// path was changed.
bool IsAssetRefusal(const std::string& errors)
{
  static const std::regex key(
    R"(scene(\.|: )(lights\[[0-9]+\]\.light_map|occluders\[[0-9]+\]\.path)[: ])");
  return std::regex_search(errors, key);
}

/// In the child: what happens to one mutant.
std::pair<Outcome, std::string> Judge(const Mutant& mutant, const fs::path& sceneFile)
{
  nimbus::SceneDescription scene;
  try
  {
    scene = nimbus::ParseScene(mutant.Text, NIMBUS_SCENES_DIR);
  }
  catch (const std::invalid_argument& error)
  {
    const std::string message = error.what();
    const bool clean = message.rfind("scene", 0) == 0 && message.size() < 2000 &&
      message.find(": ") != std::string::npos;
    return { clean ? Outcome::Refused : Outcome::BadMessage, message };
  }
  catch (const std::exception& error)
  {
    return { Outcome::BadMessage, std::string("not std::invalid_argument: ") + error.what() };
  }
  // Valid: at most 8x6 pixels and 16 points per axis, whatever the mutant says.
  scene.Camera.Width = std::min(scene.Camera.Width, 8);
  scene.Camera.Height = std::min(scene.Camera.Height, 6);
  auto clamp = [](nimbus::DensitySourceDescription& density)
  {
    for (auto& parameter : density.Parameters)
    {
      if (parameter.first == "Dimensions")
      {
        for (double& d : parameter.second)
        {
          d = std::min(d, 16.0);
        }
      }
    }
  };
  clamp(scene.Medium.Density);
  for (auto& medium : scene.Media)
  {
    clamp(medium.Density);
  }
  std::ofstream(sceneFile) << nimbus::SceneToJson(scene);

  vtkNew<vtkNimbusReferenceRenderer> renderer;
  nimbus::testing::MessageCatcher messages(renderer);
  renderer->SetSceneFileName(sceneFile.string().c_str());
  // Version-3 and version-4 features are the path tracer's: single scattering refuses them
  // by name.
  const bool refusedBySingleScattering =
    scene.UsesVersion3Features() || scene.UsesVersion4Features();
  renderer->SetModeToSingleScattering();
  renderer->SetMaxRefinements(0);
  renderer->SetStepScale(1.0);
  renderer->SetNumberOfThreads(1);
  try
  {
    renderer->Update();
  }
  catch (const std::exception& error)
  {
    return { Outcome::Escaped, error.what() };
  }
  auto* radiance =
    vtkFloatArray::SafeDownCast(renderer->GetOutput()->GetPointData()->GetArray("radiance"));
  if (!radiance && IsAssetRefusal(messages.AllErrors()))
  {
    return { Outcome::Refused, messages.AllErrors() };
  }
  if (refusedBySingleScattering)
  {
    const std::string errors = messages.AllErrors();
    if (radiance ||
      errors.find("the single-scattering renderer does not render") == std::string::npos)
    {
      return { Outcome::RenderFailed,
        "single scattering did not refuse a version-3 scene: " + errors };
    }
  }
  else if (!radiance)
  {
    const std::string errors = messages.AllErrors();
    return { errors.find("memory budget") != std::string::npos ? Outcome::OverBudget
                                                               : Outcome::RenderFailed,
      errors };
  }
  for (vtkIdType i = 0; radiance && i < radiance->GetNumberOfValues(); ++i)
  {
    if (!std::isfinite(radiance->GetValue(i)))
    {
      return { Outcome::NonFinite, "component " + std::to_string(i) };
    }
  }
  // And one path per pixel through the path tracer.
  renderer->SetModeToPathTracing();
  renderer->SetMinSamplesPerPixel(1);
  renderer->SetMaxSamplesPerPixel(1);
  renderer->Update();
  radiance =
    vtkFloatArray::SafeDownCast(renderer->GetOutput()->GetPointData()->GetArray("radiance"));
  if (!radiance)
  {
    return { Outcome::RenderFailed, "path tracing: " + messages.AllErrors() };
  }
  for (vtkIdType i = 0; i < radiance->GetNumberOfValues(); ++i)
  {
    if (!std::isfinite(radiance->GetValue(i)))
    {
      return { Outcome::NonFinite, "path tracing, component " + std::to_string(i) };
    }
  }
  return { Outcome::Rendered, std::to_string(radiance->GetNumberOfTuples()) + " pixels" };
}

/// Runs Judge in a forked child under the limits.
std::pair<Outcome, std::string> JudgeInChild(const Mutant& mutant, const fs::path& sceneFile)
{
  int fds[2];
  if (::pipe(fds) != 0)
  {
    return { Outcome::Crashed, "pipe failed" };
  }
  std::fflush(nullptr);
  const pid_t child = ::fork();
  if (child == 0)
  {
    ::close(fds[0]);
    rlimit limit{ kAddressSpaceLimit, kAddressSpaceLimit };
    ::setrlimit(RLIMIT_AS, &limit);
    ::alarm(kSecondsPerMutant);
    // Quiet: the renderer's errors are caught by its observer; the metaball
    // source's warnings about odd parameters are expected.
    vtkNew<vtkStringOutputWindow> quiet;
    vtkOutputWindow::SetInstance(quiet);
    vtkLogger::SetStderrVerbosity(vtkLogger::VERBOSITY_OFF);
    std::pair<Outcome, std::string> result;
    try
    {
      result = Judge(mutant, sceneFile);
    }
    catch (const std::exception& error)
    {
      result = { Outcome::Escaped, error.what() };
    }
    catch (...)
    {
      result = { Outcome::Escaped, "unknown exception" };
    }
    const std::string report = std::string(1, static_cast<char>(result.first)) + result.second;
    std::size_t written = 0;
    while (written < report.size())
    {
      const ssize_t n = ::write(fds[1], report.data() + written, report.size() - written);
      if (n <= 0)
      {
        break;
      }
      written += static_cast<std::size_t>(n);
    }
    ::_exit(0);
  }
  ::close(fds[1]);
  std::string report;
  char buffer[4096];
  ssize_t n;
  while ((n = ::read(fds[0], buffer, sizeof(buffer))) > 0)
  {
    report.append(buffer, static_cast<std::size_t>(n));
  }
  ::close(fds[0]);
  int status = 0;
  ::waitpid(child, &status, 0);
  if (WIFSIGNALED(status))
  {
    return { WTERMSIG(status) == SIGALRM ? Outcome::TimedOut : Outcome::Crashed,
      "signal " + std::to_string(WTERMSIG(status)) };
  }
  if (report.empty())
  {
    return { Outcome::Crashed, "no report, exit status " + std::to_string(WEXITSTATUS(status)) };
  }
  return { static_cast<Outcome>(report[0]), report.substr(1) };
}
} // namespace

TEST(SceneFuzz, MutantsAreRefusedCleanlyOrRenderFinite)
{
  std::vector<fs::path> scenes;
  for (const auto& entry : fs::directory_iterator(NIMBUS_SCENES_DIR))
  {
    if (entry.path().extension() == ".json")
    {
      scenes.push_back(entry.path());
    }
  }
  std::sort(scenes.begin(), scenes.end()); // a fixed order: the same mutants every run
  ASSERT_GE(scenes.size(), 5u);
  scenes.push_back(scenes.front()); // again, with the version-3 features (below)
  scenes.push_back(scenes.front()); // and with the version-4 features
  const fs::path work = fs::temp_directory_path() /
    ("nimbus-scene-fuzz-" + std::to_string(::getpid()) + "-" +
      std::to_string(std::random_device{}()));
  fs::create_directories(work);

  Mutator mutator(kSeed);
  std::map<std::string, std::map<Outcome, int>> table;
  std::map<Outcome, int> totals;
  int mutants = 0;
  double slowest = 0.0;
  const auto start = std::chrono::steady_clock::now();
  for (std::size_t s = 0; s < scenes.size(); ++s)
  {
    const fs::path& file = scenes[s];
    const Json base = s + 2 == scenes.size() ? WithVersion3Features(Cheap(file))
      : s + 1 == scenes.size()               ? WithVersion4Features(Cheap(file), work)
                                             : Cheap(file);
    // The unmutated (cheap) scene must render: the oracle is not vacuous.
    const auto original = JudgeInChild({ "none", base.dump(2) }, work / "original.json");
    EXPECT_EQ(original.first, Outcome::Rendered) << file << ": " << original.second;
    for (int i = 0; i < kMutantsPerScene; ++i, ++mutants)
    {
      const Mutant mutant = mutator.Make(base, i);
      const auto t0 = std::chrono::steady_clock::now();
      const auto result =
        JudgeInChild(mutant, work / ("mutant" + std::to_string(mutants) + ".json"));
      slowest = std::max(
        slowest, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
      ++table[mutant.Kind][result.first];
      ++totals[result.first];
      const bool fine = result.first == Outcome::Refused || result.first == Outcome::Rendered ||
        result.first == Outcome::OverBudget;
      EXPECT_TRUE(fine) << file.filename() << " mutant " << i << " (" << mutant.Kind
                        << "): " << Name(result.first) << ": " << result.second
                        << "\n--- text (first 600 bytes) ---\n"
                        << mutant.Text.substr(0, 600);
    }
  }
  const double seconds =
    std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("%d mutants of %zu scenes in %.1f s (slowest %.2f s), seed %llu, RLIMIT_AS %llu "
              "MiB\n",
    mutants, scenes.size(), seconds, slowest, static_cast<unsigned long long>(kSeed),
    kAddressSpaceLimit >> 20);
  for (const auto& row : table)
  {
    std::printf("  %-16s", row.first.c_str());
    for (const auto& cell : row.second)
    {
      std::printf("  %s: %d", Name(cell.first), cell.second);
    }
    std::printf("\n");
  }
  // Both branches of the oracle are exercised.
  EXPECT_GT(totals[Outcome::Refused], mutants / 4);
  EXPECT_GT(totals[Outcome::Rendered], 10);
  fs::remove_all(work);
}
