// SPDX-License-Identifier: Apache-2.0
#include "analyzer/cluster_shape.h"

#include <algorithm>
#include <initializer_list>
#include <cmath>
#include <limits>
#include <numbers>

#include <fmt/core.h>

#include "analyzer/noise_level.h"
#include "core/statistics.h"

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
  const double top = quantile_in_place(v, hi);
  return top - quantile_in_place(v, lo);
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

// The decision of analyse_shape, one step per member function, in the order of cluster_shape.h's list: each
// step either settles the class (true) or leaves the cluster to the next. The steps share the measured
// cluster (moments, noise, the fit points, the robust body line) and write their tests into s.decisions.
class ShapeDecision {
 public:
  ShapeDecision(std::span<const float> rgb, const ShapeContext& context)
      : rgb_(rgb), context_(context), k_(context.criteria) {
    s_.samples = rgb.size() / 3;
  }

  ClusterShape decide() {
    if (no_shape() || clipped()) return std::move(s_);
    measure();
    if (point() || line_through_noise()) return std::move(s_);
    find_body_and_highlight();
    if (nearly_all_on_the_body_line()) return std::move(s_);
    fit_curve();
    if (two_lines_explain_it() || curve_explains_it() || thickened_plane() || thickened_line()) return measure_highlight_branch();
    if (s_.body_only && s_.two_lines && broad_highlight()) return measure_highlight_branch();
    settle(ShapeClass::Planar, "a planar cluster that is neither two lines, a curve nor a P");
    return measure_highlight_branch();
  }

 private:
  // The colour the highlight adds, for the classes that have a highlight branch: L, skewed-T and P, and a planar
  // cluster whose body line holds p_body_fraction of it with the rest on one side of that line, as the highlights
  // of a dichromatic surface lie (the body line and highlights of several objects of one body colour, which
  // together make no single L, T or P).
  ClusterShape measure_highlight_branch() {
    const ShapeClass c = s_.shape;
    if (!s_.body_only) return std::move(s_);
    const std::vector<std::size_t> off = clearly_off_body();
    bool has_branch = c == ShapeClass::L || c == ShapeClass::SkewedT || c == ShapeClass::P;
    if (c == ShapeClass::Planar)
      has_branch = all({test("highlight branch: body line fraction >= p_body_fraction", body_fraction_, k_.p_body_fraction,
                             body_fraction_ >= k_.p_body_fraction),
                        test("highlight branch: off-body pixels on one side >= p_one_side", one_side(off), k_.p_one_side,
                             one_side(off) >= k_.p_one_side)});
    if (has_branch) s_.highlight_branch = highlight_branch(points_, s_.body_only->line, off);
    return std::move(s_);
  }

  // Whether every one of the tests passed; each is evaluated (and recorded), in order, whatever the others gave.
  static bool all(std::initializer_list<bool> results) {
    return std::all_of(results.begin(), results.end(), [](bool passed) { return passed; });
  }

  bool test(std::string name, double value, double threshold, bool passed) {
    s_.decisions.push_back({std::move(name), value, threshold, passed});
    return passed;
  }
  bool settle(ShapeClass shape, std::string reason) {
    s_.shape = shape;
    s_.reason = std::move(reason);
    return true;
  }

  // none: no samples, all black, or too few for a shape.
  bool no_shape() {
    if (s_.samples == 0) {
      s_.reason = "no valid pixels: no shape measured";
      return true;
    }
    s_.moments = moments(rgb_, context_.threads);
    for (int a = 0; a < 3; ++a) s_.sigma[a] = std::sqrt(s_.moments.eigenvalues[a]);
    if (std::all_of(rgb_.begin(), rgb_.end(), [](float v) { return v == 0.0f; })) {
      s_.reason = "all pixels are black: no colour, so no shape measured";
      return true;
    }
    if (s_.samples < k_.min_samples) {
      s_.reason = fmt::format("{} valid pixel{}: a shape needs at least {}", s_.samples, s_.samples == 1 ? "" : "s", k_.min_samples);
      return true;
    }
    return false;
  }

  // clipped: enough samples on faces of the RGB cube; the rest is classified on its own.
  bool clipped() {
    s_.clipping = find_clipping(rgb_, context_.high_levels, context_.clipping);
    ShapeContext inner = context_;
    inner.criteria.clipped_fraction = 2.0;  // the unclipped part is judged on its shape alone
    if (only_at_black(s_.clipping)) {
      const ClearOfBlack clear = clear_of_black(rgb_, s_.clipping, context_.clipping.low);
      if (!clear.rgb.empty()) s_.clear_of_black.push_back(analyse_shape(clear.rgb, inner));
      s_.clear_levels = clear.level;
    }
    if (!test("clipped fraction >= clipped_fraction", s_.clipping.fraction, k_.clipped_fraction,
              s_.clipping.fraction >= k_.clipped_fraction))
      return false;
    std::vector<float> rest;
    for (std::size_t i = 0; i < s_.samples; ++i)
      if (!s_.clipping.on_face[i])
        rest.insert(rest.end(), rgb_.begin() + static_cast<std::ptrdiff_t>(i * 3), rgb_.begin() + static_cast<std::ptrdiff_t>(i * 3 + 3));
    ClusterShape off = analyse_shape(rest, inner);
    if (only_at_black(s_.clipping) &&
        test("faces only at black: clipped fraction < black_faces_fraction", s_.clipping.fraction, k_.black_faces_fraction,
             s_.clipping.fraction < k_.black_faces_fraction) &&
        off.samples > 0) {
      // The cluster is its samples off the faces, with its clipping, its samples clear of black and all the
      // decisions taken.
      ClusterShape whole = std::move(s_);
      s_ = std::move(off);
      s_.reason += fmt::format(" (read on its {} samples off the faces; {:.1f} % lie at black, on {} face{})", s_.samples,
                               100 * whole.clipping.fraction, whole.clipping.faces.size(), whole.clipping.faces.size() == 1 ? "" : "s");
      whole.decisions.insert(whole.decisions.end(), s_.decisions.begin(), s_.decisions.end());
      s_.decisions = std::move(whole.decisions);
      s_.clipping = std::move(whole.clipping);
      s_.samples = whole.samples;
      s_.clear_of_black = std::move(whole.clear_of_black);
      s_.clear_levels = whole.clear_levels;
      return true;
    }
    s_.unclipped.push_back(std::move(off));
    return settle(ShapeClass::Clipped, fmt::format("{:.1f} % of the pixels lie on {} face{} of the RGB cube", 100 * s_.clipping.fraction,
                                                   s_.clipping.faces.size(), s_.clipping.faces.size() == 1 ? "" : "s"));
  }

  // The noise along each principal axis, the dimensionality features, the fit points and the planes.
  void measure() {
    const std::vector<double> weights = context_.noise ? band_weights(*context_.noise, rgb_) : std::vector<double>{};
    for (int a = 0; a < 3; ++a)
      s_.noise_sigma[a] = context_.noise ? noise_sigma(*context_.noise, weights, s_.moments.axes.col(a)) : context_.quantisation_sigma;
    s1_ = s_.sigma[0];
    if (s1_ > 0) {
      s_.linearity = (s_.sigma[0] - s_.sigma[1]) / s1_;
      s_.planarity = (s_.sigma[1] - s_.sigma[2]) / s1_;
      s_.scattering = s_.sigma[2] / s1_;
    }
    points_ = fit_points(rgb_, k_.max_points);
    n_ = points_.size();
    s_.fit_points = n_;
    s_.plane = Plane{s_.moments.axes.col(2), s_.moments.axes.col(2).dot(s_.moments.mean), s_.sigma[2]};
    s_.black_plane = plane_through_black(points_);
    noise_perp_ = std::hypot(s_.noise_sigma[1], s_.noise_sigma[2]);
    tolerance_ = std::max(k_.noise_factor * noise_perp_, k_.relative_floor * s1_);
  }

  bool significant(int a) {
    const double threshold = std::max(k_.noise_factor * s_.noise_sigma[a], k_.relative_floor * s1_);
    return test(fmt::format("sigma{} > max(noise_factor * noise{}, relative_floor * sigma1)", a + 1, a + 1), s_.sigma[a],
                threshold, s_.sigma[a] > threshold);
  }

  // point: every principal axis within the noise along it (judged against the noise alone: a uniform patch has no
  // relative floor). The axes' noise differs (brightness noise against colour noise), so a cluster whose first axis
  // is within its noise may still have a second that is not.
  bool point() {
    bool beyond = false;
    for (int a = 0; a < 3; ++a)
      beyond = test(fmt::format("sigma{} > noise_factor * noise{}", a + 1, a + 1), s_.sigma[a], k_.noise_factor * s_.noise_sigma[a],
                    s_.sigma[a] > k_.noise_factor * s_.noise_sigma[a]) || beyond;
    if (beyond) return false;
    return settle(ShapeClass::Point, "every principal axis is within the noise along it: a single colour");
  }

  // linear: only the first principal axis stands above the noise.
  bool line_through_noise() {
    s_.line_tolerance = tolerance_;
    const bool sigma2_significant = significant(1);
    sigma3_significant_ = significant(2);
    s_.significant_axes = 1 + sigma2_significant + sigma3_significant_;
    if (sigma2_significant) return false;
    s_.line = fit_line(points_, all_indices(n_));
    return settle(ShapeClass::Linear, "only the first principal axis stands above the noise: a straight line");
  }

  // The samples clearly off the body line (farther than 2τ): those just outside its tolerance are its own
  // fringe (the edge of a highlight, shading noise, on both sides of it).
  std::vector<std::size_t> clearly_off_body() const {
    std::vector<std::size_t> off;
    for (const std::size_t i : complement(n_, s_.body_only->inliers))
      if (s_.body_only->line.distance(points_[i]) > 2 * tolerance_) off.push_back(i);
    return off;
  }

  // The robust body line, then a highlight line among the samples clearly off it, and the two-line model's
  // tests: two candidate explanations of a cluster in a plane are two straight lines (dichromatic body and
  // highlight) or one bent curve (fit_curve); each must pass its own tests, and when both do, the one closer
  // to the points wins (they have about as many parameters: 2 × 4 against 2 × 4).
  void find_body_and_highlight() {
    min_tolerance_ = std::max(k_.noise_factor * noise_perp_, 1e-6 * s1_);
    s_.body_only = find_line(points_, all_indices(n_), tolerance_, min_tolerance_, context_.seed);
    body_fraction_ = s_.body_only ? static_cast<double>(s_.body_only->inliers.size()) / static_cast<double>(n_) : 0.0;
    body_only_ = test("body line fraction >= body_only_fraction", body_fraction_, k_.body_only_fraction,
                      body_fraction_ >= k_.body_only_fraction);
    if (!s_.body_only) return;
    if (const std::optional<LineSearch> highlight = find_highlight()) judge_two_lines(*highlight);
  }

  // The highlight is searched among the samples clearly off the body line (the fringe would otherwise pull out
  // a second body line). A line parallel to the body line among them is the body's own spread (shading beside
  // the line, the tail of a glossy lobe), not a highlight, which leaves the body line at an angle: its samples
  // are set aside and the search repeated, a few times.
  std::optional<LineSearch> find_highlight() const {
    std::vector<std::size_t> rest = clearly_off_body();
    for (int attempt = 0; attempt < 3 && rest.size() >= std::max<std::size_t>(3, k_.min_highlight_samples); ++attempt) {
      std::optional<LineSearch> highlight =
          find_line(points_, rest, tolerance_, min_tolerance_, context_.seed + 1 + static_cast<std::uint64_t>(attempt));
      if (!highlight) return std::nullopt;
      if (line_angle_degrees(highlight->line.direction, s_.body_only->line.direction) >= k_.min_line_angle_deg) return highlight;
      std::vector<std::size_t> others;
      std::set_difference(rest.begin(), rest.end(), highlight->inliers.begin(), highlight->inliers.end(), std::back_inserter(others));
      rest = std::move(others);
    }
    return std::nullopt;
  }

  void judge_two_lines(const LineSearch& highlight) {
    const TwoLines m = two_lines(*s_.body_only, highlight, n_);
    s_.two_lines = m;
    double squares = 0;
    for (const Vec3& p : points_) squares += std::pow(std::min(m.body.distance(p), m.highlight.distance(p)), 2);
    two_line_rms_ = std::sqrt(squares / static_cast<double>(n_));
    const double limit = std::max(2 * noise_perp_, k_.two_line_residual * s_.sigma[1]);
    const double highlight_samples = static_cast<double>(highlight.inliers.size());
    const double highlight_length = (m.highlight.t_max - m.highlight.t_min) / tolerance_;
    two_line_ok_ = all({test("two-line rms <= max(2 * noise, two_line_residual * sigma2)", two_line_rms_, limit, two_line_rms_ <= limit),
                   test("highlight samples >= min_highlight_samples", highlight_samples,
                        static_cast<double>(k_.min_highlight_samples),
                        highlight_samples >= static_cast<double>(k_.min_highlight_samples)),
                   test("highlight fraction >= min_highlight_fraction", m.highlight_fraction, k_.min_highlight_fraction,
                        m.highlight_fraction >= k_.min_highlight_fraction),
                   test("highlight length / tolerance >= highlight_length", highlight_length, k_.highlight_length,
                        highlight_length >= k_.highlight_length),
                   test("angle between lines (deg) >= min_line_angle_deg", m.angle_deg, k_.min_line_angle_deg,
                        m.angle_deg >= k_.min_line_angle_deg),
                   test("gap between lines <= 2 * tolerance", m.gap, 2 * tolerance_, m.gap <= 2 * tolerance_),
                   test("junction on highlight line <= highlight_end", m.junction_on_highlight, k_.highlight_end,
                        m.junction_on_highlight <= k_.highlight_end),
                   test("junction on body line within highlight_end of its ends", m.junction_on_body, k_.highlight_end,
                        m.junction_on_body >= -k_.highlight_end && m.junction_on_body <= 1 + k_.highlight_end),
                   test("junction inside the colour cube (within 2 * tolerance) / tolerance", outside_cube(m.junction) / tolerance_,
                        2.0, outside_cube(m.junction) <= 2 * tolerance_)});
  }

  // How far a colour lies outside the cube of values the image can hold (0 inside): below the lowest code or
  // above a clipping level. Where two lines meet outside it, no pixel could stand at their junction.
  double outside_cube(const Vec3& colour) const {
    double outside = 0;
    for (int c = 0; c < 3; ++c) {
      const double low = context_.clipping.low[static_cast<std::size_t>(c)];
      const double high = context_.high_levels[static_cast<std::size_t>(c)];
      outside = std::max({outside, low - colour[c], std::isfinite(high) ? colour[c] - high : 0.0});
    }
    return outside;
  }

  // linear: a line holding nearly every sample, unless the few others form a highlight line of their own.
  bool nearly_all_on_the_body_line() {
    if (!body_only_ || two_line_ok_) return false;
    s_.line = s_.body_only->line;
    return settle(ShapeClass::Linear, fmt::format("one straight line holds {:.1f} % of the pixels", 100 * body_fraction_));
  }

  // The principal curve and its tests (the curve model).
  void fit_curve() {
    s_.curve = fit_principal_curve(points_, s_.moments);
    const PrincipalCurve& c = *s_.curve;
    const double curve_limit = std::max(2 * noise_perp_, k_.curve_residual * c.straight_rms);
    curve_ok_ =
        all({test("curve rms <= max(2 * noise, curve_residual * straight rms)", c.curve_rms, curve_limit, c.curve_rms <= curve_limit),
             test("bend (sagitta / chord) > max_bend_for_straight", c.bend, k_.max_bend_for_straight, c.bend > k_.max_bend_for_straight)});
    if (two_line_ok_ && curve_ok_) test("two-line rms <= curve rms", two_line_rms_, c.curve_rms, two_line_rms_ <= c.curve_rms);
  }

  // The share of the samples off the body line that lie on its more populated side, within the principal
  // plane: a highlight lies on one side of the body line.
  double one_side(const std::vector<std::size_t>& rest) const {
    const Line& body = s_.body_only->line;
    const Vec3 across = s_.moments.axes.col(2).cross(body.direction).normalized();
    std::size_t positive = 0;
    for (const std::size_t i : rest) positive += (points_[i] - body.point).dot(across) > 0;
    return static_cast<double>(std::max(positive, rest.size() - positive)) / static_cast<double>(std::max<std::size_t>(1, rest.size()));
  }

  // P: a broad highlight. The samples clearly off the body line lie on one side of it and leave it from a
  // stretch of it, not from one point: in the dichromatic frame x − junction = a · body + b · highlight (the
  // body colour and the highlight's direction, found above even when the two-line model fails), a spreads
  // as well as b, where an L or a T keeps a ≈ 0. A P may pass the two-line model too (its scans across the
  // highlight lie near the two lines); this spread tells it from an L or a T.
  bool broad_highlight() {
    const TwoLines& m = *s_.two_lines;
    // The highlight leaves the body line: their junction lies on the body line, away from its dark end (two
    // lines from black are a fork). It need not lie at the highlight line's own end: the bowl's scans bridge
    // the gap between the body line and the straight far part of a broad highlight.
    if (!all({test("body line fraction >= p_body_fraction", body_fraction_, k_.p_body_fraction, body_fraction_ >= k_.p_body_fraction),
          test("junction on body line in [t_junction, 1]", m.junction_on_body, k_.t_junction,
               m.junction_on_body >= k_.t_junction && m.junction_on_body <= 1)}))
      return false;
    const std::vector<std::size_t> rest = clearly_off_body();
    Eigen::Matrix<double, 3, 2> frame;
    frame << m.body.direction, m.highlight.direction;
    const Eigen::ColPivHouseholderQR<Eigen::Matrix<double, 3, 2>> solve(frame);
    std::vector<double> along_body, along_highlight;
    for (const std::size_t i : rest) {
      const Eigen::Vector2d ab = solve.solve(points_[i] - m.junction);
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
    const double noise_spread = 3.29 * noise_perp_ / std::max(1e-300, sine);
    const double body_spread = along_body.size() < 2 ? 0.0 : quantile_range(along_body, 0.05, 0.95);
    const double spread = std::sqrt(std::max(0.0, body_spread * body_spread - noise_spread * noise_spread));
    const double area = highlight_spread > 0 ? spread / highlight_spread : 0.0;
    if (!all({test("highlight leads away from black (|junction + direction| - |junction|) > 0", brightening, 0.0, brightening > 0),
          test("off-body pixels on one side >= p_one_side", sided, k_.p_one_side, sided >= k_.p_one_side),
          test("off-body spread along body (beyond the noise) / along highlight >= p_area_ratio", area, k_.p_area_ratio,
               area >= k_.p_area_ratio)}))
      return false;
    return settle(ShapeClass::P, fmt::format("a body line ({:.0f} %) with a broad highlight leaving it along a stretch of it and "
                                             "filling an area on one side",
                                             100 * body_fraction_));
  }

  // fork, P, L or skewed-T: the two-line model holds (and fits better than a curve that holds too); where the
  // highlight leaves the body line decides.
  bool two_lines_explain_it() {
    if (!two_line_ok_ || (curve_ok_ && two_line_rms_ > s_.curve->curve_rms)) return false;
    const TwoLines& m = *s_.two_lines;
    if (!test("junction on body line >= t_junction", m.junction_on_body, k_.t_junction, m.junction_on_body >= k_.t_junction))
      return settle(ShapeClass::Fork,
                    fmt::format("two lines ({:.0f} % and {:.0f} %) diverging at {:.0f}° from near the dark end: two light "
                                "colours on one surface, or two surfaces in one region",
                                100 * m.body_fraction, 100 * m.highlight_fraction, m.angle_deg));
    if (broad_highlight()) return true;
    const bool l = test("junction on body line >= l_junction", m.junction_on_body, k_.l_junction, m.junction_on_body >= k_.l_junction);
    return settle(l ? ShapeClass::L : ShapeClass::SkewedT,
                  fmt::format("a body line ({:.0f} %) and a highlight line ({:.0f} %) meeting at {:.0f}° {}", 100 * m.body_fraction,
                              100 * m.highlight_fraction, m.angle_deg,
                              l ? "at the body line's bright end" : fmt::format("{:.0f} % along the body line", 100 * m.junction_on_body)));
  }

  // gamma or curved: the curve model holds; a power curve that straightens it is a tone curve, else a banana.
  bool curve_explains_it() {
    if (!curve_ok_) return false;
    s_.gamma = fit_gamma(points_);
    const bool gamma =
        s_.gamma &&
        test("gamma inside the searched range (0.2, 5)", s_.gamma->gamma, 0.0, s_.gamma->gamma > 0.201 && s_.gamma->gamma < 4.99) &&
        test("linearised / stored off-line variance <= gamma_straightening",
             s_.gamma->straightness_linearised / std::max(1e-300, s_.gamma->straightness_as_is), k_.gamma_straightening,
             s_.gamma->straightness_linearised <= k_.gamma_straightening * s_.gamma->straightness_as_is) &&
        test("|gamma - 1| >= min_gamma_departure", std::abs(s_.gamma->gamma - 1), k_.min_gamma_departure,
             std::abs(s_.gamma->gamma - 1) >= k_.min_gamma_departure);
    if (gamma) {
      s_.gamma->gamma_se = gamma_standard_error(points_, context_.seed);
      return settle(ShapeClass::Gamma, fmt::format("a bent line that the power curve γ = {:.3f} ± {:.3f} straightens",
                                                   s_.gamma->gamma, *s_.gamma->gamma_se));
    }
    return settle(ShapeClass::Curved,
                  fmt::format("a curved cluster: bend {:.3f} (sagitta / chord) that no power curve straightens", s_.curve->bend));
  }

  // thickened or volume: σ3 stands above the noise.
  bool thickened_plane() {
    if (!sigma3_significant_) return false;
    const double ratio = s_.sigma[2] / std::max(1e-300, s_.sigma[1]);
    if (test("sigma3 / sigma2 <= thickened_ratio", ratio, k_.thickened_ratio, ratio <= k_.thickened_ratio))
      return settle(ShapeClass::Thickened, fmt::format("a plane thickened off itself: σ3 = {:.3g} is {:.1f} × the noise", s_.sigma[2],
                                                       s_.sigma[2] / std::max(1e-300, s_.noise_sigma[2])));
    return settle(ShapeClass::Volume, "spread in all three directions: a volume");
  }

  // How much of the body line's length the samples off it accompany (their 5–95 % range along it, as a share
  // of the whole cluster's): a highlight sits where the object faces the light, interreflection thickens the
  // line all along.
  double coverage(const std::vector<std::size_t>& rest) const {
    const Line& body = s_.body_only->line;
    std::vector<double> along, all;
    for (const std::size_t i : rest) along.push_back((points_[i] - body.point).dot(body.direction));
    for (const Vec3& p : points_) all.push_back((p - body.point).dot(body.direction));
    if (along.size() < 2) return 0.0;
    return quantile_range(along, 0.05, 0.95) / std::max(1e-300, quantile_range(all, 0.0, 1.0));
  }

  // thickened-line: interreflected light turns the colour by a few per cent (a reflectance times a form factor
  // times a difference of colours, a second-order term), where a highlight adds a first-order one: a line
  // thickened all along it that stays thin (thick_line_ratio).
  bool thickened_line() {
    if (!s_.body_only) return false;
    const double ratio = s_.sigma[1] / s1_;
    const std::vector<std::size_t> rest = complement(n_, s_.body_only->inliers);
    if (!(test("sigma2 / sigma1 <= thick_line_ratio", ratio, k_.thick_line_ratio, ratio <= k_.thick_line_ratio) &&
          test("off-body samples along the body line >= thick_line_coverage", coverage(rest), k_.thick_line_coverage,
               coverage(rest) >= k_.thick_line_coverage)))
      return false;
    s_.line = s_.body_only->line;
    return settle(ShapeClass::ThickenedLine,
                  fmt::format("a line thickened all along it: σ2 = {:.3g} is {:.1f} × the noise and {:.1f} % of σ1", s_.sigma[1],
                              s_.sigma[1] / std::max(1e-300, s_.noise_sigma[1]), 100 * ratio));
  }

  std::span<const float> rgb_;
  const ShapeContext& context_;
  const ShapeCriteria& k_;
  ClusterShape s_;
  std::vector<Vec3> points_;  // the samples the fits use
  std::size_t n_ = 0;
  double s1_ = 0;
  double noise_perp_ = 0;      // the noise across the first principal axis
  double tolerance_ = 0;       // τ
  double min_tolerance_ = 0;
  bool sigma3_significant_ = false;
  double body_fraction_ = 0;   // of the samples on the robust body line
  bool body_only_ = false;     // … at least body_only_fraction
  bool two_line_ok_ = false;
  double two_line_rms_ = std::numeric_limits<double>::infinity();
  bool curve_ok_ = false;
};

}  // namespace

Plane plane_through_black(const std::vector<Vec3>& points) {
  Plane p;
  if (points.empty()) return p;
  const PrincipalAxes a = principal_axes_of(points, About::Black);
  p.normal = a.axes.col(2);
  if (p.normal.sum() < 0) p.normal = -p.normal;
  p.rms = std::sqrt(a.values[2]);
  return p;
}

ClusterShape analyse_shape(std::span<const float> rgb, const ShapeContext& context) {
  return ShapeDecision(rgb, context).decide();
}

}  // namespace ct::analyzer
