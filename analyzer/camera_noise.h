// SPDX-License-Identifier: Apache-2.0
#pragma once
// analyze's --camera-config (and the Python module's camera_config): the camera's calibrated noise, in its digital
// numbers, from a sensor settings file (chromatrace-sensor/1, e.g. written by chromatrace calibrate).

#include <string>

#include "analyzer/noise_level.h"

namespace ct::analyzer {

// The noise model of the settings in `file`. InputError naming the option and the file when its ADC or noise is off
// (the settings then give no noise in digital numbers).
CameraNoiseModel camera_noise_from_settings(const std::string& file);

// Checks that `image`'s layer holds the camera's digital numbers, which the settings' noise is in: the final layer of
// a camera raw, or of the simulator's EXR whose chromatrace.signal is DN. InputError naming --camera-config otherwise.
void check_camera_numbers(const std::string& image, const std::string& layer);

}  // namespace ct::analyzer
