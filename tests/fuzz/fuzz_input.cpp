// SPDX-License-Identifier: Apache-2.0
#include "tests/fuzz/fuzz_input.h"

#include <unistd.h>

#include <fstream>
#include <string>

namespace ct::fuzz {

const std::filesystem::path& scratch_directory() {
  static const std::filesystem::path directory = [] {
    const auto path = std::filesystem::temp_directory_path() / ("chromatrace-fuzz-" + std::to_string(::getpid()));
    std::filesystem::create_directories(path);
    return path;
  }();
  return directory;
}

std::filesystem::path input_file(const std::uint8_t* data, std::size_t size, std::string_view name) {
  const std::filesystem::path path = scratch_directory() / name;
  std::ofstream(path, std::ios::binary | std::ios::trunc)
      .write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  return path;
}

}  // namespace ct::fuzz
