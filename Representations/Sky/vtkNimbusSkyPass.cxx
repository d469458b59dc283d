#include "vtkNimbusSkyPass.h"

#include "vtkNimbusSky.h"
#include "vtkNimbusSkyPassFS.h"

#include "Sky.h"
#include "SkyViewTextures.h"

#include "vtkCamera.h"
#include "vtkMath.h"
#include "vtkMatrix4x4.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkOpenGLError.h"
#include "vtkOpenGLFramebufferObject.h"
#include "vtkOpenGLQuadHelper.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkOpenGLState.h"
#include "vtkRenderState.h"
#include "vtkRenderer.h"
#include "vtkShaderProgram.h"
#include "vtkTextureObject.h"

#include <algorithm>
#include <array>
#include <memory>
#include <stdexcept>
#include <vector>

vtkStandardNewMacro(vtkNimbusSkyPass);
vtkCxxSetObjectMacro(vtkNimbusSkyPass, Sky, vtkNimbusSky);

struct vtkNimbusSkyPass::Internals
{
  vtkOpenGLFramebufferObject* Framebuffer = nullptr;
  vtkTextureObject* Color = nullptr;
  vtkTextureObject* Depth = nullptr;
  nimbus::SkyViewTextures SkyView;
  std::array<vtkTextureObject*, 4> AerialTextures{ { nullptr, nullptr, nullptr, nullptr } };
  const nimbus::AerialPerspectiveLut* Aerial = nullptr; // the uploaded table
  int AerialBuilds = -1;
  std::unique_ptr<vtkOpenGLQuadHelper> Quad;

  void Release(vtkWindow* w)
  {
    auto drop = [w](vtkTextureObject*& t)
    {
      if (t)
      {
        t->ReleaseGraphicsResources(w);
        t->Delete();
        t = nullptr;
      }
    };
    drop(this->Color);
    drop(this->Depth);
    this->SkyView.Release(w);
    for (auto& t : this->AerialTextures)
    {
      drop(t);
    }
    if (this->Framebuffer)
    {
      this->Framebuffer->ReleaseGraphicsResources(w);
      this->Framebuffer->Delete();
      this->Framebuffer = nullptr;
    }
    if (this->Quad)
    {
      this->Quad->ReleaseGraphicsResources(w);
      this->Quad.reset();
    }
    this->Aerial = nullptr;
    this->AerialBuilds = -1;
  }
};

vtkNimbusSkyPass::vtkNimbusSkyPass()
  : Internal(new Internals)
{
}

vtkNimbusSkyPass::~vtkNimbusSkyPass()
{
  this->SetSky(nullptr);
}

void vtkNimbusSkyPass::ReleaseGraphicsResources(vtkWindow* w)
{
  this->Superclass::ReleaseGraphicsResources(w);
  this->Internal->Release(w);
}

void vtkNimbusSkyPass::Render(const vtkRenderState* s)
{
  // No exception leaves a render or a pipeline request (VTK does not catch).
  try
  {
    vtkOpenGLClearErrorMacro();
    this->NumberOfRenderedProps = 0;
    if (!this->DelegatePass)
    {
      vtkErrorMacro(
        "vtkNimbusSkyPass needs a delegate pass (SetDelegatePass, e.g. vtkRenderStepsPass)");
      return;
    }
    if (!this->Sky)
    {
      vtkErrorMacro("vtkNimbusSkyPass needs a sky (SetSky)");
      return;
    }
    vtkRenderer* renderer = s->GetRenderer();
    auto* window = static_cast<vtkOpenGLRenderWindow*>(renderer->GetRenderWindow());
    int x, y, width, height;
    renderer->GetTiledSizeAndOrigin(&width, &height, &x, &y);
    this->RenderDelegate(s, width, height);
    double eye[3];
    vtkNew<vtkMatrix4x4> inverse;
    nimbus::SkyViewTextures::CameraInUpFrame(this->Sky, renderer->GetActiveCamera(),
      static_cast<double>(width) / std::max(1, height), eye, inverse);
    const double cameraAltitude = nimbus::SkyViewTextures::CameraAltitude(this->Sky, eye[2]);
    if (this->UpdateTables(window, cameraAltitude))
    {
      this->DrawSky(renderer, x, y, width, height);
    }
    vtkOpenGLCheckErrorMacro("failed after vtkNimbusSkyPass::Render");
  }
  catch (const std::exception& error)
  {
    vtkErrorMacro("The sky pass did not finish: " << error.what());
  }
  catch (...)
  {
    vtkErrorMacro("The sky pass did not finish: an unknown exception.");
  }
  return;
}

void vtkNimbusSkyPass::RenderDelegate(const vtkRenderState* s, int width, int height)
{
  Internals& in = *this->Internal;
  vtkRenderer* r = s->GetRenderer();
  auto* window = static_cast<vtkOpenGLRenderWindow*>(r->GetRenderWindow());
  vtkOpenGLState* state = window->GetState();
  if (!in.Color)
  {
    in.Color = nimbus::SkyViewTextures::NewLinearTexture(window);
    in.Color->Allocate2D(width, height, 4, VTK_UNSIGNED_CHAR);
    in.Depth = nimbus::SkyViewTextures::NewLinearTexture(window);
    in.Depth->SetMinificationFilter(vtkTextureObject::Nearest);
    in.Depth->SetMagnificationFilter(vtkTextureObject::Nearest);
    in.Depth->AllocateDepth(width, height, vtkTextureObject::Fixed24);
    in.Framebuffer = vtkOpenGLFramebufferObject::New();
    in.Framebuffer->SetContext(window);
  }
  in.Color->Resize(width, height);
  in.Depth->Resize(width, height);
  state->PushFramebufferBindings();
  in.Framebuffer->Bind();
  in.Framebuffer->AddColorAttachment(0, in.Color);
  in.Framebuffer->ActivateDrawBuffers(1);
  in.Framebuffer->AddDepthAttachment(in.Depth);
  in.Framebuffer->StartNonOrtho(width, height);
  state->vtkglViewport(0, 0, width, height);
  state->vtkglScissor(0, 0, width, height);
  vtkRenderState inner(r);
  inner.SetPropArrayAndCount(s->GetPropArray(), s->GetPropArrayCount());
  inner.SetFrameBuffer(in.Framebuffer);
  // Clear to transparent black, so that translucent props (volumes, clouds) leave
  // their coverage in alpha and the sky is composited behind them.
  double background[3];
  r->GetBackground(background);
  const double backgroundAlpha = r->GetBackgroundAlpha();
  const bool gradient = r->GetGradientBackground();
  r->SetBackground(0.0, 0.0, 0.0);
  r->SetBackgroundAlpha(0.0);
  r->GradientBackgroundOff();
  this->DelegatePass->Render(&inner);
  r->SetBackground(background);
  r->SetBackgroundAlpha(backgroundAlpha);
  r->SetGradientBackground(gradient);
  this->NumberOfRenderedProps += this->DelegatePass->GetNumberOfRenderedProps();
  state->PopFramebufferBindings();
}

bool vtkNimbusSkyPass::UpdateTables(vtkOpenGLRenderWindow* window, double cameraAltitude)
{
  Internals& in = *this->Internal;
  vtkNimbusSky* sky = this->Sky;
  const nimbus::AerialPerspectiveLut* aerial = nullptr;
  std::string tableError;
  try
  {
    aerial = &sky->GetAerialPerspectiveLut(cameraAltitude);
  }
  catch (const std::exception& e)
  {
    tableError = e.what();
  }
  if (!aerial || !in.SkyView.Update(window, sky, cameraAltitude, tableError))
  {
    vtkErrorMacro("sky tables: " << tableError);
    return false;
  }
  if (in.AerialBuilds != sky->GetAerialBuilds() || in.Aerial != aerial)
  {
    // The table interleaves (Rayleigh, Mie, isotropic, transmittance) rgb per texel:
    // one 3-D texture each.
    const nimbus::SkyViewMapping& m = aerial->GetMapping();
    const std::size_t texels = static_cast<std::size_t>(aerial->GetSlices()) * m.Rows() * m.Width;
    std::vector<float> part(texels * 3);
    for (int k = 0; k < 4; ++k)
    {
      for (std::size_t i = 0; i < texels; ++i)
      {
        for (int c = 0; c < 3; ++c)
        {
          part[i * 3 + c] = aerial->GetTable()[i * 12 + k * 3 + c];
        }
      }
      if (!in.AerialTextures[k])
      {
        in.AerialTextures[k] = nimbus::SkyViewTextures::NewLinearTexture(window);
      }
      in.AerialTextures[k]->Create3DFromRaw(
        m.Width, m.Rows(), aerial->GetSlices(), 3, VTK_FLOAT, part.data());
    }
    in.AerialBuilds = sky->GetAerialBuilds();
  }
  in.Aerial = aerial;
  return true;
}

void vtkNimbusSkyPass::DrawSky(vtkRenderer* renderer, int x, int y, int width, int height)
{
  Internals& in = *this->Internal;
  auto* window = static_cast<vtkOpenGLRenderWindow*>(renderer->GetRenderWindow());
  vtkShaderProgram* program =
    nimbus::SkyViewTextures::ReadyQuad(window, in.Quad, vtkNimbusSkyPassFS);
  if (!program)
  {
    vtkErrorMacro("vtkNimbusSkyPass: the sky shader did not compile");
    return;
  }
  in.Color->Activate();
  in.Depth->Activate();
  program->SetUniformi("colorTexture", in.Color->GetTextureUnit());
  program->SetUniformi("depthTexture", in.Depth->GetTextureUnit());
  in.SkyView.Activate(program, this->Sky);
  const char* aerialNames[4] = { "aerialRayleigh", "aerialMie", "aerialIsotropic",
    "aerialTransmittance" };
  for (int k = 0; k < 4; ++k)
  {
    in.AerialTextures[k]->Activate();
    program->SetUniformi(aerialNames[k], in.AerialTextures[k]->GetTextureUnit());
  }
  double eye[3];
  vtkNew<vtkMatrix4x4> inverse;
  nimbus::SkyViewTextures::CameraInUpFrame(this->Sky, renderer->GetActiveCamera(),
    static_cast<double>(width) / std::max(1, height), eye, inverse);
  program->SetUniformMatrix("inverseViewProjection", inverse);
  program->SetUniform3f("cameraPosition", eye);
  program->SetUniformf("metresPerUnit", static_cast<float>(this->Sky->GetMetresPerUnit()));
  const nimbus::SkyViewMapping& m = in.Aerial->GetMapping();
  const float aerialTable[4] = { static_cast<float>(m.HorizonZenith), static_cast<float>(m.Width),
    static_cast<float>(m.AboveRows), static_cast<float>(m.BelowRows) };
  program->SetUniform4f("aerialTable", aerialTable);
  const float slices[2] = { static_cast<float>(in.Aerial->GetSlices()),
    static_cast<float>(in.Aerial->GetMaxDistance()) };
  program->SetUniform2f("aerialSlices", slices);
  program->SetUniformi("aerialPerspective", this->AerialPerspective ? 1 : 0);

  vtkOpenGLState* state = window->GetState();
  vtkOpenGLState::ScopedglEnableDisable blendSaver(state, GL_BLEND);
  vtkOpenGLState::ScopedglEnableDisable depthSaver(state, GL_DEPTH_TEST);
  vtkOpenGLState::ScopedglDepthFunc depthFuncSaver(state);
  state->vtkglDisable(GL_BLEND);
  state->vtkglEnable(GL_DEPTH_TEST);
  state->vtkglDepthFunc(GL_ALWAYS);
  state->vtkglDepthMask(GL_TRUE);
  state->vtkglViewport(x, y, width, height);
  state->vtkglScissor(x, y, width, height);
  in.Quad->Render();
  in.Color->Deactivate();
  in.Depth->Deactivate();
  in.SkyView.Deactivate();
  for (auto* t : in.AerialTextures)
  {
    t->Deactivate();
  }
}

void vtkNimbusSkyPass::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Sky: " << this->Sky << "\n";
  os << indent << "AerialPerspective: " << this->AerialPerspective << "\n";
}
