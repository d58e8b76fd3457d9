// SPDX-License-Identifier: Apache-2.0
#pragma once
// `chromatrace study`: what each setting a user can choose costs, and how far from the truth it leaves the image
// and its histograms (docs/study.md).
//
// From a base — the scene's own render settings — one knob at a time is changed: the band plan (uniform counts,
// and plans fitted by `chromatrace plan` to error targets), the samples, the bounce limit, the spectral mode and
// the renderer; one more setting takes every knob from `plan` at once. Each setting is rendered twice, with seeds
// s and s + 1, and each render goes through the camera and the analyzer as a series variant does
// (series/runner.h). A converged reference — 5 nm bands, the scene's bounce limit, many samples, the tracer — is
// rendered and analysed the same way, with seed s + 2.
//
// Error against the reference, over the image (plan::measure_delta_e, through the observer `camera`): mean,
// 95th percentile and root mean square of ΔE00. The Monte Carlo part is the rms ΔE00 between the two seeds' renders
// over √2 (their noise is independent and equal; compared under the reference's white). The systematic part
// (bands, bounces, mode, renderer): to first order ΔE00² is a quadratic form of the colour difference, so per pixel
// (ΔE1² + ΔE2² − ΔE12²) / 2 — the two renders against the reference and against each other — estimates |s|² plus
// the reference's noise² without the renders' own noise; the reference's noise is the tracer base setting's scaled by
// √(base samples / reference samples). The mean over pixels gives the systematic rms, with an interval of ±2
// standard errors. The error that matters
// for a histogram: whether every object's class stays the reference's, how far (degrees) its principal direction
// turns, and how far the illuminant estimate turns and whether its method stays the same.
//
// Cost: the render's wall and CPU seconds (the tracer's threads, or Blender's processes) and, for Cycles, its
// renders (band groups + the object-id render). The Pareto front over (CPU seconds, mean ΔE00) marks the
// settings no other setting beats on both.

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "core/json_input.h"
#include "core/scene.h"
#include "series/runner.h"

namespace ct::study {

struct StudyOptions {
  std::optional<int> width, height;  // image size (default: the scene's)
  std::vector<int> uniform_bands;    // uniform band counts over the scene's band range
  std::vector<double> fitted_targets;  // `plan` targets (mean ΔE00) whose fitted band plans are tried
  std::vector<int> samples;          // paths (Cycles: samples) per pixel
  std::vector<int> bounces;          // bounce limits
  std::vector<std::string> modes;    // spectral modes besides the scene's ("bands", "continuous"; tracer only)
  std::vector<series::Renderer> renderers = {series::Renderer::Tracer};
  bool planned = true;          // a setting with every knob from `plan` at target 1
  // > 0: for Cycles also the planned setting guided (docs/plan.md, "Guided band groups"): its group of most samples
  // guides the others, rendered at this fraction of its samples with adaptive sampling up to them.
  double guided_fraction = 0;
  int reference_samples = 0;    // 0: 4 × the most samples of any setting
  double reference_band_nm = 5;  // the reference's uniform band width
  std::string camera = "cie1931";  // the observer of the ΔE00
  std::uint64_t seed = 1;
  int threads = 0;
  bool progress = true;
  // What the Cycles renderer needs (series::check_renderer fills blender).
  std::filesystem::path executable, blender, batch_script;
};

// One setting: the base with one knob changed.
struct Setting {
  std::string name;   // unique, also the series variant's name: "tracer-bands-6", "cycles-base"
  std::string knob;   // base, bands, fitted, samples, bounces, mode, renderer, planned, guided, reference
  std::string value;  // the knob's value as a person reads it: "6 uniform", "fitted for 1", "64", "continuous"
  series::Renderer renderer = series::Renderer::Tracer;
  Bands bands;
  int samples = 0, max_bounces = 0;
  std::vector<int> cycles_samples;  // Cycles, planned: each band group's samples (then `samples` is the most of them)
  std::vector<std::size_t> cycles_guided_groups;  // Cycles, guided: the groups reconstructed from the others
  double cycles_guided_threshold = 0;             // and their adaptive sampling's noise threshold
  std::string mode = "bands";
};

struct ObjectFinding {
  std::string object;
  std::string cls, reference_cls;  // "absent" when not in view
  bool same = false;
  std::optional<double> direction_deg;  // angle between the principal directions (sign-free), when both have one
  bool stable = false;  // the two seeds' renders give this object the same class
};

struct SettingResult {
  Setting setting;
  bool ok = false;
  std::string error;
  double wall_s = 0, cpu_s = 0;  // of the first seed's render
  int renders = 1;               // Cycles: band groups + 1 (object ids); tracer: 1
  // ΔE00 against the reference.
  double mean = 0, p95 = 0, rms = 0;
  double noise_rms = 0, noise_rms_se = 0;  // the Monte Carlo part of one render, and its standard error
  double reference_noise_rms = 0;
  // The systematic part: its rms, with an interval of ± 2 standard errors of the per-pixel estimate (at small
  // images and few samples the noise hides a small systematic error; the interval says how much could hide).
  double systematic_rms = 0, systematic_rms_lo = 0, systematic_rms_hi = 0;
  double systematic_sq = 0, systematic_sq_se = 0;  // mean over pixels of |s|² + |n_r|², and its standard error
  bool systematic_measurable = true;  // false: the estimate fell below zero beyond its uncertainty (noise too large)
  // Structure against the reference's.
  std::vector<ObjectFinding> objects;
  int classes_kept = 0;
  std::optional<double> max_direction_deg;
  std::optional<double> illuminant_deg;
  std::string illuminant_method, reference_illuminant_method;
  bool pareto = false;
};

struct StudyResult {
  std::string scene;
  Setting reference;
  double reference_wall_s = 0, reference_cpu_s = 0;
  std::vector<SettingResult> settings;
  std::vector<std::string> notes;
  double seconds = 0;
};

// The settings the options ask for, base first, each once (a value equal to the base's is not repeated).
std::vector<Setting> make_settings(const Scene& scene, const StudyOptions& options);

// Runs the study into `dir` (created; its parent must exist): runs/ holds the series variants (renders, camera
// images, analyses), plans/ the band plans; then study.json, error_vs_cost.png, p95_vs_cost.png, systematic_vs_cost.png,
// structure_vs_cost.png and index.html.
StudyResult run_study(const std::filesystem::path& scene_file, const std::filesystem::path& dir,
                      const StudyOptions& options);

// Marks `pareto` on every successful setting that no other beats in both CPU seconds and mean ΔE00 (at least as
// good in both and better in one).
void mark_pareto_front(std::vector<SettingResult>& settings);

// study.json (format chromatrace-study/1).
Json result_json(const StudyResult& result);

}  // namespace ct::study
