// SPDX-License-Identifier: Apache-2.0
#pragma once
// An experiment series end to end (docs/series.md): for each variant, the resolved scene is rendered (by the
// reference tracer or by Cycles through the Blender add-on's headless batch), seen by the variant's camera,
// analysed, and its classes compared with the variant's `expect`.
//
// Output directory layout:
//   renders/<key>.exr       one spectral render per distinct (scene, renderer, settings): the cache
//   renders/<key>.json      what the key was made of, for a person
//   <variant>/scene.json    the resolved scene (paths relative to it): `chromatrace render` takes it
//   <variant>/sensor.json   the variant's sensor settings (chromatrace-sensor/1 patch)
//   <variant>/camera.exr    the simulated camera image with its layers
//   <variant>/camera.png    the same as a person would see it
//   <variant>/analysis/     `chromatrace analyze` of camera.exr (analysis.json, report.html, plots)
//   series.json             per variant: files, timings, found vs expected (written last)
//
// A render is reused when renders/<key>.exr exists: the key hashes everything the render depends on (the
// resolved scene with the bytes of every file it names, the renderer, resolution, samples, seed, components),
// so a killed run resumes where it stopped and a changed scene or option renders anew.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <utility>
#include <string>
#include <vector>

#include "core/json_input.h"
#include "core/series_format.h"

namespace ct::series {

enum class Renderer { Tracer, Cycles };
std::string_view renderer_name(Renderer renderer);  // "tracer", "cycles"

struct RunOptions {
  Renderer renderer = Renderer::Tracer;
  std::vector<std::string> variants;  // empty: every variant
  std::optional<int> width, height;   // override the scenes' camera resolution
  std::optional<int> spp;
  std::optional<std::uint64_t> seed;
  std::optional<int> max_bounces;      // override the scenes' render.max_bounces
  std::optional<Bands> bands;          // override the scenes' band plan: a chromatrace-bands/1 file's bands
  std::filesystem::path bands_file;    // that file (handed to the Blender batch as --bands-file), absolute
  // Cycles: the band file gives each band group of three its samples (its cycles_samples), which the batch renders
  // instead of `spp`; part of the render's cache key.
  std::vector<int> cycles_samples;
  // And the groups it guides from the others, with their adaptive sampling's threshold (core/band_plan.h); part of
  // the cache key too.
  std::vector<std::size_t> cycles_guided_groups;
  double cycles_guided_threshold = 0;
  std::string components = "paths,lights";
  int threads = 0;
  bool progress = true;
  std::filesystem::path executable;  // the running chromatrace, handed to the Blender batch
  std::filesystem::path blender;     // the Blender executable (Cycles); resolved by check_renderer
  std::filesystem::path batch_script;  // blender_addon/batch.py (Cycles)
  bool renders_only = false;  // only fill the render cache: no camera, analysis or series.json
};

// The distinct renders the selected variants need, in series order: {render key, the first variant that
// needs it}. renders/<key>.exr is where run_series keeps each.
std::vector<std::pair<std::string, std::string>> planned_renders(const Series& series, const RunOptions& options);

// Finds what the renderer needs (Blender and the add-on's batch.py for Cycles) and fills it into `options`;
// InputError naming what is missing.
void check_renderer(RunOptions& options);

// One object (or the whole image) judged against one expectation.
struct Finding {
  std::string object;  // an object's name, or "image"
  int region = -1;     // index into the analysis' regions; −1 when the object is not in view
  std::string found;   // the analyzer's class; "absent" when not in view
  bool ok = false;
  std::string explanation;  // which light paths built it, in one line; empty without component layers
  std::vector<std::string> bent_by;  // what bends it (analyzer/bend_cause.h); empty when it is not bent
  std::vector<std::string> thickened_by;  // what spreads it off the direct light's structure (analyzer/explain.h)
};

struct ExpectationResult {
  Expectation expected;
  std::vector<Finding> findings;  // one per object it covers
  bool ok = false;                // every finding ok
};

struct VariantResult {
  std::string name;
  std::string description;
  std::vector<std::string> figure;
  bool ok = false;      // every step ran
  std::string error;    // the failure, when a step failed
  std::string render_key;
  bool render_reused = false;  // the render was in the cache (from an earlier run or an earlier variant)
  double render_s = 0, sensor_s = 0, analyze_s = 0;
  double render_cpu_s = 0;  // CPU seconds of the render: this process's threads, or Blender's (0 when reused)
  std::vector<std::string> render_notes;  // what the renderer rendered otherwise than the scene asks (GGX masking)
  std::vector<ExpectationResult> expectations;
  int width = 0, height = 0;
};

struct SeriesResult {
  std::string name, description, source;
  RunOptions options;
  std::vector<VariantResult> variants;
  double seconds = 0;
};

// The variants `names` asks for, in series order (all when empty); InputError naming an unknown one.
std::vector<const SeriesVariant*> select_variants(const Series& series, const std::vector<std::string>& names);

// Runs the selected variants into `dir` (created; its parent must exist) and writes series.json. A failed
// step fails its variant, not the series: the others still run.
SeriesResult run_series(const Series& series, const std::filesystem::path& dir, const RunOptions& options);

// series.json (format chromatrace-series-result/1).
Json result_json(const SeriesResult& result);

// The directory of variant files inside the output directory.
std::filesystem::path variant_dir(const std::filesystem::path& dir, const std::string& variant);

}  // namespace ct::series
