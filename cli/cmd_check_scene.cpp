// SPDX-License-Identifier: Apache-2.0
// chromatrace check-scene: validates a scene or an experiment series file and summarises it.
#include <algorithm>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <memory>
#include <optional>
#include <tuple>
#include <string>
#include <vector>

#include <fmt/core.h>
#include <fmt/format.h>

#include "cli/app.h"
#include "cli/command.h"
#include "cli/options.h"
#include "core/error.h"
#include "core/file_io.h"
#include "core/geometry.h"
#include "core/json_input.h"
#include "core/parallel.h"
#include "core/scene.h"
#include "core/series_format.h"
#include "plan/render_check.h"
#include "sensor_sim/config.h"

namespace ct::cli {
namespace {

struct CheckSceneOptions {
  std::string file, variant, emit, emit_sensor;
  // The render settings to judge instead of the scene's (those a renderer is given on its command line, as the
  // Blender batch passes on its own): the warnings name them by these options.
  std::string bands, bands_file, resolution, renderer = "tracer";
  std::optional<int> samples, max_bounces;
  bool json = false;
  bool quiet = false;
  int threads = 0;
};

Json vec_json(const Vec3& v) { return Json::array({v.x(), v.y(), v.z()}); }

const char* fov_axis_name(FovAxis axis) {
  switch (axis) {
    case FovAxis::Horizontal: return "horizontal";
    case FovAxis::Vertical: return "vertical";
    case FovAxis::Smaller: return "smaller";
    case FovAxis::Larger: return "larger";
  }
  return "";
}

bool overrides(const CheckSceneOptions& o) {
  return !o.bands.empty() || !o.bands_file.empty() || !o.resolution.empty() || o.samples || o.max_bounces ||
         o.renderer != "tracer";
}

// The settings the warnings judge: the scene's, with the options' in their place.
plan::RenderRequest judged_settings(const Scene& scene, const CheckSceneOptions& o) {
  plan::RenderRequest request = plan::scene_settings(scene);
  if (o.renderer != "tracer" && o.renderer != "cycles")
    throw InputError(fmt::format("--renderer: must be tracer or cycles, got \"{}\"", o.renderer));
  // Cycles renders band averages only: its band plan is judged in the bands mode, and no fix names the other.
  if (o.renderer == "cycles") request.mode = SpectralMode::Bands, request.continuous_available = false, request.cycles = true;
  const std::optional<BandPlanFile> plan = band_plan_file_option(o.bands, o.bands_file, "--bands-file");
  if (plan) request.bands = plan->bands;
  if (o.max_bounces) {
    if (*o.max_bounces < 0) throw InputError(fmt::format("--max-bounces: must be >= 0, got {}", *o.max_bounces));
    request.max_bounces = *o.max_bounces, request.bounces_name = "--max-bounces";
  }
  if (o.samples) {
    if (*o.samples < 1) throw InputError(fmt::format("--samples: must be at least 1, got {}", *o.samples));
    request.samples = *o.samples, request.samples_name = "--samples";
  } else if (o.renderer == "cycles" && plan && !plan->cycles_samples.empty()) {
    // A plan that gives each band group its samples: each group's noise falls with its own.
    request.cycles_samples = plan->cycles_samples;
    request.samples = *std::min_element(request.cycles_samples.begin(), request.cycles_samples.end());
    request.samples_name = fmt::format("cycles_samples of {}", o.bands_file);
  }
  return request;
}

// What a person or a script wants to know about a valid scene; the text output is printed from this.
Json scene_summary(const Scene& scene, const plan::RenderRequest& settings) {
  std::size_t triangles = 0;
  Bounds extent;
  for (const TriangleMesh& mesh : scene_meshes(scene)) {
    triangles += mesh.triangles.size();
    extent.extend(bounds(mesh));
  }
  Json materials = Json::object();
  for (const char* type : {"lambert", "dichromatic", "mirror", "principled"}) {
    const auto n = std::count_if(scene.materials.begin(), scene.materials.end(),
                                 [&](const Material& m) { return std::string_view(material_type_name(m)) == type; });
    if (n > 0) materials[type] = n;
  }
  std::vector<std::string> groups;
  for (const Light& light : scene.lights)
    if (std::find(groups.begin(), groups.end(), light.group) == groups.end()) groups.push_back(light.group);

  const Camera& c = scene.camera;
  const RenderSettings& r = scene.render;
  const std::vector<std::string> warnings = plan::render_warnings(scene, settings);
  return {
      {"warnings", warnings},
      {"name", scene.name},
      {"spectra", scene.spectra.size()},
      {"materials", materials},
      {"objects", scene.objects.size()},
      {"lights", scene.lights.size()},
      {"light_groups", groups},
      {"triangles", triangles},
      {"extent_m", {{"min", vec_json(extent.lo)}, {"max", vec_json(extent.hi)}}},
      {"camera",
       {{"resolution", {c.width, c.height}},
        {"fov_deg", c.fov_deg},
        {"fov_axis", fov_axis_name(c.fov_axis)},
        {"focal_length_mm", c.focal_length_mm()},
        {"sensor_width_mm", c.sensor_width_mm},
        {"position", vec_json(c.position)},
        {"look_at", vec_json(c.look_at)}}},
      {"render",
       {{"samples", r.samples},
        {"max_bounces", r.max_bounces},
        {"seed", r.seed},
        {"pixel_filter", r.pixel_filter == PixelFilter::Box ? "box" : "point"},
        {"spectral_mode", r.spectral_mode == SpectralMode::Bands ? "bands" : "continuous"},
        {"bands",
         {{"count", r.bands.size()}, {"lo_nm", r.bands.min_wavelength()}, {"hi_nm", r.bands.max_wavelength()}}},
        {"tessellation",
         {{"segments", r.tessellation.segments},
          {"rings", r.tessellation.rings.value_or(std::max(2, r.tessellation.segments / 2))}}}}},
  };
}

std::string vec_text(const Json& v) {
  return fmt::format("[{:.4g}, {:.4g}, {:.4g}]", v[0].get<double>(), v[1].get<double>(), v[2].get<double>());
}

std::string materials_text(const Json& by_type) {
  std::string text;
  int total = 0;
  for (const auto& [type, n] : by_type.items()) {
    text += fmt::format("{}{} {}", text.empty() ? "" : ", ", n.get<int>(), type);
    total += n.get<int>();
  }
  return fmt::format("{} ({})", total, text);
}

std::string ids_text(int first, int last) {
  return first == last ? fmt::format("id {}", first) : fmt::format("ids {}-{}", first, last);
}

void print_scene(const Json& s) {
  const int objects = s["objects"].get<int>(), lights = s["lights"].get<int>();
  const Json& c = s["camera"];
  const Json& r = s["render"];
  fmt::print("  spectra    {}\n", s["spectra"].get<int>());
  fmt::print("  materials  {}\n", materials_text(s["materials"]));
  fmt::print("  objects    {}{}\n", objects, objects ? fmt::format(" ({})", ids_text(1, objects)) : "");
  fmt::print("  lights     {} ({}), groups: {}\n", lights, ids_text(objects + 1, objects + lights),
             fmt::join(s["light_groups"].get<std::vector<std::string>>(), ", "));
  fmt::print("  triangles  {}\n", s["triangles"].get<std::size_t>());
  fmt::print("  extent     {} to {} m\n", vec_text(s["extent_m"]["min"]), vec_text(s["extent_m"]["max"]));
  fmt::print(
      "  camera     {}x{}, fov {:.6g} deg ({} axis), focal length {:.4g} mm on a {:.4g} mm wide sensor,\n"
      "             at {} looking at {}\n",
      c["resolution"][0].get<int>(), c["resolution"][1].get<int>(), c["fov_deg"].get<double>(),
      c["fov_axis"].get<std::string>(), c["focal_length_mm"].get<double>(), c["sensor_width_mm"].get<double>(),
      vec_text(c["position"]), vec_text(c["look_at"]));
  fmt::print(
      "  render     {} samples, max {} bounces, seed {}, {} pixel filter, {} spectral mode, {} bands over "
      "{:.6g}-{:.6g} nm,\n             tessellation {} segments x {} rings\n",
      r["samples"].get<int>(), r["max_bounces"].get<int>(), r["seed"].get<std::uint64_t>(),
      r["pixel_filter"].get<std::string>(), r["spectral_mode"].get<std::string>(), r["bands"]["count"].get<int>(),
      r["bands"]["lo_nm"].get<double>(), r["bands"]["hi_nm"].get<double>(), r["tessellation"]["segments"].get<int>(),
      r["tessellation"]["rings"].get<int>());
  for (const Json& w : s["warnings"]) fmt::print("  warning    {}\n", w.get<std::string>());
}

Json expect_json(const std::vector<Expectation>& expect) {
  Json out = Json::object();
  for (const Expectation& e : expect) {
    if (e.bent_by.empty() && e.thickened_by.empty() && e.paper.empty()) {
      out[e.target] = e.any_of;
      continue;
    }
    out[e.target] = {{"classes", e.any_of}};
    if (!e.bent_by.empty()) out[e.target]["bent_by"] = e.bent_by;
    if (!e.thickened_by.empty()) out[e.target]["thickened_by"] = e.thickened_by;
    if (!e.paper.empty()) out[e.target]["paper"] = e.paper;
  }
  return out;
}

// One line per variant: what sets it apart and what it should show.
void print_variant(const Json& v) {
  const Json& s = v["scene"];
  const std::string extends = v["extends"].get<std::string>();
  std::vector<std::string> expects;
  for (const auto& [target, words] : v["expect"].items()) {
    const Json& classes = words.is_object() ? words["classes"] : words;
    auto cause = [&](const char* key) { return words.is_object() && words.contains(key) ? words[key].get<std::string>() : std::string(); };
    const std::string text =
        fmt::format("{} {}", target, expectation_phrase(classes.get<std::vector<std::string>>(), "|", cause("bent_by"), cause("thickened_by")));
    expects.push_back(std::move(text));
  }
  const auto figure = v["figure"].get<std::vector<std::string>>();
  fmt::print("  {}{}: from {}; materials {}, {} light(s), max {} bounces, {} pixels; sensor {}; expects {}\n",
             v["name"].get<std::string>(), figure.empty() ? "" : fmt::format(" (figure {})", fmt::join(figure, ", ")),
             extends.empty() ? "the base" : extends, materials_text(s["materials"]), s["lights"].get<int>(),
             s["render"]["max_bounces"].get<int>(), s["render"]["pixel_filter"].get<std::string>(), v["sensor"].dump(-1, ' ', false, kReplaceInvalidUtf8),
             expects.empty() ? "nothing" : fmt::format("{}", fmt::join(expects, ", ")));
}

// --emit / --emit-sensor: the variant's resolved scene (paths relative to where it is written) and its sensor
// settings as a chromatrace-sensor/1 file, so it can be rendered with `render` or the Blender batch by hand.
void emit_variant(const CheckSceneOptions& options, const Series& series) {
  const SeriesVariant* variant = &series.variant(options.variant, "--variant");
  std::vector<std::filesystem::path> inputs = series.base_scene.files;
  inputs.push_back(options.file);
  for (const std::string& output : {options.emit, options.emit_sensor})
    if (!output.empty()) check_output_file(output, inputs);
  check_distinct_outputs({options.emit, options.emit_sensor});
  if (!options.emit.empty()) {
    const std::filesystem::path out = std::filesystem::absolute(options.emit);
    const Json scene = rebase_scene_paths(variant->scene.json, {}, out.parent_path());
    write_file_atomically(out, scene.dump(2, ' ', false, kReplaceInvalidUtf8) + "\n");
  }
  if (!options.emit_sensor.empty()) {
    const std::filesystem::path series_dir = std::filesystem::path(series.source).parent_path();
    Json sensor = sensor::config_patch(variant->sensor, options.file, series_dir).patch;
    write_file_atomically(options.emit_sensor, sensor.dump(2, ' ', false, kReplaceInvalidUtf8) + "\n");
  }
}

int check(const CheckSceneOptions& options) {
  const Json document = read_json(options.file);
  Json report;
  if (document_format(document) == kSeriesFormat) {
    if (overrides(options))
      throw InputError(fmt::format("--bands: {} is a series; the render settings to judge apply to a scene", options.file));
    const Series series = load_series(options.file, options.threads);
    // Each variant's sensor settings, merged along "extends", must be valid for the sensor simulator.
    for (std::size_t i = 0; i < series.variants.size(); ++i)
      sensor::resolve_config(
          {sensor::config_patch(series.variants[i].sensor,
                                fmt::format("{}: variants[{}] \"{}\" sensor", options.file, i, series.variants[i].name),
                                std::filesystem::path(options.file).parent_path())});
    if (!options.variant.empty()) emit_variant(options, series);
    // Each variant's summary holds its render warnings (a small preview render each): on every thread, in file order.
    std::vector<Json> summaries(series.variants.size());
    std::vector<std::exception_ptr> errors(series.variants.size());
    parallel_for(series.variants.size(), options.threads, [&](std::size_t i) {
      try {
        summaries[i] = scene_summary(series.variants[i].scene, plan::scene_settings(series.variants[i].scene));
      } catch (...) {
        errors[i] = std::current_exception();
      }
    });
    for (const std::exception_ptr& error : errors)
      if (error) std::rethrow_exception(error);
    Json variants = Json::array();
    for (std::size_t i = 0; i < series.variants.size(); ++i) {
      const SeriesVariant& v = series.variants[i];
      variants.push_back({{"name", v.name},
                          {"extends", v.extends},
                          {"figure", v.figure},
                          {"expect", expect_json(v.expect)},
                          {"sensor", v.sensor},
                          {"scene", std::move(summaries[i])}});
    }
    report = {{"file", options.file}, {"format", kSeriesFormat}, {"valid", true},
              {"name", series.name},  {"base", series.base},     {"variants", variants}};
  } else {
    if (!options.variant.empty() || !options.emit.empty() || !options.emit_sensor.empty())
      throw InputError(fmt::format("--variant: {} is a scene, not a series", options.file));
    Scene scene = load_scene(options.file);
    if (!options.resolution.empty())
      std::tie(scene.camera.width, scene.camera.height) = parse_resolution(options.resolution);
    plan::RenderRequest settings = judged_settings(scene, options);
    settings.threads = options.threads;
    report = {{"file", options.file},
              {"format", kSceneFormat},
              {"valid", true},
              {"scene", scene_summary(scene, settings)}};
  }

  if (options.quiet) return 0;
  if (options.json) {
    fmt::print("{}\n", report.dump(2, ' ', false, kReplaceInvalidUtf8));
    return 0;
  }
  if (report.contains("scene")) {
    fmt::print("{}: valid scene \"{}\"\n", options.file, report["scene"]["name"].get<std::string>());
    print_scene(report["scene"]);
    return 0;
  }
  fmt::print("{}: valid series \"{}\" of {} variants on {}\n", options.file, report["name"].get<std::string>(),
             report["variants"].size(), report["base"].get<std::string>());
  for (const Json& v : report["variants"]) print_variant(v);
  return 0;
}

}  // namespace

Action add_check_scene(CLI::App& app) {
  auto options = std::make_shared<CheckSceneOptions>();
  CLI::App* command = add_command(app, "check-scene");
  command->add_option("file", options->file, "scene or series JSON file")->required();
  command->add_flag("--json", options->json, "print the summary as JSON");
  command->add_flag("-q,--quiet", options->quiet, "print nothing when the file is valid (errors still go to stderr)");
  command->add_option("--variant", options->variant, "a series' variant to write out with --emit / --emit-sensor");
  command->add_option("--emit", options->emit, "write the variant's resolved scene (chromatrace-scene/1) to this file")
      ->needs("--variant");
  command->add_option("--emit-sensor", options->emit_sensor,
                      "write the variant's sensor settings (chromatrace-sensor/1) to this file")
      ->needs("--variant");
  command->add_option("--bands", options->bands, "judge this band plan (lo:hi:width nm) instead of the scene's");
  command->add_option("--bands-file", options->bands_file, "judge this band plan file (chromatrace-bands/1) instead");
  command->add_option("--samples", options->samples, "judge this many samples per pixel instead of the scene's");
  command->add_option("--max-bounces", options->max_bounces, "judge this bounce limit instead of the scene's");
  command->add_option("--renderer", options->renderer,
                      "the renderer the warnings are for: tracer, or cycles (bands mode only, as the Blender batch)")
      ->capture_default_str();
  command->add_option("--resolution", options->resolution, "judge the render at this size WxH (the noise's pixel size)");
  command->add_option("--threads", options->threads, "threads for checking series variants and the warnings' previews (0: all)")
      ->check(CLI::NonNegativeNumber);
  return [options] { return check(*options); };
}

}  // namespace ct::cli
