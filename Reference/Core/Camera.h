// Pinhole camera of a scene: primary rays per pixel, VTK's conventions (vertical
// view angle, pixel row 0 at the bottom).
#ifndef NimbusCamera_h
#define NimbusCamera_h

#include "Math.h"
#include "NimbusReferenceModule.h"
#include "SceneDescription.h"

#include <array>

namespace nimbus
{

class NIMBUSREFERENCE_EXPORT Camera
{
public:
  using Vector3 = nimbus::Vector3;

  /// Throws std::invalid_argument for a degenerate camera (position == focal
  /// point, view-up parallel to the view direction, angle outside (0, 180),
  /// non-positive image size).
  explicit Camera(const CameraDescription& description);

  const Vector3& GetPosition() const { return this->Position; }
  int GetWidth() const { return this->Width; }
  int GetHeight() const { return this->Height; }

  /// Unit direction of the ray through image point (x, y) in pixel units:
  /// (0, 0) is the bottom-left corner of the image, (W, H) the top-right; a
  /// pixel's centre is (i + 0.5, j + 0.5).
  Vector3 RayDirection(double x, double y) const;

private:
  Vector3 Position;
  Vector3 Forward, Right, Up;
  double TanHalfAngle;
  int Width, Height;
};

} // namespace nimbus

#endif
