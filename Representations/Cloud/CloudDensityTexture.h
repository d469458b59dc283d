// nimbus::CloudDensityTexture — the cloud density as a float 3-D texture (000: the
// "volume texture") for vtkNimbusCloudVolumeMapper: uploads only when the data
// changed (another array or image, either modified since the last upload, or a new
// texture-size limit), resamples the array to fit (DensityResample.h), and keeps
// the density box in data coordinates with its box -> texture-coordinate map and
// the number of uploads.
//
// Point data: sample j sits at the centre of texel j, the box spans the first to the
// last sample. Cell data: the box spans the cells, texel j is cell j. An axis one
// sample thick gets a box one spacing (or one unit) thick around the sample.
#ifndef nimbus_CloudDensityTexture_h
#define nimbus_CloudDensityTexture_h

#include "DensityResample.h"
#include "NimbusRepresentationsModule.h"
#include "vtkNew.h"       // for vtkNew
#include "vtkTimeStamp.h" // for vtkTimeStamp

#include <array>
#include <string>
#include <vector>

class vtkDataArray;
class vtkImageData;
class vtkMatrix4x4;
class vtkOpenGLRenderWindow;
class vtkTextureObject;
class vtkWindow;

namespace nimbus
{
class NIMBUSREPRESENTATIONS_EXPORT CloudDensityTexture
{
public:
  CloudDensityTexture();
  ~CloudDensityTexture();
  CloudDensityTexture(const CloudDensityTexture&) = delete;
  CloudDensityTexture& operator=(const CloudDensityTexture&) = delete;

  /// Makes the texture hold `scalars` of `image` (cell data when `cellData`), at
  /// most `maximumSize` texels per side and `budgetBytes` bytes (the texture and
  /// its converted copy on the CPU, 8 bytes per texel: a larger volume is
  /// downsampled further), uploading only when it does not already.
  /// What the user should hear of (several components, downsampling, NaN,
  /// infinite, negative or too large values: once per version of the array) is
  /// appended to `warnings`. False, with the reason in `error`, when the array does
  /// not match the image, not even one texel fits the budget or the upload failed
  /// (GL_OUT_OF_MEMORY).
  bool Update(vtkOpenGLRenderWindow* window, vtkImageData* image, vtkDataArray* scalars,
    bool cellData, int maximumSize, double budgetBytes, std::vector<std::string>& warnings,
    std::string& error);

  /// The density (the first component of the array) at the texels of `plan`,
  /// read with typed access (vtkArrayDispatch) from any numeric array; a
  /// one-component float array that needs no change is borrowed, not copied.
  static ResampledDensity Resample(vtkDataArray* scalars, const DensityResamplePlan& plan);

  vtkTextureObject* GetTexture() const { return this->Texture; }
  /// Texels per axis of the last upload (0 before the first).
  void GetDimensions(int dimensions[3]) const;
  /// Input samples per texel per axis of the last upload (the block factors).
  void GetFactors(int factors[3]) const;
  /// Keep a copy of the uploaded texels on the CPU (the ray-marched method's
  /// sun-depth volume reads them; 4 bytes per texel, within the budget's 8). Turning
  /// it on makes the next Update upload again when no copy is kept.
  void SetKeepTexels(bool keep) { this->KeepTexels = keep; }
  /// The uploaded texels (x fastest; NaN and infinite as 0, negative clamped, as in
  /// the texture), when KeepTexels was on at the upload; else empty.
  const std::vector<float>& GetTexels() const { return this->Texels; }
  /// Uploads so far (tests and benchmarks).
  int GetNumberOfUploads() const { return this->Uploads; }

  ///@{
  /// The box of the density in data coordinates (valid after an Update).
  const double* GetBoxOrigin() const { return this->BoxOrigin; }
  const double* GetBoxSize() const { return this->BoxSize; }
  ///@}
  /// Data coordinates -> density texture coordinates.
  void GetDataToTexture(vtkMatrix4x4* matrix) const;
  /// Data coordinates -> the box as [0,1]^3 (the "inside the box" test).
  void GetDataToBox(vtkMatrix4x4* matrix) const;

  /// Frees the texture; the next Update uploads again.
  void Release(vtkWindow* window);

private:
  bool NeedsUpload(
    vtkImageData* image, vtkDataArray* scalars, int maximumSize, double budgetBytes) const;
  void SetBox(vtkImageData* image, bool cellData, const DensityResamplePlan& plan);

  vtkNew<vtkTextureObject> Texture;
  vtkTimeStamp UploadTime;
  vtkDataArray* UploadedArray = nullptr; // identity only, never dereferenced
  vtkImageData* UploadedImage = nullptr;
  // The uploaded image's extent, origin and spacing: a new version of the image object
  // that only changed its field data (a lightning time step) keeps the texture.
  std::array<double, 12> UploadedGeometry{};
  int UploadedMaximumSize = -1;
  double UploadedBudgetBytes = -1.0;
  // The array whose values were last reported (NaN, infinite, negative): reported
  // again only for another array or a newer version of it, not for a re-upload
  // of the same values (a new size limit).
  vtkDataArray* ReportedArray = nullptr; // identity only, never dereferenced
  vtkTimeStamp ReportTime;
  bool HasDensity = false;
  bool KeepTexels = false;
  std::vector<float> Texels;
  int Uploads = 0;
  int Dimensions[3] = { 0, 0, 0 };
  int Factors[3] = { 1, 1, 1 };
  double BoxToTexScale[3] = { 1, 1, 1 };
  double BoxToTexOffset[3] = { 0, 0, 0 };
  double BoxOrigin[3] = { 0, 0, 0 };
  double BoxSize[3] = { 1, 1, 1 };
};
} // namespace nimbus

#endif
