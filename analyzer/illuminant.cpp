#include "analyzer/illuminant.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/core.h>

namespace ct::analyzer {
namespace {

Vec3 positive(const Vec3& v) { return v.sum() < 0 ? Vec3(-v) : v; }

constexpr double kNegativeTolerance = 0.05;  // ≈ 3° towards a negative channel

bool holds_a_plane(ShapeClass c) {
  return c == ShapeClass::L || c == ShapeClass::SkewedT || c == ShapeClass::P || c == ShapeClass::Planar ||
         c == ShapeClass::Thickened;
}

}  // namespace

double angular_error_deg(const Vec3& a, const Vec3& b) {
  const double c = std::clamp(a.normalized().dot(b.normalized()), -1.0, 1.0);
  return std::acos(c) * 180.0 / std::numbers::pi;
}

std::optional<Vec3> intersect_planes(const std::vector<Vec3>& normals) {
  if (normals.size() < 2) return std::nullopt;
  // The direction nearest to lying in every plane: the least eigenvector of the normals' second moments.
  const PrincipalAxes a = principal_axes_of(normals, About::Black);
  // All planes alike leave two small eigenvalues: the intersection is undetermined.
  const double sin1deg = std::sin(std::numbers::pi / 180.0);
  if (a.values[1] < sin1deg * sin1deg / 2) return std::nullopt;
  return positive(a.axes.col(2));
}

IlluminantAnalysis estimate_illuminant(const std::vector<RegionAnalysis>& regions, std::span<const float> rgb,
                                       const std::optional<Vec3>& known) {
  IlluminantAnalysis out;
  if (known) out.known = known->normalized();
  Vec3 highlight_sum = Vec3::Zero();
  IlluminantEstimate highlights{"highlight lines", {}, {}, {}};
  IlluminantEstimate planes{"dichromatic planes", {}, {}, {}};
  std::vector<Vec3> normals;
  // The whole image mixes objects; it stands in only when it is the one region.
  const bool parts = std::any_of(regions.begin(), regions.end(), [](const RegionAnalysis& r) { return r.source != "image"; });
  for (const RegionAnalysis& r : regions) {
    if (parts && r.source == "image") continue;
    if (r.source == "unassigned") continue;  // the pixels no segment holds: no one surface
    const ClusterShape& s = r.shape;
    // A P too: its highlight line is the line the two-line search found through the broad highlight.
    if ((s.shape == ShapeClass::L || s.shape == ShapeClass::SkewedT || s.shape == ShapeClass::P) && s.two_lines) {
      highlight_sum += positive(s.two_lines->highlight.direction) * static_cast<double>(s.two_lines->highlight.inliers);
      highlights.regions.push_back(r.name);
    }
    if (holds_a_plane(s.shape) && s.black_plane) {
      normals.push_back(s.black_plane->normal);
      planes.regions.push_back(r.name);
    }
  }
  // A light's colour has no negative channel: a direction with one (beyond a few degrees of rounding)
  // means the regions did not follow the dichromatic model (interreflection, noise, mixed objects).
  auto finish = [&](IlluminantEstimate& e, const Vec3& v, std::optional<IlluminantEstimate>& slot) {
    e.rgb = positive(v.normalized());
    if (e.rgb.minCoeff() < -kNegativeTolerance) {
      out.notes.push_back(fmt::format("the {} point to ({:.3f}, {:.3f}, {:.3f}), which is no light's colour: no estimate", e.method,
                                      e.rgb[0], e.rgb[1], e.rgb[2]));
      return;
    }
    if (out.known) e.error_deg = angular_error_deg(e.rgb, *out.known);
    slot = e;
  };
  if (!highlights.regions.empty()) finish(highlights, highlight_sum, out.highlight_lines);
  else out.notes.push_back("no region is an L or skewed-T, so no highlight line gives the illuminant");
  if (const auto v = intersect_planes(normals)) finish(planes, *v, out.planes);
  else out.notes.push_back(fmt::format("{} region{} with a dichromatic plane; the intersection needs two distinct planes",
                                       normals.size(), normals.size() == 1 ? "" : "s"));
  Vec3 mean = Vec3::Zero();
  std::size_t count = 0;
  for (std::size_t i = 0; i + 2 < rgb.size(); i += 3)
    if (std::isfinite(rgb[i]) && std::isfinite(rgb[i + 1]) && std::isfinite(rgb[i + 2]))
      mean += Vec3(rgb[i], rgb[i + 1], rgb[i + 2]), ++count;
  out.grey_world.method = "grey world";
  if (count > 0 && mean.norm() > 0) {
    out.grey_world.rgb = positive(mean.normalized());
    if (out.known) out.grey_world.error_deg = angular_error_deg(out.grey_world.rgb, *out.known);
  } else out.notes.push_back("the image has no finite, non-black pixels: no grey-world estimate");
  return out;
}

}  // namespace ct::analyzer
