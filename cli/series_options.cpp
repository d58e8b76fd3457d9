// SPDX-License-Identifier: Apache-2.0
#include "cli/series_options.h"

#include <filesystem>
#include <tuple>

#include <fmt/core.h>

#include "cli/options.h"
#include "core/band_plan.h"
#include "core/error.h"
#include "core/limits.h"

namespace ct::cli {
namespace fs = std::filesystem;

void add_series_render_options(CLI::App* cmd, SeriesRenderOptions& o) {
  cmd->add_option("--variant", o.variants, "Run only this variant (repeatable)");
  cmd->add_option("--renderer", o.renderer, "tracer (the reference path tracer) or cycles (Blender's Cycles, "
                                             "through the add-on)")
      ->capture_default_str();
  cmd->add_option("--resolution", o.resolution, "Image size WxH for every variant (default: the scenes')");
  cmd->add_option("--spp", o.spp, "Paths per pixel (default: the scenes' render.samples)");
  cmd->add_option("--seed", o.seed, "Random seed of the renders (default: the scenes' render.seed)");
  cmd->add_option("--plan", o.plan, "Band plan file (chromatrace-bands/1, e.g. from chromatrace plan) for every variant");
  cmd->add_option("--max-bounces", o.max_bounces, "Scattering events per path for every variant (default: the scenes')");
  cmd->add_option("--components", o.components, "Component families rendered: paths, lights, bounces, all")
      ->capture_default_str();
}

series::RunOptions series_run_options(const SeriesRenderOptions& o, int threads, bool quiet) {
  series::RunOptions r;
  if (o.renderer == "tracer") r.renderer = series::Renderer::Tracer;
  else if (o.renderer == "cycles") r.renderer = series::Renderer::Cycles;
  else throw InputError(fmt::format("--renderer: must be tracer or cycles, got \"{}\"", o.renderer));
  if (!o.resolution.empty()) std::tie(r.width, r.height) = parse_resolution(o.resolution);
  if (o.spp && *o.spp < 1) throw InputError(fmt::format("--spp: must be >= 1, got {}", *o.spp));
  r.spp = o.spp;
  r.seed = o.seed;
  if (o.max_bounces && (*o.max_bounces < 0 || *o.max_bounces > kMaxBounces))
    throw InputError(fmt::format("--max-bounces: must be in [0, {}], got {}", kMaxBounces, *o.max_bounces));
  r.max_bounces = o.max_bounces;
  if (!o.plan.empty()) {
    r.bands = read_band_plan(o.plan);
    r.bands_file = fs::absolute(o.plan);
  }
  r.components = o.components;
  r.variants = o.variants;
  r.threads = threads;
  r.progress = !quiet;
  r.executable = own_executable();
  r.batch_script = blender_batch_script();
  return r;
}

std::vector<std::string> series_render_arguments(const SeriesRenderOptions& o) {
  std::vector<std::string> args = {"--renderer", o.renderer, "--components", o.components};
  const auto pass = [&](const char* option, const std::string& value) {
    if (!value.empty()) args.insert(args.end(), {option, value});
  };
  pass("--resolution", o.resolution);
  pass("--spp", o.spp ? std::to_string(*o.spp) : "");
  pass("--seed", o.seed ? std::to_string(*o.seed) : "");
  pass("--plan", o.plan.empty() ? "" : fs::absolute(o.plan).string());
  pass("--max-bounces", o.max_bounces ? std::to_string(*o.max_bounces) : "");
  for (const std::string& v : o.variants) pass("--variant", v);
  return args;
}

}  // namespace ct::cli
