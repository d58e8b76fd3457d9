// SPDX-License-Identifier: Apache-2.0
// chromatrace study SCENE.json -o DIR: cost against error for the settings a user can choose (docs/study.md).
#include <algorithm>
#include <filesystem>
#include <memory>
#include <string>
#include <tuple>
#include <vector>

#include <fmt/core.h>

#include "cli/app.h"
#include "cli/command.h"
#include "cli/options.h"
#include "core/error.h"
#include "core/file_io.h"
#include "core/scene.h"
#include "sensor_sim/spectral_response.h"
#include "study/study.h"

namespace ct::cli {
namespace {
namespace fs = std::filesystem;

struct StudyCommandOptions {
  std::string scene, output, resolution, camera = "cie1931";
  std::vector<int> bands = {3, 6, 9, 12, 20};
  std::vector<double> fitted = {2, 1, 0.5};
  std::vector<int> samples;  // default: the scene's samples / 16 and / 4
  std::vector<int> bounces = {1, 2, 3, 5};
  std::vector<std::string> modes = {"continuous"};
  std::vector<std::string> renderers = {"tracer"};
  bool no_plan = false;
  double guided = 0;
  int reference_spp = 0;
  std::uint64_t seed = 1;
  int threads = 0;
  bool quiet = false;
};

template <class T>
void check_each(const std::vector<T>& values, const char* option, T least) {
  for (const T& v : values)
    if (!(v >= least)) throw InputError(fmt::format("{}: every value must be >= {}, got {}", option, least, v));
}

study::StudyOptions study_options(const StudyCommandOptions& o, const Scene& scene) {
  study::StudyOptions s;
  if (!o.resolution.empty()) std::tie(s.width, s.height) = parse_resolution(o.resolution);
  check_each(o.bands, "--bands", 1);
  check_each(o.samples, "--samples", 1);
  check_each(o.bounces, "--bounces", 0);
  for (double t : o.fitted)
    if (!(t > 0)) throw InputError(fmt::format("--fitted: every target must be > 0, got {}", t));
  if (o.reference_spp < 0) throw InputError(fmt::format("--reference-spp: must be >= 1, got {}", o.reference_spp));
  for (const std::string& m : o.modes)
    if (m != "bands" && m != "continuous")
      throw InputError(fmt::format("--modes: each must be bands or continuous, got \"{}\"", m));
  s.renderers.clear();
  for (const std::string& r : o.renderers) {
    if (r == "tracer") s.renderers.push_back(series::Renderer::Tracer);
    else if (r == "cycles") s.renderers.push_back(series::Renderer::Cycles);
    else throw InputError(fmt::format("--renderers: each must be tracer or cycles, got \"{}\"", r));
  }
  sensor::camera_curves(o.camera, {"r", "g", "b"}, "--camera");  // an unknown observer, before any work
  s.uniform_bands = o.bands;
  s.fitted_targets = o.fitted;
  s.samples = o.samples;
  if (s.samples.empty())
    for (int d : {16, 4}) s.samples.push_back(std::max(1, scene.render.samples / d));
  s.bounces = o.bounces;
  s.modes = o.modes;
  s.planned = !o.no_plan;
  if (o.guided != 0) {
    if (!(o.guided > 0 && o.guided < 1))
      throw InputError(fmt::format("--guided: the guided groups' fraction of the guide's samples must be in (0, 1), got {}", o.guided));
    if (o.no_plan) throw InputError("--guided: guides the planned setting's groups, which --no-plan leaves out");
    if (std::find(o.renderers.begin(), o.renderers.end(), "cycles") == o.renderers.end())
      throw InputError("--guided: band groups are Cycles': needs --renderers cycles");
  }
  s.guided_fraction = o.guided;
  s.reference_samples = o.reference_spp;
  s.camera = o.camera;
  s.seed = o.seed;
  s.threads = o.threads;
  s.progress = !o.quiet;
  s.executable = own_executable();
  s.batch_script = blender_batch_script();
  return s;
}

void print_summary(const study::StudyResult& result, const fs::path& dir) {
  fmt::print("{:<26} {:<34} {:>8} {:>9} {:>8} {:>9} {:>10} {:>8}\n", "setting", "value", "CPU s", "mean dE00",
             "p95", "noise", "systematic", "classes");
  for (const study::SettingResult& r : result.settings) {
    if (!r.ok) {
      fmt::print("{:<26} failed: {}\n", r.setting.name, r.error);
      continue;
    }
    fmt::print("{:<26} {:<34} {:>8.2f} {:>9.2f} {:>8.2f} {:>9.2f} {:>10} {:>5}/{:<2} {}\n", r.setting.name,
               r.setting.value.substr(0, 34), r.cpu_s, r.mean, r.p95, r.noise_rms,
               r.systematic_measurable ? fmt::format("{:.2f}", r.systematic_rms) : "-", r.classes_kept,
               r.objects.size(), r.pareto ? "pareto" : "");
  }
  fmt::print("{}\n", (dir / "index.html").string());
}

}  // namespace

Action add_study(CLI::App& app) {
  auto* cmd = add_command(app, "study");
  auto o = std::make_shared<StudyCommandOptions>();
  cmd->add_option("scene", o->scene, "Scene file (chromatrace-scene/1)")->required();
  cmd->add_option("-o,--output", o->output, "Output directory (created; its parent must exist)")->required();
  cmd->add_option("--resolution", o->resolution, "Image size WxH of every render (default: the scene's)");
  cmd->add_option("--bands", o->bands, "Uniform band counts to try, comma-separated")->delimiter(',')->capture_default_str();
  cmd->add_option("--fitted", o->fitted, "Mean dE00 targets whose fitted band plans (chromatrace plan) to try")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_option("--samples", o->samples, "Samples per pixel to try (default: the scene's / 16 and / 4)")->delimiter(',');
  cmd->add_option("--bounces", o->bounces, "Bounce limits to try")->delimiter(',')->capture_default_str();
  cmd->add_option("--modes", o->modes, "Spectral modes to try besides the scene's (tracer): bands, continuous")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_option("--renderers", o->renderers, "tracer, cycles (Blender's Cycles through the add-on)")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_flag("--no-plan", o->no_plan, "Leave out the setting chromatrace plan chooses for a mean dE00 of 1");
  cmd->add_option("--guided", o->guided,
                  "Cycles: also the planned setting with its group of most samples guiding the others, rendered at this "
                  "fraction of its samples (e.g. 0.125) with adaptive sampling up to them (docs/plan.md)");
  cmd->add_option("--reference-spp", o->reference_spp, "Samples of the reference render (default: 4 x the most tried)");
  cmd->add_option("--camera", o->camera, "Observer of the dE00: cie1931 or a shipped camera")->capture_default_str();
  cmd->add_option("--seed", o->seed, "Random seed of the first render of each setting (the second: seed + 1)")
      ->capture_default_str();
  cmd->add_option("--threads", o->threads, "Worker threads (0: all cores)")->check(CLI::NonNegativeNumber);
  cmd->add_flag("-q,--quiet", o->quiet, "No progress output (the summary table is still printed)");
  return [o] {
    const Scene scene = load_scene(o->scene);
    study::StudyOptions options = study_options(*o, scene);
    check_output_directory(o->output, scene.files);
    if (std::find(options.renderers.begin(), options.renderers.end(), series::Renderer::Cycles) != options.renderers.end()) {
      series::RunOptions probe;
      probe.renderer = series::Renderer::Cycles;
      probe.batch_script = options.batch_script;
      series::check_renderer(probe);
      options.blender = probe.blender;
    }
    const study::StudyResult result = study::run_study(o->scene, o->output, options);
    print_summary(result, o->output);
    for (const study::SettingResult& r : result.settings)
      if (!r.ok) return 1;
    return 0;
  };
}

}  // namespace ct::cli
