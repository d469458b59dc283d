// FloatImage: PFM round trip (bit-exact), errors for bad files, tone mapping ends.
#include "FloatImage.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <stdexcept>
#include <string>

TEST(FloatImage, PfmRoundTripIsExact)
{
  nimbus::FloatImage image(5, 3);
  for (std::size_t i = 0; i < image.Pixels.size(); ++i)
  {
    image.Pixels[i] = 0.001f * static_cast<float>(i * i) - 0.25f;
  }
  image.At(4, 2)[1] = 1.0e30f;
  const std::string path = ::testing::TempDir() + "nimbus-roundtrip.pfm";
  image.WritePFM(path);
  const nimbus::FloatImage read = nimbus::FloatImage::ReadPFM(path);
  EXPECT_EQ(read.Width, 5);
  EXPECT_EQ(read.Height, 3);
  EXPECT_EQ(read.Pixels, image.Pixels);
  std::remove(path.c_str());
}

TEST(FloatImage, BadFilesThrow)
{
  EXPECT_THROW(nimbus::FloatImage::ReadPFM("/nonexistent/image.pfm"), std::runtime_error);
  const std::string path = ::testing::TempDir() + "nimbus-bad.pfm";
  std::ofstream(path) << "P6\n2 2\n255\n";
  EXPECT_THROW(nimbus::FloatImage::ReadPFM(path), std::runtime_error);
  std::ofstream(path) << "PF\n4 4\n-1.0\n" << std::string(10, 'x'); // truncated
  EXPECT_THROW(nimbus::FloatImage::ReadPFM(path), std::runtime_error);
  std::remove(path.c_str());
  EXPECT_THROW(nimbus::FloatImage(1, 1).WritePFM("/nonexistent/dir/x.pfm"), std::runtime_error);
}

TEST(FloatImage, ToneMapClipsAndEncodes)
{
  nimbus::FloatImage image(3, 1);
  image.Pixels = { -1.0f, 0.0f, 0.5f, 1.0f, 2.0f, 1e30f, 0.0f, 0.0f, 0.0f };
  const auto bytes = nimbus::ToneMap(image, 1.0);
  ASSERT_EQ(bytes.size(), 9u);
  EXPECT_EQ(bytes[0], 0); // negative -> 0
  EXPECT_EQ(bytes[1], 0);
  EXPECT_EQ(bytes[2], 188); // sRGB(0.5) = 0.7354 -> 188
  EXPECT_EQ(bytes[3], 255);
  EXPECT_EQ(bytes[4], 255); // clipped
  EXPECT_EQ(bytes[5], 255);
  EXPECT_EQ(nimbus::ToneMap(image, 2.0)[2], 255); // exposure 2: 0.5 -> 1
}
