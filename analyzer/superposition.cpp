// SPDX-License-Identifier: Apache-2.0
#include "analyzer/superposition.h"

#include <algorithm>
#include <cmath>

#include <fmt/core.h>
#include <fmt/format.h>

#include "analyzer/line_fit.h"
#include "core/spectral_channel_name.h"

namespace ct::analyzer {

std::optional<Superposition> find_superposition(const AnalysisImage& input, const Region& region, const ShapeCriteria& criteria) {
  Superposition s;
  double total = 0;
  for (const ComponentLayer& layer : input.components) {
    if (component_family(layer.name) != ComponentFamily::LightGroup) continue;
    Vec3 sum = Vec3::Zero();
    for (const std::uint32_t p : region.pixels)
      for (int c = 0; c < 3; ++c) {
        const float v = layer.image.rgb[3 * static_cast<std::size_t>(p) + static_cast<std::size_t>(c)];
        if (std::isfinite(v)) sum[c] += v;
      }
    s.groups.push_back({layer.name, sum.sum(), sum.norm() > 0 ? Vec3(sum.normalized()) : Vec3(Vec3::Zero())});
    total += sum.sum();
  }
  if (s.groups.size() < 2) return std::nullopt;
  for (LightGroupShare& g : s.groups) g.share = total > 0 ? g.share / total : 0.0;
  std::sort(s.groups.begin(), s.groups.end(), [](const auto& a, const auto& b) { return a.share > b.share; });
  for (std::size_t i = 0; i < s.groups.size(); ++i)
    for (std::size_t j = i + 1; j < s.groups.size(); ++j)
      if (s.groups[i].share >= criteria.superposed_share && s.groups[j].share >= criteria.superposed_share)
        s.angle_deg = std::max(s.angle_deg, line_angle_degrees(s.groups[i].colour, s.groups[j].colour));
  s.superposed = s.groups[1].share >= criteria.superposed_share && s.angle_deg >= criteria.min_line_angle_deg;
  return s;
}

void apply_superposition(ClusterShape& shape, const Superposition& superposition, const ShapeCriteria& criteria) {
  if (shape.shape == ShapeClass::None || shape.shape == ShapeClass::Clipped || shape.shape == ShapeClass::Point) return;
  const double second = superposition.groups[1].share;
  const bool shares = second >= criteria.superposed_share;
  shape.decisions.push_back({"second light group's share >= superposed_share", second, criteria.superposed_share, shares});
  if (!shares) return;
  const bool turned = superposition.angle_deg >= criteria.min_line_angle_deg;
  shape.decisions.push_back(
      {"angle between light groups' colours (deg) >= min_line_angle_deg", superposition.angle_deg, criteria.min_line_angle_deg, turned});
  if (!turned) return;
  std::vector<std::string> groups;
  for (const LightGroupShare& g : superposition.groups)
    if (g.share >= criteria.superposed_share) groups.push_back(fmt::format("{} ({:.0f} %)", g.name, 100 * g.share));
  shape.reason = fmt::format("the structures of {} superposed, their colours {:.1f}° apart; the sum is {}", fmt::join(groups, " and "),
                             superposition.angle_deg, class_name(shape.shape));
  shape.shape = ShapeClass::Superposed;
}

}  // namespace ct::analyzer
