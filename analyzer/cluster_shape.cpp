#include "analyzer/cluster_shape.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include <fmt/core.h>

#include "analyzer/noise_level.h"

namespace ct::analyzer {
namespace {

std::vector<Vec3> fit_points(std::span<const float> rgb, std::size_t max_points) {
  const std::size_t n = rgb.size() / 3;
  const std::size_t stride = (n + max_points - 1) / max_points;
  std::vector<Vec3> points;
  points.reserve(n / std::max<std::size_t>(1, stride) + 1);
  for (std::size_t i = 0; i < n; i += stride) points.emplace_back(rgb[i * 3], rgb[i * 3 + 1], rgb[i * 3 + 2]);
  return points;
}

std::vector<std::size_t> all_indices(std::size_t n) {
  std::vector<std::size_t> v(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = i;
  return v;
}

std::vector<std::size_t> complement(std::size_t n, const std::vector<std::size_t>& sorted_subset) {
  std::vector<std::size_t> rest;
  std::size_t j = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (j < sorted_subset.size() && sorted_subset[j] == i) ++j;
    else rest.push_back(i);
  }
  return rest;
}

// The distance between the lo and hi quantiles of v (which it reorders); v holds at least one value.
double quantile_range(std::vector<double>& v, double lo, double hi) {
  const auto at = [&](double q) {
    const auto k = static_cast<std::ptrdiff_t>(q * static_cast<double>(v.size() - 1));
    std::nth_element(v.begin(), v.begin() + k, v.end());
    return v[static_cast<std::size_t>(k)];
  };
  return at(hi) - at(lo);
}

// The two-line model of the dichromatic reflection model: body line, highlight line and their junction.
TwoLines two_lines(const LineSearch& body, const LineSearch& highlight, std::size_t n) {
  TwoLines m;
  m.body = body.line;
  m.highlight = highlight.line;
  m.angle_deg = line_angle_degrees(m.body.direction, m.highlight.direction);
  const auto [sb, sh] = closest_parameters(m.body, m.highlight);
  m.gap = (m.body.at(sb) - m.highlight.at(sh)).norm();
  m.junction = 0.5 * (m.body.at(sb) + m.highlight.at(sh));
  const double body_length = std::max(1e-300, m.body.t_max - m.body.t_min);
  m.junction_on_body = (sb - m.body.t_min) / body_length;
  double q = (sh - m.highlight.t_min) / std::max(1e-300, m.highlight.t_max - m.highlight.t_min);
  if (q > 0.5) {  // orient the highlight away from the junction
    Line& h = m.highlight;
    h.direction = -h.direction;
    std::tie(h.t_min, h.t_max) = std::pair{-h.t_max, -h.t_min};
    q = 1.0 - q;
  }
  m.junction_on_highlight = q;
  m.body_fraction = static_cast<double>(body.inliers.size()) / static_cast<double>(n);
  m.highlight_fraction = static_cast<double>(highlight.inliers.size()) / static_cast<double>(n);
  return m;
}

}  // namespace

Plane plane_through_black(const std::vector<Vec3>& points) {
  Plane p;
  if (points.empty()) return p;
  Mat3 second = Mat3::Zero();
  for (const Vec3& x : points) second += x * x.transpose();
  second /= static_cast<double>(points.size());
  Vec3 values;
  Mat3 axes;
  principal_axes(second, values, axes);
  p.normal = axes.col(2);
  if (p.normal.sum() < 0) p.normal = -p.normal;
  p.rms = std::sqrt(values[2]);
  return p;
}

ClusterShape analyse_shape(std::span<const float> rgb, const ShapeContext& context) {
  const ShapeCriteria& k = context.criteria;
  ClusterShape s;
  s.samples = rgb.size() / 3;
  auto test = [&s](std::string name, double value, double threshold, bool passed) {
    s.decisions.push_back({std::move(name), value, threshold, passed});
    return passed;
  };
  if (s.samples == 0) {
    s.reason = "no valid pixels: no shape measured";
    return s;
  }
  s.moments = moments(rgb, context.threads);
  for (int a = 0; a < 3; ++a) s.sigma[a] = std::sqrt(s.moments.eigenvalues[a]);
  if (std::all_of(rgb.begin(), rgb.end(), [](float v) { return v == 0.0f; })) {
    s.reason = "all pixels are black: no colour, so no shape measured";
    return s;
  }
  if (s.samples < k.min_samples) {
    s.reason = fmt::format("{} valid pixel{}: a shape needs at least {}", s.samples, s.samples == 1 ? "" : "s", k.min_samples);
    return s;
  }

  s.clipping = find_clipping(rgb, context.high_levels, context.clipping);
  if (test("clipped fraction >= clipped_fraction", s.clipping.fraction, k.clipped_fraction, s.clipping.fraction >= k.clipped_fraction)) {
    s.shape = ShapeClass::Clipped;
    s.reason = fmt::format("{:.1f} % of the pixels lie on {} face{} of the RGB cube", 100 * s.clipping.fraction,
                           s.clipping.faces.size(), s.clipping.faces.size() == 1 ? "" : "s");
    std::vector<float> rest;
    for (std::size_t i = 0; i < s.samples; ++i)
      if (!s.clipping.on_face[i]) rest.insert(rest.end(), rgb.begin() + static_cast<std::ptrdiff_t>(i * 3), rgb.begin() + static_cast<std::ptrdiff_t>(i * 3 + 3));
    ShapeContext inner = context;
    inner.criteria.clipped_fraction = 2.0;  // the unclipped part is judged on its shape alone
    s.unclipped.push_back(analyse_shape(rest, inner));
    return s;
  }

  for (int a = 0; a < 3; ++a) s.noise_sigma[a] = noise_sigma(context.differences, s.moments.axes.col(a), context.quantisation_sigma);
  const double s1 = s.sigma[0];
  auto significant = [&](int a) {
    const double threshold = std::max(k.noise_factor * s.noise_sigma[a], k.relative_floor * s1);
    return test(fmt::format("sigma{} > max(noise_factor * noise{}, relative_floor * sigma1)", a + 1, a + 1), s.sigma[a],
                threshold, s.sigma[a] > threshold);
  };
  if (s1 > 0) {
    s.linearity = (s.sigma[0] - s.sigma[1]) / s1;
    s.planarity = (s.sigma[1] - s.sigma[2]) / s1;
    s.scattering = s.sigma[2] / s1;
  }
  const std::vector<Vec3> points = fit_points(rgb, k.max_points);
  const std::size_t n = points.size();
  s.fit_points = n;
  s.plane = Plane{s.moments.axes.col(2), s.moments.axes.col(2).dot(s.moments.mean), s.sigma[2]};
  s.black_plane = plane_through_black(points);

  // σ1 is judged against the noise alone: a uniform patch has no relative floor to fall below.
  if (!test("sigma1 > noise_factor * noise1", s1, k.noise_factor * s.noise_sigma[0], s1 > k.noise_factor * s.noise_sigma[0])) {
    s.shape = ShapeClass::Point;
    s.reason = "the cluster is no larger than the noise: a single colour";
    return s;
  }
  const double noise_perp = std::hypot(s.noise_sigma[1], s.noise_sigma[2]);
  const double tolerance = std::max(k.noise_factor * noise_perp, k.relative_floor * s1);
  s.line_tolerance = tolerance;
  const bool sigma2_significant = significant(1), sigma3_significant = significant(2);
  s.significant_axes = 1 + sigma2_significant + sigma3_significant;
  if (!sigma2_significant) {
    s.shape = ShapeClass::Linear;
    s.line = fit_line(points, all_indices(n));
    s.reason = "only the first principal axis stands above the noise: a straight line";
    return s;
  }

  const double min_tolerance = std::max(k.noise_factor * noise_perp, 1e-6 * s1);
  s.body_only = find_line(points, all_indices(n), tolerance, min_tolerance, context.seed);
  const double body_fraction = s.body_only ? static_cast<double>(s.body_only->inliers.size()) / static_cast<double>(n) : 0.0;
  const bool body_only = test("body line fraction >= body_only_fraction", body_fraction, k.body_only_fraction,
                              body_fraction >= k.body_only_fraction);

  // Two candidate explanations of a cluster in a plane: two straight lines (dichromatic body and
  // highlight), or one bent curve. Each must pass its own tests; when both do, the one closer to the
  // points wins (they have about as many parameters: 2 × 4 against 2 × 4).
  bool two_line_ok = false;
  double two_line_rms = std::numeric_limits<double>::infinity();
  // The samples clearly off the body line (farther than 2τ): those just outside its tolerance are its own
  // fringe (the edge of a highlight, shading noise, on both sides of it).
  const auto clearly_off_body = [&] {
    std::vector<std::size_t> off;
    for (const std::size_t i : complement(n, s.body_only->inliers))
      if (s.body_only->line.distance(points[i]) > 2 * tolerance) off.push_back(i);
    return off;
  };
  if (s.body_only) {
    // The highlight is searched among the samples clearly off the body line: the fringe would otherwise
    // pull out a second body line.
    std::vector<std::size_t> rest = clearly_off_body();
    // A line parallel to the body line among them is the body's own spread (shading beside the line, the
    // tail of a glossy lobe), not a highlight, which leaves the body line at an angle: set its samples
    // aside and look again, a few times.
    std::optional<LineSearch> highlight;
    for (int attempt = 0; attempt < 3 && rest.size() >= std::max<std::size_t>(3, k.min_highlight_samples); ++attempt) {
      highlight = find_line(points, rest, tolerance, min_tolerance, context.seed + 1 + static_cast<std::uint64_t>(attempt));
      if (!highlight || line_angle_degrees(highlight->line.direction, s.body_only->line.direction) >= k.min_line_angle_deg) break;
      std::vector<std::size_t> others;
      std::set_difference(rest.begin(), rest.end(), highlight->inliers.begin(), highlight->inliers.end(), std::back_inserter(others));
      rest = std::move(others);
      highlight.reset();
    }
    if (highlight) {
      const TwoLines m = two_lines(*s.body_only, *highlight, n);
      s.two_lines = m;
      double squares = 0;
      for (const Vec3& p : points) squares += std::pow(std::min(m.body.distance(p), m.highlight.distance(p)), 2);
      two_line_rms = std::sqrt(squares / static_cast<double>(n));
      const double limit = std::max(2 * noise_perp, k.two_line_residual * s.sigma[1]);
      const double highlight_samples = static_cast<double>(highlight->inliers.size());
      const double highlight_length = (m.highlight.t_max - m.highlight.t_min) / tolerance;
      two_line_ok = test("two-line rms <= max(2 * noise, two_line_residual * sigma2)", two_line_rms, limit, two_line_rms <= limit) &
                    test("highlight samples >= min_highlight_samples", highlight_samples,
                         static_cast<double>(k.min_highlight_samples),
                         highlight_samples >= static_cast<double>(k.min_highlight_samples)) &
                    test("highlight fraction >= min_highlight_fraction", m.highlight_fraction, k.min_highlight_fraction,
                         m.highlight_fraction >= k.min_highlight_fraction) &
                    test("highlight length / tolerance >= highlight_length", highlight_length, k.highlight_length,
                         highlight_length >= k.highlight_length) &
                    test("angle between lines (deg) >= min_line_angle_deg", m.angle_deg, k.min_line_angle_deg, m.angle_deg >= k.min_line_angle_deg) &
                    test("gap between lines <= 2 * tolerance", m.gap, 2 * tolerance, m.gap <= 2 * tolerance) &
                    test("junction on highlight line <= highlight_end", m.junction_on_highlight, k.highlight_end,
                         m.junction_on_highlight <= k.highlight_end);
    }
  }
  // A line holding nearly every sample is linear unless the few others form a highlight line of their own.
  if (body_only && !two_line_ok) {
    s.shape = ShapeClass::Linear;
    s.line = s.body_only->line;
    s.reason = fmt::format("one straight line holds {:.1f} % of the pixels", 100 * body_fraction);
    return s;
  }
  s.curve = fit_principal_curve(points, s.moments);
  const PrincipalCurve& c = *s.curve;
  const double curve_limit = std::max(2 * noise_perp, k.curve_residual * c.straight_rms);
  const bool curve_ok =
      test("curve rms <= max(2 * noise, curve_residual * straight rms)", c.curve_rms, curve_limit, c.curve_rms <= curve_limit) &
      test("bend (sagitta / chord) > max_bend_for_straight", c.bend, k.max_bend_for_straight, c.bend > k.max_bend_for_straight);
  if (two_line_ok && curve_ok) test("two-line rms <= curve rms", two_line_rms, c.curve_rms, two_line_rms <= c.curve_rms);

  // The share of the samples off the body line that lie on its more populated side, within the principal
  // plane: a highlight lies on one side of the body line.
  const auto one_side = [&](const std::vector<std::size_t>& rest) {
    const Line& body = s.body_only->line;
    const Vec3 across = s.moments.axes.col(2).cross(body.direction).normalized();
    std::size_t positive = 0;
    for (const std::size_t i : rest) positive += (points[i] - body.point).dot(across) > 0;
    return static_cast<double>(std::max(positive, rest.size() - positive)) / static_cast<double>(std::max<std::size_t>(1, rest.size()));
  };
  // A P: a broad highlight. The samples clearly off the body line lie on one side of it and leave it from a
  // stretch of it, not from one point: in the dichromatic frame x − junction = a · body + b · highlight (the
  // body colour and the highlight's direction, found above even when the two-line model fails), a spreads
  // as well as b, where an L or a T keeps a ≈ 0. A P may pass the two-line model too (its scans across the
  // highlight lie near the two lines); this spread tells it from an L or a T.
  const auto broad_highlight = [&] {
    const TwoLines& m = *s.two_lines;
    // The highlight leaves the body line: their junction lies on the body line, away from its dark end (two
    // lines from black are a fork). It need not lie at the highlight line's own end: the bowl's scans bridge
    // the gap between the body line and the straight far part of a broad highlight.
    if (!(test("body line fraction >= p_body_fraction", body_fraction, k.p_body_fraction, body_fraction >= k.p_body_fraction) &
          test("junction on body line in [t_junction, 1]", m.junction_on_body, k.t_junction,
               m.junction_on_body >= k.t_junction && m.junction_on_body <= 1)))
      return false;
    const std::vector<std::size_t> rest = clearly_off_body();
    Eigen::Matrix<double, 3, 2> frame;
    frame << m.body.direction, m.highlight.direction;
    const Eigen::ColPivHouseholderQR<Eigen::Matrix<double, 3, 2>> solve(frame);
    std::vector<double> along_body, along_highlight;
    for (const std::size_t i : rest) {
      const Eigen::Vector2d ab = solve.solve(points[i] - m.junction);
      along_body.push_back(ab[0]);
      along_highlight.push_back(ab[1]);
    }
    // A highlight adds light: from where it leaves the body line it leads away from black. A branch that
    // leads towards black is a bent or offset dark end (a tone curve over an offset), not a highlight.
    const double brightening = (m.junction + m.highlight.direction).norm() - m.junction.norm();
    const double sided = one_side(rest);
    const double highlight_spread = along_highlight.size() < 2 ? 0.0 : quantile_range(along_highlight, 0.05, 0.95);
    // Noise across the body line scatters a by noise / sin(angle) (the oblique frame magnifies it): the
    // 5–95 % range of a Gaussian is 3.29 σ, and only the spread beyond it is the highlight's.
    const double sine = std::sin(m.angle_deg * std::numbers::pi / 180);
    const double noise_spread = 3.29 * noise_perp / std::max(1e-300, sine);
    const double body_spread = along_body.size() < 2 ? 0.0 : quantile_range(along_body, 0.05, 0.95);
    const double spread = std::sqrt(std::max(0.0, body_spread * body_spread - noise_spread * noise_spread));
    const double area = highlight_spread > 0 ? spread / highlight_spread : 0.0;
    if (test("highlight leads away from black (|junction + direction| - |junction|) > 0", brightening, 0.0, brightening > 0) &
        test("off-body pixels on one side >= p_one_side", sided, k.p_one_side, sided >= k.p_one_side) &
        test("off-body spread along body (beyond the noise) / along highlight >= p_area_ratio", area, k.p_area_ratio, area >= k.p_area_ratio)) {
      s.shape = ShapeClass::P;
      s.reason = fmt::format("a body line ({:.0f} %) with a broad highlight leaving it along a stretch of it and filling an area on one side",
                             100 * body_fraction);
      return true;
    }
    return false;
  };
  if (two_line_ok && (!curve_ok || two_line_rms <= c.curve_rms)) {
    const TwoLines& m = *s.two_lines;
    if (!test("junction on body line >= t_junction", m.junction_on_body, k.t_junction, m.junction_on_body >= k.t_junction)) {
      s.shape = ShapeClass::Fork;
      s.reason = fmt::format("two lines ({:.0f} % and {:.0f} %) diverging at {:.0f}° from near the dark end: two light "
                             "colours on one surface, or two surfaces in one region",
                             100 * m.body_fraction, 100 * m.highlight_fraction, m.angle_deg);
      return s;
    }
    if (broad_highlight()) return s;
    const bool l = test("junction on body line >= l_junction", m.junction_on_body, k.l_junction, m.junction_on_body >= k.l_junction);
    s.shape = l ? ShapeClass::L : ShapeClass::SkewedT;
    s.reason = fmt::format("a body line ({:.0f} %) and a highlight line ({:.0f} %) meeting at {:.0f}° {}", 100 * m.body_fraction,
                           100 * m.highlight_fraction, m.angle_deg,
                           l ? "at the body line's bright end" : fmt::format("{:.0f} % along the body line", 100 * m.junction_on_body));
    return s;
  }
  if (curve_ok) {
    s.gamma = fit_gamma(points);
    const bool gamma =
        s.gamma &&
        test("gamma inside the searched range (0.2, 5)", s.gamma->gamma, 0.0, s.gamma->gamma > 0.201 && s.gamma->gamma < 4.99) &&
        test("linearised / stored off-line variance <= gamma_straightening",
             s.gamma->straightness_linearised / std::max(1e-300, s.gamma->straightness_as_is), k.gamma_straightening,
             s.gamma->straightness_linearised <= k.gamma_straightening * s.gamma->straightness_as_is) &&
        test("|gamma - 1| >= min_gamma_departure", std::abs(s.gamma->gamma - 1), k.min_gamma_departure,
             std::abs(s.gamma->gamma - 1) >= k.min_gamma_departure);
    s.shape = gamma ? ShapeClass::Gamma : ShapeClass::Curved;
    s.reason = gamma ? fmt::format("a bent line that the power curve γ = {:.3f} straightens", s.gamma->gamma)
                     : fmt::format("a curved cluster: bend {:.3f} (sagitta / chord) that no power curve straightens", c.bend);
    return s;
  }

  if (sigma3_significant) {
    const double ratio = s.sigma[2] / std::max(1e-300, s.sigma[1]);
    const bool thick = test("sigma3 / sigma2 <= thickened_ratio", ratio, k.thickened_ratio, ratio <= k.thickened_ratio);
    s.shape = thick ? ShapeClass::Thickened : ShapeClass::Volume;
    s.reason = thick ? fmt::format("a plane thickened off itself: σ3 = {:.3g} is {:.1f} × the noise", s.sigma[2],
                                   s.sigma[2] / std::max(1e-300, s.noise_sigma[2]))
                     : "spread in all three directions: a volume";
    return s;
  }

  // How much of the body line's length the samples off it accompany (their 5–95 % range along it, as a share
  // of the whole cluster's): a highlight sits where the object faces the light, interreflection thickens the
  // line all along. And interreflected light turns the colour by a few per cent (a reflectance times a form
  // factor times a difference of colours, a second-order term), where a highlight adds a first-order one:
  // a thickened line stays thin (thick_line_ratio).
  const auto coverage = [&](const std::vector<std::size_t>& rest) {
    const Line& body = s.body_only->line;
    std::vector<double> along, all;
    for (const std::size_t i : rest) along.push_back((points[i] - body.point).dot(body.direction));
    for (const Vec3& p : points) all.push_back((p - body.point).dot(body.direction));
    if (along.size() < 2) return 0.0;
    return quantile_range(along, 0.05, 0.95) / std::max(1e-300, quantile_range(all, 0.0, 1.0));
  };
  if (s.body_only) {
    const double ratio = s.sigma[1] / s1;
    const std::vector<std::size_t> rest = complement(n, s.body_only->inliers);
    if (test("sigma2 / sigma1 <= thick_line_ratio", ratio, k.thick_line_ratio, ratio <= k.thick_line_ratio) &&
        test("off-body samples along the body line >= thick_line_coverage", coverage(rest), k.thick_line_coverage,
             coverage(rest) >= k.thick_line_coverage)) {
      s.shape = ShapeClass::ThickenedLine;
      s.line = s.body_only->line;
      s.reason = fmt::format("a line thickened all along it: σ2 = {:.3g} is {:.1f} × the noise and {:.1f} % of σ1", s.sigma[1],
                             s.sigma[1] / std::max(1e-300, s.noise_sigma[1]), 100 * ratio);
      return s;
    }
  }

  if (s.body_only && s.two_lines && broad_highlight()) return s;
  s.shape = ShapeClass::Planar;
  s.reason = "a planar cluster that is neither two lines, a curve nor a P";
  return s;
}

}  // namespace ct::analyzer
