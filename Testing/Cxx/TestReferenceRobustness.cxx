// Bad input to the reference renderers and nimbus-render (the robustness issue):
// sizes over the memory budget end in a message, not in VTK's abort; no exception
// leaves a VTK algorithm; NaN / Inf never come out silently; a density's direction
// matrix is not ignored; NaN, infinite and negative densities are counted; the path
// tracer reports progress and stops on AbortExecute. The children that could
// allocate too much run in a forked process under an address-space limit.
#include "Camera.h"
#include "DensityGrid.h"
#include "FloatImage.h"
#include "MessageCatcher.h"
#include "PathTracer.h"
#include "RenderContext.h"
#include "SceneJson.h"
#include "SingleScatteringRenderer.h"
#include "vtkNimbusReferenceRenderer.h"
#include "vtkNimbusSceneDensitySource.h"

#include "vtkCallbackCommand.h"
#include "vtkCommand.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkMatrix3x3.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkXMLImageDataWriter.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#ifndef NIMBUS_TEST_DATA_DIR
#error "NIMBUS_TEST_DATA_DIR must name Testing/Data"
#endif
#ifndef NIMBUS_RENDER_EXE
#error "NIMBUS_RENDER_EXE must name the nimbus-render program"
#endif

namespace
{
namespace fs = std::filesystem;
using nimbus::testing::MessageCatcher;

constexpr unsigned long long kAddressSpaceLimit = 3ull << 30; // 3 GiB

fs::path TemporaryDirectory()
{
  static const fs::path dir = []
  {
    const fs::path d = fs::temp_directory_path() /
      ("nimbus-robustness-" + std::to_string(::getpid()) + "-" +
        std::to_string(std::random_device{}()));
    fs::create_directories(d);
    return d;
  }();
  return dir;
}

/// Testing/Data/tiny_scene.json with `edit` applied to its text (a textual
/// replacement of `from` by `to`), written to a temporary file.
std::string WriteScene(const std::string& name, const std::string& from, const std::string& to)
{
  std::ifstream in(std::string(NIMBUS_TEST_DATA_DIR) + "/tiny_scene.json");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (!from.empty())
  {
    const std::size_t at = text.find(from);
    if (at == std::string::npos)
    {
      ADD_FAILURE() << "tiny_scene.json has no " << from;
      return std::string();
    }
    text.replace(at, from.size(), to);
  }
  const fs::path path = TemporaryDirectory() / (name + ".json");
  std::ofstream(path) << text;
  return path.string();
}

/// Runs `body` in a forked child under the address-space limit; returns its
/// wait status. The child exits with body()'s value (0 = its checks passed).
int RunLimited(const std::function<int()>& body)
{
  std::fflush(nullptr);
  const pid_t child = ::fork();
  if (child == 0)
  {
    rlimit limit{ kAddressSpaceLimit, kAddressSpaceLimit };
    ::setrlimit(RLIMIT_AS, &limit);
    int code = 1;
    try
    {
      code = body();
    }
    catch (...)
    {
      code = 3; // an exception escaped
    }
    std::fflush(nullptr);
    ::_exit(code);
  }
  int status = 0;
  ::waitpid(child, &status, 0);
  return status;
}

/// Runs nimbus-render (under the address-space limit); returns its exit status
/// (-signal when killed) and its output (stdout and stderr).
int RunNimbusRender(const std::string& arguments, std::string& output)
{
  const std::string command = "ulimit -v " + std::to_string(kAddressSpaceLimit / 1024) +
    "; exec \"" + NIMBUS_RENDER_EXE + "\" " + arguments + " 2>&1";
  FILE* pipe = ::popen(command.c_str(), "r");
  output.clear();
  char buffer[4096];
  std::size_t n;
  while ((n = std::fread(buffer, 1, sizeof(buffer), pipe)) > 0)
  {
    output.append(buffer, n);
  }
  const int status = ::pclose(pipe);
  if (WIFSIGNALED(status))
  {
    return -WTERMSIG(status);
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1000;
}

/// A constant-density cube (8^3 points, 100 m spacing) centred under the sky of tiny_scene.
vtkSmartPointer<vtkImageData> Cube(float density = 1.0f)
{
  auto image = vtkSmartPointer<vtkImageData>::New();
  image->SetDimensions(8, 8, 8);
  image->SetOrigin(-350.0, -350.0, 1150.0);
  image->SetSpacing(100.0, 100.0, 100.0);
  vtkNew<vtkFloatArray> values;
  values->SetName("density");
  values->SetNumberOfTuples(512);
  values->FillValue(density);
  image->GetPointData()->SetScalars(values);
  return image;
}

bool HasRadiance(vtkImageData* image)
{
  return image && image->GetPointData()->GetArray("radiance") != nullptr;
}
} // namespace

//------------------------------------------------------------------------------
// Finding 1: allocations from user-controlled sizes are checked first.

TEST(ReferenceRobustness, HugeSceneGridIsRefusedNotAborted)
{
  // 1024^3 = 2^30 points: the largest grid the schema allows (4 GiB as floats).
  const std::string scene =
    WriteScene("huge-grid", "\"Dimensions\": [24, 24, 16]", "\"Dimensions\": [1024, 1024, 1024]");
  const int status = RunLimited(
    [&]
    {
      vtkNew<vtkNimbusReferenceRenderer> renderer;
      MessageCatcher messages(renderer);
      renderer->SetSceneFileName(scene.c_str());
      renderer->SetNumberOfThreads(1);
      renderer->Update();
      const std::string errors = messages.AllErrors();
      std::printf("%s", errors.c_str());
      const bool named =
        errors.find("the density volume (1024x1024x1024 points") != std::string::npos &&
        errors.find("more than the memory budget") != std::string::npos;
      return named && !HasRadiance(renderer->GetOutput()) ? 0 : 1;
    });
  ASSERT_TRUE(WIFEXITED(status)) << "killed by signal " << WTERMSIG(status);
  EXPECT_EQ(WEXITSTATUS(status), 0);
}

TEST(ReferenceRobustness, PathTracerChecksItsBuffersBeforeAllocating)
{
  // In a child under the address-space limit: without the check this would ask
  // for 28 GiB.
  const int status = RunLimited(
    []
    {
      nimbus::SceneDescription big =
        nimbus::LoadScene(std::string(NIMBUS_TEST_DATA_DIR) + "/tiny_scene.json");
      big.Camera.Width = 16384; // the schema's largest image
      big.Camera.Height = 16384;
      const nimbus::RenderContext context(
        big, nimbus::DensityGrid::Constant({ { -100, -100, 1400 } }, { { 100, 100, 1600 } }, 0.5f));
      nimbus::PathTracingSettings settings;
      settings.MinSamplesPerPixel = settings.MaxSamplesPerPixel = 1;
      settings.MemoryBudgetBytes = 1 << 30;
      int failures = 0;
      try
      {
        nimbus::RenderPathTraced(context, settings);
        ++failures;
      }
      catch (const std::length_error& error)
      {
        const std::string expected = "the path tracer's per-pixel buffers (16384x16384 pixels, "
                                     "112 bytes each) would need 28.0 GiB, more than the memory "
                                     "budget of 1.0 GiB";
        failures += error.what() == expected ? 0 : 1;
        std::printf("%s\n", error.what());
      }
      nimbus::SingleScatteringSettings single;
      single.MemoryBudgetBytes = 1 << 30;
      try
      {
        nimbus::RenderSingleScattering(context, single);
        ++failures;
      }
      catch (const std::length_error& error)
      {
        std::printf("%s\n", error.what());
      }
      return failures;
    });
  ASSERT_TRUE(WIFEXITED(status)) << "killed by signal " << WTERMSIG(status);
  EXPECT_EQ(WEXITSTATUS(status), 0);
}

TEST(ReferenceRobustness, NimbusRenderRefusesHugeImagesWithAMessage)
{
  std::string output;
  // Path tracing at 8192^2: the image (1.5 GiB) fits the budget (3/4 of 3 GiB), the
  // path tracer's buffers (7 GiB, asked for up front before) do not.
  const std::string path = WriteScene(
    "huge-path", "\"width\": 24,\n    \"height\": 18", "\"width\": 8192,\n    \"height\": 8192");
  int code = RunNimbusRender(
    path + " --mode path --min-spp 1 --max-spp 1 --output " + (TemporaryDirectory() / "p").string(),
    output);
  EXPECT_EQ(code, 1) << output;
  EXPECT_NE(output.find("the path tracer's per-pixel buffers (8192x8192 pixels"), std::string::npos)
    << output;
  // Single scattering at 16384^2: the image alone (3 GiB) is over the budget.
  const std::string single = WriteScene("huge-single", "\"width\": 24,\n    \"height\": 18",
    "\"width\": 16384,\n    \"height\": 16384");
  code = RunNimbusRender(single + " --output " + (TemporaryDirectory() / "s").string(), output);
  EXPECT_EQ(code, 1) << output;
  EXPECT_NE(
    output.find("the rendered image (16384x16384 pixels) would need 3.0 GiB"), std::string::npos)
    << output;
}

//------------------------------------------------------------------------------
// Finding 3: no silent NaN / Inf.

TEST(ReferenceRobustness, NimbusRenderNamesExtremeValuesInsteadOfWritingInf)
{
  // Each of these made nimbus-render exit 0 with Inf, NaN or -Inf pixels.
  const std::vector<std::array<std::string, 3>> cases = {
    { "\"illuminance\": 1.0", "\"illuminance\": 1e308", "scene.sun.illuminance: expected" },
    { "\"atmosphere\": {\"enabled\": true}",
      "\"atmosphere\": {\"enabled\": true, \"rayleigh_scattering_per_metre\": 1e308}",
      "scene.atmosphere.rayleigh_scattering_per_metre: expected" },
    { "\"atmosphere\": {\"enabled\": true}",
      "\"atmosphere\": {\"enabled\": true, \"top_radius_metres\": 1e308}",
      "scene.atmosphere.top_radius_metres: expected" },
    { "\"background\": {\"type\": \"atmosphere\"}",
      "\"background\": {\"type\": \"constant\", \"radiance\": 1e308}",
      "scene.background.radiance: expected" },
  };
  for (const auto& c : cases)
  {
    const std::string scene = WriteScene("extreme", c[0], c[1]);
    std::string output;
    const int code =
      RunNimbusRender(scene + " --output " + (TemporaryDirectory() / "e").string(), output);
    EXPECT_EQ(code, 1) << c[1] << "\n" << output;
    EXPECT_NE(output.find(c[2]), std::string::npos) << output;
  }
}

TEST(ReferenceRobustness, RenderersRefuseNonFiniteImages)
{
  // Past the scene reader (a SceneDescription made in code): a sun of 1e308 makes
  // infinite radiance; the renderers say so instead of returning it.
  nimbus::SceneDescription scene =
    nimbus::LoadScene(std::string(NIMBUS_TEST_DATA_DIR) + "/tiny_scene.json");
  scene.Camera.Width = 6;
  scene.Camera.Height = 4;
  scene.Sun.Illuminance = 1e308;
  const nimbus::RenderContext context(
    scene, nimbus::DensityGrid::Constant({ { -200, -200, 1300 } }, { { 200, 200, 1700 } }, 1.0f));
  nimbus::SingleScatteringSettings single;
  single.MaxRefinements = 0;
  single.Threads = 1;
  try
  {
    nimbus::RenderSingleScattering(context, single);
    FAIL() << "no error";
  }
  catch (const std::range_error& error)
  {
    EXPECT_EQ(std::string(error.what()).rfind("RenderSingleScattering: the image has ", 0), 0u)
      << error.what();
    EXPECT_NE(std::string(error.what()).find("among 72 pixel components"), std::string::npos);
  }
  nimbus::PathTracingSettings path;
  path.MinSamplesPerPixel = path.MaxSamplesPerPixel = 2;
  path.Threads = 1;
  EXPECT_THROW(nimbus::RenderPathTraced(context, path), std::range_error);

  nimbus::FloatImage image(2, 1);
  image.Pixels = { 1.0f, -2.0f, std::numeric_limits<float>::quiet_NaN(),
    std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity(), 0.0f };
  EXPECT_EQ(
    nimbus::NonFiniteMessage(image), "1 NaN and 2 infinite values among 6 pixel components");
  image.Pixels = { 1.0f, -2.0f, 0.0f, 3.0f, 4.0f, 5.0f }; // negative linear sRGB is allowed
  EXPECT_EQ(nimbus::NonFiniteMessage(image), "");
}

TEST(ReferenceRobustness, BadDensitiesAreCountedAndNamed)
{
  vtkSmartPointer<vtkImageData> cube = Cube();
  auto* values = vtkFloatArray::SafeDownCast(cube->GetPointData()->GetArray("density"));
  values->SetValue(3, std::numeric_limits<float>::quiet_NaN());
  values->SetValue(7, std::numeric_limits<float>::quiet_NaN());
  values->SetValue(9, -1.0f);
  values->SetValue(10, std::numeric_limits<float>::infinity());
  vtkNew<vtkNimbusReferenceRenderer> renderer;
  MessageCatcher messages(renderer);
  renderer->SetSceneFileName((std::string(NIMBUS_TEST_DATA_DIR) + "/tiny_scene.json").c_str());
  renderer->SetInputData(cube);
  renderer->SetNumberOfThreads(1);
  renderer->Update();
  EXPECT_FALSE(HasRadiance(renderer->GetOutput()));
  EXPECT_NE(messages.AllErrors().find("density array 'density': nimbus::DensityGrid: 2 NaN, 1 "
                                      "infinite and 1 negative values among 512 densities"),
    std::string::npos)
    << messages.AllErrors();
}

//------------------------------------------------------------------------------
// Finding 4: the direction matrix is not ignored.

TEST(ReferenceRobustness, RotatedDensityIsRefusedNotMisplaced)
{
  const std::string scene = std::string(NIMBUS_TEST_DATA_DIR) + "/tiny_scene.json";
  // Identity: renders.
  {
    vtkNew<vtkNimbusReferenceRenderer> renderer;
    renderer->SetSceneFileName(scene.c_str());
    renderer->SetInputData(Cube());
    renderer->SetNumberOfThreads(1);
    renderer->SetMaxRefinements(0);
    renderer->Update();
    EXPECT_TRUE(HasRadiance(renderer->GetOutput()));
  }
  // A rotation by 90 degrees about z, as the OpenVDB reader may produce.
  vtkSmartPointer<vtkImageData> rotated = Cube();
  rotated->SetDirectionMatrix(0, -1, 0, 1, 0, 0, 0, 0, 1);
  {
    vtkNew<vtkNimbusReferenceRenderer> renderer;
    MessageCatcher messages(renderer);
    renderer->SetSceneFileName(scene.c_str());
    renderer->SetInputData(rotated);
    renderer->SetNumberOfThreads(1);
    renderer->Update();
    EXPECT_FALSE(HasRadiance(renderer->GetOutput()));
    EXPECT_NE(messages.AllErrors().find("the density image has a direction matrix that is not "
                                        "the identity (0.000000 -1.000000 0.000000 1.000000"),
      std::string::npos)
      << messages.AllErrors();
  }
  // The same through a scene whose density is a rotated .vti file: the scene's
  // density source keeps the matrix, so the renderer sees it.
  const fs::path vti = TemporaryDirectory() / "rotated.vti";
  vtkNew<vtkXMLImageDataWriter> writer;
  writer->SetFileName(vti.string().c_str());
  writer->SetInputData(rotated);
  ASSERT_EQ(writer->Write(), 1);
  const std::string fileScene = WriteScene("rotated-file",
    "\"type\": \"metaball_cloud\",\n      \"parameters\": {\n        \"Dimensions\": [24, 24, "
    "16],\n        \"NumberOfLevels\": 1,\n        \"Seed\": 2\n      }",
    "\"type\": \"file\", \"path\": \"" + vti.string() + "\"");
  {
    vtkNew<vtkNimbusSceneDensitySource> source;
    source->SetSceneFileName(fileScene.c_str());
    source->Update();
    ASSERT_EQ(source->GetOutput()->GetNumberOfPoints(), 512);
    EXPECT_FALSE(source->GetOutput()->GetDirectionMatrix()->IsIdentity());
  }
  vtkNew<vtkNimbusReferenceRenderer> renderer;
  MessageCatcher messages(renderer);
  renderer->SetSceneFileName(fileScene.c_str());
  renderer->SetNumberOfThreads(1);
  renderer->Update();
  EXPECT_FALSE(HasRadiance(renderer->GetOutput()));
  EXPECT_NE(messages.AllErrors().find("direction matrix"), std::string::npos)
    << messages.AllErrors();
}

//------------------------------------------------------------------------------
// Finding 5: the camera names overflow, not "equal points".

TEST(ReferenceRobustness, CameraNamesOverflow)
{
  nimbus::CameraDescription camera;
  camera.Position = { { -1e308, 0.0, 0.0 } };
  camera.FocalPoint = { { 1e308, 0.0, 0.0 } };
  camera.ViewUp = { { 0.0, 0.0, 1.0 } };
  try
  {
    nimbus::Camera c(camera);
    FAIL() << "no error";
  }
  catch (const std::invalid_argument& error)
  {
    EXPECT_STREQ(error.what(),
      "camera: position and focal point are too far apart (their difference overflows)");
  }
  camera.Position = { { std::numeric_limits<double>::infinity(), 0.0, 0.0 } };
  EXPECT_THROW(
    {
      try
      {
        nimbus::Camera c(camera);
      }
      catch (const std::invalid_argument& error)
      {
        EXPECT_STREQ(error.what(), "camera: position, focal point and view-up must be finite");
        throw;
      }
    },
    std::invalid_argument);
  // A huge view-up is still a direction.
  camera.Position = { { 0.0, -1000.0, 0.0 } };
  camera.FocalPoint = { { 0.0, 0.0, 0.0 } };
  camera.ViewUp = { { 0.0, 0.0, 1e308 } };
  EXPECT_NO_THROW(nimbus::Camera c(camera));
}

//------------------------------------------------------------------------------
// Finding 6: progress during path tracing, and AbortExecute stops it.

TEST(ReferenceRobustness, PathTracingReportsProgressAndAborts)
{
  vtkNew<vtkNimbusReferenceRenderer> renderer;
  MessageCatcher messages(renderer);
  renderer->SetSceneFileName((std::string(NIMBUS_TEST_DATA_DIR) + "/tiny_scene.json").c_str());
  renderer->SetInputData(Cube(0.02f));
  renderer->SetModeToPathTracing();
  renderer->SetMinSamplesPerPixel(1 << 20); // hours: the first round alone
  renderer->SetMaxSamplesPerPixel(1 << 20);
  renderer->SetNumberOfThreads(2);
  // Abort at the first progress report past 0 (from within the first round).
  vtkNew<vtkCallbackCommand> abortOnProgress;
  abortOnProgress->SetCallback(
    [](vtkObject* caller, unsigned long, void*, void* callData)
    {
      if (*static_cast<double*>(callData) > 0.0)
      {
        static_cast<vtkAlgorithm*>(caller)->SetAbortExecute(1);
      }
    });
  renderer->AddObserver(vtkCommand::ProgressEvent, abortOnProgress);
  const auto start = std::chrono::steady_clock::now();
  renderer->Update();
  const double seconds =
    std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_LT(seconds, 20.0);
  EXPECT_GE(messages.ProgressEvents, 2);
  EXPECT_FALSE(HasRadiance(renderer->GetOutput()));
  EXPECT_EQ(messages.AllErrors(), "");
  // Once the caller clears the flag (this VTK leaves it set), the next update renders.
  renderer->RemoveObserver(abortOnProgress);
  renderer->SetAbortExecute(0);
  renderer->SetMinSamplesPerPixel(1);
  renderer->SetMaxSamplesPerPixel(2);
  renderer->Modified();
  renderer->Update();
  EXPECT_TRUE(HasRadiance(renderer->GetOutput())) << messages.AllErrors();

  // Single scattering stops too (after the rows being rendered).
  renderer->SetModeToSingleScattering();
  renderer->SetMaxRefinements(6);
  renderer->SetRelativeTolerance(1e-12); // all 7 passes, were it not aborted
  renderer->AddObserver(vtkCommand::ProgressEvent, abortOnProgress);
  renderer->Update();
  EXPECT_FALSE(HasRadiance(renderer->GetOutput()));
  EXPECT_EQ(messages.AllErrors(), "");
}

//------------------------------------------------------------------------------
// Scene format version 3 through vtkNimbusReferenceRenderer: additional media and
// "array" emission fields are read from their .vti files; the path tracer renders them
// with a point light to finite pixels; single scattering refuses them by name; a NaN in
// an emission array is counted and named as a density's is; what the renderer cannot
// read is named by its scene key.

namespace
{
std::string Replaced(std::string text, const std::string& from, const std::string& to)
{
  const std::size_t at = text.find(from);
  if (at == std::string::npos)
  {
    ADD_FAILURE() << "no " << from;
    return text;
  }
  return text.replace(at, from.size(), to);
}

/// tiny_scene.json as version 3 with a file density (the cube), emission from the
/// array `emission`, an additional medium from the array `medium`, and a point light.
std::string WriteVersion3Scene(const std::string& name, const std::string& vti,
  const std::string& emission, const std::string& mediumDensity)
{
  std::ifstream in(std::string(NIMBUS_TEST_DATA_DIR) + "/tiny_scene.json");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  text = Replaced(text, "\"nimbus_scene\": 2", "\"nimbus_scene\": 3");
  text = Replaced(text,
    "\"type\": \"metaball_cloud\",\n      \"parameters\": {\n        \"Dimensions\": [24, 24, "
    "16],\n        \"NumberOfLevels\": 1,\n        \"Seed\": 2\n      }",
    "\"type\": \"file\", \"path\": \"" + vti + "\"");
  text = Replaced(text, "\"single_scattering_albedo\": 0.99,",
    "\"single_scattering_albedo\": 0.99, \"emission\": {\"source\": \"array\", \"array\": \"" +
      emission + "\", \"radiance_per_metre\": 0.001},");
  text = Replaced(text, "\"spectral_samples\": 8",
    "\"spectral_samples\": 8, \"media\": [{\"density\": " + mediumDensity +
      ", \"extinction_per_density\": 0.02, \"single_scattering_albedo\": 0.3, \"phase\": "
      "{\"type\": \"isotropic\"}}], \"lights\": [{\"type\": \"point\", \"position\": [0, "
      "-1000, 1500], \"intensity\": 1e6}]");
  const fs::path path = TemporaryDirectory() / (name + ".json");
  std::ofstream(path) << text;
  return path.string();
}
} // namespace

TEST(ReferenceRobustness, Version3ScenesRenderOrNameWhatIsMissing)
{
  vtkSmartPointer<vtkImageData> cube = Cube();
  for (const char* name : { "heat", "soot", "heatnan" })
  {
    vtkNew<vtkFloatArray> values;
    values->SetName(name);
    values->SetNumberOfTuples(512);
    values->FillValue(0.5f);
    if (std::string(name) == "heatnan")
    {
      values->SetValue(17, std::numeric_limits<float>::quiet_NaN());
    }
    cube->GetPointData()->AddArray(values);
  }
  const fs::path vti = TemporaryDirectory() / "version3.vti";
  vtkNew<vtkXMLImageDataWriter> writer;
  writer->SetFileName(vti.string().c_str());
  writer->SetInputData(cube);
  ASSERT_EQ(writer->Write(), 1);
  const std::string soot =
    "{\"type\": \"file\", \"path\": \"" + vti.string() + "\", \"array\": \"soot\"}";
  auto render = [](const std::string& scene, bool pathTracing, std::string& errors)
  {
    vtkNew<vtkNimbusReferenceRenderer> renderer;
    MessageCatcher messages(renderer);
    renderer->SetSceneFileName(scene.c_str());
    renderer->SetNumberOfThreads(1);
    renderer->SetMaxRefinements(0);
    if (pathTracing)
    {
      renderer->SetModeToPathTracing();
      renderer->SetMinSamplesPerPixel(2);
      renderer->SetMaxSamplesPerPixel(2);
    }
    renderer->Update();
    errors = messages.AllErrors();
    vtkImageData* output = renderer->GetOutput();
    if (!HasRadiance(output))
    {
      return false;
    }
    vtkDataArray* radiance = output->GetPointData()->GetArray("radiance");
    for (vtkIdType i = 0; i < radiance->GetNumberOfValues(); ++i)
    {
      EXPECT_TRUE(std::isfinite(radiance->GetVariantValue(i).ToDouble()));
    }
    return true;
  };
  std::string errors;
  const std::string good = WriteVersion3Scene("version3", vti.string(), "heat", soot);
  EXPECT_TRUE(render(good, true, errors)) << errors;
  EXPECT_FALSE(render(good, false, errors));
  EXPECT_NE(errors.find("the single-scattering renderer does not render point and polyline "
                        "lights (scene.lights), emission"),
    std::string::npos)
    << errors;
  EXPECT_FALSE(
    render(WriteVersion3Scene("version3-nan", vti.string(), "heatnan", soot), true, errors));
  EXPECT_NE(errors.find("scene.medium.emission.array: array 'heatnan': nimbus::DensityGrid: 1 NaN"),
    std::string::npos)
    << errors;
  EXPECT_FALSE(
    render(WriteVersion3Scene("version3-missing", vti.string(), "nope", soot), true, errors));
  EXPECT_NE(errors.find("scene.medium.emission.array: '" + vti.string() +
              "' has no one-component point array 'nope'"),
    std::string::npos)
    << errors;
  // A metaball cloud as the additional medium: made by vtkNimbusSceneDensitySource
  // (Medium 1); its grid is not the cube's, which is an error naming the key.
  EXPECT_FALSE(render(WriteVersion3Scene("version3-metaballs", vti.string(), "heat",
                        "{\"type\": \"metaball_cloud\", \"parameters\": {\"Dimensions\": "
                        "[8, 8, 8]}}"),
    true, errors));
  EXPECT_NE(errors.find("scene: media[0].density must be on the main density's grid (8x8x8 "
                        "points, origin (-350"),
    std::string::npos)
    << errors;
  {
    vtkNew<vtkNimbusSceneDensitySource> source;
    MessageCatcher messages(source);
    source->SetSceneFileName(good.c_str());
    source->SetMedium(2);
    source->Update();
    EXPECT_NE(
      messages.AllErrors().find("Medium 2 asks for media[1], but the scene has 1 additional media"),
      std::string::npos)
      << messages.AllErrors();
    source->SetMedium(1);
    source->Update();
    EXPECT_EQ(source->GetOutput()->GetNumberOfPoints(), 512);
  }
}
