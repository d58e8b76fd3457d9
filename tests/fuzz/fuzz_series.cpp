// SPDX-License-Identifier: Apache-2.0
// Experiment-series files as `series` and `check-scene` read them: load_series on a file beside the base scene
// its seeds name ("minimal.json", a copy of tests/data/scenes/minimal.json written at start-up).
#include <cstddef>
#include <cstdint>
#include <fstream>

#include "core/error.h"
#include "core/series_format.h"
#include "tests/fuzz/fuzz_input.h"

namespace {

constexpr const char* kBaseScene = R"({
  "format": "chromatrace-scene/1",
  "spectra": {"white": {"samples": [[400, 0.7], [700, 0.8]], "extend": "clamp"}},
  "materials": {
    "wall": {"type": "lambert", "reflectance": "white"},
    "plastic": {"type": "dichromatic", "diffuse": {"rgb": [0.4, 0.3, 0.2]}, "specular": 0.1, "roughness": 0.2}
  },
  "objects": [
    {"name": "floor", "material": "wall", "shape": {"type": "quad", "corner": [-1, -1, 0], "edge1": [2, 0, 0], "edge2": [0, 2, 0]}},
    {"name": "ball", "material": "plastic", "shape": {"type": "sphere", "center": [0, 0, 0.3], "radius": 0.3, "segments": 16}}
  ],
  "lights": [
    {"name": "lamp", "shape": {"type": "quad", "corner": [-0.2, -0.2, 2], "edge1": [0, 0.4, 0], "edge2": [0.4, 0, 0]},
     "radiance": {"blackbody_k": 3000}, "scale": 5}
  ],
  "camera": {"position": [0, -3, 1], "look_at": [0, 0, 0.5], "fov_deg": 40, "resolution": [64, 48]}
})";

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  std::ofstream(ct::fuzz::scratch_directory() / "minimal.json") << kBaseScene;
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    ct::load_series(ct::fuzz::input_file(data, size, "series.json"), 1);
  } catch (const ct::InputError&) {
  }
  return 0;
}
