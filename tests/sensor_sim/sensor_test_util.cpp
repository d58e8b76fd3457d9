// SPDX-License-Identifier: Apache-2.0
#include "tests/sensor_sim/sensor_test_util.h"

#include <cmath>
#include <fstream>
#include <numbers>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "core/spectral_exr.h"

namespace ct::test {

void write_radiance(const std::filesystem::path& path, const Bands& bands, int width, int height,
                    const std::function<float(int x, int y, std::size_t band)>& radiance,
                    const std::map<std::string, std::string>& attributes) {
  SpectralExrLayout layout;
  layout.width = width;
  layout.height = height;
  layout.bands = bands;
  layout.attributes = attributes;
  std::vector<float> total;
  total.reserve(static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * bands.size());
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      for (std::size_t b = 0; b < bands.size(); ++b) total.push_back(radiance(x, y, b));
  SpectralExrWriter writer(path, layout);
  SpectralRowBlock block;
  block.rows = height;
  block.total = total;
  writer.write_rows(block);
  writer.finish();
}

std::map<std::string, std::string> camera_attribute(double horizontal_fov_deg, int width, int height) {
  const double t = std::tan(horizontal_fov_deg * std::numbers::pi / 360.0) * height / width;
  const nlohmann::json camera = {{"horizontal_fov_deg", horizontal_fov_deg},
                                 {"vertical_fov_deg", 2.0 * std::atan(t) * 180.0 / std::numbers::pi},
                                 {"resolution", {width, height}}};
  return {{"chromatrace.camera", camera.dump()}};
}

std::filesystem::path write_flat_camera(const std::filesystem::path& directory) {
  const std::filesystem::path file = directory / "flat_camera.csv";
  std::ofstream(file) << "wavelength_nm,r,g,b\n300,1,1,1\n900,1,1,1\n";
  return file;
}

sensor::SensorConfig config_of(const Json& patch) { return sensor::resolve_config({{patch, "test config"}}); }

RgbLayer read_rgb(const std::filesystem::path& exr, const std::string& layer) {
  SpectralExrReader reader(exr);
  RgbLayer rgb;
  rgb.width = reader.info().width;
  rgb.height = reader.info().height;
  rgb.values.resize(static_cast<std::size_t>(rgb.width) * static_cast<std::size_t>(rgb.height) * 3);
  std::vector<std::string> channels;
  for (const char* c : {"R", "G", "B"}) channels.push_back(layer.empty() ? c : fmt::format("{}.{}", layer, c));
  reader.read_channels(channels, 0, rgb.height, rgb.values);
  return rgb;
}

sensor::RunReport run_sensor(const std::filesystem::path& input, const std::filesystem::path& output,
                             const sensor::SensorConfig& config, int threads, int block_rows) {
  sensor::RunOptions options;
  options.threads = threads;
  options.block_rows = block_rows;
  return sensor::simulate_sensor(input, output, config, options);
}

}  // namespace ct::test
