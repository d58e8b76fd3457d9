// SPDX-License-Identifier: Apache-2.0
#pragma once
// Per-band-group textures for a renderer that works in RGB (Cycles through the Blender add-on), made from an
// artist's image texture or HDRI (`chromatrace prepare-texture`, docs/blender.md).
//
// The bands are rendered in groups of up to three interleaved bands (core/band_plan.h, cycles_render_groups, and
// blender_addon/chromatrace/bands.py, band_groups: 7 bands, 3 to a render -> [0,3,6], [1,4], [2,5]). For each
// group this writes a linear float OpenEXR whose R, G, B are, per texel, the averages over the group's bands of the
// texel's spectrum exactly as the tracer upsamples it (core/texture.h: upsample_texels, palette_band_averages);
// channels without a band are 0.
//
// The outputs are cached by content: every file is named by a hash of the image's bytes, the kind, the
// colour space, the band edges and the group size, and a manifest <hash>.json (written last) lists them; when it
// and its files exist, nothing is done.

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "core/json_input.h"
#include "core/spectrum.h"
#include "core/texture.h"

namespace ct {

struct TexturePrepRequest {
  std::filesystem::path image;
  TextureUse use = TextureUse::Reflectance;
  std::optional<TextureColourSpace> colour_space;  // unset: as read_image_texture guesses (float: linear)
  Bands bands;
  int bands_per_render = 3;
  // One band per render copied into R, G and B (the add-on's one-band fallback for channel-mixing nodes, which
  // then see grey): needs bands_per_render 1.
  bool replicate = false;
  double scale = 1.0;  // multiplies every texel's spectrum (the scene format's texture "scale")
  int threads = 0;  // 0: all
};

struct TexturePrepResult {
  std::string hash;  // 32 hex digits
  bool cached = false;
  TextureColourSpace colour_space = TextureColourSpace::Srgb;
  int width = 0, height = 0;
  std::size_t texels = 0, distinct_colours = 0;
  bool had_alpha = false;
  NegativeTexels negatives;  // capture noise set to zero (core/texture.h)
  std::vector<std::vector<std::size_t>> groups;
  std::vector<std::filesystem::path> files;  // one per group
  std::filesystem::path manifest;
  double seconds = 0.0;
};

// {"zeroed", "largest", "threshold"}: the capture noise an image had (prepare-texture's summary and manifest).
Json negative_texels_json(const NegativeTexels& negatives);

// The cache key of a request: reads the image's bytes (and its header, for the default colour space).
std::string texture_prep_hash(const TexturePrepRequest& request);

// Writes (or finds) the group textures in `directory` (created if missing). Errors are InputErrors naming the
// file and what is wrong (a missing image, a reflectance texel above 1, ...), as read_image_texture's.
TexturePrepResult prepare_texture(const TexturePrepRequest& request, const std::filesystem::path& directory);

}  // namespace ct
