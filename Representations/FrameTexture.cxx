#include "FrameTexture.h"

#include "vtkOpenGLFramebufferObject.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkOpenGLState.h"
#include "vtkTextureObject.h"
#include "vtkType.h"
#include "vtk_glew.h"

namespace nimbus
{
bool EnsureFrameTexture(
  vtkTextureObject* texture, vtkOpenGLRenderWindow* window, int w, int h, FrameTextureFormat format)
{
  texture->SetContext(window);
  if (texture->GetHandle() && static_cast<int>(texture->GetWidth()) == w &&
    static_cast<int>(texture->GetHeight()) == h)
  {
    return true;
  }
  texture->ReleaseGraphicsResources(window);
  texture->SetWrapS(vtkTextureObject::ClampToEdge);
  texture->SetWrapT(vtkTextureObject::ClampToEdge);
  texture->SetMinificationFilter(vtkTextureObject::Nearest);
  texture->SetMagnificationFilter(vtkTextureObject::Nearest);
  if (format == FrameTextureFormat::Depth)
  {
    return texture->AllocateDepth(w, h, vtkTextureObject::Float32);
  }
  return texture->Allocate2D(
    w, h, 4, format == FrameTextureFormat::Float ? VTK_FLOAT : VTK_UNSIGNED_CHAR);
}

int CopySceneDepth(vtkTextureObject* depth, int x0, int y0, int w, int h)
{
  GLint samples = 0;
  glGetIntegerv(GL_SAMPLES, &samples);
  if (samples == 0)
  {
    depth->CopyFromFrameBuffer(x0, y0, 0, 0, w, h);
  }
  return samples;
}

void BeginFrameTarget(vtkOpenGLFramebufferObject* target, vtkTextureObject* sum,
  vtkTextureObject* depth, vtkOpenGLRenderWindow* window, int w, int h, bool sceneDepth)
{
  vtkOpenGLState* state = window->GetState();
  target->SetContext(window);
  target->Bind(GL_FRAMEBUFFER);
  target->RemoveColorAttachment(0);
  target->AddColorAttachment(0, sum);
  target->AddDepthAttachment(depth);
  target->ActivateDrawBuffer(0);
  state->vtkglViewport(0, 0, w, h);
  state->vtkglDisable(GL_SCISSOR_TEST);
  state->vtkglColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  state->vtkglClearColor(0.0f, 0.0f, 0.0f, 0.0f);
  if (sceneDepth)
  {
    state->vtkglClear(GL_COLOR_BUFFER_BIT);
  }
  else
  {
    state->vtkglDepthMask(GL_TRUE);
    state->vtkglClearDepth(1.0);
    state->vtkglClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  }
}
}
