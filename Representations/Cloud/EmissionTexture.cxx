#include "EmissionTexture.h"

#include "BlackbodyEmission.h"
#include "MultipleScatteringTexture.h"
#include "SpectralColor.h"

#include "vtkCellData.h"
#include "vtkDataArray.h"
#include "vtkImageData.h"
#include "vtkOpenGLRenderWindow.h"
#include "vtkPointData.h"
#include "vtkTextureObject.h"
#include "vtk_glew.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <sstream>
#include <stdexcept>

namespace nimbus
{
std::vector<float> ComputeEmissionTexels(const float* density, const float* temperature,
  const std::array<int, 3>& dimensions, const std::array<int, 3>& factors,
  const std::array<int, 3>& textureDimensions, const BlackbodyEmission& emission)
{
  const std::size_t texels =
    static_cast<std::size_t>(textureDimensions[0]) * textureDimensions[1] * textureDimensions[2];
  std::vector<double> sum(3 * texels, 0.0);
  std::vector<double> count(texels, 0.0);
  const std::size_t nx = static_cast<std::size_t>(dimensions[0]);
  const std::size_t ny = static_cast<std::size_t>(dimensions[1]);
  for (int k = 0; k < dimensions[2]; ++k)
  {
    const std::size_t tk =
      static_cast<std::size_t>(std::min(k / factors[2], textureDimensions[2] - 1));
    for (int j = 0; j < dimensions[1]; ++j)
    {
      const std::size_t tj =
        static_cast<std::size_t>(std::min(j / factors[1], textureDimensions[1] - 1));
      for (int i = 0; i < dimensions[0]; ++i)
      {
        const std::size_t ti =
          static_cast<std::size_t>(std::min(i / factors[0], textureDimensions[0] - 1));
        const std::size_t texel = (tk * textureDimensions[1] + tj) * textureDimensions[0] + ti;
        const std::size_t s = (static_cast<std::size_t>(k) * ny + j) * nx + i;
        count[texel] += 1.0;
        const double rho = density[s];
        if (!(rho > 0.0) || !std::isfinite(rho))
        {
          continue;
        }
        const auto rgb = emission.RelativeRgb(temperature[s]);
        for (int c = 0; c < 3; ++c)
        {
          sum[3 * texel + c] += rho * rgb[c];
        }
      }
    }
  }
  std::vector<float> texelsRgb(3 * texels, 0.0f);
  for (std::size_t t = 0; t < texels; ++t)
  {
    for (int c = 0; c < 3; ++c)
    {
      // Float's range: a texel holds at most 3e38 (a density of 1e30 at 10^4 K is ~1e38).
      const double v = count[t] > 0.0 ? sum[3 * t + c] / count[t] : 0.0;
      texelsRgb[3 * t + c] = static_cast<float>(std::min(v, 3.0e38));
    }
  }
  return texelsRgb;
}

EmissionTexture::EmissionTexture() = default;
EmissionTexture::~EmissionTexture() = default;

vtkTextureObject* EmissionTexture::GetTexture() const
{
  return this->Texture.GetPointer();
}

namespace
{
// One float per sample, x fastest, from any numeric 1-component array.
std::vector<float> ToFloats(vtkDataArray* array)
{
  std::vector<float> values(static_cast<std::size_t>(array->GetNumberOfTuples()));
  for (vtkIdType i = 0; i < array->GetNumberOfTuples(); ++i)
  {
    values[static_cast<std::size_t>(i)] = static_cast<float>(array->GetComponent(i, 0));
  }
  return values;
}
} // namespace

bool EmissionTexture::Update(vtkOpenGLRenderWindow* window, vtkImageData* image,
  vtkDataArray* density, bool cellData, const std::string& temperatureArray,
  double referenceTemperatureKelvin, const std::array<int, 3>& textureDimensions,
  const std::array<int, 3>& textureFactors, std::string& error)
{
  vtkDataArray* temperature = cellData ? image->GetCellData()->GetArray(temperatureArray.c_str())
                                       : image->GetPointData()->GetArray(temperatureArray.c_str());
  if (!density || !temperature || temperature->GetNumberOfComponents() != 1 ||
    temperature->GetNumberOfTuples() != density->GetNumberOfTuples() ||
    density->GetNumberOfComponents() != 1)
  {
    this->Textured = false;
    this->UploadedKey.clear();
    error = "Temperature emission needs a 1-component " + std::string(cellData ? "cell" : "point") +
      " array \"" + temperatureArray +
      "\" (kelvin) beside the density; the cloud is drawn without emission.";
    return false;
  }
  const std::vector<double> key = { static_cast<double>(reinterpret_cast<std::uintptr_t>(density)),
    static_cast<double>(density->GetMTime()),
    static_cast<double>(reinterpret_cast<std::uintptr_t>(temperature)),
    static_cast<double>(temperature->GetMTime()), referenceTemperatureKelvin,
    static_cast<double>(textureDimensions[0]), static_cast<double>(textureDimensions[1]),
    static_cast<double>(textureDimensions[2]), static_cast<double>(textureFactors[0]),
    static_cast<double>(textureFactors[1]), static_cast<double>(textureFactors[2]) };
  if (key == this->UploadedKey)
  {
    return true;
  }
  this->Textured = false;
  this->UploadedKey.clear();
  int dims[3];
  image->GetDimensions(dims);
  std::array<int, 3> samples{};
  std::size_t count = 1;
  for (int k = 0; k < 3; ++k)
  {
    samples[k] = cellData ? std::max(dims[k] - 1, 1) : dims[k];
    count *= static_cast<std::size_t>(samples[k]);
  }
  if (count != static_cast<std::size_t>(density->GetNumberOfTuples()))
  {
    error = "The density array does not fit the image; the cloud is drawn without emission.";
    return false;
  }
  std::unique_ptr<BlackbodyEmission> emission;
  try
  {
    static const SpectralSamples spectrum;
    emission.reset(new BlackbodyEmission(spectrum, referenceTemperatureKelvin));
  }
  catch (const std::invalid_argument& problem)
  {
    error = std::string("Temperature emission: ") + problem.what() +
      "; the cloud is drawn without emission.";
    return false;
  }
  const std::vector<float> rho = ToFloats(density);
  const std::vector<float> kelvin = ToFloats(temperature);
  const std::vector<float> texels = ComputeEmissionTexels(
    rho.data(), kelvin.data(), samples, textureFactors, textureDimensions, *emission);
  this->Maximum = 0.0;
  for (const float v : texels)
  {
    this->Maximum = std::max(this->Maximum, static_cast<double>(v));
  }
  this->UploadedKey = key;
  if (this->Maximum <= 0.0)
  {
    return true; // nothing glows: no texture, no cost in the shader
  }
  if (!UploadFloatTexture3D(window, this->Texture,
        { { textureDimensions[0], textureDimensions[1], textureDimensions[2] } }, 3, texels.data()))
  {
    this->UploadedKey.clear();
    std::ostringstream message;
    message << "Could not upload the emission texture (" << 12.0 * texels.size() / 3 / 1048576.0
            << " MiB; GL out of memory?); the cloud is drawn without emission.";
    error = message.str();
    return false;
  }
  this->Textured = true;
  ++this->Uploads;
  return true;
}

void EmissionTexture::Release(vtkWindow* window)
{
  this->Texture->ReleaseGraphicsResources(window);
  this->Textured = false;
  this->UploadedKey.clear();
}
} // namespace nimbus
