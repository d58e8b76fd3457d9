// SPDX-License-Identifier: Apache-2.0
// The scene reader as `check-scene` and `render` use it: load_scene on a file (its mesh, CSV and texture
// references resolve in the scratch directory, where there are none).
#include <cstddef>
#include <cstdint>

#include "core/error.h"
#include "core/scene.h"
#include "tests/fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    ct::load_scene(ct::fuzz::input_file(data, size, "scene.json"));
  } catch (const ct::InputError&) {  // bad input is one InputError; anything else escapes and is a finding
  }
  return 0;
}
