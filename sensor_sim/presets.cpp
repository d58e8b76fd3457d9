// SPDX-License-Identifier: Apache-2.0
// The presets: patches on the defaults of config.h. Their numbers, and where they come from, are tabulated in
// docs/sensor.md ("Presets"); what is not a published measurement is a representative value and says so.
#include <fmt/core.h>
#include <fmt/format.h>

#include "core/error.h"
#include "sensor_sim/config.h"

namespace ct::sensor {
namespace {

struct Preset {
  std::string name;
  Json patch;
};

const std::vector<Preset>& presets() {
  static const std::vector<Preset> all = {
      {"ideal",
       {{"description",
         "Ideal colorimetric camera: the CIE 1931 observer with unit peak QE, no noise, no saturation, no ADC; "
         "R,G,B are X,Y,Z as mean photo-electrons"}}},
      // Full-frame CMOS at ISO 100. Pixel pitch from the sensor's geometry (36 mm / 5760 pixels); full well
      // from a photon-transfer measurement (67 684 e⁻ at ISO 100, Magic Lantern forum); black level 2048 of
      // 14 bits as in its raw files; gain chosen so the full well meets the top code; QE and read noise are
      // representative of published measurements (around 49 % and 33 e⁻ at ISO 100).
      {"canon_eos_5d_mkiii",
       {{"description", "Canon EOS 5D Mark III at ISO 100 (representative, see docs/sensor.md)"},
        {"pixel", {{"pitch_um", 6.25}, {"fill_factor", 1.0}}},
        {"spectral_response", {{"camera", "canon_eos_5d_mkiii"}, {"peak_qe", 0.49}, {"outside_curve", "zero"}}},
        {"cfa", {{"enabled", true}, {"pattern", "RGGB"}, {"demosaic", "bilinear"}}},
        {"noise",
         {{"enabled", true}, {"dark_current_e_per_s", 0.1}, {"read_e", 33.0}, {"dsnu_e", 2.0}, {"prnu", 0.005}}},
        {"full_well", {{"enabled", true}, {"electrons", 67684.0}}},
        {"adc", {{"enabled", true}, {"gain_dn_per_e", 0.2118}, {"black_level_dn", 2048.0}, {"bits", 14}}}}},
      // An interline-transfer machine-vision CCD of the Sony ICX285 class (6.45 µm pixels, 12-bit camera):
      // representative values; its colour filters are approximated by a shipped camera's curves.
      {"machine_vision_ccd",
       {{"description", "Machine-vision colour CCD, ICX285 class (representative, see docs/sensor.md)"},
        {"pixel", {{"pitch_um", 6.45}, {"fill_factor", 1.0}}},
        {"spectral_response", {{"camera", "sony_ilce_6400"}, {"peak_qe", 0.45}, {"outside_curve", "zero"}}},
        {"cfa", {{"enabled", true}, {"pattern", "RGGB"}, {"demosaic", "bilinear"}}},
        {"noise", {{"enabled", true}, {"dark_current_e_per_s", 2.0}, {"read_e", 8.0}, {"dsnu_e", 1.0}, {"prnu", 0.01}}},
        {"full_well", {{"enabled", true}, {"electrons", 18000.0}}},
        {"adc", {{"enabled", true}, {"gain_dn_per_e", 0.22}, {"black_level_dn", 32.0}, {"bits", 12}}}}},
      // A small-pixel back-illuminated phone sensor behind an f/1.8 lens: representative values.
      {"smartphone",
       {{"description", "Smartphone camera, 1.4 um BSI CMOS behind f/1.8 (representative, see docs/sensor.md)"},
        {"optics", {{"f_number", 1.8}}},
        {"pixel", {{"pitch_um", 1.4}, {"fill_factor", 1.0}}},
        {"spectral_response", {{"camera", "sony_ilce_7m3"}, {"peak_qe", 0.75}, {"outside_curve", "zero"}}},
        {"cfa", {{"enabled", true}, {"pattern", "RGGB"}, {"demosaic", "bilinear"}}},
        {"noise", {{"enabled", true}, {"dark_current_e_per_s", 5.0}, {"read_e", 2.0}, {"dsnu_e", 0.5}, {"prnu", 0.01}}},
        {"full_well", {{"enabled", true}, {"electrons", 6000.0}}},
        {"adc", {{"enabled", true}, {"gain_dn_per_e", 0.16}, {"black_level_dn", 64.0}, {"bits", 10}}}}},
  };
  return all;
}

}  // namespace

const std::vector<std::string>& preset_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> n;
    for (const Preset& p : presets()) n.push_back(p.name);
    return n;
  }();
  return names;
}

const Json& preset(std::string_view name) {
  for (const Preset& p : presets())
    if (p.name == name) return p.patch;
  throw InputError(fmt::format("preset: unknown preset \"{}\" (presets: {})", name, fmt::join(preset_names(), ", ")));
}

}  // namespace ct::sensor
