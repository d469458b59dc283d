// The GLSL library (Representations/Shaders/nimbus*.glsl, ShaderLibrary.h) against
// its C++ twins in Physics/: every library function is evaluated on the GPU on a grid
// of arguments (one fragment per argument set, read from a float texture, written to
// a float render target) and compared with the C++ function evaluated on the same
// arguments (the float values, in double precision). What differs is float
// arithmetic and the GPU's transcendental functions; the bounds below are the errors
// measured on Mesa llvmpipe (printed by the test), rounded up by about 3x.
//
// No VTK and no display: an OpenGL 3.3 core context through EGL (a GPU device when
// EGL lists one, else Mesa's surfaceless platform), so the same program runs in CI and
// on a machine with a GPU and no X server. NIMBUS_EGL_DEVICE=<n> picks EGL device n.
#include "Atmosphere.h"
#include "Math.h"
#include "PhaseFunctions.h"
#include "ShaderLibrary.h"
#include "Sky.h"
#include "SpectralColor.h"

#define GL_GLEXT_PROTOTYPES 1
#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GL/gl.h>
#include <GL/glext.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <random>
#include <stdexcept>
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

// A triangle that covers the viewport, from gl_VertexID (no vertex buffer).
const char* kVertexShader = R"(#version 330 core
void main()
{
  vec2 corner = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2));
  gl_Position = vec4(2.0 * corner - 1.0, 0.0, 1.0);
}
)";

const char* kFragmentShader = R"(#version 330 core
//NIMBUS::Library
//NIMBUS::SkyView
uniform sampler2D arguments;
uniform int function;
out vec4 fragmentColor;

void main()
{
  // This fragment's argument set: texel (i, j) of the argument texture.
  vec4 a = texelFetch(arguments, ivec2(gl_FragCoord.xy), 0);
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
  fragmentColor = vec4(result, 0.0, 1.0);
}
)";

/// An OpenGL context without a window (EGL), and the evaluation machinery.
class Gpu
{
public:
  static Gpu& Get()
  {
    static Gpu gpu;
    return gpu;
  }

  bool Ready() const { return this->Program != 0; }
  const std::string& Problem() const { return this->Error; }

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
    GLuint textures[2], framebuffer;
    glGenTextures(2, textures);
    for (int k = 0; k < 2; ++k)
    {
      glBindTexture(GL_TEXTURE_2D, textures[k]);
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
      glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, width, height, 0, GL_RGBA, GL_FLOAT,
        k == 0 ? input.data() : nullptr);
    }
    glGenFramebuffers(1, &framebuffer);
    glBindFramebuffer(GL_FRAMEBUFFER, framebuffer);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, textures[1], 0);
    std::vector<float> output(static_cast<std::size_t>(width) * height * 4, 0.0f);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE)
    {
      glViewport(0, 0, width, height);
      glUseProgram(this->Program);
      glActiveTexture(GL_TEXTURE0);
      glBindTexture(GL_TEXTURE_2D, textures[0]);
      glUniform1i(glGetUniformLocation(this->Program, "arguments"), 0);
      glUniform1i(glGetUniformLocation(this->Program, "function"), static_cast<int>(function));
      glBindVertexArray(this->VertexArray);
      glDrawArrays(GL_TRIANGLES, 0, 3);
      glPixelStorei(GL_PACK_ALIGNMENT, 1);
      glReadPixels(0, 0, width, height, GL_RGBA, GL_FLOAT, output.data());
    }
    else
    {
      ADD_FAILURE() << "the float render target is incomplete";
    }
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glDeleteFramebuffers(1, &framebuffer);
    glDeleteTextures(2, textures);
    std::vector<Result> results(arguments.size());
    for (std::size_t i = 0; i < arguments.size(); ++i)
    {
      results[i] = { { output[4 * i], output[4 * i + 1] } };
    }
    return results;
  }

private:
  Gpu()
  {
    if (!this->CreateContext())
    {
      return;
    }
    std::printf("OpenGL: %s, %s, %s\n", glGetString(GL_VENDOR), glGetString(GL_RENDERER),
      glGetString(GL_VERSION));
    this->Program = this->Link(kVertexShader, nimbus::WithShaderLibrary(kFragmentShader));
    glGenVertexArrays(1, &this->VertexArray);
  }

  /// An EGL display: device `NIMBUS_EGL_DEVICE` (default: the first that initialises),
  /// else Mesa's surfaceless platform, else the default display.
  EGLDisplay OpenDisplay()
  {
    auto queryDevices =
      reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
    auto platformDisplay = reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(
      eglGetProcAddress("eglGetPlatformDisplayEXT"));
    EGLint major = 0, minor = 0;
    if (queryDevices && platformDisplay)
    {
      EGLDeviceEXT devices[16];
      EGLint count = 0;
      if (queryDevices(16, devices, &count) && count > 0)
      {
        const char* wanted = std::getenv("NIMBUS_EGL_DEVICE");
        for (EGLint d = 0; d < count; ++d)
        {
          if (wanted && std::atoi(wanted) != d)
          {
            continue;
          }
          EGLDisplay display = platformDisplay(EGL_PLATFORM_DEVICE_EXT, devices[d], nullptr);
          if (display != EGL_NO_DISPLAY && eglInitialize(display, &major, &minor))
          {
            return display;
          }
        }
      }
    }
    if (platformDisplay)
    {
      EGLDisplay display =
        platformDisplay(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
      if (display != EGL_NO_DISPLAY && eglInitialize(display, &major, &minor))
      {
        return display;
      }
    }
    EGLDisplay display = eglGetDisplay(EGL_DEFAULT_DISPLAY);
    if (display != EGL_NO_DISPLAY && eglInitialize(display, &major, &minor))
    {
      return display;
    }
    return EGL_NO_DISPLAY;
  }

  bool CreateContext()
  {
    EGLDisplay display = this->OpenDisplay();
    if (display == EGL_NO_DISPLAY)
    {
      this->Error = "no EGL display";
      return false;
    }
    // No surface is drawn to (the context is made current without one), but
    // eglChooseConfig asks for window surfaces unless told otherwise.
    const EGLint configAttributes[] = { EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_SURFACE_TYPE,
      EGL_PBUFFER_BIT, EGL_NONE };
    EGLConfig config;
    EGLint configs = 0;
    if (!eglBindAPI(EGL_OPENGL_API) ||
      !eglChooseConfig(display, configAttributes, &config, 1, &configs) || configs < 1)
    {
      this->Error = "no EGL configuration with OpenGL";
      return false;
    }
    const EGLint contextAttributes[] = { EGL_CONTEXT_MAJOR_VERSION, 3, EGL_CONTEXT_MINOR_VERSION, 3,
      EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE };
    EGLContext context = eglCreateContext(display, config, EGL_NO_CONTEXT, contextAttributes);
    if (context == EGL_NO_CONTEXT ||
      !eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context))
    {
      this->Error = "no OpenGL 3.3 core context without a surface";
      return false;
    }
    return true;
  }

  GLuint Compile(GLenum type, const std::string& source)
  {
    GLuint shader = glCreateShader(type);
    const char* text = source.c_str();
    glShaderSource(shader, 1, &text, nullptr);
    glCompileShader(shader);
    GLint ok = 0;
    glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
    if (!ok)
    {
      char log[4096];
      glGetShaderInfoLog(shader, sizeof(log), nullptr, log);
      this->Error += std::string("shader compilation failed: ") + log;
    }
    return shader;
  }

  GLuint Link(const std::string& vertex, const std::string& fragment)
  {
    GLuint program = glCreateProgram();
    glAttachShader(program, this->Compile(GL_VERTEX_SHADER, vertex));
    glAttachShader(program, this->Compile(GL_FRAGMENT_SHADER, fragment));
    glLinkProgram(program);
    GLint ok = 0;
    glGetProgramiv(program, GL_LINK_STATUS, &ok);
    if (!ok)
    {
      char log[4096];
      glGetProgramInfoLog(program, sizeof(log), nullptr, log);
      this->Error += std::string("program link failed: ") + log;
      return 0;
    }
    return program;
  }

  GLuint Program = 0;
  GLuint VertexArray = 0;
  std::string Error;
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
  ASSERT_TRUE(Gpu::Get().Ready()) << Gpu::Get().Problem();
}

// nimbusPhase.glsl against Physics/PhaseFunctions.h. Relative error.
TEST(ShaderTwins, PhaseFunctions)
{
  ASSERT_TRUE(Gpu::Get().Ready()) << Gpu::Get().Problem();
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
  ASSERT_TRUE(Gpu::Get().Ready()) << Gpu::Get().Problem();
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
  ASSERT_TRUE(Gpu::Get().Ready()) << Gpu::Get().Problem();
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
  // Eyes and paths below sea level too (a ground lowered under the scene's z = 0):
  // the density is the sea level's there, so the length stays finite.
  for (float altitude : { -3000.0f, -10.0f, 0.0f, 500.0f, 2000.0f, 8000.0f })
  {
    for (float cosZenith : Range(-1.0f, 1.0f, 81))
    {
      for (float distance : { 10.0f, 1000.0f, 30000.0f, 100000.0f })
      {
        for (float scaleHeight : { 1200.0f, 8000.0f })
        {
          layers.push_back({ { altitude, cosZenith, distance, scaleHeight } });
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
  ASSERT_TRUE(Gpu::Get().Ready()) << Gpu::Get().Problem();
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
