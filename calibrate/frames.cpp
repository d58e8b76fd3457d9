// SPDX-License-Identifier: Apache-2.0
#include "calibrate/frames.h"

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

// The exposure time a file records: EXIF's ExposureTime (camera raw, DNG), else the simulator's settings.
std::optional<double> recorded_exposure(const std::filesystem::path& file) {
  auto in = OIIO::ImageInput::open(file.string());
  if (!in) {
    (void)OIIO::geterror();
    return std::nullopt;
  }
  const OIIO::ImageSpec& spec = in->spec();
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

}  // namespace

Frame read_frame(const std::filesystem::path& file) {
  const std::string name = file.string();
  const bool raw = analyzer::is_camera_raw(file);
  analyzer::RawOptions options;
  options.half_size = true;
  const analyzer::AnalysisImage image = analyzer::read_analysis_image(file, "auto", options);
  const analyzer::ImageEncoding& e = image.encoding;
  if (!raw && e.demosaiced != false)
    throw InputError(fmt::format("{}: its pixels {} interpolated from a colour filter array, so neighbours share their noise; "
                                 "calibrate from the camera raw (or the simulator's DNG) or from frames written without a CFA",
                                 name, e.demosaiced ? "were" : "may have been"));
  if (e.curve && !e.curve->linear())
    throw InputError(fmt::format("{}: its values are encoded with a response curve ({}); calibration needs linear digital numbers", name,
                                 e.curve->describe()));
  const std::optional<double> exposure = recorded_exposure(file);
  if (!exposure)
    throw InputError(fmt::format("{}: no exposure time (EXIF ExposureTime, or exposure.time_s in chromatrace.sensor)", name));
  Frame f;
  f.file = name;
  f.exposure_s = *exposure;
  if (raw) {
    std::string camera, cfa;
    for (const auto& [key, value] : analyzer::describe_camera_raw(file)) {
      if (key == "camera") camera = value;
      if (key == "cfa") cfa = value;
    }
    f.sensor = fmt::format("camera raw, {}, CFA {}", camera, cfa);
  } else {
    f.sensor = fmt::format("linear {}, no CFA", file.extension() == ".exr" || file.extension() == ".EXR" ? "EXR" : "TIFF");
  }
  f.adc_bits = e.adc_bits;
  f.white_level_dn = e.white_level;
  const double black = e.black_subtracted && e.black_level ? *e.black_level : 0.0;
  const analyzer::RgbImage& rgb = image.image;
  for (int c = 0; c < 3; ++c) {
    Plane& p = f.channels[static_cast<std::size_t>(c)];
    p.width = rgb.width;
    p.height = rgb.height;
    p.values.resize(rgb.pixel_count());
    for (std::size_t i = 0; i < p.values.size(); ++i) {
      const float v = rgb.rgb[3 * i + static_cast<std::size_t>(c)];
      if (!std::isfinite(v)) throw InputError(fmt::format("{}: pixel {} has a value that is not a number", name, i));
      p.values[i] = static_cast<double>(v) + black;
    }
  }
  return f;
}

}  // namespace ct::calibrate
