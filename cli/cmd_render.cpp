// SPDX-License-Identifier: Apache-2.0
// chromatrace render SCENE.json -o OUT.exr: the reference path tracer.
#include <filesystem>
#include <optional>
#include <tuple>

#include <fmt/core.h>

#include "cli/app.h"
#include "cli/command.h"
#include "cli/options.h"
#include "core/error.h"
#include "core/file_io.h"
#include "core/parallel.h"
#include "core/scene.h"
#include "core/spectral_exr.h"
#include "plan/render_check.h"
#include "reference_tracer/render.h"
#include "reference_tracer/seed_split.h"

namespace ct::cli {
namespace fs = std::filesystem;

Action add_render(CLI::App& app) {
  auto* cmd = add_command(app, "render");
  struct Options {
    std::string scene, output, bands, plan, mode, resolution, components = "paths,lights";
    std::optional<int> spp, max_bounces, seeds, part;
    std::optional<std::uint64_t> seed;
    int threads = 0;
    double time_limit = 0.0;
    bool quiet = false;
  };
  auto o = std::make_shared<Options>();
  cmd->add_option("scene", o->scene, "Scene file (chromatrace-scene/1)")->required();
  cmd->add_option("-o,--output", o->output, "Output spectral EXR")->required();
  cmd->add_option("--spp", o->spp, "Paths per pixel (default: the scene's render.samples)");
  cmd->add_option("--max-bounces", o->max_bounces, "Scattering events per path: 0 emitters, 1 direct, >= 2 global");
  cmd->add_option("--resolution", o->resolution, "Image size WxH, overriding the scene's camera (e.g. 64x64)");
  cmd->add_option("--bands", o->bands, "Band plan lo:hi:width in nm, e.g. 380:780:10");
  cmd->add_option("--plan", o->plan, "Band plan file (chromatrace-bands/1), e.g. from chromatrace plan");
  cmd->add_option("--spectral-mode", o->mode, "bands (band averages, as Cycles) or continuous (hero wavelengths)");
  cmd->add_option("--components", o->components,
                  "Component families: paths, lights, bounces, all, none (comma-separated)")
      ->capture_default_str();
  cmd->add_option("--seed", o->seed, "Random seed (default: the scene's render.seed); the first part's with --seeds");
  cmd->add_option("--seeds", o->seeds,
                  "Split the samples into this many parts with consecutive seeds, rendered one after another and "
                  "combined sample-weighted (as chromatrace farm render does on a cluster)");
  cmd->add_option("--part", o->part, "With --seeds: render only this part (0-based) of the split into --output");
  cmd->add_option("--threads", o->threads, "Worker threads (0: all cores)")->capture_default_str();
  cmd->add_option("--time-limit", o->time_limit, "Stop after the pass during which this many seconds ran out");
  cmd->add_flag("-q,--quiet", o->quiet, "No progress output");

  return [o] {
    Scene scene = load_scene(o->scene);
    if (!o->resolution.empty())
      std::tie(scene.camera.width, scene.camera.height) = parse_resolution(o->resolution);
    rt::RenderOptions options;
    options.samples = o->spp;
    options.max_bounces = o->max_bounces;
    options.bands = band_plan_option(o->bands, o->plan, "--plan");
    if (!o->mode.empty()) {
      if (o->mode == "bands") options.mode = SpectralMode::Bands;
      else if (o->mode == "continuous") options.mode = SpectralMode::Continuous;
      else throw InputError(fmt::format("--spectral-mode: must be bands or continuous, got \"{}\"", o->mode));
    }
    options.seed = o->seed;
    options.components = rt::ComponentSelection::parse(o->components);
    options.threads = o->threads;
    options.time_limit_s = o->time_limit;
    options.progress = !o->quiet;
    if (o->output.empty()) throw InputError("--output: no file name");
    // Fail before a long render, not after it.
    rt::check_options(options);
    rt::check_image_memory(scene, options);
    check_output_file(o->output, scene.files);
    if (o->part && !o->seeds) throw InputError("--part: needs --seeds (the split it is a part of)");
    std::optional<rt::SeedSplit> seed_split;
    if (o->seeds) {
      seed_split.emplace(*o->seeds, options.samples.value_or(scene.render.samples),
                         options.seed.value_or(scene.render.seed));
      if (o->part && (*o->part < 0 || *o->part >= seed_split->parts))
        throw InputError(fmt::format("--part: must be in [0, {}] for --seeds {}, got {}", seed_split->parts - 1,
                                     seed_split->parts, *o->part));
    }
    // What the settings leave out (colours the bands cannot hold, light beyond the bounce limit, noise): said
    // before the render, not found after it.
    plan::RenderRequest request = plan::scene_settings(scene);
    if (options.bands) request.bands = *options.bands;
    if (options.mode) request.mode = *options.mode;
    if (o->max_bounces) request.max_bounces = *o->max_bounces, request.bounces_name = "--max-bounces";
    if (o->spp) request.samples = *o->spp, request.samples_name = "--spp";
    request.threads = o->threads;
    for (const std::string& warning : plan::render_warnings(scene, request))
      fmt::print(stderr, "chromatrace render: warning: {}\n", warning);
    set_exr_threads(thread_count(o->threads));
    const auto render_to = [&](const fs::path& output, const rt::RenderOptions& render_options) {
      const rt::RenderedImage image = rt::render(scene, render_options);
      rt::write_render(output, scene, image);
      if (!o->quiet)
        fmt::print(stderr, "{}: {}×{}, {} bands, {} spp, {:.3g} Mpaths/s\n", output.string(), image.width,
                   image.height, image.bands.size(), image.samples, image.paths / image.seconds * 1e-6);
    };
    if (!o->seeds) {
      render_to(o->output, options);
      return 0;
    }
    const rt::SeedSplit& split = *seed_split;
    const auto part_options = [&](int part) {
      rt::RenderOptions p = options;
      p.samples = split.part_samples(part);
      p.seed = split.part_seed(part);
      return p;
    };
    if (o->part) {
      render_to(o->output, part_options(*o->part));
      return 0;
    }
    // The parts go through files, as on a cluster, so that both give the same bytes (reference_tracer/seed_split.h);
    // a staging directory beside the output, never committed, holds them and is removed at the end.
    const StagedDirectory parts_dir(o->output + ".parts");
    std::vector<fs::path> parts;
    for (int part = 0; part < split.parts; ++part) {
      parts.push_back(parts_dir.path() / rt::part_file_name(part));
      render_to(parts.back(), part_options(part));
    }
    rt::combine_parts(parts, o->output, !o->quiet);
    return 0;
  };
}

}  // namespace ct::cli
