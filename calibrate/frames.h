// SPDX-License-Identifier: Apache-2.0
#pragma once
// The frames of a photon-transfer series as the calibration reads them: a camera raw (DNG, CR2, NEF, … through
// LibRaw, not demosaiced: each 2×2 tile's red, first green and blue, analyzer/raw_input.h) or a linear EXR/TIFF
// of digital numbers whose pixels were each measured on their own (the sensor simulator's output without a CFA),
// with the exposure time the file records.

#include <array>
#include <filesystem>
#include <optional>
#include <string>

#include "calibrate/photon_transfer.h"

namespace ct::calibrate {

struct Frame {
  std::string file;
  double exposure_s = 0;
  std::array<Plane, 3> channels;  // R, G, B in digital numbers, black level included
  std::string sensor;             // what took it: "camera raw, <camera>, CFA <pattern>" or "linear <EXR|TIFF>, no CFA"
  std::optional<int> adc_bits;    // from the file, when it says
  std::optional<double> white_level_dn;
};

inline constexpr std::array<const char*, 3> kChannelNames = {"R", "G", "B"};

// InputError naming the file: unreadable, not linear, demosaiced (its pixels share noise), or without an exposure
// time (EXIF ExposureTime, or exposure.time_s in the simulator's chromatrace.sensor).
Frame read_frame(const std::filesystem::path& file);

}  // namespace ct::calibrate
