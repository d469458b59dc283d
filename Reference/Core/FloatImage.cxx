#include "FloatImage.h"

#include "MemoryBudget.h"
#include "SpectralColor.h"

#include <cstdint>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

namespace nimbus
{

std::string NonFiniteMessage(const FloatImage& image)
{
  ValueCensus census = TakeCensus(image.Pixels.data(), image.Pixels.size());
  census.Negative = 0;
  if (census.AllFiniteNonNegative())
  {
    return std::string();
  }
  return DescribeCensus(census) + " among " + std::to_string(image.Pixels.size()) +
    " pixel components";
}

namespace
{
bool LittleEndianHost()
{
  const std::uint16_t one = 1;
  unsigned char first;
  std::memcpy(&first, &one, 1);
  return first == 1;
}
}

void FloatImage::WritePFM(const std::string& path) const
{
  std::ofstream out(path, std::ios::binary);
  if (!out)
  {
    throw std::runtime_error("cannot write " + path);
  }
  // Negative scale = little-endian data; rows bottom to top (our row order).
  out << "PF\n" << this->Width << " " << this->Height << "\n-1.0\n";
  if (LittleEndianHost())
  {
    out.write(reinterpret_cast<const char*>(this->Pixels.data()),
      static_cast<std::streamsize>(this->Pixels.size() * sizeof(float)));
  }
  else
  {
    for (float value : this->Pixels)
    {
      unsigned char bytes[4];
      std::memcpy(bytes, &value, 4);
      const unsigned char swapped[4] = { bytes[3], bytes[2], bytes[1], bytes[0] };
      out.write(reinterpret_cast<const char*>(swapped), 4);
    }
  }
  if (!out)
  {
    throw std::runtime_error("error writing " + path);
  }
}

FloatImage FloatImage::ReadPFM(const std::string& path)
{
  std::ifstream in(path, std::ios::binary);
  if (!in)
  {
    throw std::runtime_error("cannot read " + path);
  }
  std::string magic;
  int width = 0, height = 0;
  double scale = 0.0;
  in >> magic >> width >> height >> scale;
  in.get(); // the single whitespace after the header
  if (magic != "PF" || width <= 0 || height <= 0 || scale >= 0.0)
  {
    throw std::runtime_error(path + ": not a little-endian RGB PFM");
  }
  FloatImage image(width, height);
  in.read(reinterpret_cast<char*>(image.Pixels.data()),
    static_cast<std::streamsize>(image.Pixels.size() * sizeof(float)));
  if (!in || !LittleEndianHost())
  {
    throw std::runtime_error(path + ": truncated PFM (or big-endian host)");
  }
  return image;
}

std::vector<unsigned char> ToneMap(const FloatImage& image, double exposure)
{
  std::vector<unsigned char> bytes(image.Pixels.size());
  for (std::size_t i = 0; i < image.Pixels.size(); ++i)
  {
    const double encoded = SrgbEncode(exposure * image.Pixels[i]); // clamps to [0, 1]
    bytes[i] = static_cast<unsigned char>(encoded * 255.0 + 0.5);
  }
  return bytes;
}

} // namespace nimbus
