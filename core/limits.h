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

// Pixels of an image read (a texture, an image to analyse): 2^30, a gigapixel.
inline constexpr double kMaxImagePixels = 1073741824.0;

// The machine's physical memory, in bytes (0 if unknown).
std::uint64_t physical_memory_bytes();

// InputError "<what>: needs <N> GB of memory, more than this machine's <M> GB" when `bytes` is more than the
// machine's physical memory.
void check_memory(double bytes, std::string_view what);

// Before the pixels of an image are read, from the size its header declares: InputError "<file>: image of
// WxH pixels, more than the limit of 2^30 pixels" (or more memory than the machine has, as floats).
void check_image_size(std::string_view file, long long width, long long height, int channels);

}  // namespace ct
