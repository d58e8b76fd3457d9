// SPDX-License-Identifier: Apache-2.0
#include "analyzer/image_input.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <memory>
#include <sstream>
#include <string_view>

#include <OpenImageIO/imageio.h>
#include <OpenImageIO/strutil.h>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/exr_vocabulary.h"
#include "core/file_io.h"
#include "core/library_output.h"
#include "core/limits.h"

namespace ct::analyzer {
namespace {

struct RawImage {
  int width = 0, height = 0, channels = 0;
  std::vector<std::string> names;
  std::vector<float> values;  // [y][x][channel], integer files already scaled to their stored integers
  ImageEncoding encoding;
  std::string objects_attribute, components_attribute;
  // The camera's numbers (chromatrace.black_level …) as found: attributes, else ImageDescription's JSON.
  nlohmann::json camera = nlohmann::json::object();
  std::string camera_source;
  int alpha = -1;            // the alpha channel's index, −1 without one
  std::string colour_space;  // oiio:ColorSpace
  std::string format;        // OpenImageIO's format name ("tiff", "png", "jpeg", …)
  float display_gamma = 0;   // oiio:Gamma (0: not given)
  std::string conversion;    // what OpenImageIO did to give R, G, B from other stored values ("" for nothing)
  std::string first_of_many;  // a file of several images (an animated GIF, a multi-page TIFF): which one was read
};

constexpr const char* kCameraKeys[] = {"chromatrace.black_level", "chromatrace.white_level", "chromatrace.dark_signal",
                                       "chromatrace.read_noise",  "chromatrace.bits",        "chromatrace.noise",
                                       "chromatrace.adc",         "chromatrace.pixel_area",      "chromatrace.cfa",
                                       "chromatrace.curve_gamma", "chromatrace.curve_k",     "chromatrace.curve_srgb"};

// The camera's numbers: numeric attributes (EXR), numbers spelled as text (PNG keeps attributes as text), or
// the JSON object a TIFF or PNG holds in ImageDescription.
void read_camera_metadata(const OIIO::ImageSpec& spec, RawImage& raw) {
  for (const char* key : kCameraKeys) {
    const OIIO::ParamValue* p = spec.find_attribute(key);
    if (p == nullptr) continue;
    if (p->type().basetype == OIIO::TypeDesc::STRING) {
      const std::string text = p->get_string();
      char* end = nullptr;
      const double v = std::strtod(text.c_str(), &end);
      if (end == text.c_str() || *end != '\0' || !std::isfinite(v)) continue;
      raw.camera[key] = v;
    } else if (p->type() == OIIO::TypeDesc::DOUBLE) {
      raw.camera[key] = *static_cast<const double*>(p->data());
    } else if (p->type() == OIIO::TypeDesc::FLOAT || p->type() == OIIO::TypeDesc::INT) {
      raw.camera[key] = p->type() == OIIO::TypeDesc::INT ? double(p->get_int()) : double(p->get_float());
    }
  }
  if (!raw.camera.empty()) {
    raw.camera_source = "attributes";
    return;
  }
  const nlohmann::json description = nlohmann::json::parse(spec.get_string_attribute("ImageDescription"), nullptr, false);
  if (!description.is_object()) return;
  for (const char* key : kCameraKeys)
    if (description.contains(key) && description[key].is_number()) raw.camera[key] = description[key];
  if (!raw.camera.empty()) raw.camera_source = "ImageDescription";
}

// Whether a PNG file stores indices into a palette (IHDR colour type 3; OpenImageIO reports no attribute for it).
bool png_palette(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::array<unsigned char, 26> head{};
  in.read(reinterpret_cast<char*>(head.data()), head.size());
  return in && std::string_view(reinterpret_cast<const char*>(head.data()) + 12, 4) == "IHDR" && head[25] == 3;
}

// What OpenImageIO did to give R, G, B from a file that stores something else: CMYK inks, or indices into a palette.
std::string conversion_note(const OIIO::ImageSpec& spec, const std::string& format, const std::filesystem::path& file) {
  const std::string tiff_space = spec.get_string_attribute("tiff:ColorSpace"), jpeg_space = spec.get_string_attribute("jpeg:ColorSpace");
  for (const auto& [attribute, space] : {std::pair{"tiff:ColorSpace", tiff_space}, std::pair{"jpeg:ColorSpace", jpeg_space}})
    if (OIIO::Strutil::iequals(space, "CMYK") || OIIO::Strutil::iequals(space, "YCCK"))
      return fmt::format("the file stores CMYK ink values ({} {}): OpenImageIO converted them to R, G, B without a colour "
                         "profile, so the values analysed are not those of a calibrated conversion", attribute, space);
  const bool palette = format == "gif" || (format == "tiff" && spec.get_int_attribute("tiff:PhotometricInterpretation", -1) == 3) ||
                       (format == "png" && png_palette(file));
  if (palette)
    return fmt::format("the file stores indices into a palette ({}): OpenImageIO expanded them to the palette's R, G, B, so "
                       "the image holds at most 256 distinct colours and its clusters are sets of a few points",
                       format == "png" ? "PNG colour type 3" : format == "gif" ? "GIF" : "TIFF photometric palette");
  return "";
}

RawImage read_raw(const std::filesystem::path& file) {
  const std::string name = file.string();
  const std::uintmax_t bytes = check_input_file(file, InputAccess::Seekable, std::numeric_limits<std::uintmax_t>::max());
  std::unique_ptr<OIIO::ImageInput> in;
  {
    const LibraryStderrSilenced quiet;  // libpng prints its errors itself, which OpenImageIO reports again below
    in = OIIO::ImageInput::open(name);
  }
  if (!in) {
    std::string why = OIIO::geterror();
    std::replace(why.begin(), why.end(), '\n', ' ');
    throw InputError(fmt::format("{}: cannot read image: {}", name, why.empty() ? "unknown format" : why));
  }
  const OIIO::ImageSpec& spec = in->spec();
  RawImage raw;
  raw.width = spec.width;
  raw.height = spec.height;
  raw.channels = spec.nchannels;
  raw.names = spec.channelnames;
  // Some readers (GIF) name no channels: OpenImageIO's default names then, so that every index has a name
  // (an alpha channel's name was once read past the end: analyze any.gif crashed).
  if (raw.names.size() != static_cast<std::size_t>(raw.channels)) {
    OIIO::ImageSpec named(spec.width, spec.height, spec.nchannels, spec.format);
    named.default_channel_names();
    raw.names = named.channelnames;
  }
  const OIIO::TypeDesc type = spec.format;
  if (type.basetype == OIIO::TypeDesc::UINT8 || type.basetype == OIIO::TypeDesc::UINT16 ||
      type.basetype == OIIO::TypeDesc::UINT32) {
    raw.encoding.integer = true;
    raw.encoding.bits = static_cast<int>(type.size() * 8);
    raw.encoding.full_scale = std::ldexp(1.0, raw.encoding.bits) - 1.0;
  }
  raw.objects_attribute = spec.get_string_attribute(exr::kObjectsAttribute);
  raw.components_attribute = spec.get_string_attribute(exr::kComponentsAttribute);
  read_camera_metadata(spec, raw);
  raw.alpha = spec.alpha_channel < raw.channels ? spec.alpha_channel : -1;
  raw.colour_space = spec.get_string_attribute("oiio:ColorSpace");
  raw.format = in->format_name();
  raw.display_gamma = spec.get_float_attribute("oiio:Gamma", 0.0f);
  raw.conversion = conversion_note(spec, in->format_name(), file);
  // An animated GIF's frames, a multi-page TIFF's pages, a multi-part EXR's parts: the first is read. Counted up to
  // a bound, so that a file of thousands of frames is not decoded just to count them.
  constexpr int kCountedImages = 1000;
  int images = 1;
  {
    const LibraryStderrSilenced quiet;
    while (images < kCountedImages && in->seek_subimage(images, 0)) ++images;
    if (images > 1 && !in->seek_subimage(0, 0)) throw InputError(fmt::format("{}: cannot return to its first image", name));
  }
  if (images > 1)
    raw.first_of_many = fmt::format("the file holds {}{} images ({}); the first, {} × {}, was analysed", images >= kCountedImages ? "at least " : "",
                                    images, in->format_name(), spec.width, spec.height);
  if (raw.width < 1 || raw.height < 1) throw InputError(fmt::format("{}: image has no pixels", name));
  check_image_size(name, raw.width, raw.height, raw.channels, bytes, static_cast<int>(type.size()));
  raw.values.resize(static_cast<std::size_t>(raw.width) * static_cast<std::size_t>(raw.height) *
                    static_cast<std::size_t>(raw.channels));
  // OpenImageIO hands integer samples over as fractions of full scale; scaling back keeps digital numbers.
  bool read = false;
  {
    const LibraryStderrSilenced quiet;
    read = in->read_image(0, 0, 0, raw.channels, OIIO::TypeDesc::FLOAT, raw.values.data());
  }
  if (!read) {
    std::string why = in->geterror();
    std::replace(why.begin(), why.end(), '\n', ' ');
    throw InputError(fmt::format("{}: cannot read pixels: {}", name, why));
  }
  if (raw.encoding.integer) {
    const auto scale = static_cast<float>(raw.encoding.full_scale);
    for (float& v : raw.values) v = std::round(v * scale);
  }
  return raw;
}

int channel_index(const RawImage& raw, const std::string& name) {
  const auto it = std::find(raw.names.begin(), raw.names.end(), name);
  return it == raw.names.end() ? -1 : static_cast<int>(it - raw.names.begin());
}

// The layer <prefix>.R/G/B ("" for R, G, B), if all three channels are present.
std::optional<RgbImage> extract_rgb(const RawImage& raw, const std::string& prefix) {
  const std::string p = prefix.empty() ? "" : prefix + ".";
  const int c[3] = {channel_index(raw, p + "R"), channel_index(raw, p + "G"), channel_index(raw, p + "B")};
  if (c[0] < 0 || c[1] < 0 || c[2] < 0) return std::nullopt;
  RgbImage out{raw.width, raw.height, {}};
  const std::size_t n = out.pixel_count();
  out.rgb.resize(n * 3);
  const auto stride = static_cast<std::size_t>(raw.channels);
  for (std::size_t i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) out.rgb[i * 3 + static_cast<std::size_t>(k)] = raw.values[i * stride + static_cast<std::size_t>(c[k])];
  return out;
}

std::vector<std::int32_t> whole_numbers(const std::string& file, const std::string& what, const RawImage& raw, int channel) {
  std::vector<std::int32_t> out(static_cast<std::size_t>(raw.width) * static_cast<std::size_t>(raw.height));
  const auto stride = static_cast<std::size_t>(raw.channels);
  for (std::size_t i = 0; i < out.size(); ++i) {
    const float v = raw.values[i * stride + static_cast<std::size_t>(channel)];
    if (!exr::is_object_id(v))
      throw InputError(fmt::format("{}: {}: pixel ({}, {}) holds {}, not a whole number in [0, {}]", file, what,
                                   i % static_cast<std::size_t>(raw.width), i / static_cast<std::size_t>(raw.width), v,
                                   exr::kMaxObjectId));
    out[i] = static_cast<std::int32_t>(v);
  }
  return out;
}

std::map<std::int32_t, std::string> parse_object_names(const std::string& file, const std::string& text) {
  if (text.empty()) return {};
  return exr::parse_object_names(text, fmt::format("{}: attribute {}", file, exr::kObjectsAttribute));
}

std::vector<std::string> component_names(const RawImage& raw) {
  if (!raw.components_attribute.empty()) return exr::parse_component_list(raw.components_attribute);
  std::vector<std::string> names;
  // Without the attribute, any <prefix>.R/G/B triplet other than linear is a component.
  for (const std::string& c : raw.names) {
    if (c.size() < 3 || c.compare(c.size() - 2, 2, ".R") != 0) continue;
    const std::string prefix = c.substr(0, c.size() - 2);
    if (prefix != "linear" && prefix != "display" && extract_rgb(raw, prefix)) names.push_back(prefix);
  }
  return names;
}

std::optional<double> camera_number(const RawImage& raw, const char* key) {
  if (!raw.camera.contains(key)) return std::nullopt;
  const double v = raw.camera[key].get<double>();
  return std::isfinite(v) ? std::optional(v) : std::nullopt;
}

// What the camera did, as the file's chromatrace.* numbers say (nothing without them).
void read_camera_encoding(const RawImage& raw, ImageEncoding& e) {
  if (raw.camera_source.empty()) return;
  e.metadata = raw.camera_source;
  e.black_level = camera_number(raw, "chromatrace.black_level");
  e.white_level = camera_number(raw, "chromatrace.white_level");
  e.dark_signal = camera_number(raw, "chromatrace.dark_signal");
  e.read_noise = camera_number(raw, "chromatrace.read_noise");
  if (const auto bits = camera_number(raw, "chromatrace.bits")) e.adc_bits = static_cast<int>(*bits);
  if (const auto noise = camera_number(raw, "chromatrace.noise")) e.noise = *noise != 0;
  if (const auto adc = camera_number(raw, "chromatrace.adc")) e.adc = *adc != 0;
  if (const auto area = camera_number(raw, "chromatrace.pixel_area")) e.pixel_area = *area != 0;
  if (const auto cfa = camera_number(raw, "chromatrace.cfa")) e.demosaiced = *cfa != 0;
}

// Records what the camera did and takes the black level off R, G, B.
void apply_camera_metadata(const RawImage& raw, AnalysisImage& out) {
  ImageEncoding& e = out.encoding;
  read_camera_encoding(raw, e);
  if (e.black_level && *e.black_level != 0) {
    const auto black = static_cast<float>(*e.black_level);
    for (float& v : out.image.rgb) v -= black;
  }
  e.black_subtracted = e.black_level.has_value();
}

// The curve the sensor simulator named (chromatrace.curve_*), if it did.
std::optional<ToneCurve> simulator_curve(const RawImage& raw, const std::string& file) {
  const auto gamma = camera_number(raw, "chromatrace.curve_gamma");
  const auto srgb = camera_number(raw, "chromatrace.curve_srgb");
  if (!gamma && !srgb) return std::nullopt;
  ToneCurve curve;
  curve.srgb = srgb.value_or(0) != 0;
  if (!curve.srgb) {
    curve.gamma = gamma.value_or(1.0);
    curve.k = camera_number(raw, "chromatrace.curve_k").value_or(1.0);
    if (!(curve.gamma > 0) || !(curve.k > 0))
      throw InputError(fmt::format("{}: chromatrace.curve_gamma and chromatrace.curve_k must be > 0 (are {:g}, {:g})", file,
                                   curve.gamma, curve.k));
  }
  return curve;
}

// --input-transfer auto: what the file says of its encoding, else what its type implies. An integer file that says
// nothing is a picture (sRGB), unless it holds a measurement camera's digital numbers (`integer_is_linear`): then
// only a JPEG (a tone-mapped picture whatever it says) is sRGB, and an sRGB colour space (which EXIF's ColorSpace tag
// and PNG give by default, whatever the values are) is not taken as a curve.
void decide_curve(const RawImage& raw, const std::string& file, ImageEncoding& e, bool integer_is_linear = false) {
  if (const auto curve = simulator_curve(raw, file)) {
    e.curve = curve;
    e.curve_source = fmt::format("the file's chromatrace.curve_* ({})", raw.camera_source);
    return;
  }
  if (!raw.camera_source.empty()) {  // the simulator's camera numbers without a curve: linear signal
    e.curve = ToneCurve{};
    e.curve_source = "the file's camera metadata (chromatrace.*) names no curve: linear";
    return;
  }
  std::string space = raw.colour_space;
  std::transform(space.begin(), space.end(), space.begin(), [](unsigned char c) { return std::tolower(c); });
  if (integer_is_linear && e.integer && raw.format == "jpeg") {
    e.curve = ToneCurve{1, 1, true};
    e.curve_source = "a JPEG: a camera's tone-mapped picture";
  } else if (space == "srgb" && !(integer_is_linear && e.integer)) {
    e.curve = ToneCurve{1, 1, true};
    e.curve_source = "the file's colour space (oiio:ColorSpace sRGB)";
  } else if (space == "linear" || space == "lin_srgb" || space == "scene_linear" || space == "acescg") {
    e.curve = ToneCurve{};
    e.curve_source = fmt::format("the file's colour space (oiio:ColorSpace {})", raw.colour_space);
  } else if (space == "gammacorrected" && raw.display_gamma > 0) {
    e.curve = ToneCurve{1.0 / raw.display_gamma, 1, false};
    e.curve_source = fmt::format("the file's gamma (oiio:Gamma {:g})", raw.display_gamma);
  } else {
    // An array in memory (read_analysis_pixels) has no colour space to name.
    const std::string what = raw.format == "array" ? "array" : "file without a colour space";
    const std::string bits = fmt::format("{} {}-bit {}", e.bits == 8 ? "an" : "a", e.bits, what);
    if (!e.integer) {
      e.curve = ToneCurve{};
      e.curve_source = fmt::format("a float {}: linear", what);
    } else if (integer_is_linear) {
      e.curve = ToneCurve{};
      e.curve_source = bits + ": a measurement camera's digital numbers";
    } else {
      e.curve = ToneCurve{1, 1, true};
      e.curve_source = bits + ": sRGB, as cameras and phones store pictures";
    }
  }
}

// Sets aside (as NaN) the pixels no region should hold: fully transparent ones, and negative values in a file
// that is not a camera's (whose black-subtracted noise may be negative). Nothing valid left is an InputError.
void set_aside_invalid_pixels(const RawImage& raw, AnalysisImage& out) {
  std::vector<float>& rgb = out.image.rgb;
  const bool camera = !out.encoding.metadata.empty();
  std::size_t valid = 0, non_finite = 0;
  for (std::size_t p = 0; p < out.image.pixel_count(); ++p) {
    float* v = &rgb[p * 3];
    const bool transparent = raw.alpha >= 0 && raw.values[p * static_cast<std::size_t>(raw.channels) + static_cast<std::size_t>(raw.alpha)] <= 0.0f;
    const bool finite = std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]);
    const bool negative = !camera && finite && (v[0] < 0 || v[1] < 0 || v[2] < 0);
    if (transparent) ++out.transparent_pixels;
    else if (negative) ++out.negative_pixels;
    else if (!finite) ++non_finite;
    else ++valid;
    if (transparent || negative) v[0] = v[1] = v[2] = std::numeric_limits<float>::quiet_NaN();
  }
  if (raw.alpha >= 0)
    out.notes.push_back(fmt::format("alpha channel {}: {} fully transparent pixel{} left out of every region", raw.names[static_cast<std::size_t>(raw.alpha)],
                                    out.transparent_pixels, out.transparent_pixels == 1 ? "" : "s"));
  if (out.negative_pixels > 0)
    out.notes.push_back(fmt::format("{} pixel{} with a negative value left out of every region (no light is negative)",
                                    out.negative_pixels, out.negative_pixels == 1 ? "" : "s"));
  if (valid == 0)
    throw InputError(fmt::format("{}: no valid pixel: {} transparent, {} negative, {} NaN or infinite", out.file,
                                 out.transparent_pixels, out.negative_pixels, non_finite));
}

// What read_analysis_image and read_analysis_pixels share once the stored values are read: R, G, B and the extra
// layers, the camera's numbers, what was set aside, and the curve.
AnalysisImage analysis_image_of(RawImage raw, const std::string& name, const std::string& input_transfer,
                                const std::optional<ToneCurve>& declared) {
  AnalysisImage out;
  out.file = name;
  out.encoding = raw.encoding;
  if (raw.channels == 3 && raw.alpha < 0 && channel_index(raw, "R") == 0 && channel_index(raw, "G") == 1 && channel_index(raw, "B") == 2) {
    // R, G, B alone and in order: the values are the image, taken as they are (no copy). Nothing below reads them.
    out.image = RgbImage{raw.width, raw.height, std::move(raw.values)};
    raw.values.clear();
  } else if (auto rgb = extract_rgb(raw, "")) {
    out.image = std::move(*rgb);
  } else if (raw.channels >= 3 && channel_index(raw, "R") < 0) {
    // Files whose channels are not named R, G, B (some TIFFs, unnamed EXR layers): the first three.
    out.image = RgbImage{raw.width, raw.height, std::vector<float>(raw.width * static_cast<std::size_t>(raw.height) * 3)};
    const auto stride = static_cast<std::size_t>(raw.channels);
    for (std::size_t i = 0; i < out.image.pixel_count(); ++i)
      for (std::size_t k = 0; k < 3; ++k) out.image.rgb[i * 3 + k] = raw.values[i * stride + k];
  } else {
    throw InputError(fmt::format("{}: needs channels R, G, B; has {}", name,
                                 raw.names.empty() ? std::string("none") : fmt::format("{}", fmt::join(raw.names, ", "))));
  }
  out.linear = extract_rgb(raw, "linear");
  out.display = extract_rgb(raw, "display");
  apply_camera_metadata(raw, out);
  if (!raw.conversion.empty()) out.notes.push_back(raw.conversion);
  if (!raw.first_of_many.empty()) out.notes.push_back(raw.first_of_many);
  set_aside_invalid_pixels(raw, out);
  if (declared) {
    out.encoding.curve = declared;
    out.encoding.curve_source = fmt::format("--input-transfer {}", input_transfer);
  } else {
    decide_curve(raw, out.file, out.encoding);
  }
  // A renderer's spectral EXR names its components too, but holds them as spectra, not as camera RGB:
  // only RGB layers explain a camera image.
  for (const std::string& c : component_names(raw))
    if (auto layer = extract_rgb(raw, c)) out.components.push_back({c, std::move(*layer)});
  if (const int id = channel_index(raw, exr::kObjectIdChannel); id >= 0)
    out.object_ids = whole_numbers(name, exr::kObjectIdChannel, raw, id);
  out.object_names = parse_object_names(name, raw.objects_attribute);
  return out;
}

}  // namespace

std::optional<ToneCurve> parse_input_transfer(const std::string& text) {
  if (text == "auto") return std::nullopt;
  if (text == "linear") return ToneCurve{};
  if (text == "srgb" || text == "sRGB") return ToneCurve{1, 1, true};
  if (text.starts_with("gamma=")) {
    const std::string number = text.substr(6);
    char* end = nullptr;
    const double g = std::strtod(number.c_str(), &end);
    if (!number.empty() && *end == '\0' && std::isfinite(g) && g > 0) return ToneCurve{1.0 / g, 1, false};
  }
  throw InputError(fmt::format("--input-transfer: \"{}\" is not auto, linear, srgb or gamma=G with G > 0", text));
}

AnalysisImage read_analysis_image(const std::filesystem::path& file, const std::string& input_transfer,
                                  const RawOptions& raw_options) {
  const std::optional<ToneCurve> declared = parse_input_transfer(input_transfer);
  if (is_camera_raw(file)) {
    AnalysisImage capture = read_camera_raw(file, raw_options);
    if (declared) {
      capture.encoding.curve = declared;
      capture.encoding.curve_source = fmt::format("--input-transfer {}", input_transfer);
    }
    return capture;
  }
  return analysis_image_of(read_raw(file), file.string(), input_transfer, declared);
}

AnalysisImage read_analysis_pixels(const std::string& name, int width, int height, std::vector<float> values, int integer_bits,
                                   const std::string& input_transfer, bool alpha) {
  const std::optional<ToneCurve> declared = parse_input_transfer(input_transfer);
  if (width < 1 || height < 1) throw InputError(fmt::format("{}: image has no pixels", name));
  const int channels = alpha ? 4 : 3;
  if (values.size() != static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * static_cast<std::size_t>(channels))
    throw InputError(fmt::format("{}: {} values for {} x {} pixels of R, G, B{}", name, values.size(), width, height, alpha ? ", A" : ""));
  if (integer_bits != 0 && integer_bits != 8 && integer_bits != 16 && integer_bits != 32)
    throw InputError(fmt::format("{}: integer samples of {} bits; 8, 16 or 32 (or float)", name, integer_bits));
  RawImage raw;
  raw.width = width;
  raw.height = height;
  raw.channels = channels;
  raw.names = {"R", "G", "B"};
  if (alpha) {
    raw.names.push_back("A");
    raw.alpha = 3;
  }
  raw.format = "array";
  raw.values = std::move(values);
  if (integer_bits > 0) {
    raw.encoding.integer = true;
    raw.encoding.bits = integer_bits;
    raw.encoding.full_scale = std::ldexp(1.0, integer_bits) - 1.0;
  }
  return analysis_image_of(std::move(raw), name, input_transfer, declared);
}

CameraFrame read_camera_frame(const std::filesystem::path& file, const std::string& input_transfer) {
  const std::optional<ToneCurve> declared = parse_input_transfer(input_transfer);
  const std::string name = file.string();
  const RawImage raw = read_raw(file);
  std::vector<int> channels;
  if (const int r = channel_index(raw, "R"), g = channel_index(raw, "G"), b = channel_index(raw, "B"); r >= 0 && g >= 0 && b >= 0) {
    channels = {r, g, b};
  } else {
    for (int c = 0; c < raw.channels; ++c)
      if (c != raw.alpha) channels.push_back(c);
    if (channels.size() != 1)
      throw InputError(fmt::format("{}: needs one channel (a monochrome camera) or R, G, B; has {}", name,
                                   raw.names.empty() ? std::string("none") : fmt::format("{}", fmt::join(raw.names, ", "))));
  }
  CameraFrame out;
  out.width = raw.width;
  out.height = raw.height;
  out.encoding = raw.encoding;
  read_camera_encoding(raw, out.encoding);
  if (declared) {
    out.encoding.curve = declared;
    out.encoding.curve_source = fmt::format("--input-transfer {}", input_transfer);
  } else {
    decide_curve(raw, name, out.encoding, true);
  }
  const auto stride = static_cast<std::size_t>(raw.channels);
  const std::size_t n = static_cast<std::size_t>(raw.width) * static_cast<std::size_t>(raw.height);
  for (const int c : channels) {
    out.channels.push_back(raw.names[static_cast<std::size_t>(c)]);
    std::vector<float>& plane = out.planes.emplace_back(n);
    for (std::size_t i = 0; i < n; ++i) plane[i] = raw.values[i * stride + static_cast<std::size_t>(c)];
  }
  return out;
}

LabelImage read_label_image(const std::filesystem::path& file) {
  const RawImage raw = read_raw(file);
  return LabelImage{raw.width, raw.height, whole_numbers(file.string(), "labels", raw, 0)};
}

}  // namespace ct::analyzer
