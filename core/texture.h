// SPDX-License-Identifier: Apache-2.0
#pragma once
// Image textures: a colour input of the scene format (a reflectance, a diffuse colour, an emitter's or the
// environment's radiance) that varies over a surface's (u, v) or over directions (docs/scene-format.md,
// "Textures"). Each texel's RGB is decoded to linear sRGB and upsampled to a spectrum by core/rgb_to_spectrum's
// coefficient table (upsample_rgb_reflectance / upsample_rgb_unbounded), the code an {"rgb": [...]} spectrum
// uses, so a texture of one colour is that colour's spectrum.
//
// Lookup is nearest-texel (no filtering): the texel that contains (u, v). (u, v) = (0, 0) is the image's
// bottom-left corner and (1, 1) its top-right (Blender's convention); u and v repeat outside [0, 1).

#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "core/rgb_to_spectrum.h"
#include "core/spectrum.h"

namespace ct {

enum class TextureColourSpace { Srgb, Linear };
// What the texels mean, which fixes how they are upsampled: a reflectance must lie in [0, 1] and is upsampled as
// an {"rgb"} spectrum is; a radiance may exceed 1 and is upsampled in the unbounded form (upsample_rgb_unbounded),
// times the colour space's white (rgb_white_at): relative to D65, as an emitted {"rgb"} colour is.
enum class TextureUse { Reflectance, Radiance };

// Negative texels of an image, which a real HDRI has where the camera's and the stitcher's noise pushed a dark
// texel below zero. They are capture noise, and set to zero, when each is no deeper than the image's own dark
// end — the 10th percentile of its positive channel values (`threshold`) — and all together carry at most
// 1e-4 of its light; otherwise they are light that cannot be (an error naming the deepest texel).
struct NegativeTexels {
  std::size_t count = 0;  // channel values below zero, set to zero
  double largest = 0.0;   // the largest magnitude among them
  double threshold = 0.0;  // the image's dark end, which none exceeds
};
// The rule above on an image's linear RGB (3 values per texel, rows of `width` from the top): sets capture noise
// to zero, or throws InputError "name: ..." naming the deepest texel when the negatives carry light.
NegativeTexels zero_capture_noise(std::vector<float>& rgb, int width, const std::string& name);

struct ImageTexture {
  std::string file;  // as written in the scene
  TextureColourSpace colour_space = TextureColourSpace::Srgb;
  TextureUse use = TextureUse::Reflectance;
  double scale = 1.0;  // multiplies every texel's spectrum
  int width = 0, height = 0;
  std::vector<float> rgb;  // linear sRGB, 3 per texel, row-major from the image's top row
  bool had_alpha = false;  // the file has an alpha channel (ignored)
  NegativeTexels negatives;  // capture noise set to zero (linear images; an sRGB file has no negatives)

  std::size_t texel_count() const { return static_cast<std::size_t>(width) * static_cast<std::size_t>(height); }
  std::array<double, 3> texel(std::size_t index) const {
    return {rgb[3 * index], rgb[3 * index + 1], rgb[3 * index + 2]};
  }
  // The texel containing (u, v) (nearest lookup; u, v repeat), as an index y·width + x with y from the top.
  std::size_t texel_at(double u, double v) const;
};

// Reading an image (read_image_texture, default_texture_colour_space) is core/texture_io.cpp, the one part of
// textures that needs OpenImageIO: it is the library chromatrace_texture_io, which chromatrace_scene's users get
// unless they define these two functions themselves (the chromatrace front executable does: cli/front.cpp).
//
// Reads an image with OpenImageIO (any format it reads: PNG, JPEG, TIFF, EXR, HDR, ...): one channel is grey,
// two grey and alpha, three or more RGB(A); alpha is ignored. `colour_space` unset: linear for float images
// (EXR, HDR), sRGB for integer ones (8- or 16-bit PNG, JPEG, TIFF). sRGB texels are decoded with the sRGB
// transfer curve. Errors are InputErrors "path: message" (a missing or unreadable file, no pixels, texels that
// are not finite or are negative, a reflectance texel above 1 naming the texel).
ImageTexture read_image_texture(const std::filesystem::path& path, const std::string& file,
                                std::optional<TextureColourSpace> colour_space, TextureUse use, double scale);

// The colour space read_image_texture assumes for the file when none is given: linear for a float image, sRGB
// for an integer one. Reads the header only; errors as read_image_texture's.
TextureColourSpace default_texture_colour_space(const std::filesystem::path& path);

// The spectra of a texture's texels: each distinct colour is upsampled once (on up to `threads` threads; 0: all),
// in the order of its first texel, so the result does not depend on the thread count.
struct TexelSpectra {
  std::vector<std::uint32_t> palette_of;  // per texel: index into palette
  std::vector<ScaledSigmoid> palette;     // scale · upsampled sigmoid, the texture's scale included
};
TexelSpectra upsample_texels(const ImageTexture& texture, int threads = 0);
// The band averages of each palette entry's spectrum in the form an {"rgb"} spectrum has (1 nm samples):
// palette-major, bands.size() values per entry. What the tracer's bands mode looks up per texel, and what
// `chromatrace prepare-texture` writes for Cycles.
std::vector<double> palette_band_averages(const TexelSpectra& spectra, const Bands& bands, int threads = 0);
// The spectrum of one linear sRGB colour as a texture of `use` upsamples it (before the texture's scale).
ScaledSigmoid texel_spectrum(const std::array<double, 3>& linear_srgb, TextureUse use);

}  // namespace ct
