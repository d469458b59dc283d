// nimbus::LightningTexture — the lightning's in-scattered radiance for
// vtkNimbusCloudVolumeMapper: vtkNimbusLightningIllumination leaves J(x, w) of the cloud lit
// by the strokes in the image's field data ("nimbus_lightning_in_scattering", 12 floats
// per point of a grid of blocks of input samples, "nimbus_lightning_grid"); this uploads it
// as three RGBA float 3-D textures (the layout of the multiple-scattering texture,
// UploadShCoefficients) when the array changes, and says how to read them with the
// density texture's coordinates. When the filter computed the first scattering on the
// density's grid ("nimbus_lightning_first_scattering": E and the flux F per point,
// Physics/FirstScattering.h; "nimbus_lightning_first_scattering_grid": its blocks and the
// lightning's colour) that is a fourth, RGBA float texture (E in alpha, F in RGB).
#ifndef nimbus_LightningTexture_h
#define nimbus_LightningTexture_h

#include "NimbusRepresentationsModule.h"
#include "vtkNew.h" // for vtkNew

#include <array>
#include <string>

class vtkDataArray;
class vtkImageData;
class vtkOpenGLRenderWindow;
class vtkTextureObject;
class vtkWindow;

namespace nimbus
{
class NIMBUSREPRESENTATIONS_EXPORT LightningTexture
{
public:
  LightningTexture();
  ~LightningTexture();
  LightningTexture(const LightningTexture&) = delete;
  LightningTexture& operator=(const LightningTexture&) = delete;

  /// Uploads the image's lightning arrays when they changed since the last call (the
  /// texture is off when the image has none or they are all zero). `textureDimensions`
  /// and `textureFactors`: the density texture's texels and blocks of input samples
  /// per axis. False, with the reason in `error`, when the arrays are malformed (sizes
  /// that disagree with the image, non-finite values) or GL refuses the upload; the
  /// texture is then off.
  bool Update(vtkOpenGLRenderWindow* window, vtkImageData* image, bool cellData,
    const std::array<int, 3>& textureDimensions, const std::array<int, 3>& textureFactors,
    std::string& error);

  bool HasTexture() const { return this->Textured; }
  vtkTextureObject* GetTexture(int channel) const;
  /// Density texture coordinates -> this texture's.
  const std::array<double, 3>& GetTextureScale() const { return this->TextureScale; }
  /// The optics the lightning was computed with (ExtinctionPerDensity, Albedo, CloudG,
  /// MetresPerUnit), or NaN when the image did not say.
  const std::array<double, 4>& GetOptics() const { return this->Optics; }
  /// Uploads so far (a new lightning field each).
  int GetNumberOfUploads() const { return this->Uploads; }

  /// The first scattering on the density's grid (F in RGB, E in alpha), its coordinates
  /// from the density texture's and the lightning's colour.
  bool HasFirstScattering() const { return this->FirstScatteringTextured; }
  vtkTextureObject* GetFirstScatteringTexture() const { return this->FirstScattering; }
  const std::array<double, 3>& GetFirstScatteringScale() const
  {
    return this->FirstScatteringScale;
  }
  const std::array<double, 3>& GetFirstScatteringColour() const
  {
    return this->FirstScatteringColour;
  }

  /// Upload the delta-M view's first scattering ("nimbus_lightning_first_scattering_reduced":
  /// the beam through the reduced extinction, vtkNimbusLightningIllumination) in place of
  /// the plain one when the image has it.
  void SetPreferReducedFirstScattering(bool prefer) { this->PreferReduced = prefer; }
  /// Whether the uploaded first scattering is the reduced one.
  bool IsFirstScatteringReduced() const { return this->FirstScatteringReduced; }
  /// The delta-M view's beam's mean cosine about the sources' directions, one float per
  /// point of the first scattering's grid (1 when the first scattering is not the reduced
  /// one): (E / E')^(1 - g_peak), the spread its peak-only scatterings gave it.
  vtkTextureObject* GetBeamCosineTexture() const { return this->BeamCosine; }

  void Release(vtkWindow* window);

private:
  bool UpdateFirstScattering(vtkOpenGLRenderWindow* window, vtkImageData* image, bool cellData,
    const std::array<int, 3>& textureDimensions, const std::array<int, 3>& textureFactors,
    std::string& error);

  vtkNew<vtkTextureObject> Textures[3];
  vtkNew<vtkTextureObject> FirstScattering;
  vtkNew<vtkTextureObject> BeamCosine;
  vtkDataArray* FirstScatteringArray = nullptr; // identity only, never dereferenced
  bool PreferReduced = false;
  bool FirstScatteringReduced = false;
  unsigned long FirstScatteringTime = 0;
  std::array<double, 3> FirstScatteringScale{ { 1, 1, 1 } };
  std::array<double, 3> FirstScatteringColour{ { 1, 1, 1 } };
  bool FirstScatteringTextured = false;
  vtkDataArray* UploadedArray = nullptr; // identity only, never dereferenced
  unsigned long UploadedTime = 0;
  std::array<int, 6> UploadedLayout{};
  std::array<double, 3> TextureScale{ { 1, 1, 1 } };
  std::array<double, 4> Optics{};
  bool Textured = false;
  int Uploads = 0;
};
} // namespace nimbus

#endif
