// SPDX-License-Identifier: Apache-2.0
#include "tests/fuzz/fuzz_input.h"

#include <unistd.h>

#include <fstream>
#include <string>

namespace ct::fuzz {

namespace {

// The harness's scratch directory, removed when the process exits normally (libFuzzer's -max_total_time ends in
// exit()); a crash leaves it, with the input that was being read.
struct Scratch {
  std::filesystem::path path = std::filesystem::temp_directory_path() / ("chromatrace-fuzz-" + std::to_string(::getpid()));
  Scratch() { std::filesystem::create_directories(path); }
  ~Scratch() {
    std::error_code ignored;
    std::filesystem::remove_all(path, ignored);
  }
  Scratch(const Scratch&) = delete;
  Scratch& operator=(const Scratch&) = delete;
};

}  // namespace

const std::filesystem::path& scratch_directory() {
  static const Scratch directory;
  return directory.path;
}

std::filesystem::path input_file(const std::uint8_t* data, std::size_t size, std::string_view name) {
  const std::filesystem::path path = scratch_directory() / name;
  std::ofstream(path, std::ios::binary | std::ios::trunc)
      .write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  return path;
}

}  // namespace ct::fuzz
