// SPDX-License-Identifier: Apache-2.0
// chromatrace calibrate --flat F… --dark D… -o CAMERA.json: a camera's EMVA 1288 parameters from a photon-transfer
// series, as sensor settings the simulator takes and (--report) every estimate per channel with its standard error.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <fmt/core.h>

#include "analyzer/image_input.h"
#include "calibrate/calibration.h"
#include "calibrate/report.h"
#include "cli/app.h"
#include "cli/command.h"
#include "core/error.h"
#include "core/file_io.h"
#include "core/json_input.h"

namespace ct::cli {

Action add_calibrate(CLI::App& app) {
  auto* cmd = add_command(app, "calibrate");
  struct Options {
    std::vector<std::string> flats, darks;
    std::string output, report;
    double photons_per_s = 0;
    std::vector<double> photons_per_pixel;
    std::string input_transfer = "auto";
    double wavelength = 0, pixel_um = 0, temperature = 0;
    std::string camera, basis = "energy";
    bool quiet = false;
  };
  auto o = std::make_shared<Options>();
  // Checked after parsing rather than marked required, so that an option taken for --flat's frames ("--flat --dark D…")
  // is named as such (cli/app.cpp) rather than "--dark is required".
  cmd->add_option("--flat", o->flats,
                  "Flat-field frames: at least two at each exposure time, or, at one exposure time, a pair per irradiance in the "
                  "order given (camera raw, or linear EXR/TIFF/PNG with R, G, B or one channel)");
  cmd->add_option("--dark", o->darks,
                  "Dark frames: at least two at each exposure time of the flats; pairs at further times add to the dark current");
  cmd->add_option("-o,--output", o->output, "Sensor settings written (chromatrace-sensor/1), for chromatrace sensor --config");
  cmd->add_option("--report", o->report,
                  "Report directory: index.html (the datasheet's curves and table), calibration.json (every estimate per "
                  "channel with its standard error, the measured points), the plots as SVG");
  cmd->add_option("--photons-per-s", o->photons_per_s,
                  "Photons per pixel and second reaching the sensor in the flats (for the quantum efficiency)");
  cmd->add_option("--photons-per-pixel", o->photons_per_pixel,
                  "Flats at one exposure time: the photons per pixel of each pair, in the pairs' order (for the linearity and the "
                  "quantum efficiency)");
  cmd->add_option("--wavelength", o->wavelength,
                  "The flats' light's wavelength in nm (monochromatic): with --camera, the measured η sets the settings' peak QE");
  cmd->add_option("--camera", o->camera, "The camera's spectral curves (a shipped camera, cie1931, or a CSV file), for --wavelength");
  cmd->add_option("--pixel-um", o->pixel_um, "The pixel pitch in µm, for the datasheet (and its thresholds per area)");
  cmd->add_option("--temperature", o->temperature, "The sensor's temperature in °C while the frames were taken, for the datasheet");
  cmd->add_option("--basis", o->basis, "What --camera's curves are proportional to: energy (default) or photon");
  cmd->add_option("--input-transfer", o->input_transfer,
                  "What the frames' values are: auto (the file's metadata; an integer file that names no colour space holds digital "
                  "numbers) or linear (say so of a file that names a curve)");
  cmd->add_flag("-q,--quiet", o->quiet, "No summary on stderr");

  return [o, cmd] {
    if (o->flats.empty()) throw InputError("--flat: no flat frames");
    if (o->darks.empty()) throw InputError("--dark: no dark frames");
    if (o->output.empty()) throw InputError("--output: no settings file to write (-o CAMERA.json)");
    calibrate::CalibrationInput input;
    for (const std::string& f : o->flats) input.flats.emplace_back(f);
    for (const std::string& f : o->darks) input.darks.emplace_back(f);
    if (cmd->count("--photons-per-s") > 0) input.photons_per_s = o->photons_per_s;
    input.photons_per_pixel = o->photons_per_pixel;
    analyzer::parse_input_transfer(o->input_transfer);
    input.input_transfer = o->input_transfer;
    if (cmd->count("--wavelength") > 0) input.wavelength_nm = o->wavelength;
    if (cmd->count("--pixel-um") > 0) input.pixel_pitch_um = o->pixel_um;
    if (cmd->count("--temperature") > 0) input.temperature_c = o->temperature;
    input.camera = o->camera;
    input.basis = o->basis;
    std::vector<std::filesystem::path> inputs = input.flats;
    inputs.insert(inputs.end(), input.darks.begin(), input.darks.end());
    std::vector<std::filesystem::path> outputs = {o->output};
    if (!o->report.empty()) outputs.emplace_back(o->report);
    check_distinct_outputs(outputs);
    check_output_file(o->output, inputs);
    if (!o->report.empty()) check_output_directory(o->report, inputs, calibrate::report_files());
    const calibrate::Calibration c = calibrate::calibrate(input);
    // Both outputs or neither: each staged in full before either is moved into place.
    std::optional<StagedDirectory> report;
    if (!o->report.empty()) {
      report.emplace(o->report, std::vector<std::string>{"index.html"});
      calibrate::write_report(c, report->path());
    }
    write_file_atomically(o->output, c.sensor.dump(2, ' ', false, kReplaceInvalidUtf8) + "\n");
    if (report) report->commit();
    if (!o->quiet)
      for (const calibrate::ChannelCalibration& ch : c.channels)
        fmt::print(stderr, "{}: K {:.5g} ± {:.2g} DN/e-, dark noise {:.4g} ± {:.2g} e-, saturation {:.6g} e-, dark current {:.4g} e-/s, "
                           "DSNU {:.3g} e-, PRNU {:.3g} %, linearity error {:.2g} %\n",
                   ch.channel, ch.gain_dn_per_e.value, ch.gain_dn_per_e.standard_error, ch.dark_noise_e.value,
                   ch.dark_noise_e.standard_error, ch.saturation_capacity_e.value, ch.dark_current_e_per_s.value,
                   ch.dsnu_e.total.value, 100 * ch.prnu.total.value, 100 * ch.linearity_error);
    return 0;
  };
}

}  // namespace ct::cli
