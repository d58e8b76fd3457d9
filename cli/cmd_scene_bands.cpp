// SPDX-License-Identifier: Apache-2.0
// chromatrace scene-bands FILE: the band averages of every spectrum a scene (or a spectra list) uses, so that
// a renderer working in RGB (Cycles through the Blender add-on) only has to plug numbers into colour inputs.
#include <algorithm>
#include <memory>
#include <optional>
#include <string>
#include <type_traits>
#include <variant>
#include <vector>

#include <fmt/core.h>
#include <fmt/format.h>

#include "cli/app.h"
#include "cli/command.h"
#include "cli/options.h"
#include "core/band_plan.h"
#include "core/cie.h"
#include "core/colour.h"
#include "core/error.h"
#include "core/json_input.h"
#include "core/scene.h"

namespace ct::cli {
namespace {

struct SceneBandsOptions {
  std::string file, bands, bands_file;
  bool json = false;
};

Json averages(const PiecewiseLinearSpectrum& spectrum, const Bands& bands) { return band_averages(spectrum, bands); }

// The spectrum's colour in linear sRGB (D65 white), both ways an RGB renderer could show it: as a reflectance under
// D65 (the perfect white is [1, 1, 1]), and as an emitted radiance relative to D65 of the flat spectrum 1's luminance
// (the convention of an emitted {"rgb"}: D65 of that luminance is [1, 1, 1]), so that a source given as
// {"rgb": c} comes back as c, up to the upsampling's accuracy.
Json linear_srgb(const Vec3d& xyz) {
  const Vec3d rgb = xyz_to_linear_srgb(xyz);
  return Json::array({rgb[0], rgb[1], rgb[2]});
}

Json reflected_srgb(const PiecewiseLinearSpectrum& spectrum) {
  return linear_srgb(reflectance_to_xyz(spectrum, cie::illuminant("D65")));
}

Json emitted_srgb(const PiecewiseLinearSpectrum& spectrum) {
  static const double flat_luminance = spectrum_to_xyz(PiecewiseLinearSpectrum::constant(1.0))[1];
  Vec3d xyz = spectrum_to_xyz(spectrum);
  for (double& c : xyz) c /= flat_luminance;
  return linear_srgb(xyz);
}

// Band averages, plus the largest sample (so a caller can check a reflectance against 1 before rendering), and its
// colour in linear sRGB (what the Blender add-on shows in Blender's viewport and a plain RGB render).
Json spectrum_entry(const PiecewiseLinearSpectrum& spectrum, const Bands& bands) {
  const auto& values = spectrum.values();
  const auto peak = std::max_element(values.begin(), values.end());
  return {{"bands", averages(spectrum, bands)},
          {"max", *peak},
          {"max_nm", spectrum.wavelengths()[static_cast<std::size_t>(peak - values.begin())]},
          {"linear_srgb_reflected", reflected_srgb(spectrum)},
          {"linear_srgb_emitted", emitted_srgb(spectrum)}};
}

// Textures and the environment have no band averages of their own here yet; failing keeps a caller (the Blender
// add-on) from rendering a scene without them.
void refuse_textures_and_environment(const Scene& scene) {
  const auto refuse = [&](const SpectrumRef& ref, const std::string& where) {
    if (ref.texture)
      throw InputError(fmt::format("{}: {}: is an image texture ({}); scene-bands reports band averages of spectra only",
                                   scene.source, where, ref.texture->file));
  };
  for (const Material& m : scene.materials)
    refuse(m.reflectance_spectrum(), fmt::format("materials.{}.{}", m.name, m.reflectance_key()));
  for (std::size_t i = 0; i < scene.lights.size(); ++i) refuse(scene.lights[i].radiance, fmt::format("lights[{}].radiance", i));
  if (scene.environment)
    throw InputError(fmt::format("{}: environment: scene-bands does not report the environment yet", scene.source));
}

Json material_entry(const Material& material, const Bands& bands) {
  return std::visit(
      [&](const auto& m) -> Json {
        using M = std::decay_t<decltype(m)>;
        if constexpr (std::is_same_v<M, LambertMaterial>) {
          return {{"type", "lambert"}, {"reflectance", averages(m.reflectance.spectrum, bands)}};
        } else if constexpr (std::is_same_v<M, MirrorMaterial>) {
          return {{"type", "mirror"}, {"reflectance", averages(m.reflectance.spectrum, bands)}};
        } else if constexpr (std::is_same_v<M, PrincipledMaterial>) {
          return {{"type", "principled"}, {"version", m.version},
                  {"base_color", averages(m.base_color.spectrum, bands)}, {"roughness", m.roughness},
                  {"ior", m.effective_ior()}, {"distribution", m.multiscatter ? "multiscatter-ggx" : "ggx"}};
        } else {
          Json entry = {{"type", "dichromatic"}, {"diffuse", averages(m.diffuse.spectrum, bands)}, {"specular", m.specular}};
          if (const auto* ggx = std::get_if<DichromaticMaterial::Ggx>(&m.lobe)) {
            entry["lobe"] = "ggx";
            entry["roughness"] = ggx->roughness;
          } else {
            entry["lobe"] = "phong";
            entry["exponent"] = std::get<DichromaticMaterial::Phong>(m.lobe).exponent;
          }
          return entry;
        }
      },
      material.model);
}

int run(const SceneBandsOptions& o) {
  const std::optional<BandPlanFile> given = band_plan_file_option(o.bands, o.bands_file, "--bands-file");
  const Json document = read_json(o.file);
  const bool spectra_only = document_format(document) == kSpectraFormat;
  std::optional<Scene> scene;
  std::vector<NamedSpectrum> spectra;
  if (spectra_only) {
    spectra = parse_spectra(document, o.file, std::filesystem::path(o.file).parent_path());
  } else {
    scene = load_scene(o.file);
    spectra = scene->spectra;
    refuse_textures_and_environment(*scene);
  }
  const Bands bands = given ? given->bands : scene ? scene->render.bands : RenderSettings{}.bands;

  std::vector<double> centres;
  for (std::size_t i = 0; i < bands.size(); ++i) centres.push_back(bands.centre(i));
  Json report = {{"file", o.file},
                 {"bands", {{"count", bands.size()}, {"edges_nm", bands.edges()}, {"centres_nm", centres}}}};
  if (const BandReconstruction* r = bands.reconstruction()) report["bands"]["reconstruction"] = reconstruction_json(*r);
  if (given && !given->cycles_samples.empty())  // the Cycles samples of each band group, which the add-on renders with
    report["bands"]["cycles_samples"] = given->cycles_samples;
  if (given && !given->cycles_guided_groups.empty())  // the groups the add-on's assembly reconstructs from the others
    report["bands"]["cycles_guided_groups"] = given->cycles_guided_groups;
  if (given && given->cycles_guided_threshold > 0)  // their adaptive sampling's noise threshold
    report["bands"]["cycles_guided_threshold"] = given->cycles_guided_threshold;
  if (given && given->cycles_light_tree)  // Cycles' light tree in the add-on's renders, where the plan chose it
    report["bands"]["cycles_light_tree"] = *given->cycles_light_tree;
  Json spectra_json = Json::object();
  for (const NamedSpectrum& s : spectra) spectra_json[s.name] = spectrum_entry(s.spectrum, bands);
  report["spectra"] = spectra_json;
  if (scene) {
    Json materials = Json::object();
    for (const Material& m : scene->materials) materials[m.name] = material_entry(m, bands);
    Json objects = Json::array();
    for (const Object& object : scene->objects)
      objects.push_back({{"name", object.name}, {"id", object.id}, {"material", scene->materials[object.material].name}});
    Json lights = Json::array();
    for (const Light& light : scene->lights)
      lights.push_back({{"name", light.name},
                        {"id", light.id},
                        {"group", light.group},
                        {"two_sided", light.two_sided},
                        {"radiance", averages(light.emitted_radiance(), bands)},
                        {"material", light.material ? Json(scene->materials[*light.material].name) : Json()}});
    report["materials"] = materials;
    report["objects"] = objects;
    report["lights"] = lights;
  }

  if (o.json) {
    fmt::print("{}\n", report.dump(1, ' ', false, kReplaceInvalidUtf8));
    return 0;
  }
  auto row = [](const Json& values) {
    std::vector<std::string> cells;
    for (const Json& v : values) cells.push_back(fmt::format("{:.4g}", v.get<double>()));
    return fmt::format("{}", fmt::join(cells, " "));
  };
  fmt::print("{}: {} bands over {:.6g}-{:.6g} nm, centres {} nm\n", o.file, bands.size(), bands.min_wavelength(),
             bands.max_wavelength(), row(report["bands"]["centres_nm"]));
  for (const auto& [name, entry] : report["spectra"].items()) fmt::print("  spectrum {}: {}\n", name, row(entry["bands"]));
  if (!scene) return 0;
  for (const auto& [name, entry] : report["materials"].items()) {
    const char* key = entry.contains("diffuse") ? "diffuse" : "reflectance";
    fmt::print("  material {} ({}) {}: {}\n", name, entry["type"].get<std::string>(), key, row(entry[key]));
  }
  for (const Json& light : report["lights"])
    fmt::print("  light {} (group {}) radiance: {} W/(m2 sr nm)\n", light["name"].get<std::string>(),
               light["group"].get<std::string>(), row(light["radiance"]));
  return 0;
}

}  // namespace

Action add_scene_bands(CLI::App& app) {
  auto o = std::make_shared<SceneBandsOptions>();
  auto* cmd = add_command(app, "scene-bands");
  cmd->add_option("file", o->file, "scene (chromatrace-scene/1) or spectra list (chromatrace-spectra/1)")->required();
  cmd->add_option("--bands", o->bands, "Band plan lo:hi:width in nm (default: the scene's render.bands, else 380:780:10)");
  cmd->add_option("--bands-file", o->bands_file, "Band plan file (chromatrace-bands/1: {\"edges_nm\": [...]})");
  cmd->add_flag("--json", o->json, "Print the result as JSON");
  return [o] { return run(*o); };
}

}  // namespace ct::cli
