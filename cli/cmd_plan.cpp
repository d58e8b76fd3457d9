// SPDX-License-Identifier: Apache-2.0
// chromatrace plan SCENE.json -o PLAN.json: the fewest bands and bounces for a colour-error target (docs/plan.md).
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <fmt/core.h>
#include <fmt/ranges.h>

#include "cli/app.h"
#include "cli/command.h"
#include "core/error.h"
#include "core/file_io.h"
#include "core/json_input.h"
#include "core/scene.h"
#include "plan/plan.h"

namespace ct::cli {

constexpr int kMaxPreviewSize = 1024, kMaxPreviewSamples = 4096;

Action add_plan(CLI::App& app) {
  auto* cmd = add_command(app, "plan");
  struct Options {
    std::string scene, output, report, renderer = "cycles";
    std::vector<std::string> pilots;
    plan::PlanOptions plan;
    bool quiet = false;
  };
  auto o = std::make_shared<Options>();
  cmd->add_option("scene", o->scene, "Scene file (chromatrace-scene/1)")->required();
  cmd->add_option("-o,--output", o->output, "Band plan to write (chromatrace-bands/1)");
  cmd->add_option("--report", o->report, "Settings, predictions and cost as JSON (also printed on stdout)");
  cmd->add_option("--target-de00", o->plan.target_de00, "Mean ΔE00 to reach")->capture_default_str();
  cmd->add_option("--camera", o->plan.camera, "Observer: cie1931 or a shipped camera")->capture_default_str();
  cmd->add_option("--renderer", o->renderer, "cycles (bands in groups of 3) or tracer")->capture_default_str();
  cmd->add_option("--edge-step", o->plan.edge_step_nm, "Band edges on multiples of this many nm")->capture_default_str();
  cmd->add_option("--preview-size", o->plan.preview_size, "Longer side of the preview render, pixels")->capture_default_str();
  cmd->add_option("--preview-spp", o->plan.preview_samples, "Paths per pixel of the preview render (1 to 4096)")->capture_default_str();
  cmd->add_flag("--bounce-components", o->plan.bounce_components,
                "Cost Cycles renders for separate bounce components (one render per bounce order)");
  cmd->add_flag("!--no-reconstruction", o->plan.reconstruction,
                "Read band values as a step function instead of fitting a reconstruction to the scene's spectra");
  cmd->add_option("--cycles-noise-ratio", o->plan.cycles_noise_ratio,
                  "Cycles' Monte Carlo noise over the tracer's at equal samples (default: measured over the test "
                  "scenes, the prediction stated over their range)");
  cmd->add_option("--cycles-pilot", o->pilots,
                  "Two Cycles renders of the scene with different seeds (same samples, bands and size): Cycles' noise "
                  "against the tracer's measured on them")
      ->expected(2);
  cmd->add_option("--reference-spp", o->plan.reference_samples,
                  "Also predict the mean ΔE00 compare measures against a tracer reference of this many paths per pixel");
  cmd->add_flag("--target-against-reference", o->plan.target_against_reference,
                "With --reference-spp: plan Cycles' samples for the target as compare measures it against that "
                "reference, its noise counted");
  cmd->add_option("--object-target-de00", o->plan.object_target_de00,
                  "Cycles: the mean ΔE00 no object may be predicted above; the samples grow until none is (default: twice "
                  "--target-de00)");
  cmd->add_option("--threads", o->plan.threads, "Worker threads (0: all cores)")->capture_default_str();
  cmd->add_flag("-q,--quiet", o->quiet, "No summary on stderr");

  return [o] {
    if (o->renderer == "cycles") o->plan.renderer = plan::Renderer::Cycles;
    else if (o->renderer == "tracer") o->plan.renderer = plan::Renderer::Tracer;
    else throw InputError(fmt::format("--renderer: must be cycles or tracer, got \"{}\"", o->renderer));
    // The preview is the plan's cheap look at the scene: bounded, so that a mistyped number does not start a render
    // that never ends (the 4096 paths of a reference, on at most 1024 × 1024 pixels).
    if (o->plan.preview_size < 1 || o->plan.preview_size > kMaxPreviewSize)
      throw InputError(fmt::format("--preview-size: must be 1 to {}, got {}", kMaxPreviewSize, o->plan.preview_size));
    if (o->plan.preview_samples < 1 || o->plan.preview_samples > kMaxPreviewSamples)
      throw InputError(fmt::format("--preview-spp: must be 1 to {}, got {}", kMaxPreviewSamples, o->plan.preview_samples));
    if (o->plan.cycles_noise_ratio < 0 || !std::isfinite(o->plan.cycles_noise_ratio))
      throw InputError(fmt::format("--cycles-noise-ratio: must be > 0, got {:g}", o->plan.cycles_noise_ratio));
    if (o->plan.object_target_de00 < 0 || !std::isfinite(o->plan.object_target_de00))
      throw InputError(fmt::format("--object-target-de00: must be > 0, got {:g}", o->plan.object_target_de00));
    if (o->plan.reference_samples < 0)
      throw InputError(fmt::format("--reference-spp: must be >= 1, got {}", o->plan.reference_samples));
    if (o->plan.target_against_reference && o->plan.reference_samples <= 0)
      throw InputError("--target-against-reference: needs --reference-spp, the reference's paths per pixel");
    if (o->plan.target_against_reference && o->plan.renderer != plan::Renderer::Cycles)
      throw InputError("--target-against-reference: it plans Cycles' samples, for --renderer cycles");
    const Scene scene = load_scene(o->scene);
    // Before the preview render: neither output may be an input (the scene, its meshes and tables, the pilots) or
    // the other.
    std::vector<std::filesystem::path> inputs = scene.files;
    inputs.insert(inputs.end(), o->pilots.begin(), o->pilots.end());
    for (const std::string* out : {&o->output, &o->report})
      if (!out->empty()) check_output_file(*out, inputs);
    check_distinct_outputs({o->output, o->report});
    if (!o->pilots.empty()) {
      if (o->plan.cycles_noise_ratio > 0)
        throw InputError("--cycles-pilot: give either --cycles-pilot or --cycles-noise-ratio");
      if (o->plan.renderer != plan::Renderer::Cycles)
        throw InputError("--cycles-pilot: Cycles' noise is for --renderer cycles");
      const plan::NoiseRatio r = plan::measure_cycles_noise(scene, o->pilots[0], o->pilots[1], o->plan.camera, o->plan.threads);
      o->plan.cycles_noise_ratio = r.ratio;
      o->plan.cycles_noise_ratio_range = {std::max(0.0, r.ratio - 2 * r.se), r.ratio + 2 * r.se};
      o->plan.cycles_group_shares = r.group_shares;
      o->plan.cycles_group_shares_edges_nm = r.edges_nm;
      o->plan.cycles_min_samples = r.samples;
      o->plan.cycles_pilot_tracer_noise_at_one = r.tracer_at_one;
      o->plan.cycles_object_noise_ratio = r.object_ratio;
      o->plan.cycles_group_guided_delta_e = r.group_guided_delta_e;
      o->plan.cycles_pixel_noise = r.pixel_noise;
      o->plan.cycles_pixel_noise_width = r.width;
      o->plan.cycles_pixel_noise_height = r.height;
      o->plan.cycles_noise_ratio_from = fmt::format(
          "Cycles pilots {} and {} ({} samples): mean ΔE00 {:.3f} between them against the tracer's {:.3f}, ratio ± "
          "2 standard errors",
          o->pilots[0], o->pilots[1], r.samples, r.cycles, r.tracer);
    }
    const plan::Plan p = plan::make_plan(scene, o->plan);
    const Json report = plan::report_document(p, scene, o->plan);
    if (!o->output.empty()) write_file_atomically(o->output, plan::bands_document(p).dump(2, ' ', false, kReplaceInvalidUtf8) + "\n");
    if (!o->report.empty()) write_file_atomically(o->report, report.dump(2, ' ', false, kReplaceInvalidUtf8) + "\n");
    fmt::print("{}\n", report.dump(2, ' ', false, kReplaceInvalidUtf8));
    if (!o->quiet) {
      std::string cycles;
      if (!p.cycles_samples.empty())
        cycles = fmt::format("; Cycles samples per band group {}, with their noise {:.2f}{}", fmt::join(p.cycles_samples, ", "),
                             p.cycles_predicted_mean,
                             p.cycles_predicted_low < p.cycles_predicted_high
                                 ? fmt::format(" ({:.2f}-{:.2f} over Cycles' noise on the test scenes)",
                                               p.cycles_predicted_low, p.cycles_predicted_high)
                                 : std::string());
      fmt::print(stderr, "{}: {} bands, max bounces {}, predicted mean ΔE00 {:.2f} from them{} (target {:g}{}); Cycles "
                         "renders {} (scene's settings: {})\n",
                 o->scene, p.bands.size(), p.max_bounces, p.predicted_mean, cycles, o->plan.target_de00,
                 p.target_met ? "" : ", NOT met", p.cycles_renders, p.scene_cycles_renders);
    }
    return 0;
  };
}

}  // namespace ct::cli
