// SPDX-License-Identifier: Apache-2.0
#include "analyzer/explain.h"

#include <algorithm>
#include <cmath>

#include "analyzer/cluster_shape.h"

namespace ct::analyzer {
namespace {

const ComponentFamily kFamilies[] = {ComponentFamily::PathType, ComponentFamily::LightGroup, ComponentFamily::Bounce};

double pixel_sum(const RgbImage& image, std::uint32_t p) {
  const float* v = &image.rgb[static_cast<std::size_t>(p) * 3];
  const double s = static_cast<double>(v[0]) + v[1] + v[2];
  return std::isfinite(s) ? s : 0.0;
}

Vec3 pixel(const RgbImage& image, std::uint32_t p) {
  const float* v = &image.rgb[static_cast<std::size_t>(p) * 3];
  return Vec3(v[0], v[1], v[2]);
}

std::vector<std::size_t> members(const AnalysisImage& input, ComponentFamily family) {
  std::vector<std::size_t> m;
  for (std::size_t c = 0; c < input.components.size(); ++c)
    if (component_family(input.components[c].name) == family) m.push_back(c);
  return m;
}

// The rms distance of colours from a plane through black (normal) or a line through black (direction).
double rms_off(const std::vector<Vec3>& colours, const Vec3& direction, bool plane) {
  double squares = 0;
  for (const Vec3& x : colours) squares += plane ? std::pow(x.dot(direction), 2) : (x - x.dot(direction) * direction).squaredNorm();
  return colours.empty() ? 0.0 : std::sqrt(squares / static_cast<double>(colours.size()));
}

std::optional<OffStructure> off_structure(const AnalysisImage& input, const Region& region, ComponentFamily family) {
  std::vector<std::size_t> direct, indirect;
  for (const std::size_t c : members(input, family)) {
    const auto d = is_direct(input.components[c].name);
    if (d) (*d ? direct : indirect).push_back(c);
  }
  if (direct.empty() || indirect.empty()) return std::nullopt;
  std::vector<Vec3> direct_colours, total_colours;
  for (const std::uint32_t p : region.pixels) {
    Vec3 d = Vec3::Zero(), i = Vec3::Zero();
    for (const std::size_t c : direct) d += pixel(input.components[c].image, p);
    for (const std::size_t c : indirect) i += pixel(input.components[c].image, p);
    if (!d.allFinite() || !i.allFinite()) continue;
    direct_colours.push_back(d);
    total_colours.push_back(d + i);
  }
  if (direct_colours.size() < 3) return std::nullopt;
  const PrincipalAxes direct_axes = principal_axes_of(direct_colours, About::Black);
  OffStructure o;
  // A matte object's direct light is a line through black: a plane through it would be arbitrary.
  const bool plane = direct_axes.values[1] > 1e-6 * direct_axes.values[0];
  o.structure = plane ? "dichromatic plane" : "body line";
  o.direction = plane ? plane_through_black(direct_colours).normal : Vec3(direct_axes.axes.col(0));
  o.rms_total = rms_off(total_colours, o.direction, plane);
  o.rms_direct = rms_off(direct_colours, o.direction, plane);
  o.indirect_share = o.rms_total > 0 ? std::clamp(1.0 - std::pow(o.rms_direct / o.rms_total, 2), 0.0, 1.0) : 0.0;
  return o;
}

}  // namespace

std::optional<bool> is_direct(const std::string& c) {
  if (c == "emission" || c.ends_with("_direct") || c == "bounce.0" || c == "bounce.1") return true;
  if (c.ends_with("_indirect") || (c.starts_with("bounce.") && c != "bounce.0" && c != "bounce.1")) return false;
  return std::nullopt;
}

std::optional<Explanation> explain_region(const AnalysisImage& input, const Region& region) {
  if (input.components.empty()) return std::nullopt;
  Explanation e;
  // Energies per component over the region; the total is the linear layer, else the sum of a family.
  std::vector<double> energy(input.components.size(), 0.0);
  for (std::size_t c = 0; c < input.components.size(); ++c)
    for (const std::uint32_t p : region.pixels) energy[c] += pixel_sum(input.components[c].image, p);
  double total = 0;
  if (input.linear) {
    for (const std::uint32_t p : region.pixels) total += pixel_sum(*input.linear, p);
  } else {
    for (const ComponentFamily f : kFamilies)
      if (const auto m = members(input, f); !m.empty()) {
        for (const std::size_t c : m) total += energy[c];
        break;
      }
    e.notes.push_back("no linear layer: shares are of the sum of the components");
  }
  if (!(total > 0)) {
    e.notes.push_back("the region receives no light: no shares");
    return e;
  }
  for (const ComponentFamily f : kFamilies) {
    const std::vector<std::size_t> m = members(input, f);
    if (m.empty()) continue;
    FamilyShares shares{f, {}};
    std::vector<std::size_t> wins(m.size(), 0);
    for (const std::uint32_t p : region.pixels) {
      std::size_t best = 0;
      double largest = 0;
      for (std::size_t k = 0; k < m.size(); ++k)
        if (const double v = pixel_sum(input.components[m[k]].image, p); v > largest) largest = v, best = k;
      if (largest > 0) ++wins[best];
    }
    for (std::size_t k = 0; k < m.size(); ++k)
      shares.components.push_back({input.components[m[k]].name, energy[m[k]] / total,
                                   static_cast<double>(wins[k]) / static_cast<double>(region.pixels.size())});
    e.families.push_back(std::move(shares));
  }
  auto share_of = [&](ComponentFamily family, auto&& keep) -> std::optional<double> {
    const std::vector<std::size_t> m = members(input, family);
    if (m.empty()) return std::nullopt;
    double sum = 0;
    for (const std::size_t c : m)
      if (keep(input.components[c].name)) sum += energy[c];
    return sum / total;
  };
  const ComponentFamily split_family = members(input, ComponentFamily::PathType).empty() ? ComponentFamily::Bounce : ComponentFamily::PathType;
  e.direct_share = share_of(split_family, [](const std::string& c) { return is_direct(c) == true; });
  e.indirect_share = share_of(split_family, [](const std::string& c) { return is_direct(c) == false; });
  e.diffuse_share = share_of(ComponentFamily::PathType, [](const std::string& c) { return c.starts_with("diffuse_"); });
  e.glossy_share = share_of(ComponentFamily::PathType, [](const std::string& c) { return c.starts_with("glossy_"); });
  e.off_structure = off_structure(input, region, split_family);
  if (!e.off_structure) e.notes.push_back("no direct and indirect components to split: no off-plane attribution");
  return e;
}

double noise_across(const OffStructure& off, const ClusterShape& shape) {
  const Vec3& n = shape.noise_sigma;
  return off.structure == "dichromatic plane" ? n[2] : std::hypot(n[1], n[2]);
}

bool thickened_by_interreflection(const Explanation& explanation, const ClusterShape& shape) {
  const std::optional<OffStructure>& off = explanation.off_structure;
  return off && off->indirect_share >= kThickeningIndirectShare &&
         off->rms_total > ShapeCriteria{}.noise_factor * noise_across(*off, shape);
}

std::vector<int> dominant_component_map(const AnalysisImage& input) {
  for (const ComponentFamily f : kFamilies) {
    const std::vector<std::size_t> m = members(input, f);
    if (m.empty()) continue;
    const std::size_t n = input.image.pixel_count();
    std::vector<int> map(n, -1);
    for (std::size_t p = 0; p < n; ++p) {
      double largest = 0;
      for (const std::size_t c : m)
        if (const double v = pixel_sum(input.components[c].image, static_cast<std::uint32_t>(p)); v > largest)
          largest = v, map[p] = static_cast<int>(c);
    }
    return map;
  }
  return {};
}

}  // namespace ct::analyzer
