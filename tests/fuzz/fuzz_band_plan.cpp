// SPDX-License-Identifier: Apache-2.0
// Band-plan files as `--bands-file` reads them: read_band_plan.
#include <cstddef>
#include <cstdint>

#include "core/band_plan.h"
#include "core/error.h"
#include "tests/fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    ct::read_band_plan(ct::fuzz::input_file(data, size, "plan.json"));
  } catch (const ct::InputError&) {
  }
  return 0;
}
