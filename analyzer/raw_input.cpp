// SPDX-License-Identifier: Apache-2.0
#include "analyzer/raw_input.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <fstream>
#include <limits>
#include <memory>

#include <fmt/format.h>
#include <libraw/libraw.h>

#include "core/error.h"
#include "core/file_io.h"
#include "core/limits.h"

namespace ct::analyzer {
namespace {

// LibRaw's demosaicing methods (params.user_qual) by name.
constexpr std::array<std::pair<const char*, int>, 7> kDemosaic = {
    {{"linear", 0}, {"vng", 1}, {"ppg", 2}, {"ahd", 3}, {"dcb", 4}, {"dht", 11}, {"aahd", 12}}};

constexpr std::array<const char*, 24> kRawExtensions = {".dng", ".cr2", ".cr3", ".crw", ".nef", ".nrw", ".arw", ".srf",
                                                        ".sr2", ".raf", ".orf", ".rw2", ".raw", ".pef", ".srw", ".x3f",
                                                        ".3fr", ".fff", ".iiq", ".mos", ".erf", ".kdc", ".dcr", ".mrw"};

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

// LibRaw's data errors (a file that ends early or is corrupt), recorded instead of printed.
struct DataErrors {
  int count = 0;
  int offset = 0;  // of the first; −1 at the end of the file
};

void record_data_error(void* data, const char* /*file*/, const int offset) {
  auto* errors = static_cast<DataErrors*>(data);
  if (errors->count++ == 0) errors->offset = offset;
}

// An opened and unpacked raw file.
struct OpenRaw {
  std::unique_ptr<LibRaw> raw = std::make_unique<LibRaw>();
  DataErrors errors;
};

void check(const std::string& file, int code, const char* step) {
  if (code != LIBRAW_SUCCESS)
    throw InputError(fmt::format("{}: LibRaw cannot {} it as a camera raw: {}", file, step, libraw_strerror(code)));
}

// A TIFF-based raw (DNG, NEF, CR2, ARW, …) cut short: its header points at a first directory beyond the end of
// the file (writers put the directories after the data). InputError saying so; nothing for other files.
void check_tiff_not_truncated(const std::string& file) {
  std::ifstream in(file, std::ios::binary);
  unsigned char h[8] = {};
  if (!in.read(reinterpret_cast<char*>(h), 8)) return;
  const bool little = h[0] == 'I' && h[1] == 'I' && h[2] == 42 && h[3] == 0;
  const bool big = h[0] == 'M' && h[1] == 'M' && h[2] == 0 && h[3] == 42;
  if (!little && !big) return;
  const std::uint64_t offset = little ? (std::uint64_t{h[4]} | std::uint64_t{h[5]} << 8 | std::uint64_t{h[6]} << 16 |
                                         std::uint64_t{h[7]} << 24)
                                      : (std::uint64_t{h[7]} | std::uint64_t{h[6]} << 8 | std::uint64_t{h[5]} << 16 |
                                         std::uint64_t{h[4]} << 24);
  const std::uint64_t size = std::filesystem::file_size(file);
  if (offset + 2 > size)
    throw InputError(fmt::format("{}: the file is truncated: its TIFF header points at a first directory at byte {}, "
                                 "beyond its end ({} bytes)",
                                 file, offset, size));
}

void open_raw(const std::string& file, OpenRaw& r) {
  const std::uintmax_t bytes = check_input_file(file, InputAccess::Seekable, std::numeric_limits<std::uintmax_t>::max());
  r.raw->set_dataerror_handler(record_data_error, &r.errors);
  if (const int code = r.raw->open_file(file.c_str()); code != LIBRAW_SUCCESS) {
    check_tiff_not_truncated(file);
    check(file, code, "open");
  }
  const libraw_image_sizes_t& s = r.raw->imgdata.sizes;
  check_image_size(file, s.raw_width, s.raw_height, 1, bytes, 1);  // the mosaic as stored: one sample a pixel
  check_image_size(file, s.width, s.height, 4);                       // as LibRaw unpacks it: four per pixel
  check(file, r.raw->unpack(), "decode");
  if (r.errors.count > 0 || r.raw->error_count() > 0)
    throw InputError(fmt::format("{}: the raw data {} (LibRaw)", file,
                                 r.errors.offset < 0 ? std::string("ends early: the file is truncated")
                                                     : fmt::format("is corrupt at byte {}", r.errors.offset)));
}

// The filters of the top-left 2×2 tile, as "RGGB"; "" for a file without a 2×2 Bayer mosaic.
std::string bayer_pattern(LibRaw& raw) {
  const unsigned filters = raw.imgdata.idata.filters;
  if (filters < 1000 || raw.imgdata.idata.colors != 3) return "";
  std::string pattern;
  for (int row = 0; row < 2; ++row)
    for (int col = 0; col < 2; ++col) pattern += "RGBG"[raw.COLOR(row, col) & 3];
  return pattern;
}

// The black level of a visible pixel: LibRaw's common black, its per-colour black and its repeating pattern.
double black_at(LibRaw& raw, int row, int col) {
  const libraw_colordata_t& c = raw.imgdata.color;
  double black = c.black + c.cblack[raw.COLOR(row, col) & 3];
  if (c.cblack[4] > 0 && c.cblack[5] > 0)
    black += c.cblack[6 + (unsigned(row) % c.cblack[4]) * c.cblack[5] + unsigned(col) % c.cblack[5]];
  return black;
}

double mean_black(LibRaw& raw) {
  double sum = 0;
  for (int row = 0; row < 2; ++row)
    for (int col = 0; col < 2; ++col) sum += black_at(raw, row, col);
  return sum / 4;
}

std::string camera_name(LibRaw& raw) {
  const libraw_iparams_t& id = raw.imgdata.idata;
  return fmt::format("{} {}", id.make, id.model);
}

// Half size without demosaicing: each 2×2 tile's red, first green (row order) and blue, less their black levels.
RgbImage half_size(LibRaw& raw) {
  const libraw_image_sizes_t& s = raw.imgdata.sizes;
  const std::uint16_t* data = raw.imgdata.rawdata.raw_image;
  RgbImage out{s.width / 2, s.height / 2, {}};
  out.rgb.resize(out.pixel_count() * 3);
  for (int y = 0; y < out.height; ++y)
    for (int x = 0; x < out.width; ++x) {
      float* v = &out.rgb[(static_cast<std::size_t>(y) * static_cast<std::size_t>(out.width) + static_cast<std::size_t>(x)) * 3];
      bool green = false;
      for (int dy = 0; dy < 2; ++dy)
        for (int dx = 0; dx < 2; ++dx) {
          const int row = 2 * y + dy, col = 2 * x + dx;
          int channel = raw.COLOR(row, col) & 3;
          if (channel == 3) channel = 1;  // LibRaw's second green
          if (channel == 1 && green) continue;
          green = green || channel == 1;
          const std::size_t at = static_cast<std::size_t>(row + s.top_margin) * s.raw_pitch / 2 +
                                 static_cast<std::size_t>(col + s.left_margin);
          v[channel] = static_cast<float>(double(data[at]) - black_at(raw, row, col));
        }
    }
  return out;
}

// LibRaw's processing without white balance, colour matrix or curve: it subtracts black and scales each value
// by 65535 / (white − black), which is undone here, so that the values are digital numbers above black.
RgbImage demosaiced(LibRaw& raw, int quality, const std::string& file) {
  libraw_output_params_t& p = raw.imgdata.params;
  p.user_qual = quality;
  p.output_color = 0;  // camera RGB
  p.gamm[0] = p.gamm[1] = 1.0;
  p.no_auto_bright = 1;
  p.use_camera_wb = 0;
  p.use_auto_wb = 0;
  p.use_camera_matrix = 0;
  for (float& m : p.user_mul) m = 1.0f;
  p.highlight = 0;  // clip
  p.adjust_maximum_thr = 0.0f;
  p.output_bps = 16;
  p.user_flip = 0;  // the sensor's own orientation
  check(file, raw.dcraw_process(), "process");
  int code = LIBRAW_SUCCESS;
  std::unique_ptr<libraw_processed_image_t, void (*)(libraw_processed_image_t*)> image(
      raw.dcraw_make_mem_image(&code), LibRaw::dcraw_clear_mem);
  if (!image) check(file, code == LIBRAW_SUCCESS ? LIBRAW_UNSPECIFIED_ERROR : code, "process");
  // What is read below: three 16-bit values a pixel. A monochrome or 8-bit result (found by fuzzing: a DNG that
  // LibRaw processes to one colour was read three times past its end) is refused.
  const std::size_t values = static_cast<std::size_t>(image->width) * image->height * 3;
  if (image->type != LIBRAW_IMAGE_BITMAP || image->colors != 3 || image->bits != 16 ||
      image->data_size < values * sizeof(std::uint16_t))
    throw InputError(fmt::format("{}: LibRaw decodes it to {} colour{} of {} bits, not the 3 colours of 16 bits "
                                 "analysed as camera RGB",
                                 file, image->colors, image->colors == 1 ? "" : "s", image->bits));
  // After processing, LibRaw's maximum is the white level less the black it subtracted.
  const double range = raw.imgdata.color.maximum;
  RgbImage out{image->width, image->height, {}};
  out.rgb.resize(out.pixel_count() * 3);
  const auto* codes = reinterpret_cast<const std::uint16_t*>(image->data);
  for (std::size_t i = 0; i < out.rgb.size(); ++i) out.rgb[i] = static_cast<float>(codes[i] * range / 65535.0);
  return out;
}

}  // namespace

bool is_camera_raw(const std::filesystem::path& file) {
  const std::string ext = lower(file.extension().string());
  return std::find(kRawExtensions.begin(), kRawExtensions.end(), ext) != kRawExtensions.end();
}

const std::vector<std::string>& raw_demosaic_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> n;
    for (const auto& [name, quality] : kDemosaic) n.emplace_back(name);
    return n;
  }();
  return names;
}

AnalysisImage read_camera_raw(const std::filesystem::path& path, const RawOptions& options) {
  const std::string file = path.string();
  const std::string method = lower(options.demosaic);
  const auto known = std::find_if(kDemosaic.begin(), kDemosaic.end(), [&](auto& d) { return method == d.first; });
  if (!options.half_size && known == kDemosaic.end())
    throw InputError(fmt::format("--raw-demosaic: unknown method \"{}\" (methods: {})", options.demosaic,
                                 fmt::join(raw_demosaic_names(), ", ")));
  OpenRaw r;
  open_raw(file, r);
  LibRaw& raw = *r.raw;
  const std::string pattern = bayer_pattern(raw);
  if (options.half_size && pattern.empty())
    throw InputError(fmt::format("{}: --raw-half-size needs a 2 x 2 Bayer mosaic, and LibRaw finds none in this file", file));
  // The levels as the file gives them (before LibRaw's processing changes its numbers).
  const double black = mean_black(raw);
  const double white = raw.imgdata.color.maximum;

  AnalysisImage out;
  out.file = file;
  out.image = options.half_size ? half_size(raw) : demosaiced(raw, known->second, file);
  ImageEncoding& e = out.encoding;
  e.metadata = "camera raw (LibRaw)";
  e.black_level = black;
  e.black_subtracted = true;
  e.white_level = white;
  e.demosaiced = !options.half_size;
  e.curve = ToneCurve{};
  e.curve_source = "a camera raw: linear camera RGB (no white balance, colour matrix or curve)";
  out.notes.push_back(fmt::format("camera raw, {}: {} Bayer mosaic, black level {:g} DN and white level {:g} DN from the file",
                                  camera_name(raw), pattern.empty() ? std::string("no") : pattern, black, white));
  // The as-shot white balance: the multipliers make a white object grey, so the light they assume is their inverse.
  const float* mul = raw.imgdata.color.cam_mul;
  if (mul[0] > 0 && mul[1] > 0 && mul[2] > 0) {
    out.camera_white = Vec3(1.0 / mul[0], 1.0 / mul[1], 1.0 / mul[2]).normalized();
    out.notes.push_back(fmt::format("the camera's as-shot white balance multiplies R, G, B by {:.4g}, {:.4g}, {:.4g}: it takes the "
                                    "light to be ({:.3f}, {:.3f}, {:.3f}) in camera RGB",
                                    mul[0], mul[1], mul[2], (*out.camera_white)[0], (*out.camera_white)[1], (*out.camera_white)[2]));
  }
  if (options.half_size)
    out.notes.push_back(
        "not demosaiced (--raw-half-size): each 2 x 2 tile gives its red, first green and blue as captured, less black");
  else
    out.notes.push_back(fmt::format("demosaiced by LibRaw's {} method; values below black read as black", known->first));
  return out;
}

CameraMosaic read_camera_mosaic(const std::filesystem::path& path) {
  const std::string file = path.string();
  OpenRaw r;
  open_raw(file, r);
  LibRaw& raw = *r.raw;
  CameraMosaic out;
  out.pattern = bayer_pattern(raw);
  const std::uint16_t* data = raw.imgdata.rawdata.raw_image;
  if (out.pattern.empty() || data == nullptr)
    throw InputError(fmt::format("{}: LibRaw finds no 2 x 2 Bayer mosaic in it", file));
  const libraw_image_sizes_t& s = raw.imgdata.sizes;
  out.width = s.width;
  out.height = s.height;
  out.values.resize(static_cast<std::size_t>(s.width) * static_cast<std::size_t>(s.height));
  for (int y = 0; y < s.height; ++y)
    for (int x = 0; x < s.width; ++x)
      out.values[static_cast<std::size_t>(y) * static_cast<std::size_t>(s.width) + static_cast<std::size_t>(x)] =
          data[static_cast<std::size_t>(y + s.top_margin) * s.raw_pitch / 2 + static_cast<std::size_t>(x + s.left_margin)];
  out.black_level = mean_black(raw);
  out.white_level = raw.imgdata.color.maximum;
  return out;
}

std::vector<std::pair<std::string, std::string>> describe_camera_raw(const std::filesystem::path& path) {
  const std::string file = path.string();
  OpenRaw r;
  open_raw(file, r);
  LibRaw& raw = *r.raw;
  const libraw_iparams_t& id = raw.imgdata.idata;
  const libraw_imgother_t& other = raw.imgdata.other;
  const std::string pattern = bayer_pattern(raw);
  std::vector<std::pair<std::string, std::string>> items = {
      {"format", id.dng_version != 0 ? fmt::format("DNG {}.{}.{}.{}", id.dng_version >> 24, (id.dng_version >> 16) & 255,
                                                   (id.dng_version >> 8) & 255, id.dng_version & 255)
                                     : std::string("camera raw")},
      {"camera", camera_name(raw)},
      {"size", fmt::format("{} x {}", raw.imgdata.sizes.width, raw.imgdata.sizes.height)},
      {"cfa", pattern.empty() ? std::string("none") : pattern},
      {"black_level", fmt::format("{:g}", mean_black(raw))},
      {"white_level", fmt::format("{:g}", double(raw.imgdata.color.maximum))},
  };
  if (other.shutter > 0) items.emplace_back("exposure_s", fmt::format("{:g}", other.shutter));
  if (other.aperture > 0) items.emplace_back("f_number", fmt::format("{:g}", other.aperture));
  if (other.iso_speed > 0) items.emplace_back("iso", fmt::format("{:g}", other.iso_speed));
  return items;
}

}  // namespace ct::analyzer
