#include "vtkNimbusCloudVolumeMapper.h"
#include "Math.h"

#include "Atmosphere.h"
#include "AtmosphereTable.h"
#include "CloudDensityTexture.h"
#include "EmissionTexture.h"
#include "ExternalShadow.h"
#include "FiniteSetters.h"
#include "FrameQuality.h"
#include "LightShadowMaps.h"
#include "LightningTexture.h"
#include "MemoryBudget.h"
#include "MultipleScatteringTexture.h"
#include "PassTimer.h"
#include "SliceGeometry.h"
#include "SpectralColor.h"
#include "Sun.h"
#include "SunAndAir.h"
#include "SunDepthVolume.h"
#include "UpAxis.h"
#include "ViewLights.h"

#include "ShaderLibrary.h"
#include "cloudAirFroxelsFS.h"
#include "cloudLight.h"
#include "cloudLightDepthFS.h"
#include "cloudLightShaftsFS.h"
#include "cloudLightShaftsUpsampleFS.h"
#include "cloudMarchFS.h"
#include "cloudVirtualPlanesFS.h"
#include "nimbusLights.h"
#include "svsCommon.h"
#include "svsCompositeFS.h"
#include "svsIntervalPhaseFS.h"
#include "svsMarchFS.h"
#include "svsRayEndsFS.h"
#include "svsShadowFS.h"
#include "svsSliceFS.h"

#include "Sky.h"
#include "SkyTableCache.h"
#include "vtkNimbusSky.h"
#include "vtkNimbusSkyBackground.h"

#include "vtkCamera.h"
#include "vtkCellData.h"
#include "vtkDataArray.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkLight.h"
#include "vtkLightCollection.h"
#include "vtkMatrix3x3.h"
#include "vtkMatrix4x4.h"
#include "vtkObjectFactory.h"
#include "vtkOpenGLFramebufferObject.h"
#include "vtkOpenGLQuadHelper.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkOpenGLShaderCache.h"
#include "vtkOpenGLState.h"
#include "vtkPointData.h"
#include "vtkRenderer.h"
#include "vtkSMPTools.h"
#include "vtkShaderProgram.h"
#include "vtkSmartPointer.h"
#include "vtkTextureObject.h"
#include "vtkVolume.h"
#include "vtk_glew.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <new>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

vtkStandardNewMacro(vtkNimbusCloudVolumeMapper);
vtkCxxSetObjectMacro(vtkNimbusCloudVolumeMapper, SkyBackground, vtkNimbusSkyBackground);

// The physical numbers refuse NaN and infinity (an error; the value is kept) and
// clamp finite values to their ranges (Common/FiniteSetters.h).
nimbusDefineFiniteSetter(vtkNimbusCloudVolumeMapper, ExtinctionPerDensity);
nimbusDefineFiniteSetter(vtkNimbusCloudVolumeMapper, Albedo);
nimbusDefineFiniteSetter(vtkNimbusCloudVolumeMapper, CloudG);
nimbusDefineFiniteSetter(vtkNimbusCloudVolumeMapper, LightIntensityScale);
nimbusDefineFiniteSetter(vtkNimbusCloudVolumeMapper, SpotEdgeWidthDegrees);
nimbusDefineFiniteSetter(vtkNimbusCloudVolumeMapper, MultipleScattering);
nimbusDefineFiniteSetter(vtkNimbusCloudVolumeMapper, EmissionRadiancePerMetre);
nimbusDefineFiniteSetter(vtkNimbusCloudVolumeMapper, EmissionReferenceTemperatureKelvin);
nimbusDefineFiniteSetter(vtkNimbusCloudVolumeMapper, MultipleScatteringMemoryBudgetMiB);
nimbusDefineFiniteSetter(vtkNimbusCloudVolumeMapper, SunAzimuthDegrees);
nimbusDefineFiniteSetter(vtkNimbusCloudVolumeMapper, SunElevationDegrees);
nimbusDefineFiniteSetter(vtkNimbusCloudVolumeMapper, SunIlluminance);
nimbusDefineFiniteSetter(vtkNimbusCloudVolumeMapper, SunTemperatureKelvin);
nimbusDefineFiniteSetter(vtkNimbusCloudVolumeMapper, MieScatteringPerMetre);
nimbusDefineFiniteSetter(vtkNimbusCloudVolumeMapper, MieG);
nimbusDefineFiniteSetter(vtkNimbusCloudVolumeMapper, RayMarchStepTexels);

void vtkNimbusCloudVolumeMapper::SetTurbidity(double turbidity)
{
  if (!std::isfinite(turbidity))
  {
    vtkErrorMacro("SetTurbidity(" << turbidity << "): not a finite number; MieScatteringPerMetre "
                                  << "stays " << this->MieScatteringPerMetre);
    return;
  }
  const double clamped = std::clamp(turbidity, nimbus::kMinTurbidity, nimbus::kMaxTurbidity);
  this->SetMieScatteringPerMetre(
    nimbus::MieScatteringFromTurbidity(clamped, nimbus::AtmosphereParameters()));
}

double vtkNimbusCloudVolumeMapper::GetTurbidity()
{
  return nimbus::TurbidityFromMieScattering(
    this->MieScatteringPerMetre, nimbus::AtmosphereParameters());
}
nimbusDefineFiniteSetter(vtkNimbusCloudVolumeMapper, RayleighScatteringPerMetre);
nimbusDefineFiniteSetter(vtkNimbusCloudVolumeMapper, SceneAltitudeMetres);
nimbusDefineFiniteSetter(vtkNimbusCloudVolumeMapper, GroundHeight);
nimbusDefineFiniteSetter(vtkNimbusCloudVolumeMapper, GroundAlbedo);
nimbusDefineFiniteSetter(vtkNimbusCloudVolumeMapper, SliceAngleRatio);
nimbusDefineFiniteSetter(vtkNimbusCloudVolumeMapper, MetresPerUnit);
nimbusDefineFiniteSetter(vtkNimbusCloudVolumeMapper, Exposure);
nimbusDefineFiniteSetter(vtkNimbusCloudVolumeMapper, TextureMemoryBudgetMiB);
nimbusDefineFiniteSetter(vtkNimbusCloudVolumeMapper, FrameBudgetMilliseconds);
nimbusDefineFiniteSetter(vtkNimbusCloudVolumeMapper, Quality);
nimbusDefineFiniteSetter(vtkNimbusCloudVolumeMapper, InteractiveUpdateRate);
nimbusDefineFiniteSetter(vtkNimbusCloudVolumeMapper, OctaveExtinctionScale);
nimbusDefineFiniteSetter(vtkNimbusCloudVolumeMapper, OctaveScatteringScale);
nimbusDefineFiniteSetter(vtkNimbusCloudVolumeMapper, OctaveAsymmetryScale);
nimbusDefineFiniteSetter(vtkNimbusCloudVolumeMapper, PatternContribution);
nimbusDefineFiniteSetter(vtkNimbusCloudVolumeMapper, PatternSelection);

void vtkNimbusCloudVolumeMapper::SetScalarMode(int mode)
{
  this->ScalarMode = mode;
}

double vtkNimbusCloudVolumeMapper::GetQualityMinValue()
{
  return nimbus::kMinimumFrameQuality;
}

namespace
{
using nimbus::AllFinite;

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

// A pass's fragment shader: the GLSL library, svsCommon.glsl, for the passes that
// light the cloud cloudLight.glsl, then the pass.
std::string FragmentSource(const char* pass, bool cloudLight, bool viewLights)
{
  return nimbus::WithShaderLibrary(
    std::string("//VTK::System::Dec\n//VTK::Output::Dec\n//NIMBUS::Library\n") + svsCommon + "\n" +
    (cloudLight ? std::string(::cloudLight) + "\n" : std::string()) +
    (viewLights ? std::string(nimbusLights) + "\n" : std::string()) + pass);
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

// A nearest-filtered 2-D float texture (or depth texture) of w x h texels,
// reallocated only when its size changed.
void EnsureTexture2D(vtkTextureObject* texture, vtkOpenGLRenderWindow* window, int w, int h,
  int components, bool depth)
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

// 000 §4.3: back-to-front S_i = C_i + alpha_i S_{i-1}; front-to-back
// S_i = S_{i-1} + alpha*_i C_i with alpha* the transmittance so far (kept in alpha).
void UseSliceBlend(vtkOpenGLState* state, bool backToFront)
{
  state->vtkglEnable(GL_BLEND);
  if (backToFront)
  {
    state->vtkglBlendFuncSeparate(GL_ONE, GL_SRC_ALPHA, GL_ZERO, GL_SRC_ALPHA);
  }
  else
  {
    state->vtkglBlendFuncSeparate(GL_DST_ALPHA, GL_ONE, GL_ZERO, GL_SRC_ALPHA);
  }
}

struct SavedPassState
{
  vtkOpenGLState::ScopedglViewport Viewport;
  vtkOpenGLState::ScopedglBlendFuncSeparate BlendFunction;
  vtkOpenGLState::ScopedglEnableDisable Blend;
  vtkOpenGLState::ScopedglEnableDisable DepthTest;
  vtkOpenGLState::ScopedglEnableDisable Scissor;
  vtkOpenGLState::ScopedglScissor ScissorBox;
  vtkOpenGLState::ScopedglEnableDisable Cull;
  vtkOpenGLState::ScopedglDepthMask DepthMask;
  vtkOpenGLState::ScopedglColorMask ColorMask;

  explicit SavedPassState(vtkOpenGLState* state)
    : Viewport(state)
    , BlendFunction(state)
    , Blend(state, GL_BLEND)
    , DepthTest(state, GL_DEPTH_TEST)
    , Scissor(state, GL_SCISSOR_TEST)
    , ScissorBox(state)
    , Cull(state, GL_CULL_FACE)
    , DepthMask(state)
    , ColorMask(state)
  {
    state->vtkglColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    state->vtkglDisable(GL_CULL_FACE);
    state->vtkglDisable(GL_SCISSOR_TEST);
  }
};

// The sun, air, ground and display parameters of one frame: the mapper's own, or
// those of the Nimbus sky drawn behind it (see UseSceneSky).
struct FrameSettings
{
  nimbus::SunParameters Sun;
  nimbus::SceneAtmosphere Air;
  double GroundHeight; // height along the up axis (up-frame z), world units
  nimbus::UpAxis Up = nimbus::UpAxis::PositiveZ; // which axis of the world is up
  double GroundAlbedo;                           // dimensionless
  double MetresPerUnit;                          // metres per world unit
  double DisplayScale[3];                        // per channel
  bool EncodeSrgb;
  bool OverSky;
};
}

struct vtkNimbusCloudVolumeMapper::FrameState
{
  vtkOpenGLRenderWindow* Window = nullptr;
  vtkOpenGLState* State = nullptr;
  vtkCamera* Camera = nullptr;
  std::array<double, 3> Eye{}; // the camera's position in the up frame
  FrameSettings Settings;
  bool Atmosphere = false;     // the atmosphere is drawn (Atmosphere, not Unlit)
  bool Ground = false;         // the ground is drawn (Ground, not Unlit)
  bool OutsideRegions = false; // passes outside the slices (atmosphere or ground)
  bool ExternalShadow = false; // the other pieces' shadow (ExternalDensity) this frame
  // World -> the multiple-scattering textures' coordinates (the density texture's
  // scaled, or for a piece of a distributed cloud, the whole cloud's coarse grid's).
  std::array<float, 16> WorldToScattering{};

  // The renderer's viewport in the framebuffer.
  int Width = 0, Height = 0, X0 = 0, Y0 = 0;
  // This frame's quality level (slices, shadow surface, the size of the image the
  // passes render before the composite scales it to the viewport) and whether the
  // render window asked for an interactive frame.
  nimbus::FrameLevel Level;
  bool Interactive = false;
  // When the passes began (the frame's cost, for the cost model and the progress).
  std::chrono::steady_clock::time_point PassesStart;

  // Slice geometry (world coordinates).
  nimbus::Vector3 ToSun{ { 0.0, 0.0, 1.0 } };
  nimbus::SliceAxis Axis;
  std::vector<nimbus::Vector3> Corners; // of the density box
  nimbus::SlicePlanes Planes;
  nimbus::ShadowFrame Shadow;
  double SunStepMetres = 0.0; // sun path length between two slices

  // Matrices of the shared uniforms (column-major) and the one of the scissors.
  std::array<float, 16> InverseViewProjection{};
  // NDC -> world relative to the eye (perspective rays: no far-plane point, whose
  // w underflows in float for a far/near ratio of 1e8), the view's forward axis
  // and the clipping range (depth -> distance in closed form).
  std::array<float, 16> InverseViewProjectionFromEye{};
  std::array<double, 3> ViewForward{ { 0.0, 0.0, -1.0 } };
  std::array<float, 2> ClippingRange{ { 1.0f, 2.0f } };
  mutable bool FramebuffersPushed = false; // the scene's bindings, popped by the composite
  std::array<float, 16> WorldToTexture{};
  std::array<float, 16> WorldToBox{};
  // The first slice plane of the whole cloud's slicing (SlicingBounds), else of
  // this box's: sunward of it no sun line meets the cloud (svsMarchFS.glsl).
  double FirstPlaneOffset = 0.0;
  vtkNew<vtkMatrix4x4> WorldToNdc;
  vtkNew<vtkMatrix4x4> DataToWorld;

  // The density's source (for the multiple-scattering grid).
  vtkImageData* Image = nullptr;
  vtkDataArray* Scalars = nullptr;
  bool CellData = false;

  // Multiple scattering this frame: the solver's texture, the delta-M forward
  // fraction and the octaves (1: none).
  bool ScatteringTexture = false;
  double ForwardPeakFraction = 0.0;
  double ScatteringScale = 1.0; // this frame's illuminance / the solve's
  int Octaves = 1;

  // Lightning: the in-scattered radiance vtkNimbusLightningIllumination left in the
  // image's field data, uploaded; its first scattering on the density's grid, when there.
  bool LightningTexture = false;
  bool LightningFirstScattering = false;
  // Drawn the delta-M way (LightningDeltaMView, with the reduced first scattering): the
  // slices' third target, the march's second transmittance.
  bool LightningDeltaM = false;

  // Temperature emission (EmissionTexture.h): uploaded and glowing.
  bool EmissionTexture = false;

  // A hash of the opaque scene's depth in the viewport (0 without one).
  std::uint64_t SceneDepthHash = 0;

  // The view's lights this frame (up frame; docs/lights.md), whether their shadow maps
  // were drawn, and what the frame's image depends on through them.
  std::vector<nimbus::ViewLight> Lights;
  bool LightShadows = false;
  bool LightCloudVolume = false; // the lights' transmittance volume is drawn
  bool LightMap = false;
  std::array<double, 6> LightRegion{ { 0, -1, 0, -1, 0, -1 } }; // up frame
  std::vector<double> LightsKey;
};

struct vtkNimbusCloudVolumeMapper::Internals
{
  vtkOpenGLRenderWindow* Window = nullptr;

  // Density volume (000: the "volume texture").
  nimbus::CloudDensityTexture Density;

  // Multiple scattering (003, 004): the solver's texture, and the sky it sees
  // (a sky model of the mapper's own air, built only when the sky light needs it).
  nimbus::MultipleScatteringTexture Scattering;
  std::string LastScatteringError;
  // Lightning (LightningTexture.h).
  nimbus::LightningTexture Lightning;
  std::string LastLightningError;
  // Temperature emission (EmissionTexture.h).
  nimbus::EmissionTexture Emission;
  std::string LastEmissionError;
  double LastPrecomputeSeconds = 0.0;
  double SolvedIlluminance = 0.0; // the sun's illuminance of the last solve

  // Atmosphere texture (000 §3), keyed by the parameters it depends on.
  vtkNew<vtkTextureObject> AtmosphereTexture;
  std::vector<double> AtmosphereKey;
  nimbus::AtmosphereTable Table;
  // The air's multiple scattering (AirMultipleScattering): a sky model of the air.
  // The sky model of the frame's air and ground (FrameSkyModel): the air's multiple
  // scattering and the cloud's sky light share it; rebuilt (1.5 s) when they change. And
  // the sky seen from the cloud (CloudSkyView: its sky-view table, slot 0).
  nimbus::SkyTableCache FrameSky;

  // Sampling-interval and Mie-phase texture (000 §4.4), keyed likewise.
  vtkNew<vtkTextureObject> IntervalPhase;
  vtkNew<vtkOpenGLFramebufferObject> IntervalPhaseFramebuffer;
  std::vector<double> IntervalPhaseKey;

  // Accumulation (S, alpha) at the viewport size, and copies of the scene's colour and depth.
  vtkNew<vtkTextureObject> Accumulation;
  vtkNew<vtkTextureObject> ClearAccumulation; // S without the cloud (over a sky)
  // The lightning's delta-M view in the slices: its light through the reduced extinction
  // (radiance, reduced transmittance), a third target; on when the last slices drew it.
  vtkNew<vtkTextureObject> LightningAccumulation;
  bool LightningAccumulationOn = false;
  vtkNew<vtkOpenGLFramebufferObject> AccumulationFramebuffer;
  vtkNew<vtkTextureObject> SceneColor;
  vtkNew<vtkTextureObject> SceneDepth;
  bool WarnedMultisampling = false;
  vtkNew<vtkOpenGLFramebufferObject> SceneFramebuffer;
  vtkNew<vtkTextureObject> RayEnds;
  vtkNew<vtkOpenGLFramebufferObject> RayEndsFramebuffer;
  vtkNew<vtkImageData> Radiance; // float copy of the last accumulation (CaptureRadiance)

  // The other pieces' optical depth toward the sun (ExternalShadow.h): the
  // coarse whole density, its map facing the sun (keyed by what it depends on) and
  // the map as a 2-channel float texture.
  vtkSmartPointer<vtkImageData> ExternalDensity;
  nimbus::CoarseDensityGrid ExternalGrid;
  vtkMTimeType ExternalGridTime = 0;
  std::string ExternalGridError;
  nimbus::ExternalShadowMap ExternalMap;
  std::vector<double> ExternalMapKey;
  vtkNew<vtkTextureObject> ExternalShadowTexture;
  int ExternalMapBuilds = 0;

  // Shadow surface facing the sun (000 Eq. 10).
  vtkNew<vtkTextureObject> Shadow;
  vtkNew<vtkOpenGLFramebufferObject> ShadowFramebuffer;

  // The ray-marched method: the cloud's optical depth toward the sun per density
  // texel and the density's block maxima (keyed by what they depend on), and the
  // clear air's look-up volume over the view (an atlas: in-scattering, transmittance).
  vtkNew<vtkTextureObject> SunDepthTexture;
  vtkNew<vtkTextureObject> BlockTexture;
  std::array<int, 3> BlockCount{ { 1, 1, 1 } };
  std::vector<double> SunDepthKey;
  double DensityMaximum = 0.0; // the largest density texel (0: no cloud to shadow the lights)
  int SunDepthBuilds = 0;
  double LastSunDepthSeconds = 0.0;
  vtkNew<vtkTextureObject> FroxelScattering;
  vtkNew<vtkTextureObject> FroxelTransmittance;
  vtkNew<vtkOpenGLFramebufferObject> FroxelFramebuffer;
  vtkNew<vtkOpenGLFramebufferObject> MarchFramebuffer;

  // The view's lights: the opaque scene's shadow maps, the light map's luminance, the
  // virtual planes' target (LightShaftsByVirtualPlanes).
  nimbus::LightShadowMaps ShadowMaps;
  vtkNew<vtkTextureObject> LightMapTexture;
  vtkMTimeType LightMapTime = 0;
  vtkNew<vtkTextureObject> LightsImage;
  vtkNew<vtkOpenGLFramebufferObject> LightsFramebuffer;
  // The shafts on fewer pixels (LightShaftDownsampling): the march's span target (the
  // cloud's first and last occupied distance, its transmittance, the ray's end), the
  // shafts' own image and the framebuffer that adds them to the accumulation.
  vtkNew<vtkTextureObject> CloudSpanImage;
  vtkNew<vtkTextureObject> ShaftsImage;
  vtkNew<vtkOpenGLFramebufferObject> ShaftsFramebuffer;
  // The cloud's transmittance toward each light per texel of a coarse copy of the
  // density's grid (cloudLightDepthFS.glsl), keyed by what it depends on.
  vtkNew<vtkTextureObject> LightCloudVolume;
  vtkNew<vtkOpenGLFramebufferObject> LightCloudFramebuffer;
  std::vector<double> LightCloudKey;
  int LightCloudSlices = 1;
  int LightCloudBuilds = 0;
  int LightsLastRender = 0;
  std::string LightsMessage;

  // The GPU time of each pass (TimePasses).
  nimbus::PassTimer Timer;
  std::string LastPassTimes;

  std::unique_ptr<vtkOpenGLQuadHelper> SlicePass, ShadowPass, IntervalPhasePass, MarchPass,
    CompositePass, RayEndsPass, CloudMarchPass, FroxelPass, PlanesPass, LightCloudPass, ShaftsPass,
    ShaftsUpsamplePass;

  int AtmosphereBuilds = 0;
  int IntervalPhaseBuilds = 0;
  int PassesLastRender = 0;

  // Automatic quality: the passes' measured cost against the quality level, and
  // the last frame's key (FrameReuseKey) while its cloud image (the accumulation
  // targets) is still valid for a frame with the same key.
  nimbus::FrameCostModel Cost;
  std::vector<double> ReuseKey;
  bool ReuseValid = false;
  std::vector<float> DepthReadback;
  nimbus::FrameLevel LastLevel;
  bool LastInteractive = false;
  bool LastReused = false;
  bool LastAborted = false;
  double LastFrameSeconds = 0.0;
  bool LastBackToFront = false;
  bool LastOverSky = false;
  double LastSunElevationDegrees = 0.0;
  double LastGroundHeight = 0.0;
  // The error of the last frame that failed: the same error is not repeated every
  // frame, only after a frame that worked or another error.
  std::string LastFrameError;

  void Release(vtkWindow* window)
  {
    this->Density.Release(window);
    this->Scattering.Release(window);
    this->Lightning.Release(window);
    this->Emission.Release(window);
    for (vtkTextureObject* t :
      { AtmosphereTexture.GetPointer(), IntervalPhase.GetPointer(), Accumulation.GetPointer(),
        ClearAccumulation.GetPointer(), SceneColor.GetPointer(), SceneDepth.GetPointer(),
        Shadow.GetPointer(), RayEnds.GetPointer(), ExternalShadowTexture.GetPointer(),
        SunDepthTexture.GetPointer(), BlockTexture.GetPointer(), FroxelScattering.GetPointer(),
        FroxelTransmittance.GetPointer(), LightMapTexture.GetPointer(), LightsImage.GetPointer(),
        LightCloudVolume.GetPointer(), CloudSpanImage.GetPointer(), ShaftsImage.GetPointer(),
        LightningAccumulation.GetPointer() })
    {
      t->ReleaseGraphicsResources(window);
    }
    ShadowMaps.Release(window);
    LightMapTime = 0;
    LightCloudKey.clear();
    for (vtkOpenGLFramebufferObject* f :
      { IntervalPhaseFramebuffer.GetPointer(), SceneFramebuffer.GetPointer(),
        RayEndsFramebuffer.GetPointer(), AccumulationFramebuffer.GetPointer(),
        ShadowFramebuffer.GetPointer(), FroxelFramebuffer.GetPointer(),
        MarchFramebuffer.GetPointer(), LightsFramebuffer.GetPointer(),
        LightCloudFramebuffer.GetPointer(), ShaftsFramebuffer.GetPointer() })
    {
      f->ReleaseGraphicsResources(window);
    }
    for (auto* pass : { &SlicePass, &ShadowPass, &IntervalPhasePass, &MarchPass, &CompositePass,
           &RayEndsPass, &CloudMarchPass, &FroxelPass, &PlanesPass, &LightCloudPass, &ShaftsPass,
           &ShaftsUpsamplePass })
    {
      if (*pass)
      {
        (*pass)->ReleaseGraphicsResources(window);
        pass->reset();
      }
    }
    Timer.Release();
    AtmosphereKey.clear();
    IntervalPhaseKey.clear();
    SunDepthKey.clear();
    ReuseKey.clear();
    ReuseValid = false;
    Window = nullptr;
  }

  vtkShaderProgram* Ready(std::unique_ptr<vtkOpenGLQuadHelper>& pass, const char* source,
    bool cloudLight = false, bool viewLights = false)
  {
    if (!pass)
    {
      const std::string fs = FragmentSource(source, cloudLight, viewLights);
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
  const nimbus::SunParameters sun;
  this->SunAzimuthDegrees = sun.AzimuthDegrees;
  this->SunElevationDegrees = sun.ElevationDegrees;
}

vtkNimbusCloudVolumeMapper::~vtkNimbusCloudVolumeMapper()
{
  this->SetSkyBackground(nullptr);
  this->SetLightMap(nullptr);
}

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
  // No exception leaves Render (a VTK render loop, ParaView's, does not catch):
  // whatever a step throws ends the frame with an error, and nothing is drawn
  // over the scene (the composite, the only pass that writes there, is the last).
  Internals& in = *this->Internal;
  in.PassesLastRender = 0;
  // ViewCoverBounds serve the render they were set for (ParaView's compositor reads
  // the props' bounds before it draws them); a camera reset after it must see the
  // cloud's own bounds.
  for (int c = 0; c < 6; ++c)
  {
    this->ViewCoverBounds[c] = (c % 2) ? -1.0 : 1.0;
  }
  FrameState frame;
  std::string failure;
  try
  {
    if (this->RenderFrame(renderer, volume, frame))
    {
      in.LastFrameError.clear();
    }
    return;
  }
  catch (const std::bad_alloc&)
  {
    failure = "out of memory";
  }
  catch (const std::length_error& error)
  {
    failure = std::string("a size too large (") + error.what() + ")";
  }
  catch (const std::exception& error)
  {
    failure = error.what();
  }
  catch (...)
  {
    failure = "an unknown exception";
  }
  this->AbandonFrame(frame);
  this->ReportFrameError("The cloud is not drawn: " + failure + ".");
}

void vtkNimbusCloudVolumeMapper::ReportFrameError(const std::string& message)
{
  Internals& in = *this->Internal;
  if (message != in.LastFrameError)
  {
    vtkErrorMacro(<< message);
    in.LastFrameError = message;
  }
}

// After an exception: the scene's framebuffer bindings back, our textures released
// from their units (the GL state the passes set is restored by SavedPassState).
void vtkNimbusCloudVolumeMapper::AbandonFrame(FrameState& frame)
{
  if (frame.FramebuffersPushed && frame.State)
  {
    frame.State->PopFramebufferBindings();
    frame.FramebuffersPushed = false;
  }
  if (frame.Window)
  {
    Internals& in = *this->Internal;
    for (vtkTextureObject* t :
      { in.Density.GetTexture(), in.SceneDepth.GetPointer(), in.RayEnds.GetPointer(),
        in.IntervalPhase.GetPointer(), in.Shadow.GetPointer(), in.Accumulation.GetPointer(),
        in.SceneColor.GetPointer(), in.ClearAccumulation.GetPointer(),
        in.AtmosphereTexture.GetPointer(), in.ExternalShadowTexture.GetPointer(),
        in.SunDepthTexture.GetPointer(), in.BlockTexture.GetPointer(),
        in.FroxelScattering.GetPointer(), in.FroxelTransmittance.GetPointer(),
        in.ShadowMaps.GetTexture(), in.LightMapTexture.GetPointer(), in.LightsImage.GetPointer(),
        in.LightCloudVolume.GetPointer(), in.CloudSpanImage.GetPointer(),
        in.ShaftsImage.GetPointer(), in.LightningAccumulation.GetPointer() })
    {
      if (t->GetContext())
      {
        t->Deactivate();
      }
    }
  }
}

bool vtkNimbusCloudVolumeMapper::RenderFrame(
  vtkRenderer* renderer, vtkVolume* volume, FrameState& frame)
{
  Internals& in = *this->Internal;
  if (!this->UpdateDensityTexture(renderer, frame) || !this->ComputeFrameSettings(frame) ||
    !this->ComputeFrameGeometry(renderer, volume, frame))
  {
    return false;
  }
  const SavedPassState savedState(frame.State);
  this->CopySceneColorAndDepth(frame);
  if (!this->UpdateAtmosphereTable(frame))
  {
    frame.State->PopFramebufferBindings();
    frame.FramebuffersPushed = false;
    return false;
  }
  this->UpdateExternalShadow(frame);
  this->UpdateViewLights(renderer, frame);
  this->UpdateMultipleScattering(frame);
  this->UpdateLightning(frame);
  this->UpdateEmission(frame);
  this->UpdateSunDepthVolume(frame);
  // Nothing the cloud depends on changed since the last complete frame: its image
  // (the accumulation targets) is composited again without a pass.
  std::vector<double> key = this->FrameReuseKey(frame);
  const bool reuse = in.ReuseValid && key == in.ReuseKey;

  in.ReuseValid = false;
  in.LastLevel = frame.Level;
  in.LastInteractive = frame.Interactive;
  in.LastReused = reuse;
  in.LastAborted = false;
  in.LastFrameSeconds = 0.0;
  this->BeginPasses(frame);
  frame.PassesStart = std::chrono::steady_clock::now();
  in.Timer.BeginFrame(this->TimePasses && !reuse);
  if (reuse)
  {
    // The cloud's image of the frame before is composited again.
  }
  else if (this->UsesRayMarching())
  {
    this->UpdateLightCloudVolume(frame);
    in.Timer.Begin("air look-up volume");
    this->RenderAirFroxels(frame);
    in.Timer.Begin("ray march");
    this->RenderCloudMarch(frame);
    this->RenderLightShafts(frame);
    this->RenderVirtualPlanes(frame);
    this->CaptureRadianceImage(frame);
  }
  else
  {
    this->ClearShadowSurface(frame);
    in.Timer.Begin("interval and phase");
    this->RenderIntervalPhase(frame);
    in.Timer.Begin("ray ends");
    this->RenderRayEnds(frame);
    this->ClearAccumulation(frame);
    in.Timer.Begin("slices");
    if (!this->RenderSlices(renderer, frame))
    {
      // Aborted: nothing is drawn over the scene this frame.
      frame.State->PopFramebufferBindings();
      frame.FramebuffersPushed = false;
      this->EndPasses(frame);
      in.Timer.BeginFrame(false);
      in.LastAborted = true;
      return true;
    }
    // Behind the box first: its blend reads the cloud transmittance the slices left.
    in.Timer.Begin("air behind the box");
    this->RenderOutsideRegion(frame, true);
    in.Timer.Begin("air in front of the box");
    this->RenderOutsideRegion(frame, false);
    in.Timer.End();
    this->CaptureRadianceImage(frame);
  }
  in.Timer.Begin("composite");
  this->RenderComposite(frame);
  in.Timer.End();
  this->EndPasses(frame);
  if (!reuse)
  {
    // The passes' cost at this level (the work is done when glFinish returns).
    glFinish();
    in.LastFrameSeconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - frame.PassesStart).count();
    in.Cost.AddSample(frame.Level.Quality, in.LastFrameSeconds);
    in.Timer.Collect();
    in.LastPassTimes = this->TimePasses ? in.Timer.Report() : std::string();
  }
  in.ReuseKey = std::move(key);
  in.ReuseValid = true;
  return true;
}

//------------------------------------------------------------------------------
namespace
{
// Distances to a view light are at least this (a lamp's size): a light on a view ray
// or at the eye gives a finite beam (docs/lights.md).
constexpr double kLightRadiusMetres = 0.05;
constexpr double kRayMarchMinimumQuality = 0.25 * 0.25 * 0.25;
}

// The quality level of this frame: Quality for still frames, the level the cost
// model fits into FrameBudgetMilliseconds for interactive ones.
void vtkNimbusCloudVolumeMapper::ChooseFrameLevel(vtkRenderer* renderer, FrameState& frame)
{
  vtkRenderWindow* window = renderer->GetRenderWindow();
  frame.Interactive = window && window->GetDesiredUpdateRate() >= this->InteractiveUpdateRate;
  double quality = this->Quality;
  if (frame.Interactive && this->FrameBudgetMilliseconds > 0.0)
  {
    // The passes get 80 % of the budget; the rest of the frame (the scene's other
    // props, the copies, the swap) the rest.
    quality = this->Internal->Cost.QualityFor(0.8e-3 * this->FrameBudgetMilliseconds, quality);
    if (this->UsesRayMarching())
    {
      // The ray march's interactive frames keep at least a quarter of the view's width and
      // height (a quarter of the steps, an image of 1/16 of the pixels): its cost is
      // mostly per pixel, and a smaller image only blurs.
      quality = std::max(quality, std::min(kRayMarchMinimumQuality, this->Quality));
    }
  }
  frame.Level = nimbus::ComputeFrameLevel(
    quality, this->NumberOfSlices, this->ShadowSurfaceSize, frame.Width, frame.Height);
}

//------------------------------------------------------------------------------
// Everything the cloud's image (the accumulation targets) depends on: the mapper's
// settings (its modification time), the data, the volume's matrix (not its
// modification time: ParaView touches the vtkVolume every render), the followed
// sky, the camera, the viewport, the quality level, the solver's output and the
// opaque scene's depth. The exposure and the background only enter the composite,
// which runs every frame, but a change of them costs one frame at most.
std::vector<double> vtkNimbusCloudVolumeMapper::FrameReuseKey(const FrameState& frame)
{
  Internals& in = *this->Internal;
  std::vector<double> key;
  key.reserve(96);
  const auto time = [](vtkObject* o) { return o ? static_cast<double>(o->GetMTime()) : -1.0; };
  vtkNimbusSky* sky = this->GetFollowedSky();
  key.insert(key.end(),
    { time(this), time(frame.Image), time(frame.Scalars),
      static_cast<double>(reinterpret_cast<std::uintptr_t>(frame.Scalars)),
      frame.CellData ? 1.0 : 0.0, time(this->SkyBackground), time(sky),
      static_cast<double>(in.Density.GetNumberOfUploads()),
      static_cast<double>(in.Scattering.GetNumberOfSolves()), frame.ScatteringScale,
      static_cast<double>(in.Lightning.GetNumberOfUploads()), frame.LightningTexture ? 1.0 : 0.0,
      static_cast<double>(in.Emission.GetNumberOfUploads()), frame.EmissionTexture ? 1.0 : 0.0,
      static_cast<double>(in.ExternalMapBuilds), frame.ExternalShadow ? 1.0 : 0.0,
      static_cast<double>(in.AtmosphereBuilds),
      static_cast<double>(in.FrameSky.GetModelGeneration()), frame.Settings.Sun.ElevationDegrees,
      frame.Settings.Sun.AzimuthDegrees, frame.Settings.OverSky ? 1.0 : 0.0,
      static_cast<double>(frame.Width), static_cast<double>(frame.Height),
      static_cast<double>(frame.X0), static_cast<double>(frame.Y0),
      static_cast<double>(frame.Level.Width), static_cast<double>(frame.Level.Height),
      static_cast<double>(frame.Level.Slices), static_cast<double>(frame.Level.ShadowSurfaceSize),
      static_cast<double>(frame.SceneDepthHash >> 32),
      static_cast<double>(frame.SceneDepthHash & 0xffffffffu) });
  key.insert(key.end(), frame.WorldToNdc->GetData(), frame.WorldToNdc->GetData() + 16);
  key.insert(key.end(), frame.DataToWorld->GetData(), frame.DataToWorld->GetData() + 16);
  key.insert(key.end(), frame.Eye.begin(), frame.Eye.end());
  key.insert(key.end(), frame.ClippingRange.begin(), frame.ClippingRange.end());
  key.insert(key.end(), frame.LightsKey.begin(), frame.LightsKey.end());
  return key;
}

double vtkNimbusCloudVolumeMapper::GetLastFrameQuality() const
{
  return this->Internal->LastLevel.Quality;
}

double vtkNimbusCloudVolumeMapper::GetLastFrameImageScale() const
{
  return this->Internal->LastLevel.ImageScale;
}

int vtkNimbusCloudVolumeMapper::GetLastFrameSlices() const
{
  return this->Internal->LastLevel.Slices;
}

bool vtkNimbusCloudVolumeMapper::GetLastFrameInteractive() const
{
  return this->Internal->LastInteractive;
}

bool vtkNimbusCloudVolumeMapper::GetLastFrameReused() const
{
  return this->Internal->LastReused;
}

double vtkNimbusCloudVolumeMapper::GetLastFrameSeconds() const
{
  return this->Internal->LastFrameSeconds;
}

bool vtkNimbusCloudVolumeMapper::GetLastFrameAborted() const
{
  return this->Internal->LastAborted;
}

//------------------------------------------------------------------------------
// The render window and the density texture: uploaded only when the data (not
// the lighting) changed.
bool vtkNimbusCloudVolumeMapper::UpdateDensityTexture(vtkRenderer* renderer, FrameState& frame)
{
  Internals& in = *this->Internal;
  auto* window = vtkOpenGLRenderWindow::SafeDownCast(renderer->GetRenderWindow());
  if (!window)
  {
    this->ReportFrameError("vtkNimbusCloudVolumeMapper needs an OpenGL render window.");
    return false;
  }
  if (in.Window && in.Window != window)
  {
    in.Release(in.Window);
  }
  in.Window = window;
  frame.Window = window;
  frame.State = window->GetState();
  vtkImageData* image = vtkImageData::SafeDownCast(this->GetInput());
  if (!image)
  {
    this->ReportFrameError("No input image: connect a vtkImageData with a density array.");
    return false;
  }
  this->GetInputAlgorithm()->UpdateInformation();
  this->GetInputAlgorithm()->Update();
  image = vtkImageData::SafeDownCast(this->GetInput());

  int cellFlag = 0;
  vtkDataArray* scalars = vtkAbstractMapper::GetScalars(
    image, this->ScalarMode, this->ArrayAccessMode, this->ArrayId, this->ArrayName, cellFlag);
  if (!scalars)
  {
    this->ReportFrameError("The input image has no scalar array to render as density (set one "
                           "with SelectScalarArray, or give the image active point scalars).");
    return false;
  }
  // GL_MAX_3D_TEXTURE_SIZE (256 if the driver does not say), lowered by
  // MaximumTextureSize; the texture memory budget may lower it further.
  int glLimit = vtkTextureObject::GetMaximumTextureSize3D(window);
  glLimit = glLimit > 0 ? glLimit : 256;
  const int maxSize =
    this->MaximumTextureSize > 0 ? std::min(this->MaximumTextureSize, glLimit) : glLimit;
  const double budgetBytes = this->TextureMemoryBudgetMiB > 0.0
    ? this->TextureMemoryBudgetMiB * 1024.0 * 1024.0
    : static_cast<double>(nimbus::DefaultMemoryBudgetBytes());
  std::vector<std::string> warnings;
  std::string error;
  const bool ok = (in.Density.SetKeepTexels(this->UsesRayMarching()),
    in.Density.Update(
      window, image, scalars, cellFlag != 0, maxSize, budgetBytes, warnings, error));
  frame.Image = image;
  frame.Scalars = scalars;
  frame.CellData = cellFlag != 0;
  for (const std::string& warning : warnings)
  {
    vtkWarningMacro(<< warning);
  }
  if (!ok)
  {
    this->ReportFrameError(error);
  }
  return ok;
}

//------------------------------------------------------------------------------
vtkNimbusSky* vtkNimbusCloudVolumeMapper::GetFollowedSky()
{
  if (!this->UseSceneSky || this->Unlit || !this->SkyBackground ||
    !this->SkyBackground->GetVisibility())
  {
    return nullptr;
  }
  return this->SkyBackground->GetSky();
}

// This frame's sun, air, ground and display: ours, or the sky's behind us.
bool vtkNimbusCloudVolumeMapper::ComputeFrameSettings(FrameState& frame)
{
  FrameSettings& settings = frame.Settings;
  settings.Sun.AzimuthDegrees = this->SunAzimuthDegrees;
  settings.Sun.ElevationDegrees = this->SunElevationDegrees;
  settings.Sun.Illuminance = this->SunIlluminance;
  settings.Sun.TemperatureKelvin = this->SunTemperatureKelvin;
  settings.Air.RayleighScatteringPerMetre = this->RayleighScatteringPerMetre;
  settings.Air.MieScatteringPerMetre = this->MieScatteringPerMetre;
  settings.Air.MieG = this->MieG;
  settings.Air.SceneAltitudeMetres = this->SceneAltitudeMetres;
  settings.GroundHeight = this->GroundHeight;
  settings.Up = static_cast<nimbus::UpAxis>(this->UpAxis);
  settings.GroundAlbedo = this->GroundAlbedo;
  settings.MetresPerUnit = this->MetresPerUnit;
  std::fill(settings.DisplayScale, settings.DisplayScale + 3, this->Exposure);
  settings.EncodeSrgb = this->EncodeSrgb;
  settings.OverSky = false;
  if (vtkNimbusSky* sky = this->GetFollowedSky())
  {
    const nimbus::SkyParameters* skyParameters = nullptr;
    try
    {
      skyParameters = &sky->GetSkyModel().GetParameters();
    }
    catch (const std::exception& error)
    {
      this->ReportFrameError(std::string("The scene's sky is invalid: ") + error.what());
      return false;
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
    settings.Up = static_cast<nimbus::UpAxis>(sky->GetUpAxis());
    sky->GetDisplayScale(settings.DisplayScale);
    settings.EncodeSrgb = true; // the sky background is sRGB-encoded
    settings.OverSky = true;
  }
  if (this->Internal->ExternalDensity && settings.Up != nimbus::UpAxis::PositiveZ)
  {
    // The other pieces' coarse density and shadow are kept in world axes.
    this->ReportFrameError(
      "A distributed cloud (pieces on several ranks) is drawn with +Z up only; "
      "the up axis is " +
      nimbus::UpAxisName(settings.Up) +
      ": turn the data instead (the OpenVDB reader's Up Axis, or ParaView's Transform).");
    return false;
  }
  frame.Atmosphere = this->Atmosphere && !this->Unlit;
  frame.Ground = this->Ground && !this->Unlit;
  frame.OutsideRegions = frame.Atmosphere || frame.Ground;
  settings.Air.Enabled = frame.Atmosphere;
  this->Internal->LastOverSky = settings.OverSky;
  this->Internal->LastSunElevationDegrees = settings.Sun.ElevationDegrees;
  return true;
}

//------------------------------------------------------------------------------
namespace
{
// R of Physics/UpAxis.h as a 4x4 matrix (world -> up frame).
void UpFrameMatrix(nimbus::UpAxis up, vtkMatrix4x4* m)
{
  const auto r = nimbus::WorldToUpFrame(up);
  m->Identity();
  for (int i = 0; i < 3; ++i)
  {
    for (int j = 0; j < 3; ++j)
    {
      m->SetElement(i, j, r[i][j]);
    }
  }
}

std::array<double, 3> ToUp(nimbus::UpAxis up, const double world[3])
{
  return nimbus::ToUpFrame(up, { { world[0], world[1], world[2] } });
}
}

//------------------------------------------------------------------------------
// Sun, view, slice axis and planes, the box corners and the shadow frame in the up
// frame (world coordinates turned so that the chosen up axis is +z: every pass works
// there, with the sun, the air and the ground of Physics/), and the matrices of the
// shared uniforms. False for an empty viewport.
bool vtkNimbusCloudVolumeMapper::ComputeFrameGeometry(
  vtkRenderer* renderer, vtkVolume* volume, FrameState& frame)
{
  const nimbus::CloudDensityTexture& density = this->Internal->Density;
  vtkCamera* camera = renderer->GetActiveCamera();
  frame.Camera = camera;
  renderer->GetTiledSizeAndOrigin(&frame.Width, &frame.Height, &frame.X0, &frame.Y0);
  if (frame.Width < 1 || frame.Height < 1)
  {
    return false;
  }
  this->ChooseFrameLevel(renderer, frame);
  frame.ToSun =
    nimbus::SunDirection(frame.Settings.Sun.ElevationDegrees, frame.Settings.Sun.AzimuthDegrees);
  const nimbus::UpAxis up = frame.Settings.Up;
  vtkNew<vtkMatrix4x4> worldToUp;
  UpFrameMatrix(up, worldToUp);
  double worldProjection[3];
  camera->GetDirectionOfProjection(worldProjection);
  const double* worldEye = camera->GetPosition();
  frame.Eye = ToUp(up, worldEye);
  const std::array<double, 3> projectionUp = ToUp(up, worldProjection);
  const double* projection = projectionUp.data();
  const double* eye = frame.Eye.data();
  const double* clipping = camera->GetClippingRange();
  if (!AllFinite(eye, 3) || !AllFinite(projection, 3) || !AllFinite(clipping, 2) ||
    !(clipping[0] > 0.0 && clipping[1] > clipping[0]))
  {
    std::ostringstream message;
    message << "The camera is not usable (position " << eye[0] << ", " << eye[1] << ", " << eye[2]
            << ", clipping range " << clipping[0] << " ... " << clipping[1]
            << "): the cloud is not drawn.";
    this->ReportFrameError(message.str());
    return false;
  }
  const nimbus::Vector3 view = { { projection[0], projection[1], projection[2] } };
  frame.Axis = nimbus::ComputeSliceAxis(view, frame.ToSun, this->SliceAngleRatio);
  this->Internal->LastBackToFront = frame.Axis.BackToFront;

  // Data -> world: the volume's matrix times the image's direction matrix about its
  // origin (VTK 9.2: point = origin + D (index * spacing); the density box is in
  // the unrotated frame origin + index * spacing).
  vtkNew<vtkMatrix4x4> dataToWorld, volumeToWorld;
  if (!this->ComputeDataToWorld(volume, volumeToWorld))
  {
    return false;
  }
  vtkMatrix4x4::Multiply4x4(worldToUp, volumeToWorld, dataToWorld);
  frame.DataToWorld->DeepCopy(dataToWorld);
  const double* boxOrigin = density.GetBoxOrigin();
  const double* boxSize = density.GetBoxSize();
  for (int c = 0; c < 8; ++c)
  {
    const double p[4] = { boxOrigin[0] + ((c & 1) ? boxSize[0] : 0.0),
      boxOrigin[1] + ((c & 2) ? boxSize[1] : 0.0), boxOrigin[2] + ((c & 4) ? boxSize[2] : 0.0),
      1.0 };
    double w[4];
    dataToWorld->MultiplyPoint(p, w);
    frame.Corners.push_back({ { w[0] / w[3], w[1] / w[3], w[2] / w[3] } });
  }
  const std::array<double, 2> range = nimbus::ProjectedRange(frame.Corners, frame.Axis.Normal);
  const double* sb = this->SlicingBounds;
  if (sb[0] <= sb[1] && sb[2] <= sb[3] && sb[4] <= sb[5])
  {
    // One piece of a distributed cloud: the whole cloud's planes, those that cut
    // this piece (at least the nearest one, so the passes keep their geometry).
    std::vector<nimbus::Vector3> whole;
    for (int c = 0; c < 8; ++c)
    {
      const double corner[3] = { sb[(c & 1) ? 1 : 0], sb[(c & 2) ? 3 : 2], sb[(c & 4) ? 5 : 4] };
      whole.push_back(ToUp(up, corner));
    }
    const std::array<double, 2> wholeRange = nimbus::ProjectedRange(whole, frame.Axis.Normal);
    const nimbus::SlicePlanes all = nimbus::MakeSlicePlanes(
      wholeRange[0], std::max(wholeRange[1], wholeRange[0] + 1e-9), frame.Level.Slices);
    frame.Planes = all;
    frame.Planes.Offsets.clear();
    double nearest = all.Offsets.front();
    for (const double offset : all.Offsets)
    {
      if (offset >= range[0] - 0.5 * all.Spacing && offset <= range[1] + 0.5 * all.Spacing)
      {
        frame.Planes.Offsets.push_back(offset);
      }
      if (std::abs(offset - 0.5 * (range[0] + range[1])) <
        std::abs(nearest - 0.5 * (range[0] + range[1])))
      {
        nearest = offset;
      }
    }
    if (frame.Planes.Offsets.empty())
    {
      frame.Planes.Offsets.push_back(nearest);
    }
    frame.FirstPlaneOffset = all.Offsets.front();
  }
  else
  {
    frame.Planes =
      nimbus::MakeSlicePlanes(range[0], std::max(range[1], range[0] + 1e-9), frame.Level.Slices);
    frame.FirstPlaneOffset = frame.Planes.Offsets.front();
  }
  this->PlaceGroundBelowData(frame);
  frame.Shadow = nimbus::ComputeShadowFrame(frame.Corners, frame.ToSun, 0.02);
  frame.SunStepMetres = frame.Planes.Spacing / frame.Axis.SunCosine * frame.Settings.MetresPerUnit;

  // world -> data -> density texture coordinates, and -> the box as [0,1]^3:
  // texture coordinates are tested against [0,1] for "inside the box", and the
  // half-texel offsets of point data make the box itself [0,1]^3 for that test.
  vtkNew<vtkMatrix4x4> worldToData, dataToTexture, worldToTexture, dataToBox, worldToBox;
  vtkMatrix4x4::Invert(dataToWorld, worldToData);
  if (!AllFinite(worldToData->GetData(), 16))
  {
    this->ReportFrameError("The volume's matrix is singular: the cloud is not drawn.");
    return false;
  }
  density.GetDataToTexture(dataToTexture);
  vtkMatrix4x4::Multiply4x4(dataToTexture, worldToData, worldToTexture);
  density.GetDataToBox(dataToBox);
  vtkMatrix4x4::Multiply4x4(dataToBox, worldToData, worldToBox);
  frame.WorldToTexture = ColumnMajor(worldToTexture);
  frame.WorldToBox = ColumnMajor(worldToBox);

  const double aspect = static_cast<double>(frame.Width) / frame.Height;
  // World -> NDC of the camera, after up -> world (R^T): the passes' points are in
  // the up frame.
  vtkNew<vtkMatrix4x4> upToWorld;
  vtkMatrix4x4::Transpose(worldToUp, upToWorld);
  vtkMatrix4x4::Multiply4x4(
    camera->GetCompositeProjectionTransformMatrix(aspect, -1, 1), upToWorld, frame.WorldToNdc);
  vtkNew<vtkMatrix4x4> inverseViewProjection;
  inverseViewProjection->DeepCopy(frame.WorldToNdc);
  inverseViewProjection->Invert();
  // The same with the eye at the origin (world -> NDC of x + eye, inverted): its
  // rays need no far-plane point.
  vtkNew<vtkMatrix4x4> fromEye, eyeToNdc;
  fromEye->Identity();
  for (int k = 0; k < 3; ++k)
  {
    fromEye->SetElement(k, 3, eye[k]);
  }
  vtkMatrix4x4::Multiply4x4(frame.WorldToNdc, fromEye, eyeToNdc);
  eyeToNdc->Invert();
  if (!AllFinite(frame.WorldToNdc->GetData(), 16) ||
    !AllFinite(inverseViewProjection->GetData(), 16) || !AllFinite(eyeToNdc->GetData(), 16))
  {
    this->ReportFrameError("The camera's projection is singular or not finite: the cloud is not "
                           "drawn.");
    return false;
  }
  frame.InverseViewProjection = ColumnMajor(inverseViewProjection);
  frame.InverseViewProjectionFromEye = ColumnMajor(eyeToNdc);
  // The eye's forward axis: minus the third row of the view matrix.
  vtkMatrix4x4* viewMatrix = camera->GetViewTransformMatrix();
  const double worldForward[3] = { -viewMatrix->GetElement(2, 0), -viewMatrix->GetElement(2, 1),
    -viewMatrix->GetElement(2, 2) };
  const std::array<double, 3> forwardUp = ToUp(up, worldForward);
  const double* forward = forwardUp.data();
  const double length =
    std::sqrt(forward[0] * forward[0] + forward[1] * forward[1] + forward[2] * forward[2]);
  for (int k = 0; k < 3; ++k)
  {
    frame.ViewForward[k] = length > 0.0 ? forward[k] / length : projection[k];
  }
  frame.ClippingRange = { { static_cast<float>(clipping[0]), static_cast<float>(clipping[1]) } };
  return true;
}

//------------------------------------------------------------------------------
// GroundBelowData: the ground no higher than the bottom of the data's box (the
// whole cloud's box for one piece of a distributed cloud, so that every rank draws
// the same ground).
void vtkNimbusCloudVolumeMapper::PlaceGroundBelowData(FrameState& frame)
{
  FrameSettings& settings = frame.Settings;
  if (this->GroundBelowData && frame.Ground)
  {
    double bottom = std::numeric_limits<double>::infinity();
    for (const auto& corner : frame.Corners)
    {
      bottom = std::min(bottom, corner[2]);
    }
    const double* sb = this->SlicingBounds;
    if (sb[0] <= sb[1] && sb[2] <= sb[3] && sb[4] <= sb[5])
    {
      for (int c = 0; c < 8; ++c)
      {
        const double corner[3] = { sb[(c & 1) ? 1 : 0], sb[(c & 2) ? 3 : 2], sb[(c & 4) ? 5 : 4] };
        bottom = std::min(bottom, ToUp(settings.Up, corner)[2]);
      }
    }
    if (std::isfinite(bottom))
    {
      settings.GroundHeight = std::min(settings.GroundHeight, bottom);
    }
  }
  this->Internal->LastGroundHeight = settings.GroundHeight;
}

double vtkNimbusCloudVolumeMapper::GetLastGroundHeight() const
{
  return this->Internal->LastGroundHeight;
}

void vtkNimbusCloudVolumeMapper::SetUpAxis(int value)
{
  const std::string refusal = nimbus::UpAxisRefusal(value, this->UpAxis);
  if (!refusal.empty())
  {
    vtkErrorMacro(<< refusal);
    return;
  }
  if (value != this->UpAxis)
  {
    this->UpAxis = value;
    this->Modified();
  }
}

//------------------------------------------------------------------------------
// The volume's matrix times the input image's direction matrix about its origin.
bool vtkNimbusCloudVolumeMapper::ComputeDataToWorld(vtkVolume* volume, vtkMatrix4x4* dataToWorld)
{
  vtkNew<vtkMatrix4x4> imageFrame; // identity without a direction matrix
  auto* image = vtkImageData::SafeDownCast(this->GetInput());
  vtkMatrix3x3* direction = image ? image->GetDirectionMatrix() : nullptr;
  if (direction && !direction->IsIdentity())
  {
    const double determinant = direction->Determinant();
    if (!AllFinite(direction->GetData(), 9) || !std::isfinite(determinant) ||
      std::abs(determinant) < 1e-12)
    {
      std::ostringstream message;
      message << "The input image's direction matrix is singular or not finite (determinant "
              << determinant << "): the cloud is not drawn.";
      this->ReportFrameError(message.str());
      return false;
    }
    double origin[3];
    image->GetOrigin(origin);
    for (int r = 0; r < 3; ++r)
    {
      double shift = origin[r];
      for (int c = 0; c < 3; ++c)
      {
        imageFrame->SetElement(r, c, direction->GetElement(r, c));
        shift -= direction->GetElement(r, c) * origin[c];
      }
      imageFrame->SetElement(r, 3, shift);
    }
  }
  vtkMatrix4x4* volumeMatrix = volume->GetMatrix();
  if (!AllFinite(volumeMatrix->GetData(), 16))
  {
    this->ReportFrameError("The volume's matrix (position, orientation, scale or user matrix) "
                           "is not finite: the cloud is not drawn.");
    return false;
  }
  vtkMatrix4x4::Multiply4x4(volumeMatrix, imageFrame, dataToWorld);
  return true;
}

//------------------------------------------------------------------------------
// Copies of the scene's colour (the background) and depth (the opaque depth) in
// our textures. Leaves the scene's framebuffer bindings pushed (popped by the
// composite). A multisampled framebuffer cannot be copied from
// (GL_INVALID_OPERATION): then the colour is resolved by a blit and the depth is
// treated as empty, with a warning.
void vtkNimbusCloudVolumeMapper::CopySceneColorAndDepth(FrameState& frame)
{
  Internals& in = *this->Internal;
  vtkOpenGLState* state = frame.State;
  GLint drawFramebuffer = 0;
  glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &drawFramebuffer);
  state->PushFramebufferBindings();
  frame.FramebuffersPushed = true;
  state->vtkglBindFramebuffer(GL_READ_FRAMEBUFFER, drawFramebuffer);
  EnsureTexture2D(in.SceneColor, frame.Window, frame.Width, frame.Height, 4, false);
  EnsureTexture2D(in.SceneDepth, frame.Window, frame.Width, frame.Height, 1, true);
  GLint samples = 0;
  glGetIntegerv(GL_SAMPLES, &samples);
  if (samples == 0)
  {
    in.SceneColor->CopyFromFrameBuffer(frame.X0, frame.Y0, 0, 0, frame.Width, frame.Height);
    in.SceneDepth->CopyFromFrameBuffer(frame.X0, frame.Y0, 0, 0, frame.Width, frame.Height);
    // The opaque scene's depth, hashed (FNV-1a over its bytes) for FrameReuseKey:
    // geometry that moved in front of or behind the cloud changes the cloud's image.
    in.DepthReadback.resize(static_cast<std::size_t>(frame.Width) * frame.Height);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(frame.X0, frame.Y0, frame.Width, frame.Height, GL_DEPTH_COMPONENT, GL_FLOAT,
      in.DepthReadback.data());
    std::uint64_t hash = 1469598103934665603ull;
    for (const float depth : in.DepthReadback)
    {
      std::uint32_t bits;
      std::memcpy(&bits, &depth, sizeof bits);
      hash = (hash ^ bits) * 1099511628211ull;
    }
    frame.SceneDepthHash = hash;
    return;
  }
  in.SceneFramebuffer->SetContext(frame.Window);
  in.SceneFramebuffer->Bind(GL_DRAW_FRAMEBUFFER);
  in.SceneFramebuffer->AddColorAttachment(0, in.SceneColor);
  in.SceneFramebuffer->AddDepthAttachment(in.SceneDepth);
  in.SceneFramebuffer->ActivateDrawBuffer(0);
  state->vtkglBindFramebuffer(GL_READ_FRAMEBUFFER, drawFramebuffer);
  glBlitFramebuffer(frame.X0, frame.Y0, frame.X0 + frame.Width, frame.Y0 + frame.Height, 0, 0,
    frame.Width, frame.Height, GL_COLOR_BUFFER_BIT, GL_NEAREST);
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

//------------------------------------------------------------------------------
// The atmosphere texture (only with an atmosphere), rebuilt when the sun or the
// air or the lowest height it must cover changed. False when they are invalid.
bool vtkNimbusCloudVolumeMapper::UpdateAtmosphereTable(FrameState& frame)
{
  Internals& in = *this->Internal;
  const FrameSettings& settings = frame.Settings;
  double boxZMin = std::numeric_limits<double>::infinity();
  for (const auto& corner : frame.Corners)
  {
    boxZMin = std::min(boxZMin, corner[2]);
  }
  // The lowest point a pass samples: the box, the ground and the eye (below both,
  // e.g. under the ground; rounded down to 100 m so a moving eye rebuilds rarely).
  double zLow =
    (std::min(boxZMin, frame.Ground ? settings.GroundHeight : boxZMin)) * settings.MetresPerUnit;
  const double eyeZ = frame.Eye[2] * settings.MetresPerUnit;
  if (eyeZ < zLow)
  {
    zLow = 100.0 * std::floor(eyeZ / 100.0);
  }
  const nimbus::SceneAtmosphere& air = settings.Air;
  const double zHigh = air.TopRadiusMetres - air.EarthRadiusMetres - air.SceneAltitudeMetres;
  const std::vector<double> tableKey = { settings.Sun.AzimuthDegrees, settings.Sun.ElevationDegrees,
    settings.Sun.Illuminance, settings.Sun.TemperatureKelvin, air.Enabled ? 1.0 : 0.0,
    air.SceneAltitudeMetres, air.EarthRadiusMetres, air.TopRadiusMetres,
    air.RayleighScaleHeightMetres, air.MieScaleHeightMetres, air.RayleighScatteringPerMetre,
    air.MieScatteringPerMetre, air.MieAlbedo, air.MieG, zLow };
  // The air's multiple scattering needs a sky model of the air (and of the ground
  // it reflects from), built only when it is on and those changed.
  const bool airMultiple = this->AirMultipleScattering && frame.Atmosphere;
  const std::vector<double> skyKey = FrameSkyKey(frame);
  std::vector<double> atmosphereKey = tableKey;
  atmosphereKey.push_back(airMultiple ? 1.0 : 0.0);
  if (airMultiple)
  {
    atmosphereKey.insert(atmosphereKey.end(), skyKey.begin(), skyKey.end());
  }
  if (atmosphereKey == in.AtmosphereKey)
  {
    return true;
  }
  try
  {
    const int wavelengths = 16;
    const nimbus::SunAndAir sunAndAir(settings.Sun, air, wavelengths);
    // The sky model shared with the cloud's sky light (FrameSkyModel), 16 wavelengths
    // like the table.
    const nimbus::SkyModel* skyModel = airMultiple ? &this->FrameSkyModel(frame) : nullptr;
    in.Table =
      nimbus::BuildAtmosphereTable(sunAndAir, std::min(zLow, zHigh - 1.0), zHigh, 1024, skyModel);
  }
  catch (const std::exception& error)
  {
    this->ReportFrameError(std::string("Invalid sun or atmosphere: ") + error.what());
    return false;
  }
  if (in.Table.HasAtmosphere)
  {
    ResetTexture(in.AtmosphereTexture, frame.Window, true);
    in.AtmosphereTexture->Create2DFromRaw(
      in.Table.Samples, nimbus::AtmosphereTable::kRows, 4, VTK_FLOAT, in.Table.Data.data());
    ++in.AtmosphereBuilds;
  }
  in.AtmosphereKey = atmosphereKey;
  return true;
}

//------------------------------------------------------------------------------
// Uniforms every pass shares (svsCommon.glsl).
void vtkNimbusCloudVolumeMapper::SetCommonUniforms(
  vtkShaderProgram* program, const FrameState& frame)
{
  Internals& in = *this->Internal;
  const nimbus::SceneAtmosphere& air = frame.Settings.Air;
  program->SetUniformMatrix4x4(
    "inverseViewProjection", const_cast<float*>(frame.InverseViewProjection.data()));
  program->SetUniformMatrix4x4(
    "inverseViewProjectionFromEye", const_cast<float*>(frame.InverseViewProjectionFromEye.data()));
  program->SetUniform3f("viewForward", frame.ViewForward.data());
  program->SetUniform2f("clippingRange", frame.ClippingRange.data());
  program->SetUniformi("perspective", frame.Camera->GetParallelProjection() ? 0 : 1);
  program->SetUniform3f("cameraPosition", frame.Eye.data());
  program->SetUniformMatrix4x4("worldToTexture", const_cast<float*>(frame.WorldToTexture.data()));
  program->SetUniformMatrix4x4("worldToBox", const_cast<float*>(frame.WorldToBox.data()));
  program->SetUniform3f("sunDirection", frame.ToSun.data());
  program->SetUniform3f("sliceNormal", frame.Axis.Normal.data());
  program->SetUniformf("metresPerUnit", static_cast<float>(frame.Settings.MetresPerUnit));
  program->SetUniformi("density", in.Density.GetTexture()->GetTextureUnit());
  program->SetUniformf("extinctionPerDensity", static_cast<float>(this->ExtinctionPerDensity));
  program->SetUniformf("cloudAlbedo", static_cast<float>(this->Albedo));
  // (The ray march has no shadow surface; its sampler names a 2-D unit still.)
  program->SetUniformi("shadowSurface",
    (in.Shadow->GetTextureUnit() >= 0 ? in.Shadow.GetPointer() : in.SceneDepth.GetPointer())
      ->GetTextureUnit());
  program->SetUniform3f("shadowOrigin", frame.Shadow.Origin.data());
  program->SetUniform3f("shadowU", frame.Shadow.U.data());
  program->SetUniform3f("shadowW", frame.Shadow.W.data());
  const float extent[2] = { static_cast<float>(frame.Shadow.Width),
    static_cast<float>(frame.Shadow.Height) };
  program->SetUniform2f("shadowExtent", extent);
  program->SetUniformi("atmosphereOn", frame.Atmosphere ? 1 : 0);
  // Unused without atmosphere, but a sampler2D must not share a unit with the 3-D
  // density texture.
  program->SetUniformi("atmosphereTable",
    frame.Atmosphere ? in.AtmosphereTexture->GetTextureUnit() : in.SceneDepth->GetTextureUnit());
  const float zRange[2] = { static_cast<float>(in.Table.ZMin), static_cast<float>(in.Table.ZMax) };
  program->SetUniform2f("atmosphereZRange", zRange);
  program->SetUniform3f("rayleighExtinction0", in.Table.RayleighExtinctionSeaLevel.data());
  program->SetUniformf("mieExtinction0", static_cast<float>(in.Table.MieExtinctionSeaLevel));
  program->SetUniformf(
    "rayleighScaleHeightMetres", static_cast<float>(in.Table.Air.RayleighScaleHeightMetres));
  program->SetUniformf(
    "mieScaleHeightMetres", static_cast<float>(in.Table.Air.MieScaleHeightMetres));
  program->SetUniformf("sceneAltitudeMetres", static_cast<float>(air.SceneAltitudeMetres));
  program->SetUniformf("earthRadiusMetres", static_cast<float>(air.EarthRadiusMetres));
  program->SetUniformf("topRadiusMetres", static_cast<float>(air.TopRadiusMetres));
  program->SetUniform3f("sunIrradianceTop", in.Table.SunIrradianceTop.data());
  program->SetUniformi("groundOn", frame.Ground ? 1 : 0);
  program->SetUniformf("groundZ", static_cast<float>(frame.Settings.GroundHeight));
  program->SetUniformf("groundAlbedo", static_cast<float>(frame.Settings.GroundAlbedo));
  program->SetUniformi("sceneDepth", in.SceneDepth->GetTextureUnit());
  program->SetUniformi("overSky", frame.Settings.OverSky ? 1 : 0);
  program->SetUniformi("sliceJitter", this->SliceJitter ? 1 : 0);
  program->SetUniformf(
    "firstSliceOffset", static_cast<float>(frame.FirstPlaneOffset - 0.5 * frame.Planes.Spacing));
  const bool sunDepth = this->UsesRayMarching() && in.SunDepthTexture->GetHandle();
  program->SetUniformi("sunDepthVolumeOn", sunDepth ? 1 : 0);
  // Unused when off, but the sampler must name a 3-D texture unit.
  program->SetUniformi("sunDepthVolume",
    (sunDepth ? in.SunDepthTexture.GetPointer() : in.Density.GetTexture())->GetTextureUnit());
  program->SetUniformi("externalShadowOn", frame.ExternalShadow ? 1 : 0);
  // Unused when off, but the sampler must name a 2-D texture unit.
  program->SetUniformi("externalShadow",
    (frame.ExternalShadow ? in.ExternalShadowTexture.GetPointer() : in.SceneDepth.GetPointer())
      ->GetTextureUnit());
  const nimbus::ShadowFrame& external = in.ExternalMap.Frame;
  program->SetUniform3f("externalOrigin", external.Origin.data());
  program->SetUniform3f("externalU", external.U.data());
  program->SetUniform3f("externalW", external.W.data());
  const float externalExtent[2] = { static_cast<float>(external.Width),
    static_cast<float>(external.Height) };
  program->SetUniform2f("externalExtent", externalExtent);
}

//------------------------------------------------------------------------------
// The textures every pass reads (density, scene depth, atmosphere); the passes
// neither test nor write depth.
void vtkNimbusCloudVolumeMapper::BeginPasses(const FrameState& frame)
{
  Internals& in = *this->Internal;
  in.Density.GetTexture()->Activate();
  in.SceneDepth->Activate();
  if (frame.ExternalShadow)
  {
    in.ExternalShadowTexture->Activate();
  }
  if (frame.Atmosphere)
  {
    in.AtmosphereTexture->Activate();
  }
  if (frame.ScatteringTexture)
  {
    for (int c = 0; c < 3; ++c)
    {
      in.Scattering.GetTexture(c)->Activate();
    }
  }
  if (frame.LightningTexture)
  {
    for (int c = 0; c < 3; ++c)
    {
      in.Lightning.GetTexture(c)->Activate();
    }
  }
  if (frame.LightningFirstScattering)
  {
    in.Lightning.GetFirstScatteringTexture()->Activate();
    in.Lightning.GetBeamCosineTexture()->Activate();
  }
  if (frame.EmissionTexture)
  {
    in.Emission.GetTexture()->Activate();
  }
  if (this->UsesRayMarching())
  {
    in.SunDepthTexture->Activate();
    in.BlockTexture->Activate();
  }
  if (frame.LightShadows)
  {
    in.ShadowMaps.GetTexture()->Activate();
  }
  if (frame.LightMap)
  {
    in.LightMapTexture->Activate();
  }
  frame.State->vtkglDisable(GL_DEPTH_TEST);
  frame.State->vtkglDepthMask(GL_FALSE);
}

void vtkNimbusCloudVolumeMapper::EndPasses(const FrameState& frame)
{
  Internals& in = *this->Internal;
  for (vtkTextureObject* t : { in.Density.GetTexture(), in.SceneDepth.GetPointer(),
         in.RayEnds.GetPointer(), in.IntervalPhase.GetPointer(), in.Shadow.GetPointer(),
         in.Accumulation.GetPointer(), in.SceneColor.GetPointer() })
  {
    t->Deactivate();
  }
  if (frame.Settings.OverSky)
  {
    in.ClearAccumulation->Deactivate();
  }
  if (frame.ExternalShadow)
  {
    in.ExternalShadowTexture->Deactivate();
  }
  if (frame.Atmosphere)
  {
    in.AtmosphereTexture->Deactivate();
  }
  if (frame.ScatteringTexture)
  {
    for (int c = 0; c < 3; ++c)
    {
      in.Scattering.GetTexture(c)->Deactivate();
    }
  }
  if (frame.LightningTexture)
  {
    for (int c = 0; c < 3; ++c)
    {
      in.Lightning.GetTexture(c)->Deactivate();
    }
  }
  if (frame.LightningFirstScattering)
  {
    in.Lightning.GetFirstScatteringTexture()->Deactivate();
    in.Lightning.GetBeamCosineTexture()->Deactivate();
  }
  if (frame.EmissionTexture)
  {
    in.Emission.GetTexture()->Deactivate();
  }
  for (vtkTextureObject* t : { in.SunDepthTexture.GetPointer(), in.BlockTexture.GetPointer(),
         in.FroxelScattering.GetPointer(), in.FroxelTransmittance.GetPointer(),
         in.ClearAccumulation.GetPointer(), in.LightningAccumulation.GetPointer() })
  {
    if (t->GetContext())
    {
      t->Deactivate();
    }
  }
}

namespace
{
// World -> the multiple-scattering textures' coordinates: the density texture's times
// the solve's TextureScale, or (`coarse`: the whole cloud's coarse copy, in world
// coordinates) its point grid's, texel centres at (index + 0.5) / dimensions.
std::array<float, 16> WorldToScatteringTexture(vtkImageData* coarse, const int textureDims[3],
  const std::array<float, 16>& worldToTexture, const std::array<double, 3>& textureScale)
{
  vtkNew<vtkMatrix4x4> worldToScattering;
  if (coarse)
  {
    const double* origin = coarse->GetOrigin();
    const double* spacing = coarse->GetSpacing();
    for (int a = 0; a < 3; ++a)
    {
      const double d = std::max(textureDims[a], 1);
      worldToScattering->SetElement(a, a, 1.0 / (spacing[a] * d));
      worldToScattering->SetElement(a, 3, (-origin[a] / spacing[a] + 0.5) / d);
    }
  }
  else
  {
    for (int r = 0; r < 4; ++r)
    {
      for (int c = 0; c < 4; ++c)
      {
        worldToScattering->SetElement(r, c, worldToTexture[4 * c + r]);
      }
    }
  }
  for (int r = 0; r < 3; ++r)
  {
    for (int c = 0; c < 4; ++c)
    {
      worldToScattering->SetElement(r, c, worldToScattering->GetElement(r, c) * textureScale[r]);
    }
  }
  return ColumnMajor(worldToScattering);
}
} // namespace

//------------------------------------------------------------------------------
// Multiple scattering (003, 004): the solver's term, re-solved only when the
// density, the sun, the air, the ground, the optics or the method's knobs change.
void vtkNimbusCloudVolumeMapper::UpdateMultipleScattering(FrameState& frame)
{
  Internals& in = *this->Internal;
  const auto start = std::chrono::steady_clock::now();
  const FrameSettings& settings = frame.Settings;
  const int method = this->Unlit ? MultipleScatteringNone : this->MultipleScatteringMethod;
  frame.Octaves = method == MultipleScatteringOctaves ? this->Octaves : 1;
  frame.ScatteringTexture = false;
  frame.ForwardPeakFraction = 0.0;
  if (method == MultipleScatteringNone ||
    (method == MultipleScatteringOctaves &&
      !(this->SkyLight && (frame.Atmosphere || frame.Ground))))
  {
    return; // nothing to precompute (octaves alone live in the shader)
  }
  nimbus::MultipleScatteringTexture::Request request;
  nimbus::MultipleScatteringOptions& options = request.Options;
  options.Method = static_cast<nimbus::MultipleScatteringMethod>(method);
  options.Orders = method == MultipleScatteringReferencePatterns ? this->PatternOrders
                                                                 : this->MultipleScatteringOrders;
  options.NumberOfDirections = this->MultipleScatteringDirections;
  options.SkyLight = this->SkyLight;
  options.PatternRadius = this->PatternRadius;
  options.PatternContribution = this->PatternContribution;
  options.PatternSelection = this->PatternSelection;
  options.Threads = vtkSMPTools::GetEstimatedNumberOfThreads();
  request.Optics = { this->Albedo, nimbus::PhaseFunctionKind::CornetteShanks, this->CloudG };
  request.ExtinctionPerDensity = this->ExtinctionPerDensity;
  // One piece of a distributed cloud (under MPI): the solve runs on the whole cloud's
  // coarse copy, the same on every rank, so that light crosses the pieces' faces as in
  // one renderer (each piece's own solve would lose it there: dark seams, measured).
  const bool wholeCloud = frame.ExternalShadow && this->PieceCompositing;
  vtkImageData* solveImage = frame.Image;
  vtkDataArray* solveScalars = frame.Scalars;
  bool solveCellData = frame.CellData;
  vtkNew<vtkMatrix4x4> identity;
  vtkMatrix4x4* solveToWorld = frame.DataToWorld;
  int textureDims[3];
  int textureFactors[3];
  in.Density.GetDimensions(textureDims);
  in.Density.GetFactors(textureFactors);
  if (wholeCloud)
  {
    solveImage = in.ExternalDensity;
    solveScalars = solveImage->GetPointData()->GetScalars();
    solveCellData = false;
    solveToWorld = identity; // the coarse grid is in world coordinates
    solveImage->GetDimensions(textureDims);
    textureFactors[0] = textureFactors[1] = textureFactors[2] = 1;
  }
  const int longest = std::max({ textureDims[0], textureDims[1], textureDims[2], 1 });
  request.Downsampling = this->MultipleScatteringDownsampling > 0
    ? this->MultipleScatteringDownsampling
    : (longest + kAutomaticScatteringGridSide - 1) / kAutomaticScatteringGridSide;
  for (int k = 0; k < 3; ++k)
  {
    request.TextureDimensions[k] = std::max(textureDims[k], 1);
    request.TextureFactors[k] = textureFactors[k];
  }
  request.MetresPerUnit = settings.MetresPerUnit;
  request.BudgetBytes = this->MultipleScatteringMemoryBudgetMiB > 0.0
    ? this->MultipleScatteringMemoryBudgetMiB * 1024.0 * 1024.0
    : static_cast<double>(nimbus::DefaultMemoryBudgetBytes());

  // The light: the sun as the slices see it (the atmosphere table's E_sun(z)), and
  // the sky and the ground as seen from the cloud's middle (004 §3.5).
  nimbus::CloudLighting& lighting = request.Lighting;
  lighting.Sun.ToLight = frame.ToSun;
  const nimbus::AtmosphereTable& table = in.Table;
  if (frame.Atmosphere && table.HasAtmosphere)
  {
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
  else
  {
    lighting.Sun.ConstantIrradiance = table.SunIrradianceTop;
  }
  double zMiddle = 0.0;
  for (const auto& corner : frame.Corners)
  {
    zMiddle += corner[2] / static_cast<double>(frame.Corners.size());
  }
  if (wholeCloud)
  {
    const double* sb = this->SlicingBounds;
    const double low[3] = { sb[0], sb[2], sb[4] }, high[3] = { sb[1], sb[3], sb[5] };
    zMiddle = 0.5 * (ToUp(settings.Up, low)[2] + ToUp(settings.Up, high)[2]);
  }
  if (this->SkyLight && frame.Atmosphere)
  {
    const nimbus::SkyViewLut* view = this->CloudSkyView(frame, zMiddle * settings.MetresPerUnit);
    if (!view)
    {
      return;
    }
    // The sky's radiance is relative to its own sun; the mapper's sun may be brighter.
    const nimbus::SkyModel& model = *in.FrameSky.CurrentModel();
    const auto skySun = model.GetSpectrum().ToLinearSrgb(model.GetSunIrradiance());
    nimbus::Rgb scale{ { 0, 0, 0 } };
    for (int c = 0; c < 3; ++c)
    {
      scale[c] = skySun[c] > 0.0 ? table.SunIrradianceTop[c] / skySun[c] : 0.0;
    }
    const double azimuth = settings.Sun.AzimuthDegrees;
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
  else if (this->SkyLight && frame.Ground)
  {
    // No air: the ground alone, lit by the sun (Lambertian, albedo / pi).
    const double cosSun = std::max(frame.ToSun[2], 0.0);
    nimbus::Rgb ground{ { 0, 0, 0 } };
    for (int c = 0; c < 3; ++c)
    {
      ground[c] = settings.GroundAlbedo / nimbus::kPi * cosSun * table.SunIrradianceTop[c];
    }
    lighting.Sky = [ground](const nimbus::Vector3& w) {
      return w[2] < 0.0 ? ground : nimbus::Rgb{ { 0, 0, 0 } };
    };
  }

  const nimbus::SceneAtmosphere& air = settings.Air;
  request.Key = { static_cast<double>(method), static_cast<double>(options.Orders),
    static_cast<double>(options.NumberOfDirections), options.SkyLight ? 1.0 : 0.0,
    static_cast<double>(options.Threads), this->Albedo, this->CloudG, this->ExtinctionPerDensity,
    static_cast<double>(request.Downsampling), request.MetresPerUnit, request.BudgetBytes,
    // Not the sun's illuminance itself: the answer is linear in it, so a new
    // illuminance only rescales the texture (ScatteringScale), without a solve.
    frame.ToSun[0], frame.ToSun[1], frame.ToSun[2], settings.Sun.Illuminance > 0.0 ? 1.0 : 0.0,
    settings.Sun.TemperatureKelvin, frame.Atmosphere ? 1.0 : 0.0, frame.Ground ? 1.0 : 0.0,
    air.SceneAltitudeMetres, air.RayleighScatteringPerMetre, air.MieScatteringPerMetre, air.MieG,
    settings.GroundAlbedo, settings.GroundHeight };
  this->AddViewLightsToSolve(frame, zMiddle, request.Lighting, request.Key);
  if (method == MultipleScatteringDiscreteDirections && !wholeCloud)
  {
    request.EmissionTemperature = this->EmissionForSolve(frame, request.Key);
    request.EmissionRadiancePerMetre = this->EmissionRadiancePerMetre;
    request.EmissionReferenceKelvin = this->EmissionReferenceTemperatureKelvin;
    // Its first scattering on a grid twice as fine (docs/smoke.md: the grid's effect).
    request.EmissionFirstScatteringDownsampling = std::max(1, request.Downsampling / 2);
  }
  if (method == MultipleScatteringReferencePatterns)
  {
    request.Key.insert(request.Key.end(),
      { static_cast<double>(options.PatternRadius), options.PatternContribution,
        options.PatternSelection });
  }
  const double solvesBefore = in.Scattering.GetNumberOfSolves();
  std::string error;
  // The density's identity: the uploads of the piece, or (negative, never equal to
  // those) the coarse copy's modification time.
  const double densityVersion = wholeCloud ? -1.0 - static_cast<double>(in.ExternalGridTime)
                                           : static_cast<double>(in.Density.GetNumberOfUploads());
  const bool ok = in.Scattering.Update(
    frame.Window, solveImage, solveScalars, solveCellData, solveToWorld, densityVersion, request,
    [this](double fraction) { this->UpdateProgress(fraction); }, error);
  if (!ok)
  {
    if (error != in.LastScatteringError)
    {
      vtkErrorMacro(<< error);
      in.LastScatteringError = error;
    }
    return;
  }
  in.LastScatteringError.clear();
  if (in.Scattering.GetNumberOfSolves() != solvesBefore)
  {
    // The whole precompute: the sky (when rebuilt), the grid, the solve, the upload.
    in.LastPrecomputeSeconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    in.SolvedIlluminance = settings.Sun.Illuminance;
    vtkDebugMacro(<< "multiple scattering: " << in.LastPrecomputeSeconds << " s");
  }
  frame.ScatteringTexture = in.Scattering.HasTexture();
  frame.WorldToScattering = WorldToScatteringTexture(wholeCloud ? solveImage : nullptr, textureDims,
    frame.WorldToTexture, in.Scattering.GetTextureScale());
  frame.ScatteringScale =
    in.SolvedIlluminance > 0.0 ? settings.Sun.Illuminance / in.SolvedIlluminance : 1.0;
  frame.ForwardPeakFraction = in.Scattering.GetForwardPeakFraction();
}

//------------------------------------------------------------------------------
// The glow as a source of the discrete-direction solve (CloudLighting::Emission): the
// temperature array when Temperature Emission is on (the same conditions as
// UpdateEmission; its errors are reported there), null otherwise. The key gains what
// the emission depends on besides the density: the array and its modification time,
// E and T_ref, and the sun's illuminance itself: the shader scales the solve's J by
// the sun's illuminance now / at the solve (scatteringScale), right for the sun's
// light but not for the glow's, so with a glow a new illuminance solves again (the
// scale is then 1).
vtkDataArray* vtkNimbusCloudVolumeMapper::EmissionForSolve(
  const FrameState& frame, std::vector<double>& key) const
{
  vtkDataArray* temperature = nullptr;
  if (!this->Unlit && this->TemperatureEmission && this->EmissionRadiancePerMetre > 0.0 &&
    frame.Image && frame.Scalars)
  {
    const char* name = this->EmissionTemperatureArray.c_str();
    temperature = frame.CellData ? frame.Image->GetCellData()->GetArray(name)
                                 : frame.Image->GetPointData()->GetArray(name);
    if (temperature &&
      (temperature->GetNumberOfComponents() != 1 || frame.Scalars->GetNumberOfComponents() != 1 ||
        temperature->GetNumberOfTuples() != frame.Scalars->GetNumberOfTuples()))
    {
      temperature = nullptr;
    }
  }
  if (!temperature)
  {
    key.push_back(0.0);
    return nullptr;
  }
  key.insert(key.end(),
    { 1.0, static_cast<double>(reinterpret_cast<std::uintptr_t>(temperature)),
      static_cast<double>(temperature->GetMTime()), this->EmissionRadiancePerMetre,
      this->EmissionReferenceTemperatureKelvin, frame.Settings.Sun.Illuminance });
  return temperature;
}

//------------------------------------------------------------------------------
// Lightning: the field vtkNimbusLightningIllumination computed, uploaded
// when it changes (every time step of a flash).
void vtkNimbusCloudVolumeMapper::UpdateLightning(FrameState& frame)
{
  Internals& in = *this->Internal;
  frame.LightningTexture = false;
  frame.LightningFirstScattering = false;
  frame.LightningDeltaM = false;
  if (this->Unlit)
  {
    return;
  }
  in.Lightning.SetPreferReducedFirstScattering(this->LightningDeltaMView);
  int textureDims[3], textureFactors[3];
  in.Density.GetDimensions(textureDims);
  in.Density.GetFactors(textureFactors);
  std::string error;
  if (!in.Lightning.Update(frame.Window, frame.Image, frame.CellData,
        { { std::max(textureDims[0], 1), std::max(textureDims[1], 1),
          std::max(textureDims[2], 1) } },
        { { textureFactors[0], textureFactors[1], textureFactors[2] } }, error))
  {
    if (error != in.LastLightningError)
    {
      vtkErrorMacro(<< error);
      in.LastLightningError = error;
    }
    return;
  }
  frame.LightningTexture = in.Lightning.HasTexture();
  frame.LightningFirstScattering = in.Lightning.HasFirstScattering();
  frame.LightningDeltaM = this->LightningDeltaMView && frame.LightningFirstScattering &&
    in.Lightning.IsFirstScatteringReduced();
  if (!frame.LightningTexture && !frame.LightningFirstScattering)
  {
    return;
  }
  // The lightning was solved with the filter's optics; say so once when they are not
  // the mapper's (the picture mixes two clouds).
  const auto& optics = in.Lightning.GetOptics();
  const double mine[4] = { this->ExtinctionPerDensity, this->Albedo, this->CloudG,
    frame.Settings.MetresPerUnit };
  std::string mismatch;
  const char* names[4] = { "ExtinctionPerDensity", "Albedo", "CloudG", "MetresPerUnit" };
  for (int k = 0; k < 4; ++k)
  {
    if (std::isfinite(optics[k]) && std::abs(optics[k] - mine[k]) > 1e-9 * std::abs(mine[k]))
    {
      mismatch += std::string(mismatch.empty() ? "" : ", ") + names[k];
    }
  }
  const std::string warning = mismatch.empty()
    ? std::string()
    : "The lightning was computed with another " + mismatch +
      " than this cloud is drawn with; set the same on the Lightning Illumination filter.";
  if (warning != in.LastLightningError)
  {
    if (!warning.empty())
    {
      vtkWarningMacro(<< warning);
    }
    in.LastLightningError = warning;
  }
}

//------------------------------------------------------------------------------
// Temperature emission (Planck's law): rho B(T) / Y[B(T_ref)] per texel, uploaded when the
// density, the temperature or the reference temperature change.
void vtkNimbusCloudVolumeMapper::UpdateEmission(FrameState& frame)
{
  Internals& in = *this->Internal;
  frame.EmissionTexture = false;
  if (this->Unlit || !this->TemperatureEmission || this->EmissionRadiancePerMetre <= 0.0)
  {
    return;
  }
  int textureDims[3], textureFactors[3];
  in.Density.GetDimensions(textureDims);
  in.Density.GetFactors(textureFactors);
  std::string error;
  if (!in.Emission.Update(frame.Window, frame.Image, frame.Scalars, frame.CellData,
        this->EmissionTemperatureArray, this->EmissionReferenceTemperatureKelvin,
        { { std::max(textureDims[0], 1), std::max(textureDims[1], 1),
          std::max(textureDims[2], 1) } },
        { { std::max(textureFactors[0], 1), std::max(textureFactors[1], 1),
          std::max(textureFactors[2], 1) } },
        error))
  {
    if (error != in.LastEmissionError)
    {
      vtkErrorMacro(<< error);
      in.LastEmissionError = error;
    }
    return;
  }
  in.LastEmissionError.clear();
  frame.EmissionTexture = in.Emission.HasTexture();
}

// The sky seen from the cloud at altitude `cloudAltitude` above the scene [m]: a
// sky model of the frame's air (built when the air or the ground changes) and its
// sky-view table for the sun's elevation. nullptr (after an error) when the air is
// refused.
const nimbus::SkyViewLut* vtkNimbusCloudVolumeMapper::CloudSkyView(
  const FrameState& frame, double cloudAltitude)
{
  Internals& in = *this->Internal;
  const FrameSettings& settings = frame.Settings;
  const nimbus::SceneAtmosphere& air = settings.Air;
  try
  {
    this->FrameSkyModel(frame);
    const double altitude = std::max(0.0, air.SceneAltitudeMetres + cloudAltitude);
    // 64 x (32 + 16): the solver looks up a few dozen directions (the background's
    // 128 x (64 + 32) takes 0.36 s on 2 cores). Rebuilt when the model, the sun's
    // elevation or the altitude changed.
    nimbus::SkyTableCache::ViewSize size;
    size.Width = 64;
    size.AboveRows = 32;
    size.BelowRows = 16;
    return &in.FrameSky.SkyView(0, settings.Sun.ElevationDegrees, altitude, 0.0, size);
  }
  catch (const std::exception& error)
  {
    in.FrameSky.Clear();
    const std::string message = std::string("The sky light on the cloud is off: ") + error.what();
    if (message != in.LastScatteringError)
    {
      vtkErrorMacro(<< message);
      in.LastScatteringError = message;
    }
    return nullptr;
  }
}

std::vector<double> vtkNimbusCloudVolumeMapper::FrameSkyKey(const FrameState& frame)
{
  const FrameSettings& settings = frame.Settings;
  const nimbus::SceneAtmosphere& air = settings.Air;
  return { air.RayleighScatteringPerMetre, air.MieScatteringPerMetre, air.MieG, air.MieAlbedo,
    air.RayleighScaleHeightMetres, air.MieScaleHeightMetres, air.EarthRadiusMetres,
    air.TopRadiusMetres, frame.Ground ? settings.GroundAlbedo : 0.0,
    settings.Sun.TemperatureKelvin };
}

// The sky model of the frame's air, ground albedo and sun temperature (throws for an
// air the model refuses).
const nimbus::SkyModel& vtkNimbusCloudVolumeMapper::FrameSkyModel(const FrameState& frame)
{
  const std::vector<double> key = FrameSkyKey(frame);
  return this->Internal->FrameSky.Model(key,
    [&frame, &key]()
    {
      nimbus::SkyParameters parameters;
      parameters.Atmosphere = frame.Settings.Air;
      parameters.GroundAlbedo = key[8];
      parameters.SunTemperatureKelvin = frame.Settings.Sun.TemperatureKelvin;
      parameters.Wavelengths = 16; // as the atmosphere table's SunAndAir
      return parameters;
    });
}

int vtkNimbusCloudVolumeMapper::GetNumberOfMultipleScatteringSolves() const
{
  return this->Internal->Scattering.GetNumberOfSolves();
}

double vtkNimbusCloudVolumeMapper::GetLastMultipleScatteringSeconds() const
{
  return this->Internal->LastPrecomputeSeconds;
}

double vtkNimbusCloudVolumeMapper::GetLastMultipleScatteringBytes() const
{
  return this->Internal->Scattering.GetLastEstimatedBytes();
}

void vtkNimbusCloudVolumeMapper::GetMultipleScatteringGridDimensions(int dims[3]) const
{
  const auto& d = this->Internal->Scattering.GetGridDimensions();
  std::copy(d.begin(), d.end(), dims);
}

//------------------------------------------------------------------------------
double* vtkNimbusCloudVolumeMapper::GetBounds()
{
  double* bounds = this->Superclass::GetBounds();
  const double* cover = this->ViewCoverBounds;
  if (!(this->PieceCompositing && this->DrawOutsideRegions) || !bounds || bounds[0] > bounds[1] ||
    !(cover[0] <= cover[1] && cover[2] <= cover[3] && cover[4] <= cover[5]))
  {
    return bounds;
  }
  for (int a = 0; a < 3; ++a)
  {
    this->PieceBounds[2 * a] = std::min(bounds[2 * a], cover[2 * a]);
    this->PieceBounds[2 * a + 1] = std::max(bounds[2 * a + 1], cover[2 * a + 1]);
  }
  return this->PieceBounds;
}

void vtkNimbusCloudVolumeMapper::SetViewCoverBounds(const double bounds[6])
{
  std::copy(bounds, bounds + 6, this->ViewCoverBounds);
}

//------------------------------------------------------------------------------
void vtkNimbusCloudVolumeMapper::SetExternalDensity(vtkImageData* coarse)
{
  if (this->Internal->ExternalDensity.GetPointer() != coarse)
  {
    this->Internal->ExternalDensity = coarse;
    this->Modified();
  }
}

vtkImageData* vtkNimbusCloudVolumeMapper::GetExternalDensity()
{
  return this->Internal->ExternalDensity;
}

//------------------------------------------------------------------------------
// The other pieces' shadow (ExternalShadow.h): the coarse whole density
// converted when it changes, its map rebuilt when the sun, the piece, the optics or
// the grid change (not with the camera), uploaded as a (Beyond, Whole) texture.
void vtkNimbusCloudVolumeMapper::UpdateExternalShadow(FrameState& frame)
{
  Internals& in = *this->Internal;
  vtkImageData* coarse = in.ExternalDensity;
  frame.ExternalShadow = false;
  if (!coarse || this->Unlit)
  {
    return;
  }
  if (coarse->GetMTime() != in.ExternalGridTime)
  {
    in.ExternalGridTime = coarse->GetMTime();
    in.ExternalGrid = nimbus::CoarseDensityGrid();
    vtkDataArray* values = coarse->GetPointData()->GetScalars();
    int dims[3];
    coarse->GetDimensions(dims);
    if (values && values->GetNumberOfComponents() == 1 &&
      values->GetNumberOfTuples() == static_cast<vtkIdType>(dims[0]) * dims[1] * dims[2])
    {
      const double* origin = coarse->GetOrigin();
      const double* spacing = coarse->GetSpacing();
      for (int a = 0; a < 3; ++a)
      {
        in.ExternalGrid.Origin[a] = origin[a];
        in.ExternalGrid.Spacing[a] = spacing[a];
        in.ExternalGrid.Dimensions[a] = dims[a];
      }
      in.ExternalGrid.Values.resize(static_cast<std::size_t>(values->GetNumberOfTuples()));
      for (vtkIdType i = 0; i < values->GetNumberOfTuples(); ++i)
      {
        const double v = values->GetComponent(i, 0);
        in.ExternalGrid.Values[static_cast<std::size_t>(i)] =
          std::isfinite(v) ? static_cast<float>(std::max(v, 0.0)) : 0.0f;
      }
    }
    in.ExternalMapKey.clear();
  }
  if (!in.ExternalGrid.IsValid())
  {
    const std::string message = "The external density (the other pieces' coarse density) "
                                "has no single-component point scalars on its lattice: the "
                                "other pieces cast no shadow on this one.";
    if (message != in.ExternalGridError)
    {
      vtkWarningMacro(<< message);
      in.ExternalGridError = message;
    }
    return;
  }
  in.ExternalGridError.clear();
  // The piece's box (world) from its corners.
  std::array<double, 6> piece = { { VTK_DOUBLE_MAX, VTK_DOUBLE_MIN, VTK_DOUBLE_MAX, VTK_DOUBLE_MIN,
    VTK_DOUBLE_MAX, VTK_DOUBLE_MIN } };
  for (const auto& corner : frame.Corners)
  {
    for (int a = 0; a < 3; ++a)
    {
      piece[2 * a] = std::min(piece[2 * a], corner[a]);
      piece[2 * a + 1] = std::max(piece[2 * a + 1], corner[a]);
    }
  }
  // About two texels per coarse cell across the footprint, within [64, 512].
  const int largest = std::max({ in.ExternalGrid.Dimensions[0], in.ExternalGrid.Dimensions[1],
    in.ExternalGrid.Dimensions[2] });
  const int size = std::min(512, std::max(64, 2 * largest));
  std::vector<double> key(piece.begin(), piece.end());
  key.insert(key.end(),
    { frame.ToSun[0], frame.ToSun[1], frame.ToSun[2], this->ExtinctionPerDensity,
      frame.Settings.MetresPerUnit, static_cast<double>(size),
      static_cast<double>(in.ExternalGridTime) });
  if (key != in.ExternalMapKey)
  {
    in.ExternalMap = nimbus::ComputeExternalShadowMap(in.ExternalGrid, piece, frame.ToSun,
      this->ExtinctionPerDensity, frame.Settings.MetresPerUnit, size);
    in.ExternalMapKey = key;
    ++in.ExternalMapBuilds;
    ResetTexture(in.ExternalShadowTexture, frame.Window, true);
    in.ExternalShadowTexture->Create2DFromRaw(static_cast<unsigned int>(size),
      static_cast<unsigned int>(size), 2, VTK_FLOAT,
      const_cast<float*>(in.ExternalMap.Depths.data()));
  }
  frame.ExternalShadow = in.ExternalMap.Size > 0;
}

//------------------------------------------------------------------------------
// The shadow surface (000 Eq. 10), cleared to optical depth 0.
void vtkNimbusCloudVolumeMapper::ClearShadowSurface(const FrameState& frame)
{
  Internals& in = *this->Internal;
  const int size = frame.Level.ShadowSurfaceSize;
  in.Shadow->SetContext(frame.Window);
  if (static_cast<int>(in.Shadow->GetWidth()) != size || !in.Shadow->GetHandle())
  {
    ResetTexture(in.Shadow, frame.Window, true);
    in.Shadow->Allocate2D(size, size, 1, VTK_FLOAT);
  }
  DrawInto(in.ShadowFramebuffer, in.Shadow, frame.Window);
  frame.State->vtkglViewport(0, 0, size, size);
  frame.State->vtkglClearColor(0.0f, 0.0f, 0.0f, 0.0f);
  frame.State->vtkglClear(GL_COLOR_BUFFER_BIT);
}

//------------------------------------------------------------------------------
// The sampling-interval and Mie-phase texture (000 §4.4), rebuilt when the camera,
// the sun or the phase functions changed.
void vtkNimbusCloudVolumeMapper::RenderIntervalPhase(const FrameState& frame)
{
  Internals& in = *this->Internal;
  const nimbus::Vector3& toSun = frame.ToSun;
  const nimbus::Vector3& normal = frame.Axis.Normal;
  const double mieG = frame.Settings.Air.MieG;
  std::vector<double> key(frame.InverseViewProjection.begin(), frame.InverseViewProjection.end());
  key.insert(key.end(),
    { static_cast<double>(frame.Level.Width), static_cast<double>(frame.Level.Height), toSun[0],
      toSun[1], toSun[2], normal[0], normal[1], normal[2], this->CloudG, mieG,
      this->MultipleScattering });
  if (key != in.IntervalPhaseKey || !in.IntervalPhase->GetHandle())
  {
    EnsureTexture2D(
      in.IntervalPhase, frame.Window, frame.Level.Width, frame.Level.Height, 4, false);
    DrawInto(in.IntervalPhaseFramebuffer, in.IntervalPhase, frame.Window);
    frame.State->vtkglViewport(0, 0, frame.Level.Width, frame.Level.Height);
    frame.State->vtkglDisable(GL_BLEND);
    vtkShaderProgram* program = in.Ready(in.IntervalPhasePass, svsIntervalPhaseFS);
    this->SetCommonUniforms(program, frame);
    program->SetUniformf("cloudG", static_cast<float>(this->CloudG));
    program->SetUniformf("mieG", static_cast<float>(mieG));
    program->SetUniformf("multipleScattering", static_cast<float>(this->MultipleScattering));
    in.IntervalPhasePass->Render();
    ++in.PassesLastRender;
    ++in.IntervalPhaseBuilds;
    in.IntervalPhaseKey = key;
  }
  in.IntervalPhase->Activate();
  in.Shadow->Activate();
}

//------------------------------------------------------------------------------
// Where each view ray ends this frame (opaque depth, ground, top of the atmosphere),
// and the air's optical lengths to the box entry (BoxEntryOpticalLengths).
void vtkNimbusCloudVolumeMapper::RenderRayEnds(const FrameState& frame)
{
  Internals& in = *this->Internal;
  EnsureTexture2D(in.RayEnds, frame.Window, frame.Level.Width, frame.Level.Height, 4, false);
  DrawInto(in.RayEndsFramebuffer, in.RayEnds, frame.Window);
  frame.State->vtkglViewport(0, 0, frame.Level.Width, frame.Level.Height);
  frame.State->vtkglDisable(GL_BLEND);
  vtkShaderProgram* program = in.Ready(in.RayEndsPass, svsRayEndsFS);
  this->SetCommonUniforms(program, frame);
  program->SetUniformi("steps", this->AtmosphereSteps); // as the march in front of the box
  in.RayEndsPass->Render();
  ++in.PassesLastRender;
  in.RayEnds->Activate();
}

//------------------------------------------------------------------------------
// A float RGBA target of this frame's image size (the accumulation, the cloud-free
// one): linear where the composite scales a smaller image (a lower quality level) to
// the viewport; nearest at full size, where the composite's texture coordinates,
// interpolated across a viewport at an offset, can miss texel centres by a rounding
// error that linear filtering would turn into a neighbour's share.
void vtkNimbusCloudVolumeMapper::EnsureImageTarget(
  vtkTextureObject* target, const FrameState& frame)
{
  const int filter = frame.Level.Width == frame.Width && frame.Level.Height == frame.Height
    ? vtkTextureObject::Nearest
    : vtkTextureObject::Linear;
  EnsureTexture2D(target, frame.Window, frame.Level.Width, frame.Level.Height, 4, false);
  target->SetMinificationFilter(filter);
  target->SetMagnificationFilter(filter);
}

//------------------------------------------------------------------------------
// The accumulation target (S, cloud transmittance), cleared to (0, 0, 0, 1); over a
// sky a second target, S_clear, summed by the same blend (its alpha stays 1).
void vtkNimbusCloudVolumeMapper::ClearAccumulation(const FrameState& frame)
{
  Internals& in = *this->Internal;
  this->EnsureImageTarget(in.Accumulation, frame);
  DrawInto(in.AccumulationFramebuffer, in.Accumulation, frame.Window);
  in.AccumulationFramebuffer->RemoveColorAttachment(1);
  if (frame.Settings.OverSky)
  {
    this->EnsureImageTarget(in.ClearAccumulation, frame);
    in.AccumulationFramebuffer->AddColorAttachment(1, in.ClearAccumulation);
    in.AccumulationFramebuffer->ActivateDrawBuffers(2);
  }
  // The lightning's delta-M view: a third target, cleared with the others, drawn by the
  // slices only (UseLightningTarget).
  in.AccumulationFramebuffer->RemoveColorAttachment(2);
  in.LightningAccumulationOn = frame.LightningDeltaM;
  if (frame.LightningDeltaM)
  {
    this->EnsureImageTarget(in.LightningAccumulation, frame);
    in.AccumulationFramebuffer->AddColorAttachment(2, in.LightningAccumulation);
  }
  UseLightningTarget(frame, true);
  frame.State->vtkglViewport(0, 0, frame.Level.Width, frame.Level.Height);
  frame.State->vtkglClearColor(0.0f, 0.0f, 0.0f, 1.0f);
  frame.State->vtkglClear(GL_COLOR_BUFFER_BIT);
  UseLightningTarget(frame, false);
}

//------------------------------------------------------------------------------
// The accumulation framebuffer's draw buffers with the lightning's third target (on) or
// as ClearAccumulation left them (off), set directly: this VTK's state cache can leave a
// draw buffer at GL_NONE (RenderCloudMarch). Nothing without the delta-M view.
void vtkNimbusCloudVolumeMapper::UseLightningTarget(const FrameState& frame, bool on)
{
  if (!frame.LightningDeltaM)
  {
    return;
  }
  const GLenum second = frame.Settings.OverSky ? GL_COLOR_ATTACHMENT1 : GL_NONE;
  const GLenum buffers[3] = { GL_COLOR_ATTACHMENT0, second, GL_COLOR_ATTACHMENT2 };
  glDrawBuffers(on ? 3 : (frame.Settings.OverSky ? 2 : 1), buffers);
}

//------------------------------------------------------------------------------
// The atmosphere and the ground outside the cloud box (only when either is drawn),
// after the slices, through the finished shadow surface (the shafts): the part of
// each ray in front of the box added as it is, the part behind it (behindBox)
// multiplied by the cloud transmittance the slices left in the alpha, whatever
// their order. The ground, where a ray ends on it, zeroes that alpha (not over a
// sky).
void vtkNimbusCloudVolumeMapper::RenderOutsideRegion(const FrameState& frame, bool behindBox)
{
  // A piece whose image goes over the one that draws the air (under MPI): only the
  // air in front of its box, weighted by its opacity 1 - T_i (and none in its box).
  // The bottom image has all the air in front of its own box, which compositing
  // multiplies by the transmittances of the pieces in front; each piece adds back
  // what its cloud took of the air in front of it: sum_i prod_{j<i} T_j (1 - T_i)
  // A_i + prod_i T_i A = A_1 + T_1 (A_2 - A_1) + ..., the air in front of each piece
  // attenuated by the pieces in front of it. The air inside a piece's box counts as
  // behind its cloud (measured, docs/parallel.md).
  const bool overAir = this->PieceCompositing && !this->DrawOutsideRegions;
  if (!frame.OutsideRegions || (overAir && behindBox))
  {
    return;
  }
  Internals& in = *this->Internal;
  in.AccumulationFramebuffer->Bind(GL_FRAMEBUFFER);
  frame.State->vtkglViewport(0, 0, frame.Level.Width, frame.Level.Height);
  frame.State->vtkglEnable(GL_BLEND);
  if (overAir)
  {
    frame.State->vtkglBlendFuncSeparate(GL_ONE_MINUS_DST_ALPHA, GL_ONE, GL_ZERO, GL_ONE);
  }
  else
  {
    frame.State->vtkglBlendFuncSeparate(
      behindBox ? GL_DST_ALPHA : GL_ONE, GL_ONE, GL_ZERO, GL_SRC_ALPHA);
  }
  vtkShaderProgram* program = in.Ready(in.MarchPass, svsMarchFS);
  this->SetCommonUniforms(program, frame);
  program->SetUniformi("intervalPhase", in.IntervalPhase->GetTextureUnit());
  program->SetUniformi("rayEnds", in.RayEnds->GetTextureUnit());
  program->SetUniformi("segment", behindBox ? 1 : 0);
  program->SetUniformi("shaftsOn", this->Shafts ? 1 : 0);
  program->SetUniformi("steps", this->AtmosphereSteps);
  program->SetUniformf("sliceSpacing", static_cast<float>(frame.Planes.Spacing));

  program->SetUniformi("maxShadowSteps", std::min(frame.Level.Slices, 2 * this->AtmosphereSteps));
  // Only rays through the box have a part behind it: the box's pixels.
  int scissor[4];
  const bool scissored = behindBox &&
    nimbus::ScreenRectangle(
      frame.Corners, frame.WorldToNdc->GetData(), frame.Level.Width, frame.Level.Height, scissor);
  if (scissored)
  {
    frame.State->vtkglEnable(GL_SCISSOR_TEST);
    frame.State->vtkglScissor(scissor[0], scissor[1], scissor[2], scissor[3]);
  }
  in.MarchPass->Render();
  if (scissored)
  {
    frame.State->vtkglDisable(GL_SCISSOR_TEST);
  }
  ++in.PassesLastRender;
}

//------------------------------------------------------------------------------
// The uniforms of cloudLight.glsl: multiple scattering, lightning, emission, octaves.
void vtkNimbusCloudVolumeMapper::SetCloudLightUniforms(
  vtkShaderProgram* program, const FrameState& frame)
{
  Internals& in = *this->Internal;
  // Multiple scattering. Without a texture the samplers name the
  // density's unit (a 3-D texture, never read), so no unit has two sampler types.
  program->SetUniformf("cloudG", static_cast<float>(this->CloudG));
  program->SetUniformi("scatteringTextureOn", frame.ScatteringTexture ? 1 : 0);
  program->SetUniformf("scatteringScale", static_cast<float>(frame.ScatteringScale));
  const char* scatteringSamplers[3] = { "scatteringRed", "scatteringGreen", "scatteringBlue" };
  for (int c = 0; c < 3; ++c)
  {
    program->SetUniformi(scatteringSamplers[c],
      (frame.ScatteringTexture ? in.Scattering.GetTexture(c) : in.Density.GetTexture())
        ->GetTextureUnit());
  }
  program->SetUniformMatrix4x4(
    "worldToScattering", const_cast<float*>(frame.WorldToScattering.data()));
  // Lightning, the same way.
  program->SetUniformi("lightningTextureOn", frame.LightningTexture ? 1 : 0);
  const char* lightningSamplers[3] = { "lightningRed", "lightningGreen", "lightningBlue" };
  for (int c = 0; c < 3; ++c)
  {
    program->SetUniformi(lightningSamplers[c],
      (frame.LightningTexture ? in.Lightning.GetTexture(c) : in.Density.GetTexture())
        ->GetTextureUnit());
  }
  const auto& lightningScale = in.Lightning.GetTextureScale();
  const float lightningTextureScale[3] = { static_cast<float>(lightningScale[0]),
    static_cast<float>(lightningScale[1]), static_cast<float>(lightningScale[2]) };
  program->SetUniform3f("lightningTextureScale", lightningTextureScale);
  program->SetUniformi("lightningFirstOn", frame.LightningFirstScattering ? 1 : 0);
  program->SetUniformi("lightningFirst",
    (frame.LightningFirstScattering ? in.Lightning.GetFirstScatteringTexture()
                                    : in.Density.GetTexture())
      ->GetTextureUnit());
  program->SetUniformi("lightningBeamCosine",
    (frame.LightningFirstScattering ? in.Lightning.GetBeamCosineTexture() : in.Density.GetTexture())
      ->GetTextureUnit());
  const auto& firstScale = in.Lightning.GetFirstScatteringScale();
  const auto& colour = in.Lightning.GetFirstScatteringColour();
  const float lightningFirstScale[3] = { static_cast<float>(firstScale[0]),
    static_cast<float>(firstScale[1]), static_cast<float>(firstScale[2]) };
  const float lightningColour[3] = { static_cast<float>(colour[0]), static_cast<float>(colour[1]),
    static_cast<float>(colour[2]) };
  program->SetUniform3f("lightningFirstScale", lightningFirstScale);
  program->SetUniform3f("lightningColour", lightningColour);
  nimbus::CloudOptics lightningOptics;
  lightningOptics.G = this->CloudG;
  const double k1 = nimbus::PhaseLegendreCoefficient(lightningOptics, 1);
  program->SetUniformf("lightningFirstK1", static_cast<float>(k1));
  // The delta-M view (LightningDeltaMView): f = k2, as the solver's truncation
  // (MultipleScattering.cxx) and the filter's reduced first scattering take it, and the
  // truncated phase function's g' = (k1 - k2) / (1 - k2).
  const double k2 = nimbus::PhaseLegendreCoefficient(lightningOptics, 2);
  const bool deltaM = frame.LightningDeltaM && k2 > 0.0 && k1 > k2 && k2 < 0.999;
  const double truncatedG = deltaM ? (k1 - k2) / (1.0 - k2) : k1;
  program->SetUniformi("lightningDeltaM", deltaM ? 1 : 0);
  program->SetUniformf("lightningPeakFraction", static_cast<float>(deltaM ? k2 : 0.0));
  program->SetUniformf("lightningTruncatedG", static_cast<float>(truncatedG));
  program->SetUniformf(
    "lightningDegreeOneScale", static_cast<float>(deltaM && k1 > 0.0 ? truncatedG / k1 : 1.0));
  program->SetUniformf("lightningPeakLobeG",
    static_cast<float>(deltaM ? nimbus::DeltaMPeakLobeG(lightningOptics) : 0.0));
  // Temperature emission: the texels hold rho B(T) / Y[B(T_ref)] (linear sRGB);
  // E [Y/(sr m)] scales them.
  program->SetUniformi("emissionOn", frame.EmissionTexture ? 1 : 0);
  program->SetUniformi("emissionRgb",
    (frame.EmissionTexture ? in.Emission.GetTexture() : in.Density.GetTexture())->GetTextureUnit());
  program->SetUniformf("emissionScale",
    static_cast<float>(frame.EmissionTexture ? this->EmissionRadiancePerMetre : 0.0));
  program->SetUniformf("forwardPeakFraction", static_cast<float>(frame.ForwardPeakFraction));
  program->SetUniformi("octaves", frame.Octaves);
  const float octaveScales[3] = { static_cast<float>(this->OctaveExtinctionScale),
    static_cast<float>(this->OctaveScatteringScale),
    static_cast<float>(this->OctaveAsymmetryScale) };
  program->SetUniform3f("octaveScales", octaveScales);
  this->SetViewLightUniforms(program, frame);
}

//------------------------------------------------------------------------------
// The ray-marched method (docs/ray-march.md). A piece of a distributed cloud keeps the
// slices: its air and its premultiplied layer are the slices' passes' (docs/parallel.md).
bool vtkNimbusCloudVolumeMapper::UsesRayMarching() const
{
  return this->RenderingMethod == RayMarching && !this->PieceCompositing;
}

const char* vtkNimbusCloudVolumeMapper::GetLastPassTimes() const
{
  return this->Internal->LastPassTimes.c_str();
}

int vtkNimbusCloudVolumeMapper::GetNumberOfSunDepthBuilds() const
{
  return this->Internal->SunDepthBuilds;
}

double vtkNimbusCloudVolumeMapper::GetLastSunDepthSeconds() const
{
  return this->Internal->LastSunDepthSeconds;
}

namespace
{
// The density texture's grid for SunDepthVolume: world (up frame) -> texel index
// (index = texture coordinate x texels - 1/2) and the box in index coordinates.
nimbus::SunDepthGrid SunDepthGridOf(const std::array<float, 16>& worldToTexture,
  const std::array<float, 16>& worldToBox, const int dims[3])
{
  nimbus::SunDepthGrid grid;
  vtkNew<vtkMatrix4x4> toTexture, toBox, boxToWorld, boxToTexture;
  for (int r = 0; r < 4; ++r)
  {
    for (int c = 0; c < 4; ++c)
    {
      toTexture->SetElement(r, c, worldToTexture[4 * c + r]);
      toBox->SetElement(r, c, worldToBox[4 * c + r]);
    }
  }
  vtkMatrix4x4::Invert(toBox, boxToWorld);
  vtkMatrix4x4::Multiply4x4(toTexture, boxToWorld, boxToTexture);
  for (int r = 0; r < 3; ++r)
  {
    grid.Dimensions[r] = dims[r];
    for (int c = 0; c < 3; ++c)
    {
      grid.Linear[3 * r + c] = dims[r] * toTexture->GetElement(r, c);
    }
    // The box's corners (0 and 1 in box coordinates) in index coordinates.
    const double low = dims[r] * boxToTexture->GetElement(r, 3) - 0.5;
    double high = low;
    for (int c = 0; c < 3; ++c)
    {
      high += dims[r] * boxToTexture->GetElement(r, c);
    }
    grid.BoxLow[r] = std::min(low, high);
    grid.BoxHigh[r] = std::max(low, high);
  }
  return grid;
}

// The ray march's empty-space blocks (texels per side) and the air's look-up volume:
// columns across the view (rows by its aspect) and distances along each ray (32: against
// the path tracer on the five scenes within 0.1 dB of 64, at a quarter of the cost).
constexpr int kRayMarchBlockTexels = 4;
constexpr int kFroxelColumns = 32;
constexpr int kFroxelSlices = 32;

// The look-up volume's ladder of distances (world units): d_1 and 1 / log(d_{k+1} / d_k),
// from 1e-5 of the farthest distance to it, the ray from the eye that grazes the
// ground to the top of the atmosphere.
std::array<float, 2> FroxelLadder(
  const std::array<double, 3>& eye, const nimbus::SceneAtmosphere& air, double metresPerUnit)
{
  const double ground = air.EarthRadiusMetres;
  const double r = std::max(ground + air.SceneAltitudeMetres + eye[2] * metresPerUnit, ground);
  const double farthest =
    (std::sqrt(std::max(r * r - ground * ground, 0.0)) +
      std::sqrt(std::max(air.TopRadiusMetres * air.TopRadiusMetres - ground * ground, 0.0))) /
    metresPerUnit;
  const double nearest = 1e-5 * farthest;
  const double logRatio = std::log(farthest / nearest) / (kFroxelSlices - 2);
  return { { static_cast<float>(nearest), static_cast<float>(1.0 / logRatio) } };
}

// The box as [0,1]^3 -> density texture coordinates (column-major, as the uniforms).
std::array<float, 16> BoxToTextureOf(
  const std::array<float, 16>& worldToTexture, const std::array<float, 16>& worldToBox)
{
  vtkNew<vtkMatrix4x4> toTexture, toBox, boxToWorld, boxToTexture;
  for (int r = 0; r < 4; ++r)
  {
    for (int c = 0; c < 4; ++c)
    {
      toTexture->SetElement(r, c, worldToTexture[4 * c + r]);
      toBox->SetElement(r, c, worldToBox[4 * c + r]);
    }
  }
  vtkMatrix4x4::Invert(toBox, boxToWorld);
  vtkMatrix4x4::Multiply4x4(toTexture, boxToWorld, boxToTexture);
  std::array<float, 16> result{};
  for (int r = 0; r < 4; ++r)
  {
    for (int c = 0; c < 4; ++c)
    {
      result[4 * c + r] = static_cast<float>(boxToTexture->GetElement(r, c));
    }
  }
  return result;
}

// The length in world units of the density's smallest texel side.
double SmallestTexelLength(const nimbus::SunDepthGrid& grid)
{
  double smallest = std::numeric_limits<double>::max();
  for (int r = 0; r < 3; ++r)
  {
    const double* row = &grid.Linear[3 * r];
    const double norm = std::sqrt(row[0] * row[0] + row[1] * row[1] + row[2] * row[2]);
    if (norm > 0.0 && grid.Dimensions[r] > 1)
    {
      smallest = std::min(smallest, 1.0 / norm);
    }
  }
  return smallest == std::numeric_limits<double>::max() ? 1.0 : smallest;
}

void UploadVolume(vtkTextureObject* texture, vtkOpenGLRenderWindow* window, const int dims[3],
  const float* values, bool linear)
{
  ResetTexture(texture, window, linear);
  if (!texture->Create3DFromRaw(
        dims[0], dims[1], dims[2], 1, VTK_FLOAT, const_cast<float*>(values)))
  {
    throw std::runtime_error("could not upload a 3-D texture of the ray march");
  }
}
} // namespace

//------------------------------------------------------------------------------
// The cloud's optical depth toward the sun per density texel and the density's block
// maxima, computed again only when the density, the sun or the optics change.
void vtkNimbusCloudVolumeMapper::UpdateSunDepthVolume(FrameState& frame)
{
  if (!this->UsesRayMarching())
  {
    return;
  }
  Internals& in = *this->Internal;
  int dims[3];
  in.Density.GetDimensions(dims);
  const std::vector<float>& texels = in.Density.GetTexels();
  std::vector<double> key{ static_cast<double>(in.Density.GetNumberOfUploads()), frame.ToSun[0],
    frame.ToSun[1], frame.ToSun[2], this->ExtinctionPerDensity, frame.Settings.MetresPerUnit };
  key.insert(key.end(), frame.WorldToTexture.begin(), frame.WorldToTexture.end());
  key.insert(key.end(), frame.WorldToBox.begin(), frame.WorldToBox.end());
  if (key == in.SunDepthKey && in.SunDepthTexture->GetHandle())
  {
    return;
  }
  if (texels.size() !=
    static_cast<std::size_t>(dims[0]) * dims[1] * static_cast<std::size_t>(dims[2]))
  {
    throw std::runtime_error("the density's texels are not kept for the ray march");
  }
  const auto start = std::chrono::steady_clock::now();
  const nimbus::SunDepthGrid grid = SunDepthGridOf(frame.WorldToTexture, frame.WorldToBox, dims);
  const std::vector<float> depth =
    nimbus::ComputeSunDepthVolume(texels.data(), grid, frame.ToSun, this->ExtinctionPerDensity,
      frame.Settings.MetresPerUnit, vtkSMPTools::GetEstimatedNumberOfThreads());
  // Uploaded as the transmittance exp(-tau): the texture's trilinear filter then
  // averages light, not depth, as the sweep does (SunDepthVolume.h).
  std::vector<float> transmittance(depth.size());
  std::transform(
    depth.begin(), depth.end(), transmittance.begin(), [](float tau) { return std::exp(-tau); });
  UploadVolume(in.SunDepthTexture, frame.Window, dims, transmittance.data(), true);
  const std::vector<float> maxima =
    nimbus::ComputeBlockMaxima(texels.data(), grid.Dimensions, kRayMarchBlockTexels, in.BlockCount);
  UploadVolume(in.BlockTexture, frame.Window, in.BlockCount.data(), maxima.data(), false);
  in.DensityMaximum = maxima.empty() ? 0.0 : *std::max_element(maxima.begin(), maxima.end());
  in.SunDepthKey = std::move(key);
  ++in.SunDepthBuilds;
  in.LastSunDepthSeconds =
    std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

//------------------------------------------------------------------------------
// The clear air's look-up volume over the view (cloudAirFroxelsFS.glsl): a ladder of
// kFroxelSlices distances from 1e-5 of the farthest one to the farthest: the ray that
// grazes the ground to the top of the atmosphere.
void vtkNimbusCloudVolumeMapper::RenderAirFroxels(const FrameState& frame)
{
  if (!frame.Atmosphere)
  {
    return;
  }
  Internals& in = *this->Internal;
  const int columns = kFroxelColumns;
  const int rows = std::max(8,
    std::min(kFroxelColumns,
      static_cast<int>(std::lround(
        static_cast<double>(columns) * frame.Level.Height / std::max(frame.Level.Width, 1)))));
  for (vtkTextureObject* t :
    { in.FroxelScattering.GetPointer(), in.FroxelTransmittance.GetPointer() })
  {
    EnsureTexture2D(t, frame.Window, columns, rows * kFroxelSlices, 4, false);
    t->SetMinificationFilter(vtkTextureObject::Linear);
    t->SetMagnificationFilter(vtkTextureObject::Linear);
  }
  DrawInto(in.FroxelFramebuffer, in.FroxelScattering, frame.Window);
  in.FroxelFramebuffer->RemoveColorAttachment(1);
  in.FroxelFramebuffer->AddColorAttachment(1, in.FroxelTransmittance);
  in.FroxelFramebuffer->ActivateDrawBuffers(2);
  const GLenum buffers[2] = { GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1 };
  glDrawBuffers(2, buffers); // as in RenderCloudMarch
  frame.State->vtkglViewport(0, 0, columns, rows * kFroxelSlices);
  frame.State->vtkglDisable(GL_BLEND);
  vtkShaderProgram* program = in.Ready(in.FroxelPass, cloudAirFroxelsFS);
  this->SetCommonUniforms(program, frame);
  const float size[3] = { static_cast<float>(columns), static_cast<float>(rows),
    static_cast<float>(kFroxelSlices) };
  program->SetUniform3f("froxelDimensions", size);
  const std::array<float, 2> depths =
    FroxelLadder(frame.Eye, frame.Settings.Air, frame.Settings.MetresPerUnit);
  program->SetUniform2f("froxelDepths", depths.data());
  program->SetUniformi("stepsPerInterval", 1);
  program->SetUniformf("mieG", static_cast<float>(frame.Settings.Air.MieG));
  in.FroxelPass->Render();
  ++in.PassesLastRender;
  in.FroxelScattering->Activate();
  in.FroxelTransmittance->Activate();
}

//------------------------------------------------------------------------------
// The ray march (cloudMarchFS.glsl) into the accumulation targets: the cloud's and
// the air's radiance and the cloud's transmittance, and over a sky the same without
// the cloud.
void vtkNimbusCloudVolumeMapper::RenderCloudMarch(const FrameState& frame)
{
  Internals& in = *this->Internal;
  // Its own framebuffer, always with both targets (the cloud-free one is read over a
  // sky only).
  this->EnsureImageTarget(in.Accumulation, frame);
  this->EnsureImageTarget(in.ClearAccumulation, frame);
  in.LightningAccumulationOn = false; // the march attenuates the lightning itself
  DrawInto(in.MarchFramebuffer, in.Accumulation, frame.Window);
  in.MarchFramebuffer->RemoveColorAttachment(1);
  in.MarchFramebuffer->AddColorAttachment(1, in.ClearAccumulation);
  in.MarchFramebuffer->ActivateDrawBuffers(2);
  // This VTK's vtkOpenGLState can take the two draw buffers for a change it already made
  // (its cache compares with the framebuffer's list of the call before) and leave the
  // second at GL_NONE (measured: GL_DRAW_BUFFER1 read back as GL_NONE): set them directly.
  // The lights' shafts on fewer pixels need the march's span (a third target).
  const bool spans = this->ShaftsApart(frame);
  in.MarchFramebuffer->RemoveColorAttachment(2);
  if (spans)
  {
    EnsureTexture2D(
      in.CloudSpanImage, frame.Window, frame.Level.Width, frame.Level.Height, 4, false);
    in.MarchFramebuffer->AddColorAttachment(2, in.CloudSpanImage);
  }
  const GLenum buffers[3] = { GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1, GL_COLOR_ATTACHMENT2 };
  glDrawBuffers(spans ? 3 : 2, buffers);
  frame.State->vtkglViewport(0, 0, frame.Level.Width, frame.Level.Height);
  frame.State->vtkglDisable(GL_BLEND);
  vtkShaderProgram* program = in.Ready(in.CloudMarchPass, cloudMarchFS, true, true);
  this->SetCommonUniforms(program, frame);
  this->SetCloudLightUniforms(program, frame);
  int dims[3];
  in.Density.GetDimensions(dims);
  const nimbus::SunDepthGrid grid = SunDepthGridOf(frame.WorldToTexture, frame.WorldToBox, dims);
  // Fewer samples at a lower quality level, as the slices (ComputeFrameLevel).
  const double levelScale =
    static_cast<double>(this->NumberOfSlices) / std::max(frame.Level.Slices, 1);
  const double step = this->RayMarchStepTexels * levelScale * SmallestTexelLength(grid);
  double diagonal = 0.0;
  for (int a = 0; a < 3; ++a)
  {
    const double side = (grid.BoxHigh[a] - grid.BoxLow[a] + 1.0) * SmallestTexelLength(grid);
    diagonal += side * side;
  }
  const int blocks = std::max({ in.BlockCount[0], in.BlockCount[1], in.BlockCount[2] });
  const double steps = std::sqrt(diagonal) / step + 8.0;
  program->SetUniformf("stepLength", static_cast<float>(step));
  program->SetUniformi("maxSteps", static_cast<int>(std::min(steps, 1e6)));
  program->SetUniformi("maxBlockSteps", 3 * blocks + 8);
  const float size[3] = { static_cast<float>(dims[0]), static_cast<float>(dims[1]),
    static_cast<float>(dims[2]) };
  program->SetUniform3f("densitySize", size);
  program->SetUniformi("blockMaxima", in.BlockTexture->GetTextureUnit());
  program->SetUniformf("blockTexels", static_cast<float>(kRayMarchBlockTexels));
  const float blockCount[3] = { static_cast<float>(in.BlockCount[0]),
    static_cast<float>(in.BlockCount[1]), static_cast<float>(in.BlockCount[2]) };
  program->SetUniform3f("blockCount", blockCount);
  program->SetUniformi("unlit", this->Unlit ? 1 : 0);
  program->SetUniformi("shaftsOn", this->Shafts ? 1 : 0);
  program->SetUniformi("shaftSteps", std::max(this->AtmosphereSteps / 2, 1));
  const std::array<float, 16> boxToTexture = BoxToTextureOf(frame.WorldToTexture, frame.WorldToBox);
  program->SetUniformMatrix4x4("boxToTexture", const_cast<float*>(boxToTexture.data()));
  program->SetUniformf("shaftSpacing", static_cast<float>(4.0 * SmallestTexelLength(grid)));
  program->SetUniformf("mieG", static_cast<float>(frame.Settings.Air.MieG));
  program->SetUniformf("multipleScattering", static_cast<float>(this->MultipleScattering));
  // Without air the look-up volume is not read; its samplers name a 2-D unit.
  vtkTextureObject* scattering =
    frame.Atmosphere ? in.FroxelScattering.GetPointer() : in.SceneDepth.GetPointer();
  vtkTextureObject* transmittance =
    frame.Atmosphere ? in.FroxelTransmittance.GetPointer() : in.SceneDepth.GetPointer();
  program->SetUniformi("froxelScattering", scattering->GetTextureUnit());
  program->SetUniformi("froxelTransmittance", transmittance->GetTextureUnit());
  const float froxelSize[3] = { static_cast<float>(in.FroxelScattering->GetWidth()),
    static_cast<float>(in.FroxelScattering->GetHeight() / kFroxelSlices),
    static_cast<float>(kFroxelSlices) };
  program->SetUniform3f("froxelDimensions", froxelSize);
  const std::array<float, 2> depths =
    FroxelLadder(frame.Eye, frame.Settings.Air, frame.Settings.MetresPerUnit);
  program->SetUniform2f("froxelDepths", depths.data());
  program->SetUniformi("lightSamples", this->LightSamples);
  program->SetUniformi(
    "lightsInAir", this->LightShaftMethod == LightShaftsByRayMarching && !spans ? 1 : 0);
  in.CloudMarchPass->Render();
  ++in.PassesLastRender;
}

//------------------------------------------------------------------------------
// The slices (000 §4.2-4.3), in order of increasing distance from the sun: each
// seen from the eye with the shadow so far, then added to the shadow surface. The
// eye pass is scissored to the slice's pixels (only the box's part of the slice is
// drawn; the air and ground outside the box are RenderOutsideRegion's).
bool vtkNimbusCloudVolumeMapper::RenderSlices(vtkRenderer* renderer, const FrameState& frame)
{
  Internals& in = *this->Internal;
  vtkShaderProgram* sliceProgram = in.Ready(in.SlicePass, svsSliceFS, true);
  this->SetCommonUniforms(sliceProgram, frame);
  sliceProgram->SetUniformi("intervalPhase", in.IntervalPhase->GetTextureUnit());
  sliceProgram->SetUniformi("rayEnds", in.RayEnds->GetTextureUnit());
  sliceProgram->SetUniformf("sliceSpacing", static_cast<float>(frame.Planes.Spacing));
  sliceProgram->SetUniformf("sunStepMetres", static_cast<float>(frame.SunStepMetres));
  sliceProgram->SetUniformi("shaftsOn", this->Shafts ? 1 : 0);
  sliceProgram->SetUniformi("unlit", this->Unlit ? 1 : 0);
  sliceProgram->SetUniformi(
    "boxAirOn", this->PieceCompositing && !this->DrawOutsideRegions ? 0 : 1);
  this->SetCloudLightUniforms(sliceProgram, frame);
  vtkShaderProgram* shadowProgram = nullptr;
  if (!this->Unlit)
  {
    shadowProgram = in.Ready(in.ShadowPass, svsShadowFS);
    this->SetCommonUniforms(shadowProgram, frame);
    shadowProgram->SetUniformf("sunStepMetres", static_cast<float>(frame.SunStepMetres));
    shadowProgram->SetUniformf("sliceSpacing", static_cast<float>(frame.Planes.Spacing));
  }
  // A still frame that has taken a second reports its progress every 16 slices
  // (after glFinish: the slices done, not queued) and stops when the render window
  // or the caller asks for an abort.
  const std::size_t total = frame.Planes.Offsets.size();
  bool reported = false;
  std::size_t done = 0;
  for (const double offset : frame.Planes.Offsets)
  {
    if (!frame.Interactive && done > 0 && done % 16 == 0)
    {
      glFinish();
      const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - frame.PassesStart).count();
      if (seconds > 1.0)
      {
        reported = true;
        this->UpdateProgress(static_cast<double>(done) / total);
        vtkRenderWindow* window = renderer->GetRenderWindow();
        if ((window && window->CheckAbortStatus()) || this->GetAbortExecute())
        {
          this->SetAbortExecute(0);
          this->UpdateProgress(1.0);
          return false;
        }
      }
    }
    ++done;
    // The pixels (texels) the slice can touch: with SliceJitter its planes move by up
    // to half a spacing either way.
    const std::vector<nimbus::Vector3> polygon = this->SliceJitter
      ? nimbus::SlabPoints(frame.Corners, frame.Axis.Normal, offset, 0.5 * frame.Planes.Spacing)
      : nimbus::SlicePolygon(frame.Corners, frame.Axis.Normal, offset);
    if (polygon.empty())
    {
      continue;
    }
    int scissor[4];
    const bool scissored = nimbus::ScreenRectangle(
      polygon, frame.WorldToNdc->GetData(), frame.Level.Width, frame.Level.Height, scissor);
    this->RenderSliceFromEye(
      frame, sliceProgram, static_cast<float>(offset), scissored ? scissor : nullptr);
    if (shadowProgram)
    {
      int texels[4];
      nimbus::ShadowRectangle(polygon, frame.Shadow, frame.Level.ShadowSurfaceSize, texels);
      this->RenderSliceShadow(frame, shadowProgram, static_cast<float>(offset), texels);
    }
  }
  if (reported)
  {
    this->UpdateProgress(1.0);
  }
  return true;
}

void vtkNimbusCloudVolumeMapper::RenderSliceFromEye(
  const FrameState& frame, vtkShaderProgram* program, float offset, const int* scissor)
{
  Internals& in = *this->Internal;
  in.AccumulationFramebuffer->Bind(GL_FRAMEBUFFER);
  frame.State->vtkglViewport(0, 0, frame.Level.Width, frame.Level.Height);
  if (scissor)
  {
    frame.State->vtkglEnable(GL_SCISSOR_TEST);
    frame.State->vtkglScissor(scissor[0], scissor[1], scissor[2], scissor[3]);
  }
  UseSliceBlend(frame.State, frame.Axis.BackToFront);
  frame.Window->GetShaderCache()->ReadyShaderProgram(program);
  program->SetUniformf("sliceOffset", offset);
  UseLightningTarget(frame, true);
  in.SlicePass->Render();
  UseLightningTarget(frame, false);
  ++in.PassesLastRender;
  if (scissor)
  {
    frame.State->vtkglDisable(GL_SCISSOR_TEST);
  }
}

void vtkNimbusCloudVolumeMapper::RenderSliceShadow(
  const FrameState& frame, vtkShaderProgram* program, float offset, const int texels[4])
{
  Internals& in = *this->Internal;
  in.ShadowFramebuffer->Bind(GL_FRAMEBUFFER);
  frame.State->vtkglViewport(0, 0, frame.Level.ShadowSurfaceSize, frame.Level.ShadowSurfaceSize);
  frame.State->vtkglEnable(GL_SCISSOR_TEST);
  frame.State->vtkglScissor(texels[0], texels[1], texels[2], texels[3]);
  frame.State->vtkglEnable(GL_BLEND);
  frame.State->vtkglBlendFuncSeparate(GL_ONE, GL_ONE, GL_ONE, GL_ONE);
  frame.Window->GetShaderCache()->ReadyShaderProgram(program);
  program->SetUniformf("sliceOffset", offset);
  in.ShadowPass->Render();
  frame.State->vtkglDisable(GL_SCISSOR_TEST);
  ++in.PassesLastRender;
}

//------------------------------------------------------------------------------
// With CaptureRadiance: a float copy of the sum of the slices (radiance and cloud
// transmittance) as the "radiance" array of GetRadianceImage().
void vtkNimbusCloudVolumeMapper::CaptureRadianceImage(const FrameState& frame)
{
  if (!this->CaptureRadiance)
  {
    return;
  }
  Internals& in = *this->Internal;
  // The framebuffer the frame's method drew the accumulation with.
  vtkOpenGLFramebufferObject* framebuffer = this->UsesRayMarching()
    ? in.MarchFramebuffer.GetPointer()
    : in.AccumulationFramebuffer.GetPointer();
  framebuffer->Bind(GL_FRAMEBUFFER);
  framebuffer->ActivateReadBuffer(0);
  vtkNew<vtkFloatArray> values;
  values->SetName("radiance");
  values->SetNumberOfComponents(4);
  const int width = frame.Level.Width, height = frame.Level.Height;
  values->SetNumberOfTuples(static_cast<vtkIdType>(width) * height);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, width, height, GL_RGBA, GL_FLOAT, values->GetPointer(0));
  if (!frame.Lights.empty() && this->UsesRayMarching() &&
    this->LightShaftMethod == LightShaftsByVirtualPlanes)
  {
    // The virtual planes' shafts, which the composite adds.
    std::vector<float> shafts(static_cast<std::size_t>(width) * height * 4);
    in.LightsFramebuffer->Bind(GL_FRAMEBUFFER);
    in.LightsFramebuffer->ActivateReadBuffer(0);
    glReadPixels(0, 0, width, height, GL_RGBA, GL_FLOAT, shafts.data());
    float* radiance = values->GetPointer(0);
    for (std::size_t i = 0; i < shafts.size(); i += 4)
    {
      for (int c = 0; c < 3; ++c)
      {
        radiance[i + c] += shafts[i + c];
      }
    }
  }
  if (!this->UsesRayMarching() && in.LightningAccumulationOn)
  {
    // The lightning's delta-M view (the slices' third target), which the composite adds.
    std::vector<float> lightning(static_cast<std::size_t>(width) * height * 4);
    in.AccumulationFramebuffer->Bind(GL_FRAMEBUFFER);
    glReadBuffer(GL_COLOR_ATTACHMENT2);
    glReadPixels(0, 0, width, height, GL_RGBA, GL_FLOAT, lightning.data());
    glReadBuffer(GL_COLOR_ATTACHMENT0);
    float* radiance = values->GetPointer(0);
    for (std::size_t i = 0; i < lightning.size(); i += 4)
    {
      for (int c = 0; c < 3; ++c)
      {
        radiance[i + c] += lightning[i + c];
      }
    }
  }
  in.Radiance->Initialize();
  in.Radiance->SetDimensions(width, height, 1);
  in.Radiance->GetPointData()->SetScalars(values);
}

//------------------------------------------------------------------------------
// The cloud composited over the scene in the renderer's framebuffer (000 Eq. 4),
// over a sky as I = S - T_cl S_clear + T_cl L_sky.
void vtkNimbusCloudVolumeMapper::RenderComposite(const FrameState& frame)
{
  Internals& in = *this->Internal;
  frame.State->PopFramebufferBindings();
  frame.FramebuffersPushed = false;
  frame.State->vtkglViewport(frame.X0, frame.Y0, frame.Width, frame.Height);
  frame.State->vtkglDisable(GL_BLEND);
  in.Accumulation->Activate();
  in.SceneColor->Activate();
  vtkShaderProgram* program = in.Ready(in.CompositePass, svsCompositeFS);
  this->SetCommonUniforms(program, frame);
  program->SetUniformi("accumulation", in.Accumulation->GetTextureUnit());
  program->SetUniformi("sceneColor", in.SceneColor->GetTextureUnit());
  program->SetUniform3f("displayScale", frame.Settings.DisplayScale);
  program->SetUniformi("encodeSrgb", frame.Settings.EncodeSrgb ? 1 : 0);
  program->SetUniformi("skyBackground", frame.Settings.OverSky ? 1 : 0);
  program->SetUniformi(
    "premultipliedPiece", this->PieceCompositing && !this->DrawOutsideRegions ? 1 : 0);
  float pieceBackground[3];
  for (int c = 0; c < 3; ++c)
  {
    pieceBackground[c] = static_cast<float>(this->PieceBackground[c]);
  }
  program->SetUniform3f("pieceBackground", pieceBackground);
  program->SetUniformi("usePieceBackground",
    this->PieceCompositing && this->DrawOutsideRegions && !frame.Settings.OverSky ? 1 : 0);
  const bool planes = !frame.Lights.empty() && this->UsesRayMarching() &&
    this->LightShaftMethod == LightShaftsByVirtualPlanes;
  if (planes)
  {
    in.LightsImage->Activate();
  }
  program->SetUniformi("lightsImageOn", planes ? 1 : 0);
  if (in.LightningAccumulationOn)
  {
    in.LightningAccumulation->Activate();
  }
  program->SetUniformi("lightningImageOn", in.LightningAccumulationOn ? 1 : 0);
  program->SetUniformi("lightningAccumulation",
    (in.LightningAccumulationOn ? in.LightningAccumulation.GetPointer()
                                : in.Accumulation.GetPointer())
      ->GetTextureUnit());
  program->SetUniformi("lightsImage",
    (planes ? in.LightsImage.GetPointer() : in.Accumulation.GetPointer())->GetTextureUnit());
  if (frame.Settings.OverSky)
  {
    in.ClearAccumulation->Activate();
    program->SetUniformi("clearAccumulation", in.ClearAccumulation->GetTextureUnit());
  }
  else
  {
    // Unused; a sampler must still name a 2-D texture unit.
    program->SetUniformi("clearAccumulation", in.Accumulation->GetTextureUnit());
  }
  in.CompositePass->Render();
  ++in.PassesLastRender;
}

//------------------------------------------------------------------------------
// The view's lights as point lights of the multiple-scattering solve (their orders >= 2
// in the cloud; the march draws their single scattering): metres in the up frame, each
// dimmed by the clear air between it and the cloud's middle height (the solve sees no
// air), and what they are in the solve's key. The opaque scene's shadows are not in the
// solve.
void vtkNimbusCloudVolumeMapper::AddViewLightsToSolve(const FrameState& frame, double cloudMiddleZ,
  nimbus::CloudLighting& lighting, std::vector<double>& key)
{
  const Internals& in = *this->Internal;
  if (frame.Lights.empty())
  {
    return;
  }
  // The lights' part of the answer does not scale with the sun's illuminance: with
  // lights, a new illuminance is a new solve.
  key.push_back(frame.Settings.Sun.Illuminance);
  key.insert(key.end(), frame.LightsKey.begin(), frame.LightsKey.end());
  const double metres = frame.Settings.MetresPerUnit;
  for (const nimbus::ViewLight& light : frame.Lights)
  {
    nimbus::PointLight point;
    point.Position = { { light.Position[0] * metres, light.Position[1] * metres,
      light.Position[2] * metres } };
    point.Spot = light.Spot;
    std::array<double, 3> transmittance{ { 1.0, 1.0, 1.0 } };
    if (frame.Atmosphere && in.Table.HasAtmosphere)
    {
      // Straight up or down to the cloud's middle height: a vertical path's optical length.
      const double h = frame.Settings.Air.SceneAltitudeMetres + point.Position[2];
      const double rise = cloudMiddleZ * metres - point.Position[2];
      const double cosZenith = rise >= 0.0 ? 1.0 : -1.0;
      const double lr = nimbus::FlatLayerOpticalLength(
        h, cosZenith, std::abs(rise), in.Table.Air.RayleighScaleHeightMetres);
      const double lm = nimbus::FlatLayerOpticalLength(
        h, cosZenith, std::abs(rise), in.Table.Air.MieScaleHeightMetres);
      for (int c = 0; c < 3; ++c)
      {
        transmittance[c] = std::exp(
          -(in.Table.RayleighExtinctionSeaLevel[c] * lr + in.Table.MieExtinctionSeaLevel * lm));
      }
    }
    for (int c = 0; c < 3; ++c)
    {
      point.Intensity[c] = light.Intensity[c] * transmittance[c];
    }
    lighting.PointLights.push_back(point);
  }
}

//------------------------------------------------------------------------------
// The view's lights (docs/lights.md).
void vtkNimbusCloudVolumeMapper::SetLightMap(vtkImageData* image)
{
  vtkSetObjectBodyMacro(LightMap, vtkImageData, image);
}

int vtkNimbusCloudVolumeMapper::GetNumberOfLightsLastRender() const
{
  return this->Internal->LightsLastRender;
}

int vtkNimbusCloudVolumeMapper::GetNumberOfShadowCastersLastRender() const
{
  return this->Internal->ShadowMaps.GetNumberOfCasters();
}

namespace
{
// The renderer's switched-on positional lights as ViewLights (VTK world).
std::vector<nimbus::ViewLight> PositionalLightsOf(
  vtkRenderer* renderer, double intensityScale, double edgeWidthDegrees)
{
  std::vector<nimbus::ViewLight> lights;
  vtkLightCollection* collection = renderer->GetLights();
  vtkCollectionSimpleIterator it;
  collection->InitTraversal(it);
  while (vtkLight* light = collection->GetNextLight(it))
  {
    if (!light->GetSwitch() || !light->GetPositional())
    {
      continue;
    }
    double position[3], focal[3];
    light->GetTransformedPosition(position);
    light->GetTransformedFocalPoint(focal);
    nimbus::ViewLight v;
    v.Position = { { position[0], position[1], position[2] } };
    const nimbus::Vector3 axis{ { focal[0] - position[0], focal[1] - position[1],
      focal[2] - position[2] } };
    const double length = nimbus::Length(axis);
    if (length > 0.0 && std::isfinite(length))
    {
      v.Spot.Axis = { { axis[0] / length, axis[1] / length, axis[2] / length } };
      v.Spot.ConeHalfAngleDegrees = light->GetConeAngle();
    }
    v.Spot.EdgeWidthDegrees =
      std::min(edgeWidthDegrees, std::max(v.Spot.ConeHalfAngleDegrees, 0.0));
    const double* color = light->GetDiffuseColor();
    const double intensity = light->GetIntensity() * intensityScale;
    v.Intensity = { { intensity * color[0], intensity * color[1], intensity * color[2] } };
    lights.push_back(v);
  }
  return lights;
}

// The region the lights must reach and the shadow maps cover: the visible props'
// bounds (the cloud's box among them), VTK world.
std::array<double, 6> LightRegionOf(vtkRenderer* renderer)
{
  double bounds[6];
  renderer->ComputeVisiblePropBounds(bounds);
  return { { bounds[0], bounds[1], bounds[2], bounds[3], bounds[4], bounds[5] } };
}
}

// The lights this frame draws: the renderer's, selected (ViewLights.h), their shadow
// maps drawn, then turned into the up frame; and the key of the image they light.
void vtkNimbusCloudVolumeMapper::UpdateViewLights(vtkRenderer* renderer, FrameState& frame)
{
  Internals& in = *this->Internal;
  frame.Lights.clear();
  frame.LightShadows = false;
  frame.LightMap = false;
  frame.LightsKey.clear();
  in.LightsLastRender = 0;
  if (this->LightSources == NoLights || !this->UsesRayMarching() || this->Unlit)
  {
    return;
  }
  const std::vector<nimbus::ViewLight> candidates =
    PositionalLightsOf(renderer, this->LightIntensityScale, this->SpotEdgeWidthDegrees);
  if (candidates.empty())
  {
    return;
  }
  const std::array<double, 6> region = LightRegionOf(renderer);
  // The view's frustum (VTK world): lights whose beams miss it cost nothing.
  std::array<double, 24> frustum{};
  renderer->GetActiveCamera()->GetFrustumPlanes(renderer->GetTiledAspectRatio(), frustum.data());
  nimbus::ViewLightSelection selection =
    nimbus::SelectViewLights(candidates, region, this->MaximumLights, &frustum);
  if (selection.Message != in.LightsMessage && !selection.Message.empty())
  {
    vtkWarningMacro(<< selection.Message);
  }
  in.LightsMessage = selection.Message;
  if (selection.Lights.empty())
  {
    return;
  }
  if (this->LightShadowMapSize > 0)
  {
    frame.LightShadows = in.ShadowMaps.Update(
      renderer, frame.Window, selection.Lights, region, this->LightShadowMapSize);
  }
  this->UpdateLightMapTexture(frame);
  const nimbus::UpAxis up = frame.Settings.Up;
  for (nimbus::ViewLight& light : selection.Lights)
  {
    frame.LightsKey.insert(frame.LightsKey.end(), light.Position.begin(), light.Position.end());
    frame.LightsKey.insert(frame.LightsKey.end(), light.Spot.Axis.begin(), light.Spot.Axis.end());
    frame.LightsKey.insert(frame.LightsKey.end(), light.Intensity.begin(), light.Intensity.end());
    frame.LightsKey.push_back(light.Spot.ConeHalfAngleDegrees);
    frame.LightsKey.push_back(light.Spot.EdgeWidthDegrees);
    light.Position = nimbus::ToUpFrame(up, light.Position);
    light.Spot.Axis = nimbus::ToUpFrame(up, light.Spot.Axis);
  }
  // What the shadow maps hold: the casters' geometry and placement.
  vtkPropCollection* props = renderer->GetViewProps();
  vtkCollectionSimpleIterator it;
  props->InitTraversal(it);
  while (vtkProp* prop = props->GetNextProp(it))
  {
    frame.LightsKey.push_back(static_cast<double>(prop->GetRedrawMTime()));
    frame.LightsKey.push_back(prop->GetVisibility() ? 1.0 : 0.0);
  }
  frame.LightsKey.push_back(static_cast<double>(in.LightMapTime));
  frame.LightsKey.push_back(frame.LightShadows ? 1.0 : 0.0);
  for (int a = 0; a < 3; ++a)
  {
    const double low[3] = { region[0], region[2], region[4] };
    const double high[3] = { region[1], region[3], region[5] };
    const auto l = ToUp(up, low), h = ToUp(up, high);
    frame.LightRegion[2 * a] = std::min(l[a], h[a]);
    frame.LightRegion[2 * a + 1] = std::max(l[a], h[a]);
  }
  frame.Lights = std::move(selection.Lights);
  in.LightsLastRender = static_cast<int>(frame.Lights.size());
}

// The light map's luminance as a one-channel float texture, uploaded when the image
// changed: 8-bit images are sRGB-encoded (decoded first), others taken as linear; one
// component is the luminance, three or four are linear sRGB (Y = 0.2126 R + 0.7152 G +
// 0.0722 B).
void vtkNimbusCloudVolumeMapper::UpdateLightMapTexture(FrameState& frame)
{
  Internals& in = *this->Internal;
  vtkDataArray* scalars = this->LightMap ? this->LightMap->GetPointData()->GetScalars() : nullptr;
  if (!scalars)
  {
    return;
  }
  int dims[3];
  this->LightMap->GetDimensions(dims);
  const vtkMTimeType time = std::max(this->LightMap->GetMTime(), scalars->GetMTime());
  if (time == in.LightMapTime && in.LightMapTexture->GetHandle())
  {
    frame.LightMap = true;
    return;
  }
  const int components = scalars->GetNumberOfComponents();
  if (dims[0] < 1 || dims[1] < 1 ||
    scalars->GetNumberOfTuples() < static_cast<vtkIdType>(dims[0]) * dims[1])
  {
    return;
  }
  const bool encoded = scalars->GetDataType() == VTK_UNSIGNED_CHAR;
  std::vector<float> luminance(static_cast<std::size_t>(dims[0]) * dims[1]);
  for (std::size_t i = 0; i < luminance.size(); ++i)
  {
    double rgb[3];
    for (int c = 0; c < 3; ++c)
    {
      double value = scalars->GetComponent(static_cast<vtkIdType>(i), std::min(c, components - 1));
      value = encoded ? nimbus::SrgbDecode(value / 255.0) : value;
      rgb[c] = std::isfinite(value) ? std::max(value, 0.0) : 0.0;
    }
    luminance[i] = static_cast<float>(
      components >= 3 ? 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2] : rgb[0]);
  }
  in.LightMapTexture->SetContext(frame.Window);
  in.LightMapTexture->ReleaseGraphicsResources(frame.Window);
  in.LightMapTexture->SetWrapS(vtkTextureObject::ClampToEdge);
  in.LightMapTexture->SetWrapT(vtkTextureObject::ClampToEdge);
  in.LightMapTexture->SetMinificationFilter(vtkTextureObject::Linear);
  in.LightMapTexture->SetMagnificationFilter(vtkTextureObject::Linear);
  in.LightMapTexture->Create2DFromRaw(dims[0], dims[1], 1, VTK_FLOAT, luminance.data());
  in.LightMapTime = time;
  frame.LightMap = true;
}

void vtkNimbusCloudVolumeMapper::SetViewLightUniforms(
  vtkShaderProgram* program, const FrameState& frame)
{
  Internals& in = *this->Internal;
  const int count = static_cast<int>(frame.Lights.size());
  program->SetUniformi("lightCount", count);
  // Unused when off, but the samplers must name 2-D units.
  program->SetUniformi("lightMap",
    (frame.LightMap ? in.LightMapTexture.GetPointer() : in.SceneDepth.GetPointer())
      ->GetTextureUnit());
  program->SetUniformi("lightShadowAtlas",
    (frame.LightShadows ? in.ShadowMaps.GetTexture() : in.SceneDepth.GetPointer())
      ->GetTextureUnit());
  if (count == 0)
  {
    return;
  }
  float position[nimbus::kMaximumViewLights][3] = {}, axis[nimbus::kMaximumViewLights][3] = {},
        mapU[nimbus::kMaximumViewLights][3] = {}, mapV[nimbus::kMaximumViewLights][3] = {},
        intensity[nimbus::kMaximumViewLights][3] = {}, cone[nimbus::kMaximumViewLights][4] = {},
        range[nimbus::kMaximumViewLights][2] = {}, cosines[nimbus::kMaximumViewLights][2] = {};
  const auto& ranges = in.ShadowMaps.GetRanges();
  for (int i = 0; i < count; ++i)
  {
    const nimbus::ViewLight& light = frame.Lights[i];
    nimbus::Vector3 e1{ { 1, 0, 0 } }, e2{ { 0, 1, 0 } };
    nimbus::SpotLightMapFrame(light.Spot.Axis, e1, e2);
    for (int c = 0; c < 3; ++c)
    {
      position[i][c] = static_cast<float>(light.Position[c]);
      axis[i][c] = static_cast<float>(light.Spot.Axis[c]);
      mapU[i][c] = static_cast<float>(e1[c]);
      mapV[i][c] = static_cast<float>(e2[c]);
      intensity[i][c] = static_cast<float>(light.Intensity[c]);
    }
    const double outer = std::clamp(light.Spot.ConeHalfAngleDegrees, 0.0, 180.0) * nimbus::kDegree;
    const double inner =
      std::max(outer - std::max(light.Spot.EdgeWidthDegrees, 0.0) * nimbus::kDegree, 0.0);
    cone[i][0] = static_cast<float>(outer);
    cone[i][1] = static_cast<float>(inner);
    cone[i][2] =
      static_cast<float>(outer < 0.5 * nimbus::kPi ? std::tan(std::max(outer, 1e-6)) : 1.0);
    cone[i][3] = frame.LightMap ? 1.0f : 0.0f;
    cosines[i][0] = static_cast<float>(std::cos(outer));
    cosines[i][1] = static_cast<float>(std::cos(inner));
    if (frame.LightShadows && i < static_cast<int>(ranges.size()))
    {
      range[i][0] = static_cast<float>(ranges[i][0]);
      range[i][1] = static_cast<float>(ranges[i][1]);
    }
  }
  program->SetUniform3fv("lightPosition", count, position);
  program->SetUniform3fv("lightAxis", count, axis);
  program->SetUniform3fv("lightMapU", count, mapU);
  program->SetUniform3fv("lightMapV", count, mapV);
  program->SetUniform3fv("lightIntensity", count, intensity);
  program->SetUniform4fv("lightCone", count, cone);
  program->SetUniform2fv("lightConeCosines", count, cosines);
  program->SetUniform2fv("lightShadowRange", count, range);
  program->SetUniformi("lightShadowsOn", frame.LightShadows ? 1 : 0);
  const float atlas[2] = { 6.0f, static_cast<float>(count) };
  program->SetUniform2f("lightShadowAtlasSize", atlas);
  const auto r = nimbus::WorldToUpFrame(frame.Settings.Up);
  float upToWorld[9];
  for (int a = 0; a < 3; ++a)
  {
    for (int b = 0; b < 3; ++b)
    {
      upToWorld[a * 3 + b] = static_cast<float>(r[a][b]); // column-major R^T
    }
  }
  program->SetUniformMatrix3x3("lightUpToWorld", upToWorld);
  program->SetUniformi("lightCloudVolumeOn", frame.LightCloudVolume ? 1 : 0);
  // Unused when off, but the sampler must name a 3-D unit.
  program->SetUniformi("lightCloudVolume",
    (frame.LightCloudVolume ? in.LightCloudVolume.GetPointer() : in.Density.GetTexture())
      ->GetTextureUnit());
  program->SetUniformf("lightCloudVolumeSlices", static_cast<float>(in.LightCloudSlices));
  program->SetUniformf("lightRadiusMetres", static_cast<float>(kLightRadiusMetres));
  program->SetUniformf("lightMieScattering0", static_cast<float>(in.Table.MieScatteringSeaLevel));
  program->SetUniformf(
    "lightPhaseConstant", static_cast<float>(this->MultipleScattering / (4.0 * nimbus::kPi)));
}

// True when this frame draws the lights' shafts by ray marching on fewer pixels than
// the march (LightShaftDownsampling > 1), in their own pass.
bool vtkNimbusCloudVolumeMapper::ShaftsApart(const FrameState& frame) const
{
  return !frame.Lights.empty() && this->LightShaftMethod == LightShaftsByRayMarching &&
    this->LightShaftDownsampling > 1 && frame.Atmosphere;
}

// The lights' shafts by ray marching on 1 / LightShaftDownsampling of the pixels per
// side (cloudLightShaftsFS.glsl), then added to the accumulation at every pixel with
// depth-aware weights (cloudLightShaftsUpsampleFS.glsl): the shafts are smooth except
// where a ray's end jumps (a silhouette), and the weights follow the ends there.
void vtkNimbusCloudVolumeMapper::RenderLightShafts(const FrameState& frame)
{
  if (!this->ShaftsApart(frame))
  {
    return;
  }
  Internals& in = *this->Internal;
  in.Timer.Begin("lights' shafts");
  const int s = this->LightShaftDownsampling;
  const int w = std::max((frame.Level.Width + s - 1) / s, 1);
  const int h = std::max((frame.Level.Height + s - 1) / s, 1);
  EnsureTexture2D(in.ShaftsImage, frame.Window, w, h, 4, false);
  in.CloudSpanImage->Activate();
  DrawInto(in.ShaftsFramebuffer, in.ShaftsImage, frame.Window);
  frame.State->vtkglViewport(0, 0, w, h);
  frame.State->vtkglDisable(GL_BLEND);
  vtkShaderProgram* program = in.Ready(in.ShaftsPass, cloudLightShaftsFS, true, true);
  this->SetCommonUniforms(program, frame);
  this->SetCloudLightUniforms(program, frame);
  program->SetUniformi("cloudSpan", in.CloudSpanImage->GetTextureUnit());
  program->SetUniformi("lightSamples", this->LightSamples);
  program->SetUniformf("lightsMieG", static_cast<float>(frame.Settings.Air.MieG));
  in.ShaftsPass->Render();
  ++in.PassesLastRender;
  // Added to the accumulation's radiance (its transmittance kept).
  in.ShaftsImage->Activate();
  DrawInto(in.ShaftsFramebuffer, in.Accumulation, frame.Window);
  frame.State->vtkglViewport(0, 0, frame.Level.Width, frame.Level.Height);
  frame.State->vtkglEnable(GL_BLEND);
  frame.State->vtkglBlendFuncSeparate(GL_ONE, GL_ONE, GL_ZERO, GL_ONE);
  vtkShaderProgram* upsample = in.Ready(in.ShaftsUpsamplePass, cloudLightShaftsUpsampleFS);
  upsample->SetUniformi("shafts", in.ShaftsImage->GetTextureUnit());
  upsample->SetUniformi("cloudSpan", in.CloudSpanImage->GetTextureUnit());
  in.ShaftsUpsamplePass->Render();
  ++in.PassesLastRender;
  frame.State->vtkglDisable(GL_BLEND);
  in.ShaftsFramebuffer->RemoveColorAttachment(0);
}

// The cloud's transmittance toward each view light at the texels of a grid over the
// density's box (at most 64 per axis; cloudLightDepthFS.glsl), lights stacked along the
// third axis: redrawn when the density, the lights or the optics change, so a view ray's
// sample reads one texel instead of marching toward the light. An empty density (fog
// around geometry, no cloud) or LightCloudSteps 0: none.
void vtkNimbusCloudVolumeMapper::UpdateLightCloudVolume(FrameState& frame)
{
  Internals& in = *this->Internal;
  frame.LightCloudVolume = false;
  if (frame.Lights.empty() || this->LightCloudSteps <= 0 || !(in.DensityMaximum > 0.0))
  {
    return;
  }
  int dims[3];
  in.Density.GetDimensions(dims);
  int grid[3];
  for (int a = 0; a < 3; ++a)
  {
    grid[a] = std::clamp(dims[a], 2, 64);
  }
  const int lights = static_cast<int>(frame.Lights.size());
  std::vector<double> key{ static_cast<double>(in.Density.GetNumberOfUploads()),
    this->ExtinctionPerDensity, frame.Settings.MetresPerUnit,
    static_cast<double>(this->LightCloudSteps) };
  key.insert(key.end(), frame.WorldToBox.begin(), frame.WorldToBox.end());
  for (const nimbus::ViewLight& light : frame.Lights)
  {
    key.insert(key.end(), light.Position.begin(), light.Position.end());
  }
  if (key != in.LightCloudKey || !in.LightCloudVolume->GetHandle())
  {
    in.Timer.Begin("lights' cloud transmittance");
    ResetTexture(in.LightCloudVolume, frame.Window, true);
    if (!in.LightCloudVolume->Allocate3D(grid[0], grid[1], grid[2] * lights, 1, VTK_FLOAT))
    {
      throw std::runtime_error("could not allocate the lights' transmittance volume");
    }
    vtkShaderProgram* program = in.Ready(in.LightCloudPass, cloudLightDepthFS);
    this->SetCommonUniforms(program, frame);
    vtkNew<vtkMatrix4x4> boxToWorld;
    for (int r = 0; r < 4; ++r)
    {
      for (int c = 0; c < 4; ++c)
      {
        boxToWorld->SetElement(r, c, frame.WorldToBox[c * 4 + r]); // column-major
      }
    }
    boxToWorld->Invert();
    std::array<float, 16> boxToWorldColumns{};
    for (int r = 0; r < 4; ++r)
    {
      for (int c = 0; c < 4; ++c)
      {
        boxToWorldColumns[c * 4 + r] = static_cast<float>(boxToWorld->GetElement(r, c));
      }
    }
    program->SetUniformMatrix4x4("boxToWorld", boxToWorldColumns.data());
    program->SetUniformi("cloudSteps", this->LightCloudSteps);
    frame.State->vtkglDisable(GL_BLEND);
    frame.State->vtkglViewport(0, 0, grid[0], grid[1]);
    frame.State->PushFramebufferBindings();
    in.LightCloudFramebuffer->SetContext(frame.Window);
    in.LightCloudFramebuffer->Bind(GL_FRAMEBUFFER);
    for (int i = 0; i < lights; ++i)
    {
      const float position[3] = { static_cast<float>(frame.Lights[i].Position[0]),
        static_cast<float>(frame.Lights[i].Position[1]),
        static_cast<float>(frame.Lights[i].Position[2]) };
      program->SetUniform3f("sourcePosition", position);
      for (int z = 0; z < grid[2]; ++z)
      {
        in.LightCloudFramebuffer->RemoveColorAttachment(0);
        in.LightCloudFramebuffer->AddColorAttachment(
          0, in.LightCloudVolume, static_cast<unsigned int>(i * grid[2] + z));
        in.LightCloudFramebuffer->ActivateDrawBuffer(0);
        program->SetUniformf("sliceW", (z + 0.5f) / static_cast<float>(grid[2]));
        in.LightCloudPass->Render();
      }
    }
    in.LightCloudFramebuffer->RemoveColorAttachment(0);
    frame.State->PopFramebufferBindings();
    in.LightCloudKey = std::move(key);
    in.LightCloudSlices = grid[2];
    ++in.LightCloudBuilds;
  }
  in.LightCloudVolume->Activate();
  frame.LightCloudVolume = true;
}

// 002 §6.2's virtual planes: NumberOfVirtualPlanes planes parallel to the screen from
// the near clipping plane to the far side of the lit region, spaced geometrically (the
// paper places them "in front of the viewpoint"; a light's 1/d^2 and the view's
// perspective both ask for more planes near the eye), drawn back to front into their
// own target (cloudVirtualPlanesFS.glsl), which the composite adds.
void vtkNimbusCloudVolumeMapper::RenderVirtualPlanes(const FrameState& frame)
{
  if (frame.Lights.empty() || this->LightShaftMethod != LightShaftsByVirtualPlanes)
  {
    return;
  }
  Internals& in = *this->Internal;
  in.Timer.Begin("virtual planes");
  // The lit region's farthest depth along the view's axis.
  double farthest = 0.0;
  for (int i = 0; i < 8; ++i)
  {
    const double corner[3] = { frame.LightRegion[(i & 1) ? 1 : 0],
      frame.LightRegion[(i & 2) ? 3 : 2], frame.LightRegion[(i & 4) ? 5 : 4] };
    double depth = 0.0;
    for (int a = 0; a < 3; ++a)
    {
      depth += (corner[a] - frame.Eye[a]) * frame.ViewForward[a];
    }
    farthest = std::max(farthest, depth);
  }
  farthest = std::min(farthest, static_cast<double>(frame.ClippingRange[1]));
  const double nearest = std::max(static_cast<double>(frame.ClippingRange[0]), 1e-4 * farthest);
  this->EnsureImageTarget(in.LightsImage, frame);
  DrawInto(in.LightsFramebuffer, in.LightsImage, frame.Window);
  frame.State->vtkglViewport(0, 0, frame.Level.Width, frame.Level.Height);
  frame.State->vtkglClearColor(0.0, 0.0, 0.0, 1.0);
  frame.State->vtkglClear(GL_COLOR_BUFFER_BIT);
  if (!(farthest > nearest))
  {
    return;
  }
  UseSliceBlend(frame.State, true);
  vtkShaderProgram* program = in.Ready(in.PlanesPass, cloudVirtualPlanesFS, true, true);
  this->SetCommonUniforms(program, frame);
  this->SetCloudLightUniforms(program, frame);
  program->SetUniformf("lightsMieG", static_cast<float>(frame.Settings.Air.MieG));
  const int planes = this->NumberOfVirtualPlanes;
  const double ratio = std::pow(farthest / nearest, 1.0 / planes);
  for (int k = planes - 1; k >= 0; --k)
  {
    // Plane k stands for the slab [nearest r^k, nearest r^(k+1)], at its middle.
    const double front = nearest * std::pow(ratio, k), back = front * ratio;
    program->SetUniformf("planeDepth", static_cast<float>(0.5 * (front + back)));
    program->SetUniformf("planeSpacing", static_cast<float>(back - front));
    in.PlanesPass->Render();
    ++in.PassesLastRender;
  }
  frame.State->vtkglDisable(GL_BLEND);
}

//------------------------------------------------------------------------------
void vtkNimbusCloudVolumeMapper::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "ExtinctionPerDensity: " << this->ExtinctionPerDensity << " 1/m\n";
  os << indent << "Albedo: " << this->Albedo << "\n";
  os << indent << "TemperatureEmission: " << (this->TemperatureEmission ? "on" : "off")
     << " (array \"" << this->EmissionTemperatureArray << "\", " << this->EmissionRadiancePerMetre
     << " Y/(sr m) per density at " << this->EmissionReferenceTemperatureKelvin << " K)\n";
  os << indent << "LightningDeltaMView: " << (this->LightningDeltaMView ? "on" : "off") << "\n";
  os << indent << "CloudG: " << this->CloudG << "\n";
  os << indent << "MultipleScattering (k_multi): " << this->MultipleScattering << "\n";
  static const char* methods[4] = { "None", "Octaves", "ReferencePatterns", "DiscreteDirections" };
  os << indent << "MultipleScatteringMethod: " << methods[this->MultipleScatteringMethod] << "\n";
  os << indent << "MultipleScatteringOrders: " << this->MultipleScatteringOrders << "\n";
  os << indent << "MultipleScatteringDownsampling: " << this->MultipleScatteringDownsampling
     << (this->MultipleScatteringDownsampling == 0 ? " (automatic)" : "") << "\n";
  os << indent << "MultipleScatteringDirections: " << this->MultipleScatteringDirections << "\n";
  os << indent << "SkyLight: " << (this->SkyLight ? "on" : "off") << "\n";
  os << indent << "Octaves: " << this->Octaves << " (scales a " << this->OctaveExtinctionScale
     << ", b " << this->OctaveScatteringScale << ", c " << this->OctaveAsymmetryScale << ")\n";
  os << indent << "PatternOrders: " << this->PatternOrders
     << ", PatternRadius: " << this->PatternRadius
     << ", PatternContribution: " << this->PatternContribution
     << ", PatternSelection: " << this->PatternSelection << "\n";
  os << indent << "MultipleScatteringMemoryBudgetMiB: " << this->MultipleScatteringMemoryBudgetMiB
     << (this->MultipleScatteringMemoryBudgetMiB > 0.0 ? "" : " (default)") << "\n";
  os << indent << "SunAzimuthDegrees: " << this->SunAzimuthDegrees << "\n";
  os << indent << "SunElevationDegrees: " << this->SunElevationDegrees << "\n";
  os << indent << "SunIlluminance: " << this->SunIlluminance << "\n";
  os << indent << "SunTemperatureKelvin: " << this->SunTemperatureKelvin << "\n";
  os << indent << "Atmosphere: " << this->Atmosphere << "\n";
  os << indent << "MieScatteringPerMetre: " << this->MieScatteringPerMetre << "\n";
  os << indent << "MieG: " << this->MieG << "\n";
  os << indent << "RayleighScatteringPerMetre: " << this->RayleighScatteringPerMetre << "\n";
  os << indent << "SceneAltitudeMetres: " << this->SceneAltitudeMetres << "\n";
  os << indent << "AirMultipleScattering: " << (this->AirMultipleScattering ? "on" : "off") << "\n";
  os << indent << "Ground: " << this->Ground << "\n";
  os << indent << "PieceCompositing: " << this->PieceCompositing << "\n";
  os << indent << "DrawOutsideRegions: " << this->DrawOutsideRegions << "\n";
  os << indent << "PieceBackground: " << this->PieceBackground[0] << ", "
     << this->PieceBackground[1] << ", " << this->PieceBackground[2] << "\n";
  os << indent << "SlicingBounds: " << this->SlicingBounds[0] << " .. " << this->SlicingBounds[1]
     << ", " << this->SlicingBounds[2] << " .. " << this->SlicingBounds[3] << ", "
     << this->SlicingBounds[4] << " .. " << this->SlicingBounds[5] << "\n";
  os << indent << "ViewCoverBounds: " << this->ViewCoverBounds[0] << " .. "
     << this->ViewCoverBounds[1] << ", " << this->ViewCoverBounds[2] << " .. "
     << this->ViewCoverBounds[3] << ", " << this->ViewCoverBounds[4] << " .. "
     << this->ViewCoverBounds[5] << "\n";
  os << indent << "ExternalDensity: " << this->Internal->ExternalDensity.GetPointer() << "\n";
  os << indent << "GroundHeight: " << this->GroundHeight << "\n";
  os << indent << "GroundBelowData: " << this->GroundBelowData << "\n";
  os << indent << "UpAxis: " << nimbus::UpAxisName(static_cast<nimbus::UpAxis>(this->UpAxis))
     << "\n";
  os << indent << "GroundAlbedo: " << this->GroundAlbedo << "\n";
  os << indent << "Shafts: " << this->Shafts << "\n";
  os << indent << "RenderingMethod: "
     << (this->RenderingMethod == RayMarching ? "RayMarching" : "ShadowViewSlicing") << "\n";
  os << indent << "RayMarchStepTexels: " << this->RayMarchStepTexels << "\n";
  os << indent << "TimePasses: " << (this->TimePasses ? "On" : "Off") << "\n";
  os << indent << "NumberOfSlices: " << this->NumberOfSlices << "\n";
  os << indent << "SliceAngleRatio (a): " << this->SliceAngleRatio << "\n";
  os << indent << "ShadowSurfaceSize: " << this->ShadowSurfaceSize << "\n";
  os << indent << "FrameBudgetMilliseconds: " << this->FrameBudgetMilliseconds << " ms\n";
  os << indent << "Quality: " << this->Quality << "\n";
  os << indent << "InteractiveUpdateRate: " << this->InteractiveUpdateRate << " frames/s\n";
  os << indent << "AtmosphereSteps: " << this->AtmosphereSteps << "\n";
  os << indent << "SliceJitter: " << this->SliceJitter << "\n";
  os << indent << "MetresPerUnit: " << this->MetresPerUnit << "\n";
  os << indent << "Exposure: " << this->Exposure << "\n";
  os << indent << "EncodeSrgb: " << this->EncodeSrgb << "\n";
  os << indent << "Unlit: " << this->Unlit << "\n";
  os << indent << "CaptureRadiance: " << this->CaptureRadiance << "\n";
  os << indent << "MaximumTextureSize: " << this->MaximumTextureSize << "\n";
  os << indent << "TextureMemoryBudgetMiB: " << this->TextureMemoryBudgetMiB
     << (this->TextureMemoryBudgetMiB > 0.0 ? "" : " (default)") << "\n";
  os << indent << "UseSceneSky: " << this->UseSceneSky << "\n";
  os << indent << "SkyBackground: " << this->SkyBackground << "\n";
}
