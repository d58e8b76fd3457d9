// SPDX-License-Identifier: Apache-2.0
// PLY meshes as a scene's "mesh" shape reads them: read_ply.
#include <cstddef>
#include <cstdint>

#include "core/error.h"
#include "core/ply.h"
#include "tests/fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    ct::read_ply(ct::fuzz::input_file(data, size, "mesh.ply"));
  } catch (const ct::InputError&) {
  }
  return 0;
}
