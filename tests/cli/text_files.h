// SPDX-License-Identifier: Apache-2.0
#pragma once
// Small file helpers the end-to-end tests share: what a command printed is checked by lines, and inputs and
// outputs are read and written whole.

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace ct::test {

inline int line_count(const std::string& text) { return static_cast<int>(std::count(text.begin(), text.end(), '\n')); }

inline std::string read_text(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream bytes;
  bytes << in.rdbuf();
  return bytes.str();
}

// The smallest valid scene, tests/data/scenes/minimal.json.
inline const std::filesystem::path kMinimal = std::filesystem::path(CHROMATRACE_TEST_DATA) / "scenes" / "minimal.json";
// The paper's test box, scenes/paper/box.json.
inline const std::string kPaperBox = std::string(CHROMATRACE_SOURCE_DIR) + "/scenes/paper/box.json";

inline void write_text(const std::filesystem::path& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

}  // namespace ct::test
