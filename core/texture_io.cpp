// SPDX-License-Identifier: Apache-2.0
// Image textures read with OpenImageIO: the part of core/texture.h that needs an image library, kept out of
// chromatrace_scene (core/CMakeLists.txt) so that what only loads and checks scenes does not load OpenImageIO.
#include "core/texture.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include <OpenImageIO/imageio.h>
#include <fmt/core.h>

#include "core/colour.h"
#include "core/error.h"
#include "core/statistics.h"
#include "core/file_io.h"
#include "core/library_output.h"
#include "core/limits.h"

namespace ct {
namespace {

std::unique_ptr<OIIO::ImageInput> open_image(const std::filesystem::path& path) {
  const std::string name = path.string();
  const std::uintmax_t bytes = check_input_file(path, InputAccess::Seekable, std::numeric_limits<std::uintmax_t>::max());
  std::unique_ptr<OIIO::ImageInput> in;
  {
    const LibraryStderrSilenced quiet;  // libpng prints its errors itself, which OpenImageIO reports again below
    in = OIIO::ImageInput::open(name);
  }
  if (!in) {
    const std::string why = one_line(OIIO::geterror());
    throw InputError(fmt::format("{}: cannot read image: {}", name, why.empty() ? "unknown format" : why));
  }
  const OIIO::ImageSpec& spec = in->spec();
  if (spec.width < 1 || spec.height < 1 || spec.nchannels < 1)
    throw InputError(fmt::format("{}: image has no pixels", name));
  check_image_size(name, spec.width, spec.height, spec.nchannels, bytes, static_cast<int>(spec.format.size()));
  return in;
}

bool is_float_image(const OIIO::ImageSpec& spec) {
  return spec.format.basetype == OIIO::TypeDesc::FLOAT || spec.format.basetype == OIIO::TypeDesc::HALF ||
         spec.format.basetype == OIIO::TypeDesc::DOUBLE;
}

}  // namespace

NegativeTexels zero_capture_noise(std::vector<float>& values, int width, const std::string& name) {
  NegativeTexels n;
  double negative_sum = 0.0, positive_sum = 0.0;
  std::size_t deepest = 0;
  std::vector<float> positive;
  for (std::size_t i = 0; i < values.size(); ++i) {
    const float v = values[i];
    if (v < 0.0f) {
      ++n.count;
      negative_sum -= v;
      if (-v > n.largest) {
        n.largest = -v;
        deepest = i;
      }
    } else if (v > 0.0f) {
      positive_sum += v;
      positive.push_back(v);
    }
  }
  if (n.count == 0) return n;
  if (!positive.empty()) {
    n.threshold = static_cast<float>(quantile_in_place(std::span<float>(positive), 0.1));
  }
  if (n.largest > n.threshold || negative_sum > 1e-4 * positive_sum)
    throw InputError(fmt::format(
        "{}: {} negative channel values carry light that cannot be ({:.3g} of the image's light; the deepest, {:.4g} "
        "at texel ({}, {}) (x from the left, y from the top), lies below the image's dark end {:.4g}, the 10th "
        "percentile of its positive values; only negatives within it, and together under 1e-4 of the light, are "
        "taken for capture noise and set to zero)",
        name, n.count, positive_sum > 0 ? negative_sum / positive_sum : 1.0, -n.largest,
        deepest / 3 % static_cast<std::size_t>(width), deepest / 3 / static_cast<std::size_t>(width), n.threshold));
  for (float& v : values) v = std::max(v, 0.0f);
  return n;
}

TextureColourSpace default_texture_colour_space(const std::filesystem::path& path) {
  return is_float_image(open_image(path)->spec()) ? TextureColourSpace::Linear : TextureColourSpace::Srgb;
}

ImageTexture read_image_texture(const std::filesystem::path& path, const std::string& file,
                                std::optional<TextureColourSpace> colour_space, TextureUse use, double scale) {
  const std::string name = path.string();
  auto in = open_image(path);
  const OIIO::ImageSpec& spec = in->spec();
  const bool is_float = is_float_image(spec);
  ImageTexture texture;
  texture.file = file;
  texture.colour_space = colour_space.value_or(is_float ? TextureColourSpace::Linear : TextureColourSpace::Srgb);
  texture.use = use;
  texture.scale = scale;
  texture.width = spec.width;
  texture.had_alpha = spec.alpha_channel >= 0 || spec.nchannels == 2 || spec.nchannels >= 4;
  texture.height = spec.height;

  const int channels = spec.nchannels;
  std::vector<float> pixels(texture.texel_count() * static_cast<std::size_t>(channels));
  bool read = false;
  {
    const LibraryStderrSilenced quiet;
    read = in->read_image(0, 0, 0, channels, OIIO::TypeDesc::FLOAT, pixels.data());
  }
  if (!read)
    throw InputError(fmt::format("{}: cannot read pixels: {}", name, one_line(in->geterror())));
  // R, G, B by name when the image names them so; otherwise the first channels (one: grey; two: grey, alpha).
  std::array<int, 3> source = {0, 0, 0};
  const auto named = [&](const char* c) {
    const auto it = std::find(spec.channelnames.begin(), spec.channelnames.end(), c);
    return it == spec.channelnames.end() ? -1 : static_cast<int>(it - spec.channelnames.begin());
  };
  if (named("R") >= 0 && named("G") >= 0 && named("B") >= 0) source = {named("R"), named("G"), named("B")};
  else if (channels >= 3) source = {0, 1, 2};

  texture.rgb.resize(texture.texel_count() * 3);
  for (std::size_t t = 0; t < texture.texel_count(); ++t) {
    for (int c = 0; c < 3; ++c) {
      double value = pixels[t * static_cast<std::size_t>(channels) + static_cast<std::size_t>(source[c])];
      const std::size_t x = t % static_cast<std::size_t>(texture.width), y = t / static_cast<std::size_t>(texture.width);
      if (!std::isfinite(value))
        throw InputError(fmt::format("{}: texel ({}, {}) (x from the left, y from the top) is not finite", name, x, y));
      if (texture.colour_space == TextureColourSpace::Srgb) value = srgb_decode(value);
      if (use == TextureUse::Reflectance && value > 1.0)
        throw InputError(fmt::format("{}: texel ({}, {}) (x from the left, y from the top) reaches {} in linear sRGB, "
                                     "but a reflectance must be in [0, 1]",
                                     name, x, y, value));
      texture.rgb[3 * t + static_cast<std::size_t>(c)] = static_cast<float>(value);
    }
  }
  texture.negatives = zero_capture_noise(texture.rgb, texture.width, name);
  return texture;
}

}  // namespace ct
