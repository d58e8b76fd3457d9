// SPDX-License-Identifier: Apache-2.0
#include "core/band_plan.h"

#include <limits>
#include <string>
#include <vector>

#include <fmt/core.h>

#include "core/error.h"
#include "core/json_input.h"

namespace ct {

BandPlanFile read_band_plan_file(const std::filesystem::path& file) {
  const Json document = read_json(file);
  const JsonNode root(document, file.string());
  const std::string format = root["format"].string();
  if (format != "chromatrace-bands/1") root["format"].fail(fmt::format("must be \"chromatrace-bands/1\", got \"{}\"", format));
  root.expect_object(
      {"format", "edges_nm", "reconstruction", "cycles_samples", "cycles_guided_groups", "cycles_guided_threshold",
       "cycles_light_tree"});
  const JsonNode edges_node = root["edges_nm"];
  std::vector<double> edges;
  for (const JsonNode& edge : edges_node.elements()) {
    const double nm = edge.number();
    if (!edges.empty() && !(nm > edges.back()))
      edge.fail(fmt::format("edges must increase, but {} follows {}", nm, edges.back()));
    edges.push_back(nm);
  }
  if (edges.size() < 2) edges_node.fail(fmt::format("needs at least 2 edges (one band), got {}", edges.size()));
  if (edges.back() <= 360.0 || edges.front() >= 830.0)
    edges_node.fail(fmt::format("bands [{}, {}] nm do not overlap the visible range 360-830 nm (wavelengths in nm?)",
                                edges.front(), edges.back()));
  BandPlanFile plan{Bands::from_edges(std::move(edges), edges_node.location()), {}, {}, 0.0, std::nullopt};
  if (const auto r = root.find("reconstruction")) plan.bands = read_reconstruction(*r, plan.bands);
  if (const auto samples = root.find("cycles_samples")) {
    const std::vector<JsonNode> groups = samples->elements();
    const std::size_t wanted = cycles_band_groups(plan.bands.size());
    if (groups.size() != wanted)
      samples->fail(fmt::format("{} entries, needs one per Cycles band group of three bands ({} for {} bands)",
                                groups.size(), wanted, plan.bands.size()));
    for (const JsonNode& g : groups) plan.cycles_samples.push_back(static_cast<int>(g.integer_in(1, std::numeric_limits<int>::max())));
  }
  if (const auto guided = root.find("cycles_guided_groups")) {
    if (plan.cycles_samples.empty()) guided->fail("needs cycles_samples: the guided groups are those rendered with fewer");
    const std::size_t groups = plan.cycles_samples.size();
    for (const JsonNode& g : guided->elements()) {
      const auto group = static_cast<std::size_t>(g.integer_in(0, static_cast<std::int64_t>(groups) - 1));
      if (!plan.cycles_guided_groups.empty() && group <= plan.cycles_guided_groups.back())
        g.fail("groups must increase");
      plan.cycles_guided_groups.push_back(group);
    }
    if (plan.cycles_guided_groups.size() == groups) guided->fail("names every group: none is left to guide them");
  }
  if (const auto threshold = root.find("cycles_guided_threshold")) {
    if (plan.cycles_guided_groups.empty()) threshold->fail("needs cycles_guided_groups: it is their adaptive sampling's");
    plan.cycles_guided_threshold = threshold->number_in(1e-4, 1.0);
  }
  if (const auto light_tree = root.find("cycles_light_tree")) plan.cycles_light_tree = light_tree->boolean();
  return plan;
}

Bands read_band_plan(const std::filesystem::path& file) { return read_band_plan_file(file).bands; }

Json band_plan_document(const Bands& bands, const std::vector<int>& cycles_samples,
                        const std::vector<std::size_t>& cycles_guided_groups, double cycles_guided_threshold) {
  Json j;
  j["format"] = "chromatrace-bands/1";
  j["edges_nm"] = bands.edges();
  if (const BandReconstruction* r = bands.reconstruction()) j["reconstruction"] = reconstruction_json(*r);
  if (!cycles_samples.empty()) j["cycles_samples"] = cycles_samples;
  if (!cycles_guided_groups.empty()) j["cycles_guided_groups"] = cycles_guided_groups;
  if (cycles_guided_threshold > 0) j["cycles_guided_threshold"] = cycles_guided_threshold;
  return j;
}

Json reconstruction_json(const BandReconstruction& r) {
  const std::size_t n = r.fine ? r.matrix.size() / r.fine : 0;
  Json rows = Json::array();
  for (std::size_t j = 0; j < r.fine; ++j)
    rows.push_back(std::vector<double>(r.matrix.begin() + static_cast<std::ptrdiff_t>(j * n),
                                       r.matrix.begin() + static_cast<std::ptrdiff_t>((j + 1) * n)));
  return Json{{"lo_nm", r.lo_nm}, {"step_nm", r.step_nm}, {"matrix", rows}};
}

Bands read_reconstruction(const JsonNode& node, const Bands& bands) {
  node.expect_object({"lo_nm", "step_nm", "matrix"});
  BandReconstruction r;
  r.lo_nm = node["lo_nm"].number_above(0);
  r.step_nm = node["step_nm"].number_above(0);
  const std::vector<JsonNode> rows = node["matrix"].elements();
  r.fine = rows.size();
  for (const JsonNode& row : rows) {
    const std::vector<JsonNode> entries = row.elements();
    if (entries.size() != bands.size())
      row.fail(fmt::format("{} entries, needs one per band ({})", entries.size(), bands.size()));
    for (const JsonNode& e : entries) r.matrix.push_back(e.number());
  }
  return bands.with_reconstruction(std::move(r), node["matrix"].location());
}

std::vector<std::vector<std::size_t>> cycles_render_groups(std::size_t band_count, int per_render) {
  if (per_render < 1 || per_render > 3)
    throw InputError(fmt::format("bands per render must be 1 to 3, got {}", per_render));
  const auto per = static_cast<std::size_t>(per_render);
  const std::size_t renders = (band_count + per - 1) / per;
  std::vector<std::vector<std::size_t>> groups(renders);
  for (std::size_t b = 0; b < band_count; ++b) groups[b % renders].push_back(b);
  return groups;
}

}  // namespace ct
