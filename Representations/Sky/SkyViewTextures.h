// nimbus::SkyViewTextures — the sky-view table of a vtkNimbusSky as three GL
// textures (A_R, A_M, A_I) and the uniforms of Shaders/nimbusSkyView.glsl.
// Shared by vtkNimbusSkyPass and vtkNimbusSkyBackground so that both draw the
// same sky. Uploads again only when the sky rebuilt its table.
#ifndef nimbus_SkyViewTextures_h
#define nimbus_SkyViewTextures_h

#include <array>
#include <memory>
#include <string>

class vtkCamera;
class vtkMatrix4x4;
class vtkNimbusSky;
class vtkOpenGLQuadHelper;
class vtkOpenGLRenderWindow;
class vtkShaderProgram;
class vtkTextureObject;
class vtkWindow;

namespace nimbus
{
class SkyViewLut;

class SkyViewTextures
{
public:
  SkyViewTextures() = default;
  ~SkyViewTextures();
  SkyViewTextures(const SkyViewTextures&) = delete;
  SkyViewTextures& operator=(const SkyViewTextures&) = delete;

  /// Builds (through the sky's cache) and uploads the sky-view table seen from
  /// `altitude` (m; see vtkNimbusSky::GetSkyViewLutAt) when it changed. False,
  /// with the reason in `error`, when the table cannot be built.
  bool Update(
    vtkOpenGLRenderWindow* window, vtkNimbusSky* sky, double altitude, std::string& error);
  /// Binds the textures and sets the sky uniforms of nimbusSkyView.glsl.
  void Activate(vtkShaderProgram* program, vtkNimbusSky* sky);
  /// The altitude a camera at scene height z sees the sky from:
  /// SceneAltitudeMetres + z MetresPerUnit, at least 0.
  static double CameraAltitude(vtkNimbusSky* sky, double z);

  /// The camera in the sky's up frame (vtkNimbusSky::UpAxis, Physics/UpAxis.h: the
  /// world turned so that the up axis is +z, where the sky's tables live): its
  /// position and the inverse of projection x view x (up frame -> world), for the
  /// view rays of a full-screen pass. `aspect` = viewport width / height.
  static void CameraInUpFrame(vtkNimbusSky* sky, vtkCamera* camera, double aspect, double eye[3],
    vtkMatrix4x4* inverseViewProjection);
  void Deactivate();
  void Release(vtkWindow* window);

  /// `source` with the GLSL library and nimbusSkyView.glsl put where its lines
  /// `//NIMBUS::Library` and `//NIMBUS::SkyView` are (nimbus::WithShaderLibrary).
  static std::string Substitute(const char* source);
  /// The full-screen quad drawing `fragmentSource` (the GLSL library substituted):
  /// created on first use, its program made current; null when it did not compile.
  static vtkShaderProgram* ReadyQuad(vtkOpenGLRenderWindow* window,
    std::unique_ptr<vtkOpenGLQuadHelper>& quad, const char* fragmentSource);
  /// A float texture with linear filtering and clamp-to-edge wrapping.
  static vtkTextureObject* NewLinearTexture(vtkOpenGLRenderWindow* window);

private:
  std::array<vtkTextureObject*, 3> Textures{ { nullptr, nullptr, nullptr } };
  const SkyViewLut* Table = nullptr; // the uploaded table (its layout sets the uniforms)
  int Builds = -1;
};
}

#endif
