// SPDX-License-Identifier: Apache-2.0
#pragma once
// Writing the sensor simulator's image (docs/sensor.md, "Output"), block by block and atomically: the rows go
// to a temporary file beside the target, renamed into place by finish(); a writer destroyed before finish()
// removes it, so nothing half-written is ever left.
//
// EXR (OpenEXR, FLOAT, ZIP): R, G, B (the final image), linear.R/G/B (noise-free linear signal of the
// total), <component>.R/G/B per path component, display.R/G/B (the picture for people), object_id, string
// attributes and numeric ones (the camera's black and white levels …). TIFF and PNG (OpenImageIO, 8 or 16
// bits): the final image only, with the numeric attributes as OpenImageIO attributes and, since TIFF keeps
// no attributes of its own, as JSON in ImageDescription. DNG (libtiff, dng_writer.h): the Bayer mosaic's digital
// numbers, one per pixel, before demosaicing.

#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "sensor_sim/dng_writer.h"

namespace ct::sensor {

enum class OutputFormat { Exr, Tiff, Png, Dng };

// From the extension (.exr, .tif, .tiff, .png, .dng, any case); an InputError naming the file otherwise.
OutputFormat output_format(const std::filesystem::path& file);

struct OutputLayout {
  int width = 0;
  int height = 0;
  OutputFormat format = OutputFormat::Exr;
  // EXR only.
  std::vector<std::string> components;  // layers <component>.R/G/B, in this order of rows
  bool object_ids = false;
  std::map<std::int32_t, std::string> object_names;  // written as chromatrace.objects
  std::map<std::string, std::string> attributes;     // further string attributes, by full name
  bool display = false;                              // layer display.R/G/B
  // TIFF and PNG only: each value is stored as the code round(value·code_scale), clamped to [0, 2^bits − 1].
  int bits = 16;
  double code_scale = 65535.0;
  std::string colour_space;  // "sRGB" tags the file as such; empty: untagged
  // DNG only: what the file says of the capture.
  DngMetadata dng;
  // Every format but DNG: numeric attributes by full name (EXR: double and int attributes).
  std::map<std::string, double> number_attributes;
  std::map<std::string, int> integer_attributes;
};

// The next rows; every image span holds rows·width·3 floats (a DNG's image rows·width: the mosaic) ([row][x][channel]); components in layout order.
struct OutputRows {
  int rows = 0;
  std::span<const float> image;
  std::span<const float> linear;                   // EXR only
  std::vector<std::span<const float>> components;  // EXR only
  std::span<const float> display;                  // EXR with the display layer only
  std::span<const std::int32_t> object_ids;        // EXR with object ids only: rows·width
};

class SensorImageWriter {
 public:
  // Creates the temporary file (an InputError naming the target if its directory is unusable).
  SensorImageWriter(const std::filesystem::path& path, OutputLayout layout);
  ~SensorImageWriter();
  SensorImageWriter(const SensorImageWriter&) = delete;
  SensorImageWriter& operator=(const SensorImageWriter&) = delete;

  const OutputLayout& layout() const { return layout_; }
  // Appends rows, top to bottom.
  void write_rows(const OutputRows& rows);
  // After the last row: completes the file and renames it into place.
  void finish();

 private:
  struct File;
  std::filesystem::path path_;
  OutputLayout layout_;
  std::unique_ptr<File> file_;
  int rows_written_ = 0;
};

}  // namespace ct::sensor
