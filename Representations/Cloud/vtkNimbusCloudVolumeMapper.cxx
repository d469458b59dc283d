#include "vtkNimbusCloudVolumeMapper.h"
#include "Math.h"

#include "AtmosphereTable.h"
#include "CloudDensityTexture.h"
#include "SliceGeometry.h"
#include "SunAndAir.h"

#include "svsCommon.h"
#include "svsCompositeFS.h"
#include "svsIntervalPhaseFS.h"
#include "svsMarchFS.h"
#include "svsRayEndsFS.h"
#include "svsShadowFS.h"
#include "svsSliceFS.h"

#include "Sky.h"
#include "vtkNimbusSky.h"
#include "vtkNimbusSkyBackground.h"

#include "vtkCamera.h"
#include "vtkCellData.h"
#include "vtkDataArray.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkMatrix4x4.h"
#include "vtkObjectFactory.h"
#include "vtkOpenGLFramebufferObject.h"
#include "vtkOpenGLQuadHelper.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkOpenGLShaderCache.h"
#include "vtkOpenGLState.h"
#include "vtkPointData.h"
#include "vtkPropCollection.h"
#include "vtkRenderer.h"
#include "vtkShaderProgram.h"
#include "vtkTextureObject.h"
#include "vtkVolume.h"
#include "vtk_glew.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

vtkStandardNewMacro(vtkNimbusCloudVolumeMapper);

namespace
{
using nimbus::kDegree;

// Column-major float copy of a VTK (row-major) matrix, for glUniformMatrix4fv.
std::array<float, 16> ColumnMajor(const vtkMatrix4x4* m)
{
  std::array<float, 16> out{};
  for (int r = 0; r < 4; ++r)
  {
    for (int c = 0; c < 4; ++c)
    {
      out[c * 4 + r] = static_cast<float>(m->GetElement(r, c));
    }
  }
  return out;
}

std::string FragmentSource(const char* pass)
{
  return std::string("//VTK::System::Dec\n//VTK::Output::Dec\n") + svsCommon + "\n" + pass;
}

// Frees a texture's storage and sets clamp-to-edge wrapping and its filter, ready
// for a new allocation.
void ResetTexture(vtkTextureObject* texture, vtkOpenGLRenderWindow* window, bool linear)
{
  texture->SetContext(window);
  texture->ReleaseGraphicsResources(window);
  texture->SetWrapS(vtkTextureObject::ClampToEdge);
  texture->SetWrapT(vtkTextureObject::ClampToEdge);
  texture->SetWrapR(vtkTextureObject::ClampToEdge);
  const int filter = linear ? vtkTextureObject::Linear : vtkTextureObject::Nearest;
  texture->SetMinificationFilter(filter);
  texture->SetMagnificationFilter(filter);
}

// The sun, air, ground and display parameters of one frame: the mapper's own, or
// those of the Nimbus sky drawn behind it (see UseSceneSky).
struct FrameSettings
{
  nimbus::SunParameters Sun;
  nimbus::SceneAtmosphere Air;
  double GroundHeight;    // world units
  double GroundAlbedo;    // dimensionless
  double MetresPerUnit;   // metres per world unit
  double DisplayScale[3]; // per channel
  bool EncodeSrgb;
  bool OverSky;
};

// The sky of the first visible vtkNimbusSkyBackground among the renderer's props.
vtkNimbusSky* FindSceneSky(vtkRenderer* renderer)
{
  vtkPropCollection* props = renderer->GetViewProps();
  vtkCollectionSimpleIterator it;
  props->InitTraversal(it);
  while (vtkProp* prop = props->GetNextProp(it))
  {
    auto* background = vtkNimbusSkyBackground::SafeDownCast(prop);
    if (background && background->GetVisibility())
    {
      return background->GetSky();
    }
  }
  return nullptr;
}

// Binds the framebuffer with `target` as its only draw buffer. The attachment is
// renewed every time: a reallocated texture keeps its vtkTextureObject, and
// vtkOpenGLFramebufferObject skips attaching the same object again.
void DrawInto(
  vtkOpenGLFramebufferObject* framebuffer, vtkTextureObject* target, vtkOpenGLRenderWindow* window)
{
  framebuffer->SetContext(window);
  framebuffer->Bind(GL_FRAMEBUFFER);
  framebuffer->RemoveColorAttachment(0);
  framebuffer->AddColorAttachment(0, target);
  framebuffer->ActivateDrawBuffer(0);
}
}

struct vtkNimbusCloudVolumeMapper::Internals
{
  vtkOpenGLRenderWindow* Window = nullptr;

  // Density volume (000: the "volume texture").
  nimbus::CloudDensityTexture Density;

  // Atmosphere texture (000 §3), keyed by the parameters it depends on.
  vtkNew<vtkTextureObject> AtmosphereTexture;
  std::vector<double> AtmosphereKey;
  nimbus::AtmosphereTable Table;

  // Sampling-interval and Mie-phase texture (000 §4.4), keyed likewise.
  vtkNew<vtkTextureObject> IntervalPhase;
  vtkNew<vtkOpenGLFramebufferObject> IntervalPhaseFramebuffer;
  std::vector<double> IntervalPhaseKey;

  // Accumulation (S, alpha) at the viewport size, and copies of the scene's colour and depth.
  vtkNew<vtkTextureObject> Accumulation;
  vtkNew<vtkTextureObject> ClearAccumulation; // S without the cloud (over a sky)
  vtkNew<vtkOpenGLFramebufferObject> AccumulationFramebuffer;
  vtkNew<vtkTextureObject> SceneColor;
  vtkNew<vtkTextureObject> SceneDepth;
  bool WarnedMultisampling = false;
  vtkNew<vtkOpenGLFramebufferObject> SceneFramebuffer;
  vtkNew<vtkTextureObject> RayEnds;
  vtkNew<vtkOpenGLFramebufferObject> RayEndsFramebuffer;
  vtkNew<vtkImageData> Radiance; // float copy of the last accumulation (CaptureRadiance)

  // Shadow surface facing the sun (000 Eq. 10).
  vtkNew<vtkTextureObject> Shadow;
  vtkNew<vtkOpenGLFramebufferObject> ShadowFramebuffer;

  std::unique_ptr<vtkOpenGLQuadHelper> SlicePass, ShadowPass, IntervalPhasePass, MarchPass,
    CompositePass, RayEndsPass;

  int AtmosphereBuilds = 0;
  int IntervalPhaseBuilds = 0;
  int PassesLastRender = 0;
  bool LastBackToFront = false;
  bool LastOverSky = false;
  double LastSunElevationDegrees = 0.0;

  void Release(vtkWindow* window)
  {
    this->Density.Release(window);
    for (vtkTextureObject* t : { AtmosphereTexture.GetPointer(), IntervalPhase.GetPointer(),
           Accumulation.GetPointer(), ClearAccumulation.GetPointer(), SceneColor.GetPointer(),
           SceneDepth.GetPointer(), Shadow.GetPointer(), RayEnds.GetPointer() })
    {
      t->ReleaseGraphicsResources(window);
    }
    for (vtkOpenGLFramebufferObject* f : { IntervalPhaseFramebuffer.GetPointer(),
           SceneFramebuffer.GetPointer(), RayEndsFramebuffer.GetPointer(),
           AccumulationFramebuffer.GetPointer(), ShadowFramebuffer.GetPointer() })
    {
      f->ReleaseGraphicsResources(window);
    }
    for (auto* pass :
      { &SlicePass, &ShadowPass, &IntervalPhasePass, &MarchPass, &CompositePass, &RayEndsPass })
    {
      if (*pass)
      {
        (*pass)->ReleaseGraphicsResources(window);
        pass->reset();
      }
    }
    AtmosphereKey.clear();
    IntervalPhaseKey.clear();
    Window = nullptr;
  }

  vtkShaderProgram* Ready(std::unique_ptr<vtkOpenGLQuadHelper>& pass, const char* source)
  {
    if (!pass)
    {
      const std::string fs = FragmentSource(source);
      pass = std::make_unique<vtkOpenGLQuadHelper>(Window, nullptr, fs.c_str(), "");
    }
    else
    {
      Window->GetShaderCache()->ReadyShaderProgram(pass->Program);
    }
    return pass->Program;
  }
};

vtkNimbusCloudVolumeMapper::vtkNimbusCloudVolumeMapper()
  : Internal(new Internals)
{
}

vtkNimbusCloudVolumeMapper::~vtkNimbusCloudVolumeMapper() = default;

int vtkNimbusCloudVolumeMapper::GetNumberOfVolumeUploads() const
{
  return this->Internal->Density.GetNumberOfUploads();
}
int vtkNimbusCloudVolumeMapper::GetNumberOfAtmosphereBuilds() const
{
  return this->Internal->AtmosphereBuilds;
}
int vtkNimbusCloudVolumeMapper::GetNumberOfIntervalPhaseBuilds() const
{
  return this->Internal->IntervalPhaseBuilds;
}
int vtkNimbusCloudVolumeMapper::GetNumberOfPassesLastRender() const
{
  return this->Internal->PassesLastRender;
}
bool vtkNimbusCloudVolumeMapper::GetLastRenderUsedSceneSky() const
{
  return this->Internal->LastOverSky;
}
double vtkNimbusCloudVolumeMapper::GetLastSunElevationDegrees() const
{
  return this->Internal->LastSunElevationDegrees;
}
bool vtkNimbusCloudVolumeMapper::GetLastBackToFront() const
{
  return this->Internal->LastBackToFront;
}
vtkImageData* vtkNimbusCloudVolumeMapper::GetRadianceImage()
{
  return this->Internal->Radiance;
}
void vtkNimbusCloudVolumeMapper::GetTextureDimensions(int dims[3]) const
{
  this->Internal->Density.GetDimensions(dims);
}

void vtkNimbusCloudVolumeMapper::ReleaseGraphicsResources(vtkWindow* window)
{
  this->Internal->Release(window);
}

//------------------------------------------------------------------------------
void vtkNimbusCloudVolumeMapper::Render(vtkRenderer* renderer, vtkVolume* volume)
{
  Internals& in = *this->Internal;
  in.PassesLastRender = 0;
  auto* window = vtkOpenGLRenderWindow::SafeDownCast(renderer->GetRenderWindow());
  if (!window)
  {
    vtkErrorMacro("vtkNimbusCloudVolumeMapper needs an OpenGL render window.");
    return;
  }
  if (in.Window && in.Window != window)
  {
    in.Release(in.Window);
  }
  in.Window = window;
  vtkImageData* image = vtkImageData::SafeDownCast(this->GetInput());
  if (!image)
  {
    vtkErrorMacro("No input image: connect a vtkImageData with a density array.");
    return;
  }
  this->GetInputAlgorithm()->UpdateInformation();
  this->GetInputAlgorithm()->Update();
  image = vtkImageData::SafeDownCast(this->GetInput());

  // --- density texture: uploaded only when the data (not the lighting) changed.
  int cellFlag = 0;
  vtkDataArray* scalars = vtkAbstractMapper::GetScalars(
    image, this->ScalarMode, this->ArrayAccessMode, this->ArrayId, this->ArrayName, cellFlag);
  if (!scalars)
  {
    vtkErrorMacro("The input image has no scalar array to render as density (set one with "
                  "SelectScalarArray, or give the image active point scalars).");
    return;
  }
  const int maxSize = this->MaximumTextureSize > 0
    ? std::min(this->MaximumTextureSize, vtkTextureObject::GetMaximumTextureSize3D(window))
    : vtkTextureObject::GetMaximumTextureSize3D(window);
  std::vector<std::string> warnings;
  std::string error;
  const bool uploaded =
    in.Density.Update(window, image, scalars, cellFlag != 0, maxSize, warnings, error);
  for (const std::string& warning : warnings)
  {
    vtkWarningMacro(<< warning);
  }
  if (!uploaded)
  {
    vtkErrorMacro(<< error);
    return;
  }

  // --- this frame's sun, air, ground and display: ours, or the sky's behind us.
  FrameSettings settings;
  settings.Sun.AzimuthDegrees = this->SunAzimuthDegrees;
  settings.Sun.ElevationDegrees = this->SunElevationDegrees;
  settings.Sun.Illuminance = this->SunIlluminance;
  settings.Sun.TemperatureKelvin = this->SunTemperatureKelvin;
  settings.Air.RayleighScatteringPerMetre = this->RayleighScatteringPerMetre;
  settings.Air.MieScatteringPerMetre = this->MieScatteringPerMetre;
  settings.Air.MieG = this->MieG;
  settings.Air.SceneAltitudeMetres = this->SceneAltitudeMetres;
  settings.GroundHeight = this->GroundHeight;
  settings.GroundAlbedo = this->GroundAlbedo;
  settings.MetresPerUnit = this->MetresPerUnit;
  std::fill(settings.DisplayScale, settings.DisplayScale + 3, this->Exposure);
  settings.EncodeSrgb = this->EncodeSrgb;
  settings.OverSky = false;
  if (vtkNimbusSky* sky = (this->UseSceneSky && !this->Unlit) ? FindSceneSky(renderer) : nullptr)
  {
    const nimbus::SkyParameters* skyParameters = nullptr;
    try
    {
      skyParameters = &sky->GetSkyModel().GetParameters();
    }
    catch (const std::exception& error)
    {
      vtkErrorMacro("The scene's sky is invalid: " << error.what());
      return;
    }
    settings.Sun.AzimuthDegrees = sky->GetSunAzimuthDegrees();
    settings.Sun.ElevationDegrees = sky->GetSunElevationDegrees();
    settings.Sun.Illuminance = 1.0; // the sky's sun: luminance 1 above the atmosphere
    settings.Sun.TemperatureKelvin = skyParameters->SunTemperatureKelvin;
    static_cast<nimbus::AtmosphereParameters&>(settings.Air) = skyParameters->Atmosphere;
    settings.Air.SceneAltitudeMetres = sky->GetSceneAltitudeMetres();
    settings.MetresPerUnit = sky->GetMetresPerUnit();
    settings.GroundHeight = -sky->GetSceneAltitudeMetres() / sky->GetMetresPerUnit(); // sea level
    settings.GroundAlbedo = sky->GetGroundAlbedo();
    sky->GetDisplayScale(settings.DisplayScale);
    settings.EncodeSrgb = true; // the sky background is sRGB-encoded
    settings.OverSky = true;
  }
  in.LastOverSky = settings.OverSky;
  in.LastSunElevationDegrees = settings.Sun.ElevationDegrees;

  // --- geometry: sun, view, slice axis, box corners in world coordinates.
  vtkCamera* camera = renderer->GetActiveCamera();
  int width = 0, height = 0, x0 = 0, y0 = 0;
  renderer->GetTiledSizeAndOrigin(&width, &height, &x0, &y0);
  if (width < 1 || height < 1)
  {
    return;
  }
  const nimbus::Vector3 toSun =
    nimbus::SunDirection(settings.Sun.ElevationDegrees, settings.Sun.AzimuthDegrees);
  double projection[3];
  camera->GetDirectionOfProjection(projection);
  const nimbus::Vector3 view = { { projection[0], projection[1], projection[2] } };
  const nimbus::SliceAxis axis = nimbus::ComputeSliceAxis(view, toSun, this->SliceAngleRatio);
  in.LastBackToFront = axis.BackToFront;

  vtkMatrix4x4* dataToWorld = volume->GetMatrix();
  const double* boxOrigin = in.Density.GetBoxOrigin();
  const double* boxSize = in.Density.GetBoxSize();
  std::vector<nimbus::Vector3> corners;
  for (int c = 0; c < 8; ++c)
  {
    const double p[4] = { boxOrigin[0] + ((c & 1) ? boxSize[0] : 0.0),
      boxOrigin[1] + ((c & 2) ? boxSize[1] : 0.0), boxOrigin[2] + ((c & 4) ? boxSize[2] : 0.0),
      1.0 };
    double w[4];
    dataToWorld->MultiplyPoint(p, w);
    corners.push_back({ { w[0] / w[3], w[1] / w[3], w[2] / w[3] } });
  }
  const std::array<double, 2> range = nimbus::ProjectedRange(corners, axis.Normal);
  const nimbus::SlicePlanes planes =
    nimbus::MakeSlicePlanes(range[0], std::max(range[1], range[0] + 1e-9), this->NumberOfSlices);
  const nimbus::ShadowFrame frame = nimbus::ComputeShadowFrame(corners, toSun, 0.02);
  const double sunStepMetres = planes.Spacing / axis.SunCosine * settings.MetresPerUnit;

  // world -> box [0,1]^3 -> density texture coordinates.
  vtkNew<vtkMatrix4x4> worldToData;
  vtkMatrix4x4::Invert(dataToWorld, worldToData);
  vtkNew<vtkMatrix4x4> dataToTexture;
  in.Density.GetDataToTexture(dataToTexture);
  vtkNew<vtkMatrix4x4> worldToTexture;
  vtkMatrix4x4::Multiply4x4(dataToTexture, worldToData, worldToTexture);
  // Texture coordinates are tested against [0,1] for "inside the box": with the
  // half-texel offsets of point data, map the box itself to [0,1] for that test.
  vtkNew<vtkMatrix4x4> worldToBox;
  {
    vtkNew<vtkMatrix4x4> dataToBox;
    in.Density.GetDataToBox(dataToBox);
    vtkMatrix4x4::Multiply4x4(dataToBox, worldToData, worldToBox);
  }

  const double aspect = static_cast<double>(width) / height;
  vtkNew<vtkMatrix4x4> inverseViewProjection;
  inverseViewProjection->DeepCopy(camera->GetCompositeProjectionTransformMatrix(aspect, -1, 1));
  inverseViewProjection->Invert();

  vtkOpenGLState* state = window->GetState();
  vtkOpenGLState::ScopedglViewport savedViewport(state);
  vtkOpenGLState::ScopedglBlendFuncSeparate savedBlend(state);
  vtkOpenGLState::ScopedglEnableDisable savedBlendEnable(state, GL_BLEND);
  vtkOpenGLState::ScopedglEnableDisable savedDepthTest(state, GL_DEPTH_TEST);
  vtkOpenGLState::ScopedglEnableDisable savedScissor(state, GL_SCISSOR_TEST);
  vtkOpenGLState::ScopedglScissor savedScissorBox(state);
  vtkOpenGLState::ScopedglEnableDisable savedCull(state, GL_CULL_FACE);
  vtkOpenGLState::ScopedglDepthMask savedDepthMask(state);
  vtkOpenGLState::ScopedglColorMask savedColorMask(state);
  state->vtkglColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  state->vtkglDisable(GL_CULL_FACE);
  state->vtkglDisable(GL_SCISSOR_TEST);

  // --- copies of the scene's colour and depth (the background and the opaque depth).
  GLint drawFramebuffer = 0;
  glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &drawFramebuffer);
  state->PushFramebufferBindings();
  state->vtkglBindFramebuffer(GL_READ_FRAMEBUFFER, drawFramebuffer);
  auto ensure2D = [&](vtkTextureObject* texture, int w, int h, int components, bool depth)
  {
    texture->SetContext(window);
    if (static_cast<int>(texture->GetWidth()) != w || static_cast<int>(texture->GetHeight()) != h ||
      !texture->GetHandle())
    {
      ResetTexture(texture, window, false);
      if (depth)
      {
        texture->AllocateDepth(w, h, vtkTextureObject::Float32);
      }
      else
      {
        texture->Allocate2D(w, h, components, VTK_FLOAT);
      }
    }
  };
  // Copy the viewport's colour and depth into our textures. A multisampled
  // framebuffer cannot be copied from (GL_INVALID_OPERATION): then the colour is
  // resolved by a blit and the depth is treated as empty, with a warning.
  ensure2D(in.SceneColor, width, height, 4, false);
  ensure2D(in.SceneDepth, width, height, 1, true);
  GLint samples = 0;
  glGetIntegerv(GL_SAMPLES, &samples);
  if (samples > 0)
  {
    in.SceneFramebuffer->SetContext(window);
    in.SceneFramebuffer->Bind(GL_DRAW_FRAMEBUFFER);
    in.SceneFramebuffer->AddColorAttachment(0, in.SceneColor);
    in.SceneFramebuffer->AddDepthAttachment(in.SceneDepth);
    in.SceneFramebuffer->ActivateDrawBuffer(0);
    state->vtkglBindFramebuffer(GL_READ_FRAMEBUFFER, drawFramebuffer);
    glBlitFramebuffer(
      x0, y0, x0 + width, y0 + height, 0, 0, width, height, GL_COLOR_BUFFER_BIT, GL_NEAREST);
    state->vtkglClearDepth(1.0);
    state->vtkglClear(GL_DEPTH_BUFFER_BIT);
    in.SceneFramebuffer->RemoveDepthAttachment();
    in.SceneFramebuffer->RemoveColorAttachments(1);
    if (!in.WarnedMultisampling)
    {
      vtkWarningMacro("The render window is multisampled (MultiSamples = "
        << samples << "): opaque geometry will not cut the clouds. Set MultiSamples to 0.");
      in.WarnedMultisampling = true;
    }
  }
  else
  {
    in.SceneColor->CopyFromFrameBuffer(x0, y0, 0, 0, width, height);
    in.SceneDepth->CopyFromFrameBuffer(x0, y0, 0, 0, width, height);
  }

  // --- atmosphere texture (only with an atmosphere; rebuilt when sun or air change).
  const bool atmosphere = this->Atmosphere && !this->Unlit;
  const bool ground = this->Ground && !this->Unlit;
  double boxZMin = std::numeric_limits<double>::infinity();
  for (const auto& corner : corners)
  {
    boxZMin = std::min(boxZMin, corner[2]);
  }
  const double zLow =
    (std::min(boxZMin, ground ? settings.GroundHeight : boxZMin)) * settings.MetresPerUnit;
  settings.Air.Enabled = atmosphere;
  const nimbus::SceneAtmosphere& air = settings.Air;
  const double zHigh = air.TopRadiusMetres - air.EarthRadiusMetres - air.SceneAltitudeMetres;
  const std::vector<double> atmosphereKey = { settings.Sun.AzimuthDegrees,
    settings.Sun.ElevationDegrees, settings.Sun.Illuminance, settings.Sun.TemperatureKelvin,
    air.Enabled ? 1.0 : 0.0, air.SceneAltitudeMetres, air.EarthRadiusMetres, air.TopRadiusMetres,
    air.RayleighScaleHeightMetres, air.MieScaleHeightMetres, air.RayleighScatteringPerMetre,
    air.MieScatteringPerMetre, air.MieAlbedo, air.MieG, zLow };
  if (atmosphereKey != in.AtmosphereKey)
  {
    try
    {
      const nimbus::SunAndAir sunAndAir(settings.Sun, air, 16);
      in.Table = nimbus::BuildAtmosphereTable(sunAndAir, std::min(zLow, zHigh - 1.0), zHigh, 1024);
    }
    catch (const std::exception& error)
    {
      vtkErrorMacro("Invalid sun or atmosphere: " << error.what());
      state->PopFramebufferBindings();
      return;
    }
    if (in.Table.HasAtmosphere)
    {
      ResetTexture(in.AtmosphereTexture, window, true);
      in.AtmosphereTexture->Create2DFromRaw(
        in.Table.Samples, nimbus::AtmosphereTable::kRows, 4, VTK_FLOAT, in.Table.Data.data());
      ++in.AtmosphereBuilds;
    }
    in.AtmosphereKey = atmosphereKey;
  }

  // Uniforms every pass shares.
  const std::array<float, 16> ivp = ColumnMajor(inverseViewProjection);
  const std::array<float, 16> w2t = ColumnMajor(worldToTexture);
  const std::array<float, 16> w2b = ColumnMajor(worldToBox);
  auto setCommon = [&](vtkShaderProgram* program)
  {
    program->SetUniformMatrix4x4("inverseViewProjection", const_cast<float*>(ivp.data()));
    program->SetUniformi("perspective", camera->GetParallelProjection() ? 0 : 1);
    program->SetUniform3f("eyePosition", camera->GetPosition());
    program->SetUniformMatrix4x4("worldToTexture", const_cast<float*>(w2t.data()));
    program->SetUniformMatrix4x4("worldToBox", const_cast<float*>(w2b.data()));
    program->SetUniform3f("toSun", toSun.data());
    program->SetUniform3f("sliceNormal", axis.Normal.data());
    program->SetUniformf("lengthUnit", static_cast<float>(settings.MetresPerUnit));
    program->SetUniformi("density", in.Density.GetTexture()->GetTextureUnit());
    program->SetUniformf("extinctionPerDensity", static_cast<float>(this->ExtinctionPerDensity));
    program->SetUniformf("cloudAlbedo", static_cast<float>(this->Albedo));
    program->SetUniformi("shadowSurface", in.Shadow->GetTextureUnit());
    program->SetUniform3f("shadowOrigin", frame.Origin.data());
    program->SetUniform3f("shadowU", frame.U.data());
    program->SetUniform3f("shadowW", frame.W.data());
    const float extent[2] = { static_cast<float>(frame.Width), static_cast<float>(frame.Height) };
    program->SetUniform2f("shadowExtent", extent);
    program->SetUniformi("atmosphereOn", atmosphere ? 1 : 0);
    if (atmosphere)
    {
      program->SetUniformi("atmosphereTable", in.AtmosphereTexture->GetTextureUnit());
    }
    else
    {
      // Unused, but a sampler2D must not share a unit with the 3-D density texture.
      program->SetUniformi("atmosphereTable", in.SceneDepth->GetTextureUnit());
    }
    const float zRange[2] = { static_cast<float>(in.Table.ZMin),
      static_cast<float>(in.Table.ZMax) };
    program->SetUniform2f("atmosphereZRange", zRange);
    program->SetUniform3f("rayleighExtinction0", in.Table.RayleighExtinctionSeaLevel.data());
    program->SetUniformf("mieExtinction0", static_cast<float>(in.Table.MieExtinctionSeaLevel));
    program->SetUniformf(
      "rayleighScaleHeight", static_cast<float>(in.Table.Air.RayleighScaleHeightMetres));
    program->SetUniformf("mieScaleHeight", static_cast<float>(in.Table.Air.MieScaleHeightMetres));
    program->SetUniformf("sceneAltitude", static_cast<float>(air.SceneAltitudeMetres));
    program->SetUniformf("earthRadius", static_cast<float>(air.EarthRadiusMetres));
    program->SetUniformf("topRadius", static_cast<float>(air.TopRadiusMetres));
    program->SetUniform3f("sunIrradianceTop", in.Table.SunIrradianceTop.data());
    program->SetUniformi("groundOn", ground ? 1 : 0);
    program->SetUniformf("groundZ", static_cast<float>(settings.GroundHeight));
    program->SetUniformf("groundAlbedo", static_cast<float>(settings.GroundAlbedo));
    program->SetUniformi("sceneDepth", in.SceneDepth->GetTextureUnit());
    program->SetUniformi("overSky", settings.OverSky ? 1 : 0);
  };

  in.Density.GetTexture()->Activate();
  in.SceneDepth->Activate();
  if (atmosphere)
  {
    in.AtmosphereTexture->Activate();
  }

  // --- shadow surface, cleared to optical depth 0.
  in.Shadow->SetContext(window);
  if (static_cast<int>(in.Shadow->GetWidth()) != this->ShadowSurfaceSize || !in.Shadow->GetHandle())
  {
    ResetTexture(in.Shadow, window, true);
    in.Shadow->Allocate2D(this->ShadowSurfaceSize, this->ShadowSurfaceSize, 1, VTK_FLOAT);
  }
  DrawInto(in.ShadowFramebuffer, in.Shadow, window);
  state->vtkglViewport(0, 0, this->ShadowSurfaceSize, this->ShadowSurfaceSize);
  state->vtkglClearColor(0.0f, 0.0f, 0.0f, 0.0f);
  state->vtkglClear(GL_COLOR_BUFFER_BIT);

  // --- sampling-interval and Mie-phase texture (rebuilt when camera or sun change).
  const bool unlit = this->Unlit;
  std::vector<double> intervalKey(ivp.begin(), ivp.end());
  intervalKey.insert(intervalKey.end(),
    { static_cast<double>(width), static_cast<double>(height), toSun[0], toSun[1], toSun[2],
      axis.Normal[0], axis.Normal[1], axis.Normal[2], this->CloudG, settings.Air.MieG,
      this->MultipleScattering });
  state->vtkglDisable(GL_DEPTH_TEST);
  state->vtkglDepthMask(GL_FALSE);
  if (intervalKey != in.IntervalPhaseKey || !in.IntervalPhase->GetHandle())
  {
    ensure2D(in.IntervalPhase, width, height, 4, false);
    DrawInto(in.IntervalPhaseFramebuffer, in.IntervalPhase, window);
    state->vtkglViewport(0, 0, width, height);
    state->vtkglDisable(GL_BLEND);
    vtkShaderProgram* program = in.Ready(in.IntervalPhasePass, svsIntervalPhaseFS);
    setCommon(program);
    program->SetUniformf("cloudG", static_cast<float>(this->CloudG));
    program->SetUniformf("hazeG", static_cast<float>(settings.Air.MieG));
    program->SetUniformf("multipleScattering", static_cast<float>(this->MultipleScattering));
    in.IntervalPhasePass->Render();
    ++in.PassesLastRender;
    ++in.IntervalPhaseBuilds;
    in.IntervalPhaseKey = intervalKey;
  }
  in.IntervalPhase->Activate();
  in.Shadow->Activate();

  // --- where each view ray ends this frame (opaque depth, ground, top of the atmosphere).
  ensure2D(in.RayEnds, width, height, 4, false);
  DrawInto(in.RayEndsFramebuffer, in.RayEnds, window);
  state->vtkglViewport(0, 0, width, height);
  state->vtkglDisable(GL_BLEND);
  {
    vtkShaderProgram* program = in.Ready(in.RayEndsPass, svsRayEndsFS);
    setCommon(program);
    in.RayEndsPass->Render();
    ++in.PassesLastRender;
  }
  in.RayEnds->Activate();

  // --- accumulation (S, cloud transmittance), cleared to (0, 0, 0, 1).
  ensure2D(in.Accumulation, width, height, 4, false);
  DrawInto(in.AccumulationFramebuffer, in.Accumulation, window);
  in.AccumulationFramebuffer->RemoveColorAttachment(1);
  if (settings.OverSky)
  {
    // Second target, S_clear: the same blend sums it (its alpha stays 1).
    ensure2D(in.ClearAccumulation, width, height, 4, false);
    in.AccumulationFramebuffer->AddColorAttachment(1, in.ClearAccumulation);
    in.AccumulationFramebuffer->ActivateDrawBuffers(2);
  }
  state->vtkglViewport(0, 0, width, height);
  state->vtkglClearColor(0.0f, 0.0f, 0.0f, 1.0f);
  state->vtkglClear(GL_COLOR_BUFFER_BIT);

  // 000 §4.3: back-to-front S_i = C_i + alpha_i S_{i-1}; front-to-back
  // S_i = S_{i-1} + alpha*_i C_i with alpha* the transmittance so far (kept in alpha).
  auto useSliceBlend = [&]()
  {
    state->vtkglEnable(GL_BLEND);
    if (axis.BackToFront)
    {
      state->vtkglBlendFuncSeparate(GL_ONE, GL_SRC_ALPHA, GL_ZERO, GL_SRC_ALPHA);
    }
    else
    {
      state->vtkglBlendFuncSeparate(GL_DST_ALPHA, GL_ONE, GL_ZERO, GL_SRC_ALPHA);
    }
  };

  const bool outsideRegions = atmosphere || ground;
  auto drawRegion = [&](double start, double end, bool useShadow)
  {
    in.AccumulationFramebuffer->Bind(GL_FRAMEBUFFER);
    state->vtkglViewport(0, 0, width, height);
    useSliceBlend();
    vtkShaderProgram* program = in.Ready(in.MarchPass, svsMarchFS);
    setCommon(program);
    program->SetUniformi("intervalPhase", in.IntervalPhase->GetTextureUnit());
    program->SetUniformi("rayEnds", in.RayEnds->GetTextureUnit());
    program->SetUniformf("regionStart", static_cast<float>(start));
    program->SetUniformf("regionEnd", static_cast<float>(end));
    program->SetUniformi("useShadow", useShadow ? 1 : 0);
    program->SetUniformi("shaftsOn", this->Shafts ? 1 : 0);
    program->SetUniformi("steps", this->AtmosphereSteps);
    in.MarchPass->Render();
    ++in.PassesLastRender;
  };
  const double firstStart = planes.Offsets.front() - 0.5 * planes.Spacing;
  const double lastEnd = planes.Offsets.back() + 0.5 * planes.Spacing;
  if (outsideRegions)
  {
    drawRegion(-1e30, firstStart, false); // sunward of the cloud: unshadowed
  }

  // Scissor rectangles: each slice's passes only touch the pixels (and shadow
  // texels) onto which the polygon "slice plane cut by the box" projects; outside
  // it the density is zero. On screen this holds only when nothing outside the
  // box is drawn (no atmosphere, no ground).
  vtkMatrix4x4* worldToNdc = camera->GetCompositeProjectionTransformMatrix(aspect, -1, 1);
  auto screenRect = [&](const std::vector<nimbus::Vector3>& points, int rect[4])
  {
    double lo[2] = { 1e30, 1e30 }, hi[2] = { -1e30, -1e30 };
    for (const auto& point : points)
    {
      const double p[4] = { point[0], point[1], point[2], 1.0 };
      double q[4];
      worldToNdc->MultiplyPoint(p, q);
      if (q[3] <= 1e-9)
      {
        return false; // behind the eye: no finite rectangle
      }
      for (int k = 0; k < 2; ++k)
      {
        lo[k] = std::min(lo[k], q[k] / q[3]);
        hi[k] = std::max(hi[k], q[k] / q[3]);
      }
    }
    const int px0 =
      std::clamp(static_cast<int>(std::floor((lo[0] + 1) * 0.5 * width)) - 1, 0, width);
    const int py0 =
      std::clamp(static_cast<int>(std::floor((lo[1] + 1) * 0.5 * height)) - 1, 0, height);
    const int px1 =
      std::clamp(static_cast<int>(std::ceil((hi[0] + 1) * 0.5 * width)) + 1, 0, width);
    const int py1 =
      std::clamp(static_cast<int>(std::ceil((hi[1] + 1) * 0.5 * height)) + 1, 0, height);
    rect[0] = px0;
    rect[1] = py0;
    rect[2] = std::max(px1 - px0, 0);
    rect[3] = std::max(py1 - py0, 0);
    return true;
  };
  auto shadowRect = [&](const std::vector<nimbus::Vector3>& points, int rect[4])
  {
    const int size = this->ShadowSurfaceSize;
    double lo[2] = { 1e30, 1e30 }, hi[2] = { -1e30, -1e30 };
    for (const auto& point : points)
    {
      const nimbus::Vector3 q = { { point[0] - frame.Origin[0], point[1] - frame.Origin[1],
        point[2] - frame.Origin[2] } };
      const double st[2] = { nimbus::Dot(q, frame.U) / frame.Width * size,
        nimbus::Dot(q, frame.W) / frame.Height * size };
      for (int k = 0; k < 2; ++k)
      {
        lo[k] = std::min(lo[k], st[k]);
        hi[k] = std::max(hi[k], st[k]);
      }
    }
    const int x0s = std::clamp(static_cast<int>(std::floor(lo[0])) - 1, 0, size);
    const int y0s = std::clamp(static_cast<int>(std::floor(lo[1])) - 1, 0, size);
    const int x1s = std::clamp(static_cast<int>(std::ceil(hi[0])) + 1, 0, size);
    const int y1s = std::clamp(static_cast<int>(std::ceil(hi[1])) + 1, 0, size);
    rect[0] = x0s;
    rect[1] = y0s;
    rect[2] = std::max(x1s - x0s, 0);
    rect[3] = std::max(y1s - y0s, 0);
  };

  // --- the slices: eye pass with the shadow so far, then the shadow update.
  vtkShaderProgram* sliceProgram = in.Ready(in.SlicePass, svsSliceFS);
  setCommon(sliceProgram);
  sliceProgram->SetUniformi("intervalPhase", in.IntervalPhase->GetTextureUnit());
  sliceProgram->SetUniformi("rayEnds", in.RayEnds->GetTextureUnit());
  sliceProgram->SetUniformf("sliceSpacing", static_cast<float>(planes.Spacing));
  sliceProgram->SetUniformf("sunStepMetres", static_cast<float>(sunStepMetres));
  sliceProgram->SetUniformi("shaftsOn", this->Shafts ? 1 : 0);
  sliceProgram->SetUniformi("unlit", unlit ? 1 : 0);
  vtkShaderProgram* shadowProgram = nullptr;
  if (!unlit)
  {
    shadowProgram = in.Ready(in.ShadowPass, svsShadowFS);
    setCommon(shadowProgram);
    shadowProgram->SetUniformf("sunStepMetres", static_cast<float>(sunStepMetres));
  }
  for (size_t i = 0; i < planes.Offsets.size(); ++i)
  {
    const float offset = static_cast<float>(planes.Offsets[i]);
    const std::vector<nimbus::Vector3> polygon =
      nimbus::SlicePolygon(corners, axis.Normal, planes.Offsets[i]);
    if (polygon.empty())
    {
      continue;
    }
    in.AccumulationFramebuffer->Bind(GL_FRAMEBUFFER);
    state->vtkglViewport(0, 0, width, height);
    int scissorBox[4];
    const bool scissor = !outsideRegions && screenRect(polygon, scissorBox);
    if (scissor)
    {
      state->vtkglEnable(GL_SCISSOR_TEST);
      state->vtkglScissor(scissorBox[0], scissorBox[1], scissorBox[2], scissorBox[3]);
    }
    useSliceBlend();
    window->GetShaderCache()->ReadyShaderProgram(sliceProgram);
    sliceProgram->SetUniformf("sliceOffset", offset);
    in.SlicePass->Render();
    ++in.PassesLastRender;
    if (scissor)
    {
      state->vtkglDisable(GL_SCISSOR_TEST);
    }
    if (shadowProgram)
    {
      in.ShadowFramebuffer->Bind(GL_FRAMEBUFFER);
      state->vtkglViewport(0, 0, this->ShadowSurfaceSize, this->ShadowSurfaceSize);
      int texels[4];
      shadowRect(polygon, texels);
      state->vtkglEnable(GL_SCISSOR_TEST);
      state->vtkglScissor(texels[0], texels[1], texels[2], texels[3]);
      state->vtkglEnable(GL_BLEND);
      state->vtkglBlendFuncSeparate(GL_ONE, GL_ONE, GL_ONE, GL_ONE);
      window->GetShaderCache()->ReadyShaderProgram(shadowProgram);
      shadowProgram->SetUniformf("sliceOffset", offset);
      in.ShadowPass->Render();
      state->vtkglDisable(GL_SCISSOR_TEST);
      ++in.PassesLastRender;
    }
  }
  if (outsideRegions)
  {
    drawRegion(lastEnd, 1e30, true); // beyond the cloud: the finished shadow surface
  }

  if (this->CaptureRadiance)
  {
    // Float copy of the sum of the slices (radiance and cloud transmittance).
    in.AccumulationFramebuffer->Bind(GL_FRAMEBUFFER);
    in.AccumulationFramebuffer->ActivateReadBuffer(0);
    vtkNew<vtkFloatArray> values;
    values->SetName("radiance");
    values->SetNumberOfComponents(4);
    values->SetNumberOfTuples(static_cast<vtkIdType>(width) * height);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, width, height, GL_RGBA, GL_FLOAT, values->GetPointer(0));
    in.Radiance->Initialize();
    in.Radiance->SetDimensions(width, height, 1);
    in.Radiance->GetPointData()->SetScalars(values);
  }

  // --- composite over the scene in the renderer's framebuffer (000 Eq. 4).
  state->PopFramebufferBindings();
  state->vtkglViewport(x0, y0, width, height);
  state->vtkglDisable(GL_BLEND);
  in.Accumulation->Activate();
  in.SceneColor->Activate();
  vtkShaderProgram* composite = in.Ready(in.CompositePass, svsCompositeFS);
  setCommon(composite);
  composite->SetUniformi("accumulation", in.Accumulation->GetTextureUnit());
  composite->SetUniformi("sceneColor", in.SceneColor->GetTextureUnit());
  composite->SetUniformi("rayEnds", in.RayEnds->GetTextureUnit());
  composite->SetUniform3f("displayScale", settings.DisplayScale);
  composite->SetUniformi("encodeSrgb", settings.EncodeSrgb ? 1 : 0);
  composite->SetUniformi("skyBackground", settings.OverSky ? 1 : 0);
  if (settings.OverSky)
  {
    in.ClearAccumulation->Activate();
    composite->SetUniformi("clearAccumulation", in.ClearAccumulation->GetTextureUnit());
  }
  else
  {
    // Unused; a sampler must still name a 2-D texture unit.
    composite->SetUniformi("clearAccumulation", in.Accumulation->GetTextureUnit());
  }
  in.CompositePass->Render();
  ++in.PassesLastRender;

  for (vtkTextureObject* t : { in.Density.GetTexture(), in.SceneDepth.GetPointer(),
         in.RayEnds.GetPointer(), in.IntervalPhase.GetPointer(), in.Shadow.GetPointer(),
         in.Accumulation.GetPointer(), in.SceneColor.GetPointer() })
  {
    t->Deactivate();
  }
  if (settings.OverSky)
  {
    in.ClearAccumulation->Deactivate();
  }
  if (atmosphere)
  {
    in.AtmosphereTexture->Deactivate();
  }
}

//------------------------------------------------------------------------------
void vtkNimbusCloudVolumeMapper::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "ExtinctionPerDensity: " << this->ExtinctionPerDensity << " 1/m\n";
  os << indent << "Albedo: " << this->Albedo << "\n";
  os << indent << "CloudG: " << this->CloudG << "\n";
  os << indent << "MultipleScattering (k_multi): " << this->MultipleScattering << "\n";
  os << indent << "SunAzimuthDegrees: " << this->SunAzimuthDegrees << "\n";
  os << indent << "SunElevationDegrees: " << this->SunElevationDegrees << "\n";
  os << indent << "SunIlluminance: " << this->SunIlluminance << "\n";
  os << indent << "SunTemperatureKelvin: " << this->SunTemperatureKelvin << "\n";
  os << indent << "Atmosphere: " << this->Atmosphere << "\n";
  os << indent << "MieScatteringPerMetre: " << this->MieScatteringPerMetre << "\n";
  os << indent << "MieG: " << this->MieG << "\n";
  os << indent << "RayleighScatteringPerMetre: " << this->RayleighScatteringPerMetre << "\n";
  os << indent << "SceneAltitudeMetres: " << this->SceneAltitudeMetres << "\n";
  os << indent << "Ground: " << this->Ground << "\n";
  os << indent << "GroundHeight: " << this->GroundHeight << "\n";
  os << indent << "GroundAlbedo: " << this->GroundAlbedo << "\n";
  os << indent << "Shafts: " << this->Shafts << "\n";
  os << indent << "NumberOfSlices: " << this->NumberOfSlices << "\n";
  os << indent << "SliceAngleRatio (a): " << this->SliceAngleRatio << "\n";
  os << indent << "ShadowSurfaceSize: " << this->ShadowSurfaceSize << "\n";
  os << indent << "AtmosphereSteps: " << this->AtmosphereSteps << "\n";
  os << indent << "MetresPerUnit: " << this->MetresPerUnit << "\n";
  os << indent << "Exposure: " << this->Exposure << "\n";
  os << indent << "EncodeSrgb: " << this->EncodeSrgb << "\n";
  os << indent << "Unlit: " << this->Unlit << "\n";
  os << indent << "CaptureRadiance: " << this->CaptureRadiance << "\n";
  os << indent << "MaximumTextureSize: " << this->MaximumTextureSize << "\n";
  os << indent << "UseSceneSky: " << this->UseSceneSky << "\n";
}
