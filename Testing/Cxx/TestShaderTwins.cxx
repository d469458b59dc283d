// The GLSL library (Representations/Shaders/nimbus*.glsl, ShaderLibrary.h) against
// its C++ twins in Physics/: every library function is evaluated on the GPU on a grid
// of arguments (one fragment per argument set, read from a float texture, written to
// a float render target) and compared with the C++ function evaluated on the same
// arguments (the float values, in double precision). What differs is float
// arithmetic and the GPU's transcendental functions; the bounds below are the errors
// measured on Mesa llvmpipe (printed by the test), rounded up by about 3x.
//
// Run under a display: Testing/with-display.sh build/bin/TestShaderTwins.
#include "Atmosphere.h"
#include "Math.h"
#include "PhaseFunctions.h"
#include "ShaderLibrary.h"
#include "Sky.h"
#include "SpectralColor.h"

#include "vtkNew.h"
#include "vtkOpenGLFramebufferObject.h"
#include "vtkOpenGLQuadHelper.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkOpenGLShaderCache.h"
#include "vtkOpenGLState.h"
#include "vtkRenderWindow.h"
#include "vtkShaderProgram.h"
#include "vtkTextureObject.h"
#include "vtk_glew.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <functional>
#include <memory>
#include <random>
#include <string>
#include <vector>

namespace
{
using Arguments = std::array<float, 4>;
using Result = std::array<double, 2>;

// The functions under test, selected by the uniform `function`.
enum Function
{
  RayleighFunction = 0,
  HenyeyGreensteinFunction,
  CornetteShanksFunction,
  SrgbEncodeFunction,
  SrgbDecodeFunction,
  DistanceToTopFunction,
  FlatLayerFunction,
  SkyViewRowFunction,
  SkyViewTexelFunction
};

// The sky-view table layout the two sky-view functions use: 128 columns, 64 + 32
// rows (SkyViewLut's default), the horizon zenith in the argument.
constexpr float kSkyColumns = 128.0f, kSkyRowsAbove = 64.0f, kSkyRowsBelow = 32.0f;

const char* kFragmentShader = R"(//VTK::System::Dec
in vec2 texCoord;
//VTK::Output::Dec
//NIMBUS::Library
//NIMBUS::SkyView
uniform sampler2D arguments;
uniform int function;

void main()
{
  // This fragment's argument set: texel (i, j) of the argument texture.
  vec4 a = texelFetch(arguments, ivec2(floor(texCoord * vec2(textureSize(arguments, 0)))), 0);
  vec2 result = vec2(0.0);
  if (function == 0) { result.x = Rayleigh(a.x); }
  else if (function == 1) { result.x = HenyeyGreenstein(a.x, a.y); }
  else if (function == 2) { result.x = CornetteShanks(a.x, a.y); }
  else if (function == 3) { result.x = SrgbEncode(a.x); }
  else if (function == 4) { result.x = SrgbDecode(a.x); }
  else if (function == 5) { result.x = DistanceToTopOfAtmosphere(a.x, a.y, a.z); }
  else if (function == 6) { result.x = FlatLayerOpticalLength(a.x, a.y, a.z, a.w); }
  else if (function == 7) { result.x = SkyViewRow(a.x, vec4(a.y, 128.0, 64.0, 32.0)); }
  else if (function == 8)
  {
    // Direction from its zenith angle (a.x) and azimuth (a.y), the sun's azimuth a.z,
    // the horizon zenith a.w: the same floats the C++ side uses.
    vec3 w = vec3(sin(a.x) * sin(a.y), sin(a.x) * cos(a.y), cos(a.x));
    result = SkyViewTexel(w, a.z, vec4(a.w, 128.0, 64.0, 32.0));
  }
  gl_FragData[0] = vec4(result, 0.0, 1.0);
}
)";

/// One OpenGL context for the whole test program, and the evaluation machinery.
class Gpu
{
public:
  static Gpu& Get()
  {
    static Gpu gpu;
    return gpu;
  }

  /// Evaluates `function` for each argument set; returns (x, y) per set.
  std::vector<Result> Evaluate(Function function, const std::vector<Arguments>& arguments)
  {
    const int width = static_cast<int>(std::min<std::size_t>(arguments.size(), 1024));
    const int height = static_cast<int>((arguments.size() + width - 1) / width);
    std::vector<float> input(static_cast<std::size_t>(width) * height * 4, 0.0f);
    for (std::size_t i = 0; i < arguments.size(); ++i)
    {
      std::copy(arguments[i].begin(), arguments[i].end(), input.begin() + 4 * i);
    }
    this->Window->MakeCurrent();
    vtkNew<vtkTextureObject> argumentTexture;
    argumentTexture->SetContext(this->Window);
    argumentTexture->SetMinificationFilter(vtkTextureObject::Nearest);
    argumentTexture->SetMagnificationFilter(vtkTextureObject::Nearest);
    argumentTexture->Create2DFromRaw(width, height, 4, VTK_FLOAT, input.data());
    vtkNew<vtkTextureObject> target;
    target->SetContext(this->Window);
    target->Allocate2D(width, height, 4, VTK_FLOAT);
    vtkNew<vtkOpenGLFramebufferObject> framebuffer;
    framebuffer->SetContext(this->Window);
    vtkOpenGLState* state = this->Window->GetState();
    state->PushFramebufferBindings();
    framebuffer->Bind(GL_FRAMEBUFFER);
    framebuffer->AddColorAttachment(0, target);
    framebuffer->ActivateDrawBuffer(0);
    state->vtkglViewport(0, 0, width, height);
    state->vtkglDisable(GL_BLEND);
    state->vtkglDisable(GL_DEPTH_TEST);
    state->vtkglDisable(GL_SCISSOR_TEST);
    this->Window->GetShaderCache()->ReadyShaderProgram(this->Quad->Program);
    argumentTexture->Activate();
    this->Quad->Program->SetUniformi("arguments", argumentTexture->GetTextureUnit());
    this->Quad->Program->SetUniformi("function", static_cast<int>(function));
    this->Quad->Render();
    std::vector<float> output(static_cast<std::size_t>(width) * height * 4);
    framebuffer->ActivateReadBuffer(0);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, width, height, GL_RGBA, GL_FLOAT, output.data());
    argumentTexture->Deactivate();
    state->PopFramebufferBindings();
    framebuffer->ReleaseGraphicsResources(this->Window);
    argumentTexture->ReleaseGraphicsResources(this->Window);
    target->ReleaseGraphicsResources(this->Window);
    std::vector<Result> results(arguments.size());
    for (std::size_t i = 0; i < arguments.size(); ++i)
    {
      results[i] = { { output[4 * i], output[4 * i + 1] } };
    }
    return results;
  }

  bool Compiled() const { return this->Quad && this->Quad->Program->GetCompiled(); }

private:
  Gpu()
  {
    this->RenderWindow->SetOffScreenRendering(1);
    this->RenderWindow->SetSize(8, 8);
    this->RenderWindow->Render();
    this->Window = vtkOpenGLRenderWindow::SafeDownCast(this->RenderWindow);
    this->Window->MakeCurrent();
    const std::string source = nimbus::WithShaderLibrary(kFragmentShader);
    this->Quad = std::make_unique<vtkOpenGLQuadHelper>(this->Window, nullptr, source.c_str(), "");
  }
  ~Gpu()
  {
    if (this->Quad)
    {
      this->Quad->ReleaseGraphicsResources(this->Window);
    }
  }

  vtkNew<vtkRenderWindow> RenderWindow;
  vtkOpenGLRenderWindow* Window = nullptr;
  std::unique_ptr<vtkOpenGLQuadHelper> Quad;
};

/// How an error is measured: relative to max(|cpu|, Floor), or absolute.
struct ErrorMeasure
{
  bool Relative = true;
  double Floor = 1e-30;
};
const ErrorMeasure kRelative{ true, 1e-30 };
const ErrorMeasure kAbsolute{ false, 1.0 };

/// The largest error over the grid; prints it with the worst arguments.
double WorstError(const char* name, Function function, const std::vector<Arguments>& grid,
  const std::function<Result(const Arguments&)>& twin, const ErrorMeasure& measure,
  int components = 1)
{
  const std::vector<Result> gpu = Gpu::Get().Evaluate(function, grid);
  double worst = 0.0;
  std::size_t worstAt = 0;
  for (std::size_t i = 0; i < grid.size(); ++i)
  {
    const Result cpu = twin(grid[i]);
    for (int c = 0; c < components; ++c)
    {
      const double difference = std::abs(gpu[i][c] - cpu[c]);
      const double error =
        measure.Relative ? difference / std::max(std::abs(cpu[c]), measure.Floor) : difference;
      if (!(error <= worst)) // NaN counts as the worst
      {
        worst = std::isnan(error) ? HUGE_VAL : error;
        worstAt = i;
      }
    }
  }
  const Arguments& a = grid[worstAt];
  std::printf("%-26s %6zu arguments: worst error %.3g at (%g, %g, %g, %g)\n", name, grid.size(),
    worst, a[0], a[1], a[2], a[3]);
  return worst;
}

std::vector<float> Range(float first, float last, int count)
{
  std::vector<float> values;
  for (int i = 0; i < count; ++i)
  {
    values.push_back(
      first + (last - first) * static_cast<float>(i) / static_cast<float>(count - 1));
  }
  return values;
}

/// Cosines over [-1, 1] plus the forward and backward peaks.
std::vector<float> Cosines()
{
  std::vector<float> mu = Range(-1.0f, 1.0f, 401);
  for (float d : { 1e-2f, 1e-3f, 1e-4f, 1e-5f, 1e-6f })
  {
    mu.push_back(1.0f - d);
    mu.push_back(-1.0f + d);
  }
  return mu;
}

const std::vector<float> kAsymmetries = { -0.99f, -0.5f, 0.0f, 0.3f, 0.76f, 0.85f, 0.9f, 0.99f,
  0.999f };
} // namespace

TEST(ShaderTwins, Compiles)
{
  ASSERT_TRUE(Gpu::Get().Compiled()) << "the GLSL library did not compile";
}

// nimbusPhase.glsl against Physics/PhaseFunctions.h. Relative error.
TEST(ShaderTwins, PhaseFunctions)
{
  std::vector<Arguments> rayleigh, lobes;
  for (float mu : Cosines())
  {
    rayleigh.push_back({ { mu, 0.0f, 0.0f, 0.0f } });
    for (float g : kAsymmetries)
    {
      lobes.push_back({ { mu, g, 0.0f, 0.0f } });
    }
  }
  EXPECT_LT(WorstError(
              "Rayleigh", RayleighFunction, rayleigh,
              [](const Arguments& a) {
                return Result{ { nimbus::Rayleigh(a[0]), 0.0 } };
              },
              kRelative),
    3e-7); // measured 9.8e-8 (llvmpipe)
  EXPECT_LT(WorstError(
              "HenyeyGreenstein", HenyeyGreensteinFunction, lobes,
              [](const Arguments& a) {
                return Result{ { nimbus::HenyeyGreenstein(a[0], a[1]), 0.0 } };
              },
              kRelative),
    1e-6); // measured 2.8e-7 (llvmpipe)
  EXPECT_LT(WorstError(
              "CornetteShanks", CornetteShanksFunction, lobes,
              [](const Arguments& a) {
                return Result{ { nimbus::CornetteShanks(a[0], a[1]), 0.0 } };
              },
              kRelative),
    1e-6); // measured 3.3e-7 (llvmpipe)
}

// nimbusColor.glsl against Physics/SpectralColor.h. Absolute error (values in [0, 1]).
TEST(ShaderTwins, SrgbTransferFunctions)
{
  std::vector<Arguments> grid;
  for (float c : Range(-0.1f, 1.1f, 2401))
  {
    grid.push_back({ { c, 0.0f, 0.0f, 0.0f } });
  }
  for (float c : { 0.0031308f, 0.04045f, 1e-6f, 0.999999f })
  {
    grid.push_back({ { c, 0.0f, 0.0f, 0.0f } });
  }
  EXPECT_LT(WorstError(
              "SrgbEncode", SrgbEncodeFunction, grid,
              [](const Arguments& a) {
                return Result{ { nimbus::SrgbEncode(a[0]), 0.0 } };
              },
              kAbsolute),
    1e-6); // measured 2.2e-7 (llvmpipe)
  EXPECT_LT(WorstError(
              "SrgbDecode", SrgbDecodeFunction, grid,
              [](const Arguments& a) {
                return Result{ { nimbus::SrgbDecode(a[0]), 0.0 } };
              },
              kAbsolute),
    1e-6); // measured 3.1e-7 (llvmpipe)
}

// nimbusAtmosphere.glsl against Physics/Atmosphere.h.
TEST(ShaderTwins, AtmosphereGeometryAndLayers)
{
  const float earth = 6360000.0f, top = 6420000.0f;
  std::vector<Arguments> distances;
  for (float height : { 0.0f, 10.0f, 1000.0f, 10000.0f, 59000.0f })
  {
    for (float mu : Range(-1.0f, 1.0f, 401))
    {
      distances.push_back({ { earth + height, mu, top, 0.0f } });
    }
  }
  // Relative to the distance, floored at 10 km: float radii of 6.4e6 m resolve 0.5 m,
  // so short distances near the top are good to a few tenths of a metre.
  EXPECT_LT(WorstError(
              "DistanceToTopOfAtmosphere", DistanceToTopFunction, distances,
              [](const Arguments& a) {
                return Result{ { nimbus::DistanceToTopOfAtmosphere(a[0], a[1], a[2]), 0.0 } };
              },
              ErrorMeasure{ true, 1e4 }),
    1e-4); // measured 3.6e-5 (llvmpipe)

  std::vector<Arguments> layers;
  for (float altitude : { -10.0f, 0.0f, 500.0f, 2000.0f, 8000.0f })
  {
    for (float cosZenith : Range(-1.0f, 1.0f, 81))
    {
      for (float distance : { 10.0f, 1000.0f, 30000.0f, 100000.0f })
      {
        for (float scaleHeight : { 1200.0f, 8000.0f })
        {
          // The mapper's rays end at the ground: none runs more than 100 m below sea
          // level (where the layer's density, and in float the length, overflows).
          if (altitude + distance * cosZenith >= -100.0f)
          {
            layers.push_back({ { altitude, cosZenith, distance, scaleHeight } });
          }
        }
      }
    }
  }
  for (float cosZenith :
    { 1e-9f, 1e-7f, -1e-7f, 1e-5f, 1.1e-2f, -1.1e-2f }) // both sides of the series
  {
    layers.push_back({ { 100.0f, cosZenith, 1000.0f, 1200.0f } });
  }
  EXPECT_LT(WorstError(
              "FlatLayerOpticalLength", FlatLayerFunction, layers,
              [](const Arguments& a) {
                return Result{ { nimbus::FlatLayerOpticalLength(a[0], a[1], a[2], a[3]), 0.0 } };
              },
              kRelative),
    2.5e-5); // measured 7.9e-6 (llvmpipe)
}

// nimbusSkyView.glsl against nimbus::SkyViewMapping (Physics/Sky.h). Absolute error
// in texels.
TEST(ShaderTwins, SkyViewMapping)
{
  const std::vector<float> horizons = { static_cast<float>(nimbus::kPi / 2.0), 1.6f, 1.8f };
  auto mapping = [](float horizon)
  {
    nimbus::SkyViewMapping m;
    m.Width = static_cast<int>(kSkyColumns);
    m.AboveRows = static_cast<int>(kSkyRowsAbove);
    m.BelowRows = static_cast<int>(kSkyRowsBelow);
    m.HorizonZenith = horizon;
    return m;
  };
  std::vector<Arguments> rows;
  for (float horizon : horizons)
  {
    for (float zenith : Range(0.0f, static_cast<float>(nimbus::kPi), 1001))
    {
      rows.push_back({ { zenith, horizon, 0.0f, 0.0f } });
    }
  }
  EXPECT_LT(WorstError(
              "SkyViewRow", SkyViewRowFunction, rows,
              [&](const Arguments& a) {
                return Result{ { mapping(a[1]).Row(a[0]), 0.0 } };
              },
              kAbsolute),
    4e-5); // measured 1.2e-5 rows (llvmpipe)

  std::vector<Arguments> texels;
  std::mt19937 random(7);
  std::uniform_real_distribution<float> zenith(0.0f, static_cast<float>(nimbus::kPi)),
    azimuth(-3.1f, 3.1f);
  for (float sunAzimuth : { 0.0f, 1.0f, 3.0f, 5.5f })
  {
    for (float horizon : horizons)
    {
      for (int k = 0; k < 400; ++k)
      {
        // Rows are split at the horizon (no row straddles it): which side a direction
        // within float rounding of the horizon lands on is rounding, not a difference.
        const float z = zenith(random);
        if (std::abs(z - horizon) > 1e-4f)
        {
          texels.push_back({ { z, azimuth(random), sunAzimuth, horizon } });
        }
      }
    }
  }
  EXPECT_LT(WorstError(
              "SkyViewTexel", SkyViewTexelFunction, texels,
              [&](const Arguments& a)
              {
                // The direction from the same float angles, in double.
                const double z = a[0], phi = a[1];
                const nimbus::Vector3 w{ { std::sin(z) * std::sin(phi), std::sin(z) * std::cos(phi),
                  std::cos(z) } };
                Result texel{ { 0.0, 0.0 } };
                mapping(a[3]).Texel(w, a[2] / nimbus::kDegree, texel[0], texel[1]);
                return texel;
              },
              kAbsolute, 2),
    7e-3); // measured 2.3e-3 texels (llvmpipe)
}
