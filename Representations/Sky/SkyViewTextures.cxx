#include "SkyViewTextures.h"

#include "ShaderLibrary.h"
#include "Sky.h"
#include "UpAxis.h"
#include "vtkCamera.h"
#include "vtkMath.h"
#include "vtkMatrix4x4.h"
#include "vtkNew.h"
#include "vtkNimbusSky.h"
#include "vtkOpenGLQuadHelper.h"
#include "vtkOpenGLRenderUtilities.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkOpenGLShaderCache.h"
#include "vtkShaderProgram.h"
#include "vtkTextureObject.h"

#include <algorithm>
#include <exception>

namespace nimbus
{
SkyViewTextures::~SkyViewTextures()
{
  this->Release(nullptr);
}

vtkTextureObject* SkyViewTextures::NewLinearTexture(vtkOpenGLRenderWindow* window)
{
  vtkTextureObject* t = vtkTextureObject::New();
  t->SetContext(window);
  t->SetMinificationFilter(vtkTextureObject::Linear);
  t->SetMagnificationFilter(vtkTextureObject::Linear);
  t->SetWrapS(vtkTextureObject::ClampToEdge);
  t->SetWrapT(vtkTextureObject::ClampToEdge);
  t->SetWrapR(vtkTextureObject::ClampToEdge);
  return t;
}

std::string SkyViewTextures::Substitute(const char* source)
{
  return nimbus::WithShaderLibrary(source);
}

vtkShaderProgram* SkyViewTextures::ReadyQuad(vtkOpenGLRenderWindow* window,
  std::unique_ptr<vtkOpenGLQuadHelper>& quad, const char* fragmentSource)
{
  if (!quad)
  {
    quad = std::make_unique<vtkOpenGLQuadHelper>(window,
      vtkOpenGLRenderUtilities::GetFullScreenQuadVertexShader().c_str(),
      Substitute(fragmentSource).c_str(), "");
  }
  else
  {
    window->GetShaderCache()->ReadyShaderProgram(quad->Program);
  }
  vtkShaderProgram* program = quad->Program;
  return program && program->GetCompiled() ? program : nullptr;
}

void SkyViewTextures::CameraInUpFrame(vtkNimbusSky* sky, vtkCamera* camera, double aspect,
  double eye[3], vtkMatrix4x4* inverseViewProjection)
{
  const auto up = static_cast<UpAxis>(sky->GetUpAxis());
  const double* position = camera->GetPosition();
  const auto turned = ToUpFrame(up, { { position[0], position[1], position[2] } });
  std::copy(turned.begin(), turned.end(), eye);
  const auto r = WorldToUpFrame(up);
  vtkNew<vtkMatrix4x4> upToWorld; // R^T
  for (int i = 0; i < 3; ++i)
  {
    for (int j = 0; j < 3; ++j)
    {
      upToWorld->SetElement(i, j, r[j][i]);
    }
  }
  vtkMatrix4x4::Multiply4x4(camera->GetCompositeProjectionTransformMatrix(aspect, -1.0, 1.0),
    upToWorld, inverseViewProjection);
  inverseViewProjection->Invert();
}

double SkyViewTextures::CameraAltitude(vtkNimbusSky* sky, double z)
{
  return std::max(0.0, sky->GetSceneAltitudeMetres() + z * sky->GetMetresPerUnit());
}

bool SkyViewTextures::Update(
  vtkOpenGLRenderWindow* window, vtkNimbusSky* sky, double altitude, std::string& error)
{
  const SkyViewLut* table = nullptr;
  try
  {
    table = &sky->GetSkyViewLutAt(altitude);
  }
  catch (const std::exception& e)
  {
    error = e.what();
    return false;
  }
  const bool uploaded =
    this->Builds == sky->GetSkyViewBuilds() && this->Table == table && this->Textures[0];
  this->Table = table;
  if (uploaded)
  {
    return true;
  }
  const SkyViewMapping& m = table->GetMapping();
  const std::size_t plane = static_cast<std::size_t>(m.Rows()) * m.Width * 3;
  for (int k = 0; k < 3; ++k)
  {
    if (!this->Textures[k])
    {
      this->Textures[k] = NewLinearTexture(window);
    }
    this->Textures[k]->Create2DFromRaw(
      m.Width, m.Rows(), 3, VTK_FLOAT, const_cast<float*>(table->GetTable().data() + k * plane));
  }
  this->Builds = sky->GetSkyViewBuilds();
  return true;
}

void SkyViewTextures::Activate(vtkShaderProgram* program, vtkNimbusSky* sky)
{
  const char* names[3] = { "skyRayleigh", "skyMie", "skyIsotropic" };
  for (int k = 0; k < 3; ++k)
  {
    this->Textures[k]->Activate();
    program->SetUniformi(names[k], this->Textures[k]->GetTextureUnit());
  }
  const SkyViewMapping& m = this->Table->GetMapping();
  double sun[3], scale[3], disc[3];
  sky->GetSunDirection(sun);
  sky->GetDisplayScale(scale);
  sky->GetSunDiscRadiance(disc);
  program->SetUniform3f("sunDirection", sun);
  program->SetUniformf("sunAzimuthRadians",
    static_cast<float>(vtkMath::RadiansFromDegrees(sky->GetSunAzimuthDegrees())));
  program->SetUniformf(
    "mieG", static_cast<float>(sky->GetSkyModel().GetParameters().Atmosphere.MieG));
  program->SetUniform3f("displayScale", scale);
  const float skyTable[4] = { static_cast<float>(m.HorizonZenith), static_cast<float>(m.Width),
    static_cast<float>(m.AboveRows), static_cast<float>(m.BelowRows) };
  program->SetUniform4f("skyTable", skyTable);
  program->SetUniformi("sunDisc", sky->GetSunDisc() ? 1 : 0);
  program->SetUniform3f("sunDiscRadiance", disc);
  program->SetUniformf("sunAngularRadius", static_cast<float>(vtkNimbusSky::GetSunAngularRadius()));
}

void SkyViewTextures::Deactivate()
{
  for (vtkTextureObject* t : this->Textures)
  {
    if (t)
    {
      t->Deactivate();
    }
  }
}

void SkyViewTextures::Release(vtkWindow* window)
{
  for (vtkTextureObject*& t : this->Textures)
  {
    if (t)
    {
      if (window)
      {
        t->ReleaseGraphicsResources(window);
      }
      t->Delete();
      t = nullptr;
    }
  }
  this->Table = nullptr;
  this->Builds = -1;
}
}
