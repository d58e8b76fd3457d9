// SPDX-License-Identifier: Apache-2.0
#pragma once
// The image an analysis reads, as its readers (analyzer/image_input.h, analyzer/raw_input.h) give it: the final
// R, G, B and, from the sensor simulator's EXR output, also the noise-free linear signal, the light-path components
// and the object ids, with what is known of how R, G, B were encoded.
//
// Values keep the file's own scale: integer files in digital numbers (0…255, 0…65535), float files as
// stored (HDR values above 1 stay above 1), so every number in analysis.json is in the units a person
// sees when they open the file.

#include <cmath>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "analyzer/moments.h"  // Vec3

namespace ct::analyzer {

// Three channels per pixel, [y][x][channel], rows from the top.
struct RgbImage {
  int width = 0;
  int height = 0;
  std::vector<float> rgb;

  std::size_t pixel_count() const { return static_cast<std::size_t>(width) * static_cast<std::size_t>(height); }
};

// The response curve that encoded R, G, B from a normalised linear signal n (1 = the camera's white):
// stored = full_scale · f(n) with f(n) = k·n^γ, or the sRGB curve; odd-symmetric, so that values below black
// keep their sign (docs/sensor.md, "Output").
struct ToneCurve {
  double gamma = 1;
  double k = 1;
  bool srgb = false;

  bool linear() const { return !srgb && gamma == 1 && k == 1; }
  std::string describe() const;
  // The linear signal, in the file's units, of a stored value.
  double decode(double stored, double full_scale) const;
};

struct ImageEncoding {
  bool integer = false;    // stored as unsigned integers
  int bits = 0;            // bits per sample of integer files (8, 16, 32); 0 for float
  double full_scale = 1;   // the value of a full-scale sample: 2^bits − 1, or 1 for float files

  // What the camera did, from the sensor simulator's metadata (chromatrace.black_level …, docs/sensor.md),
  // in the units of the file's R, G, B; absent without it. Describes the final layer only.
  std::string metadata = "";          // where it was read: "attributes", "ImageDescription", or "" (none)
  std::optional<double> black_level = std::nullopt;  // the value that means no light
  bool black_subtracted = false;      // R, G, B hold the stored value − black_level
  std::optional<double> white_level = std::nullopt;  // the stored value at which R, G, B clip (black level included)
  std::optional<double> dark_signal = std::nullopt;  // the mean dark-current signal above black
  std::optional<double> read_noise = std::nullopt;   // σ of the read noise
  std::optional<int> adc_bits = std::nullopt;  // the ADC's bits (0: no ADC)
  std::optional<bool> noise = std::nullopt;  // whether noise was on
  std::optional<bool> adc = std::nullopt;    // whether the ADC was on
  std::optional<bool> pixel_area = std::nullopt;  // whether pixels integrate an area (false: point samples)
  // Whether R, G, B were interpolated from a colour filter array's photosites (chromatrace.cfa, or a raw file
  // read through LibRaw's demosaicing), so that neighbouring pixels share their noise; unknown for a
  // photograph, whose camera almost surely did.
  std::optional<bool> demosaiced = std::nullopt;
  std::optional<ToneCurve> curve = std::nullopt;   // the response curve R, G, B were encoded with
  std::string curve_source = "";                   // why that curve: the metadata or rule it came from

  // The value R, G, B hold for black: −black_level once subtracted, else 0 (the ADC's code 0 lies at
  // −black_level after subtraction).
  double lowest_code() const { return black_subtracted && black_level ? -*black_level : 0.0; }
  // Whether each pixel's noise is its own, so that adjacent pixels measure it (analyzer/noise_level.h): only
  // when the file says no colour filter array was demosaiced.
  bool independent_pixel_noise() const { return demosaiced == false; }
  // The level at which the analysed R, G, B clip: the white level less the subtracted black level.
  std::optional<double> clipping_level() const {
    if (!white_level) return std::nullopt;
    return *white_level - (black_subtracted && black_level ? *black_level : 0.0);
  }
};

// One light-path component layer, <name>.R/G/B, in the units of the linear layer.
struct ComponentLayer {
  std::string name;  // "diffuse_direct", "light.key", "bounce.2", …
  RgbImage image;
};

struct AnalysisImage {
  std::string file;  // as given, for messages
  RgbImage image;    // R, G, B: the final image
  ImageEncoding encoding;
  std::optional<RgbImage> linear;          // linear.R/G/B: noise-free linear camera signal of the total
  std::optional<RgbImage> display;         // display.R/G/B: the picture for people, sRGB-encoded in [0, 1]
  std::vector<ComponentLayer> components;  // in chromatrace.components order when the file names them
  std::vector<std::int32_t> object_ids;    // channel object_id, [y][x]; empty when absent
  std::map<std::int32_t, std::string> object_names;  // attribute chromatrace.objects
  // Pixels of R, G, B set aside as they were read (set to NaN, so that every region leaves them out): those an
  // alpha channel makes fully transparent, and, in a file without the camera's numbers, those with a negative
  // value (no light is negative; a camera's noise below black comes with its black level).
  std::size_t transparent_pixels = 0;
  std::size_t negative_pixels = 0;
  std::vector<std::string> notes;  // what was decided while reading (alpha, conversions)
  // A camera raw's as-shot white balance as the light's colour it assumes: (1/m_R, 1/m_G, 1/m_B) of LibRaw's
  // camera multipliers, in the file's linear camera RGB. A reference beside the estimates, not the truth.
  std::optional<Vec3> camera_white;
};

// Stored values to linear light: a table for the integer codes of an integer file (exactly the curve's value
// at each code), else the curve itself.
struct CodeDecoder {
  std::optional<ToneCurve> curve;  // none when linear
  double full_scale = 1;
  std::vector<float> table;
  CodeDecoder(const std::optional<ToneCurve>& c, double full_scale);
  float operator()(float v) const {
    if (!curve) return v;
    if (!table.empty() && v >= 0 && v < static_cast<float>(table.size()) && v == std::floor(v)) return table[static_cast<std::size_t>(v)];
    return static_cast<float>(curve->decode(v, full_scale));
  }
};

// The final image in linear light: R, G, B with the encoding's curve undone (a copy of the image when the
// curve is linear or unknown).
RgbImage linear_light(const AnalysisImage& input);

// The RGB layer the histograms are made of: "" or "final" for R,G,B, "linear", or a component's name.
// An unknown name is an InputError listing the layers the file has.
const RgbImage& select_layer(const AnalysisImage& input, const std::string& layer);

}  // namespace ct::analyzer
