// SPDX-License-Identifier: Apache-2.0
#include "analyzer/edge_mixing.h"

#include <algorithm>
#include <cmath>

#include <fmt/core.h>
#include <fmt/format.h>

namespace ct::analyzer {
namespace {

Vec3 colour(const RgbImage& image, std::size_t p) {
  return Vec3(image.rgb[3 * p], image.rgb[3 * p + 1], image.rgb[3 * p + 2]);
}

}  // namespace

EdgeMixing find_edge_mixing(const RgbImage& layer, const std::vector<std::int32_t>& labels, const Region& region,
                            std::int32_t label, double noise) {
  EdgeMixing m;
  const int w = layer.width, h = layer.height;
  const auto id = [&](int x, int y) { return labels[static_cast<std::size_t>(y) * w + x]; };
  const auto inside = [&](int x, int y) { return x >= 0 && y >= 0 && x < w && y < h; };
  // The 4-neighbours first, then the diagonal ones: on a slanted edge a pixel may touch the other object
  // only at a corner and still be partly covered by it.
  static constexpr int kSteps[8][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}, {1, 1}, {-1, -1}, {1, -1}, {-1, 1}};
  for (const std::uint32_t p : region.pixels) {
    const int x = static_cast<int>(p % static_cast<std::uint32_t>(w)), y = static_cast<int>(p / static_cast<std::uint32_t>(w));
    bool edge = false, mixed = false;
    std::int32_t towards = label;
    for (const auto& [dx, dy] : kSteps) {
      if (!inside(x + dx, y + dy) || id(x + dx, y + dy) == label) continue;
      edge = true;
      // A's colour one step inside, B's one step beyond the neighbour (the neighbour may itself be mixed).
      if (!inside(x - dx, y - dy) || id(x - dx, y - dy) != label) continue;
      const std::int32_t other = id(x + dx, y + dy);
      const bool far = inside(x + 2 * dx, y + 2 * dy) && id(x + 2 * dx, y + 2 * dy) == other;
      // A's colour at the edge pixel: extrapolated from the two pixels behind it, since shading, shadows and
      // an offset (flare, black level) under a tone curve turn a colour smoothly across an object, while a
      // mix turns it at the edge pixel alone. Where the object is not three pixels deep along the step, the
      // step cannot tell the two apart and is not judged.
      if (!inside(x - 2 * dx, y - 2 * dy) || id(x - 2 * dx, y - 2 * dy) != label) continue;
      const Vec3 a = 2 * colour(layer, static_cast<std::size_t>(y - dy) * w + (x - dx)) -
                     colour(layer, static_cast<std::size_t>(y - 2 * dy) * w + (x - 2 * dx));
      const Vec3 b = colour(layer, far ? static_cast<std::size_t>(y + 2 * dy) * w + (x + 2 * dx)
                                       : static_cast<std::size_t>(y + dy) * w + (x + dx));
      const Vec3 c = colour(layer, p);
      if (!a.allFinite() || !b.allFinite() || !c.allFinite() || a.norm() <= 0 || b.norm() <= 0 || c.norm() <= 0) continue;
      // Compared by direction (chromaticity): shading from pixel to pixel changes a colour's length, a mix
      // turns it from A's colour towards B's.
      const Vec3 ua = a.normalized(), ub = b.normalized(), uc = c.normalized();
      const double apart = std::acos(std::clamp(ua.dot(ub), -1.0, 1.0));
      const double noise_angle = 3 * noise / c.norm();
      if (apart <= std::max(noise_angle, 1e-3)) continue;  // the two sides have one colour: nothing to tell apart
      const double from_a = std::acos(std::clamp(ua.dot(uc), -1.0, 1.0));
      const double from_b = std::acos(std::clamp(ub.dot(uc), -1.0, 1.0));
      const double off = std::abs(uc.dot(ua.cross(ub).normalized()));
      const double t = from_a / apart;  // 0 at A's colour, 1 at B's
      // Turned towards B beyond the noise, and by at least 5 % of the way: a mix, not a noisy pixel of A.
      if (t >= 0.05 && from_a > noise_angle && from_b < apart && off <= std::max(noise_angle, 0.1 * apart)) {
        mixed = true;
        towards = other;
        break;
      }
    }
    m.edge_pixels += edge;
    if (mixed) {
      m.mixed.push_back(p);
      ++m.with[towards];
    }
  }
  return m;
}

void apply_edge_mixing(RegionAnalysis& analysed, const EdgeMixing& mixing, const RgbImage& layer, const LayerContext& context,
                       const Region& region, const AnalyzeOptions& options, const std::map<std::int32_t, std::string>& names) {
  ClusterShape& shape = analysed.shape;
  if (shape.shape == ShapeClass::None || shape.shape == ShapeClass::Clipped) return;
  const std::size_t min_mixed = options.criteria.min_mixed_samples;
  const bool enough = mixing.mixed.size() >= min_mixed;
  shape.decisions.push_back({"mixed edge pixels >= min_mixed_samples", static_cast<double>(mixing.mixed.size()),
                             static_cast<double>(min_mixed), enough});
  if (!enough) return;
  Region rest = region;
  rest.pixels.clear();
  std::set_difference(region.pixels.begin(), region.pixels.end(), mixing.mixed.begin(), mixing.mixed.end(),
                      std::back_inserter(rest.pixels));
  const RegionAnalysis unmixed = analyse_region(layer, context, rest, options);
  const bool changed = unmixed.shape.shape != shape.shape;
  shape.decisions.push_back({"class without the mixed pixels differs", changed ? 1.0 : 0.0, 1.0, changed});
  // A line keeps its class when a few per cent of its pixels leave it, yet those pixels can be a structure
  // of their own in the histogram: a tail from the line towards a neighbour's cluster. That is the mixing's
  // when the samples clearly off the line of the rest (beyond 2τ, as a highlight is searched for) are
  // mostly mixed edge pixels; interreflection near an edge turns the colours beside it too.
  std::size_t off_line = 0, mixed_off_line = 0;
  const bool line_class = unmixed.shape.shape == ShapeClass::Linear || unmixed.shape.shape == ShapeClass::ThickenedLine;
  if (!changed && line_class && unmixed.shape.line) {
    const Line& line = *unmixed.shape.line;
    const auto off = [&](std::uint32_t p) {
      const Vec3 c(layer.rgb[3 * std::size_t{p}], layer.rgb[3 * std::size_t{p} + 1], layer.rgb[3 * std::size_t{p} + 2]);
      return c.allFinite() && line.distance(c) > 2 * unmixed.shape.line_tolerance;
    };
    for (const std::uint32_t p : region.pixels) off_line += off(p);
    for (const std::uint32_t p : mixing.mixed) mixed_off_line += off(p);
    const double share = static_cast<double>(mixed_off_line) / static_cast<double>(std::max<std::size_t>(1, off_line));
    shape.decisions.push_back({"mixed pixels off the line of the rest >= min_mixed_samples", static_cast<double>(mixed_off_line),
                               static_cast<double>(min_mixed), mixed_off_line >= min_mixed});
    shape.decisions.push_back({"mixed share of the samples off that line >= 0.5", share, 0.5, share >= 0.5});
  }
  const bool tail = mixed_off_line >= min_mixed && 2 * mixed_off_line >= off_line;
  if (!changed && !tail) return;
  std::vector<std::string> with;
  for (const auto& [id, n] : mixing.with) {
    const auto name = names.find(id);
    with.push_back(fmt::format("{} ({})", name != names.end() ? name->second : fmt::format("id {}", id), n));
  }
  shape.reason =
      changed ? fmt::format("{} of its {} edge pixels mix its colour with its neighbours' ({}): with them the cluster is {}, "
                            "without them {}",
                            mixing.mixed.size(), mixing.edge_pixels, fmt::join(with, ", "), class_name(shape.shape),
                            class_name(unmixed.shape.shape))
              : fmt::format("{} of its {} edge pixels mix its colour with its neighbours' ({}), {} of them off its {} cluster: "
                            "a tail towards its neighbours' clusters",
                            mixing.mixed.size(), mixing.edge_pixels, fmt::join(with, ", "), mixed_off_line, class_name(unmixed.shape.shape));
  shape.shape = ShapeClass::Mixed;
}

}  // namespace ct::analyzer
