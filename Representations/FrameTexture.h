// A frame-sized texture for the mappers' own render targets (the cloud splats' float
// frame and its copy of the scene's depth, the lightning glow's float sum): one way of
// making it, shared by the mappers that draw into a target of their own and add it to
// the frame once.
#ifndef nimbus_FrameTexture_h
#define nimbus_FrameTexture_h

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
}

#endif
