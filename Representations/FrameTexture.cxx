#include "FrameTexture.h"

#include "vtkOpenGLRenderWindow.h"
#include "vtkTextureObject.h"
#include "vtkType.h"

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
}
