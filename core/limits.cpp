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

void check_image_size(std::string_view file, long long width, long long height, int channels) {
  const double pixels = static_cast<double>(width) * static_cast<double>(height);
  if (pixels > kMaxImagePixels)
    throw InputError(fmt::format("{}: image of {}x{} pixels, more than the limit of 2^30 ({:.0f}) pixels", file, width,
                                 height, kMaxImagePixels));
  check_memory(pixels * std::max(channels, 1) * sizeof(float), fmt::format("{}: image of {}x{} pixels", file, width, height));
}

}  // namespace ct
