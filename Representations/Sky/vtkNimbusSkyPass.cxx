#include "vtkNimbusSkyPass.h"

#include "vtkNimbusSky.h"
#include "vtkNimbusSkyPassFS.h"

#include "Sky.h"
#include "SkyViewTextures.h"

#include "vtkCamera.h"
#include "vtkMath.h"
#include "vtkMatrix4x4.h"
#include "vtkObjectFactory.h"
#include "vtkOpenGLError.h"
#include "vtkOpenGLFramebufferObject.h"
#include "vtkOpenGLQuadHelper.h"
#include "vtkOpenGLRenderUtilities.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkOpenGLShaderCache.h"
#include "vtkOpenGLState.h"
#include "vtkRenderState.h"
#include "vtkRenderer.h"
#include "vtkShaderProgram.h"
#include "vtkTextureObject.h"

#include <array>
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
  const void* AerialTable = nullptr; // identity of the uploaded table
  int AerialBuilds = -1;
  vtkOpenGLQuadHelper* Quad = nullptr;

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
    delete this->Quad;
    this->Quad = nullptr;
    this->AerialTable = nullptr;
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
  Internals& in = *this->Internal;
  vtkRenderer* r = s->GetRenderer();
  vtkOpenGLRenderWindow* window = static_cast<vtkOpenGLRenderWindow*>(r->GetRenderWindow());
  vtkOpenGLState* state = window->GetState();
  int x, y, w, h;
  r->GetTiledSizeAndOrigin(&w, &h, &x, &y);

  // 1. The delegate into colour + depth textures.
  if (!in.Color)
  {
    in.Color = nimbus::SkyViewTextures::NewLinearTexture(window);
    in.Color->Allocate2D(w, h, 4, VTK_UNSIGNED_CHAR);
    in.Depth = nimbus::SkyViewTextures::NewLinearTexture(window);
    in.Depth->SetMinificationFilter(vtkTextureObject::Nearest);
    in.Depth->SetMagnificationFilter(vtkTextureObject::Nearest);
    in.Depth->AllocateDepth(w, h, vtkTextureObject::Fixed24);
    in.Framebuffer = vtkOpenGLFramebufferObject::New();
    in.Framebuffer->SetContext(window);
  }
  in.Color->Resize(w, h);
  in.Depth->Resize(w, h);
  state->PushFramebufferBindings();
  in.Framebuffer->Bind();
  in.Framebuffer->AddColorAttachment(0, in.Color);
  in.Framebuffer->ActivateDrawBuffers(1);
  in.Framebuffer->AddDepthAttachment(in.Depth);
  in.Framebuffer->StartNonOrtho(w, h);
  state->vtkglViewport(0, 0, w, h);
  state->vtkglScissor(0, 0, w, h);
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

  // 2. Tables (uploaded again only when the sky rebuilt them).
  vtkNimbusSky* sky = this->Sky;
  vtkCamera* camera = r->GetActiveCamera();
  double eye[3];
  camera->GetPosition(eye);
  const double cameraAltitude = nimbus::SkyViewTextures::CameraAltitude(sky, eye[2]);
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
    return;
  }
  const nimbus::SkyViewMapping& am = aerial->GetMapping();
  if (in.AerialBuilds != sky->GetAerialBuilds() || in.AerialTable != aerial)
  {
    const std::size_t texels = static_cast<std::size_t>(aerial->GetSlices()) * am.Rows() * am.Width;
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
        am.Width, am.Rows(), aerial->GetSlices(), 3, VTK_FLOAT, part.data());
    }
    in.AerialBuilds = sky->GetAerialBuilds();
    in.AerialTable = aerial;
  }

  // 3. The full-screen quad.
  if (!in.Quad)
  {
    in.Quad = new vtkOpenGLQuadHelper(window,
      vtkOpenGLRenderUtilities::GetFullScreenQuadVertexShader().c_str(),
      nimbus::SkyViewTextures::Substitute(vtkNimbusSkyPassFS).c_str(), "");
  }
  else
  {
    window->GetShaderCache()->ReadyShaderProgram(in.Quad->Program);
  }
  vtkShaderProgram* program = in.Quad->Program;
  if (!program || !program->GetCompiled())
  {
    vtkErrorMacro("vtkNimbusSkyPass: the sky shader did not compile");
    return;
  }
  in.Color->Activate();
  in.Depth->Activate();
  program->SetUniformi("colorTexture", in.Color->GetTextureUnit());
  program->SetUniformi("depthTexture", in.Depth->GetTextureUnit());
  in.SkyView.Activate(program, sky);
  const char* aerialNames[4] = { "aerialRayleigh", "aerialMie", "aerialIsotropic",
    "aerialTransmittance" };
  for (int k = 0; k < 4; ++k)
  {
    in.AerialTextures[k]->Activate();
    program->SetUniformi(aerialNames[k], in.AerialTextures[k]->GetTextureUnit());
  }
  vtkNew<vtkMatrix4x4> inverse;
  inverse->DeepCopy(camera->GetCompositeProjectionTransformMatrix(
    static_cast<double>(w) / std::max(1, h), -1.0, 1.0));
  inverse->Invert();
  program->SetUniformMatrix("inverseViewProjection", inverse);
  program->SetUniform3f("cameraPosition", eye);
  program->SetUniformf("metresPerUnit", static_cast<float>(sky->GetMetresPerUnit()));
  const float aerialTable[4] = { static_cast<float>(am.HorizonZenith), static_cast<float>(am.Width),
    static_cast<float>(am.AboveRows), static_cast<float>(am.BelowRows) };
  program->SetUniform4f("aerialTable", aerialTable);
  const float slices[2] = { static_cast<float>(aerial->GetSlices()),
    static_cast<float>(aerial->GetMaxDistance()) };
  program->SetUniform2f("aerialSlices", slices);
  program->SetUniformi("aerialPerspective", this->AerialPerspective ? 1 : 0);

  vtkOpenGLState::ScopedglEnableDisable blendSaver(state, GL_BLEND);
  vtkOpenGLState::ScopedglEnableDisable depthSaver(state, GL_DEPTH_TEST);
  vtkOpenGLState::ScopedglDepthFunc depthFuncSaver(state);
  state->vtkglDisable(GL_BLEND);
  state->vtkglEnable(GL_DEPTH_TEST);
  state->vtkglDepthFunc(GL_ALWAYS);
  state->vtkglDepthMask(GL_TRUE);
  state->vtkglViewport(x, y, w, h);
  state->vtkglScissor(x, y, w, h);
  in.Quad->Render();
  in.Color->Deactivate();
  in.Depth->Deactivate();
  in.SkyView.Deactivate();
  for (auto* t : in.AerialTextures)
  {
    t->Deactivate();
  }
  vtkOpenGLCheckErrorMacro("failed after vtkNimbusSkyPass::Render");
}

void vtkNimbusSkyPass::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Sky: " << this->Sky << "\n";
  os << indent << "AerialPerspective: " << this->AerialPerspective << "\n";
}
