// SPDX-License-Identifier: Apache-2.0
// chromatrace sensor IN.exr -o OUT.{exr,tif,png,dng}: the camera simulator (docs/sensor.md).
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <fmt/core.h>

#include "cli/app.h"
#include "cli/command.h"
#include "core/error.h"
#include "core/json_input.h"
#include "core/parallel.h"
#include "core/spectral_exr.h"
#include "sensor_sim/config.h"
#include "sensor_sim/pipeline.h"

namespace ct::cli {
namespace {

struct SensorOptions {
  std::string input, output, config, preset, camera, exposure, outside_curve, cfa, illuminant;
  std::optional<double> exposure_scale, f_number, fov_deg;
  std::optional<int> supersample;
  std::optional<std::uint64_t> seed;
  std::vector<std::string> set;
  bool no_noise = false, print_config = false, quiet = false;
  int threads = 0, block_rows = 0;
};

// A patch {"a": {"b": value}} for the path "a.b".
Json patch_at(const std::string& path, Json value) {
  Json patch = std::move(value);
  std::string rest = path;
  for (std::size_t dot = rest.rfind('.');; dot = rest.rfind('.')) {
    const std::string key = dot == std::string::npos ? rest : rest.substr(dot + 1);
    if (key.empty()) throw InputError(fmt::format("--set {}: empty key in the path", path));
    patch = Json{{key, std::move(patch)}};
    if (dot == std::string::npos) break;
    rest.resize(dot);
  }
  return patch;
}

// --set KEY=VALUE: VALUE as JSON when it parses (numbers, true, null, [1,2,3]), else as a string.
sensor::ConfigPatch set_patch(const std::string& assignment) {
  const std::size_t eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0)
    throw InputError(fmt::format("--set {}: expected KEY=VALUE, e.g. noise.read_e=3", assignment));
  const std::string text = assignment.substr(eq + 1);
  Json value = Json::parse(text, nullptr, false);
  if (value.is_discarded()) value = text;
  return {patch_at(assignment.substr(0, eq), std::move(value)), "--set " + assignment};
}

// The configuration: preset, config file, then each option in a fixed order and --set in the order given;
// each is checked as it is applied, so an error names the file or option that caused it.
sensor::SensorConfig configuration(const SensorOptions& o) {
  std::vector<sensor::ConfigPatch> patches;
  if (!o.config.empty()) patches.push_back(sensor::read_config_patch(o.config));
  const auto add = [&](const char* option, const std::string& path, Json value) {
    patches.push_back({patch_at(path, std::move(value)), option});
  };
  if (!o.preset.empty()) patches.push_back({Json{{"preset", o.preset}}, "--preset"});
  if (!o.camera.empty()) add("--camera", "spectral_response.camera", o.camera);
  if (!o.outside_curve.empty()) add("--outside-curve", "spectral_response.outside_curve", o.outside_curve);
  if (!o.exposure.empty()) {
    Json time = o.exposure;
    if (o.exposure != "auto") {
      time = Json::parse(o.exposure, nullptr, false);
      if (!time.is_number())
        throw InputError(fmt::format("--exposure-s: must be a time in seconds or \"auto\", got \"{}\"", o.exposure));
    }
    add("--exposure-s", "exposure.time_s", time);
  }
  if (o.exposure_scale) add("--exposure-scale", "exposure.scale", *o.exposure_scale);
  if (o.f_number) add("--f-number", "optics.f_number", *o.f_number);
  if (o.fov_deg) add("--fov-deg", "optics.fov_deg", *o.fov_deg);
  if (o.supersample) add("--supersample", "pixel.supersample", *o.supersample);
  if (!o.cfa.empty()) {
    if (o.cfa == "none")
      add("--cfa", "cfa.enabled", false);
    else
      patches.push_back({{{"cfa", {{"enabled", true}, {"pattern", o.cfa}}}}, "--cfa"});
  }
  if (o.no_noise) add("--no-noise", "noise.enabled", false);
  if (o.seed) add("--seed", "noise.seed", *o.seed);
  for (const std::string& s : o.set) patches.push_back(set_patch(s));
  return sensor::resolve_config(patches);
}

int run(const SensorOptions& o) {
  const sensor::SensorConfig config = configuration(o);
  if (o.print_config) {
    fmt::print("{}\n", sensor::config_json(config).dump(2, ' ', false, kReplaceInvalidUtf8));
    return 0;
  }
  if (o.input.empty()) throw InputError("input: no spectral EXR given");
  if (o.output.empty()) throw InputError("--output: no file name given");
  std::vector<std::filesystem::path> inputs = {o.input};
  if (!o.config.empty()) inputs.push_back(o.config);
  if (std::filesystem::is_regular_file(config.response.camera)) inputs.push_back(config.response.camera);
  if (std::filesystem::is_regular_file(o.illuminant)) inputs.push_back(o.illuminant);
  sensor::check_output_path(o.output, inputs);
  set_exr_threads(thread_count(o.threads));

  const auto start = std::chrono::steady_clock::now();
  sensor::RunOptions options;
  options.threads = o.threads;
  options.block_rows = o.block_rows;
  options.progress = !o.quiet;
  options.illuminant = o.illuminant;
  const sensor::RunReport report = sensor::simulate_sensor(o.input, o.output, config, options);
  if (!o.quiet) {
    for (const std::string& note : report.notes) fmt::print(stderr, "note: {}\n", note);
    fmt::print(stderr, "{}: {}x{} pixels, camera {}, exposure {:.6g} s, in {:.3g} s\n", o.output, report.width,
               report.height, config.response.camera, report.exposure_s,
               std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  return 0;
}

}  // namespace

Action add_sensor(CLI::App& app) {
  auto* cmd = add_command(app, "sensor");
  auto o = std::make_shared<SensorOptions>();
  cmd->add_option("input", o->input, "Spectral EXR (emitted radiance, S0 channels; or reflectance with --illuminant)");
  cmd->add_option("-o,--output", o->output,
                  "Output image: .exr (all layers), .tif/.tiff or .png (final image), .dng (the Bayer mosaic)");
  cmd->add_option("--illuminant", o->illuminant,
                  "Light a spectral reflectance EXR (T channels): a CIE illuminant (A, D50, D65, F1..F12) or a CSV file");
  cmd->add_option("--config", o->config, "Sensor settings (chromatrace-sensor/1 JSON), applied over the preset");
  cmd->add_option("--preset", o->preset,
                  "Starting settings: ideal, canon_eos_5d_mkiii, machine_vision_ccd, smartphone");
  cmd->add_option("--camera", o->camera, "Spectral response: a shipped camera, cie1931, or a CSV file");
  cmd->add_option("--outside-curve", o->outside_curve, "Bands beyond the camera curves: error or zero");
  cmd->add_option("--exposure-s", o->exposure, "Exposure time in seconds, or auto");
  cmd->add_option("--exposure-scale", o->exposure_scale, "Multiplies the exposure time (e.g. 4 over-exposes 2 stops)");
  cmd->add_option("--f-number", o->f_number, "Lens f-number N");
  cmd->add_option("--fov-deg", o->fov_deg, "Horizontal field of view for cos4 when the EXR has no camera");
  cmd->add_option("--supersample", o->supersample, "Average k x k rendered pixels into one sensor pixel");
  cmd->add_option("--cfa", o->cfa, "Bayer pattern RGGB, BGGR, GRBG, GBRG, or none");
  cmd->add_flag("--no-noise", o->no_noise, "Every pixel at its expected value (no shot, read or fixed-pattern noise)");
  cmd->add_option("--seed", o->seed, "Seed of the temporal noise (a new frame)");
  cmd->add_option("--set", o->set, "Any setting as KEY=VALUE, e.g. --set noise.read_e=3 (repeatable)")
      ->allow_extra_args(false);
  cmd->add_flag("--print-config", o->print_config, "Print the effective settings as JSON and exit");
  cmd->add_option("--threads", o->threads, "Worker threads (0: all cores)")->check(CLI::NonNegativeNumber);
  cmd->add_option("--block-rows", o->block_rows, "Sensor rows per block (0: automatic)")->check(CLI::NonNegativeNumber);
  cmd->add_flag("-q,--quiet", o->quiet, "No progress or notes on stderr");
  return [o] { return run(*o); };
}

}  // namespace ct::cli
