// SPDX-License-Identifier: Apache-2.0
#include "series/runner.h"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>

#include <fmt/core.h>
#include <fmt/format.h>

#include "analyzer/analysis.h"
#include "analyzer/output.h"
#include "core/band_plan.h"
#include "core/error.h"
#include "core/file_io.h"
#include "core/json_input.h"
#include "core/parallel.h"
#include "core/process.h"
#include "core/spectral_exr.h"
#include "reference_tracer/render.h"
#include "sensor_sim/config.h"
#include "sensor_sim/pipeline.h"
#include "series/blender_batch.h"
#include "series/preview.h"
#include "series/render_cache.h"

namespace ct::series {
namespace fs = std::filesystem;

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

// CPU seconds (user + system) of this process and of its waited-for children so far.
double cpu_seconds() {
  double total = 0;
  for (const int who : {RUSAGE_SELF, RUSAGE_CHILDREN}) {
    rusage usage{};
    getrusage(who, &usage);
    for (const timeval& t : {usage.ru_utime, usage.ru_stime}) total += static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_usec);
  }
  return total;
}

// The run's options with the component families the variant asks for besides the run's (a variant whose analysis
// needs the bounces, say).
RunOptions for_variant(const SeriesVariant& variant, const RunOptions& options) {
  RunOptions o = options;
  if (!variant.components.empty())
    o.components = options.components == "none" ? variant.components : options.components + "," + variant.components;
  return o;
}

// ---- Renderers ------------------------------------------------------------------------------------------

void render_with_tracer(Scene scene, const fs::path& out, const RunOptions& options) {
  if (options.width) scene.camera.width = *options.width;
  if (options.height) scene.camera.height = *options.height;
  rt::RenderOptions render;
  render.samples = options.spp;
  render.seed = options.seed;
  render.max_bounces = options.max_bounces;
  render.bands = options.bands;
  render.components = rt::ComponentSelection::parse(options.components);
  render.threads = options.threads;
  render.progress = options.progress;
  rt::write_render(out, scene, rt::render(scene, render));
}

// Renders with Cycles through the add-on's batch. A series' scenes are written for the tracer, whose GGX masking
// defaults to the separable form that Cycles has only up to Blender 3.x: each GGX material is rendered with the
// masking of the Cycles that runs (--ggx-masking cycles); the batch names each one it changed, and the render's
// header carries the scene as rendered (masking_notes).
void render_with_cycles(const Scene& scene, const fs::path& scene_file, const fs::path& out, const fs::path& dir,
                        const RunOptions& options) {
  BlenderBatchCommand batch(options.blender, options.batch_script);
  batch.option("--scene", scene_file.string())
      .option("--ggx-masking", "cycles")
      .option("--out", out.string())
      .option("--seed", std::to_string(options.seed.value_or(scene.render.seed)))
      .option("--components", options.components)
      .option("--cache-dir", (dir / "renders" / "cycles-cache").string());
  if (options.width || options.height)
    batch.option("--resolution", fmt::format("{}x{}", options.width.value_or(scene.camera.width),
                                             options.height.value_or(scene.camera.height)));
  if (options.cycles_samples.empty())  // else the band file gives each group its own
    batch.option("--samples", std::to_string(options.spp.value_or(scene.render.samples)));
  batch.option("--max-bounces", options.max_bounces);
  if (options.bands) batch.option("--bands-file", options.bands_file.string());
  if (!options.progress) batch.flag("--quiet");
  const fs::path log = dir / "renders" / "blender.log";
  const int status = run_program(batch.argv(), BlenderBatchCommand::environment(options.executable), log).status;
  if (status != 0 || !fs::exists(out))
    throw std::runtime_error(fmt::format("Blender's batch exited with status {} (its output: {})", status, log.string()));
}

// The GGX materials a Cycles render has with another masking than the scene asks: the scene as rendered is in the
// render's header (chromatrace.scene), fresh or from the cache.
std::vector<std::string> masking_notes(const Scene& scene, const fs::path& render) {
  const SpectralExrInfo info = SpectralExrReader(render).info();
  const auto it = info.metadata.find("chromatrace.scene");
  if (it == info.metadata.end()) return {};
  const Json rendered = Json::parse(it->second, nullptr, false);
  if (!rendered.is_object() || !rendered.contains("materials") || !scene.json.contains("materials")) return {};
  std::vector<std::string> notes;
  for (const auto& [name, material] : scene.json["materials"].items()) {
    if (!material.is_object() || material.value("type", "") != "dichromatic" || material.value("lobe", "ggx") != "ggx") continue;
    const std::string asked = material.value("masking", "separable");
    const auto other = rendered["materials"].find(name);
    if (other == rendered["materials"].end() || !other->is_object()) continue;
    const std::string used = other->value("masking", "separable");
    if (used != asked)
      notes.push_back(fmt::format("materials.{}.masking: \"{}\" rendered with the {} masking of the Cycles that rendered it",
                                  name, asked, used));
  }
  return notes;
}

// ---- Expectations ---------------------------------------------------------------------------------------

// Which light paths built a region's cluster, in one line: the path types that carry most of its energy,
// and how much of its spread off the direct light's structure the indirect light explains.
std::string explain(const std::optional<analyzer::Explanation>& explanation, const analyzer::ClusterShape& shape) {
  if (!explanation) return "";
  std::vector<std::string> parts;
  for (const analyzer::FamilyShares& family : explanation->families) {
    if (family.family != ComponentFamily::PathType && family.family != ComponentFamily::LightGroup) continue;
    std::vector<analyzer::ComponentShare> shares = family.components;
    std::sort(shares.begin(), shares.end(), [](const auto& a, const auto& b) { return a.energy_share > b.energy_share; });
    std::vector<std::string> named;
    for (const analyzer::ComponentShare& s : shares)
      if (s.energy_share >= 0.02 && named.size() < 3) named.push_back(fmt::format("{} {:.0f} %", s.name, 100 * s.energy_share));
    if (family.family == ComponentFamily::LightGroup && shares.size() < 2) continue;  // one light: nothing to say
    if (!named.empty()) parts.push_back(fmt::format("{}", fmt::join(named, ", ")));
  }
  if (const auto& off = explanation->off_structure;
      off && off->rms_total > 0 && explanation->indirect_share.value_or(0) >= 0.01)
    parts.push_back(fmt::format("indirect light makes {:.0f} % of the spread off the {} ({:.1f} × the noise across it)",
                                100 * off->indirect_share, off->structure,
                                off->rms_total / std::max(1e-300, analyzer::noise_across(*off, shape))));
  return fmt::format("{}", fmt::join(parts, "; "));
}

std::vector<ExpectationResult> judge(const SeriesVariant& variant, const analyzer::ImageAnalysis& analysis) {
  // Object id → region index (label regions carry the id as their label).
  std::map<std::int64_t, int> region_of_id;
  for (std::size_t r = 0; r < analysis.regions.size(); ++r)
    if (analysis.regions[r].source == "labels") region_of_id[analysis.regions[r].label] = static_cast<int>(r);

  std::vector<ExpectationResult> results;
  for (const Expectation& e : variant.expect) {
    ExpectationResult result{e, {}, true};
    auto add = [&](const std::string& object, int region) {
      Finding f{object, region, "absent", false, "", {}, {}};
      if (region >= 0) {
        const auto& shape = analysis.results[static_cast<std::size_t>(region)].shape;
        f.found = std::string(analyzer::class_name(shape.shape));
        if (const auto& bend = analysis.results[static_cast<std::size_t>(region)].bend) f.bent_by = bend->causes;
        const auto& explanation = static_cast<std::size_t>(region) < analysis.explanations.size()
                                      ? analysis.explanations[static_cast<std::size_t>(region)]
                                      : std::optional<analyzer::Explanation>();
        if (explanation && analyzer::thickened_by_interreflection(*explanation, shape)) f.thickened_by = {"interreflection"};
        auto named = [](const std::vector<std::string>& causes, const std::string& cause) {
          return cause.empty() || std::find(causes.begin(), causes.end(), cause) != causes.end();
        };
        f.ok = std::find(e.any_of.begin(), e.any_of.end(), f.found) != e.any_of.end() && named(f.bent_by, e.bent_by) &&
               named(f.thickened_by, e.thickened_by);
        if (static_cast<std::size_t>(region) < analysis.explanations.size())
          f.explanation = explain(analysis.explanations[static_cast<std::size_t>(region)], shape);
        const analyzer::RegionAnalysis& result = analysis.results[static_cast<std::size_t>(region)];
        if (result.bend) f.explanation += (f.explanation.empty() ? "" : "; ") + result.bend->summary;
        if (const auto& g = result.declared_gamma; g && result.shape.gamma)
          f.explanation += fmt::format("{}γ = {:.4f} ± {:.2g} flattens its {} again (declared {:.3g}: {})", f.explanation.empty() ? "" : "; ",
                                       g->fitted, g->se, result.shape.gamma->flat == analyzer::GammaFlat::Plane ? "plane" : "line",
                                       g->declared_gamma,
                                       g->agree ? fmt::format("agrees, {:.1f} standard errors off", g->difference_in_se)
                                                : fmt::format("differs by {:.1f} standard errors", g->difference_in_se));
      }
      result.ok = result.ok && f.ok;
      result.findings.push_back(std::move(f));
    };
    if (e.objects.empty()) add("image", 0);
    for (const std::string& name : e.objects) {
      const auto object = std::find_if(variant.scene.objects.begin(), variant.scene.objects.end(),
                                       [&](const Object& o) { return o.name == name; });
      const auto region = region_of_id.find(object->id);
      add(name, region == region_of_id.end() ? -1 : region->second);
    }
    results.push_back(std::move(result));
  }
  return results;
}

// ---- One variant ----------------------------------------------------------------------------------------

class Stage {
 public:
  Stage(const RunOptions& options, std::size_t k, std::size_t n, const std::string& variant)
      : options_(options), prefix_(fmt::format("[{}/{}] {}", k, n, variant)) {}
  void operator()(std::string_view what) const {
    if (options_.progress) fmt::print(stderr, "{}: {}\n", prefix_, what);
  }

 private:
  const RunOptions& options_;
  std::string prefix_;
};

VariantResult run_variant(const Series& series, const SeriesVariant& variant, const fs::path& dir,
                          const RunOptions& run_options, const Stage& stage) {
  const RunOptions options = for_variant(variant, run_options);
  VariantResult result;
  result.name = variant.name;
  result.description = variant.description;
  result.figure = variant.figure;
  const fs::path out = variant_dir(dir, variant.name);
  fs::create_directories(out);
  const fs::path series_dir = fs::path(series.source).parent_path();

  const fs::path scene_file = out / "scene.json";
  write_file_atomically(scene_file, rebase_scene_paths(variant.scene.json, {}, fs::absolute(out)).dump(2, ' ', false, kReplaceInvalidUtf8) + "\n");
  const sensor::ConfigPatch sensor_patch = sensor::config_patch(
      variant.sensor, fmt::format("{}: variant \"{}\" sensor", series.source, variant.name), series_dir);
  write_file_atomically(out / "sensor.json", sensor_patch.patch.dump(2, ' ', false, kReplaceInvalidUtf8) + "\n");

  // Render, or take it from the cache.
  const Json inputs = render_inputs(variant.scene, options);
  result.render_key = render_key(inputs);
  const fs::path render = dir / "renders" / (result.render_key + ".exr");
  result.render_reused = fs::exists(render);
  if (result.render_reused) {
    stage(fmt::format("render {} from the cache", render.filename().string()));
  } else {
    stage(fmt::format("rendering with {}", renderer_name(options.renderer)));
    const auto start = Clock::now();
    const double start_cpu = cpu_seconds();
    write_file_atomically(dir / "renders" / (result.render_key + ".json"), inputs.dump(2, ' ', false, kReplaceInvalidUtf8) + "\n");
    if (options.renderer == Renderer::Tracer)
      render_with_tracer(variant.scene, render, options);
    else
      render_with_cycles(variant.scene, fs::absolute(scene_file), fs::absolute(render), fs::absolute(dir), options);
    result.render_s = seconds_since(start);
    result.render_cpu_s = cpu_seconds() - start_cpu;
  }

  if (options.renderer == Renderer::Cycles) result.render_notes = masking_notes(variant.scene, render);

  if (options.renders_only) {
    result.ok = true;
    return result;
  }

  stage("camera");
  auto start = Clock::now();
  const sensor::SensorConfig config = sensor::resolve_config({sensor_patch});
  sensor::RunOptions sensor_options;
  sensor_options.threads = options.threads;
  sensor::simulate_sensor(render, out / "camera.exr", config, sensor_options);
  result.sensor_s = seconds_since(start);

  stage("analysis");
  start = Clock::now();
  const analyzer::AnalysisImage input = analyzer::read_analysis_image(out / "camera.exr");
  const analyzer::RgbImage& layer = analyzer::select_layer(input, "final");
  analyzer::AnalyzeOptions analyze_options;
  analyze_options.threads = options.threads;
  const analyzer::ImageAnalysis analysis = analyzer::analyse_image(
      input, "final", analyzer::select_regions(input, layer, {}), analyze_options, std::nullopt, false);
  analyzer::write_analysis(out / "analysis", input, analysis, {});
  write_preview_png(out / "camera.png", input);
  result.analyze_s = seconds_since(start);
  result.width = input.image.width;
  result.height = input.image.height;

  result.expectations = judge(variant, analysis);
  result.ok = true;
  return result;
}

Json finding_json(const Finding& f) {
  Json j = {{"object", f.object}, {"found", f.found}, {"ok", f.ok}};
  if (f.region >= 0) j["region"] = f.region;
  if (!f.explanation.empty()) j["explanation"] = f.explanation;
  if (!f.bent_by.empty()) j["bent_by"] = f.bent_by;
  if (!f.thickened_by.empty()) j["thickened_by"] = f.thickened_by;
  return j;
}

}  // namespace

std::string_view renderer_name(Renderer renderer) { return renderer == Renderer::Tracer ? "tracer" : "cycles"; }

fs::path variant_dir(const fs::path& dir, const std::string& variant) {
  check_file_name(variant, "variant name");  // load_series refuses such names; never a path outside `dir`
  return dir / variant;
}

void check_renderer(RunOptions& options) {
  if (options.renderer != Renderer::Cycles) return;
  if (options.blender.empty()) {
    const char* env = std::getenv("CHROMATRACE_BLENDER");
    std::string found;
    if (env && *env) {
      found = env;
    } else if (const char* path = std::getenv("PATH")) {
      for (std::string_view rest = path; found.empty() && !rest.empty();) {
        const std::size_t colon = std::min(rest.find(':'), rest.size());
        const fs::path candidate = fs::path(rest.substr(0, colon)) / "blender";
        if (colon > 0 && access(candidate.c_str(), X_OK) == 0) found = candidate.string();
        rest.remove_prefix(std::min(colon + 1, rest.size()));
      }
    }
    if (found.empty())
      throw InputError("--renderer cycles: Blender is not installed (no blender on PATH; set CHROMATRACE_BLENDER to its "
                       "executable)");
    options.blender = found;
  }
  if (access(options.blender.c_str(), X_OK) != 0)
    throw InputError(fmt::format("--renderer cycles: {} is not an executable (CHROMATRACE_BLENDER)", options.blender.string()));
  if (options.batch_script.empty() || !fs::is_regular_file(options.batch_script))
    throw InputError(fmt::format("--renderer cycles: the Blender add-on's batch.py is not at {} (set CHROMATRACE_BLENDER_ADDON "
                                 "to the folder holding batch.py)",
                                 options.batch_script.string()));
}

std::vector<const SeriesVariant*> select_variants(const Series& series, const std::vector<std::string>& names) {
  std::vector<const SeriesVariant*> selected;
  for (const std::string& name : names) series.variant(name, "--variant");
  for (const SeriesVariant& v : series.variants)
    if (names.empty() || std::find(names.begin(), names.end(), v.name) != names.end()) selected.push_back(&v);
  return selected;
}

SeriesResult run_series(const Series& series, const fs::path& dir, const RunOptions& options) {
  const auto start = Clock::now();
  const std::vector<const SeriesVariant*> selected = select_variants(series, options.variants);
  // Every variant's sensor settings are checked before any work.
  const fs::path series_dir = fs::path(series.source).parent_path();
  for (const SeriesVariant* v : selected)
    sensor::resolve_config({sensor::config_patch(v->sensor, fmt::format("{}: variant \"{}\" sensor", series.source, v->name),
                                                 series_dir)});
  fs::create_directories(dir / "renders");
  set_exr_threads(thread_count(options.threads));

  SeriesResult result{series.name, series.description, series.source, options, {}, 0};
  for (std::size_t k = 0; k < selected.size(); ++k) {
    const SeriesVariant& variant = *selected[k];
    const Stage stage(options, k + 1, selected.size(), variant.name);
    try {
      result.variants.push_back(run_variant(series, variant, dir, options, stage));
    } catch (const std::exception& e) {
      VariantResult failed;
      failed.name = variant.name;
      failed.description = variant.description;
      failed.figure = variant.figure;
      failed.error = e.what();
      stage(fmt::format("failed: {}", failed.error));
      result.variants.push_back(std::move(failed));
    }
  }
  result.seconds = seconds_since(start);
  if (!options.renders_only) write_file_atomically(dir / "series.json", result_json(result).dump(2, ' ', false, kReplaceInvalidUtf8) + "\n");
  return result;
}

std::vector<std::pair<std::string, std::string>> planned_renders(const Series& series, const RunOptions& options) {
  std::vector<std::pair<std::string, std::string>> renders;
  for (const SeriesVariant* v : select_variants(series, options.variants)) {
    const std::string key = render_key(render_inputs(v->scene, for_variant(*v, options)));
    if (std::none_of(renders.begin(), renders.end(), [&](const auto& r) { return r.first == key; }))
      renders.emplace_back(key, v->name);
  }
  return renders;
}

Json result_json(const SeriesResult& result) {
  Json variants = Json::array();
  for (const VariantResult& v : result.variants) {
    const std::string folder = v.name;
    Json expect = Json::array();
    int met = 0;
    for (const ExpectationResult& e : v.expectations) {
      Json findings = Json::array();
      for (const Finding& f : e.findings) findings.push_back(finding_json(f));
      Json row = {{"target", e.expected.target}, {"any_of", e.expected.any_of}, {"ok", e.ok}, {"objects", findings}};
      if (!e.expected.bent_by.empty()) row["bent_by"] = e.expected.bent_by;
      if (!e.expected.thickened_by.empty()) row["thickened_by"] = e.expected.thickened_by;
      if (!e.expected.paper.empty()) row["paper"] = e.expected.paper;
      expect.push_back(std::move(row));
      met += e.ok ? 1 : 0;
    }
    Json j = {{"name", v.name}, {"description", v.description}, {"figure", v.figure}, {"ok", v.ok}};
    if (!v.ok) {
      j["error"] = v.error;
    } else {
      j["size"] = {v.width, v.height};
      j["render"] = {{"file", "renders/" + v.render_key + ".exr"}, {"key", v.render_key}, {"reused", v.render_reused},
                     {"seconds", v.render_s}, {"cpu_seconds", v.render_cpu_s}, {"notes", v.render_notes}};
      j["scene"] = folder + "/scene.json";
      j["sensor"] = {{"settings", folder + "/sensor.json"}, {"file", folder + "/camera.exr"}, {"seconds", v.sensor_s}};
      j["preview"] = folder + "/camera.png";
      j["analysis"] = {{"file", folder + "/analysis/analysis.json"},
                       {"report", folder + "/analysis/report.html"},
                       {"seconds", v.analyze_s}};
      j["expect"] = expect;
      j["expectations_met"] = met;
      j["expectations"] = v.expectations.size();
    }
    variants.push_back(std::move(j));
  }
  const RunOptions& o = result.options;
  Json options = {{"renderer", renderer_name(o.renderer)}, {"components", o.components}};
  if (o.width) options["resolution"] = {*o.width, *o.height};
  if (o.spp) options["spp"] = *o.spp;
  if (o.seed) options["seed"] = *o.seed;
  return {{"format", "chromatrace-series-result/1"},
          {"series", result.name},
          {"description", result.description},
          {"source", result.source},
          {"options", options},
          {"seconds", result.seconds},
          {"variants", variants}};
}

}  // namespace ct::series
