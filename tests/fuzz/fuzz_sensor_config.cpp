// SPDX-License-Identifier: Apache-2.0
// Sensor settings files as `sensor --config` reads them: the JSON patch (read_config_patch), then the settings it
// resolves to over its preset (resolve_config), every key checked.
#include <cstddef>
#include <cstdint>

#include "core/error.h"
#include "sensor_sim/config.h"
#include "tests/fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    ct::sensor::resolve_config({ct::sensor::read_config_patch(ct::fuzz::input_file(data, size, "sensor.json"))});
  } catch (const ct::InputError&) {
  }
  return 0;
}
