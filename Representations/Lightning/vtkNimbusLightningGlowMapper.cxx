#include "vtkNimbusLightningGlowMapper.h"

#include "FiniteSetters.h"

#include "Lightning.h"

#include "FrameTexture.h"
#include "lightningGlowCompositeFS.h"
#include "lightningGlowSplatFS.h"
#include "lightningGlowSplatVS.h"

#include "vtkActor.h"
#include "vtkAlgorithm.h"
#include "vtkDataArray.h"
#include "vtkHardwareSelector.h"
#include "vtkInformation.h"
#include "vtkMatrix3x3.h"
#include "vtkMatrix4x4.h"
#include "vtkObjectFactory.h"
#include "vtkOpenGLActor.h"
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
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkShaderProgram.h"
#include "vtkTextureObject.h"
#include "vtk_glew.h"

#include <algorithm>
#include <cmath>
#include <vector>

struct vtkNimbusLightningGlowMapper::Internals
{
  // The splats: six vertices per source, each (x, y, z, I, corner x, corner y).
  vtkNew<vtkOpenGLBufferObject> Vertices;
  vtkNew<vtkOpenGLVertexArrayObject> Layout;
  vtkShaderProgram* SplatProgram = nullptr;  // owned by the window's shader cache
  vtkShaderProgram* LayoutProgram = nullptr; // the program Layout was set up for
  int VertexCount = 0;
  vtkMTimeType VerticesTime = 0; // the input's and the mapper's time when uploaded
  // The float sum of the splats and a copy of the scene's depth, at the renderer's size.
  vtkNew<vtkTextureObject> Sum;
  vtkNew<vtkTextureObject> Depth;
  vtkNew<vtkOpenGLFramebufferObject> Framebuffer;
  std::unique_ptr<vtkOpenGLQuadHelper> Composite;
  vtkOpenGLRenderWindow* Window = nullptr;
  bool WarnedMultisampling = false;

  void Release(vtkWindow* window)
  {
    if (window)
    {
      this->Sum->ReleaseGraphicsResources(window);
      this->Depth->ReleaseGraphicsResources(window);
      this->Framebuffer->ReleaseGraphicsResources(window);
      if (this->Composite)
      {
        this->Composite->ReleaseGraphicsResources(window);
      }
    }
    this->Composite.reset();
    this->Vertices->ReleaseGraphicsResources();
    this->Layout->ReleaseGraphicsResources();
    this->SplatProgram = nullptr;
    this->LayoutProgram = nullptr;
    this->VertexCount = 0;
    this->VerticesTime = 0;
    this->Window = nullptr;
  }
};

vtkStandardNewMacro(vtkNimbusLightningGlowMapper);

// Setters with a range refuse NaN and infinity at once (the value is kept) and clamp
// finite values (Common/FiniteSetters.h).
nimbusDefineFiniteSetter(vtkNimbusLightningGlowMapper, AirScatteringPerMetre);
nimbusDefineFiniteSetter(vtkNimbusLightningGlowMapper, GlowRadiusMetres);
nimbusDefineFiniteSetter(vtkNimbusLightningGlowMapper, ChannelRadiusMetres);
nimbusDefineFiniteSetter(vtkNimbusLightningGlowMapper, Exposure);
nimbusDefineFiniteSetter(vtkNimbusLightningGlowMapper, MetresPerUnit);

vtkNimbusLightningGlowMapper::vtkNimbusLightningGlowMapper()
  : Internal(new Internals)
{
}

// The textures, framebuffer and quad free themselves (their resource callbacks); the
// window, if any, may be gone already.
vtkNimbusLightningGlowMapper::~vtkNimbusLightningGlowMapper() = default;

void vtkNimbusLightningGlowMapper::ReleaseGraphicsResources(vtkWindow* window)
{
  this->Internal->Release(window);
  this->Superclass::ReleaseGraphicsResources(window);
}

void vtkNimbusLightningGlowMapper::Render(vtkRenderer* renderer, vtkActor* actor)
{
  if (renderer->GetSelector() || renderer->GetRenderWindow()->CheckAbortStatus())
  {
    return; // the glow is light, not a surface to pick
  }
  int port = 0; // the producer's port (the lightning source's point sources are its port 1)
  vtkAlgorithm* producer =
    this->GetNumberOfInputConnections(0) ? this->GetInputAlgorithm(0, 0, port) : nullptr;
  if (!this->Static && producer)
  {
    producer->Update(port);
  }
  vtkPolyData* input = this->GetInput();
  vtkDataArray* intensity = input ? input->GetPointData()->GetArray("intensity") : nullptr;
  if (!intensity || !input->GetPoints() || input->GetNumberOfPoints() == 0)
  {
    return; // no sources (before the flash): no glow
  }
  Internals& in = *this->Internal;
  auto* window = vtkOpenGLRenderWindow::SafeDownCast(renderer->GetRenderWindow());
  if (!window)
  {
    return;
  }
  if (in.Window && in.Window != window)
  {
    in.Release(in.Window);
  }
  in.Window = window;

  this->UpdateSplatVertices(input, intensity);
  if (in.VertexCount == 0)
  {
    return;
  }

  vtkOpenGLState* state = static_cast<vtkOpenGLRenderer*>(renderer)->GetState();
  int width = 0, height = 0, x0 = 0, y0 = 0;
  renderer->GetTiledSizeAndOrigin(&width, &height, &x0, &y0);
  if (width <= 0 || height <= 0)
  {
    return;
  }
  vtkOpenGLState::ScopedglViewport viewportSaver(state);
  vtkOpenGLState::ScopedglScissor scissorSaver(state);
  vtkOpenGLState::ScopedglEnableDisable scissorTestSaver(state, GL_SCISSOR_TEST);
  vtkOpenGLState::ScopedglEnableDisable depthTestSaver(state, GL_DEPTH_TEST);
  vtkOpenGLState::ScopedglEnableDisable blendSaver(state, GL_BLEND);
  vtkOpenGLState::ScopedglEnableDisable cullSaver(state, GL_CULL_FACE);
  vtkOpenGLState::ScopedglBlendFuncSeparate blendFuncSaver(state);
  vtkOpenGLState::ScopedglDepthMask depthMaskSaver(state);
  vtkOpenGLState::ScopedglDepthFunc depthFuncSaver(state);
  vtkOpenGLState::ScopedglClearColor clearColorSaver(state);
  vtkOpenGLState::ScopedglColorMask colorMaskSaver(state);

  // The scene's depth so far (opaque geometry drawn before the glow), copied from the
  // framebuffer the frame is drawn in.
  GLint frame = 0;
  glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &frame);
  state->PushFramebufferBindings();
  state->vtkglBindFramebuffer(GL_READ_FRAMEBUFFER, frame);
  nimbus::EnsureFrameTexture(in.Sum, window, width, height, nimbus::FrameTextureFormat::Float);
  nimbus::EnsureFrameTexture(in.Depth, window, width, height, nimbus::FrameTextureFormat::Depth);
  const int samples = nimbus::CopySceneDepth(in.Depth, x0, y0, width, height);
  if (samples != 0 && !in.WarnedMultisampling)
  {
    vtkWarningMacro("The render window is multisampled (MultiSamples = "
      << samples << "): opaque geometry will not hide the lightning glow. Set MultiSamples to 0.");
    in.WarnedMultisampling = true;
  }

  // The splats, summed in float.
  nimbus::BeginFrameTarget(in.Framebuffer, in.Sum, in.Depth, window, width, height, samples == 0);
  state->vtkglEnable(GL_DEPTH_TEST);
  state->vtkglDepthFunc(GL_LEQUAL);
  state->vtkglDepthMask(GL_FALSE);
  state->vtkglDisable(GL_CULL_FACE);
  state->vtkglEnable(GL_BLEND);
  state->vtkglBlendFuncSeparate(GL_ONE, GL_ONE, GL_ONE, GL_ONE);

  this->DrawSplats(renderer, actor, window);
  in.Framebuffer->RemoveDepthAttachment();

  // The sum added to the frame once.
  state->PopFramebufferBindings();
  state->vtkglViewport(x0, y0, width, height);
  state->vtkglDisable(GL_DEPTH_TEST);
  state->vtkglBlendFuncSeparate(GL_ONE, GL_ONE, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
  if (!in.Composite)
  {
    in.Composite =
      std::make_unique<vtkOpenGLQuadHelper>(window, nullptr, lightningGlowCompositeFS, "");
  }
  else
  {
    window->GetShaderCache()->ReadyShaderProgram(in.Composite->Program);
  }
  if (in.Composite->Program)
  {
    in.Sum->Activate();
    in.Composite->Program->SetUniformi("glowSum", in.Sum->GetTextureUnit());
    in.Composite->Render();
    in.Sum->Deactivate();
  }
}

// The splats' vertices (six corners per lit source: position, intensity, corner),
// uploaded again when the input or the mapper changed.
void vtkNimbusLightningGlowMapper::UpdateSplatVertices(vtkPolyData* input, vtkDataArray* intensity)
{
  Internals& in = *this->Internal;
  const vtkMTimeType time = std::max(input->GetMTime(), this->GetMTime());
  if (time != in.VerticesTime || !in.Vertices->GetHandle())
  {
    static const float corners[6][2] = { { -1, -1 }, { 1, -1 }, { 1, 1 }, { -1, -1 }, { 1, 1 },
      { -1, 1 } };
    std::vector<float> vertices;
    vertices.reserve(static_cast<std::size_t>(input->GetNumberOfPoints()) * 36);
    for (vtkIdType i = 0; i < input->GetNumberOfPoints(); ++i)
    {
      const double value = intensity->GetComponent(i, 0);
      if (!(value > 0.0) || !std::isfinite(value))
      {
        continue; // dark (or invalid) sources add nothing
      }
      double p[3];
      input->GetPoint(i, p);
      for (const auto& corner : corners)
      {
        vertices.insert(vertices.end(),
          { static_cast<float>(p[0]), static_cast<float>(p[1]), static_cast<float>(p[2]),
            static_cast<float>(value), corner[0], corner[1] });
      }
    }
    in.VertexCount = static_cast<int>(vertices.size() / 6);
    if (in.VertexCount > 0)
    {
      in.Vertices->Upload(vertices, vtkOpenGLBufferObject::ArrayBuffer);
    }
    in.VerticesTime = time;
  }
}

// The splats into the bound float target: L(b) = sigma_s I / (4 b) per source.
void vtkNimbusLightningGlowMapper::DrawSplats(
  vtkRenderer* renderer, vtkActor* actor, vtkOpenGLRenderWindow* window)
{
  Internals& in = *this->Internal;
  in.SplatProgram =
    window->GetShaderCache()->ReadyShaderProgram(lightningGlowSplatVS, lightningGlowSplatFS, "");
  vtkShaderProgram* program = in.SplatProgram;
  if (program)
  {
    if (in.LayoutProgram != program)
    {
      in.Layout->ShaderProgramChanged(); // (deletes the vertex array: before Bind)
      in.Layout->Bind();
      const int stride = 6 * sizeof(float);
      in.Layout->AddAttributeArray(
        program, in.Vertices, "sourceMC", 0, stride, VTK_FLOAT, 4, false);
      in.Layout->AddAttributeArray(
        program, in.Vertices, "cornerIn", 4 * sizeof(float), stride, VTK_FLOAT, 2, false);
      in.LayoutProgram = program;
    }
    else
    {
      in.Layout->Bind();
    }
    vtkMatrix4x4* wcvc = nullptr;
    vtkMatrix4x4* vcdc = nullptr;
    vtkMatrix4x4* wcdc = nullptr;
    vtkMatrix3x3* normals = nullptr;
    static_cast<vtkOpenGLCamera*>(renderer->GetActiveCamera())
      ->GetKeyMatrices(renderer, wcvc, normals, vcdc, wcdc);
    vtkNew<vtkMatrix4x4> mcvc;
    mcvc->DeepCopy(wcvc);
    if (auto* glActor = vtkOpenGLActor::SafeDownCast(actor))
    {
      if (!actor->GetIsIdentity())
      {
        vtkMatrix4x4* mcwc = nullptr;
        vtkMatrix3x3* actorNormals = nullptr;
        glActor->GetKeyMatrices(mcwc, actorNormals);
        vtkMatrix4x4::Multiply4x4(mcwc, wcvc, mcvc);
      }
    }
    // L(b) = sigma_s I / (4 b) (Physics/Lightning.h) with b = (the splat's offset) x R:
    // the gain at offset 1 for I = 1, the offset floored at the channel's radius.
    const double radius = this->GlowRadiusMetres;
    const double gain =
      nimbus::LightningGlowRadiance(this->AirScatteringPerMetre, 1.0, radius) * this->Exposure;
    program->SetUniformMatrix("MCVCMatrix", mcvc);
    program->SetUniformMatrix("VCDCMatrix", vcdc);
    program->SetUniformf("radius", static_cast<float>(radius / this->MetresPerUnit));
    program->SetUniformf("gain", static_cast<float>(gain));
    program->SetUniformf(
      "innerLimit", static_cast<float>(std::min(1.0, this->ChannelRadiusMetres / radius)));
    const float color[3] = { static_cast<float>(std::clamp(this->Color[0], 0.0, 1.0)),
      static_cast<float>(std::clamp(this->Color[1], 0.0, 1.0)),
      static_cast<float>(std::clamp(this->Color[2], 0.0, 1.0)) };
    program->SetUniform3f("glowColor", color);
    glDrawArrays(GL_TRIANGLES, 0, in.VertexCount);
    in.Layout->Release();
  }
}

void vtkNimbusLightningGlowMapper::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "AirScatteringPerMetre: " << this->AirScatteringPerMetre << " /m\n";
  os << indent << "GlowRadiusMetres: " << this->GlowRadiusMetres << "\n";
  os << indent << "ChannelRadiusMetres: " << this->ChannelRadiusMetres << "\n";
  os << indent << "Exposure: " << this->Exposure << "\n";
  os << indent << "Color: " << this->Color[0] << ", " << this->Color[1] << ", " << this->Color[2]
     << "\n";
  os << indent << "MetresPerUnit: " << this->MetresPerUnit << "\n";
}
