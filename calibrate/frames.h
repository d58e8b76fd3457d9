// SPDX-License-Identifier: Apache-2.0
#pragma once
// The frames of a photon-transfer series as the calibration reads them: a camera raw (DNG, CR2, NEF, … through
// LibRaw, not demosaiced: each 2×2 tile's red, first green and blue, analyzer/raw_input.h), or a linear EXR/TIFF/PNG
// of digital numbers, three channels (R, G, B) or one (a monochrome camera), with the exposure time the file
// records.

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "calibrate/photon_transfer.h"

namespace ct::calibrate {

struct Frame {
  std::string file;
  double exposure_s = 0;
  std::vector<std::string> channel_names;  // R, G, B, or the one channel of a monochrome camera
  std::vector<Plane> channels;             // in digital numbers, black level included
  // What took it: "camera raw, <camera>, CFA <pattern>", or "linear <TIFF|EXR|…>, <channels>".
  std::string sensor;
  // Each pixel read on its own, as a camera raw's photosites are. Otherwise a file's pixels may have been
  // interpolated (demosaiced) or filtered, which the calibration tests on the noise of neighbouring pixels.
  bool photosites = false;
  std::string date;             // EXIF DateTime ("YYYY:MM:DD HH:MM:SS"), when the file has it
  std::optional<int> adc_bits;  // from the file, when it says
  std::optional<double> white_level_dn;
};

// InputError naming the file: unreadable; neither one channel nor R, G, B; not linear (a curve the file names, or
// `input_transfer` declares: analyzer::parse_input_transfer); said by its own metadata to be demosaiced (its pixels
// share noise); a float file of values that are not whole numbers (not digital numbers); or without an exposure time
// (EXIF ExposureTime, or exposure.time_s in the simulator's chromatrace.sensor).
Frame read_frame(const std::filesystem::path& file, const std::string& input_transfer = "auto");

// A frame already in memory (the Python module's arrays), named `name` in messages: one plane (a monochrome camera) or
// three (R, G, B) of `width` × `height` digital numbers, [y][x], black level included, each pixel read on its own
// (their noise's correlation is tested as a file's is). InputError naming `name` for a non-positive exposure time,
// another count of planes, planes of the wrong size, or values that are not finite whole numbers.
Frame frame_in_memory(const std::string& name, double exposure_s, int width, int height, const std::vector<std::vector<double>>& planes);

}  // namespace ct::calibrate
