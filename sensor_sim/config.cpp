// SPDX-License-Identifier: Apache-2.0
#include "sensor_sim/config.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <utility>

#include <fmt/core.h>
#include <fmt/format.h>

#include "core/cie.h"
#include "core/csv.h"
#include "core/error.h"

namespace ct::sensor {
namespace {

namespace fs = std::filesystem;

// Runs `read` on the key's node when the key is present.
template <typename Read>
void read_key(const JsonNode& parent, std::string_view key, Read read) {
  if (const std::optional<JsonNode> node = parent.find(key)) read(*node);
}

// A number, or null for "none".
std::optional<double> optional_number(const JsonNode& node, double above) {
  if (node.json().is_null()) return std::nullopt;
  return node.number_above(above);
}

// A positive number no larger than `most`: exposure, pixel size and gains whose product the linear signal forms
// in floats (1e308 once overflowed into Inf and NaN pixels).
double positive_at_most(const JsonNode& node, double most) {
  const double value = node.number_above(0);
  if (value > most) node.fail(fmt::format("must be at most {:g}, got {:g}", most, value));
  return value;
}

std::uint64_t seed(const JsonNode& node) {
  return static_cast<std::uint64_t>(node.integer_in(0, std::numeric_limits<std::int64_t>::max()));
}

template <typename Enum, std::size_t N>
Enum choose(const JsonNode& node, const std::array<std::pair<std::string_view, Enum>, N>& names) {
  std::vector<std::string_view> allowed;
  for (const auto& [name, value] : names) allowed.push_back(name);
  const std::string text = node.string();
  for (const auto& [name, value] : names)
    if (text == name) return value;
  node.fail(fmt::format("must be one of {}, got \"{}\"", fmt::join(allowed, ", "), text));
}

template <typename Enum, std::size_t N>
std::string_view name_of(Enum value, const std::array<std::pair<std::string_view, Enum>, N>& names) {
  for (const auto& [name, v] : names)
    if (v == value) return name;
  return "?";
}

constexpr std::array<std::pair<std::string_view, BayerPattern>, 4> kPatterns = {{{"RGGB", BayerPattern::RGGB},
                                                                                 {"BGGR", BayerPattern::BGGR},
                                                                                 {"GRBG", BayerPattern::GRBG},
                                                                                 {"GBRG", BayerPattern::GBRG}}};
constexpr std::array<std::pair<std::string_view, DemosaicMethod>, 3> kDemosaic = {
    {{"bilinear", DemosaicMethod::Bilinear}, {"vng", DemosaicMethod::Vng}, {"edge_aware", DemosaicMethod::EdgeAware}}};
constexpr std::array<std::pair<std::string_view, ResponseBasis>, 2> kBases = {
    {{"energy", ResponseBasis::Energy}, {"photon", ResponseBasis::Photon}}};
constexpr std::array<std::pair<std::string_view, CurveOutside>, 2> kOutside = {
    {{"error", CurveOutside::Error}, {"zero", CurveOutside::Zero}}};
constexpr std::array<std::pair<std::string_view, ResponseCurve>, 3> kCurves = {
    {{"linear", ResponseCurve::Linear}, {"gamma", ResponseCurve::Gamma}, {"srgb", ResponseCurve::Srgb}}};

// A transmittance τ(λ) in [0, 1]: a constant, {"csv": file, "column": name} or {"samples": [[nm, τ], …]};
// beyond its table it keeps its end values.
PiecewiseLinearSpectrum transmittance(const JsonNode& node) {
  if (node.json().is_number()) return PiecewiseLinearSpectrum::constant(node.number_in(0, 1));
  node.expect_object({"csv", "column", "samples"});
  std::vector<double> lambda, value;
  if (const auto samples = node.find("samples")) {
    for (const JsonNode& sample : samples->elements()) {
      const std::vector<JsonNode> pair = sample.elements();
      if (pair.size() != 2) sample.fail("must be [wavelength_nm, transmittance]");
      lambda.push_back(pair[0].number_above(0));
      value.push_back(pair[1].number_in(0, 1));
    }
  } else {
    const JsonNode csv = node["csv"];
    PiecewiseLinearSpectrum column;
    try {
      column = read_csv(csv.non_empty_string()).spectrum(node["column"].non_empty_string());
    } catch (const InputError& e) {
      csv.fail(e.what());
    }
    lambda = column.wavelengths();
    value = column.values();
    for (double v : value)
      if (!(v >= 0 && v <= 1)) csv.fail(fmt::format("transmittance must be in [0, 1], got {}", v));
  }
  if (lambda.empty()) node.fail("no samples");
  return PiecewiseLinearSpectrum(std::move(lambda), std::move(value), Extrapolation::Clamp, node.location());
}

void read_optics(const JsonNode& node, OpticsConfig& o) {
  node.expect_object({"enabled", "f_number", "cos4", "fov_deg", "transmittance", "flare"});
  read_key(node, "flare", [&](const JsonNode& n) { o.flare = n.number_in(0, 1); });
  read_key(node, "enabled", [&](const JsonNode& n) { o.enabled = n.boolean(); });
  read_key(node, "f_number", [&](const JsonNode& n) { o.f_number = positive_at_most(n, 1e4); });
  read_key(node, "cos4", [&](const JsonNode& n) { o.cos4 = n.boolean(); });
  read_key(node, "fov_deg", [&](const JsonNode& n) {
    o.fov_deg = optional_number(n, 0);
    if (o.fov_deg && *o.fov_deg >= 180) n.fail(fmt::format("must be below 180 degrees, got {}", *o.fov_deg));
  });
  read_key(node, "transmittance", [&](const JsonNode& n) {
    o.transmittance_spec = n.json();
    o.transmittance = n.json().is_null() ? std::nullopt : std::optional(transmittance(n));
  });
}

void read_exposure(const JsonNode& node, ExposureConfig& e) {
  node.expect_object({"time_s", "scale", "auto_percentile", "auto_level", "auto_exclude_emitters"});
  read_key(node, "time_s", [&](const JsonNode& n) {
    if (n.json().is_string()) {
      if (n.string() != "auto") n.fail(fmt::format("must be a time in seconds or \"auto\", got \"{}\"", n.string()));
      e.time_s.reset();
    } else {
      e.time_s = positive_at_most(n, 1e6);
    }
  });
  read_key(node, "scale", [&](const JsonNode& n) { e.scale = positive_at_most(n, 1e6); });
  read_key(node, "auto_percentile", [&](const JsonNode& n) {
    e.auto_percentile = n.number_in(0, 100);
    if (e.auto_percentile == 0) n.fail("must be > 0");
  });
  read_key(node, "auto_level", [&](const JsonNode& n) { e.auto_level = n.number_above(0); });
  read_key(node, "auto_exclude_emitters", [&](const JsonNode& n) { e.auto_exclude_emitters = n.boolean(); });
}

void read_pixel(const JsonNode& node, PixelConfig& p) {
  node.expect_object({"pitch_um", "fill_factor", "supersample"});
  read_key(node, "pitch_um", [&](const JsonNode& n) { p.pitch_um = positive_at_most(n, 1e4); });
  read_key(node, "fill_factor", [&](const JsonNode& n) {
    p.fill_factor = n.number_in(0, 1);
    if (p.fill_factor == 0) n.fail("must be > 0");
  });
  read_key(node, "supersample", [&](const JsonNode& n) { p.supersample = static_cast<int>(n.integer_in(1, 64)); });
}

void read_response(const JsonNode& node, SpectralResponseConfig& r) {
  node.expect_object({"camera", "columns", "basis", "peak_qe", "outside_curve"});
  std::string where = fmt::format("{}.camera", node.location());
  read_key(node, "camera", [&](const JsonNode& n) {
    r.camera = n.non_empty_string();
    where = n.location();
  });
  read_key(node, "columns", [&](const JsonNode& n) {
    const std::vector<JsonNode> columns = n.elements();
    if (columns.size() != 3) n.fail(fmt::format("must name 3 columns, got {}", columns.size()));
    for (std::size_t c = 0; c < 3; ++c) r.columns[c] = columns[c].non_empty_string();
  });
  read_key(node, "basis", [&](const JsonNode& n) { r.basis = choose(n, kBases); });
  read_key(node, "peak_qe", [&](const JsonNode& n) {
    r.peak_qe = n.number_in(0, 1);
    if (r.peak_qe == 0) n.fail("must be > 0");
  });
  read_key(node, "outside_curve", [&](const JsonNode& n) { r.outside_curve = choose(n, kOutside); });
  r.curves = camera_curves(r.camera, r.columns, where);
}

void read_cfa(const JsonNode& node, CfaConfig& c) {
  node.expect_object({"enabled", "pattern", "demosaic"});
  read_key(node, "enabled", [&](const JsonNode& n) { c.enabled = n.boolean(); });
  read_key(node, "pattern", [&](const JsonNode& n) { c.pattern = choose(n, kPatterns); });
  read_key(node, "demosaic", [&](const JsonNode& n) { c.demosaic = choose(n, kDemosaic); });
}

void read_noise(const JsonNode& node, NoiseConfig& z) {
  node.expect_object({"enabled", "shot", "dark_current_e_per_s", "read_e", "dsnu_e", "prnu", "dsnu_row_e", "dsnu_column_e", "prnu_row",
                      "prnu_column", "seed", "pattern_seed"});
  read_key(node, "enabled", [&](const JsonNode& n) { z.enabled = n.boolean(); });
  read_key(node, "shot", [&](const JsonNode& n) { z.shot = n.boolean(); });
  read_key(node, "dark_current_e_per_s", [&](const JsonNode& n) { z.dark_current_e_per_s = n.number_at_least(0); });
  read_key(node, "read_e", [&](const JsonNode& n) { z.read_e = n.number_at_least(0); });
  read_key(node, "dsnu_e", [&](const JsonNode& n) { z.dsnu_e = n.number_at_least(0); });
  read_key(node, "prnu", [&](const JsonNode& n) {
    z.prnu = n.number_in(0, 1);
    if (z.prnu == 1) n.fail("must be below 1");
  });
  read_key(node, "dsnu_row_e", [&](const JsonNode& n) { z.dsnu_row_e = n.number_at_least(0); });
  read_key(node, "dsnu_column_e", [&](const JsonNode& n) { z.dsnu_column_e = n.number_at_least(0); });
  read_key(node, "prnu_row", [&](const JsonNode& n) { z.prnu_row = n.number_in(0, 0.5); });
  read_key(node, "prnu_column", [&](const JsonNode& n) { z.prnu_column = n.number_in(0, 0.5); });
  read_key(node, "seed", [&](const JsonNode& n) { z.seed = seed(n); });
  read_key(node, "pattern_seed", [&](const JsonNode& n) { z.pattern_seed = seed(n); });
}

void read_full_well(const JsonNode& node, FullWellConfig& f) {
  node.expect_object({"enabled", "electrons"});
  read_key(node, "enabled", [&](const JsonNode& n) { f.enabled = n.boolean(); });
  read_key(node, "electrons", [&](const JsonNode& n) { f.electrons = positive_at_most(n, 1e12); });
}

void read_adc(const JsonNode& node, AdcConfig& a) {
  node.expect_object({"enabled", "gain_dn_per_e", "black_level_dn", "bits"});
  read_key(node, "enabled", [&](const JsonNode& n) { a.enabled = n.boolean(); });
  read_key(node, "gain_dn_per_e", [&](const JsonNode& n) { a.gain_dn_per_e = positive_at_most(n, 1e6); });
  read_key(node, "black_level_dn", [&](const JsonNode& n) { a.black_level_dn = n.number_at_least(0); });
  read_key(node, "bits", [&](const JsonNode& n) { a.bits = static_cast<int>(n.integer_in(1, 32)); });
}

void read_rendering(const JsonNode& node, RenderingConfig& r) {
  node.expect_object(
      {"enabled", "white_balance", "colour_matrix", "white_level", "curve", "gamma", "k", "clip", "output_bits"});
  read_key(node, "enabled", [&](const JsonNode& n) { r.enabled = n.boolean(); });
  read_key(node, "white_balance", [&](const JsonNode& n) {
    if (n.json().is_string()) {
      try {
        cie::illuminant(n.string());
      } catch (const InputError& e) {
        n.fail(e.what());
      }
      r.white_balance_illuminant = n.string();
      return;
    }
    r.white_balance_illuminant.reset();
    const std::vector<JsonNode> gains = n.elements();
    if (gains.size() != 3) n.fail("must be 3 gains [r, g, b] or an illuminant name");
    for (int c = 0; c < 3; ++c) r.white_balance[c] = gains[static_cast<std::size_t>(c)].number_above(0);
  });
  read_key(node, "colour_matrix", [&](const JsonNode& n) {
    const std::vector<JsonNode> rows = n.elements();
    if (rows.size() != 3) n.fail("must be 3 rows of 3 numbers");
    for (int i = 0; i < 3; ++i) r.colour_matrix.row(i) = rows[static_cast<std::size_t>(i)].vec3().transpose();
  });
  read_key(node, "white_level", [&](const JsonNode& n) { r.white_level = optional_number(n, 0); });
  read_key(node, "curve", [&](const JsonNode& n) { r.curve = choose(n, kCurves); });
  read_key(node, "gamma", [&](const JsonNode& n) { r.gamma = n.number_above(0); });
  read_key(node, "k", [&](const JsonNode& n) { r.k = n.number_above(0); });
  read_key(node, "clip", [&](const JsonNode& n) { r.clip = n.boolean(); });
  read_key(node, "output_bits", [&](const JsonNode& n) {
    if (n.json().is_null()) {
      r.output_bits.reset();
      return;
    }
    const auto bits = n.integer();
    if (bits != 8 && bits != 16) n.fail(fmt::format("must be 8, 16 or null, got {}", bits));
    r.output_bits = static_cast<int>(bits);
  });
}

void read_display(const JsonNode& node, DisplayConfig& d) {
  node.expect_object({"enabled", "white_balance", "percentile", "level"});
  read_key(node, "enabled", [&](const JsonNode& n) { d.enabled = n.boolean(); });
  read_key(node, "white_balance", [&](const JsonNode& n) {
    const std::string name = n.string();
    if (name == "auto") {
      d.white_balance.reset();
      return;
    }
    try {
      cie::illuminant(name);
    } catch (const InputError& e) {
      n.fail(fmt::format("must be \"auto\" or an illuminant: {}", e.what()));
    }
    d.white_balance = name;
  });
  read_key(node, "percentile", [&](const JsonNode& n) {
    d.percentile = n.number_in(0, 100);
    if (d.percentile == 0) n.fail("must be > 0");
  });
  read_key(node, "level", [&](const JsonNode& n) { d.level = n.number_above(0); });
}

// Settings that are valid one by one but not together. `source_of` names the document that set a path last.
void check_combination(const SensorConfig& c, const std::function<std::string(std::string_view)>& source_of) {
  const auto fail = [&](std::string_view path, const std::string& message) {
    throw InputError(fmt::format("{}: {}: {}", source_of(path), path, message));
  };
  if (c.adc.enabled && c.adc.black_level_dn >= c.adc.max_dn())
    fail("adc.black_level_dn", fmt::format("must be below the ADC's top code {} ({} bits), got {}", c.adc.max_dn(),
                                           c.adc.bits, c.adc.black_level_dn));
  if (c.cfa.enabled && !c.adc.enabled)
    fail("cfa.enabled", "the colour filter array needs the ADC (adc.enabled): OpenCV demosaics digital numbers");
  if (c.cfa.enabled && c.adc.bits > demosaic_max_bits(c.cfa.demosaic))
    fail("cfa.demosaic", fmt::format("{} demosaicing takes at most {}-bit digital numbers, but adc.bits is {}",
                                     demosaic_name(c.cfa.demosaic), demosaic_max_bits(c.cfa.demosaic), c.adc.bits));
}

// Every value's path in a patch ("adc.bits"), for telling which document set it.
void leaf_paths(const Json& value, const std::string& path, std::vector<std::string>& out) {
  if (!value.is_object() || value.empty()) {
    if (!path.empty()) out.push_back(path);
    return;
  }
  for (const auto& [key, child] : value.items()) leaf_paths(child, path.empty() ? key : path + "." + key, out);
}

bool is_csv_path(const Json& value) {
  if (!value.is_string()) return false;
  const std::string text = value.get<std::string>();
  return text.find('/') != std::string::npos || text.ends_with(".csv");
}

void rebase(Json& value, const fs::path& directory) {
  const fs::path path = value.get<std::string>();
  if (path.is_relative()) value = (directory / path).lexically_normal().string();
}

// Every key on its own, without the checks of combinations.
SensorConfig read_settings(const JsonNode& root) {
  root.expect_object({"format", "preset", "description", "notes", "optics", "exposure", "pixel", "spectral_response",
                      "cfa", "noise", "full_well", "adc", "rendering", "display"});
  SensorConfig c;
  read_key(root, "format", [&](const JsonNode& n) {
    if (n.string() != kSensorFormat) n.fail(fmt::format("must be \"{}\", got \"{}\"", kSensorFormat, n.string()));
  });
  // resolve_config applies the preset and checks its name; here it is only recorded.
  read_key(root, "preset", [&](const JsonNode& n) { c.preset = n.non_empty_string(); });
  read_key(root, "description", [&](const JsonNode& n) { c.description = n.string(); });
  // Notes describe one earlier run (config_json writes them); they are no setting.
  read_key(root, "notes", [&](const JsonNode& n) {
    for (const JsonNode& note : n.elements()) note.string();
  });
  read_key(root, "optics", [&](const JsonNode& n) { read_optics(n, c.optics); });
  read_key(root, "exposure", [&](const JsonNode& n) { read_exposure(n, c.exposure); });
  read_key(root, "pixel", [&](const JsonNode& n) { read_pixel(n, c.pixel); });
  if (const auto response = root.find("spectral_response"))
    read_response(*response, c.response);
  else
    c.response.curves = camera_curves(c.response.camera, c.response.columns, root.location());
  read_key(root, "cfa", [&](const JsonNode& n) { read_cfa(n, c.cfa); });
  read_key(root, "noise", [&](const JsonNode& n) { read_noise(n, c.noise); });
  read_key(root, "full_well", [&](const JsonNode& n) { read_full_well(n, c.full_well); });
  read_key(root, "adc", [&](const JsonNode& n) { read_adc(n, c.adc); });
  read_key(root, "rendering", [&](const JsonNode& n) { read_rendering(n, c.rendering); });
  read_key(root, "display", [&](const JsonNode& n) { read_display(n, c.display); });
  return c;
}

}  // namespace

std::string_view pattern_name(BayerPattern pattern) { return name_of(pattern, kPatterns); }
std::string_view demosaic_name(DemosaicMethod method) { return name_of(method, kDemosaic); }
int demosaic_max_bits(DemosaicMethod method) { return method == DemosaicMethod::Vng ? 8 : 16; }

std::optional<double> saturation_electrons(const SensorConfig& config) {
  std::optional<double> limit;
  if (config.full_well.enabled) limit = config.full_well.electrons;
  if (config.adc.enabled) {
    const double adc = (config.adc.max_dn() - config.adc.black_level_dn) / config.adc.gain_dn_per_e;
    limit = limit ? std::min(*limit, adc) : adc;
  }
  return limit;
}

double white_level(const SensorConfig& config) {
  if (config.rendering.white_level) return *config.rendering.white_level;
  if (config.adc.enabled) {
    const double full_well_dn =
        config.full_well.enabled ? config.adc.gain_dn_per_e * config.full_well.electrons : config.adc.max_dn();
    return std::min(config.adc.max_dn() - config.adc.black_level_dn, full_well_dn);
  }
  return saturation_electrons(config).value_or(1.0);
}

SensorConfig parse_config(const JsonNode& root) {
  SensorConfig c = read_settings(root);
  check_combination(c, [&](std::string_view) { return root.source(); });
  return c;
}

ConfigPatch config_patch(Json patch, std::string source, const fs::path& directory) {
  if (patch.is_object() && patch.contains("spectral_response") && patch["spectral_response"].is_object()) {
    Json& response = patch["spectral_response"];
    if (response.contains("camera") && is_csv_path(response["camera"])) rebase(response["camera"], directory);
  }
  if (patch.is_object() && patch.contains("optics") && patch["optics"].is_object()) {
    Json& optics = patch["optics"];
    if (optics.contains("transmittance") && optics["transmittance"].is_object() &&
        optics["transmittance"].contains("csv") && optics["transmittance"]["csv"].is_string())
      rebase(optics["transmittance"]["csv"], directory);
  }
  return ConfigPatch{std::move(patch), std::move(source)};
}

ConfigPatch read_config_patch(const fs::path& file) {
  return config_patch(read_json(file), file.string(), file.parent_path());
}

SensorConfig resolve_config(const std::vector<ConfigPatch>& patches) {
  std::string preset_name = "ideal";
  Json settings = Json::object();
  SensorConfig config = read_settings(JsonNode(preset(preset_name), "preset ideal"));
  std::map<std::string, std::string, std::less<>> set_by;  // path -> the document that set it last
  for (const ConfigPatch& p : patches) {
    const JsonNode root(p.patch, p.source);
    if (!p.patch.is_object()) root.fail(fmt::format("must be a JSON object, got {}", describe_json(p.patch)));
    Json patch = p.patch;
    if (const auto name = root.find("preset")) {
      const std::string wanted = name->non_empty_string();
      const auto& names = preset_names();
      if (std::find(names.begin(), names.end(), wanted) == names.end())
        name->fail(fmt::format("unknown preset \"{}\" (presets: {})", wanted, fmt::join(names, ", ")));
      preset_name = wanted;
      patch.erase("preset");
    }
    settings.merge_patch(patch);
    Json document = preset(preset_name);
    document.merge_patch(settings);
    document["preset"] = preset_name;
    config = read_settings(JsonNode(document, p.source));
    std::vector<std::string> paths;
    leaf_paths(p.patch, "", paths);
    for (const std::string& path : paths) set_by[path] = p.source;
  }
  check_combination(config, [&](std::string_view path) {
    // The path itself, else the closest enclosing object a document replaced, else the preset.
    for (std::string_view prefix = path;;) {
      if (const auto it = set_by.find(prefix); it != set_by.end()) return it->second;
      const std::size_t dot = prefix.rfind('.');
      if (dot == std::string_view::npos) return fmt::format("preset {}", preset_name);
      prefix = prefix.substr(0, dot);
    }
  });
  return config;
}

Json config_json(const SensorConfig& c) {
  const auto optional = [](const std::optional<double>& v) { return v ? Json(*v) : Json(nullptr); };
  Json matrix = Json::array();
  for (int i = 0; i < 3; ++i)
    matrix.push_back(
        {c.rendering.colour_matrix(i, 0), c.rendering.colour_matrix(i, 1), c.rendering.colour_matrix(i, 2)});
  const Eigen::Vector3d& g = c.rendering.white_balance;
  Json json = {
      {"format", kSensorFormat},
      {"preset", c.preset},
      {"description", c.description},
      {"optics",
       {{"enabled", c.optics.enabled},
        {"f_number", c.optics.f_number},
        {"cos4", c.optics.cos4},
        {"fov_deg", optional(c.optics.fov_deg)},
        {"transmittance", c.optics.transmittance ? c.optics.transmittance_spec : Json(nullptr)},
        {"flare", c.optics.flare}}},
      {"exposure",
       {{"time_s", c.exposure.time_s ? Json(*c.exposure.time_s) : Json("auto")},
        {"scale", c.exposure.scale},
        {"auto_percentile", c.exposure.auto_percentile},
        {"auto_level", c.exposure.auto_level},
        {"auto_exclude_emitters", c.exposure.auto_exclude_emitters}}},
      {"pixel",
       {{"pitch_um", c.pixel.pitch_um}, {"fill_factor", c.pixel.fill_factor}, {"supersample", c.pixel.supersample}}},
      {"spectral_response",
       {{"camera", c.response.camera},
        {"columns", c.response.columns},
        {"basis", name_of(c.response.basis, kBases)},
        {"peak_qe", c.response.peak_qe},
        {"outside_curve", name_of(c.response.outside_curve, kOutside)}}},
      {"cfa",
       {{"enabled", c.cfa.enabled},
        {"pattern", pattern_name(c.cfa.pattern)},
        {"demosaic", demosaic_name(c.cfa.demosaic)}}},
      {"noise",
       {{"enabled", c.noise.enabled},
        {"shot", c.noise.shot},
        {"dark_current_e_per_s", c.noise.dark_current_e_per_s},
        {"read_e", c.noise.read_e},
        {"dsnu_e", c.noise.dsnu_e},
        {"prnu", c.noise.prnu},
        {"seed", c.noise.seed},
        {"pattern_seed", c.noise.pattern_seed}}},
      {"full_well", {{"enabled", c.full_well.enabled}, {"electrons", c.full_well.electrons}}},
      {"adc",
       {{"enabled", c.adc.enabled},
        {"gain_dn_per_e", c.adc.gain_dn_per_e},
        {"black_level_dn", c.adc.black_level_dn},
        {"bits", c.adc.bits}}},
      {"rendering",
       {{"enabled", c.rendering.enabled},
        {"white_balance",
         c.rendering.white_balance_illuminant ? Json(*c.rendering.white_balance_illuminant) : Json({g[0], g[1], g[2]})},
        {"colour_matrix", matrix},
        {"white_level", optional(c.rendering.white_level)},
        {"curve", name_of(c.rendering.curve, kCurves)},
        {"gamma", c.rendering.gamma},
        {"k", c.rendering.k},
        {"clip", c.rendering.clip},
        {"output_bits", c.rendering.output_bits ? Json(*c.rendering.output_bits) : Json(nullptr)}}},
      {"display",
       {{"enabled", c.display.enabled},
        {"white_balance", c.display.white_balance ? Json(*c.display.white_balance) : Json("auto")},
        {"percentile", c.display.percentile},
        {"level", c.display.level}}},
      {"notes", c.notes},
  };
  // The row and column patterns are written only when set, so that the settings of every other sensor read as before.
  for (const auto& [key, value] : {std::pair{"dsnu_row_e", c.noise.dsnu_row_e}, std::pair{"dsnu_column_e", c.noise.dsnu_column_e},
                                   std::pair{"prnu_row", c.noise.prnu_row}, std::pair{"prnu_column", c.noise.prnu_column}})
    if (value > 0) json["noise"][key] = value;
  return json;
}

}  // namespace ct::sensor
