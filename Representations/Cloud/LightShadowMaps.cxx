#include "LightShadowMaps.h"

#include <vtkActor.h>
#include <vtkCamera.h>
#include <vtkMatrix4x4.h>
#include <vtkNew.h>
#include <vtkOpenGLFramebufferObject.h>
#include <vtkOpenGLRenderWindow.h>
#include <vtkOpenGLState.h>
#include <vtkPropCollection.h>
#include <vtkRenderer.h>
#include <vtkSmartPointer.h>
#include <vtkTextureObject.h>
#include <vtk_glew.h>

#include <cstdint>

namespace nimbus
{
struct LightShadowMaps::Internals
{
  vtkNew<vtkTextureObject> Atlas;
  vtkNew<vtkOpenGLFramebufferObject> Framebuffer;
  vtkSmartPointer<vtkCamera> Camera;
};

LightShadowMaps::LightShadowMaps()
  : Internal(new Internals)
{
}

LightShadowMaps::~LightShadowMaps() = default;

vtkTextureObject* LightShadowMaps::GetTexture() const
{
  return this->Internal->Atlas;
}

void LightShadowMaps::Release(vtkWindow* window)
{
  this->Internal->Atlas->ReleaseGraphicsResources(window);
  this->Internal->Framebuffer->ReleaseGraphicsResources(window);
  this->Casters = 0;
  this->Key.clear();
}

namespace
{
// The renderer's actors that cast shadows (see the header).
std::vector<vtkActor*> ShadowCasters(vtkRenderer* renderer)
{
  std::vector<vtkActor*> casters;
  vtkPropCollection* props = renderer->GetViewProps();
  vtkCollectionSimpleIterator it;
  props->InitTraversal(it);
  while (vtkProp* prop = props->GetNextProp(it))
  {
    vtkActor* actor = vtkActor::SafeDownCast(prop);
    if (actor && actor->GetVisibility() && actor->GetUseBounds() && actor->HasOpaqueGeometry())
    {
      casters.push_back(actor);
    }
  }
  return casters;
}

// A depth texture of w x h texels, reallocated only when its size changed.
void EnsureDepthAtlas(vtkTextureObject* atlas, vtkOpenGLRenderWindow* window, int w, int h)
{
  if (atlas->GetHandle() && atlas->GetContext() == window &&
    static_cast<int>(atlas->GetWidth()) == w && static_cast<int>(atlas->GetHeight()) == h)
  {
    return;
  }
  atlas->SetContext(window);
  atlas->ReleaseGraphicsResources(window);
  atlas->SetWrapS(vtkTextureObject::ClampToEdge);
  atlas->SetWrapT(vtkTextureObject::ClampToEdge);
  atlas->SetMinificationFilter(vtkTextureObject::Nearest);
  atlas->SetMagnificationFilter(vtkTextureObject::Nearest);
  atlas->AllocateDepth(w, h, vtkTextureObject::Float32);
}

// The light's camera looking along face f.
void AimCamera(vtkCamera* camera, const Vector3& position, const ShadowFace& face,
  const std::array<double, 2>& range)
{
  camera->SetPosition(position[0], position[1], position[2]);
  camera->SetFocalPoint(
    position[0] + face.Forward[0], position[1] + face.Forward[1], position[2] + face.Forward[2]);
  camera->SetViewUp(face.Up[0], face.Up[1], face.Up[2]);
  camera->SetClippingRange(range[0], range[1]);
  const std::array<double, 16> p = ShadowFaceProjection(range[0], range[1]);
  vtkNew<vtkMatrix4x4> projection;
  for (int r = 0; r < 4; ++r)
  {
    for (int c = 0; c < 4; ++c)
    {
      projection->SetElement(r, c, p[c * 4 + r]); // column-major -> row-major
    }
  }
  camera->SetExplicitProjectionTransformMatrix(projection);
  camera->UseExplicitProjectionTransformMatrixOn();
}
}

bool LightShadowMaps::Update(vtkRenderer* renderer, vtkOpenGLRenderWindow* window,
  const std::vector<ViewLight>& lights, const std::array<double, 6>& region, int faceSize)
{
  const std::vector<vtkActor*> casters = ShadowCasters(renderer);
  if (casters.empty() || lights.empty())
  {
    this->Ranges.clear();
    this->Casters = 0;
    this->Key.clear();
    return false;
  }
  std::vector<double> key(region.begin(), region.end());
  key.push_back(faceSize);
  key.push_back(static_cast<double>(reinterpret_cast<std::uintptr_t>(window)));
  for (const ViewLight& light : lights)
  {
    key.insert(key.end(), light.Position.begin(), light.Position.end());
  }
  for (vtkActor* actor : casters)
  {
    key.push_back(static_cast<double>(reinterpret_cast<std::uintptr_t>(actor)));
    key.push_back(static_cast<double>(actor->GetRedrawMTime()));
  }
  if (key == this->Key && this->Internal->Atlas->GetHandle())
  {
    return true;
  }
  this->Key = std::move(key);
  ++this->Renders;
  return this->Render(renderer, window, lights, region, faceSize, casters);
}

bool LightShadowMaps::Render(vtkRenderer* renderer, vtkOpenGLRenderWindow* window,
  const std::vector<ViewLight>& lights, const std::array<double, 6>& region, int faceSize,
  const std::vector<vtkActor*>& casters)
{
  Internals& in = *this->Internal;
  this->Ranges.clear();
  faceSize = std::max(faceSize, 16);
  EnsureDepthAtlas(in.Atlas, window, 6 * faceSize, static_cast<int>(lights.size()) * faceSize);
  vtkOpenGLState* state = window->GetState();
  // The caller's framebuffer bindings come back afterwards (ParaView draws into its own).
  state->PushFramebufferBindings();
  in.Framebuffer->SetContext(window);
  in.Framebuffer->Bind(GL_FRAMEBUFFER);
  in.Framebuffer->RemoveColorAttachments(4);
  in.Framebuffer->AddDepthAttachment(in.Atlas);
  in.Framebuffer->ActivateDrawBuffers(0);
  state->vtkglDrawBuffer(GL_NONE);
  state->vtkglReadBuffer(GL_NONE);
  state->vtkglEnable(GL_DEPTH_TEST);
  state->vtkglDepthMask(GL_TRUE);
  state->vtkglDepthFunc(GL_LEQUAL);
  state->vtkglDisable(GL_BLEND);
  state->vtkglEnable(GL_SCISSOR_TEST);
  state->vtkglClearDepth(1.0);
  if (!in.Camera)
  {
    in.Camera.TakeReference(renderer->MakeCamera());
  }
  // The renderer's camera is held while the light's stands in for it.
  vtkSmartPointer<vtkCamera> viewCamera = renderer->GetActiveCamera();
  renderer->SetActiveCamera(in.Camera);
  for (std::size_t i = 0; i < lights.size(); ++i)
  {
    const std::array<double, 2> range = ShadowDepthRange(lights[i].Position, region);
    this->Ranges.push_back(range);
    for (int f = 0; f < 6; ++f)
    {
      const int x = f * faceSize, y = static_cast<int>(i) * faceSize;
      state->vtkglViewport(x, y, faceSize, faceSize);
      state->vtkglScissor(x, y, faceSize, faceSize);
      state->vtkglClear(GL_DEPTH_BUFFER_BIT);
      AimCamera(in.Camera, lights[i].Position, ShadowFaces()[f], range);
      for (vtkActor* actor : casters)
      {
        actor->RenderOpaqueGeometry(renderer);
      }
    }
  }
  renderer->SetActiveCamera(viewCamera);
  state->vtkglDisable(GL_SCISSOR_TEST);
  state->vtkglDrawBuffer(GL_COLOR_ATTACHMENT0);
  state->vtkglReadBuffer(GL_COLOR_ATTACHMENT0);
  in.Framebuffer->RemoveDepthAttachment();
  state->PopFramebufferBindings();
  this->Casters = static_cast<int>(casters.size());
  return true;
}
}
