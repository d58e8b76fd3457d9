// SPDX-License-Identifier: Apache-2.0
#pragma once
// Camera raw files (DNG and the raw formats LibRaw knows: CR2, CR3, NEF, ARW, RAF, ORF, RW2, PEF, …) read as
// linear camera RGB for the analysis (docs/analyze.md, "Camera raw"): the file's black level subtracted, no
// white balance, no colour matrix, no tone curve, and the white level the file gives, so that the clipping
// faces of the histogram are the sensor's. Either demosaiced by one of LibRaw's methods, or, without
// demosaicing, at half size: each 2×2 Bayer tile gives its red, its first green (in row order) and its blue
// exactly as captured.

#include <cstdint>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "analyzer/analysis_image.h"

namespace ct::analyzer {

// How a camera raw file is read: demosaiced by LibRaw's `demosaic` method, or, with `half_size`, not demosaiced
// (each 2×2 tile's own red, green and blue, as captured).
struct RawOptions {
  std::string demosaic = "linear";
  bool half_size = false;
};

// Whether the file is read as a camera raw: by its extension (.dng, .cr2, .nef, … any case).
bool is_camera_raw(const std::filesystem::path& file);

// The demosaicing methods LibRaw offers, by the names --raw-demosaic takes.
const std::vector<std::string>& raw_demosaic_names();

// Reads a camera raw. InputError naming the file when LibRaw cannot decode it (not a raw it knows, data
// ending early or corrupt), when it holds no Bayer mosaic and half size is asked for, or for an unknown
// demosaicing method.
AnalysisImage read_camera_raw(const std::filesystem::path& file, const RawOptions& options);

// A camera raw's Bayer mosaic as stored: one value per visible photosite, [y][x], its black level not subtracted; the
// 2×2 pattern of its top-left tile ("RGGB" …), the mean black level of a tile and the white level. InputError naming
// the file when LibRaw cannot decode it or finds no 2×2 Bayer mosaic in it.
struct CameraMosaic {
  int width = 0, height = 0;
  std::vector<std::uint16_t> values;
  std::string pattern;
  double black_level = 0, white_level = 0;
};
CameraMosaic read_camera_mosaic(const std::filesystem::path& file);

// What `chromatrace info` says of a camera raw: one "key: value" per line, in order.
std::vector<std::pair<std::string, std::string>> describe_camera_raw(const std::filesystem::path& file);

}  // namespace ct::analyzer
