// SPDX-License-Identifier: Apache-2.0
// Spectral EXR files as `info --check` reads them: the header (SpectralExrReader), then every pixel of every
// layer, object ids and component sums (scan_spectral_exr).
#include <cstddef>
#include <cstdint>

#include "core/error.h"
#include "core/spectral_exr.h"
#include "core/spectral_exr_scan.h"
#include "tests/fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    ct::SpectralExrReader reader(ct::fuzz::input_file(data, size, "image.exr"));
    ct::ScanOptions options;
    options.check_components = true;
    ct::scan_spectral_exr(reader, options);
  } catch (const ct::InputError&) {
  }
  return 0;
}
