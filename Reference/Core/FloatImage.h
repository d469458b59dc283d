// A linear float RGB image (linear sRGB radiance, the scene's relative units),
// row 0 at the bottom like vtkImageData and PFM.
#ifndef NimbusFloatImage_h
#define NimbusFloatImage_h

#include "NimbusReferenceModule.h"

#include <array>
#include <string>
#include <vector>

namespace nimbus
{

struct NIMBUSREFERENCE_EXPORT FloatImage
{
  int Width = 0;
  int Height = 0;
  std::vector<float> Pixels; // RGB interleaved, Width * Height * 3

  FloatImage() = default;
  FloatImage(int width, int height)
    : Width(width)
    , Height(height)
    , Pixels(static_cast<std::size_t>(width) * height * 3, 0.0f)
  {
  }
  float* At(int x, int y)
  {
    return &this->Pixels[3 * (static_cast<std::size_t>(y) * this->Width + x)];
  }
  const float* At(int x, int y) const
  {
    return &this->Pixels[3 * (static_cast<std::size_t>(y) * this->Width + x)];
  }

  /// Portable float map (little-endian "PF"); throws std::runtime_error on I/O failure.
  void WritePFM(const std::string& path) const;
  static FloatImage ReadPFM(const std::string& path);
};

/// Empty when every pixel component is finite; else how many are NaN and how many
/// infinite, e.g. "3 NaN and 1 infinite values among 147 pixel components".
/// (Negative components are allowed: linear sRGB of a saturated spectrum.)
NIMBUSREFERENCE_EXPORT std::string NonFiniteMessage(const FloatImage& image);

/// Display encoding for looking at a linear image: multiply by exposure, clip to
/// [0, 1], apply the sRGB transfer function; 8-bit RGB, row 0 at the bottom.
NIMBUSREFERENCE_EXPORT std::vector<unsigned char> ToneMap(const FloatImage& image, double exposure);

} // namespace nimbus

#endif
