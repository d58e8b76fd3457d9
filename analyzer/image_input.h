// SPDX-License-Identifier: Apache-2.0
#pragma once
// Reading the image an analysis reads (analyzer/analysis_image.h): any file OpenImageIO opens (8/16-bit PNG/TIFF,
// float EXR, …), with the sensor simulator's extra layers, object ids and camera numbers when present, or a
// camera raw through analyzer/raw_input.h; and label images.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "analyzer/analysis_image.h"
#include "analyzer/raw_input.h"  // RawOptions

namespace ct::analyzer {

// What R, G, B are: "auto" (decide from the file, below), "linear", "srgb", or "gamma=G" (stored = I^(1/G), as
// a display gamma G: gamma=2.2 is I' = I^0.4545). InputError naming --input-transfer for anything else.
// auto: the sensor simulator's chromatrace.curve_* (or, from an older simulator, linear with its other camera
// numbers); else the colour space OpenImageIO reports (oiio:ColorSpace sRGB, linear, or GammaCorrected with
// oiio:Gamma); else a float file is linear and an integer file is sRGB, as cameras, phones and browsers store it.
std::optional<ToneCurve> parse_input_transfer(const std::string& text);

// Reads R, G, B (or a grey-free file's first three channels) and whatever extra layers are present.
// When the file says what the camera's black level was (chromatrace.black_level, as an attribute or in the
// ImageDescription JSON of a TIFF/PNG), it is subtracted from R, G, B, so that black is 0 for every fit
// through black. An unreadable file, fewer than three channels or a malformed object_id /
// chromatrace.objects is an InputError naming the file.
// A camera raw (DNG, CR2, NEF, …: raw_input.h) is read as linear camera RGB as `raw` says.
AnalysisImage read_analysis_image(const std::filesystem::path& file, const std::string& input_transfer = "auto",
                                  const RawOptions& raw = {});

// The same analysis image from R, G, B (and, with `alpha`, A) already in memory (an array: [y][x][channel], `width` ×
// `height` × 3 or 4 values), named `name` in messages: `integer_bits` 8, 16 or 32 for integer samples given as their
// stored integers (as an integer file's are read), 0 for float. Read as a file of those values would be, without the
// metadata a file can carry: under "auto", integer samples are sRGB (a picture) and float ones linear; an alpha of 0
// sets its pixel aside, as a file's does. InputError naming `name` for a size that does not match or other bits.
AnalysisImage read_analysis_pixels(const std::string& name, int width, int height, std::vector<float> values, int integer_bits,
                                   const std::string& input_transfer = "auto", bool alpha = false);

// The frame of a camera measurement (chromatrace calibrate): one channel (a monochrome camera) or R, G, B (an alpha
// channel aside), each as stored: integer files in their stored integers, the black level not subtracted. The
// encoding says what the file says of the camera (chromatrace.*) and of its curve. Under "auto", an integer TIFF or
// PNG holds a measurement camera's digital numbers (linear) unless the simulator's chromatrace.curve_* or a gamma
// (oiio:Gamma) says otherwise, where read_analysis_image takes it for a picture (sRGB): the sRGB colour space that
// EXIF's ColorSpace tag and PNG give by default says nothing of such frames. A JPEG is a tone-mapped picture (sRGB).
// InputError naming the file for anything else.
struct CameraFrame {
  int width = 0;
  int height = 0;
  std::vector<std::string> channels;       // the channels' names
  std::vector<std::vector<float>> planes;  // one per channel, [y][x]
  ImageEncoding encoding;
};
CameraFrame read_camera_frame(const std::filesystem::path& file, const std::string& input_transfer = "auto");

// A single-channel integer image (a label image), [y][x]. Integer files give their stored integers; a
// float file must hold whole numbers. InputError naming the file otherwise.
struct LabelImage {
  int width = 0;
  int height = 0;
  std::vector<std::int32_t> labels;
};
LabelImage read_label_image(const std::filesystem::path& file);

}  // namespace ct::analyzer
