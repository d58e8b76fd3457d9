// SPDX-License-Identifier: Apache-2.0
#include "calibrate/frames.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <string>

#include <fmt/format.h>
#include <OpenImageIO/imageio.h>

#include "analyzer/image_input.h"
#include "analyzer/raw_input.h"
#include "core/error.h"
#include "core/json_input.h"

namespace ct::calibrate {
namespace {

// The exposure time a file records: EXIF's ExposureTime (camera raw, DNG, a camera's TIFF), else the simulator's
// settings; and its date (EXIF DateTime).
std::optional<double> recorded_exposure(const std::filesystem::path& file, std::string& date) {
  auto in = OIIO::ImageInput::open(file.string());
  if (!in) {
    (void)OIIO::geterror();
    return std::nullopt;
  }
  const OIIO::ImageSpec& spec = in->spec();
  date = spec.get_string_attribute("DateTime");
  // EXIF's time is a float here: read as the decimal it is the nearest float to (0.0012, not 0.0012000000569969416),
  // so that it prints as the camera wrote it.
  if (const float t = spec.get_float_attribute("ExposureTime", 0.0f); t > 0) return std::stod(fmt::format("{}", t));
  const std::string sensor = spec.get_string_attribute("chromatrace.sensor");
  if (!sensor.empty()) {
    const Json j = Json::parse(sensor, nullptr, false);
    if (j.is_object() && j.contains("exposure") && j["exposure"].contains("time_s") && j["exposure"]["time_s"].is_number())
      return j["exposure"]["time_s"].get<double>();
  }
  return std::nullopt;
}

// Digital numbers are whole: a frame scaled to 0–1, or processed, would give a gain in its own units and no
// quantisation to judge the dark noise by. InputError naming the first finite value that is not.
void check_whole_numbers(const std::string& name, const std::string& channel, const auto& plane, int width) {
  for (std::size_t i = 0; i < plane.size(); ++i)
    if (std::isfinite(plane[i]) && plane[i] != std::round(plane[i]))
      throw InputError(fmt::format("{}: channel {} holds {} at pixel ({}, {}), not a whole number: calibration needs the camera's "
                                   "digital numbers (a frame scaled to 0–1 or processed is not)",
                                   name, channel, plane[i], i % static_cast<std::size_t>(width), i / static_cast<std::size_t>(width)));
}

Plane plane_of(int width, int height, const std::string& file, std::size_t count, auto value) {
  Plane p{width, height, std::vector<double>(count)};
  for (std::size_t i = 0; i < count; ++i) {
    const float v = value(i);
    if (!std::isfinite(v)) throw InputError(fmt::format("{}: pixel ({}, {}) has a value that is not a number", file,
                                                        i % static_cast<std::size_t>(width), i / static_cast<std::size_t>(width)));
    p.values[i] = static_cast<double>(v);
  }
  return p;
}

Frame read_camera_raw_frame(const std::filesystem::path& file) {
  analyzer::RawOptions options;
  options.half_size = true;
  const analyzer::AnalysisImage image = analyzer::read_analysis_image(file, "auto", options);
  const analyzer::ImageEncoding& e = image.encoding;
  Frame f;
  f.file = file.string();
  std::string camera, cfa;
  for (const auto& [key, value] : analyzer::describe_camera_raw(file)) {
    if (key == "camera") camera = value;
    if (key == "cfa") cfa = value;
  }
  f.sensor = fmt::format("camera raw, {}, CFA {}", camera, cfa);
  f.photosites = true;
  f.adc_bits = e.adc_bits;
  f.white_level_dn = e.white_level;
  const double black = e.black_subtracted && e.black_level ? *e.black_level : 0.0;
  const analyzer::RgbImage& rgb = image.image;
  for (std::size_t c = 0; c < 3; ++c) {
    f.channel_names.emplace_back(std::string(1, "RGB"[c]));
    f.channels.push_back(plane_of(rgb.width, rgb.height, f.file, rgb.pixel_count(),
                                  [&](std::size_t i) { return rgb.rgb[3 * i + c] + static_cast<float>(black); }));
  }
  return f;
}

Frame read_linear_frame(const std::filesystem::path& file, const std::string& input_transfer) {
  const std::string name = file.string();
  const analyzer::CameraFrame image = analyzer::read_camera_frame(file, input_transfer);
  const analyzer::ImageEncoding& e = image.encoding;
  if (e.demosaiced == true)
    throw InputError(fmt::format("{}: its pixels were interpolated from a colour filter array, so neighbours share their noise; "
                                 "calibrate from the camera raw (or the simulator's DNG) or from frames written without a CFA",
                                 name));
  if (e.curve && !e.curve->linear())
    throw InputError(fmt::format("{}: its values are encoded with a response curve ({}, from {}); calibration needs linear digital "
                                 "numbers{}",
                                 name, e.curve->describe(), e.curve_source,
                                 input_transfer == "auto" ? " (if the camera wrote them so, say it: --input-transfer linear)" : ""));
  Frame f;
  f.file = name;
  const std::size_t n = static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height);
  for (std::size_t c = 0; c < image.planes.size(); ++c) {
    const std::vector<float>& plane = image.planes[c];
    // A float file that is not the simulator's holds digital numbers only when they are whole.
    if (!e.integer && e.metadata.empty()) check_whole_numbers(name, image.channels[c], plane, image.width);
    f.channel_names.push_back(image.channels.size() == 1 ? image.channels[c] : std::string(1, "RGB"[c]));
    f.channels.push_back(plane_of(image.width, image.height, name, n, [&](std::size_t i) { return plane[i]; }));
  }
  std::string format = file.extension().string();
  if (!format.empty()) format.erase(0, 1);
  std::transform(format.begin(), format.end(), format.begin(), [](unsigned char ch) { return std::toupper(ch); });
  f.sensor = f.channels.size() == 1 ? fmt::format("linear {}, one channel (monochrome)", format)
                                    : fmt::format("linear {}, R, G, B", format);
  f.adc_bits = e.adc_bits;
  f.white_level_dn = e.white_level;
  return f;
}

}  // namespace

Frame read_frame(const std::filesystem::path& file, const std::string& input_transfer) {
  Frame f = analyzer::is_camera_raw(file) ? read_camera_raw_frame(file) : read_linear_frame(file, input_transfer);
  const std::optional<double> exposure = recorded_exposure(file, f.date);
  if (!exposure)
    throw InputError(fmt::format("{}: no exposure time (EXIF ExposureTime, or exposure.time_s in chromatrace.sensor)", f.file));
  f.exposure_s = *exposure;
  return f;
}

Frame frame_in_memory(const std::string& name, double exposure_s, int width, int height, const std::vector<std::vector<double>>& planes) {
  if (!(exposure_s > 0 && std::isfinite(exposure_s)))
    throw InputError(fmt::format("{}: the exposure time must be a positive number of seconds, got {}", name, exposure_s));
  if (planes.size() != 1 && planes.size() != 3)
    throw InputError(fmt::format("{}: needs one channel (a monochrome camera) or R, G, B; has {}", name, planes.size()));
  const std::size_t n = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  Frame f;
  f.file = name;
  f.exposure_s = exposure_s;
  for (std::size_t c = 0; c < planes.size(); ++c) {
    const std::vector<double>& plane = planes[c];
    if (width < 1 || height < 1 || plane.size() != n)
      throw InputError(fmt::format("{}: {} values for {} x {} pixels", name, plane.size(), width, height));
    check_whole_numbers(name, std::to_string(c), plane, width);
    f.channel_names.push_back(planes.size() == 1 ? "Y" : std::string(1, "RGB"[c]));
    f.channels.push_back(plane_of(width, height, name, n, [&](std::size_t i) { return static_cast<float>(plane[i]); }));
  }
  f.sensor = planes.size() == 1 ? "array, one channel (monochrome)" : "array, R, G, B";
  return f;
}

}  // namespace ct::calibrate
