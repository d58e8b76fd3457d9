// SPDX-License-Identifier: Apache-2.0
#pragma once
// What every harness shares: the fuzzed bytes as a file, since the commands read files (a directory of this
// process's own under the system's temporary directory, reused by every run).

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string_view>

namespace ct::fuzz {

// This process's scratch directory, created on first use.
const std::filesystem::path& scratch_directory();

// Writes `data` to `name` in the scratch directory and returns its path.
std::filesystem::path input_file(const std::uint8_t* data, std::size_t size, std::string_view name);

}  // namespace ct::fuzz
