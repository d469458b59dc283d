// nimbus::EmissionTexture — the glow of hot smoke and fire for vtkNimbusCloudVolumeMapper
// (Planck's law). Per texel of the density texture, the mean over its block of input samples
// of rho B(T) / Y[B(T_ref)] in linear sRGB (Physics/BlackbodyEmission.h): the emission
// coefficient without its scale E, which the shader applies. Uploaded as one RGB float
// 3-D texture with the density texture's dimensions (the same texture coordinates) when
// the density or temperature arrays, the reference temperature or the layout change.
#ifndef nimbus_EmissionTexture_h
#define nimbus_EmissionTexture_h

#include "NimbusRepresentationsModule.h"
#include "vtkNew.h" // for vtkNew

#include <array>
#include <cstddef>
#include <string>
#include <vector>

class vtkDataArray;
class vtkImageData;
class vtkOpenGLRenderWindow;
class vtkTextureObject;
class vtkWindow;

namespace nimbus
{
class BlackbodyEmission;

/// The texels (3 floats each, x fastest) for density and temperature samples of
/// `dimensions` (x fastest) averaged over blocks of `factors` samples into
/// `textureDimensions` texels: the mean of rho B(T) / Y[B(T_ref)] (linear sRGB). Non-finite
/// or negative densities count as 0, non-finite temperatures as 0 K (no light).
NIMBUSREPRESENTATIONS_EXPORT std::vector<float> ComputeEmissionTexels(const float* density,
  const float* temperature, const std::array<int, 3>& dimensions, const std::array<int, 3>& factors,
  const std::array<int, 3>& textureDimensions, const BlackbodyEmission& emission);

class NIMBUSREPRESENTATIONS_EXPORT EmissionTexture
{
public:
  EmissionTexture();
  ~EmissionTexture();
  EmissionTexture(const EmissionTexture&) = delete;
  EmissionTexture& operator=(const EmissionTexture&) = delete;

  /// Uploads the emission of `density` (the mapper's density array) at the temperatures
  /// of the image's array `temperatureArray` (point or cell data, as the density) when
  /// any changed since the last call. False, with the reason in `error`, when the image
  /// has no such numeric 1-component array of the density's size, the reference
  /// temperature is out of [500, 50000] K or GL refuses the upload; the texture is then
  /// off.
  bool Update(vtkOpenGLRenderWindow* window, vtkImageData* image, vtkDataArray* density,
    bool cellData, const std::string& temperatureArray, double referenceTemperatureKelvin,
    const std::array<int, 3>& textureDimensions, const std::array<int, 3>& textureFactors,
    std::string& error);

  bool HasTexture() const { return this->Textured; }
  vtkTextureObject* GetTexture() const;
  /// Uploads so far.
  int GetNumberOfUploads() const { return this->Uploads; }
  /// The largest texel channel of the last upload (0: nothing glows).
  double GetMaximum() const { return this->Maximum; }

  void Release(vtkWindow* window);

private:
  vtkNew<vtkTextureObject> Texture;
  std::vector<double> UploadedKey;
  bool Textured = false;
  int Uploads = 0;
  double Maximum = 0.0;
};
} // namespace nimbus

#endif
