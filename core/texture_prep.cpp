// SPDX-License-Identifier: Apache-2.0
#include "core/texture_prep.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string_view>

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <fmt/core.h>

#include "core/band_plan.h"
#include "core/error.h"
#include "core/exr_output.h"
#include "core/file_io.h"
#include "core/json_input.h"
#include "core/spectral_exr.h"

namespace ct {
namespace {

// Bump when the upsampling or the output layout changes, so that old caches are not reused.
constexpr std::string_view kPrepVersion = "chromatrace-texture-prep/3";
constexpr int kRowsPerWrite = 64;

// Two independent 64-bit multiply-xor lanes over 8-byte words (not cryptographic; a content key for a cache).
class Hash128 {
 public:
  void add(std::string_view bytes) {
    std::size_t i = 0;
    for (; i + 8 <= bytes.size(); i += 8) {
      std::uint64_t w;
      std::memcpy(&w, bytes.data() + i, 8);
      mix(w);
    }
    std::uint64_t tail = 0;
    std::memcpy(&tail, bytes.data() + i, bytes.size() - i);
    mix(tail ^ (static_cast<std::uint64_t>(bytes.size() - i) << 56));
    mix(static_cast<std::uint64_t>(bytes.size()));
  }
  std::string hex() const { return fmt::format("{:016x}{:016x}", finish(a_), finish(b_)); }

 private:
  void mix(std::uint64_t w) {
    a_ = (a_ ^ w) * 0x100000001B3ull;
    a_ ^= a_ >> 29;
    b_ = (b_ + w) * 0x9E3779B97F4A7C15ull;
    b_ ^= b_ >> 31;
  }
  static std::uint64_t finish(std::uint64_t h) {
    h ^= h >> 33;
    h *= 0xFF51AFD7ED558CCDull;
    h ^= h >> 33;
    h *= 0xC4CEB9FE1A85EC53ull;
    return h ^ (h >> 33);
  }
  std::uint64_t a_ = 0xCBF29CE484222325ull, b_ = 0x84222325CBF29CE4ull;
};

const char* kind_name(TextureUse use) { return use == TextureUse::Reflectance ? "reflectance" : "radiance"; }
const char* space_name(TextureColourSpace cs) { return cs == TextureColourSpace::Srgb ? "sRGB" : "linear"; }

TextureColourSpace resolved_colour_space(const TexturePrepRequest& r) {
  return r.colour_space ? *r.colour_space : default_texture_colour_space(r.image);
}

std::string hash_of(const TexturePrepRequest& r, TextureColourSpace colour_space) {
  Hash128 h;
  h.add(read_file(r.image));
  std::string key = fmt::format("{}|{}|{}|{}|{}", kPrepVersion, kind_name(r.use), space_name(colour_space),
                                r.bands_per_render, r.replicate ? "replicate|" : "");
  if (r.scale != 1.0) key += fmt::format("scale={:.17g}|", r.scale);
  for (const double e : r.bands.edges()) key += fmt::format("{:.17g},", e);
  h.add(key);
  return h.hex();
}

std::string group_file_name(const std::string& hash, std::size_t group) { return fmt::format("{}-group{}.exr", hash, group); }

// The manifest of a complete earlier run, if there is one and all its files exist.
std::optional<Json> cached_manifest(const std::filesystem::path& manifest, const std::filesystem::path& directory) {
  if (!std::filesystem::is_regular_file(manifest)) return std::nullopt;
  try {
    Json m = parse_json(read_file(manifest), manifest.string());
    for (const Json& g : m.at("groups"))
      if (!std::filesystem::is_regular_file(directory / g.at("file").get<std::string>())) return std::nullopt;
    return m;
  } catch (const std::exception&) {
    return std::nullopt;  // unreadable: make it again
  }
}

void write_group(const std::filesystem::path& target, const ImageTexture& texture, const TexelSpectra& spectra,
                 const std::vector<double>& averages, std::size_t band_count, const std::vector<std::size_t>& group,
                 bool replicate) {
  const int w = texture.width, h = texture.height;
  Imf::Header header(w, h);
  for (const char* c : {"R", "G", "B"}) header.channels().insert(c, Imf::Channel(Imf::FLOAT));
  header.compression() = Imf::ZIP_COMPRESSION;
  AtomicExrOutput out(target, header);
  const std::size_t width = static_cast<std::size_t>(w);
  std::vector<float> rows(static_cast<std::size_t>(kRowsPerWrite) * width * 3);
  for (int y0 = 0; y0 < h; y0 += kRowsPerWrite) {
    const int n = std::min(kRowsPerWrite, h - y0);
    const std::size_t first = static_cast<std::size_t>(y0) * width;
    for (std::size_t i = 0; i < static_cast<std::size_t>(n) * width; ++i) {
      const double* entry = averages.data() + static_cast<std::size_t>(spectra.palette_of[first + i]) * band_count;
      for (std::size_t c = 0; c < 3; ++c) {
        const std::size_t k = replicate ? 0 : c;
        rows[3 * i + c] = k < group.size() ? static_cast<float>(entry[group[k]]) : 0.0f;
      }
    }
    const Imath::Box2i window({0, y0}, {w - 1, y0 + n - 1});
    Imf::FrameBuffer frame;
    const char* names[3] = {"R", "G", "B"};
    for (std::size_t c = 0; c < 3; ++c)
      frame.insert(names[c], Imf::Slice::Make(Imf::FLOAT, rows.data() + c, window, 3 * sizeof(float),
                                              3 * sizeof(float) * width));
    out.write_rows(frame, y0, n);
  }
  out.finish();
}

}  // namespace

Json negative_texels_json(const NegativeTexels& n) {
  return {{"zeroed", n.count}, {"largest", n.largest}, {"threshold", n.threshold}};
}

std::string texture_prep_hash(const TexturePrepRequest& request) {
  return hash_of(request, resolved_colour_space(request));
}

TexturePrepResult prepare_texture(const TexturePrepRequest& request, const std::filesystem::path& directory) {
  const auto start = std::chrono::steady_clock::now();
  const auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };
  if (request.bands.size() == 0) throw InputError("bands: no bands");
  if (request.replicate && request.bands_per_render != 1)
    throw InputError(fmt::format("replicate: needs one band per render, not {}", request.bands_per_render));
  if (!(request.scale >= 0.0) || !std::isfinite(request.scale))
    throw InputError(fmt::format("scale: must be a finite number >= 0, got {}", request.scale));
  check_input_file(request.image, InputAccess::Seekable, std::numeric_limits<std::uintmax_t>::max());
  TexturePrepResult result;
  result.groups = cycles_render_groups(request.bands.size(), request.bands_per_render);
  result.colour_space = resolved_colour_space(request);
  result.hash = hash_of(request, result.colour_space);
  result.manifest = directory / (result.hash + ".json");
  for (std::size_t g = 0; g < result.groups.size(); ++g) result.files.push_back(directory / group_file_name(result.hash, g));

  if (const auto m = cached_manifest(result.manifest, directory)) {
    result.cached = true;
    result.width = m->value("width", 0);
    result.height = m->value("height", 0);
    result.texels = m->value("texels", std::size_t{0});
    result.distinct_colours = m->value("distinct_colours", std::size_t{0});
    result.had_alpha = m->value("alpha_ignored", false);
    if (const auto n = m->find("negative_texels"); n != m->end()) {
      result.negatives.count = n->value("zeroed", std::size_t{0});
      result.negatives.largest = n->value("largest", 0.0);
      result.negatives.threshold = n->value("threshold", 0.0);
    }
    result.seconds = elapsed();
    return result;
  }

  const ImageTexture texture =
      read_image_texture(request.image, request.image.string(), result.colour_space, request.use, request.scale);
  const TexelSpectra spectra = upsample_texels(texture, request.threads);
  const std::vector<double> averages = palette_band_averages(spectra, request.bands, request.threads);
  result.width = texture.width;
  result.height = texture.height;
  result.texels = texture.texel_count();
  result.distinct_colours = spectra.palette.size();
  result.had_alpha = texture.had_alpha;
  result.negatives = texture.negatives;

  std::error_code ec;
  const bool made_directory = !std::filesystem::exists(directory, ec);
  std::filesystem::create_directories(directory, ec);
  if (!std::filesystem::is_directory(directory))
    throw InputError(fmt::format("{}: cannot create the output directory", directory.string()));
  // All the groups and their manifest, or none: a run that fails part way (a full disk) removes the group files it
  // wrote, and the directory it made, so that no group is left without the manifest that says what it is.
  std::size_t written = 0;
  struct Cleanup {
    const std::vector<std::filesystem::path>& files;
    const std::filesystem::path& directory;
    const std::size_t& written;
    bool made_directory, done = false;
    ~Cleanup() {
      if (done) return;
      std::error_code ignored;
      for (std::size_t g = 0; g < written; ++g) std::filesystem::remove(files[g], ignored);
      if (made_directory) std::filesystem::remove(directory, ignored);  // only when empty
    }
  } cleanup{result.files, directory, written, made_directory};
  set_exr_threads(request.threads);
  Json groups = Json::array();
  for (std::size_t g = 0; g < result.groups.size(); ++g) {
    write_group(result.files[g], texture, spectra, averages, request.bands.size(), result.groups[g], request.replicate);
    written = g + 1;
    std::vector<double> lo, hi;
    for (const std::size_t b : result.groups[g]) {
      lo.push_back(request.bands.lo(b));
      hi.push_back(request.bands.hi(b));
    }
    groups.push_back({{"file", result.files[g].filename().string()}, {"bands", result.groups[g]}, {"lo_nm", lo}, {"hi_nm", hi}});
  }
  const Json manifest = {{"format", kPrepVersion},
                         {"hash", result.hash},
                         {"image", request.image.string()},
                         {"kind", kind_name(request.use)},
                         {"colour_space", space_name(result.colour_space)},
                         {"bands_per_render", request.bands_per_render},
                         {"replicate", request.replicate},
                         {"scale", request.scale},
                         {"edges_nm", request.bands.edges()},
                         {"width", result.width},
                         {"height", result.height},
                         {"texels", result.texels},
                         {"distinct_colours", result.distinct_colours},
                         {"alpha_ignored", result.had_alpha},
                         {"negative_texels", negative_texels_json(result.negatives)},
                         {"groups", groups}};
  write_file_atomically(result.manifest, manifest.dump(1, ' ', false, kReplaceInvalidUtf8) + "\n");
  cleanup.done = true;
  result.seconds = elapsed();
  return result;
}

}  // namespace ct
