// SPDX-License-Identifier: Apache-2.0
#include "analyzer/camera_noise.h"

#include <cmath>

#include <fmt/format.h>
#include <OpenImageIO/imageio.h>

#include "analyzer/raw_input.h"
#include "core/error.h"
#include "sensor_sim/config.h"

namespace ct::analyzer {

CameraNoiseModel camera_noise_from_settings(const std::string& file) {
  const sensor::SensorConfig c = sensor::resolve_config({sensor::read_config_patch(file)});
  if (!c.adc.enabled || !c.noise.enabled)
    throw InputError(fmt::format("--camera-config: {}: {} is off, so the settings give no noise in digital numbers", file,
                                 !c.adc.enabled ? "adc.enabled" : "noise.enabled"));
  CameraNoiseModel m;
  m.gain_dn_per_e = c.adc.gain_dn_per_e;
  m.read_e = c.noise.read_e;
  m.dsnu_e = std::sqrt(c.noise.dsnu_e * c.noise.dsnu_e + c.noise.dsnu_row_e * c.noise.dsnu_row_e + c.noise.dsnu_column_e * c.noise.dsnu_column_e);
  m.prnu = std::sqrt(c.noise.prnu * c.noise.prnu + c.noise.prnu_row * c.noise.prnu_row + c.noise.prnu_column * c.noise.prnu_column);
  m.source = file;
  return m;
}

void check_camera_numbers(const std::string& image, const std::string& layer) {
  if (!layer.empty() && layer != "final")
    throw InputError(fmt::format("--camera-config: the camera's noise is that of the final layer's digital numbers, not of --layer {}", layer));
  if (is_camera_raw(image)) return;
  std::string signal = "of unknown units";
  if (auto in = OIIO::ImageInput::open(image)) {
    const std::string s = in->spec().get_string_attribute("chromatrace.signal");
    if (!s.empty()) signal = "in " + s;
  } else {
    (void)OIIO::geterror();
  }
  if (signal != "in DN")
    throw InputError(fmt::format("--camera-config: {}'s values are {}, but the camera's noise is in its digital numbers (a camera "
                                 "raw, or the simulator's EXR with chromatrace.signal DN)",
                                 image, signal));
}

}  // namespace ct::analyzer
