// SPDX-License-Identifier: Apache-2.0
#pragma once
// The sensor simulator end to end (docs/sensor.md): a spectral EXR in, the camera's image out, streamed in
// blocks of rows.
//
// Each block of sensor rows is read (total, path components, object ids), turned into the noise-free linear
// signal (stages 1–3, linear_signal.h) and then into the camera image (stages 4–6: CFA, noise, full well,
// ADC, demosaicing, rendering intent), its rows in parallel, and written while the next block is read; so
// memory holds two blocks, never the spectral image. Demosaicing needs neighbouring rows: a block also reads
// the context rows demosaic_context() asks for (overlapping blocks) and keeps only its own. Noise is keyed by
// pixel (noise.h), so the output is the same for any block size and thread count.

#include <filesystem>
#include <string>
#include <vector>

#include "core/json_input.h"
#include "sensor_sim/config.h"

namespace ct::sensor {

struct RunOptions {
  int threads = 0;     // 0: all cores
  int block_rows = 0;  // sensor rows per block; 0: chosen to keep the input buffers near 8 MB
  bool progress = false;
  // For a spectral reflectance image (T channels): the illuminant that lights it, a CIE name or a CSV file
  // (illumination.h). Empty: the input must hold emitted radiance (S0).
  std::string illuminant;
};

struct RunReport {
  int width = 0;  // the sensor image
  int height = 0;
  double exposure_s = 0;           // the exposure time used (time_s × scale)
  std::vector<std::string> notes;  // decisions taken for this image, also in chromatrace.sensor
  Json effective_config;           // as written to chromatrace.sensor
};

// Checks what can be checked before any work: the output's format and directory, that it is no special file
// and none of `inputs` (core/file_io.h). InputError naming the file.
void check_output_path(const std::filesystem::path& output, const std::vector<std::filesystem::path>& inputs = {});

// Runs the sensor on `input` (an emissive spectral EXR, or a reflective one with options.illuminant) and writes
// `output` (.exr, .tif/.tiff, .png, .dng).
// Bad input is an InputError naming the file and the field; the output then does not exist.
RunReport simulate_sensor(const std::filesystem::path& input, const std::filesystem::path& output, SensorConfig config,
                          const RunOptions& options);

}  // namespace ct::sensor
