// nimbus::LightShadowMaps — the shadows the view's opaque geometry casts into the
// beams of its lights (002 §6.2: a shadow map per light): the renderer's visible opaque
// actors drawn into a depth atlas, six 90-degree faces per light (a cube around the
// light, ShadowFaces() in ViewLights.h), row i for light i. Read by LightShadow() in
// nimbusLights.glsl. VTK/GL glue of vtkNimbusCloudVolumeMapper (not wrapped).
//
// Casters: the renderer's visible vtkActors with opaque geometry that count for the
// bounds (ParaView's annotations, the centre axes and the like do not); the cloud's own
// volume is not an actor. Each is drawn with its own mapper through a camera at the
// light (the renderer's active camera is swapped for the light's and put back, as
// VTK's shadow-map baker does).
#ifndef nimbus_LightShadowMaps_h
#define nimbus_LightShadowMaps_h

#include "NimbusRepresentationsModule.h"

#include "ViewLights.h"

#include <array>
#include <memory>
#include <vector>

class vtkActor;
class vtkOpenGLRenderWindow;
class vtkRenderer;
class vtkTextureObject;
class vtkWindow;

namespace nimbus
{
class NIMBUSREPRESENTATIONS_EXPORT LightShadowMaps
{
public:
  LightShadowMaps();
  ~LightShadowMaps();

  /// Draws the casters of `renderer` into the atlas for `lights` (positions in VTK world
  /// coordinates), `faceSize` texels per face side, depth range from `region` (VTK world
  /// bounds the shadows must cover), unless nothing they depend on changed since the last
  /// call (the lights, the region, the size, the casters and their modification times):
  /// a camera that moves costs no shadow map. False, with nothing drawn, when the
  /// renderer has no caster or no light is given.
  bool Update(vtkRenderer* renderer, vtkOpenGLRenderWindow* window,
    const std::vector<ViewLight>& lights, const std::array<double, 6>& region, int faceSize);
  /// Times the maps were drawn (tests, benchmarks).
  int GetNumberOfRenders() const { return this->Renders; }

  vtkTextureObject* GetTexture() const;
  /// Near and far plane (world units) of light i's faces.
  const std::vector<std::array<double, 2>>& GetRanges() const { return this->Ranges; }
  /// Casters drawn by the last Render.
  int GetNumberOfCasters() const { return this->Casters; }
  void Release(vtkWindow* window);

private:
  struct Internals;
  std::unique_ptr<Internals> Internal;
  bool Render(vtkRenderer* renderer, vtkOpenGLRenderWindow* window,
    const std::vector<ViewLight>& lights, const std::array<double, 6>& region, int faceSize,
    const std::vector<vtkActor*>& casters);
  std::vector<std::array<double, 2>> Ranges;
  std::vector<double> Key;
  int Casters = 0;
  int Renders = 0;
};
}

#endif
