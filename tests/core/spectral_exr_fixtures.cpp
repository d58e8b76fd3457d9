// SPDX-License-Identifier: Apache-2.0
#include "tests/core/spectral_exr_fixtures.h"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <fstream>
#include <iterator>
#include <random>
#include <stdexcept>

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfOutputFile.h>
#include <half.h>

namespace ct::test {

TempDir::TempDir() {
  static std::atomic<int> counter{0};
  path_ = std::filesystem::temp_directory_path() /
          ("chromatrace-test-" + std::to_string(::getpid()) + "-" + std::to_string(counter++));
  std::filesystem::remove_all(path_);
  std::filesystem::create_directories(path_);
}

TempDir::~TempDir() {
  std::error_code ignored;
  std::filesystem::remove_all(path_, ignored);
}

void write_raw_exr(const std::filesystem::path& path, int width, int height, const std::vector<RawChannel>& channels,
                   const std::function<void(Imf::Header&)>& edit_header) {
  Imf::Header header(width, height);
  header.compression() = Imf::ZIP_COMPRESSION;
  if (edit_header) edit_header(header);
  Imf::FrameBuffer frame;
  std::vector<std::vector<half>> halves;
  halves.reserve(channels.size());
  for (const RawChannel& channel : channels) {
    if (channel.values.size() != static_cast<std::size_t>(width) * static_cast<std::size_t>(height))
      throw std::invalid_argument("write_raw_exr: wrong number of values for " + channel.name);
    header.channels().insert(channel.name, Imf::Channel(channel.type));
    if (channel.type == Imf::HALF) {
      halves.emplace_back(channel.values.begin(), channel.values.end());
      frame.insert(channel.name, Imf::Slice(Imf::HALF, reinterpret_cast<char*>(halves.back().data()), sizeof(half),
                                            sizeof(half) * static_cast<std::size_t>(width)));
    } else {
      frame.insert(channel.name,
                   Imf::Slice(Imf::FLOAT, const_cast<char*>(reinterpret_cast<const char*>(channel.values.data())),
                              sizeof(float), sizeof(float) * static_cast<std::size_t>(width)));
    }
  }
  Imf::OutputFile file(path.c_str(), header);
  file.setFrameBuffer(frame);
  file.writePixels(height);
}

RawChannel constant_channel(std::string name, int width, int height, float value) {
  return RawChannel{std::move(name),
                    std::vector<float>(static_cast<std::size_t>(width) * static_cast<std::size_t>(height), value)};
}

std::vector<char> read_bytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + path.string());
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void write_truncated_copy(const std::filesystem::path& source, const std::filesystem::path& target, std::size_t size) {
  const std::vector<char> bytes = read_bytes(source);
  std::ofstream out(target, std::ios::binary);
  out.write(bytes.data(), static_cast<std::streamsize>(std::min(size, bytes.size())));
}

ComponentImage make_component_image(int width, int height, std::uint32_t seed) {
  ComponentImage image;
  SpectralExrLayout& layout = image.layout;
  layout.width = width;
  layout.height = height;
  layout.bands = Bands::from_edges({400, 412.5, 430, 470, 500, 560, 700});
  layout.components = path_type_components();
  layout.object_ids = true;
  layout.object_names = {{1, "floor"}, {2, "sphere"}, {10, "lamp"}};
  layout.attributes = {{"chromatrace.renderer", "test"}, {"chromatrace.samples", "16"}};

  std::mt19937 random(seed);
  std::uniform_real_distribution<float> radiance(0.0f, 2.0f);
  const std::size_t pixels = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  const std::size_t values = pixels * layout.bands.size();
  image.components.assign(layout.components.size(), std::vector<float>(values));
  for (auto& component : image.components)
    for (float& v : component) v = radiance(random);
  // The total as a renderer would write it: the exact sum of the components, rounded once to float.
  image.total.resize(values);
  for (std::size_t i = 0; i < values; ++i) {
    double sum = 0;
    for (const auto& component : image.components) sum += component[i];
    image.total[i] = static_cast<float>(sum);
  }
  image.object_ids.resize(pixels);
  for (std::size_t p = 0; p < pixels; ++p) image.object_ids[p] = static_cast<std::int32_t>(p % 3);
  return image;
}

void write_image(const std::filesystem::path& path, const ComponentImage& image, int rows_per_block) {
  const SpectralExrLayout& layout = image.layout;
  SpectralExrWriter writer(path, layout);
  const std::size_t row_pixels = static_cast<std::size_t>(layout.width);
  const std::size_t row_values = row_pixels * layout.bands.size();
  for (int y0 = 0; y0 < layout.height; y0 += rows_per_block) {
    const int rows = std::min(rows_per_block, layout.height - y0);
    const std::size_t y = static_cast<std::size_t>(y0);
    const std::size_t n = static_cast<std::size_t>(rows);
    SpectralRowBlock block;
    block.rows = rows;
    block.total = std::span<const float>(image.total).subspan(y * row_values, n * row_values);
    for (const auto& component : image.components)
      block.components.push_back(std::span<const float>(component).subspan(y * row_values, n * row_values));
    if (layout.object_ids)
      block.object_ids = std::span<const std::int32_t>(image.object_ids).subspan(y * row_pixels, n * row_pixels);
    writer.write_rows(block);
  }
  writer.finish();
}

}  // namespace ct::test
