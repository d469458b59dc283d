#include "vtkNimbusSkyBackground.h"

#include "SkyViewTextures.h"
#include "vtkCamera.h"
#include "vtkInformation.h"
#include "vtkInformationObjectBaseKey.h"
#include "vtkMatrix4x4.h"
#include "vtkNimbusSky.h"
#include "vtkNimbusSkyBackgroundFS.h"
#include "vtkObjectFactory.h"
#include "vtkOpenGLError.h"
#include "vtkOpenGLQuadHelper.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkOpenGLState.h"
#include "vtkPropCollection.h"
#include "vtkRenderer.h"
#include "vtkShaderProgram.h"

#include <algorithm>
#include <stdexcept>
#include <string>

vtkStandardNewMacro(vtkNimbusSkyBackground);
vtkInformationKeyRestrictedMacro(
  vtkNimbusSkyBackground, RENDERER_SKY_BACKGROUND, ObjectBase, "vtkNimbusSkyBackground");

vtkNimbusSkyBackground* vtkNimbusSkyBackground::ShownIn(vtkRenderer* renderer)
{
  if (!renderer)
  {
    return nullptr;
  }
  auto* named = vtkNimbusSkyBackground::SafeDownCast(
    renderer->GetInformation()->Get(vtkNimbusSkyBackground::RENDERER_SKY_BACKGROUND()));
  if (named && named->GetVisibility())
  {
    return named;
  }
  vtkPropCollection* props = renderer->GetViewProps();
  vtkCollectionSimpleIterator it;
  props->InitTraversal(it);
  while (vtkProp* prop = props->GetNextProp(it))
  {
    auto* background = vtkNimbusSkyBackground::SafeDownCast(prop);
    if (background && background->GetVisibility())
    {
      return background;
    }
  }
  return named;
}

struct vtkNimbusSkyBackground::Internals
{
  nimbus::SkyViewTextures SkyView;
  std::unique_ptr<vtkOpenGLQuadHelper> Quad;
  vtkOpenGLRenderWindow* Window = nullptr;

  void Release(vtkWindow* window)
  {
    this->SkyView.Release(window);
    if (this->Quad)
    {
      this->Quad->ReleaseGraphicsResources(window);
      this->Quad.reset();
    }
    this->Window = nullptr;
  }
};

vtkNimbusSkyBackground::vtkNimbusSkyBackground()
  : Internal(new Internals)
{
  this->Sky = vtkNimbusSky::New();
  this->PickableOff();
}

vtkNimbusSkyBackground::~vtkNimbusSkyBackground()
{
  if (this->Sky)
  {
    this->Sky->Delete();
  }
}

void vtkNimbusSkyBackground::SetSky(vtkNimbusSky* sky)
{
  if (!sky)
  {
    vtkErrorMacro("SetSky: a sky is required (keeping the current one).");
    return;
  }
  if (sky == this->Sky)
  {
    return;
  }
  sky->Register(this);
  this->Sky->UnRegister(this);
  this->Sky = sky;
  this->Modified();
}

vtkMTimeType vtkNimbusSkyBackground::GetMTime()
{
  return std::max(this->Superclass::GetMTime(), this->Sky->GetMTime());
}

void vtkNimbusSkyBackground::ReleaseGraphicsResources(vtkWindow* window)
{
  this->Internal->Release(window);
  this->Superclass::ReleaseGraphicsResources(window);
}

int vtkNimbusSkyBackground::RenderOpaqueGeometry(vtkViewport* viewport)
{
  // No exception leaves a render or a pipeline request (VTK does not catch).
  try
  {
    auto* renderer = vtkRenderer::SafeDownCast(viewport);
    if (!renderer || renderer->GetSelector() || !this->DrawSky)
    {
      return 0; // nothing to pick (the sky is not a selectable prop), or another draws it
    }
    auto* window = vtkOpenGLRenderWindow::SafeDownCast(renderer->GetRenderWindow());
    if (!window)
    {
      vtkErrorMacro("vtkNimbusSkyBackground needs an OpenGL render window.");
      return 0;
    }
    vtkOpenGLClearErrorMacro();
    Internals& in = *this->Internal;
    if (in.Window && in.Window != window)
    {
      in.Release(in.Window);
    }
    in.Window = window;
    std::string error;
    vtkCamera* camera = renderer->GetActiveCamera();
    int width = 0, height = 0, x0 = 0, y0 = 0;
    renderer->GetTiledSizeAndOrigin(&width, &height, &x0, &y0);
    double eye[3];
    vtkNew<vtkMatrix4x4> inverse;
    nimbus::SkyViewTextures::CameraInUpFrame(
      this->Sky, camera, static_cast<double>(width) / std::max(1, height), eye, inverse);
    const double altitude = nimbus::SkyViewTextures::CameraAltitude(this->Sky, eye[2]);
    if (!in.SkyView.Update(window, this->Sky, altitude, error))
    {
      vtkErrorMacro("Sky tables: " << error);
      return 0;
    }
    vtkShaderProgram* program =
      nimbus::SkyViewTextures::ReadyQuad(window, in.Quad, vtkNimbusSkyBackgroundFS);
    if (!program)
    {
      vtkErrorMacro("The sky background shader did not compile.");
      return 0;
    }
    program->SetUniformMatrix("inverseViewProjection", inverse);
    program->SetUniform3f("cameraPosition", eye);
    in.SkyView.Activate(program, this->Sky);

    vtkOpenGLState* state = window->GetState();
    vtkOpenGLState::ScopedglEnableDisable blendSaver(state, GL_BLEND);
    vtkOpenGLState::ScopedglEnableDisable depthSaver(state, GL_DEPTH_TEST);
    vtkOpenGLState::ScopedglDepthFunc depthFuncSaver(state);
    vtkOpenGLState::ScopedglDepthMask depthMaskSaver(state);
    state->vtkglDisable(GL_BLEND);
    state->vtkglEnable(GL_DEPTH_TEST);
    state->vtkglDepthFunc(GL_LEQUAL); // only where the depth is still the cleared 1
    state->vtkglDepthMask(GL_FALSE);
    in.Quad->Render();
    in.SkyView.Deactivate();
    ++this->NumberOfDraws;
    vtkOpenGLCheckErrorMacro("failed after vtkNimbusSkyBackground::RenderOpaqueGeometry");
    return 1;
  }
  catch (const std::exception& error)
  {
    vtkErrorMacro("The sky background was not drawn: " << error.what());
  }
  catch (...)
  {
    vtkErrorMacro("The sky background was not drawn: an unknown exception.");
  }
  return 0;
}

void vtkNimbusSkyBackground::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Sky: " << this->Sky << "\n";
  if (this->Sky)
  {
    this->Sky->PrintSelf(os, indent.GetNextIndent());
  }
  os << indent << "NumberOfDraws: " << this->NumberOfDraws << "\n";
  os << indent << "DrawSky: " << this->DrawSky << "\n";
}
