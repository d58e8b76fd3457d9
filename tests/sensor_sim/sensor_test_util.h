// SPDX-License-Identifier: Apache-2.0
#pragma once
// Inputs and readers for the sensor simulator's tests: spectral EXRs written on the spot (nothing binary is
// committed), sensor runs on them, and the layers of the result.

#include <array>
#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "core/json_input.h"
#include "core/spectrum.h"
#include "sensor_sim/config.h"
#include "sensor_sim/pipeline.h"

namespace ct::test {

// Writes an emissive spectral EXR whose band values are radiance(x, y, band), with extra chromatrace.* string
// attributes (e.g. chromatrace.camera).
void write_radiance(const std::filesystem::path& path, const Bands& bands, int width, int height,
                    const std::function<float(int x, int y, std::size_t band)>& radiance,
                    const std::map<std::string, std::string>& attributes = {});

// A chromatrace.camera attribute for a horizontal field of view and square pixels.
std::map<std::string, std::string> camera_attribute(double horizontal_fov_deg, int width, int height);

// A camera whose three channels respond equally (1) to every wavelength in 300–900 nm, written as a CSV file.
std::filesystem::path write_flat_camera(const std::filesystem::path& directory);

// The configuration of a patch over the defaults (or the patch's "preset").
sensor::SensorConfig config_of(const Json& patch);

// An RGB layer of an image written by the simulator: "" for R, G, B, else "<layer>.R/G/B"; [y][x][channel].
struct RgbLayer {
  int width = 0;
  int height = 0;
  std::vector<float> values;
  float at(int x, int y, int c) const {
    return values[(static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x)) * 3 +
                  static_cast<std::size_t>(c)];
  }
};
RgbLayer read_rgb(const std::filesystem::path& exr, const std::string& layer = "");

// Runs the simulator quietly.
sensor::RunReport run_sensor(const std::filesystem::path& input, const std::filesystem::path& output,
                             const sensor::SensorConfig& config, int threads = 0, int block_rows = 0);

}  // namespace ct::test
