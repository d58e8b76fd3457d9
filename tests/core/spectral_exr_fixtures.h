// SPDX-License-Identifier: Apache-2.0
#pragma once
// Spectral EXR files made by the tests themselves (good ones through SpectralExrWriter, bad ones through
// OpenEXR directly) in a temporary directory, so that no generated binary is committed.

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include <ImfHeader.h>
#include <ImfPixelType.h>

#include "core/spectral_exr.h"

namespace ct::test {

// A fresh directory under the system's temporary directory, removed with everything in it.
class TempDir {
 public:
  TempDir();
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path file(std::string_view name) const { return path_ / name; }

 private:
  std::filesystem::path path_;
};

// A channel given as one value per pixel, [y][x], stored with the given pixel type.
struct RawChannel {
  std::string name;
  std::vector<float> values;
  Imf::PixelType type = Imf::FLOAT;
};

// Writes exactly these channels (ZIP, data window at the origin); `edit_header` may add attributes.
void write_raw_exr(const std::filesystem::path& path, int width, int height, const std::vector<RawChannel>& channels,
                   const std::function<void(Imf::Header&)>& edit_header = {});

// The same value in every pixel of a width × height channel.
RawChannel constant_channel(std::string name, int width, int height, float value);

std::vector<char> read_bytes(const std::filesystem::path& path);
// Writes the first `size` bytes of `source` to `target`.
void write_truncated_copy(const std::filesystem::path& source, const std::filesystem::path& target, std::size_t size);

// An emissive image with all seven path-type components, object ids and metadata, whose total is the
// sum of its components (each pixel and band), from a seeded random generator.
struct ComponentImage {
  SpectralExrLayout layout;
  std::vector<float> total;                    // [y][x][band]
  std::vector<std::vector<float>> components;  // in layout.components order
  std::vector<std::int32_t> object_ids;        // [y][x]
};
ComponentImage make_component_image(int width, int height, std::uint32_t seed);

// Writes an image through SpectralExrWriter, `rows_per_block` rows per write_rows call.
void write_image(const std::filesystem::path& path, const ComponentImage& image, int rows_per_block);

}  // namespace ct::test
