// SPDX-License-Identifier: Apache-2.0
#include "analyzer/iic.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <numeric>
#include <sstream>
#include <stdexcept>

#include "core/geometry.h"
#include "core/principal_axes.h"
#include "core/random.h"
#include "core/statistics.h"

namespace ct::analyzer {
namespace {

// The median distance of a two-dimensional normal of unit standard deviation per axis from its centre, √(2 ln 2):
// chromaticities move in a plane (their components sum to 1), so noise about a point is two-dimensional, and so
// is a point's noise across a line in RGB.
const double kMedianRadius = std::sqrt(2.0 * std::numbers::ln2);

double component_sum(const Vec3& v) { return v[0] + v[1] + v[2]; }

// The angle between two directions, in degrees; atan2 keeps its precision at small angles, where acos loses half
// the digits.
double angle_deg(const Vec3& a, const Vec3& b) { return std::atan2(a.cross(b).norm(), a.dot(b)) * kDegreesPerRadian; }

std::size_t draw(Random& random, std::size_t n) {
  return std::min(n - 1, static_cast<std::size_t>(random.uniform() * static_cast<double>(n)));
}

// A surface's pixels as colours, without those of no brightness (their chromaticity is undefined).
std::vector<Vec3> surface_colours(std::span<const float> rgb) {
  if (rgb.size() % 3 != 0) throw std::invalid_argument("estimate_iic: a surface's values are not RGB triplets");
  std::vector<Vec3> colours;
  colours.reserve(rgb.size() / 3);
  for (std::size_t i = 0; i + 2 < rgb.size(); i += 3) {
    const Vec3 c(rgb[i], rgb[i + 1], rgb[i + 2]);
    if (c.allFinite() && component_sum(c) > 0) colours.push_back(c);
  }
  return colours;
}

// The body's chromaticity and the chromaticity noise, from the darker part of the surface (its diffuse
// reference): the component-wise median chromaticity, and the per-axis standard deviation of the chromaticity's
// distance from it scaled by ΣI (additive sensor noise moves the chromaticity by noise / ΣI), from its median.
struct Body {
  Vec3 chromaticity = Vec3::Zero();
  double noise = 0;  // per-axis standard deviation of the chromaticity times ΣI
};

Body diffuse_body(const std::vector<Vec3>& colours, const IicSettings& settings) {
  std::vector<std::size_t> order(colours.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return component_sum(colours[a]) < component_sum(colours[b]); });
  const std::size_t count = std::clamp<std::size_t>(
      static_cast<std::size_t>(std::ceil(settings.reference_fraction * static_cast<double>(colours.size()))), 1,
      colours.size());
  Body body;
  for (int c = 0; c < 3; ++c) {
    std::vector<double> values;
    for (std::size_t k = 0; k < count; ++k) values.push_back(colours[order[k]][c] / component_sum(colours[order[k]]));
    body.chromaticity[c] = quantile(values, 0.5);
  }
  std::vector<double> scaled;
  for (std::size_t k = 0; k < count; ++k) {
    const double s = component_sum(colours[order[k]]);
    scaled.push_back((colours[order[k]] / s - body.chromaticity).norm() * s);
  }
  body.noise = quantile(scaled, 0.5) / kMedianRadius;
  return body;
}

// The pixels whose chromaticity has moved away from the body's by more than its noise allows at their brightness.
std::vector<Vec3> highlight_pixels(const std::vector<Vec3>& colours, const Body& body, const IicSettings& settings) {
  std::vector<Vec3> out;
  for (const Vec3& c : colours) {
    const double s = component_sum(c);
    const double threshold = std::max(settings.min_highlight_shift, settings.highlight_sigmas * body.noise / s);
    if ((c / s - body.chromaticity).norm() > threshold) out.push_back(c);
  }
  return out;
}

// The IIC line through pixels[i] for i in `subset` (all when empty), fitted in RGB by total least squares:
// the principal axis v through the mean. Its intercept in IIC space is the light's chromaticity Γ = v / Σv, and
// its slope p = mean − Σmean · Γ (σ = Γ + p / ΣI along it).
struct Fit {
  Vec3 light = Vec3::Zero();  // Γ, components summing to 1
  Vec3 slope = Vec3::Zero();  // p, components summing to 0
  Vec3 mean = Vec3::Zero();
  Vec3 axis = Vec3::Zero();   // unit, positive sum
};

std::optional<Fit> fit_line(const std::vector<Vec3>& pixels, std::span<const std::size_t> subset = {}) {
  const PrincipalAxes axes = principal_axes_of(pixels, About::Mean, subset);
  Vec3 v = axes.axes.col(0);
  if (component_sum(v) < 0) v = -v;
  // A line along which ΣI does not grow (Σv ≈ 0) has no intercept at 1/ΣI = 0.
  if (!(component_sum(v) > 1e-9) || !(axes.values[0] > 0)) return std::nullopt;
  Fit fit;
  fit.axis = v;
  fit.mean = axes.mean;
  fit.light = v / component_sum(v);
  fit.slope = axes.mean - component_sum(axes.mean) * fit.light;
  return fit;
}

// One pass of trimming: the pixels within settings.trim_sigmas robust standard deviations of the line (distance
// across it), with a floor at float rounding so that exact data loses nothing.
std::vector<Vec3> near_line(const std::vector<Vec3>& pixels, const Fit& fit, const IicSettings& settings) {
  std::vector<double> distance;
  for (const Vec3& c : pixels) {
    const Vec3 d = c - fit.mean;
    distance.push_back((d - d.dot(fit.axis) * fit.axis).norm());
  }
  const double sigma = quantile(distance, 0.5) / kMedianRadius;
  const double limit = std::max(settings.trim_sigmas * sigma, 1e-6 * fit.mean.norm());
  std::vector<Vec3> out;
  for (std::size_t i = 0; i < pixels.size(); ++i)
    if (distance[i] <= limit) out.push_back(pixels[i]);
  return out;
}

// The chromaticity change along the line across the pixels: |p| times their range of 1/ΣI.
double chromaticity_change(const std::vector<Vec3>& pixels, const Fit& fit) {
  double lo = std::numeric_limits<double>::infinity(), hi = 0;
  for (const Vec3& c : pixels) {
    const double x = 1.0 / component_sum(c);
    lo = std::min(lo, x);
    hi = std::max(hi, x);
  }
  return fit.slope.norm() * (hi - lo);
}

// Resampled with replacement: the subset of pixel indices for one bootstrap replicate.
std::vector<std::size_t> resample(std::size_t n, Random& random) {
  std::vector<std::size_t> subset(n);
  for (std::size_t& i : subset) i = draw(random, n);
  return subset;
}

// A surface's highlight line, or why it gave none.
enum class Outcome { Line, TooFewPixels, NoHighlight, TooFewHighlightPixels, NoChromaticityChange };

struct SurfaceLine {
  Outcome outcome = Outcome::TooFewPixels;
  Vec3 light = Vec3::Zero();  // Γ
  std::vector<Vec3> pixels;   // the highlight pixels it was fitted to
  double se_deg = 0;          // from a bootstrap over those pixels
};

SurfaceLine surface_line(std::span<const float> rgb, const IicSettings& settings, std::uint64_t stream) {
  SurfaceLine line;
  const std::vector<Vec3> colours = surface_colours(rgb);
  if (colours.size() < settings.min_surface_pixels) return line;
  std::vector<Vec3> highlight = highlight_pixels(colours, diffuse_body(colours, settings), settings);
  if (highlight.size() > settings.max_line_pixels) {  // thinned by an even stride (IicSettings::max_line_pixels)
    std::vector<Vec3> kept;
    kept.reserve(settings.max_line_pixels);
    for (std::size_t k = 0; k < settings.max_line_pixels; ++k) kept.push_back(highlight[k * highlight.size() / settings.max_line_pixels]);
    highlight = std::move(kept);
  }
  line.outcome = highlight.empty() ? Outcome::NoHighlight : Outcome::TooFewHighlightPixels;
  if (highlight.size() < settings.min_line_pixels) return line;
  const std::optional<Fit> first = fit_line(highlight);
  if (!first) return line;
  line.pixels = near_line(highlight, *first, settings);
  if (line.pixels.size() < settings.min_line_pixels) return line;
  const std::optional<Fit> fit = fit_line(line.pixels);
  if (!fit) return line;
  if (!(chromaticity_change(line.pixels, *fit) >= settings.min_chromaticity_change)) {
    line.outcome = Outcome::NoChromaticityChange;
    return line;
  }
  line.outcome = Outcome::Line;
  line.light = fit->light;
  // The pixel level of the uncertainty, which the consensus needs to tell noise from another light.
  Random random(settings.seed, stream);
  double sum_squares = 0;
  int made = 0;
  for (int r = 0; r < settings.replicates; ++r) {
    const std::optional<Fit> f = fit_line(line.pixels, resample(line.pixels.size(), random));
    if (!f) continue;
    sum_squares += std::pow(angle_deg(f->light, line.light), 2);
    ++made;
  }
  line.se_deg = made > 0 ? std::sqrt(sum_squares / made) : 0.0;
  return line;
}

// One surface's evidence in the consensus.
struct Vote {
  Vec3 light = Vec3::Zero();  // Γ
  double se_deg = 0;
  std::size_t pixels = 0;
};

struct Consensus {
  Vec3 light = Vec3::Zero();  // Γ of the agreeing votes, pixel-weighted
  std::size_t votes = 0, pixels = 0;
};

bool agree(const Vote& a, const Vote& b, const IicSettings& settings) {
  const double radius = std::max(settings.consensus_deg, settings.consensus_sigmas * std::hypot(a.se_deg, b.se_deg));
  return angle_deg(a.light, b.light) <= radius;
}

// The intercept with most support: the vote that most others agree with (ties: more pixels behind it, then the
// earlier vote), and the pixel-weighted mean of the votes agreeing with it.
Consensus consensus(const std::vector<Vote>& votes, const IicSettings& settings) {
  Consensus best;
  for (const Vote& centre : votes) {
    Consensus c;
    for (const Vote& v : votes)
      if (agree(centre, v, settings)) {
        ++c.votes;
        c.pixels += v.pixels;
        c.light += static_cast<double>(v.pixels) * v.light;
      }
    if (c.votes > best.votes || (c.votes == best.votes && c.pixels > best.pixels)) best = c;
  }
  if (best.pixels > 0) best.light /= static_cast<double>(best.pixels);
  return best;
}

// The root-mean-square angle to `estimate` of the consensus of `replicates` resampled sets of votes.
template <typename Replicate>
double bootstrap_deg(const Vec3& estimate, const IicSettings& settings, Replicate replicate) {
  double sum_squares = 0;
  int made = 0;
  for (int r = 0; r < settings.replicates; ++r) {
    const Consensus c = consensus(replicate(), settings);
    if (c.votes == 0) continue;
    sum_squares += std::pow(angle_deg(c.light, estimate), 2);
    ++made;
  }
  return made > 0 ? std::sqrt(sum_squares / made) : 0.0;
}

// The two levels of the evidence, each resampled alone: resampling both at once would count the pixel noise
// twice, since the scatter between surfaces already holds it. Over pixels (every surface kept, each refitted to
// its pixels drawn with replacement): the noise of these highlights. Over surfaces (drawn with replacement, each
// with its own line): the noise as well, and whatever else makes surfaces disagree, but coarse with few
// surfaces and nothing with one. The uncertainty is the larger.
double uncertainty_deg(const std::vector<SurfaceLine>& lines, const Vec3& estimate, const IicSettings& settings) {
  Random pixel_random(settings.seed, 0x706978656c73ull);  // "pixels"
  const double over_pixels = bootstrap_deg(estimate, settings, [&] {
    std::vector<Vote> votes;
    for (const SurfaceLine& line : lines) {
      const std::optional<Fit> f = fit_line(line.pixels, resample(line.pixels.size(), pixel_random));
      if (f) votes.push_back({f->light, line.se_deg, line.pixels.size()});
    }
    return votes;
  });
  Random surface_random(settings.seed, 0x7375726661636573ull);  // "surfaces"
  const double over_surfaces = bootstrap_deg(estimate, settings, [&] {
    std::vector<Vote> votes;
    for (std::size_t k = 0; k < lines.size(); ++k) {
      const SurfaceLine& line = lines[draw(surface_random, lines.size())];
      votes.push_back({line.light, line.se_deg, line.pixels.size()});
    }
    return votes;
  });
  return std::max(over_pixels, over_surfaces);
}

std::string no_line_reason(const std::vector<Outcome>& outcomes, const IicSettings& settings) {
  const auto count = [&](Outcome o) { return std::count(outcomes.begin(), outcomes.end(), o); };
  std::ostringstream s;
  s << "no surface gave a highlight line in inverse-intensity chromaticity space (of " << outcomes.size() << ": "
    << count(Outcome::TooFewPixels) << " with fewer than " << settings.min_surface_pixels << " usable pixels, "
    << count(Outcome::NoHighlight) << " with no pixel's chromaticity away from the body colour (diffuse only, or a "
    << "body colour at the light's), " << count(Outcome::TooFewHighlightPixels) << " with fewer than "
    << settings.min_line_pixels << " highlight pixels, " << count(Outcome::NoChromaticityChange)
    << " whose highlight changes the chromaticity by less than " << settings.min_chromaticity_change << ")";
  return s.str();
}

}  // namespace

IicResult estimate_iic(const std::vector<IicSurface>& surfaces, const IicSettings& settings) {
  IicResult result;
  if (surfaces.empty()) {
    result.reason = "no surfaces";
    return result;
  }
  std::vector<SurfaceLine> lines;
  std::vector<Outcome> outcomes;
  for (std::size_t k = 0; k < surfaces.size(); ++k) {
    SurfaceLine line = surface_line(surfaces[k].rgb, settings, k);
    outcomes.push_back(line.outcome);
    if (line.outcome == Outcome::Line) lines.push_back(std::move(line));
  }
  if (lines.empty()) {
    result.reason = no_line_reason(outcomes, settings);
    return result;
  }
  std::vector<Vote> votes;
  for (const SurfaceLine& line : lines) votes.push_back({line.light, line.se_deg, line.pixels.size()});
  const Consensus c = consensus(votes, settings);
  IicEstimate e;
  e.rgb = c.light.normalized();
  e.surfaces = c.votes;
  e.pixels = c.pixels;
  e.disagreeing = lines.size() - c.votes;
  e.uncertainty_deg = uncertainty_deg(lines, c.light, settings);
  result.estimate = e;
  return result;
}

}  // namespace ct::analyzer
