#include "core/band_plan.h"

#include <string>
#include <vector>

#include <fmt/core.h>

#include "core/json_input.h"

namespace ct {

Bands read_band_plan(const std::filesystem::path& file) {
  const Json document = read_json(file);
  const JsonNode root(document, file.string());
  const std::string format = root["format"].string();
  if (format != "chromatrace-bands/1") root["format"].fail(fmt::format("must be \"chromatrace-bands/1\", got \"{}\"", format));
  root.expect_object({"format", "edges_nm"});
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
  return Bands::from_edges(std::move(edges), edges_node.location());
}

}  // namespace ct
