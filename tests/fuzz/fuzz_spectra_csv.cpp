// SPDX-License-Identifier: Apache-2.0
// Spectrum CSV tables as scenes, sensor settings and CSV cameras read them: read_csv, then every column as a
// spectrum.
#include <cstddef>
#include <cstdint>

#include "core/csv.h"
#include "core/error.h"
#include "tests/fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const ct::CsvTable table = ct::read_csv(ct::fuzz::input_file(data, size, "spectra.csv"));
    for (const std::string& column : table.columns) {
      try {
        table.spectrum(column);
      } catch (const ct::InputError&) {
      }
    }
  } catch (const ct::InputError&) {
  }
  return 0;
}
