// A frame-sized texture for the mappers' own render targets (the cloud splats' float
// frame and its copy of the scene's depth, the lightning glow's float sum): one way of
// making it, shared by the mappers that draw into a target of their own and add it to
// the frame once.
#ifndef nimbus_FrameTexture_h
#define nimbus_FrameTexture_h

class vtkOpenGLFramebufferObject;
class vtkOpenGLRenderWindow;
class vtkTextureObject;

namespace nimbus
{
enum class FrameTextureFormat
{
  Float, // RGBA, 32-bit float per channel
  Byte,  // RGBA, 8 bits per channel
  Depth  // a 32-bit float depth
};

/// Makes `texture` a w x h texture of `format` in `window`'s context: nearest filtered,
/// clamped to the edge, reallocated only when its size changed. Returns false when the
/// allocation failed.
bool EnsureFrameTexture(vtkTextureObject* texture, vtkOpenGLRenderWindow* window, int w, int h,
  FrameTextureFormat format);

/// Copies the depth of the bound read framebuffer, w x h from (x0, y0), into `depth`
/// (a Depth frame texture), so that the mapper's own drawing is hidden by the opaque
/// geometry drawn before it. Returns the frame's samples per pixel: 0 when the depth was
/// copied; more, copying nothing, when the frame is multisampled (its depth cannot be
/// copied into a single-sampled texture).
int CopySceneDepth(vtkTextureObject* depth, int x0, int y0, int w, int h);

/// Binds `target` for drawing into `sum` (colour 0) over `depth`, w x h, with the colour
/// cleared to 0 and the depth kept when it holds the scene's (sceneDepth), else cleared
/// to the far plane.
void BeginFrameTarget(vtkOpenGLFramebufferObject* target, vtkTextureObject* sum,
  vtkTextureObject* depth, vtkOpenGLRenderWindow* window, int w, int h, bool sceneDepth);
}

#endif
