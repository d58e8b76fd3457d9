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

constexpr double kDeg = 180.0 / std::numbers::pi;

// Standard error (radians) of a total-least-squares line's direction: the inliers' spread across it (rms distance,
// over two axes) against their spread along it (taken as uniform over its extent), over √n.
double line_direction_se(const Line& h) {
  const double extent = std::max(h.t_max - h.t_min, 1e-12);
  const double across = h.rms / std::sqrt(2.0), along = extent / std::sqrt(12.0);
  return across / (along * std::sqrt(static_cast<double>(std::max<std::size_t>(h.inliers, 2))));
}

// Standard error (radians) of a plane's normal through black: the samples' distance from it (rms) against their
// second spread within it (σ2; the normal tilts most readily about the longer axis), over √n.
double plane_normal_se(const ClusterShape& s) {
  const double n = static_cast<double>(std::max<std::size_t>(s.fit_points ? s.fit_points : s.samples, 3));
  return s.black_plane->rms / (std::max(s.sigma[1], 1e-12) * std::sqrt(n));
}

// The standard error of a weighted mean direction, in degrees: the propagated errors of the members and, with
// several members, their scatter about the mean (the weighted rms angle over √k), whichever is larger.
double mean_direction_se_deg(const std::vector<Vec3>& directions, const std::vector<double>& weights,
                             const std::vector<double>& se, const Vec3& mean) {
  double w = 0, propagated = 0, scatter = 0;
  for (std::size_t i = 0; i < directions.size(); ++i) {
    w += weights[i];
    propagated += weights[i] * weights[i] * se[i] * se[i];
    const double a = angular_error_deg(directions[i], mean) / kDeg;
    scatter += weights[i] * a * a;
  }
  const double k = static_cast<double>(directions.size());
  const double from_fits = std::sqrt(propagated) / w;
  const double from_scatter = k > 1 ? std::sqrt(scatter / w / k) : 0.0;
  return std::max(from_fits, from_scatter) * kDeg;
}

// The standard error of the planes' intersection, in degrees: a normal tilted by δ moves the least eigenvector of
// Σ n nᵀ by about δ / √λ₂ (two planes φ apart: λ₂ = 1 − cos φ, so √2 δ / φ for both tilted). δ is the
// normals' rms standard error or, with more than two planes, their misfit — the rms angle by which the planes
// miss the common direction, √(λ₃ / (k − 2)) — whichever is larger.
double intersection_se_deg(const std::vector<Vec3>& normals, const std::vector<double>& se, const Vec3& direction) {
  Mat3 m = Mat3::Zero();
  double tilt = 0, miss = 0;
  for (std::size_t i = 0; i < normals.size(); ++i) {
    const Vec3 n = normals[i].normalized();
    m += n * n.transpose();
    tilt += se[i] * se[i];
    miss += std::pow(n.dot(direction), 2);
  }
  const double k = static_cast<double>(normals.size());
  Vec3 values;
  Mat3 axes;
  principal_axes(m, values, axes);  // descending: the third is the intersection's
  const double lambda2 = std::max(values[1], 1e-12);
  double delta = std::sqrt(tilt / k);
  if (k > 2) delta = std::max(delta, std::sqrt(miss / (k - 2)));
  return delta / std::sqrt(lambda2) * kDeg;
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
                                       const std::optional<Vec3>& known, const std::array<double, 3>& high_levels) {
  IlluminantAnalysis out;
  if (known) out.known = known->normalized();
  IlluminantEstimate highlights{"highlight lines", {}, {}, {}, {}};
  IlluminantEstimate planes{"dichromatic planes", {}, {}, {}, {}};
  std::vector<Vec3> line_directions, normals;
  std::vector<double> line_weights, line_se, normal_se;
  // The whole image mixes objects; it stands in only when it is the one region.
  const bool parts = std::any_of(regions.begin(), regions.end(), [](const RegionAnalysis& r) { return r.source != "image"; });
  for (const RegionAnalysis& r : regions) {
    if (parts && r.source == "image") continue;
    if (r.source == "unassigned") continue;  // the pixels no segment holds: no one surface
    const ClusterShape& s = r.shape;
    // A P too: its highlight line is the line the two-line search found through the broad highlight.
    if ((s.shape == ShapeClass::L || s.shape == ShapeClass::SkewedT || s.shape == ShapeClass::P) && s.two_lines) {
      const Line& h = s.two_lines->highlight;
      const Vec3 bright = h.at(h.t_max);
      int clipped = -1;
      for (int c = 0; c < 3; ++c)
        if (std::isfinite(high_levels[c]) && bright[c] >= high_levels[c] - 2 * s.line_tolerance) clipped = c;
      if (clipped >= 0) {
        out.notes.push_back(fmt::format("{}: its highlight line ends at the clipping level of {} ({:.4g}), so it is "
                                        "left out of the highlight-line estimate", r.name, "RGB"[clipped],
                                        high_levels[clipped]));
      } else {
        line_directions.push_back(positive(h.direction));
        line_weights.push_back(static_cast<double>(h.inliers));
        line_se.push_back(line_direction_se(h));
        highlights.regions.push_back(r.name);
      }
    }
    if (holds_a_plane(s.shape) && s.black_plane) {
      normals.push_back(s.black_plane->normal);
      normal_se.push_back(plane_normal_se(s));
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
  if (!highlights.regions.empty()) {
    Vec3 sum = Vec3::Zero();
    for (std::size_t i = 0; i < line_directions.size(); ++i) sum += line_weights[i] * line_directions[i];
    highlights.uncertainty_deg = mean_direction_se_deg(line_directions, line_weights, line_se, sum.normalized());
    finish(highlights, sum, out.highlight_lines);
  } else if (line_directions.empty()) {
    out.notes.push_back("no region is an L, skewed-T or P with a highlight line inside the clipping levels, so no "
                        "highlight line gives the illuminant");
  }
  if (const auto v = intersect_planes(normals)) {
    planes.uncertainty_deg = intersection_se_deg(normals, normal_se, *v);
    finish(planes, *v, out.planes);
  } else {
    out.notes.push_back(fmt::format("{} region{} with a dichromatic plane; the intersection needs two distinct planes",
                                    normals.size(), normals.size() == 1 ? "" : "s"));
  }
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
  out.choice = out.planes ? fmt::format("dichromatic planes: every dichromatic object's plane holds the light's colour, "
                                        "and {} planes meet in one direction; the highlight lines tilt towards the "
                                        "body colours where the shading changes across a highlight", out.planes->regions.size())
               : out.highlight_lines ? "highlight lines: fewer than two distinct dichromatic planes; a highlight line points "
                                       "along the light but tilts towards its body colour where the shading changes"
                                     : "grey world: no dichromatic plane pair and no highlight line; the image's mean colour "
                                       "is the light's only if its surfaces average to grey, so treat it as a guess";
  return out;
}

}  // namespace ct::analyzer
