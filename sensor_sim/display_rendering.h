// SPDX-License-Identifier: Apache-2.0
#pragma once
// The display rendering of an image (display.h: the display layer's equations) chosen from the exposure survey
// (exposure.h): the white balance's illuminant and the scale that sets the display's brightness; and the
// display value of linear camera signal.

#include <cstddef>
#include <string>
#include <vector>

#include "core/json_input.h"
#include "core/spectral_exr.h"
#include "sensor_sim/config.h"
#include "sensor_sim/display.h"
#include "sensor_sim/exposure.h"
#include "sensor_sim/linear_signal.h"

namespace ct::sensor {

// The display rendering at unit exposure: the white balance's illuminant (display.white_balance, else the
// illuminant lighting a reflectance image, else the white the file says its colours are relative to
// (chromatrace.white), else the brightest of the scene's lights the survey saw, else D65), its matrix, and
// the scale that puts the display.percentile of the surfaces' brightest linear sRGB channel at display.level.
// `description` says what was chosen, as JSON; `scene_light` is the illuminant's band values.
DisplayRendering display_rendering(const Survey& survey, const LinearModel& unit_model, const SensorConfig& config,
                                   const SpectralExrInfo& info, const std::string& lit_by, const std::vector<double>& lighting,
                                   Json& description, std::vector<std::string>& notes, std::vector<double>& scene_light);

// The display rendering of `count` pixels of linear signal from `linear`, into `out`.
void display_pixels(const DisplayRendering& display, const float* linear, std::size_t count, int threads, float* out);

}  // namespace ct::sensor
