// SPDX-License-Identifier: Apache-2.0
// Camera raw files as `analyze` and `info` read them: LibRaw's open and unpack, the sizes checked before
// allocating, then the demosaiced linear camera RGB (read_camera_raw), here of a file named like a DNG.
#include <cstddef>
#include <cstdint>

#include "analyzer/raw_input.h"
#include "core/error.h"
#include "tests/fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    ct::analyzer::read_camera_raw(ct::fuzz::input_file(data, size, "capture.dng"), {});
  } catch (const ct::InputError&) {
  }
  return 0;
}
