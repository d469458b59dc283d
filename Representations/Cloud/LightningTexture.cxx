#include "LightningTexture.h"

#include "FirstScattering.h"
#include "MultipleScattering.h"
#include "MultipleScatteringTexture.h"

#include "vtkDataArray.h"
#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkIntArray.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkTextureObject.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <vector>

namespace nimbus
{
namespace
{
// The delta-M beam's mean cosine at each point (DeltaMBeamMeanCosine) from the plain and
// the reduced fields; 1 everywhere when the plain field or the optics are missing.
std::vector<float> BeamMeanCosine(vtkFieldData* fields, vtkFloatArray* reduced, std::size_t points)
{
  std::vector<float> out(points, 1.0f);
  vtkFloatArray* plain =
    vtkFloatArray::SafeDownCast(fields->GetAbstractArray("nimbus_lightning_first_scattering"));
  vtkDoubleArray* optics =
    vtkDoubleArray::SafeDownCast(fields->GetAbstractArray("nimbus_lightning_optics"));
  if (!plain || !optics || optics->GetNumberOfValues() != 4 ||
    static_cast<std::size_t>(plain->GetNumberOfTuples()) != points ||
    plain->GetNumberOfComponents() != 4)
  {
    return out;
  }
  nimbus::CloudOptics phase; // the filter's: Cornette-Shanks of its CloudG
  phase.G = optics->GetValue(2);
  const double f = nimbus::PhaseLegendreCoefficient(phase, 2);
  const double lobeG = nimbus::DeltaMPeakLobeG(phase);
  const float* e = plain->GetPointer(0);
  const float* r = reduced->GetPointer(0);
  for (std::size_t i = 0; i < points; ++i)
  {
    out[i] = static_cast<float>(nimbus::DeltaMBeamMeanCosine(e[4 * i], r[4 * i], f, lobeG));
  }
  return out;
}
} // namespace

LightningTexture::LightningTexture() = default;
LightningTexture::~LightningTexture() = default;

vtkTextureObject* LightningTexture::GetTexture(int channel) const
{
  return this->Textures[channel].GetPointer();
}

bool LightningTexture::Update(vtkOpenGLRenderWindow* window, vtkImageData* image, bool cellData,
  const std::array<int, 3>& textureDimensions, const std::array<int, 3>& textureFactors,
  std::string& error)
{
  if (!this->UpdateFirstScattering(
        window, image, cellData, textureDimensions, textureFactors, error))
  {
    return false;
  }
  vtkFieldData* fields = image->GetFieldData();
  vtkFloatArray* values = fields
    ? vtkFloatArray::SafeDownCast(fields->GetAbstractArray("nimbus_lightning_in_scattering"))
    : nullptr;
  vtkIntArray* layout =
    fields ? vtkIntArray::SafeDownCast(fields->GetAbstractArray("nimbus_lightning_grid")) : nullptr;
  const std::array<int, 6> noLayout{};
  if (!values || !layout)
  {
    this->Textured = false;
    this->UploadedArray = nullptr;
    return true;
  }
  std::array<int, 6> grid{};
  const bool layoutShape = layout->GetNumberOfValues() == 7;
  for (int k = 0; layoutShape && k < 6; ++k)
  {
    grid[k] = layout->GetValue(k);
  }
  const unsigned long time = values->GetMTime();
  if (values == this->UploadedArray && time == this->UploadedTime && grid == this->UploadedLayout)
  {
    return true;
  }
  this->Textured = false;
  this->UploadedArray = values;
  this->UploadedTime = time;
  this->UploadedLayout = noLayout;

  // The layout must fit this image: blocks of D input samples, ceil(n / D) points.
  int pointDims[3];
  image->GetDimensions(pointDims);
  bool fits =
    layoutShape && values->GetNumberOfComponents() == 12 && (layout->GetValue(6) != 0) == cellData;
  std::size_t points = 1;
  for (int k = 0; fits && k < 3; ++k)
  {
    const int samples = cellData ? std::max(pointDims[k] - 1, 1) : pointDims[k];
    fits = grid[k] >= 1 && grid[3 + k] >= 1 && (samples + grid[3 + k] - 1) / grid[3 + k] == grid[k];
    points *= static_cast<std::size_t>(std::max(grid[k], 0));
  }
  if (!fits || static_cast<std::size_t>(values->GetNumberOfTuples()) != points)
  {
    error = "The lightning arrays in the image's field data do not fit this image (another "
            "density array, point and cell data mixed, or a changed grid); the cloud is drawn "
            "without lightning. Re-run the Lightning Illumination filter on this cloud.";
    return false;
  }
  const float* data = values->GetPointer(0);
  bool any = false;
  for (std::size_t i = 0; i < 12 * points; ++i)
  {
    if (!std::isfinite(data[i]))
    {
      error = "The lightning field holds NaN or infinite values; the cloud is drawn without "
              "lightning.";
      return false;
    }
    any = any || data[i] != 0.0f;
  }
  vtkDoubleArray* optics =
    vtkDoubleArray::SafeDownCast(fields->GetAbstractArray("nimbus_lightning_optics"));
  for (int k = 0; k < 4; ++k)
  {
    this->Optics[k] = optics && optics->GetNumberOfValues() == 4
      ? optics->GetValue(k)
      : std::numeric_limits<double>::quiet_NaN();
  }
  for (int k = 0; k < 3; ++k)
  {
    // As for the multiple-scattering texture: density texture coordinate u = (s + 0.5) /
    // (n_tex f) for input sample position s; this texture's v = (s + 0.5) / (n' D).
    this->TextureScale[k] = static_cast<double>(textureDimensions[k]) * textureFactors[k] /
      (static_cast<double>(grid[k]) * grid[3 + k]);
  }
  this->UploadedLayout = grid;
  if (!any)
  {
    return true; // dark: nothing to draw
  }
  vtkTextureObject* textures[3] = { this->Textures[0], this->Textures[1], this->Textures[2] };
  if (!UploadShCoefficients(window, textures, { { grid[0], grid[1], grid[2] } }, data))
  {
    std::ostringstream message;
    message << "Could not upload the lightning texture (" << 48.0 * points / 1048576.0
            << " MiB; GL out of memory?); the cloud is drawn without lightning.";
    error = message.str();
    return false;
  }
  this->Textured = true;
  ++this->Uploads;
  return true;
}

bool LightningTexture::UpdateFirstScattering(vtkOpenGLRenderWindow* window, vtkImageData* image,
  bool cellData, const std::array<int, 3>& textureDimensions,
  const std::array<int, 3>& textureFactors, std::string& error)
{
  vtkFieldData* fields = image->GetFieldData();
  vtkFloatArray* reduced = fields && this->PreferReduced
    ? vtkFloatArray::SafeDownCast(
        fields->GetAbstractArray("nimbus_lightning_first_scattering_reduced"))
    : nullptr;
  vtkFloatArray* values = reduced ? reduced
    : fields
    ? vtkFloatArray::SafeDownCast(fields->GetAbstractArray("nimbus_lightning_first_scattering"))
    : nullptr;
  this->FirstScatteringReduced = reduced != nullptr;
  vtkDoubleArray* layout = fields ? vtkDoubleArray::SafeDownCast(fields->GetAbstractArray(
                                      "nimbus_lightning_first_scattering_grid"))
                                  : nullptr;
  if (!values || !layout || layout->GetNumberOfValues() != 10)
  {
    this->FirstScatteringTextured = false;
    this->FirstScatteringArray = nullptr;
    return true;
  }
  if (values == this->FirstScatteringArray && values->GetMTime() == this->FirstScatteringTime)
  {
    return true;
  }
  this->FirstScatteringTextured = false;
  this->FirstScatteringArray = values;
  this->FirstScatteringTime = values->GetMTime();
  int pointDims[3];
  image->GetDimensions(pointDims);
  std::array<int, 3> grid{}, blocks{};
  bool fits = values->GetNumberOfComponents() == 4 && (layout->GetValue(6) != 0) == cellData;
  std::size_t points = 1;
  for (int k = 0; fits && k < 3; ++k)
  {
    grid[k] = static_cast<int>(layout->GetValue(k));
    blocks[k] = static_cast<int>(layout->GetValue(3 + k));
    this->FirstScatteringColour[k] = layout->GetValue(7 + k);
    const int samples = cellData ? std::max(pointDims[k] - 1, 1) : pointDims[k];
    fits = grid[k] >= 1 && blocks[k] >= 1 && (samples + blocks[k] - 1) / blocks[k] == grid[k] &&
      std::isfinite(this->FirstScatteringColour[k]) && this->FirstScatteringColour[k] >= 0.0;
    points *= static_cast<std::size_t>(std::max(grid[k], 0));
  }
  if (!fits || static_cast<std::size_t>(values->GetNumberOfTuples()) != points)
  {
    error = "The lightning's first-scattering arrays do not fit this image; the cloud is drawn "
            "without lightning. Re-run the Lightning Illumination filter on this cloud.";
    return false;
  }
  // E in alpha, F in RGB: one texture fetch gives the lobe.
  const float* data = values->GetPointer(0);
  std::vector<float> texels(4 * points);
  for (std::size_t i = 0; i < points; ++i)
  {
    for (int c = 0; c < 4; ++c)
    {
      if (!std::isfinite(data[4 * i + c]))
      {
        error = "The lightning's first scattering holds NaN or infinite values; the cloud is "
                "drawn without lightning.";
        return false;
      }
    }
    texels[4 * i] = data[4 * i + 1];
    texels[4 * i + 1] = data[4 * i + 2];
    texels[4 * i + 2] = data[4 * i + 3];
    texels[4 * i + 3] = data[4 * i];
  }
  for (int k = 0; k < 3; ++k)
  {
    this->FirstScatteringScale[k] = static_cast<double>(textureDimensions[k]) * textureFactors[k] /
      (static_cast<double>(grid[k]) * blocks[k]);
  }
  if (!UploadFloatTexture3D(window, this->FirstScattering, grid, 4, texels.data()))
  {
    std::ostringstream message;
    message << "Could not upload the lightning's first scattering (" << 16.0 * points / 1048576.0
            << " MiB; GL out of memory?); the cloud is drawn without lightning.";
    error = message.str();
    return false;
  }
  // The delta-M view's beam: how far its light has spread from the sources' directions.
  std::vector<float> beamCosine(points, 1.0f);
  if (reduced)
  {
    beamCosine = BeamMeanCosine(fields, reduced, points);
  }
  if (!UploadFloatTexture3D(window, this->BeamCosine, grid, 1, beamCosine.data()))
  {
    error = "Could not upload the lightning beam's spread (GL out of memory?); the cloud is "
            "drawn without lightning.";
    return false;
  }
  this->FirstScatteringTextured = true;
  ++this->Uploads;
  return true;
}

void LightningTexture::Release(vtkWindow* window)
{
  for (auto& t : this->Textures)
  {
    t->ReleaseGraphicsResources(window);
  }
  this->FirstScattering->ReleaseGraphicsResources(window);
  this->BeamCosine->ReleaseGraphicsResources(window);
  this->Textured = false;
  this->UploadedArray = nullptr;
  this->FirstScatteringTextured = false;
  this->FirstScatteringArray = nullptr;
}
} // namespace nimbus
