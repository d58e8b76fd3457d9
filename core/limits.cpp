// SPDX-License-Identifier: Apache-2.0
#include "core/limits.h"

#include <unistd.h>

#include <algorithm>

#include <fmt/core.h>

#include "core/error.h"

namespace ct {

std::uint64_t physical_memory_bytes() {
  const long pages = ::sysconf(_SC_PHYS_PAGES), page = ::sysconf(_SC_PAGE_SIZE);
  return pages > 0 && page > 0 ? static_cast<std::uint64_t>(pages) * static_cast<std::uint64_t>(page) : 0;
}

void check_memory(double bytes, std::string_view what) {
  const double memory = static_cast<double>(physical_memory_bytes());
  if (memory > 0 && !(bytes <= memory))
    throw InputError(fmt::format("{}: needs {:.3g} GB of memory, more than this machine's {:.3g} GB", what, bytes * 1e-9,
                                 memory * 1e-9));
}

void check_image_size(std::string_view file, long long width, long long height, int channels,
                      std::uintmax_t file_bytes, int bytes_per_sample) {
  const double pixels = static_cast<double>(width) * static_cast<double>(height);
  if (pixels > kMaxImagePixels)
    throw InputError(fmt::format("{}: image of {}x{} pixels, more than the limit of 2^30 ({:.0f}) pixels", file, width,
                                 height, kMaxImagePixels));
  const double floats = pixels * std::max(channels, 1) * sizeof(float);
  if (floats > kImageMemoryBudgetBytes)
    throw InputError(fmt::format("{}: image of {}x{} pixels, {} channels: needs {:.3g} GB as floats, more than the "
                                 "budget of 1 GiB for one image (about 89 megapixels of RGB)",
                                 file, width, height, channels, floats * 1e-9));
  if (file_bytes > 0) {
    const double stored = pixels * std::max(channels, 1) * std::max(bytes_per_sample, 1);
    if (stored > kMaxCompressionRatio * static_cast<double>(file_bytes))
      throw InputError(fmt::format("{}: image of {}x{} pixels, {} channels: its header claims {:.0f} bytes of samples, "
                                   "more than its {} bytes can hold (at most {:.0f} each); the file is corrupt or cut "
                                   "short",
                                   file, width, height, channels, stored, file_bytes, kMaxCompressionRatio));
  }
  check_memory(floats, fmt::format("{}: image of {}x{} pixels", file, width, height));
}

}  // namespace ct
