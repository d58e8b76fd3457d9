// SPDX-License-Identifier: Apache-2.0
#pragma once
// A small image file for a test: float for .exr, 8-bit otherwise (values as fractions of 255), rows from the top.
#include <filesystem>
#include <vector>

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

namespace ct::test {

inline std::filesystem::path write_test_image(const std::filesystem::path& path, int width, int height,
                                              const std::vector<float>& pixels, int channels = 3) {
  auto out = OIIO::ImageOutput::create(path.string());
  const bool exr = path.extension() == ".exr";
  OIIO::ImageSpec spec(width, height, channels, exr ? OIIO::TypeDesc::FLOAT : OIIO::TypeDesc::UINT8);
  EXPECT_TRUE(out && out->open(path.string(), spec)) << path;
  EXPECT_TRUE(out && out->write_image(OIIO::TypeDesc::FLOAT, pixels.data())) << path;
  if (out) out->close();
  return path;
}

}  // namespace ct::test
