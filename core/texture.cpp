// SPDX-License-Identifier: Apache-2.0
#include "core/texture.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <unordered_map>

#include <fmt/core.h>

#include "core/colour.h"
#include "core/error.h"
#include "core/parallel.h"

namespace ct {
namespace {

// Index of wrapping t·n into [0, n).
std::size_t wrapped_cell(double t, int n) {
  double cell = std::floor((t - std::floor(t)) * n);
  if (!(cell >= 0.0)) cell = 0.0;  // NaN
  return static_cast<std::size_t>(std::min(cell, n - 1.0));
}

}  // namespace

std::size_t ImageTexture::texel_at(double u, double v) const {
  // v runs up from the bottom row; image rows are stored from the top.
  const std::size_t x = wrapped_cell(u, width);
  const std::size_t y = static_cast<std::size_t>(height) - 1 - wrapped_cell(v, height);
  return y * static_cast<std::size_t>(width) + x;
}

ScaledSigmoid texel_spectrum(const std::array<double, 3>& linear_srgb, TextureUse use) {
  if (use == TextureUse::Reflectance) return ScaledSigmoid{1.0, upsample_rgb_reflectance(linear_srgb)};
  ScaledSigmoid emitted = upsample_rgb_unbounded(linear_srgb);
  emitted.illuminant = true;  // relative to the colour space's white, D65
  return emitted;
}

TexelSpectra upsample_texels(const ImageTexture& texture, int threads) {
  struct Key {
    std::array<std::uint32_t, 3> bits;
    bool operator==(const Key&) const = default;
  };
  struct KeyHash {
    std::size_t operator()(const Key& k) const {
      return (static_cast<std::size_t>(k.bits[0]) * 0x9E3779B97F4A7C15ull) ^
             (static_cast<std::size_t>(k.bits[1]) * 0xC2B2AE3D27D4EB4Full) ^ static_cast<std::size_t>(k.bits[2]);
    }
  };
  TexelSpectra out;
  out.palette_of.resize(texture.texel_count());
  std::unordered_map<Key, std::uint32_t, KeyHash> index;
  std::vector<std::size_t> first_texel;
  for (std::size_t t = 0; t < texture.texel_count(); ++t) {
    Key key;
    std::memcpy(key.bits.data(), texture.rgb.data() + 3 * t, sizeof(key.bits));
    const auto [it, fresh] = index.emplace(key, static_cast<std::uint32_t>(first_texel.size()));
    if (fresh) first_texel.push_back(t);
    out.palette_of[t] = it->second;
  }
  out.palette.resize(first_texel.size());
  parallel_for(first_texel.size(), threads, [&](std::size_t i) {
    ScaledSigmoid s = texel_spectrum(texture.texel(first_texel[i]), texture.use);
    s.scale *= texture.scale;
    out.palette[i] = s;
  });
  return out;
}

std::vector<double> palette_band_averages(const TexelSpectra& spectra, const Bands& bands, int threads) {
  const std::size_t entries = spectra.palette.size(), nb = bands.size();
  std::vector<double> values(entries * nb);
  parallel_for(entries, threads, [&](std::size_t i) {
    tabulated_band_averages(spectra.palette[i], bands, values.data() + i * nb);
  });
  return values;
}

}  // namespace ct
