// SPDX-License-Identifier: Apache-2.0
// chromatrace info FILE: describes an image (spectral EXR or any other EXR, or a camera raw), like
// `oiiotool --info -v`.
#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "analyzer/raw_input.h"
#include "cli/app.h"
#include "cli/command.h"
#include "core/error.h"
#include "core/json_input.h"
#include "core/parallel.h"
#include "core/progress.h"
#include "core/spectral_exr.h"
#include "core/spectral_exr_scan.h"

namespace ct::cli {
namespace {

struct InfoOptions {
  std::string file;
  bool json = false;
  bool check = false;
  int threads = 0;
  bool quiet = false;
};

// Decoding this many values takes about a second, the point from which commands show progress.
constexpr std::uint64_t kValuesWorthProgress = std::uint64_t{1} << 26;

bool uniform_widths(const Bands& bands) {
  for (std::size_t i = 1; i < bands.size(); ++i)
    if (std::abs(bands.width(i) - bands.width(0)) > 1e-9 * bands.width(0)) return false;
  return true;
}

std::string join(const std::vector<std::string>& items) {
  std::string text;
  for (const std::string& item : items) text += (text.empty() ? "" : ", ") + item;
  return items.empty() ? "none" : text;
}

std::string bands_text(const SpectralExrInfo& info) {
  const Bands& bands = info.bands;
  std::string source = info.edges_from_file ? "edges from chromatrace.bandEdgesNm" : "edges halfway between centres";
  if (const BandReconstruction* r = bands.reconstruction())
    source += fmt::format("; values reconstructed into {} bands of {} nm from {} nm by chromatrace.bandReconstruction",
                          r->fine, r->step_nm, r->lo_nm);
  std::string text = fmt::format("{} bands, {}-{} nm, centres {}-{} nm, ", bands.size(), bands.min_wavelength(),
                                 bands.max_wavelength(), info.centres_nm.front(), info.centres_nm.back());
  if (uniform_widths(bands)) return text + fmt::format("width {} nm ({})", bands.width(0), source);
  std::vector<std::string> edges;
  for (double edge : bands.edges()) edges.push_back(fmt::format("{}", edge));
  return text + fmt::format("edges {} nm ({})", join(edges), source);
}

std::string units_text(const SpectralExrInfo& info) {
  std::vector<std::string> units;
  if (info.emissive) units.push_back(info.emissive_units.value_or("W.m^-2.sr^-1 (assumed)") + " (S channels)");
  if (info.reflective) units.push_back("dimensionless reflectance (T channels)");
  return join(units);
}

std::vector<std::string> component_names(const SpectralExrInfo& info) {
  std::vector<std::string> names;
  for (const SpectralLayer& layer : info.layers)
    if (!layer.component.empty() && (names.empty() || names.back() != layer.component))
      names.push_back(layer.component);
  return names;
}

std::string components_text(const SpectralExrInfo& info) {
  std::vector<std::string> groups;
  for (ComponentFamily family :
       {ComponentFamily::PathType, ComponentFamily::LightGroup, ComponentFamily::Bounce, ComponentFamily::Unknown}) {
    std::vector<std::string> members;
    for (const std::string& name : component_names(info))
      if (component_family(name) == family) members.push_back(name);
    if (!members.empty()) groups.push_back(fmt::format("{} ({})", join(members), family_name(family)));
  }
  std::string text;
  for (const std::string& group : groups) text += (text.empty() ? "" : "; ") + group;
  return groups.empty() ? "none" : text;
}

std::string object_ids_text(const SpectralExrInfo& info) {
  if (!info.has_object_ids) return "none";
  std::vector<std::string> names;
  for (const auto& [id, name] : info.object_names) names.push_back(fmt::format("{} {}", id, name));
  return fmt::format("channel object_id; names: {}", join(names));
}

std::string other_channels_text(const SpectralExrInfo& info) {
  std::vector<std::string> items;
  for (const std::string& name : info.other_channels)
    for (const ExrChannel& channel : info.channels)
      if (channel.name == name) items.push_back(fmt::format("{} ({})", name, pixel_type_name(channel.type)));
  return join(items);
}

// The layout's own attributes first, then the rest of the header.
std::vector<std::pair<std::string, std::string>> metadata_items(const SpectralExrInfo& info) {
  std::vector<std::pair<std::string, std::string>> items;
  if (info.layout_version) items.emplace_back("spectralLayoutVersion", *info.layout_version);
  if (info.emissive_units) items.emplace_back("emissiveUnits", *info.emissive_units);
  if (info.polarisation_handedness) items.emplace_back("polarisationHandedness", *info.polarisation_handedness);
  if (info.ev) items.emplace_back("EV", fmt::format("{}", *info.ev));
  for (const auto& [name, value] : info.metadata) items.emplace_back(name, value);
  return items;
}

std::string check_text(const ComponentSumCheck& check) {
  const std::string what = fmt::format("{} ({})", family_name(check.family), quantity_name(check.quantity));
  if (!check.checked && check.family == ComponentFamily::PathType)
    return fmt::format("{}: not checked, only {} of the {} path types present", what, check.components.size(),
                       path_type_components().size());
  if (!check.checked) return fmt::format("{}: not checked, no total {} layer", what, quantity_name(check.quantity));
  return fmt::format("{}: {} components {} the total (worst {:.3g} of the tolerance, at {} pixel ({}, {}))", what,
                     check.components.size(), check.passed() ? "sum to" : "do NOT sum to", check.worst_ratio,
                     check.channel, check.x, check.y);
}

void print_text(const SpectralExrInfo& info, const std::optional<SpectralExrScan>& scan, bool check) {
  auto line = [](std::string_view label, const std::string& value) { fmt::print("{:<16}{}\n", label, value); };
  line("file", fmt::format("{} ({} bytes)", info.file, info.file_bytes));
  line("image", fmt::format("{} x {}, origin ({}, {}), {} compression, {} channels", info.width, info.height,
                            info.origin_x, info.origin_y, info.compression, info.channels.size()));
  line("kind", info.kind());
  if (info.spectral()) {
    line("bands", bands_text(info));
    line("units", units_text(info));
    std::vector<std::string> layers;
    for (const SpectralLayer& layer : info.layers)
      if (layer.component.empty()) layers.push_back(layer.name());
    line("total", join(layers));
    line("components", components_text(info));
    if (info.bispectral)
      line("re-radiation", fmt::format("{} channels T.<in>.<out>", info.reradiation_channels.size()));
  }
  line("object ids", object_ids_text(info));
  line("other channels", other_channels_text(info));
  fmt::print("metadata\n");
  for (const auto& [name, value] : metadata_items(info)) fmt::print("  {} = {}\n", name, value);
  if (!info.notes.empty()) fmt::print("notes\n");
  for (const std::string& note : info.notes) fmt::print("  {}\n", note);
  if (!scan) return;
  if (check && scan->component_sums.empty()) line("check", "no path-type, light-group or bounce layers to check");
  for (const ComponentSumCheck& sum : scan->component_sums) line("check", check_text(sum));
  fmt::print("{} per band (finite values): min / mean / max\n", info.total().name());
  for (std::size_t i = 0; i < scan->total_statistics.size(); ++i) {
    const BandStatistics& s = scan->total_statistics[i];
    fmt::print("  {:>10} nm {:>14.6g} {:>14.6g} {:>14.6g}\n", info.centres_nm[i], s.min, s.mean, s.max);
  }
}

nlohmann::json to_json(const SpectralExrInfo& info, const std::optional<SpectralExrScan>& scan) {
  nlohmann::json j;
  j["file"] = info.file;
  j["file_bytes"] = info.file_bytes;
  j["width"] = info.width;
  j["height"] = info.height;
  j["origin"] = {info.origin_x, info.origin_y};
  j["compression"] = info.compression;
  j["kind"] = info.kind();
  j["spectral"] = info.spectral();
  j["emissive"] = info.emissive;
  j["reflective"] = info.reflective;
  j["polarised"] = info.polarised;
  j["bispectral"] = info.bispectral;
  for (const ExrChannel& channel : info.channels)
    j["channels"].push_back({{"name", channel.name}, {"type", pixel_type_name(channel.type)}});
  if (info.spectral()) {
    j["bands"] = {{"count", info.bands.size()},
                  {"centres_nm", info.centres_nm},
                  {"edges_nm", info.bands.edges()},
                  {"edges_from", info.edges_from_file ? "chromatrace.bandEdgesNm" : "centres"}};
    if (const BandReconstruction* r = info.bands.reconstruction())
      j["bands"]["reconstruction"] = {{"lo_nm", r->lo_nm}, {"step_nm", r->step_nm}, {"fine_bands", r->fine}};
    j["emissive_units"] = info.emissive_units ? nlohmann::json(*info.emissive_units) : nlohmann::json();
    for (const SpectralLayer& layer : info.layers)
      j["layers"].push_back(
          {{"name", layer.name()},
           {"component", layer.component},
           {"quantity", quantity_name(layer.quantity)},
           {"family", layer.component.empty() ? "total" : family_name(component_family(layer.component))}});
    j["reradiation_channels"] = info.reradiation_channels.size();
  }
  j["object_ids"] = nullptr;
  if (info.has_object_ids) {
    nlohmann::json names = nlohmann::json::object();
    for (const auto& [id, name] : info.object_names) names[std::to_string(id)] = name;
    j["object_ids"] = {{"channel", "object_id"}, {"names", names}};
  }
  j["other_channels"] = info.other_channels;
  j["metadata"] = nlohmann::json::object();
  for (const auto& [name, value] : metadata_items(info)) j["metadata"][name] = value;
  j["notes"] = info.notes;
  if (!scan) return j;
  nlohmann::json statistics = {{"layer", info.total().name()}};
  for (const BandStatistics& s : scan->total_statistics) {
    statistics["min"].push_back(s.min);
    statistics["mean"].push_back(s.mean);
    statistics["max"].push_back(s.max);
  }
  j["statistics"] = statistics;
  j["non_finite"] = nlohmann::json::array();
  for (const NonFiniteCount& n : scan->non_finite)
    j["non_finite"].push_back({{"channel", n.channel}, {"count", n.count}, {"first", {n.first_x, n.first_y}}});
  for (const ComponentSumCheck& check : scan->component_sums)
    j["checks"].push_back({{"family", family_name(check.family)},
                           {"quantity", quantity_name(check.quantity)},
                           {"components", check.components},
                           {"checked", check.checked},
                           {"passed", check.passed()},
                           {"worst_ratio", check.worst_ratio},
                           {"channel", check.channel},
                           {"pixel", {check.x, check.y}},
                           {"sum", check.sum},
                           {"total", check.total},
                           {"tolerance", check.tolerance}});
  return j;
}

// NaN/Inf values: one line on stderr (exit 2), after the description.
void fail_on_non_finite(const SpectralExrInfo& info, const std::vector<NonFiniteCount>& non_finite) {
  if (!non_finite.empty()) {
    const NonFiniteCount& first = non_finite.front();
    const std::size_t others = non_finite.size() - 1;
    const std::string more = others == 0   ? ""
                             : others == 1 ? "; 1 more channel has NaN/Inf"
                                           : fmt::format("; {} more channels have NaN/Inf", others);
    throw InputError(fmt::format("{}: {} NaN/Inf values in channel {} (first at {},{}){}", info.file, first.count,
                                 first.channel, first.first_x, first.first_y, more));
  }
}

// A bad file is one line on stderr (exit 2), after the description.
void fail_on_bad_pixels(const SpectralExrInfo& info, const SpectralExrScan& scan) {
  fail_on_non_finite(info, scan.non_finite);
  for (const ComponentSumCheck& check : scan.component_sums)
    if (!check.passed())
      throw InputError(
          fmt::format("{}: channel {}: pixel ({}, {}): the {} sum to {:.9g} but the total is {:.9g} "
                      "(difference {:.3g} exceeds the rounding tolerance {:.3g})",
                      info.file, check.channel, check.x, check.y, family_name(check.family), check.sum, check.total,
                      std::abs(check.sum - check.total), check.tolerance));
}

// A camera raw (DNG, CR2, NEF, …): what LibRaw reads of it, as text or JSON.
int run_raw_info(const InfoOptions& options) {
  const auto items = analyzer::describe_camera_raw(options.file);
  if (options.json) {
    nlohmann::json j = {{"file", options.file}, {"kind", "camera raw"}};
    for (const auto& [key, value] : items) j[key] = value;
    fmt::print("{}\n", j.dump(2, ' ', false, kReplaceInvalidUtf8));
  } else {
    fmt::print("{:<16}{}\n", "file", options.file);
    fmt::print("{:<16}{}\n", "kind", "camera raw");
    for (const auto& [key, value] : items) fmt::print("{:<16}{}\n", key, value);
  }
  return 0;
}

int run_info(const InfoOptions& options) {
  if (analyzer::is_camera_raw(options.file)) return run_raw_info(options);
  set_exr_threads(thread_count(options.threads));
  SpectralExrReader reader(options.file);
  const SpectralExrInfo& info = reader.info();

  std::optional<SpectralExrScan> scan;
  if (info.spectral() || options.check) {
    std::uint64_t values = static_cast<std::uint64_t>(info.width) * static_cast<std::uint64_t>(info.height);
    values *= info.channels.size();
    Progress progress("info", static_cast<std::size_t>(info.height), !options.quiet && values >= kValuesWorthProgress);
    int rows_done = 0;
    ScanOptions scan_options;
    scan_options.check_components = options.check;
    scan_options.progress = [&](int rows) {
      progress.advance(static_cast<std::size_t>(rows - rows_done));
      rows_done = rows;
    };
    scan = scan_spectral_exr(reader, scan_options);
  }

  if (options.json)
    fmt::print("{}\n", to_json(info, scan).dump(2, ' ', false, kReplaceInvalidUtf8));
  else
    print_text(info, scan, options.check);
  if (scan) fail_on_bad_pixels(info, *scan);
  else fail_on_non_finite(info, scan_non_finite(reader));  // any image: a camera RGB one from sensor too
  return 0;
}

}  // namespace

Action add_info(CLI::App& app) {
  auto options = std::make_shared<InfoOptions>();
  CLI::App* sub = add_command(app, "info");
  sub->add_option("file", options->file, "OpenEXR file (spectral or not), or a camera raw (DNG, CR2, NEF, …)")->required();
  sub->add_flag("--json", options->json, "Print one JSON object instead of text");
  sub->add_flag("--check", options->check,
                "Also verify that each family of component layers sums to the total within float rounding "
                "(exit 2 if not)");
  sub->add_option("--threads", options->threads, "Decoding threads (default: all)")->check(CLI::NonNegativeNumber);
  sub->add_flag("--quiet", options->quiet, "No progress on stderr");
  return [options] { return run_info(*options); };
}

}  // namespace ct::cli
