// SPDX-License-Identifier: Apache-2.0
#include "analyzer/bend_cause.h"

#include <algorithm>
#include <cmath>

#include <fmt/core.h>
#include <fmt/format.h>

#include "analyzer/explain.h"
#include "analyzer/principal_curve.h"
#include "core/series_format.h"

namespace ct::analyzer {
namespace {

constexpr std::size_t kMaxPoints = 50000;  // as the shape's fits: an even stride over larger regions

Vec3 pixel(const RgbImage& image, std::uint32_t p) {
  const float* v = &image.rgb[static_cast<std::size_t>(p) * 3];
  return Vec3(v[0], v[1], v[2]);
}

// The region's colours in `image`, less those of `leave_out` (sorted), finite ones only.
std::vector<Vec3> colours_of(const Region& region, const std::vector<std::uint32_t>& leave_out, auto&& colour) {
  std::vector<Vec3> out;
  const std::size_t stride = (region.pixels.size() + kMaxPoints - 1) / kMaxPoints;
  for (std::size_t i = 0; i < region.pixels.size(); i += std::max<std::size_t>(1, stride)) {
    const std::uint32_t p = region.pixels[i];
    if (std::binary_search(leave_out.begin(), leave_out.end(), p)) continue;
    const Vec3 c = colour(p);
    if (c.allFinite()) out.push_back(c);
  }
  return out;
}

// The components of one family that `keep` selects, summed per pixel.
struct ComponentSum {
  std::vector<const RgbImage*> layers;
  Vec3 operator()(std::uint32_t p) const {
    Vec3 s = Vec3::Zero();
    for (const RgbImage* layer : layers) s += pixel(*layer, p);
    return s;
  }
};

ComponentSum components_where(const AnalysisImage& input, ComponentFamily family, auto&& keep) {
  ComponentSum sum;
  for (const ComponentLayer& c : input.components)
    if (component_family(c.name) == family && keep(c.name)) sum.layers.push_back(&c.image);
  return sum;
}

bool has_family(const AnalysisImage& input, ComponentFamily family) {
  return std::any_of(input.components.begin(), input.components.end(),
                     [&](const ComponentLayer& c) { return component_family(c.name) == family; });
}

}  // namespace

double bend_of(const std::vector<Vec3>& colours) {
  if (colours.size() < 5) return 0.0;
  std::vector<float> rgb;
  rgb.reserve(colours.size() * 3);
  for (const Vec3& c : colours) rgb.insert(rgb.end(), {static_cast<float>(c[0]), static_cast<float>(c[1]), static_cast<float>(c[2])});
  return fit_principal_curve(colours, moments(rgb, 1)).bend;
}

std::optional<BendCause> find_bend_cause(const AnalysisImage& input, const RgbImage& stored, const Region& region,
                                         const ClusterShape& shape, const ClusterShape* linear_light,
                                         const std::vector<std::uint32_t>& mixed, const ShapeCriteria& k) {
  if (!shape.curve || !(shape.curve->bend > k.max_bend_for_straight)) return std::nullopt;
  BendCause b;
  b.bend = shape.curve->bend;
  b.reference_bend = b.bend;
  auto add = [&](const char* cause, std::string without, double bend) {
    b.tests.push_back({cause, std::move(without), bend, bend <= k.max_bend_for_straight});
  };
  const std::vector<std::uint32_t> none;

  // The camera's curve: the same pixels in linear light.
  if (linear_light) add(kCauseCameraCurve, "the response curve", linear_light->curve ? linear_light->curve->bend : 0.0);

  // Mixing at edges: the region without its mixed edge pixels, as analysed.
  if (mixed.size() >= k.min_mixed_samples)
    add(kCauseEdgeMixing, fmt::format("its {} mixed edge pixels", mixed.size()),
        bend_of(colours_of(region, mixed, [&](std::uint32_t p) { return pixel(stored, p); })));

  // The light paths, from the noise-free linear camera signal of the total.
  if (!input.components.empty()) {
    const ComponentFamily split = has_family(input, ComponentFamily::PathType) ? ComponentFamily::PathType : ComponentFamily::Bounce;
    const ComponentSum all = components_where(input, split, [](const std::string&) { return true; });
    auto total = [&](std::uint32_t p) { return input.linear ? pixel(*input.linear, p) : all(p); };
    b.reference_bend = bend_of(colours_of(region, none, total));
    const ComponentSum glossy = components_where(input, ComponentFamily::PathType,
                                                 [](const std::string& c) { return c.starts_with("glossy_"); });
    if (!glossy.layers.empty())
      add(kCauseHighlight, "the glossy light",
          bend_of(colours_of(region, none, [&](std::uint32_t p) { return Vec3(total(p) - glossy(p)); })));
    const ComponentSum direct = components_where(input, split, [](const std::string& c) { return is_direct(c) == true; });
    const ComponentSum indirect = components_where(input, split, [](const std::string& c) { return is_direct(c) == false; });
    if (!direct.layers.empty() && !indirect.layers.empty())
      add(kCauseInterreflection, "the indirect light", bend_of(colours_of(region, none, direct)));
  }
  if (b.tests.empty()) {
    b.summary = fmt::format("bent {:.3f} (sagitta / chord); no cause could be taken away (no components, curve or mixed pixels)",
                            b.bend);
    return b;
  }

  // Where each test started: the light-path tests from the linear total, the others from the analysed values.
  const auto start = [&](const BendTest& t) {
    return t.cause == kCauseHighlight || t.cause == kCauseInterreflection ? b.reference_bend : b.bend;
  };
  // A cause bends the cluster when taking it away leaves it straight; it adds to the bend when taking it away
  // lowers the bend by more than a straight cluster may bend (the camera's curve bending a highlight further). A
  // light-path test can only name a cause when the light itself is bent (a wall straight in linear light that the
  // camera's curve bends has no light path to blame).
  const auto can_name = [&](const BendTest& t) { return start(t) > k.max_bend_for_straight; };
  for (const BendTest& t : b.tests)
    if (can_name(t) && (t.straight || start(t) - t.bend > k.max_bend_for_straight)) b.causes.push_back(t.cause);
  b.straightened = std::any_of(b.tests.begin(), b.tests.end(), [&](const BendTest& t) { return can_name(t) && t.straight; });
  if (b.causes.empty()) {
    // The one whose removal lowers the bend most, if any lowers it.
    const auto best = std::min_element(b.tests.begin(), b.tests.end(),
                                       [&](const BendTest& x, const BendTest& y) { return x.bend / start(x) < y.bend / start(y); });
    if (can_name(*best) && best->bend < start(*best)) b.causes.push_back(best->cause);
  }
  std::vector<std::string> others, named;
  for (const BendTest& t : b.tests) {
    const bool cause = std::find(b.causes.begin(), b.causes.end(), t.cause) != b.causes.end();
    (cause ? named : others).push_back(fmt::format("{:.3f} without {}", t.bend, t.without));
  }
  std::vector<std::string> phrases;
  for (const std::string& c : b.causes) phrases.push_back(bend_cause_phrase(c));
  if (b.causes.empty())
    b.summary = fmt::format("bent {:.3f} (sagitta / chord), by none of the {}: {}", b.bend,
                            "camera curve, mixing at edges, highlight lobe or interreflection", fmt::join(others, ", "));
  else
    b.summary = fmt::format("bent {:.3f} (sagitta / chord) {}by {}: {}{}{}", b.bend, b.causes.size() > 1 || b.straightened ? "" : "mostly ",
                            fmt::join(phrases, " and "), fmt::join(named, ", "), others.empty() ? "" : "; ",
                            fmt::join(others, ", "));
  return b;
}

}  // namespace ct::analyzer
