// SPDX-License-Identifier: Apache-2.0
// chromatrace farm render|cycles|series ... -o DIR: work split into Slurm jobs on a cluster (docs/farm.md). The
// scripts, submission and following are in farm/slurm.h; this file says what the tasks of each kind run.
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <fmt/core.h>

#include "cli/app.h"
#include "cli/command.h"
#include "cli/options.h"
#include "cli/series_options.h"
#include "core/band_plan.h"
#include "core/error.h"
#include "core/file_io.h"
#include "core/json_input.h"
#include "core/scene.h"
#include "core/series_format.h"
#include "farm/blender_preflight.h"
#include "farm/slurm.h"
#include "reference_tracer/integrator.h"
#include "reference_tracer/seed_split.h"
#include "series/blender_batch.h"
#include "series/runner.h"

namespace ct::cli {
namespace {
namespace fs = std::filesystem;

struct Common {
  std::string output;
  farm::SlurmOptions slurm;
  std::optional<int> max_concurrent;
  bool dry_run = false, resume = false, wait = false, follow = false, quiet = false;
};

void add_common(CLI::App* cmd, Common& c) {
  cmd->add_option("-o,--output", c.output, "Output directory: scripts, logs, parts and the result (created)")->required();
  cmd->add_option("--partition", c.slurm.partition, "Slurm partition(s) (default: the cluster's)");
  cmd->add_option("--time", c.slurm.time_limit, "Time limit per job, as sbatch --time (e.g. 30, 2:00:00, 1-0)");
  cmd->add_option("--cpus-per-task", c.slurm.cpus_per_task, "CPUs per task; the task uses as many threads")
      ->capture_default_str();
  cmd->add_option("--mem", c.slurm.memory, "Memory per job, as sbatch --mem (e.g. 4G)");
  cmd->add_option("--max-concurrent", c.max_concurrent, "At most this many tasks at once (the array's %N)");
  cmd->add_option("--sbatch-arg", c.slurm.sbatch_args, "A further sbatch option for every job, e.g. --qos=long (repeatable)");
  cmd->add_flag("--dry-run", c.dry_run, "Write the scripts and print the sbatch commands; submit nothing");
  cmd->add_flag("--resume", c.resume, "Submit only the tasks whose outputs are missing (after a failure or scancel)");
  cmd->add_flag("--wait", c.wait, "Follow the jobs to the end with progress; exit 1 when they did not all succeed");
  cmd->add_flag("--follow", c.follow, "Submit nothing: follow the jobs submitted into the directory before, as --wait");
  cmd->add_flag("-q,--quiet", c.quiet, "No progress output");
}

// The options every kind shares, checked before the kind's own work (Blender's pre-flight check, loading a series).
void check_common(Common& c) {
  c.slurm.max_concurrent = c.max_concurrent;
  if (c.dry_run && (c.resume || c.wait || c.follow))
    throw InputError("--dry-run: submits nothing, so cannot --resume, --wait or --follow");
  if (c.follow && c.resume) throw InputError("--follow: submits nothing, so cannot --resume");
  farm::check_options(c.slurm);
}

int run_farm(const farm::FarmJob& job, const Common& c) {
  if (c.follow) return farm::wait(job, !c.quiet);
  farm::submit(job, c.slurm, c.dry_run ? farm::Mode::DryRun : c.resume ? farm::Mode::Resume : farm::Mode::Submit);
  return c.wait ? farm::wait(job, !c.quiet) : 0;
}

fs::path output_directory(const std::string& output, const std::vector<fs::path>& inputs) {
  if (output.empty()) throw InputError("--output: no directory name");
  check_output_directory(output, inputs);
  return fs::absolute(output).lexically_normal();
}

// ---- farm render: the reference tracer, split by seed ----------------------------------------------------------

struct RenderOptions {
  Common common;
  std::string scene, resolution, bands, plan, mode, components = "paths,lights";
  int seeds = 0;
  std::optional<int> spp, max_bounces;
  std::optional<std::uint64_t> seed;
};

CLI::App* add_render(CLI::App* farm, RenderOptions& o) {
  auto* cmd = farm->add_subcommand("render", "The reference tracer's render split into --seeds parts, one task each, "
                                             "combined into DIR/render.exr (as chromatrace render --seeds)");
  cmd->add_option("scene", o.scene, "Scene file (chromatrace-scene/1)")->required();
  cmd->add_option("--seeds", o.seeds, "Parts (array tasks), each with its own seed and a share of the samples")->required();
  cmd->add_option("--spp", o.spp, "Paths per pixel in all (default: the scene's render.samples)");
  cmd->add_option("--seed", o.seed, "The first part's seed (default: the scene's render.seed)");
  cmd->add_option("--resolution", o.resolution, "Image size WxH, overriding the scene's camera");
  cmd->add_option("--bands", o.bands, "Band plan lo:hi:width in nm");
  cmd->add_option("--plan", o.plan, "Band plan file (chromatrace-bands/1)");
  cmd->add_option("--spectral-mode", o.mode, "bands or continuous");
  cmd->add_option("--max-bounces", o.max_bounces, "Scattering events per path");
  cmd->add_option("--components", o.components, "Component families: paths, lights, bounces, all, none")
      ->capture_default_str();
  add_common(cmd, o.common);
  return cmd;
}

int run_render(RenderOptions& o) {
  check_common(o.common);
  // Everything a task would refuse is refused here, before anything is submitted.
  const Scene scene = load_scene(o.scene);
  if (!o.resolution.empty()) parse_resolution(o.resolution);
  if (!o.bands.empty() && !o.plan.empty()) throw InputError("--plan: give either --bands or --plan, not both");
  if (!o.bands.empty()) Bands::parse(o.bands, "--bands");
  if (!o.plan.empty()) read_band_plan(o.plan);
  if (!o.mode.empty() && o.mode != "bands" && o.mode != "continuous")
    throw InputError(fmt::format("--spectral-mode: must be bands or continuous, got \"{}\"", o.mode));
  if (o.max_bounces && *o.max_bounces < 0)
    throw InputError(fmt::format("--max-bounces: must be >= 0, got {}", *o.max_bounces));
  if (o.spp && *o.spp < 1) throw InputError(fmt::format("--spp: must be at least 1, got {}", *o.spp));
  rt::ComponentSelection::parse(o.components);
  const rt::SeedSplit split(o.seeds, o.spp.value_or(scene.render.samples), o.seed.value_or(scene.render.seed));

  farm::FarmJob job;
  job.kind = "render";
  job.directory = output_directory(o.common.output, {o.scene});
  job.result = job.directory / "render.exr";
  std::vector<std::string> render = {own_executable().string(), "render", fs::absolute(o.scene).string(),
                                     "--seeds", std::to_string(split.parts), "--spp", std::to_string(split.samples),
                                     "--seed", std::to_string(split.first_seed), "--components", o.components, "--quiet"};
  const auto pass = [&](const char* option, const std::string& value) {
    if (value.empty()) return;
    render.push_back(option);
    render.push_back(value);
  };
  pass("--resolution", o.resolution);
  pass("--bands", o.bands);
  pass("--plan", o.plan.empty() ? "" : fs::absolute(o.plan).string());
  pass("--spectral-mode", o.mode);
  pass("--max-bounces", o.max_bounces ? std::to_string(*o.max_bounces) : "");
  std::vector<std::string> combine = {own_executable().string(), "combine", "--quiet", "-o", job.result.string()};
  for (int part = 0; part < split.parts; ++part) {
    const fs::path file = job.directory / "parts" / rt::part_file_name(part);
    std::vector<std::string> words = render;
    words.insert(words.end(), {"--part", std::to_string(part), "-o", file.string()});
    job.task_commands.push_back(farm::shell_command(words) + " --threads \"$THREADS\"");
    job.task_outputs.push_back(file);
    combine.push_back(file.string());
  }
  job.assembly_command = farm::shell_command(combine) + " --threads \"$THREADS\"";
  return run_farm(job, o.common);
}

// ---- farm cycles: a spectral Cycles render through the Blender add-on, one task per band group -----------------

struct CyclesOptions {
  Common common;
  std::string source, bands, bands_file, components, resolution, on_mixing_nodes, on_world, ggx_masking;
  std::optional<int> samples, max_bounces, bands_per_render;
  std::optional<std::uint64_t> seed;
};

CLI::App* add_cycles(CLI::App* farm, CyclesOptions& o) {
  auto* cmd = farm->add_subcommand("cycles", "A spectral Cycles render (the Blender add-on's batch) split into one task "
                                             "per band group (and bounce limit, with the bounces components), "
                                             "assembled into DIR/render.exr");
  cmd->add_option("source", o.source, "Scene file (chromatrace-scene/1) or a .blend with chromatrace settings")->required();
  cmd->add_option("--samples", o.samples, "Samples per pixel (default: the scene's)");
  cmd->add_option("--bands", o.bands, "Band plan lo:hi:width in nm (default: the scene's)");
  cmd->add_option("--bands-file", o.bands_file, "Band plan file (chromatrace-bands/1)");
  cmd->add_option("--max-bounces", o.max_bounces, "Scattering events per path");
  cmd->add_option("--components", o.components, "Component families: paths, lights, bounces, all, none (default: the scene's)");
  cmd->add_option("--resolution", o.resolution, "Image size WxH, overriding the camera's");
  cmd->add_option("--seed", o.seed, "Cycles seed (default: the scene's)");
  cmd->add_option("--bands-per-render", o.bands_per_render, "Bands multiplexed into one Cycles render: 1, 2 or 3");
  cmd->add_option("--on-mixing-nodes", o.on_mixing_nodes, "refuse or one-band (as the batch)");
  cmd->add_option("--on-world", o.on_world, "refuse or omit (as the batch)");
  cmd->add_option("--ggx-masking", o.ggx_masking, "scene or cycles: GGX with the scene's masking or this Cycles' own (as the batch)");
  add_common(cmd, o.common);
  return cmd;
}

int run_cycles(CyclesOptions& o) {
  check_common(o.common);
  series::RunOptions renderer;
  renderer.renderer = series::Renderer::Cycles;
  renderer.batch_script = blender_batch_script();
  series::check_renderer(renderer);
  if (!fs::is_regular_file(o.source)) throw InputError(fmt::format("{}: no such file", o.source));
  const bool blend = fs::path(o.source).extension() == ".blend";

  farm::FarmJob job;
  job.kind = "cycles";
  job.directory = output_directory(o.common.output, {o.source});
  job.result = job.directory / "render.exr";
  const fs::path parts = job.directory / "parts";

  // The batch's own options, the same for every task and the assembly.
  series::BlenderBatchCommand batch(renderer.blender, fs::absolute(renderer.batch_script));
  batch.option(blend ? "--blend" : "--scene", fs::absolute(o.source).string())
      .option("--samples", o.samples)
      .option("--bands", o.bands)
      .option("--bands-file", o.bands_file.empty() ? "" : fs::absolute(o.bands_file).string())
      .option("--max-bounces", o.max_bounces)
      .option("--components", o.components)
      .option("--resolution", o.resolution)
      .option("--seed", o.seed)
      .option("--bands-per-render", o.bands_per_render)
      .option("--on-mixing-nodes", o.on_mixing_nodes)
      .option("--on-world", o.on_world)
      .option("--ggx-masking", o.ggx_masking);

  // How many band groups: the batch's pre-flight check, here and now, which also refuses bad input before
  // anything is submitted. Its summary lands in DIR/slurm/preflight.json only when something is submitted.
  std::vector<std::string> explain = batch.argv();
  explain.insert(explain.end(), {"--explain", "-"});
  const farm::BlenderPreflight preflight =
      farm::run_blender_preflight(explain, series::BlenderBatchCommand::environment(own_executable()), o.source);
  job.notes.emplace_back("preflight.json", preflight.summary.dump(1, ' ', false, kReplaceInvalidUtf8) + "\n");
  const int groups = preflight.band_groups;
  // With the bounces components every group has a render per bounce limit: one task each.
  const std::vector<std::string>& variants = preflight.render_variants;

  // Blender's render threads: the task's CPUs (--threads before --python).
  const std::string start = "CHROMATRACE_EXE=" + farm::shell_quote(own_executable().string()) + " " +
                            farm::shell_command(batch.blender_words()) + " --threads \"$THREADS\" " +
                            farm::shell_command(batch.batch_words());
  const auto command = [&](const std::vector<std::string>& more) { return start + " " + farm::shell_command(more); };
  for (int g = 0; g < groups; ++g)
    for (const std::string& variant : variants) {
      std::vector<std::string> more = {"--out", job.result.string(), "--cache-dir", parts.string(), "--band-group",
                                       std::to_string(g), "--quiet"};
      std::string name = fmt::format("band_group_{}", g);
      if (variants.size() > 1) {
        more.insert(more.end(), {"--bounce-limit", variant});
        name += "_" + variant;
      }
      const fs::path done = parts / (name + ".done");
      job.task_commands.push_back(command(more) + " && touch " + farm::shell_quote(done.string()));
      job.task_outputs.push_back(done);
    }
  job.assembly_command = command({"--out", job.result.string(), "--cache-dir", parts.string(), "--quiet"});
  return run_farm(job, o.common);
}

// ---- farm series: an experiment series, one task per distinct render --------------------------------------------

struct SeriesFarmOptions {
  Common common;
  std::string series;
  SeriesRenderOptions render;
};

CLI::App* add_series(CLI::App* farm, SeriesFarmOptions& o) {
  auto* cmd = farm->add_subcommand("series", "An experiment series: one task per distinct render, then camera, "
                                             "analysis and the figure page in DIR (as chromatrace series)");
  cmd->add_option("series", o.series, "Series file (chromatrace-series/1)")->required();
  add_series_render_options(cmd, o.render);
  add_common(cmd, o.common);
  return cmd;
}

int run_series_farm(SeriesFarmOptions& o) {
  check_common(o.common);
  series::RunOptions options = series_run_options(o.render, 0, true);
  series::check_renderer(options);
  const Series series = load_series(o.series, 0);
  const std::vector<std::pair<std::string, std::string>> renders = series::planned_renders(series, options);

  farm::FarmJob job;
  job.kind = "series";
  job.directory = output_directory(o.common.output, {o.series});
  job.result = job.directory / "index.html";  // the figure page, written last
  const std::vector<std::string> start = {own_executable().string(), "series", fs::absolute(o.series).string(),
                                          "-o", job.directory.string(), "--quiet"};
  SeriesRenderOptions one = o.render;
  one.variants.clear();
  for (const auto& [key, variant] : renders) {
    std::vector<std::string> words = start;
    for (const std::string& a : series_render_arguments(one)) words.push_back(a);
    words.insert(words.end(), {"--variant", variant, "--renders-only"});
    job.task_commands.push_back(farm::shell_command(words) + " --threads \"$THREADS\"");
    job.task_outputs.push_back(job.directory / "renders" / (key + ".exr"));
  }
  std::vector<std::string> words = start;
  for (const std::string& a : series_render_arguments(o.render)) words.push_back(a);
  job.assembly_command = farm::shell_command(words) + " --threads \"$THREADS\"";
  return run_farm(job, o.common);
}

}  // namespace

Action add_farm(CLI::App& app) {
  auto* cmd = add_command(app, "farm");
  cmd->require_subcommand(1);
  auto render = std::make_shared<RenderOptions>();
  auto* render_cmd = add_render(cmd, *render);
  auto cycles = std::make_shared<CyclesOptions>();
  auto* cycles_cmd = add_cycles(cmd, *cycles);
  auto series = std::make_shared<SeriesFarmOptions>();
  auto* series_cmd = add_series(cmd, *series);
  return [=] {
    if (render_cmd->parsed()) return run_render(*render);
    if (series_cmd->parsed()) return run_series_farm(*series);
    if (cycles_cmd->parsed()) return run_cycles(*cycles);
    return 2;
  };
}

}  // namespace ct::cli
