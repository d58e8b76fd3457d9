// SPDX-License-Identifier: Apache-2.0
#pragma once
// A spectral EXR's rendered rows read as sensor rows, and their noise-free linear signal (stages 1–3,
// linear_signal.h): what the exposure survey (exposure.h) and the sensor's blocks (pipeline.cpp) both read.
// A sensor pixel covers k×k rendered pixels (k = pixel.supersample).

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "core/spectral_exr.h"
#include "sensor_sim/config.h"
#include "sensor_sim/linear_signal.h"
#include "sensor_sim/rendering_intent.h"

namespace ct::sensor {

inline std::size_t to_size(int n) { return static_cast<std::size_t>(n); }

// OpenEXR's ZIP compression packs 16 scanlines per chunk; blocks of whole chunks decompress each chunk once.
constexpr int kChunkRows = 16;

// What stays fixed over a run.
struct SensorRun {
  SensorConfig config;
  LinearModel model;
  RenderingIntent intent;
  double exposure_s = 0;
  int threads = 0;
  std::vector<double> lighting;  // a reflectance image's illuminant per band (empty for radiance)
  int width() const { return model.width(); }
  int height() const { return model.height(); }
};

// Rows [y0, y1) of a layer read for sensor rows: the rendered rows [k·y0, k·y1). A NaN or infinite radiance
// has no photon count, and no surface emits or reflects a negative total radiance: both are bad input, named by
// channel and pixel. (A component may dip below zero by rounding where it was taken as a difference.) A
// reflectance image is lit: each band's value times the illuminant's band average `lighting` (illumination.h).
std::vector<float> read_sensor_rows(SpectralExrReader& reader, const SpectralLayer& layer, int k, int y0, int y1,
                                    const std::vector<double>& lighting);

// The linear signal of sensor rows [y0, y1) from their rendered rows, in parallel over rows.
std::vector<float> linear_rows(const SensorRun& run, std::span<const float> spectral, int y0, int y1);

// The object id of each sensor pixel: the most frequent of its k×k rendered pixels (the smallest id on a tie).
std::vector<std::int32_t> sensor_ids(const std::vector<std::int32_t>& rendered, int in_width, int k, int width,
                                     int rows);

}  // namespace ct::sensor
