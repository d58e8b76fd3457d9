// SPDX-License-Identifier: Apache-2.0
#pragma once
// Ceilings checked before allocating, so that a mistyped size is one line of bad input (exit 2) instead of a
// process that grows until the system kills it (docs/errors.md, "Sizes and memory").

#include <cstddef>
#include <cstdint>
#include <string_view>

namespace ct {

// Bands of a band plan: 0.2 nm bands over 380-780 nm.
inline constexpr std::size_t kMaxBands = 2000;
// Width or height of an image to render (as the scene's camera.resolution allows).
inline constexpr int kMaxImageSide = 65536;

// Scattering events per path (`--max-bounces`, `render.max_bounces`): far beyond where a path's throughput
// under any physical albedo is below a float's resolution; per-bounce layers and counters stay within an int.
inline constexpr int kMaxBounces = 1000;

// Pixels of an image read (a texture, an image to analyse): 2^30, a gigapixel.
inline constexpr double kMaxImagePixels = 1073741824.0;
// The memory an image read may take as floats (pixels x channels x 4 bytes): 1 GiB, e.g. 89 megapixels of RGB.
// Reading one image costs a few times this (the decoder's rows, conversions), which keeps a command under 2 GB.
inline constexpr double kImageMemoryBudgetBytes = 1073741824.0;
// The most bytes of decoded samples one byte of a compressed image file can hold: deflate's limit (PNG, ZIP in
// TIFF) is 1032; LZW (GIF, TIFF) and JPEG reach about 1400 on a constant image. A header claiming more than this
// of its file is refused before anything is allocated.
inline constexpr double kMaxCompressionRatio = 2048.0;
// Bytes of a file read whole (a scene, series, settings, band plan, CSV table, PLY mesh, manifest): 256 MiB.
inline constexpr std::uintmax_t kMaxInputBytes = 256u << 20;

// The machine's physical memory, in bytes (0 if unknown).
std::uint64_t physical_memory_bytes();

// InputError "<what>: needs <N> GB of memory, more than this machine's <M> GB" when `bytes` is more than the
// machine's physical memory.
void check_memory(double bytes, std::string_view what);

// Before the pixels of an image are read, from the size its header declares: InputError "<file>: image of
// WxH pixels, more than the limit of 2^30 pixels", "… needs N GB as floats, more than the budget of 1 GiB for
// one image" (kImageMemoryBudgetBytes), or — given the file's size in bytes and the bytes of one stored
// sample — "… claims N bytes of samples, more than its M bytes can hold" (kMaxCompressionRatio).
void check_image_size(std::string_view file, long long width, long long height, int channels,
                      std::uintmax_t file_bytes = 0, int bytes_per_sample = 1);

}  // namespace ct
