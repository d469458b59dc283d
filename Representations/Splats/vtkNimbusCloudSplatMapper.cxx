#include "vtkNimbusCloudSplatMapper.h"

#include "AtmosphereTable.h"
#include "CloudSplats.h"
#include "FiniteSetters.h"
#include "FrameTexture.h"
#include "MultipleScattering.h"
#include "MultipleScatteringTexture.h"
#include "ShaderLibrary.h"
#include "Sky.h"
#include "SkyViewTextures.h"
#include "Sun.h"
#include "SunAndAir.h"

#include "cloudSplatCompositeFS.h"
#include "cloudSplatSunFS.h"
#include "cloudSplatSunVS.h"
#include "cloudSplatViewFS.h"
#include "cloudSplatViewVS.h"

#include "vtkActor.h"
#include "vtkAlgorithm.h"
#include "vtkCamera.h"
#include "vtkDataArray.h"
#include "vtkMatrix3x3.h"
#include "vtkMatrix4x4.h"
#include "vtkNimbusSky.h"
#include "vtkNimbusSkyBackground.h"
#include "vtkObjectFactory.h"
#include "vtkOpenGLBufferObject.h"
#include "vtkOpenGLCamera.h"
#include "vtkOpenGLFramebufferObject.h"
#include "vtkOpenGLQuadHelper.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkOpenGLRenderer.h"
#include "vtkOpenGLShaderCache.h"
#include "vtkOpenGLState.h"
#include "vtkOpenGLVertexArrayObject.h"
#include "vtkPointData.h"
#include "vtkPolyData.h"
#include "vtkShaderProgram.h"
#include "vtkTextureObject.h"
#include "vtkTimerLog.h"
#include "vtk_glew.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <exception>
#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace
{
// The billboard texture's side and supersampling, and the partial-column table's sizes.
constexpr int kBillboardSize = 64;
constexpr int kBillboardSupersample = 4;
constexpr int kTableU = 64;
constexpr int kTableH = 128;
// Floats per ball instance: centre (3), radius, kappa, the sun's transmittance (read
// back), the air's tint of the sun at the centre (3), the air's transmittance (3) and
// in-scattered radiance (3) between the eye and the centre.
constexpr int kInstanceFloats = 15;
}

struct vtkNimbusCloudSplatMapper::Internals
{
  // The balls in world coordinates, as read from the input (once per change).
  std::vector<float> Centres; // 3 per ball
  std::vector<float> Radii;
  std::vector<float> Kappa;         // k d R (metres): the column's optical scale
  std::vector<float> Densities;     // d, the centre densities
  std::vector<float> Transmittance; // the sun's, per ball (read-back variant)
  vtkMTimeType BallsTime = 0;
  std::vector<double> SunKey; // what the sun pass's result depends on

  // The sun's frame: axes across the light, the window and the depth range.
  std::array<std::array<double, 3>, 3> Frame{};
  std::array<double, 4> Rect{};       // x min, y min, 1 / width, 1 / height
  std::array<double, 2> DepthRange{}; // depth of the first layer, 1 / (last - first)

  vtkNew<vtkOpenGLBufferObject> SunInstances;
  vtkNew<vtkOpenGLBufferObject> ViewInstances;
  vtkNew<vtkOpenGLVertexArrayObject> SunLayout;
  vtkNew<vtkOpenGLVertexArrayObject> ViewLayout;
  vtkShaderProgram* SunLayoutProgram = nullptr;
  vtkShaderProgram* ViewLayoutProgram = nullptr;
  std::vector<std::array<std::size_t, 2>> LayerRanges;
  std::vector<std::uint32_t> SunOrder;

  vtkNew<vtkTextureObject> SunDepth;    // 3-D: the accumulated optical depth
  vtkNew<vtkTextureObject> SunReadBack; // 2-D: the read-back variant's framebuffer
  vtkNew<vtkTextureObject> Billboard;   // C over the billboard
  vtkNew<vtkTextureObject> Partial;     // P(u, h)
  vtkNew<vtkOpenGLFramebufferObject> Framebuffer;
  vtkOpenGLRenderWindow* Window = nullptr;
  // [1]: with the accumulation texture, [2]: with multiple scattering at the centre.
  std::string ViewVertexSource[4];

  // Multiple scattering: J's SH coefficients (R, G, B) on the splatted grid.
  vtkNew<vtkTextureObject> Scattering[3];
  std::vector<double> ScatteringKey;      // what the last solve depends on
  bool ScatteringOn = false;              // the textures hold a solve
  std::array<float, 3> ScatteringScale{}; // texture coordinate = x scale + offset (world)
  std::array<float, 3> ScatteringOffset{};
  float ForwardPeakFraction = 0.0f;
  double ScatteringSeconds = 0.0;
  int ScatteringSolves = 0;

  // The frame's sun, air and display: the mapper's own or the sky's (ComputeFrameSettings).
  nimbus::SunParameters Sun;
  nimbus::SceneAtmosphere Air; // Enabled only over a sky
  double MetresPerUnit = 1.0;
  std::array<double, 3> DisplayScale{ { 1.0, 1.0, 1.0 } };
  bool OverSky = false;
  double BallsMetres = 0.0; // the metres per unit of the balls' kappa
  std::string LastSkyError;
  // Over a sky: the atmosphere table over the balls' heights (E_sun(z), as the cloud
  // mapper's row 0), the sun's tint at each ball (E_sun(z) / E_sun above the air; 3 per
  // ball, the input's order), and the air between the eye and each ball (3 + 3 per ball;
  // the radiance x the display scale).
  nimbus::AtmosphereTable Table;
  std::vector<double> TintKey;
  std::vector<float> SunTint;
  std::vector<float> AirTransmittance;
  std::vector<float> AirRadiance;
  double AirSeconds = 0.0;
  // The sky seen from the balls' middle (the sky light's solve).
  std::unique_ptr<nimbus::SkyViewLut> SkyView;
  std::vector<double> SkyViewKey;

  // The float target the balls are drawn into, the scene's depth and colour under them.
  vtkNew<vtkTextureObject> FrameSum;
  vtkNew<vtkTextureObject> FrameDepth;
  vtkNew<vtkTextureObject> SceneColor;
  vtkNew<vtkOpenGLFramebufferObject> FrameTarget;
  std::unique_ptr<vtkOpenGLQuadHelper> Composite;
  bool WarnedMultisampling = false;

  double SunSeconds = 0.0;
  double ViewSeconds = 0.0;
  vtkIdType Balls = 0;
  bool ReportedError = false;

  void Release(vtkWindow* window)
  {
    if (window)
    {
      for (vtkTextureObject* texture : { this->SunDepth.Get(), this->SunReadBack.Get(),
             this->Billboard.Get(), this->Partial.Get() })
      {
        texture->ReleaseGraphicsResources(window);
      }
      this->Framebuffer->ReleaseGraphicsResources(window);
      for (vtkTextureObject* texture :
        { this->FrameSum.Get(), this->FrameDepth.Get(), this->SceneColor.Get() })
      {
        texture->ReleaseGraphicsResources(window);
      }
      this->FrameTarget->ReleaseGraphicsResources(window);
      if (this->Composite)
      {
        this->Composite->ReleaseGraphicsResources(window);
      }
      for (auto& texture : this->Scattering)
      {
        texture->ReleaseGraphicsResources(window);
      }
    }
    this->ScatteringKey.clear();
    this->ScatteringOn = false;
    this->SunInstances->ReleaseGraphicsResources();
    this->ViewInstances->ReleaseGraphicsResources();
    this->SunLayout->ReleaseGraphicsResources();
    this->ViewLayout->ReleaseGraphicsResources();
    this->SunLayoutProgram = nullptr;
    this->ViewLayoutProgram = nullptr;
    this->SunKey.clear();
    this->Composite.reset();
    this->Window = nullptr;
  }

  // The splats' frame targets (FrameTexture.h); an allocation that fails stops the frame.
  static void EnsureTarget(vtkTextureObject* texture, vtkOpenGLRenderWindow* window, int w, int h,
    nimbus::FrameTextureFormat format)
  {
    if (!nimbus::EnsureFrameTexture(texture, window, w, h, format))
    {
      throw std::runtime_error("the splats' frame target could not be allocated");
    }
  }

  // A linear-filtered, edge-clamped single-channel float texture from values.
  static void Upload2D(
    vtkTextureObject* texture, vtkOpenGLRenderWindow* window, int w, int h, std::vector<float> data)
  {
    texture->SetContext(window);
    if (texture->GetHandle())
    {
      return;
    }
    texture->SetWrapS(vtkTextureObject::ClampToEdge);
    texture->SetWrapT(vtkTextureObject::ClampToEdge);
    texture->SetMinificationFilter(vtkTextureObject::Linear);
    texture->SetMagnificationFilter(vtkTextureObject::Linear);
    texture->Create2DFromRaw(w, h, 1, VTK_FLOAT, data.data());
  }

  // The instances of `order` (centre, radius, kappa, sun transmittance) into `buffer`.
  void UploadInstances(vtkOpenGLBufferObject* buffer, const std::vector<std::uint32_t>& order)
  {
    std::vector<float> data(order.size() * kInstanceFloats);
    for (std::size_t n = 0; n < order.size(); ++n)
    {
      const std::uint32_t i = order[n];
      float* d = &data[n * kInstanceFloats];
      d[0] = this->Centres[3 * i];
      d[1] = this->Centres[3 * i + 1];
      d[2] = this->Centres[3 * i + 2];
      d[3] = this->Radii[i];
      d[4] = this->Kappa[i];
      d[5] = this->Transmittance.empty() ? 1.0f : this->Transmittance[i];
      for (int c = 0; c < 3; ++c)
      {
        d[6 + c] = this->SunTint.empty() ? 1.0f : this->SunTint[3 * i + c];
        d[9 + c] = this->AirTransmittance.empty() ? 1.0f : this->AirTransmittance[3 * i + c];
        d[12 + c] = this->AirRadiance.empty() ? 0.0f : this->AirRadiance[3 * i + c];
      }
    }
    buffer->Upload(data, vtkOpenGLBufferObject::ArrayBuffer);
  }

  // Binds `layout` for `program` over `buffer`'s instances.
  static void BindLayout(vtkOpenGLVertexArrayObject* layout, vtkShaderProgram*& layoutProgram,
    vtkShaderProgram* program, vtkOpenGLBufferObject* buffer, bool view = false)
  {
    if (layoutProgram != program)
    {
      layout->ShaderProgramChanged();
      layout->Bind();
      const int stride = kInstanceFloats * sizeof(float);
      layout->AddAttributeArrayWithDivisor(
        program, buffer, "ball", 0, stride, VTK_FLOAT, 4, false, 1, false);
      layout->AddAttributeArrayWithDivisor(
        program, buffer, "ballOptics", 4 * sizeof(float), stride, VTK_FLOAT, 2, false, 1, false);
      if (view)
      {
        layout->AddAttributeArrayWithDivisor(
          program, buffer, "ballTint", 6 * sizeof(float), stride, VTK_FLOAT, 3, false, 1, false);
        layout->AddAttributeArrayWithDivisor(program, buffer, "ballAirTransmittance",
          9 * sizeof(float), stride, VTK_FLOAT, 3, false, 1, false);
        layout->AddAttributeArrayWithDivisor(program, buffer, "ballAirRadiance", 12 * sizeof(float),
          stride, VTK_FLOAT, 3, false, 1, false);
      }
      layoutProgram = program;
    }
    else
    {
      layout->Bind();
    }
  }

  void SetSunFrameUniforms(vtkShaderProgram* program) const
  {
    float v[3];
    for (int axis = 0; axis < 3; ++axis)
    {
      for (int c = 0; c < 3; ++c)
      {
        v[c] = static_cast<float>(this->Frame[axis][c]);
      }
      program->SetUniform3f(axis == 0 ? "sunAxisX" : (axis == 1 ? "sunAxisY" : "toSun"), v);
    }
    const float rect[4] = { static_cast<float>(this->Rect[0]), static_cast<float>(this->Rect[1]),
      static_cast<float>(this->Rect[2]), static_cast<float>(this->Rect[3]) };
    program->SetUniform4f("sunRect", rect);
  }
};

vtkStandardNewMacro(vtkNimbusCloudSplatMapper);
nimbusDefineFiniteSetter(vtkNimbusCloudSplatMapper, SunAzimuthDegrees);
nimbusDefineFiniteSetter(vtkNimbusCloudSplatMapper, SunElevationDegrees);
nimbusDefineFiniteSetter(vtkNimbusCloudSplatMapper, SunIlluminance);
nimbusDefineFiniteSetter(vtkNimbusCloudSplatMapper, SunTemperatureKelvin);
nimbusDefineFiniteSetter(vtkNimbusCloudSplatMapper, ExtinctionPerDensity);
nimbusDefineFiniteSetter(vtkNimbusCloudSplatMapper, Albedo);
nimbusDefineFiniteSetter(vtkNimbusCloudSplatMapper, CloudG);
nimbusDefineFiniteSetter(vtkNimbusCloudSplatMapper, MetresPerUnit);
nimbusDefineFiniteSetter(vtkNimbusCloudSplatMapper, Exposure);

vtkNimbusCloudSplatMapper::vtkNimbusCloudSplatMapper()
  : Internal(new Internals)
{
  this->SetRadiusArrayName("radius");
  this->SetDensityArrayName("density");
}

vtkNimbusCloudSplatMapper::~vtkNimbusCloudSplatMapper()
{
  this->SetRadiusArrayName(nullptr);
  this->SetDensityArrayName(nullptr);
  this->SetSkyBackground(nullptr);
}

vtkCxxSetObjectMacro(vtkNimbusCloudSplatMapper, SkyBackground, vtkNimbusSkyBackground);

double vtkNimbusCloudSplatMapper::GetLastAirSeconds() const
{
  return this->Internal->AirSeconds;
}

double vtkNimbusCloudSplatMapper::GetLastSunPassSeconds() const
{
  return this->Internal->SunSeconds;
}

double vtkNimbusCloudSplatMapper::GetLastViewPassSeconds() const
{
  return this->Internal->ViewSeconds;
}

double vtkNimbusCloudSplatMapper::GetLastMultipleScatteringSeconds() const
{
  return this->Internal->ScatteringSeconds;
}

int vtkNimbusCloudSplatMapper::GetNumberOfMultipleScatteringSolves() const
{
  return this->Internal->ScatteringSolves;
}

vtkIdType vtkNimbusCloudSplatMapper::GetLastNumberOfBalls() const
{
  return this->Internal->Balls;
}

void vtkNimbusCloudSplatMapper::ReleaseGraphicsResources(vtkWindow* window)
{
  this->Internal->Release(window);
  this->Superclass::ReleaseGraphicsResources(window);
}

// The balls in world coordinates (the actor's matrix applied), their optical scales, when
// the input, the mapper or the actor changed. False when there is nothing to draw.
bool vtkNimbusCloudSplatMapper::UpdateBalls(vtkPolyData* input, vtkActor* actor)
{
  Internals& in = *this->Internal;
  const vtkMTimeType time =
    std::max({ input->GetMTime(), this->GetMTime(), actor->GetMatrix()->GetMTime() });
  if (time == in.BallsTime && in.MetresPerUnit == in.BallsMetres)
  {
    return !in.Radii.empty();
  }
  in.BallsTime = time;
  in.BallsMetres = in.MetresPerUnit;
  in.TintKey.clear();
  in.SunKey.clear();
  in.Centres.clear();
  in.Radii.clear();
  in.Kappa.clear();
  in.Densities.clear();
  in.Transmittance.clear();
  vtkDataArray* radii =
    this->RadiusArrayName ? input->GetPointData()->GetArray(this->RadiusArrayName) : nullptr;
  vtkDataArray* densities =
    this->DensityArrayName ? input->GetPointData()->GetArray(this->DensityArrayName) : nullptr;
  if (!radii || !densities)
  {
    vtkErrorMacro("The input has no point array \""
      << (radii ? (this->DensityArrayName ? this->DensityArrayName : "")
                : (this->RadiusArrayName ? this->RadiusArrayName : ""))
      << "\" (RadiusArrayName, DensityArrayName): nothing drawn.");
    return false;
  }
  vtkMatrix4x4* matrix = actor->GetMatrix();
  const double scale = std::cbrt(std::abs(matrix->Determinant()));
  const vtkIdType n = input->GetNumberOfPoints();
  in.Centres.reserve(3 * n);
  in.Radii.reserve(n);
  in.Kappa.reserve(n);
  for (vtkIdType i = 0; i < n; ++i)
  {
    const double radius = radii->GetComponent(i, 0) * scale;
    const double density = densities->GetComponent(i, 0);
    double p[4] = { 0, 0, 0, 1 };
    input->GetPoint(i, p);
    matrix->MultiplyPoint(p, p);
    // k d R (R in metres): tau through the column = kappa C(u) (CloudSplats.h).
    const double kappa = this->ExtinctionPerDensity * density * radius * in.MetresPerUnit;
    if (!(radius > 0.0) || !(density > 0.0) || !std::isfinite(radius) || !std::isfinite(kappa) ||
      !std::isfinite(p[0] + p[1] + p[2]))
    {
      continue; // empty (or invalid) balls add nothing
    }
    in.Centres.insert(in.Centres.end(),
      { static_cast<float>(p[0]), static_cast<float>(p[1]), static_cast<float>(p[2]) });
    in.Radii.push_back(static_cast<float>(radius));
    in.Kappa.push_back(static_cast<float>(kappa));
    in.Densities.push_back(static_cast<float>(density));
  }
  return !in.Radii.empty();
}

void vtkNimbusCloudSplatMapper::Render(vtkRenderer* renderer, vtkActor* actor)
{
  Internals& in = *this->Internal;
  if (renderer->GetSelector() || renderer->GetRenderWindow()->CheckAbortStatus())
  {
    return; // light, not a surface to pick
  }
  int port = 0;
  vtkAlgorithm* producer =
    this->GetNumberOfInputConnections(0) ? this->GetInputAlgorithm(0, 0, port) : nullptr;
  if (!this->Static && producer)
  {
    producer->Update(port);
  }
  vtkPolyData* input = this->GetInput();
  auto* window = vtkOpenGLRenderWindow::SafeDownCast(renderer->GetRenderWindow());
  if (!input || !window || input->GetNumberOfPoints() == 0)
  {
    return;
  }
  if (in.Window && in.Window != window)
  {
    in.Release(in.Window);
  }
  in.Window = window;
  try
  {
    this->ComputeFrameSettings();
    if (!this->UpdateBalls(input, actor))
    {
      in.Balls = 0;
      return;
    }
    in.Balls = static_cast<vtkIdType>(in.Radii.size());
    Internals::Upload2D(in.Billboard, window, kBillboardSize, kBillboardSize,
      nimbus::SplatColumnTexture(kBillboardSize, kBillboardSupersample));
    Internals::Upload2D(
      in.Partial, window, kTableU, kTableH, nimbus::SplatPartialColumnTable(kTableU, kTableH));

    // The sun's pass, again only when the balls, the sun or its texture changed.
    const nimbus::Vector3 toSun =
      nimbus::SunDirection(in.Sun.ElevationDegrees, in.Sun.AzimuthDegrees);
    const std::vector<double> sunKey = { toSun[0], toSun[1], toSun[2],
      static_cast<double>(this->SunLightMethod), static_cast<double>(this->SunTextureSize),
      static_cast<double>(this->SunTextureLayers) };
    vtkNew<vtkTimerLog> timer;
    timer->StartTimer();
    if (sunKey != in.SunKey)
    {
      in.Frame = nimbus::SplatFrame(toSun);
      if (this->SunLightMethod == FramebufferReadBack)
      {
        this->SunPassReadBack(window);
      }
      else
      {
        this->SunPassTexture(window);
      }
      in.SunKey = sunKey;
      if (this->TimePasses)
      {
        glFinish();
      }
    }
    timer->StopTimer();
    in.SunSeconds = timer->GetElapsedTime();
    this->UpdateSunTint();
    if (this->MultipleScattering || (in.OverSky && this->SkyLight))
    {
      this->UpdateMultipleScattering(window, toSun.data());
    }
    timer->StartTimer();
    this->DrawIntoFloatTarget(renderer, window);
    if (this->TimePasses)
    {
      glFinish();
    }
    timer->StopTimer();
    in.ViewSeconds = timer->GetElapsedTime();
    in.ReportedError = false;
  }
  catch (const std::exception& error)
  {
    if (!in.ReportedError)
    {
      vtkErrorMacro("Cloud splats not drawn: " << error.what());
      in.ReportedError = true;
    }
    in.SunKey.clear();
  }
}

namespace
{
// The sun's irradiance above the air, linear sRGB of its blackbody spectrum (relative).
std::array<double, 3> SunIrradianceRgb(const nimbus::SunParameters& sun)
{
  nimbus::SceneAtmosphere air;
  air.Enabled = false;
  const nimbus::SunAndAir sunAndAir(sun, air, 16);
  const std::array<double, 3> rgb = sunAndAir.ToLinearSrgb(sunAndAir.GetSunIrradiance());
  return { std::max(rgb[0], 0.0), std::max(rgb[1], 0.0), std::max(rgb[2], 0.0) };
}

// The balls' window across the sun's light and their depth range along it (world units).
void SunWindow(const std::vector<float>& centres, const std::vector<float>& radii,
  const std::array<std::array<double, 3>, 3>& frame, std::array<double, 4>& rect,
  std::array<double, 2>& depth, std::vector<float>& centreDepths)
{
  double lo[3] = { std::numeric_limits<double>::max(), std::numeric_limits<double>::max(),
    std::numeric_limits<double>::max() };
  double hi[3] = { -lo[0], -lo[1], -lo[2] };
  centreDepths.resize(radii.size());
  for (std::size_t i = 0; i < radii.size(); ++i)
  {
    const double p[3] = { centres[3 * i], centres[3 * i + 1], centres[3 * i + 2] };
    for (int a = 0; a < 3; ++a)
    {
      double x = frame[a][0] * p[0] + frame[a][1] * p[1] + frame[a][2] * p[2];
      if (a == 2)
      {
        x = -x; // depth grows away from the sun
        centreDepths[i] = static_cast<float>(x);
      }
      lo[a] = std::min(lo[a], x - radii[i]);
      hi[a] = std::max(hi[a], x + radii[i]);
    }
  }
  const double width = std::max(hi[0] - lo[0], 1e-30);
  const double height = std::max(hi[1] - lo[1], 1e-30);
  rect = { lo[0], lo[1], 1.0 / width, 1.0 / height };
  depth = { lo[2], 1.0 / std::max(hi[2] - lo[2], 1e-30) };
}
}

namespace
{
// The GL state of a pass facing the sun, saved and restored around it: `target`
// (size x size) the only colour attachment of `framebuffer`, cleared; no scissor, depth
// test or culling; the blend summing the balls (Sum, cleared to 0) or multiplying their
// attenuation in (Multiply, cleared to 1).
class SunPassTarget
{
public:
  enum Blend
  {
    Sum,
    Multiply
  };
  SunPassTarget(vtkOpenGLRenderWindow* window, vtkOpenGLFramebufferObject* framebuffer,
    vtkTextureObject* target, int size, Blend blend)
    : State(window->GetState())
    , ViewportSaver(State)
    , ScissorSaver(State, GL_SCISSOR_TEST)
    , DepthSaver(State, GL_DEPTH_TEST)
    , BlendSaver(State, GL_BLEND)
    , CullSaver(State, GL_CULL_FACE)
    , BlendFuncSaver(State)
    , ClearSaver(State)
    , MaskSaver(State)
    , Framebuffer(framebuffer)
  {
    this->State->PushFramebufferBindings();
    framebuffer->SetContext(window);
    framebuffer->Bind(GL_FRAMEBUFFER);
    framebuffer->AddColorAttachment(0, target);
    framebuffer->ActivateDrawBuffer(0);
    framebuffer->ActivateReadBuffer(0);
    vtkOpenGLState* state = this->State;
    state->vtkglViewport(0, 0, size, size);
    state->vtkglDisable(GL_SCISSOR_TEST);
    state->vtkglDisable(GL_DEPTH_TEST);
    state->vtkglDisable(GL_CULL_FACE);
    state->vtkglEnable(GL_BLEND);
    if (blend == Sum)
    {
      state->vtkglBlendFuncSeparate(GL_ONE, GL_ONE, GL_ONE, GL_ONE);
    }
    else
    {
      state->vtkglBlendFuncSeparate(GL_ZERO, GL_SRC_COLOR, GL_ZERO, GL_SRC_COLOR);
    }
    state->vtkglColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    const float clear = blend == Sum ? 0.0f : 1.0f;
    state->vtkglClearColor(clear, clear, clear, clear);
    state->vtkglClear(GL_COLOR_BUFFER_BIT);
  }
  ~SunPassTarget()
  {
    this->Framebuffer->RemoveColorAttachment(0);
    this->State->PopFramebufferBindings();
  }
  SunPassTarget(const SunPassTarget&) = delete;
  SunPassTarget& operator=(const SunPassTarget&) = delete;

private:
  vtkOpenGLState* State;
  vtkOpenGLState::ScopedglViewport ViewportSaver;
  vtkOpenGLState::ScopedglEnableDisable ScissorSaver;
  vtkOpenGLState::ScopedglEnableDisable DepthSaver;
  vtkOpenGLState::ScopedglEnableDisable BlendSaver;
  vtkOpenGLState::ScopedglEnableDisable CullSaver;
  vtkOpenGLState::ScopedglBlendFuncSeparate BlendFuncSaver;
  vtkOpenGLState::ScopedglClearColor ClearSaver;
  vtkOpenGLState::ScopedglColorMask MaskSaver;
  vtkOpenGLFramebufferObject* Framebuffer;
};

} // namespace

// The GPU variant: the optical depth toward the sun accumulated in SunTextureLayers planes
// of a 3-D float texture (002 §3.3's sun-facing billboards, summed instead of multiplied
// and read back): a 2-D running sum gains each slab's columns (only the balls that cross
// the slab are drawn) and is copied into the slab's layer.
void vtkNimbusCloudSplatMapper::SunPassTexture(vtkOpenGLRenderWindow* window)
{
  Internals& in = *this->Internal;
  if (!glDrawArraysInstancedBaseInstance || !glCopyTexSubImage3D)
  {
    throw std::runtime_error("the accumulation texture needs OpenGL 4.2 (base instances)");
  }
  std::vector<float> depths;
  SunWindow(in.Centres, in.Radii, in.Frame, in.Rect, in.DepthRange, depths);
  // Sorted by the front toward the sun (depth - R): slab k draws the range LayerRanges[k].
  const std::array<double, 3> away = { -in.Frame[2][0], -in.Frame[2][1], -in.Frame[2][2] };
  std::vector<float> offsets(in.Radii.size());
  float maxRadius = 0.0f;
  for (std::size_t i = 0; i < offsets.size(); ++i)
  {
    offsets[i] = -in.Radii[i];
    maxRadius = std::max(maxRadius, in.Radii[i]);
  }
  in.SunOrder = nimbus::SplatOrder(in.Centres, away, offsets);
  std::vector<float> sortedFronts(depths.size());
  for (std::size_t n = 0; n < in.SunOrder.size(); ++n)
  {
    sortedFronts[n] = depths[in.SunOrder[n]] - in.Radii[in.SunOrder[n]];
  }
  const int layers = this->SunTextureLayers;
  const double zMin = in.DepthRange[0];
  const double zMax = zMin + 1.0 / in.DepthRange[1];
  const double slab = (zMax - zMin) / (layers - 1);
  in.LayerRanges = nimbus::SplatLayerRanges(sortedFronts, zMin, zMax, layers, 2.0 * maxRadius);
  in.UploadInstances(in.SunInstances, in.SunOrder);

  const int size = this->SunTextureSize;
  vtkTextureObject* texture = in.SunDepth;
  texture->SetContext(window);
  if (!texture->GetHandle() || static_cast<int>(texture->GetWidth()) != size ||
    static_cast<int>(texture->GetDepth()) != layers)
  {
    texture->ReleaseGraphicsResources(window);
    texture->SetWrapS(vtkTextureObject::ClampToEdge);
    texture->SetWrapT(vtkTextureObject::ClampToEdge);
    texture->SetWrapR(vtkTextureObject::ClampToEdge);
    texture->SetMinificationFilter(vtkTextureObject::Linear);
    texture->SetMagnificationFilter(vtkTextureObject::Linear);
    if (!texture->Allocate3D(size, size, layers, 1, VTK_FLOAT))
    {
      throw std::runtime_error("the sun's accumulation texture could not be allocated");
    }
  }
  vtkTextureObject* running = in.SunReadBack; // the running sum (the read-back's target)
  running->SetContext(window);
  if (!running->GetHandle() || static_cast<int>(running->GetWidth()) != size)
  {
    running->ReleaseGraphicsResources(window);
    running->SetMinificationFilter(vtkTextureObject::Nearest);
    running->SetMagnificationFilter(vtkTextureObject::Nearest);
    if (!running->Allocate2D(size, size, 1, VTK_FLOAT))
    {
      throw std::runtime_error("the sun pass's running sum could not be allocated");
    }
  }
  vtkShaderProgram* program =
    window->GetShaderCache()->ReadyShaderProgram(cloudSplatSunVS, cloudSplatSunFS, "");
  if (!program)
  {
    throw std::runtime_error("the sun pass's shaders did not compile");
  }
  SunPassTarget target(window, in.Framebuffer, running, size, SunPassTarget::Sum);
  Internals::BindLayout(in.SunLayout, in.SunLayoutProgram, program, in.SunInstances);
  in.SetSunFrameUniforms(program);
  in.Partial->Activate();
  program->SetUniformi("partialColumn", in.Partial->GetTextureUnit());
  program->SetUniformi("multiply", 0);
  program->SetUniformf("slabThickness", static_cast<float>(slab));
  texture->Activate(); // its unit active: glCopyTexSubImage3D writes into it
  for (int k = 0; k < layers; ++k)
  {
    const auto& range = in.LayerRanges[k];
    if (range[1] > range[0])
    {
      program->SetUniformf("planeDepth", static_cast<float>(zMin + slab * k));
      glDrawArraysInstancedBaseInstance(GL_TRIANGLE_STRIP, 0, 4,
        static_cast<GLsizei>(range[1] - range[0]), static_cast<GLuint>(range[0]));
    }
    glCopyTexSubImage3D(GL_TEXTURE_3D, 0, 0, 0, k, 0, 0, size, size);
  }
  texture->Deactivate();
  in.Partial->Deactivate();
  in.SunLayout->Release();
}

// 002 §3.3's read-back: the framebuffer facing the sun starts at 1; the balls, nearest to
// the sun first, each read the pixel under their centre and then multiply in their
// attenuation ratios.
void vtkNimbusCloudSplatMapper::SunPassReadBack(vtkOpenGLRenderWindow* window)
{
  Internals& in = *this->Internal;
  if (!glDrawArraysInstancedBaseInstance)
  {
    throw std::runtime_error("FramebufferReadBack needs OpenGL 4.2 (base instances)");
  }
  std::vector<float> depths;
  SunWindow(in.Centres, in.Radii, in.Frame, in.Rect, in.DepthRange, depths);
  const std::array<double, 3> away = { -in.Frame[2][0], -in.Frame[2][1], -in.Frame[2][2] };
  in.SunOrder = nimbus::SplatOrder(in.Centres, away, {});
  in.Transmittance.assign(in.Radii.size(), 1.0f);
  in.UploadInstances(in.SunInstances, in.SunOrder);

  const int size = this->SunTextureSize;
  vtkTextureObject* texture = in.SunReadBack;
  texture->SetContext(window);
  if (!texture->GetHandle() || static_cast<int>(texture->GetWidth()) != size)
  {
    texture->ReleaseGraphicsResources(window);
    texture->SetMinificationFilter(vtkTextureObject::Nearest);
    texture->SetMagnificationFilter(vtkTextureObject::Nearest);
    if (!texture->Allocate2D(size, size, 1, VTK_FLOAT))
    {
      throw std::runtime_error("the read-back framebuffer could not be allocated");
    }
  }
  vtkShaderProgram* program =
    window->GetShaderCache()->ReadyShaderProgram(cloudSplatSunVS, cloudSplatSunFS, "");
  if (!program)
  {
    throw std::runtime_error("the sun pass's shaders did not compile");
  }
  SunPassTarget target(window, in.Framebuffer, texture, size, SunPassTarget::Multiply);
  Internals::BindLayout(in.SunLayout, in.SunLayoutProgram, program, in.SunInstances);
  in.SetSunFrameUniforms(program);
  in.Partial->Activate();
  program->SetUniformi("partialColumn", in.Partial->GetTextureUnit());
  program->SetUniformi("multiply", 1);
  program->SetUniformf("planeDepth", 0.0f);
  program->SetUniformf("slabThickness", 1e30f); // whole columns: nothing culled
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  const double halfColumn = nimbus::SplatPartialColumn(0.0, 0.0);
  for (std::size_t n = 0; n < in.SunOrder.size(); ++n)
  {
    const std::uint32_t i = in.SunOrder[n];
    const double p[3] = { in.Centres[3 * i], in.Centres[3 * i + 1], in.Centres[3 * i + 2] };
    const double x =
      (in.Frame[0][0] * p[0] + in.Frame[0][1] * p[1] + in.Frame[0][2] * p[2] - in.Rect[0]) *
      in.Rect[2] * size;
    const double y =
      (in.Frame[1][0] * p[0] + in.Frame[1][1] * p[1] + in.Frame[1][2] * p[2] - in.Rect[1]) *
      in.Rect[3] * size;
    float value = 1.0f;
    glReadPixels(std::clamp(static_cast<int>(x), 0, size - 1),
      std::clamp(static_cast<int>(y), 0, size - 1), 1, 1, GL_RED, GL_FLOAT, &value);
    in.Transmittance[i] = static_cast<float>(value * std::exp(-in.Kappa[i] * halfColumn));
    glDrawArraysInstancedBaseInstance(GL_TRIANGLE_STRIP, 0, 4, 1, static_cast<GLuint>(n));
  }
  in.Partial->Deactivate();
  in.SunLayout->Release();
}

// The billboards facing the viewer, back to front, into the frame.
void vtkNimbusCloudSplatMapper::ViewPass(vtkRenderer* renderer, vtkOpenGLRenderWindow* window)
{
  Internals& in = *this->Internal;
  vtkCamera* camera = renderer->GetActiveCamera();
  double eye[3];
  camera->GetPosition(eye);
  std::vector<std::uint32_t> order;
  if (camera->GetParallelProjection())
  {
    double direction[3];
    camera->GetDirectionOfProjection(direction);
    order = nimbus::SplatOrder(in.Centres, { -direction[0], -direction[1], -direction[2] }, {});
  }
  else
  {
    order = nimbus::SplatOrderBackToFront(in.Centres, { eye[0], eye[1], eye[2] });
  }
  this->UpdateAir(renderer);
  in.UploadInstances(in.ViewInstances, order);

  const bool texture = this->SunLightMethod == AccumulationTexture;
  const int samples = texture ? this->SunLightSamples : 0;
  const bool scattering =
    (this->MultipleScattering || (in.OverSky && this->SkyLight)) && in.ScatteringOn;
  // Multiple scattering at the ball's centre (vertex shader) or along the fragment's ray.
  const bool centreScattering = scattering && samples == 0;
  std::string& source = in.ViewVertexSource[(texture ? 1 : 0) + (centreScattering ? 2 : 0)];
  if (source.empty())
  {
    source = cloudSplatViewVS;
    if (texture)
    {
      vtkShaderProgram::Substitute(source, "//SPLAT::SunTexture", "#define SUN_TEXTURE");
    }
    if (centreScattering)
    {
      vtkShaderProgram::Substitute(
        source, "//SPLAT::MultipleScattering", "#define MULTIPLE_SCATTERING");
    }
    source = nimbus::WithShaderLibrary(source);
  }
  std::string fragment = cloudSplatViewFS;
  if (samples > 0)
  {
    vtkShaderProgram::Substitute(
      fragment, "//SPLAT::SunSamples", "#define SUN_SAMPLES " + std::to_string(samples));
    if (scattering)
    {
      vtkShaderProgram::Substitute(
        fragment, "//SPLAT::MultipleScattering", "#define MULTIPLE_SCATTERING");
    }
    fragment = nimbus::WithShaderLibrary(fragment);
  }
  vtkShaderProgram* program =
    window->GetShaderCache()->ReadyShaderProgram(source.c_str(), fragment.c_str(), "");
  if (!program)
  {
    throw std::runtime_error("the view pass's shaders did not compile");
  }
  vtkOpenGLState* state = window->GetState();
  vtkOpenGLState::ScopedglEnableDisable depthSaver(state, GL_DEPTH_TEST);
  vtkOpenGLState::ScopedglEnableDisable blendSaver(state, GL_BLEND);
  vtkOpenGLState::ScopedglEnableDisable cullSaver(state, GL_CULL_FACE);
  vtkOpenGLState::ScopedglBlendFuncSeparate blendFuncSaver(state);
  vtkOpenGLState::ScopedglDepthMask depthMaskSaver(state);
  vtkOpenGLState::ScopedglDepthFunc depthFuncSaver(state);
  state->vtkglEnable(GL_DEPTH_TEST);
  state->vtkglDepthFunc(GL_LEQUAL);
  state->vtkglDepthMask(GL_FALSE);
  state->vtkglDisable(GL_CULL_FACE);
  state->vtkglEnable(GL_BLEND);
  state->vtkglBlendFuncSeparate(GL_ONE, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);

  Internals::BindLayout(in.ViewLayout, in.ViewLayoutProgram, program, in.ViewInstances, true);
  vtkMatrix4x4* wcvc = nullptr;
  vtkMatrix4x4* vcdc = nullptr;
  vtkMatrix4x4* wcdc = nullptr;
  vtkMatrix3x3* normals = nullptr;
  static_cast<vtkOpenGLCamera*>(camera)->GetKeyMatrices(renderer, wcvc, normals, vcdc, wcdc);
  program->SetUniformMatrix("MCVCMatrix", wcvc); // the balls are in world coordinates
  program->SetUniformMatrix("VCDCMatrix", vcdc);
  const float eyeWorld[3] = { static_cast<float>(eye[0]), static_cast<float>(eye[1]),
    static_cast<float>(eye[2]) };
  program->SetUniform3f("eyeWorld", eyeWorld);
  in.SetSunFrameUniforms(program);
  program->SetUniform2f("sunDepthRange",
    std::array<float, 2>{
      static_cast<float>(in.DepthRange[0]), static_cast<float>(in.DepthRange[1]) }
      .data());
  if (texture)
  {
    in.SunDepth->Activate();
    program->SetUniformi("sunDepth", in.SunDepth->GetTextureUnit());
  }
  in.Billboard->Activate();
  program->SetUniformi("billboard", in.Billboard->GetTextureUnit());
  if (samples > 0)
  {
    in.Partial->Activate();
    program->SetUniformi("partialColumn", in.Partial->GetTextureUnit());
  }
  // The camera's axes in world coordinates: the rows of the view transform.
  vtkMatrix4x4* view = camera->GetViewTransformMatrix();
  const float right[3] = { static_cast<float>(view->GetElement(0, 0)),
    static_cast<float>(view->GetElement(0, 1)), static_cast<float>(view->GetElement(0, 2)) };
  const float up[3] = { static_cast<float>(view->GetElement(1, 0)),
    static_cast<float>(view->GetElement(1, 1)), static_cast<float>(view->GetElement(1, 2)) };
  program->SetUniform3f("viewRight", right);
  program->SetUniform3f("viewUp", up);

  // The sun's colour above the air (linear sRGB of its blackbody spectrum) x the display
  // scale (the exposure, or the sky's exposure and white balance); the air's tint per ball.
  const std::array<double, 3> rgb = SunIrradianceRgb(in.Sun);
  const float color[3] = { static_cast<float>(rgb[0] * in.DisplayScale[0]),
    static_cast<float>(rgb[1] * in.DisplayScale[1]),
    static_cast<float>(rgb[2] * in.DisplayScale[2]) };
  program->SetUniform3f("sunColor", color);
  program->SetUniformf("albedo", static_cast<float>(this->Albedo));
  program->SetUniformf("cloudG", static_cast<float>(this->CloudG));
  if (scattering)
  {
    this->SetMultipleScatteringUniforms(program);
  }
  glDrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, static_cast<GLsizei>(order.size()));
  if (scattering)
  {
    for (auto& t : in.Scattering)
    {
      t->Deactivate();
    }
  }
  in.Billboard->Deactivate();
  if (samples > 0)
  {
    in.Partial->Deactivate();
  }
  if (texture)
  {
    in.SunDepth->Deactivate();
  }
  in.ViewLayout->Release();
}

// The sun's light scattered more than once (003 Eq. 1, iterated: Physics/MultipleScattering.h,
// DiscreteDirections): the balls' density splatted onto a coarse grid, the solve's J(x, w)
// uploaded as three RGBA 3-D textures (SH c_00, c_1-1, c_10, c_11 of R, G, B). Again only
// when the balls (or the mapper's settings) or the sun change, not on camera moves.
void vtkNimbusCloudSplatMapper::UpdateMultipleScattering(
  vtkOpenGLRenderWindow* window, const double toSun[3])
{
  Internals& in = *this->Internal;
  const nimbus::SceneAtmosphere& air = in.Air;
  const std::vector<double> key = { static_cast<double>(in.BallsTime), toSun[0], toSun[1], toSun[2],
    static_cast<double>(this->MultipleScatteringGridSize), this->MultipleScattering ? 1.0 : 0.0,
    in.OverSky && this->SkyLight ? 1.0 : 0.0, in.MetresPerUnit, in.Sun.Illuminance,
    in.Sun.TemperatureKelvin, air.Enabled ? 1.0 : 0.0, air.RayleighScatteringPerMetre,
    air.MieScatteringPerMetre, air.MieG, air.SceneAltitudeMetres,
    this->Sky && in.OverSky ? this->Sky->GetGroundAlbedo() : 0.0 };
  if (key == in.ScatteringKey)
  {
    return;
  }
  in.ScatteringKey = key; // a failed solve is not tried again until something changes
  in.ScatteringOn = false;
  const auto start = std::chrono::steady_clock::now();
  const nimbus::SplatDensityGrid splat = nimbus::SplatBallsOntoGrid(
    in.Centres, in.Radii, in.Densities, this->MultipleScatteringGridSize);
  nimbus::ExtinctionGrid grid;
  grid.Dimensions = splat.Dimensions;
  const double metres = in.MetresPerUnit;
  for (int a = 0; a < 3; ++a)
  {
    grid.Origin[a] = splat.Origin[a] * metres;
    grid.Spacing[a] = splat.Spacing * metres;
    in.ScatteringScale[a] = static_cast<float>(1.0 / (splat.Spacing * splat.Dimensions[a]));
    in.ScatteringOffset[a] = static_cast<float>(
      (0.5 - splat.Origin[a] / splat.Spacing) / splat.Dimensions[a]); // texel centres
  }
  grid.Extinction.resize(splat.Density.size());
  for (std::size_t n = 0; n < splat.Density.size(); ++n)
  {
    grid.Extinction[n] = static_cast<float>(this->ExtinctionPerDensity * splat.Density[n]);
  }
  nimbus::CloudOptics optics;
  optics.Albedo = this->Albedo;
  optics.Phase = nimbus::PhaseFunctionKind::CornetteShanks;
  optics.G = this->CloudG;
  nimbus::CloudLighting lighting;
  lighting.HasSun = true;
  lighting.Sun.ToLight = { { toSun[0], toSun[1], toSun[2] } };
  const std::array<double, 3> rgb = SunIrradianceRgb(in.Sun);
  lighting.Sun.ConstantIrradiance = { { rgb[0], rgb[1], rgb[2] } };
  lighting.HasSun = this->MultipleScattering; // else the sky's light alone
  if (in.OverSky && in.Table.HasAtmosphere)
  {
    const nimbus::AtmosphereTable& table = in.Table; // E_sun(z), z in scene metres
    lighting.Sun.Irradiance = [&table](double z)
    {
      auto e = table.Lookup(0, z);
      for (double& c : e)
      {
        c = std::max(c, 0.0);
      }
      return e;
    };
  }
  nimbus::MultipleScatteringOptions options;
  options.Method = nimbus::MultipleScatteringMethod::DiscreteDirections;
  options.SkyLight = in.OverSky && this->SkyLight;
  if (options.SkyLight &&
    !this->SkyLightOf((splat.Origin[2] + 0.5 * splat.Spacing * (splat.Dimensions[2] - 1)) * metres,
      rgb.data(), lighting))
  {
    return;
  }
  nimbus::MultipleScatteringField field;
  try
  {
    field = nimbus::SolveMultipleScattering(
      grid, optics, lighting, options, [this](double fraction) { this->UpdateProgress(fraction); });
  }
  catch (const std::exception& problem)
  {
    vtkErrorMacro("Multiple scattering not drawn: " << problem.what());
    return;
  }
  vtkTextureObject* const textures[3] = { in.Scattering[0], in.Scattering[1], in.Scattering[2] };
  if (!nimbus::UploadShCoefficients(window, textures, grid.Dimensions, field.Coefficients.data()))
  {
    vtkErrorMacro("Multiple scattering not drawn: its textures could not be uploaded.");
    return;
  }
  // Without the sun in the solve (the sky alone) no forward peak is left on its direction.
  in.ForwardPeakFraction = lighting.HasSun ? static_cast<float>(field.ForwardPeakFraction) : 0.0f;
  in.ScatteringOn = true;
  ++in.ScatteringSolves;
  in.ScatteringSeconds =
    std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void vtkNimbusCloudSplatMapper::SetMultipleScatteringUniforms(vtkShaderProgram* program)
{
  Internals& in = *this->Internal;
  const char* names[3] = { "scatteringRed", "scatteringGreen", "scatteringBlue" };
  for (int c = 0; c < 3; ++c)
  {
    in.Scattering[c]->Activate();
    program->SetUniformi(names[c], in.Scattering[c]->GetTextureUnit());
  }
  program->SetUniform3f("scatteringScale", in.ScatteringScale.data());
  program->SetUniform3f("scatteringOffset", in.ScatteringOffset.data());
  const float scale[3] = { static_cast<float>(in.DisplayScale[0]),
    static_cast<float>(in.DisplayScale[1]), static_cast<float>(in.DisplayScale[2]) };
  program->SetUniform3f("lightScale", scale);
  program->SetUniformf("forwardPeakFraction", in.ForwardPeakFraction);
}

// The frame's sun, air, metres per unit and display: the mapper's own, or over a sky the
// sky's (as vtkNimbusCloudVolumeMapper::ComputeFrameSettings takes them).
void vtkNimbusCloudSplatMapper::ComputeFrameSettings()
{
  Internals& in = *this->Internal;
  in.Sun.AzimuthDegrees = this->SunAzimuthDegrees;
  in.Sun.ElevationDegrees = this->SunElevationDegrees;
  in.Sun.Illuminance = this->SunIlluminance;
  in.Sun.TemperatureKelvin = this->SunTemperatureKelvin;
  in.Air = nimbus::SceneAtmosphere();
  in.Air.Enabled = false;
  in.MetresPerUnit = this->MetresPerUnit;
  in.DisplayScale = { { this->Exposure, this->Exposure, this->Exposure } };
  in.OverSky = false;
  this->Sky = this->SkyBackground && this->SkyBackground->GetVisibility()
    ? this->SkyBackground->GetSky()
    : nullptr;
  if (!this->Sky)
  {
    return;
  }
  const nimbus::SkyParameters* parameters = nullptr;
  try
  {
    parameters = &this->Sky->GetSkyModel().GetParameters();
  }
  catch (const std::exception& error)
  {
    const std::string message = std::string("The sky is invalid, the splats keep their own sun "
                                            "and no air: ") +
      error.what();
    if (message != in.LastSkyError)
    {
      vtkErrorMacro(<< message);
      in.LastSkyError = message;
    }
    this->Sky = nullptr;
    return;
  }
  in.LastSkyError.clear();
  in.Sun.AzimuthDegrees = this->Sky->GetSunAzimuthDegrees();
  in.Sun.ElevationDegrees = this->Sky->GetSunElevationDegrees();
  in.Sun.Illuminance = 1.0; // the sky's sun: luminance 1 above the air
  in.Sun.TemperatureKelvin = parameters->SunTemperatureKelvin;
  static_cast<nimbus::AtmosphereParameters&>(in.Air) = parameters->Atmosphere;
  in.Air.SceneAltitudeMetres = this->Sky->GetSceneAltitudeMetres();
  in.Air.Enabled = true;
  in.MetresPerUnit = this->Sky->GetMetresPerUnit();
  this->Sky->GetDisplayScale(in.DisplayScale.data());
  in.OverSky = true;
}

// Over a sky: the sun at each ball as the cloud mapper's slices see it, E_sun(z) of the
// atmosphere table (nimbus::BuildAtmosphereTable, its row 0) over the balls' heights,
// kept as a tint E_sun(z) / E_sun above the air per ball. Again only when the balls, the
// sun or the air change.
void vtkNimbusCloudSplatMapper::UpdateSunTint()
{
  Internals& in = *this->Internal;
  if (!in.OverSky)
  {
    in.SunTint.clear();
    in.TintKey.clear();
    in.Table = nimbus::AtmosphereTable();
    return;
  }
  const nimbus::SceneAtmosphere& air = in.Air;
  const std::vector<double> key = { static_cast<double>(in.BallsTime), in.MetresPerUnit,
    in.Sun.AzimuthDegrees, in.Sun.ElevationDegrees, in.Sun.TemperatureKelvin,
    air.RayleighScatteringPerMetre, air.MieScatteringPerMetre, air.MieG, air.MieAlbedo,
    air.SceneAltitudeMetres, air.RayleighScaleHeightMetres, air.MieScaleHeightMetres };
  if (key == in.TintKey)
  {
    return;
  }
  double zLow = std::numeric_limits<double>::max();
  double zHigh = -zLow;
  for (std::size_t i = 0; i < in.Radii.size(); ++i)
  {
    zLow = std::min(zLow, static_cast<double>(in.Centres[3 * i + 2] - in.Radii[i]));
    zHigh = std::max(zHigh, static_cast<double>(in.Centres[3 * i + 2] + in.Radii[i]));
  }
  zLow *= in.MetresPerUnit;
  zHigh = std::max(zHigh * in.MetresPerUnit, zLow + 1.0);
  const nimbus::SunAndAir sunAndAir(in.Sun, air, 16); // 16 wavelengths, as the cloud mapper
  in.Table = nimbus::BuildAtmosphereTable(sunAndAir, zLow, zHigh, 64);
  const std::array<double, 3>& top = in.Table.SunIrradianceTop;
  in.SunTint.resize(3 * in.Radii.size());
  for (std::size_t i = 0; i < in.Radii.size(); ++i)
  {
    const std::array<double, 3> e = in.Table.Lookup(0, in.Centres[3 * i + 2] * in.MetresPerUnit);
    for (int c = 0; c < 3; ++c)
    {
      in.SunTint[3 * i + c] =
        top[c] > 0.0 ? static_cast<float>(std::max(e[c], 0.0) / top[c]) : 0.0f;
    }
  }
  in.TintKey = key;
}

// Over a sky, with AerialPerspective: the air between the eye and each ball's centre, its
// transmittance and in-scattered radiance (x the display scale) from the sky's
// aerial-perspective table for the camera's altitude (what vtkNimbusSkyPass applies to
// geometry; Physics/Sky.h AerialPerspectiveLut). Per frame: the eye moves.
void vtkNimbusCloudSplatMapper::UpdateAir(vtkRenderer* renderer)
{
  Internals& in = *this->Internal;
  in.AirSeconds = 0.0;
  if (!in.OverSky || !this->AerialPerspective)
  {
    in.AirTransmittance.clear();
    in.AirRadiance.clear();
    return;
  }
  const auto start = std::chrono::steady_clock::now();
  double eye[3];
  renderer->GetActiveCamera()->GetPosition(eye);
  const double altitude = nimbus::SkyViewTextures::CameraAltitude(this->Sky, eye[2]);
  const nimbus::AerialPerspectiveLut& table = this->Sky->GetAerialPerspectiveLut(altitude);
  const std::size_t n = in.Radii.size();
  in.AirTransmittance.resize(3 * n);
  in.AirRadiance.resize(3 * n);
  for (std::size_t i = 0; i < n; ++i)
  {
    nimbus::Vector3 w{ { in.Centres[3 * i] - eye[0], in.Centres[3 * i + 1] - eye[1],
      in.Centres[3 * i + 2] - eye[2] } };
    const double length = std::sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
    std::array<double, 3> t{ { 1.0, 1.0, 1.0 } };
    std::array<double, 3> l{ { 0.0, 0.0, 0.0 } };
    if (length > 0.0)
    {
      for (double& c : w)
      {
        c /= length;
      }
      table.Lookup(w, length * in.MetresPerUnit, in.Sun.AzimuthDegrees, t, l);
    }
    for (int c = 0; c < 3; ++c)
    {
      in.AirTransmittance[3 * i + c] = static_cast<float>(std::max(t[c], 0.0));
      in.AirRadiance[3 * i + c] = static_cast<float>(std::max(l[c], 0.0) * in.DisplayScale[c]);
    }
  }
  in.AirSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// The sky's and the ground's light for the solve (004 §3.5): the sky seen from the balls'
// middle (height zMiddle, scene metres) as a sky-view table of the sky's model (64 x
// (32 + 16), as the cloud mapper's CloudSkyView), in the units of the mapper's sun
// (sunTop: its linear-sRGB irradiance above the air). False (after an error) when the
// sky's model is refused.
bool vtkNimbusCloudSplatMapper::SkyLightOf(
  double zMiddle, const double sunTop[3], nimbus::CloudLighting& lighting)
{
  Internals& in = *this->Internal;
  try
  {
    const nimbus::SkyModel& model = this->Sky->GetSkyModel();
    const double altitude = std::max(0.0, in.Air.SceneAltitudeMetres + zMiddle);
    const std::vector<double> key = { in.Sun.ElevationDegrees, altitude,
      static_cast<double>(this->Sky->GetModelBuilds()),
      static_cast<double>(reinterpret_cast<std::uintptr_t>(&model)) };
    if (!in.SkyView || key != in.SkyViewKey)
    {
      in.SkyView =
        std::make_unique<nimbus::SkyViewLut>(model, in.Sun.ElevationDegrees, altitude, 64, 32, 16);
      in.SkyViewKey = key;
    }
    // The sky's radiance is relative to its own sun.
    const auto skySun = model.GetSpectrum().ToLinearSrgb(model.GetSunIrradiance());
    nimbus::Rgb scale{ { 0, 0, 0 } };
    for (int c = 0; c < 3; ++c)
    {
      scale[c] = skySun[c] > 0.0 ? sunTop[c] / skySun[c] : 0.0;
    }
    const nimbus::SkyViewLut* view = in.SkyView.get();
    const double azimuth = in.Sun.AzimuthDegrees;
    lighting.Sky = [view, scale, azimuth](const nimbus::Vector3& w)
    {
      auto radiance = view->Radiance(w, azimuth);
      for (int c = 0; c < 3; ++c)
      {
        radiance[c] *= scale[c];
      }
      return radiance;
    };
  }
  catch (const std::exception& error)
  {
    in.SkyView.reset();
    vtkErrorMacro("The sky's light on the splats is off: " << error.what());
    return false;
  }
  return true;
}

// The view pass into a float target of the renderer's size (the balls' premultiplied
// colour and coverage, depth-tested against a copy of the scene's depth), then added to
// the frame once (as vtkNimbusLightningGlowMapper): blended (1, 1 - coverage), or over a
// sky's sRGB-encoded frame decoded, blended in linear light and encoded again.
void vtkNimbusCloudSplatMapper::DrawIntoFloatTarget(
  vtkRenderer* renderer, vtkOpenGLRenderWindow* window)
{
  Internals& in = *this->Internal;
  int width = 0, height = 0, x0 = 0, y0 = 0;
  renderer->GetTiledSizeAndOrigin(&width, &height, &x0, &y0);
  if (width <= 0 || height <= 0)
  {
    return;
  }
  vtkOpenGLState* state = window->GetState();
  vtkOpenGLState::ScopedglViewport viewportSaver(state);
  vtkOpenGLState::ScopedglScissor scissorSaver(state);
  vtkOpenGLState::ScopedglEnableDisable scissorTestSaver(state, GL_SCISSOR_TEST);
  vtkOpenGLState::ScopedglEnableDisable depthTestSaver(state, GL_DEPTH_TEST);
  vtkOpenGLState::ScopedglEnableDisable blendSaver(state, GL_BLEND);
  vtkOpenGLState::ScopedglBlendFuncSeparate blendFuncSaver(state);
  vtkOpenGLState::ScopedglClearColor clearColorSaver(state);
  vtkOpenGLState::ScopedglColorMask colorMaskSaver(state);
  vtkOpenGLState::ScopedglDepthMask depthMaskSaver(state);

  // The scene's depth (and, over a sky, its colour) so far, from the frame's framebuffer.
  GLint frame = 0;
  glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &frame);
  state->PushFramebufferBindings();
  try
  {
    state->vtkglBindFramebuffer(GL_READ_FRAMEBUFFER, frame);
    Internals::EnsureTarget(in.FrameSum, window, width, height, nimbus::FrameTextureFormat::Float);
    Internals::EnsureTarget(
      in.FrameDepth, window, width, height, nimbus::FrameTextureFormat::Depth);
    const int samples = nimbus::CopySceneDepth(in.FrameDepth, x0, y0, width, height);
    const bool sceneDepth = samples == 0;
    if (sceneDepth && in.OverSky)
    {
      Internals::EnsureTarget(
        in.SceneColor, window, width, height, nimbus::FrameTextureFormat::Byte);
      in.SceneColor->CopyFromFrameBuffer(x0, y0, 0, 0, width, height);
    }
    else if (!sceneDepth && !in.WarnedMultisampling)
    {
      vtkWarningMacro("The render window is multisampled (MultiSamples = "
        << samples << "): opaque geometry will not hide the cloud splats. Set MultiSamples to 0.");
      in.WarnedMultisampling = true;
    }
    nimbus::BeginFrameTarget(
      in.FrameTarget, in.FrameSum, in.FrameDepth, window, width, height, sceneDepth);
    this->ViewPass(renderer, window);
    in.FrameTarget->RemoveDepthAttachment();
  }
  catch (...)
  {
    state->PopFramebufferBindings();
    throw;
  }
  state->PopFramebufferBindings();

  // Added to the frame once.
  state->vtkglViewport(x0, y0, width, height);
  state->vtkglDisable(GL_DEPTH_TEST);
  if (in.OverSky)
  {
    state->vtkglDisable(GL_BLEND);
  }
  else
  {
    state->vtkglEnable(GL_BLEND);
    state->vtkglBlendFuncSeparate(GL_ONE, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
  }
  if (!in.Composite)
  {
    const std::string source = nimbus::WithShaderLibrary(cloudSplatCompositeFS);
    in.Composite = std::make_unique<vtkOpenGLQuadHelper>(window, nullptr, source.c_str(), "");
  }
  else
  {
    window->GetShaderCache()->ReadyShaderProgram(in.Composite->Program);
  }
  if (!in.Composite->Program)
  {
    throw std::runtime_error("the splats' composite shader did not compile");
  }
  vtkShaderProgram* program = in.Composite->Program;
  in.FrameSum->Activate();
  program->SetUniformi("splatSum", in.FrameSum->GetTextureUnit());
  program->SetUniformi("encodeSrgb", in.OverSky ? 1 : 0);
  if (in.OverSky)
  {
    in.SceneColor->Activate();
    program->SetUniformi("sceneColor", in.SceneColor->GetTextureUnit());
  }
  in.Composite->Render();
  if (in.OverSky)
  {
    in.SceneColor->Deactivate();
  }
  in.FrameSum->Deactivate();
}

void vtkNimbusCloudSplatMapper::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "RadiusArrayName: " << (this->RadiusArrayName ? this->RadiusArrayName : "(none)")
     << "\n";
  os << indent
     << "DensityArrayName: " << (this->DensityArrayName ? this->DensityArrayName : "(none)")
     << "\n";
  os << indent << "SunAzimuthDegrees: " << this->SunAzimuthDegrees << "\n";
  os << indent << "SunElevationDegrees: " << this->SunElevationDegrees << "\n";
  os << indent << "SunIlluminance: " << this->SunIlluminance << "\n";
  os << indent << "SunTemperatureKelvin: " << this->SunTemperatureKelvin << "\n";
  os << indent << "ExtinctionPerDensity: " << this->ExtinctionPerDensity << " /m\n";
  os << indent << "Albedo: " << this->Albedo << "\n";
  os << indent << "CloudG: " << this->CloudG << "\n";
  os << indent << "MetresPerUnit: " << this->MetresPerUnit << "\n";
  os << indent << "Exposure: " << this->Exposure << "\n";
  os << indent << "SunLightMethod: " << this->SunLightMethod << "\n";
  os << indent << "SunTextureSize: " << this->SunTextureSize << "\n";
  os << indent << "SunTextureLayers: " << this->SunTextureLayers << "\n";
  os << indent << "SunLightSamples: " << this->SunLightSamples << "\n";
  os << indent << "TimePasses: " << this->TimePasses << "\n";
  os << indent << "MultipleScattering: " << this->MultipleScattering << "\n";
  os << indent << "MultipleScatteringGridSize: " << this->MultipleScatteringGridSize << "\n";
  os << indent << "SkyBackground: " << this->SkyBackground << "\n";
  os << indent << "SkyLight: " << this->SkyLight << "\n";
  os << indent << "AerialPerspective: " << this->AerialPerspective << "\n";
}
