// SPDX-License-Identifier: Apache-2.0
#pragma once
// The exposure (docs/sensor.md, "2. Exposure and pixel area"): one pass over the image at unit exposure (T = 1 s) — the survey —
// and the automatic exposure time chosen from it. The survey also gathers what the display rendering
// (display_rendering.h) and veiling glare need: the emitters' spectra, the surfaces' signal in the display's
// sample rows and the image's mean signal.

#include <array>
#include <cstddef>
#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "core/progress.h"
#include "core/spectral_exr.h"
#include "sensor_sim/cfa.h"
#include "sensor_sim/config.h"
#include "sensor_sim/sensor_rows.h"

namespace ct::sensor {

// Sensor row ranges [first, last) to survey: every row in blocks when the exposure is automatic, else only the
// rows the display samples.
std::vector<RowRange> survey_rows(bool all_rows, int k, int height, int rows_per_block);

// What one pass over the image at unit exposure (T = 1 s) finds: the brightest channel of each pixel for the
// automatic exposure (surfaces and emitters apart), the emitters' spectra, and the camera signal of the
// surfaces in the display's sample rows.
struct Survey {
  std::vector<float> surfaces, emitters;  // brightest channel per pixel, e⁻/s
  std::map<std::int32_t, std::pair<std::vector<double>, std::size_t>> emitter_spectra;  // by id: Σ bands, pixels
  std::vector<float> display_samples;                                                  // surfaces, 3 per pixel
  std::array<double, 3> signal_sum{};  // Σ linear signal over every surveyed pixel, emitters included (veiling glare)
  std::size_t pixels = 0;
};

// Surveys the rows `ranges` of `total` (with `emission`, when given, and the ids of the `lights`, to tell
// emitters from surfaces) at the unit exposure of `unit_run`; `want_display` gathers the display's samples and
// the emitters' spectra too.
Survey survey_image(SpectralExrReader& reader, const SensorRun& unit_run, const SpectralLayer& total,
                    const SpectralLayer* emission, const std::set<std::int32_t>& lights,
                    const std::vector<RowRange>& ranges, bool want_display, Progress& progress);

// Exposure time that puts the `auto_percentile` of the brightest channel's noise-free signal of the surfaces
// (every pixel unless emitters are excluded, or when nothing else is in view) at `auto_level` of the
// saturation signal (1 e⁻ for an ideal sensor).
double auto_exposure(Survey& survey, const SensorConfig& config, const std::string& file,
                     std::vector<std::string>& notes);

}  // namespace ct::sensor
