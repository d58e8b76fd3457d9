// SPDX-License-Identifier: Apache-2.0
// Images as `analyze` (and every command that reads an ordinary image) reads them: OpenImageIO's header, the
// size it claims checked against the file and the memory budget, then the pixels, R, G, B and the extra layers
// (read_analysis_image). The file is named by its magic number, as a user's file is by its format, so that
// OpenImageIO picks the reader it would pick for that file.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "analyzer/image_input.h"
#include "core/error.h"
#include "tests/fuzz/fuzz_input.h"

namespace {

std::string_view name_for(std::string_view bytes) {
  const auto starts = [&](std::string_view magic) { return bytes.substr(0, magic.size()) == magic; };
  if (starts("\x89PNG")) return "image.png";
  if (starts("GIF8")) return "image.gif";
  if (starts("II*") || starts("MM\0*")) return "image.tif";
  if (starts("\xff\xd8")) return "image.jpg";
  if (starts("BM")) return "image.bmp";
  if (starts("v/1\x01")) return "image.exr";
  if (bytes.size() > 1 && bytes[0] == 'P' && bytes[1] >= '1' && bytes[1] <= '6') return "image.pnm";
  return "image";
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  try {
    ct::analyzer::read_analysis_image(ct::fuzz::input_file(data, size, name_for(bytes)), "", {});
  } catch (const ct::InputError&) {
  }
  return 0;
}
