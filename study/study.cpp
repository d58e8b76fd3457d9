// SPDX-License-Identifier: Apache-2.0
#include "study/study.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <set>

#include <fmt/core.h>
#include <fmt/format.h>
#include <fmt/ranges.h>

#include "core/band_plan.h"
#include "core/error.h"
#include "core/colour.h"
#include "core/file_io.h"
#include "core/json_input.h"
#include "plan/plan.h"
#include "study/charts.h"
#include "study/page.h"

namespace ct::study {
namespace {
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

constexpr const char* kComponents = "paths";  // every setting renders the same layers, so costs compare
// The guided groups' adaptive sampling threshold: Cycles' own default Noise Threshold (docs/plan.md).
constexpr double kGuidedThreshold = 0.01;

double sq(double x) { return x * x; }
double mean_of(const std::vector<double>& v) {
  double sum = 0;
  for (double x : v) sum += x;
  return v.empty() ? 0.0 : sum / static_cast<double>(v.size());
}
double variance_of(const std::vector<double>& v, double mean) {
  double sum = 0;
  for (double x : v) sum += sq(x - mean);
  return v.size() > 1 ? sum / static_cast<double>(v.size() - 1) : 0.0;
}

std::string renderer_label(series::Renderer r) { return std::string(series::renderer_name(r)); }

// Uniform bands of about `width` nm (a whole number of them) over [lo, hi].
Bands uniform_count(double lo, double hi, int count) {
  std::vector<double> edges(static_cast<std::size_t>(count) + 1);
  for (int i = 0; i <= count; ++i) edges[static_cast<std::size_t>(i)] = lo + (hi - lo) * i / count;
  edges.back() = hi;
  return Bands::from_edges(std::move(edges));
}

Bands reference_bands(const Bands& scene, double width_nm) {
  const double lo = scene.min_wavelength(), hi = scene.max_wavelength();
  return uniform_count(lo, hi, std::max(1, static_cast<int>(std::lround((hi - lo) / width_nm))));
}

std::string band_value(const Bands& bands) {
  bool uniform = true;
  for (std::size_t b = 1; b < bands.size(); ++b) uniform = uniform && std::abs(bands.width(b) - bands.width(0)) < 1e-6;
  return uniform ? fmt::format("{} x {:g} nm", bands.size(), bands.width(0)) : fmt::format("{} fitted", bands.size());
}

int cycles_renders(const Bands& bands) { return static_cast<int>((bands.size() + 2) / 3) + 1; }

bool same_settings(const Setting& a, const Setting& b) {
  return a.renderer == b.renderer && a.bands == b.bands && a.samples == b.samples && a.max_bounces == b.max_bounces &&
         a.mode == b.mode && a.cycles_samples == b.cycles_samples && a.cycles_guided_groups == b.cycles_guided_groups &&
         a.cycles_guided_threshold == b.cycles_guided_threshold;
}


// ---- Analyses compared ------------------------------------------------------------------------------------

struct Region {
  std::string cls;
  std::optional<Vec3d> direction;
};

struct AnalysisSummary {
  std::vector<std::pair<std::string, Region>> objects;  // in the analysis' order
  std::optional<Vec3d> illuminant;
  std::string illuminant_method;
};

std::optional<Vec3d> unit_vector(const Json& v) {
  if (!v.is_array() || v.size() != 3) return std::nullopt;
  Vec3d out{};
  double n = 0;
  for (int c = 0; c < 3; ++c) {
    if (!v[c].is_number()) return std::nullopt;
    out[c] = v[c].get<double>();
    n += out[c] * out[c];
  }
  if (!(n > 0)) return std::nullopt;
  for (double& x : out) x /= std::sqrt(n);
  return out;
}

AnalysisSummary read_analysis(const fs::path& file) {
  std::ifstream in(file);
  if (!in) throw std::runtime_error(fmt::format("{}: cannot read", file.string()));
  const Json doc = Json::parse(in);
  AnalysisSummary out;
  for (const Json& region : doc.at("regions")) {
    if (region.value("source", "") != "labels") continue;
    Region r;
    const Json& shape = region.at("shape");
    r.cls = shape.value("class", "");
    if (shape.contains("axes") && shape["axes"].is_array() && !shape["axes"].empty()) r.direction = unit_vector(shape["axes"][0]);
    out.objects.emplace_back(region.value("name", ""), r);
  }
  const Json& estimate = doc.at("illuminant").at("estimate");
  if (estimate.is_object()) {
    out.illuminant = unit_vector(estimate.value("rgb", Json()));
    out.illuminant_method = estimate.value("method", "");
  }
  return out;
}

double angle_deg(const Vec3d& a, const Vec3d& b, bool sign_free) {
  double d = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  if (sign_free) d = std::abs(d);
  return std::acos(std::clamp(d, -1.0, 1.0)) * 180.0 / M_PI;
}

void compare_structure(SettingResult& r, const AnalysisSummary& test, const AnalysisSummary& twin,
                       const AnalysisSummary& reference) {
  auto find = [](const AnalysisSummary& a, const std::string& name) -> const Region* {
    for (const auto& [n, region] : a.objects)
      if (n == name) return &region;
    return nullptr;
  };
  r.objects.clear();
  r.classes_kept = 0;
  r.max_direction_deg.reset();
  for (const auto& [name, ref] : reference.objects) {
    ObjectFinding f;
    f.object = name;
    f.reference_cls = ref.cls;
    const Region* mine = find(test, name);
    const Region* other = find(twin, name);
    f.cls = mine ? mine->cls : "absent";
    f.same = f.cls == f.reference_cls;
    f.stable = other && mine && other->cls == mine->cls;
    if (mine && mine->direction && ref.direction) {
      f.direction_deg = angle_deg(*mine->direction, *ref.direction, true);
      r.max_direction_deg = std::max(r.max_direction_deg.value_or(0.0), *f.direction_deg);
    }
    r.classes_kept += f.same ? 1 : 0;
    r.objects.push_back(f);
  }
  r.illuminant_method = test.illuminant_method;
  r.reference_illuminant_method = reference.illuminant_method;
  if (test.illuminant && reference.illuminant) r.illuminant_deg = angle_deg(*test.illuminant, *reference.illuminant, false);
}

// ---- The series the settings run as -----------------------------------------------------------------------

Json series_document(const fs::path& scene_file, const std::vector<Setting>& settings, const std::string& scene_name) {
  Json variants = Json::array();
  for (const Setting& s : settings)
    for (int twin = 0; twin < 2; ++twin) {
      if (twin == 1 && s.knob == "reference") continue;
      variants.push_back({{"name", twin == 0 ? s.name : s.name + "~seed2"},
                          {"description", fmt::format("{}: {} ({})", s.knob, s.value, renderer_label(s.renderer))},
                          {"patch", {{"render", {{"spectral_mode", s.mode}}}}},
                          {"sensor", {{"noise", {{"enabled", false}}}}}});
    }
  return {{"format", "chromatrace-series/1"},
          {"name", "study of " + scene_name},
          {"description", "The settings of chromatrace study, each a variant of the scene; bands, samples and bounce "
                          "limits are given as options of each run."},
          {"base", fs::absolute(scene_file).string()},
          {"variants", variants}};
}

}  // namespace

std::vector<Setting> make_settings(const Scene& scene, const StudyOptions& options) {
  std::vector<Setting> out;
  auto add = [&](Setting s) {
    for (const Setting& o : out)
      if (same_settings(o, s)) return;
    out.push_back(std::move(s));
  };
  const double lo = scene.render.bands.min_wavelength(), hi = scene.render.bands.max_wavelength();
  for (const series::Renderer renderer : options.renderers) {
    const std::string r = renderer_label(renderer);
    Setting base;
    base.renderer = renderer;
    base.bands = scene.render.bands;
    base.samples = scene.render.samples;
    base.max_bounces = scene.render.max_bounces;
    base.mode = renderer == series::Renderer::Tracer && scene.render.spectral_mode == SpectralMode::Continuous ? "continuous" : "bands";
    base.knob = "base";
    base.value = "the scene's settings";
    base.name = r + "-base";
    add(base);
    auto vary = [&](const std::string& knob, const std::string& value, const std::string& tag, auto change) {
      Setting s = base;
      s.knob = knob;
      s.value = value;
      s.name = fmt::format("{}-{}-{}", r, knob, tag);
      change(s);
      add(std::move(s));
    };
    for (int n : options.uniform_bands)
      vary("bands", fmt::format("{} uniform", n), std::to_string(n), [&](Setting& s) { s.bands = uniform_count(lo, hi, n); });
    for (double target : options.fitted_targets) {
      plan::PlanOptions po;
      po.target_de00 = target;
      po.camera = options.camera;
      po.renderer = renderer == series::Renderer::Cycles ? plan::Renderer::Cycles : plan::Renderer::Tracer;
      po.threads = options.threads;
      const plan::Plan p = plan::make_plan(scene, po);
      vary("fitted", fmt::format("{} fitted for {:g}", p.bands.size(), target), fmt::format("{:g}", target),
           [&](Setting& s) { s.bands = p.bands; });
    }
    for (int n : options.samples) vary("samples", std::to_string(n), std::to_string(n), [&](Setting& s) { s.samples = n; });
    for (int k : options.bounces)
      vary("bounces", std::to_string(k), std::to_string(k), [&](Setting& s) { s.max_bounces = k; });
    if (renderer == series::Renderer::Tracer)
      for (const std::string& m : options.modes) vary("mode", m, m, [&](Setting& s) { s.mode = m; });
    if (options.planned) {
      plan::PlanOptions po;
      po.camera = options.camera;
      po.renderer = renderer == series::Renderer::Cycles ? plan::Renderer::Cycles : plan::Renderer::Tracer;
      po.threads = options.threads;
      const plan::Plan p = plan::make_plan(scene, po);
      // Cycles: each band group with the samples the plan gives it, chosen with the bands (docs/plan.md).
      const bool groups = renderer == series::Renderer::Cycles && !p.cycles_samples.empty();
      vary("planned",
           groups ? fmt::format("{} bands, {} bounces, samples per band group {}", p.bands.size(), p.max_bounces,
                                fmt::join(p.cycles_samples, ", "))
                  : fmt::format("{} bands, {} bounces, {} samples", p.bands.size(), p.max_bounces, p.samples),
           "1", [&](Setting& s) {
             s.bands = p.bands;
             s.max_bounces = p.max_bounces;
             s.samples = groups ? *std::max_element(p.cycles_samples.begin(), p.cycles_samples.end()) : p.samples;
             if (groups) s.cycles_samples = p.cycles_samples;
           });
      // Guided: the plan's guide group (the least noisy relative to its signal on the pilots), else the group of
      // most samples, takes the most samples and guides the others, rendered at a fraction of them, with adaptive
      // sampling up to them where a pixel stays noisy (at Cycles' own default threshold, 0.01).
      if (groups && options.guided_fraction > 0) {
        const auto most_at = std::max_element(p.cycles_samples.begin(), p.cycles_samples.end());
        const auto guide = p.cycles_guide_group >= 0 ? static_cast<std::size_t>(p.cycles_guide_group)
                                                     : static_cast<std::size_t>(most_at - p.cycles_samples.begin());
        const int most = *most_at;
        const int few = std::max(1, static_cast<int>(std::ceil(most * options.guided_fraction)));
        std::vector<int> samples;
        std::vector<std::size_t> guided;
        for (std::size_t g = 0; g < p.cycles_samples.size(); ++g) {
          samples.push_back(g == guide ? most : few);
          if (g != guide) guided.push_back(g);
        }
        vary("guided",
             fmt::format("{} bands, {} bounces, samples per band group {}, groups {} guided", p.bands.size(),
                         p.max_bounces, fmt::join(samples, ", "), fmt::join(guided, ", ")),
             "1", [&](Setting& s) {
               s.bands = p.bands;
               s.max_bounces = p.max_bounces;
               s.samples = most;
               s.cycles_samples = samples;
               s.cycles_guided_groups = guided;
               s.cycles_guided_threshold = kGuidedThreshold;
             });
      }
    }
  }
  return out;
}

void mark_pareto_front(std::vector<SettingResult>& settings) {
  for (SettingResult& a : settings) {
    a.pareto = a.ok;
    if (!a.ok) continue;
    for (const SettingResult& b : settings) {
      if (&a == &b || !b.ok) continue;
      const bool no_worse = b.cpu_s <= a.cpu_s && b.mean <= a.mean;
      const bool better = b.cpu_s < a.cpu_s || b.mean < a.mean;
      if (no_worse && better) {
        a.pareto = false;
        break;
      }
    }
  }
}

StudyResult run_study(const fs::path& scene_file, const fs::path& dir, const StudyOptions& options) {
  const auto start = Clock::now();
  const Scene scene = load_scene(scene_file);
  StudyResult result;
  result.scene = scene_file.string();

  std::vector<Setting> settings = make_settings(scene, options);
  int most_samples = 0;
  for (const Setting& s : settings) most_samples = std::max(most_samples, s.samples);
  Setting& ref = result.reference;
  ref.name = "reference";
  ref.knob = "reference";
  ref.renderer = series::Renderer::Tracer;
  ref.bands = reference_bands(scene.render.bands, options.reference_band_nm);
  ref.samples = options.reference_samples > 0 ? options.reference_samples : 4 * most_samples;
  ref.max_bounces = scene.render.max_bounces;
  ref.mode = "bands";
  ref.value = fmt::format("{}, {} bounces, {} samples, tracer", band_value(ref.bands), ref.max_bounces, ref.samples);

  fs::create_directory(dir);
  fs::create_directories(dir / "plans");
  std::vector<Setting> all = settings;
  all.push_back(ref);
  const fs::path series_file = dir / "study-series.json";
  write_file_atomically(series_file, series_document(scene_file, all, scene.name).dump(2, ' ', false, kReplaceInvalidUtf8) + "\n");
  const Series series = load_series(series_file, options.threads);
  const fs::path runs = dir / "runs";

  auto run_one = [&](const Setting& s, const std::string& variant, std::uint64_t seed) {
    series::RunOptions ro;
    ro.renderer = s.renderer;
    ro.variants = {variant};
    ro.width = options.width;
    ro.height = options.height;
    ro.spp = s.samples;
    ro.seed = seed;
    ro.max_bounces = s.max_bounces;
    ro.bands = s.bands;
    ro.bands_file = fs::absolute(dir / "plans" / (s.name + ".json"));
    ro.cycles_samples = s.cycles_samples;
    ro.cycles_guided_groups = s.cycles_guided_groups;
    ro.cycles_guided_threshold = s.cycles_guided_threshold;
    write_file_atomically(ro.bands_file, band_plan_document(s.bands, s.cycles_samples, s.cycles_guided_groups,
                                                            s.cycles_guided_threshold)
                                             .dump(2, ' ', false, kReplaceInvalidUtf8) +
                                             "\n");
    ro.components = kComponents;
    ro.threads = options.threads;
    ro.progress = options.progress;
    ro.executable = options.executable;
    ro.blender = options.blender;
    ro.batch_script = options.batch_script;
    series::SeriesResult sr = series::run_series(series, runs, ro);
    series::VariantResult v = std::move(sr.variants.at(0));
    if (!v.ok) throw std::runtime_error(fmt::format("{}: {}", variant, v.error));
    // What the render cost, kept beside it: a render taken from the cache (a study run again) keeps its cost.
    const fs::path cost = runs / "renders" / (v.render_key + ".cost.json");
    if (!v.render_reused) {
      write_file_atomically(cost, Json{{"wall_seconds", v.render_s}, {"cpu_seconds", v.render_cpu_s}}.dump(-1, ' ', false, kReplaceInvalidUtf8) + "\n");
    } else if (fs::exists(cost)) {
      std::ifstream in(cost);
      const Json c = Json::parse(in);
      v.render_s = c.at("wall_seconds").get<double>();
      v.render_cpu_s = c.at("cpu_seconds").get<double>();
    }
    return v;
  };
  auto render_of = [&](const series::VariantResult& v) { return runs / "renders" / (v.render_key + ".exr"); };
  auto analysis_of = [&](const std::string& variant) { return series::variant_dir(runs, variant) / "analysis" / "analysis.json"; };

  if (options.progress) fmt::print(stderr, "study: reference ({})\n", ref.value);
  // A seed of its own: the settings' noise must be independent of the reference's for the split below.
  const series::VariantResult ref_run = run_one(ref, ref.name, options.seed + 2);
  result.reference_wall_s = ref_run.render_s;
  result.reference_cpu_s = ref_run.render_cpu_s;
  const fs::path ref_render = render_of(ref_run);
  const AnalysisSummary ref_analysis = read_analysis(analysis_of(ref.name));

  double base_noise = 0;
  int base_samples = 0;
  for (std::size_t i = 0; i < settings.size(); ++i) {
    const Setting& s = settings[i];
    SettingResult r;
    r.setting = s;
    if (options.progress) fmt::print(stderr, "study: [{}/{}] {}: {}\n", i + 1, settings.size(), s.name, s.value);
    try {
      const series::VariantResult first = run_one(s, s.name, options.seed);
      const series::VariantResult second = run_one(s, s.name + "~seed2", options.seed + 1);
      r.wall_s = first.render_s;
      r.cpu_s = first.render_cpu_s;
      r.renders = s.renderer == series::Renderer::Cycles ? cycles_renders(s.bands) : 1;
      const plan::Measurement total = plan::measure_delta_e(render_of(first), ref_render, scene, options.camera);
      const plan::Measurement twin = plan::measure_delta_e(render_of(second), ref_render, scene, options.camera);
      const plan::Measurement pair =
          plan::measure_delta_e(render_of(second), render_of(first), scene, options.camera, ref_render);
      r.mean = total.mean;
      r.p95 = total.p95;
      r.rms = total.rms;
      std::vector<double> noise_sq(pair.per_pixel.size());
      for (std::size_t p = 0; p < noise_sq.size(); ++p) noise_sq[p] = 0.5 * sq(pair.per_pixel[p]);
      const double noise_mean = mean_of(noise_sq);
      r.noise_rms = std::sqrt(noise_mean);
      r.noise_rms_se = noise_mean > 0 && noise_sq.size() > 1
                           ? std::sqrt(variance_of(noise_sq, noise_mean) / static_cast<double>(noise_sq.size())) /
                                 (2 * r.noise_rms)
                           : 0.0;
      // Per pixel, with s the systematic error, n1, n2 the two renders' noise and n_r the reference's, in the
      // quadratic approximation of ΔE00: (ΔE1² + ΔE2² − ΔE12²) / 2 has the expectation |s|² + |n_r|², whatever
      // the renders' own noise. Its mean over pixels, and the standard error of that mean.
      const std::size_t n = total.per_pixel.size();
      std::vector<double> e(n);
      for (std::size_t p = 0; p < n; ++p)
        e[p] = 0.5 * (sq(total.per_pixel[p]) + sq(twin.per_pixel[p]) - sq(pair.per_pixel[p]));
      r.systematic_sq = mean_of(e);
      r.systematic_sq_se = n > 1 ? std::sqrt(variance_of(e, r.systematic_sq) / static_cast<double>(n)) : 0.0;
      if (s.knob == "base" && s.renderer == series::Renderer::Tracer) {
        base_noise = r.noise_rms;
        base_samples = s.samples;
      }
      compare_structure(r, read_analysis(analysis_of(s.name)), read_analysis(analysis_of(s.name + "~seed2")), ref_analysis);
      r.ok = true;
    } catch (const InputError&) {
      throw;
    } catch (const std::exception& e) {
      r.error = e.what();
    }
    result.settings.push_back(std::move(r));
  }
  // The reference's own noise, from the tracer's base setting, and so the systematic part of every error.
  const double ref_noise = base_samples > 0 ? base_noise * std::sqrt(static_cast<double>(base_samples) / ref.samples) : 0.0;
  for (SettingResult& r : result.settings) {
    if (!r.ok) continue;
    r.reference_noise_rms = ref_noise;
    const double s2 = r.systematic_sq - ref_noise * ref_noise;
    r.systematic_rms = std::sqrt(std::max(0.0, s2));
    r.systematic_rms_lo = std::sqrt(std::max(0.0, s2 - 2 * r.systematic_sq_se));
    r.systematic_rms_hi = std::sqrt(std::max(0.0, s2 + 2 * r.systematic_sq_se));
    // Below zero by more than its own uncertainty: the split's first-order assumption fails (noise so large that
    // ΔE00 is no longer a quadratic form of it), and the systematic part cannot be told.
    r.systematic_measurable = s2 + 2 * r.systematic_sq_se >= 0;
  }
  if (base_samples == 0)
    result.notes.push_back("no tracer base setting: the reference's own noise is not subtracted from the systematic part");
  mark_pareto_front(result.settings);
  result.seconds = std::chrono::duration<double>(Clock::now() - start).count();

  write_file_atomically(dir / "study.json", result_json(result).dump(2, ' ', false, kReplaceInvalidUtf8) + "\n");
  write_charts(dir, result);
  write_page(dir / "index.html", result);
  return result;
}

Json result_json(const StudyResult& result) {
  auto setting_json = [](const Setting& s) {
    Json j{{"name", s.name},
           {"knob", s.knob},
           {"value", s.value},
           {"renderer", renderer_label(s.renderer)},
           {"bands", s.bands.edges()},
           {"band_count", s.bands.size()},
           {"reconstruction", s.bands.reconstruction() != nullptr},
           {"samples", s.samples},
           {"max_bounces", s.max_bounces},
           {"spectral_mode", s.mode}};
    if (!s.cycles_samples.empty()) j["cycles_samples"] = s.cycles_samples;
    if (!s.cycles_guided_groups.empty()) {
      j["cycles_guided_groups"] = s.cycles_guided_groups;
      j["cycles_guided_threshold"] = s.cycles_guided_threshold;
    }
    return j;
  };
  auto optional = [](const std::optional<double>& v) { return v ? Json(*v) : Json(); };
  Json settings = Json::array();
  for (const SettingResult& r : result.settings) {
    Json j = setting_json(r.setting);
    j["ok"] = r.ok;
    if (!r.ok) {
      j["error"] = r.error;
      settings.push_back(j);
      continue;
    }
    j["cost"] = {{"wall_seconds", r.wall_s}, {"cpu_seconds", r.cpu_s}, {"renders", r.renders}};
    j["error"] = {{"mean_de00", r.mean},
                  {"p95_de00", r.p95},
                  {"rms_de00", r.rms},
                  {"noise_rms_de00", r.noise_rms},
                  {"noise_rms_de00_se", r.noise_rms_se},
                  {"reference_noise_rms_de00", r.reference_noise_rms},
                  {"systematic_rms_de00", r.systematic_measurable ? Json(r.systematic_rms) : Json()},
                  {"systematic_rms_de00_interval",
                   r.systematic_measurable ? Json{r.systematic_rms_lo, r.systematic_rms_hi} : Json()}};
    Json objects = Json::array();
    for (const ObjectFinding& f : r.objects)
      objects.push_back({{"object", f.object},
                         {"class", f.cls},
                         {"reference_class", f.reference_cls},
                         {"same", f.same},
                         {"stable_over_seeds", f.stable},
                         {"direction_deg", optional(f.direction_deg)}});
    j["structure"] = {{"objects", objects},
                      {"classes_kept", r.classes_kept},
                      {"classes", r.objects.size()},
                      {"max_direction_deg", optional(r.max_direction_deg)},
                      {"illuminant_deg", optional(r.illuminant_deg)},
                      {"illuminant_method", r.illuminant_method},
                      {"reference_illuminant_method", r.reference_illuminant_method}};
    j["pareto"] = r.pareto;
    settings.push_back(j);
  }
  Json reference = setting_json(result.reference);
  reference["cost"] = {{"wall_seconds", result.reference_wall_s}, {"cpu_seconds", result.reference_cpu_s}};
  return {{"format", "chromatrace-study/1"},
          {"scene", result.scene},
          {"reference", reference},
          {"settings", settings},
          {"notes", result.notes},
          {"seconds", result.seconds}};
}

}  // namespace ct::study
