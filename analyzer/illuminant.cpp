// SPDX-License-Identifier: Apache-2.0
#include "analyzer/illuminant.h"

#include "analyzer/colour_constancy.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/core.h>

#include "core/geometry.h"

namespace ct::analyzer {
namespace {

Vec3 positive(const Vec3& v) { return v.sum() < 0 ? Vec3(-v) : v; }

constexpr double kNegativeTolerance = 0.05;  // ≈ 3° towards a negative channel
constexpr double kNoiseFactor = ShapeCriteria{}.noise_factor;  // a spread is beyond the noise past this many σ

bool holds_a_plane(ShapeClass c) {
  return c == ShapeClass::L || c == ShapeClass::SkewedT || c == ShapeClass::P || c == ShapeClass::Planar ||
         c == ShapeClass::Thickened;
}

// "B once R + G passes 0.031": per channel with a level, the other two channels' sum above which it is clear of black.
std::string clear_levels_text(const std::array<double, 3>& levels) {
  std::string out;
  for (std::size_t c = 0; c < 3; ++c) {
    if (std::isnan(levels[c])) continue;
    const std::size_t a = std::min((c + 1) % 3, (c + 2) % 3), b = std::max((c + 1) % 3, (c + 2) % 3);
    out += fmt::format("{}{} once {} + {} passes {:.4g}", out.empty() ? "" : ", ", "RGB"[c], "RGB"[a], "RGB"[b], levels[c]);
  }
  return out;
}

// Standard error (radians) of a total-least-squares line's direction: the inliers' spread across it (rms distance,
// over two axes) against their spread along it (taken as uniform over its extent), over √n.
double line_direction_se(const Line& h) {
  const double extent = std::max(h.t_max - h.t_min, 1e-12);
  const double across = h.rms / std::sqrt(2.0), along = extent / std::sqrt(12.0);
  return across / (along * std::sqrt(static_cast<double>(std::max<std::size_t>(h.inliers, 2))));
}

// Standard error (radians) of a plane's normal through black: the samples' distance from it (rms) against their
// second spread within it (σ2; the normal tilts most readily about the longer axis). Spread off the plane that is
// noise averages out over the n samples (÷ √n); spread beyond the noise (thickness_over_noise above noise_factor) is
// structure — interreflection, texture, a second light — that does not, and tilts the plane by up to rms / σ2.
double plane_normal_se(const ClusterShape& s, double noise_factor) {
  const double n = static_cast<double>(std::max<std::size_t>(s.fit_points ? s.fit_points : s.samples, 3));
  const double tilt = s.black_plane->rms / std::max(s.sigma[1], 1e-12);
  const bool thick = s.sigma[2] > noise_factor * s.noise_sigma[2];
  return thick ? tilt : tilt / std::sqrt(n);
}

// The standard error of a weighted mean direction, in degrees: the propagated errors of the members and, with
// several members, their scatter about the mean (the weighted rms angle over √k), whichever is larger.
double mean_direction_se_deg(const std::vector<Vec3>& directions, const std::vector<double>& weights,
                             const std::vector<double>& se, const Vec3& mean) {
  double w = 0, propagated = 0, scatter = 0;
  for (std::size_t i = 0; i < directions.size(); ++i) {
    w += weights[i];
    propagated += weights[i] * weights[i] * se[i] * se[i];
    const double a = angular_error_deg(directions[i], mean) / kDegreesPerRadian;
    scatter += weights[i] * a * a;
  }
  const double k = static_cast<double>(directions.size());
  const double from_fits = std::sqrt(propagated) / w;
  const double from_scatter = k > 1 ? std::sqrt(scatter / w / k) : 0.0;
  return std::max(from_fits, from_scatter) * kDegreesPerRadian;
}

// The standard error of the planes' intersection, in degrees: a normal tilted by δ moves the least eigenvector of
// Σ n nᵀ by about δ / √λ₂ (two planes φ apart: λ₂ = 1 − cos φ, so √2 δ / φ for both tilted). δ is the
// normals' rms standard error or, with more than two planes, their misfit — the rms angle by which the planes
// miss the common direction, √(λ₃ / (k − 2)) — whichever is larger. The fits' errors are independent and average
// down over the k planes (λ₂ of the sum grows with k); a misfit beyond them is the model failing the same way in
// many regions (saturated colours near a face of the cube, interreflection, a second light), which does not, so it
// is taken against λ₂ of the mean, λ₂ / k.
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
  const double from_fits = std::sqrt(tilt / k) / std::sqrt(lambda2);
  // The misfit's standard error rests on ν = k − 2 degrees of freedom: |error|² / (2 s²) follows F(2, ν), whose
  // distribution function is 1 − (1 + 2f/ν)^(−ν/2). Widened by √(ν (e^(4/ν) − 1)) / 2, the stated σ keeps what it
  // means when known: 2σ holds the error with probability 1 − e⁻² ≈ 86 % (×3.7 at three planes, ×1.45 at five, ×1.14 at ten).
  const double nu = k - 2;
  const double from_misfit =
      k > 2 ? std::sqrt(miss / nu) / std::sqrt(lambda2 / k) * std::sqrt(nu * std::expm1(4 / nu)) / 2 : 0.0;
  return std::max(from_fits, from_misfit) * kDegreesPerRadian;
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

namespace {

// What the regions say of the light: the directions of their highlight branches or lines, and the normals of
// their planes through black, with each one's standard error and the regions that gave them.
struct Evidence {
  std::vector<Vec3> line_directions, normals;
  std::vector<double> line_weights, line_se, normal_se;
  std::vector<std::string> line_regions, plane_regions;
  bool line_fitted = false;  // a highlight line fitted across the highlight, not a branch's regression
  std::size_t lines_left_out = 0;  // highlight lines or branches found but left out (each with a note)

  void add_line(const Vec3& direction, double weight, double se, const std::string& region) {
    line_directions.push_back(positive(direction));
    line_weights.push_back(weight);
    line_se.push_back(se);
    line_regions.push_back(region);
  }
};

// A highlight branch is evidence of the light's colour only when it can be told from the body colour: turned from
// the body line by more than 2 of its standard errors.
bool told_from_body(const RegionAnalysis& r, const ClusterShape& s, std::vector<std::string>& notes) {
  const double turn = angular_error_deg(s.highlight_branch->direction, s.body_only->line.direction);
  if (turn > 2 * s.highlight_branch->uncertainty_deg) return true;
  const HighlightBranch& b = *s.highlight_branch;
  // Say what made the error wide: the branch's lower and upper halves disagreeing (the shading, or another surface
  // of the region, follows the highlight), or too few samples off the body line.
  const std::string why = b.halves_deg / 2 > b.statistical_deg
                              ? fmt::format(", most of it from its lower and upper halves, {:.1f}° apart: the shading or another "
                                            "surface of the region follows the highlight", b.halves_deg)
                              : fmt::format(", most of it statistical, from its {} samples off the body line", b.samples);
  notes.push_back(fmt::format("{}: its highlight branch turns {:.1f}° from its body colour, within 2 × its standard error "
                              "({:.1f}°{}): it cannot be told from the body colour, so it is left out",
                              r.name, turn, b.uncertainty_deg, why));
  return false;
}

// An L, skewed T or P: its highlight line (for a P, the line the two-line search found through the broad
// highlight), unless it ends at a clipping level; the branch's colour by regression when measured
// (highlight_branch.h), not tilted by the shading across the highlight. False when the region's branch cannot be
// told from its body colour: then the region is no evidence at all, its plane included.
bool add_highlight_line(const RegionAnalysis& r, const ClusterShape& s, const std::array<double, 3>& high_levels, Evidence& e,
                        std::vector<std::string>& notes) {
  const Line& h = s.two_lines->highlight;
  const Vec3 bright = h.at(h.t_max);
  int clipped = -1;
  for (int c = 0; c < 3; ++c)
    if (std::isfinite(high_levels[c]) && bright[c] >= high_levels[c] - 2 * s.line_tolerance) clipped = c;
  if (clipped >= 0) {
    notes.push_back(fmt::format("{}: its highlight line ends at the clipping level of {} ({:.4g}), so it is left out of the "
                                "highlight-line estimate", r.name, "RGB"[clipped], high_levels[clipped]));
    ++e.lines_left_out;
  } else if (const auto& b = s.highlight_branch; b) {
    if (!told_from_body(r, s, notes)) {
      ++e.lines_left_out;
      return false;
    }
    e.add_line(b->direction, static_cast<double>(b->samples), b->uncertainty_deg / kDegreesPerRadian, r.name);
  } else {
    e.add_line(h.direction, static_cast<double>(h.inliers), line_direction_se(h), r.name);
    e.line_fitted = true;
  }
  return true;
}

Evidence gather_evidence(const std::vector<RegionAnalysis>& regions, const std::array<double, 3>& high_levels,
                         const std::vector<std::string>& lights, std::vector<std::string>& notes) {
  Evidence e;
  // The whole image mixes objects; it stands in only when it is the one region.
  const bool parts = std::any_of(regions.begin(), regions.end(), [](const RegionAnalysis& r) { return r.source != "image"; });
  for (const RegionAnalysis& r : regions) {
    if (parts && r.source == "image") continue;
    if (r.source == "unassigned") continue;  // the pixels no segment holds: no one surface
    if (std::find(lights.begin(), lights.end(), r.name) != lights.end()) continue;  // a light seen directly
    // A cluster clipped only at black (its darkest pixels at the file's lowest value) keeps its highlight whole:
    // its highlight line is read on the samples off the faces; its plane, on its samples clear of black (below).
    const ClusterShape& s = only_at_black(r.shape.clipping) ? off_the_faces(r.shape) : r.shape;
    if ((s.shape == ShapeClass::L || s.shape == ShapeClass::SkewedT || s.shape == ShapeClass::P) && s.two_lines &&
        !add_highlight_line(r, s, high_levels, e, notes))
      continue;
    // A planar cluster with a highlight branch (cluster_shape.h): several objects of one body colour with their
    // highlights. Its branch counts when no channel of it reaches a clipping level.
    if (s.shape == ShapeClass::Planar && s.highlight_branch) {
      if (!told_from_body(r, s, notes)) {
        ++e.lines_left_out;
      } else if (!reaches_the_top(s.clipping)) {
        e.add_line(s.highlight_branch->direction, static_cast<double>(s.highlight_branch->samples), s.highlight_branch->uncertainty_deg / kDegreesPerRadian, r.name);
      } else {
        notes.push_back(fmt::format("{}: its highlight branch reaches a clipping level, so it is left out of the highlight-line estimate", r.name));
        ++e.lines_left_out;
      }
    }
    if (!holds_a_plane(s.shape) || !s.black_plane) continue;
    // A cluster that reaches a face of the cube lost what lay beyond it: its plane through black is partly the
    // face's (a saturated colour clipped at 0 or at the top lies on the face), not the one its light made.
    if (!r.shape.clipping.faces.empty()) {
      const ClippedFace& f = r.shape.clipping.faces.front();
      if (only_at_black(r.shape.clipping)) {
        // The samples left near a face at black are those whose noise happened to lie above it: biased off the face,
        // they tilt the plane of the rest. The samples clear of black (clipping.h) are not, and hold the plane when
        // they are enough to make one.
        const ClusterShape* clear = r.shape.clear_of_black.empty() ? nullptr : &r.shape.clear_of_black.front();
        const std::string at_black = fmt::format("{}: {:.1f} % of its pixels lie at black ({} low at {:.4g} …)", r.name,
                                                 100 * r.shape.clipping.fraction, "RGB"[f.channel], f.level);
        if (clear && holds_a_plane(clear->shape) && clear->black_plane) {
          notes.push_back(fmt::format("{}; its plane is fitted on its {} samples clear of black, where no channel reaches it "
                                      "any more ({})", at_black, clear->samples, clear_levels_text(r.shape.clear_levels)));
          e.normals.push_back(clear->black_plane->normal);
          e.normal_se.push_back(plane_normal_se(*clear, kNoiseFactor));
          e.plane_regions.push_back(r.name);
          continue;
        }
        notes.push_back(fmt::format("{}; the rest near them kept only the noise above that level, which tilts its plane, and "
                                    "{}: left out of the planes' estimate", at_black,
                                    clear ? fmt::format("its {} samples clear of black make a {} cluster, no plane", clear->samples,
                                                        class_name(clear->shape))
                                          : std::string("no samples are clear of black")));
        continue;
      }
      notes.push_back(fmt::format("{}: {:.1f} % of its pixels lie on clipping faces ({} {} at {:.4g} …), so its plane is "
                                  "partly the cube's face: left out of the planes' estimate", r.name,
                                  100 * r.shape.clipping.fraction, "RGB"[f.channel], f.high ? "high" : "low", f.level));
      continue;
    }
    e.normals.push_back(s.black_plane->normal);
    e.normal_se.push_back(plane_normal_se(s, kNoiseFactor));
    e.plane_regions.push_back(r.name);
  }
  return e;
}

// The estimate in `slot`, with its angles to the known light and the camera's white — unless it has a negative
// channel (beyond a few degrees of rounding): no light's colour, so the regions did not follow the dichromatic
// model (interreflection, noise, mixed objects).
void finish(IlluminantAnalysis& out, IlluminantEstimate e, const Vec3& v, std::optional<IlluminantEstimate>& slot) {
  e.rgb = positive(v.normalized());
  if (e.rgb.minCoeff() < -kNegativeTolerance) {
    out.notes.push_back(fmt::format("the {} point to ({:.3f}, {:.3f}, {:.3f}), which is no light's colour: no estimate", e.method,
                                    e.rgb[0], e.rgb[1], e.rgb[2]));
    return;
  }
  if (out.known) e.error_deg = angular_error_deg(e.rgb, *out.known);
  if (out.camera_white) e.camera_angle_deg = angular_error_deg(e.rgb, *out.camera_white);
  slot = e;
}

// The highlight lines' weighted mean direction.
void estimate_from_lines(const Evidence& e, IlluminantAnalysis& out) {
  if (e.line_regions.empty()) {
    out.notes.push_back(e.lines_left_out
                            ? fmt::format("the {} highlight line{} or branch{} found {} left out (above), so no highlight line "
                                          "gives the illuminant", e.lines_left_out, e.lines_left_out == 1 ? "" : "s",
                                          e.lines_left_out == 1 ? "" : "es", e.lines_left_out == 1 ? "is" : "are")
                            : "no region is an L, skewed-T or P with a highlight line, nor a planar cluster with a highlight "
                              "branch, so no highlight line gives the illuminant");
    return;
  }
  IlluminantEstimate lines;
  lines.method = "highlight lines";
  lines.regions = e.line_regions;
  Vec3 sum = Vec3::Zero();
  for (std::size_t i = 0; i < e.line_directions.size(); ++i) sum += e.line_weights[i] * e.line_directions[i];
  lines.uncertainty_deg = mean_direction_se_deg(e.line_directions, e.line_weights, e.line_se, sum.normalized());
  if (e.line_fitted)
    lines.systematic = "a highlight line fitted across the highlight tilts towards its body colour where the shading "
                       "changes along it, which its standard error leaves out";
  finish(out, lines, sum, out.highlight_lines);
}

// The planes' intersection. Two planes always meet in a line, whatever made them; only a third plane, or the
// highlight lines, can show that they are dichromatic planes of one light.
void estimate_from_planes(const Evidence& e, IlluminantAnalysis& out) {
  const auto v = intersect_planes(e.normals);
  if (!v) {
    out.notes.push_back(fmt::format("{} region{} with a usable dichromatic plane; the intersection needs two distinct planes",
                                    e.normals.size(), e.normals.size() == 1 ? "" : "s"));
    return;
  }
  IlluminantEstimate planes;
  planes.method = "dichromatic planes";
  planes.regions = e.plane_regions;
  planes.uncertainty_deg = intersection_se_deg(e.normals, e.normal_se, *v);
  if (e.normals.size() == 2 && !out.highlight_lines) {
    planes.reliable = false;
    planes.unreliable_reason = "two planes meet in a line whatever made them, and no third plane or highlight line "
                               "checks that both are dichromatic planes of one light";
  }
  finish(out, planes, *v, out.planes);
}

constexpr std::size_t kIicSurfacePixels = 200000;

// Inverse-intensity chromaticity over the segments' usable pixels (lights seen directly are not usable).
void estimate_from_iic(const RgbImage& image, const IlluminantContext& context, std::span<const std::uint8_t> usable,
                       IlluminantAnalysis& out) {
  std::vector<std::vector<float>> pixels;
  for (const Region& r : context.pixels) {
    if (r.source != "segment") continue;
    // A segment of a large photograph is thinned by an even stride to at most kIicSurfacePixels: its body colour (a
    // median) and its highlight pixels are as well measured on those, at a fraction of the time.
    const std::size_t stride = std::max<std::size_t>(1, (r.pixels.size() + kIicSurfacePixels - 1) / kIicSurfacePixels);
    std::vector<float> rgb;
    for (std::size_t k = 0; k < r.pixels.size(); k += stride) {
      const std::size_t p = r.pixels[k];
      if (usable[p]) rgb.insert(rgb.end(), &image.rgb[3 * p], &image.rgb[3 * p] + 3);
    }
    pixels.push_back(std::move(rgb));
  }
  if (pixels.empty()) return;
  std::vector<IicSurface> surfaces;
  for (const std::vector<float>& rgb : pixels) surfaces.push_back({rgb});
  const IicResult r = estimate_iic(surfaces);
  if (!r.estimate) {
    out.notes.push_back("inverse-intensity chromaticity: " + r.reason);
    return;
  }
  IlluminantEstimate e;
  e.method = "inverse-intensity chromaticity";
  e.uncertainty_deg = r.estimate->uncertainty_deg;
  e.systematic = "shading that changes across every highlight tilts each line towards its body colour, which no "
                 "resampling of the same surfaces shows";
  if (r.estimate->disagreeing > 0)
    out.notes.push_back(fmt::format("inverse-intensity chromaticity: {} surface{} with a highlight line point{} to another "
                                    "light than the {} that agree", r.estimate->disagreeing, r.estimate->disagreeing == 1 ? "" : "s",
                                    r.estimate->disagreeing == 1 ? "s" : "", r.estimate->surfaces));
  finish(out, e, r.estimate->rgb, out.iic);
}

// Where both exist they must agree within their errors (3 σ combined); when they do not, the planes' estimate
// is not trusted (the highlight branch checks its own model on its two halves), and with three or more planes,
// which check each other, neither is.
void cross_check(std::size_t plane_count, IlluminantAnalysis& out) {
  if (!out.planes || !out.highlight_lines) return;
  const double apart = angular_error_deg(out.planes->rgb, out.highlight_lines->rgb);
  const double sigma = std::hypot(out.planes->uncertainty_deg.value_or(0), out.highlight_lines->uncertainty_deg.value_or(0));
  // Two planes are checked only as far as the highlight lines reach: no closer than their standard error.
  if (plane_count == 2)
    out.planes->uncertainty_deg = std::max(out.planes->uncertainty_deg.value_or(0), out.highlight_lines->uncertainty_deg.value_or(0));
  if (apart > 3 * sigma) {
    const std::string reason = fmt::format("the dichromatic planes and the highlight lines disagree by {:.1f}°, more than "
                                           "3 × their combined standard error ({:.1f}°)", apart, sigma);
    out.planes->reliable = false;
    out.planes->unreliable_reason = reason;
    if (plane_count > 2) out.highlight_lines->reliable = false, out.highlight_lines->unreliable_reason = reason;
  }
}

// Every light's colour lies within 54.7° of grey (arccos(1/√3), grey to a primary): an estimate whose 2σ reaches
// that far could be any light's colour, so it says nothing of this one.
void refuse_if_uninformative(std::optional<IlluminantEstimate>& e) {
  const double octant_deg = std::acos(1 / std::sqrt(3.0)) * kDegreesPerRadian;
  if (!e || !e->reliable || !e->uncertainty_deg || 2 * *e->uncertainty_deg < octant_deg) return;
  e->reliable = false;
  e->unreliable_reason = fmt::format("its 2σ ({:.0f}°) reaches past {:.1f}°, the angle from grey to a primary: it could be any "
                                     "light's colour", 2 * *e->uncertainty_deg, octant_deg);
}

// A pixel counts in the statistical methods when it is finite and no channel is at or past a clipping level or at
// the file's black: there the light's colour was cut off.
std::vector<std::uint8_t> usable_pixels(const RgbImage& image, const IlluminantContext& context) {
  std::vector<std::uint8_t> usable(image.pixel_count(), 0);
  for (std::size_t i = 0; i < usable.size(); ++i) {
    bool ok = true;
    for (std::size_t c = 0; c < 3; ++c) {
      const float v = image.rgb[3 * i + c];
      ok = ok && std::isfinite(v) && v > context.low_levels[c] && v < context.high_levels[c];
    }
    usable[i] = ok ? 1 : 0;
  }
  return usable;
}

// The lights seen directly: their pixels are taken out of `usable`, and the regions that are mostly light pixels
// are named (left out of the dichromatic evidence).
void find_lights(const RgbImage& image, std::span<const Region> regions, const std::array<double, 3>& high_levels,
                 std::vector<std::uint8_t>& usable, IlluminantAnalysis& out) {
  const LightsInView found = find_lights_in_view(image, usable, high_levels);
  if (found.lights.empty()) return;
  for (std::size_t p = 0; p < usable.size(); ++p)
    if (found.mask[p]) usable[p] = 0;
  // One note for them all: the table of estimates lists each with its colour.
  std::string names;
  for (std::size_t k = 0; k < std::min(found.lights.size(), kLightsNamed); ++k) names += (names.empty() ? "" : ", ") + found.lights[k].name;
  if (found.lights.size() > kLightsNamed) names += fmt::format(" and {} dimmer, listed in analysis.json", found.lights.size() - kLightsNamed);
  out.notes.push_back(fmt::format("{} light{} seen directly or mirrored by a glossy surface ({}): at least {:.0f} times the image's "
                                  "median brightness and {:.0f} times its 95th percentile, brighter than a surface they light; "
                                  "references, left out of every estimate", found.lights.size(), found.lights.size() == 1 ? "" : "s",
                                  names, kLightSeed, kLightOverLit));
  out.lights = found.lights;
  for (const Region& r : regions) {
    if (r.source == "image" || r.source == "unassigned" || r.pixels.empty()) continue;
    std::size_t on = 0;
    for (const std::uint32_t p : r.pixels) on += found.mask[p] ? 1 : 0;
    if (2 * on < r.pixels.size()) continue;
    out.light_regions.push_back(r.name);
    out.notes.push_back(fmt::format("{}: {:.0f} % of its pixels are a light seen directly: no dichromatic object, left out of the "
                                    "planes and highlight lines", r.name, 100.0 * static_cast<double>(on) / static_cast<double>(r.pixels.size())));
  }
}

// The statistical methods read at most kStatisticalPixels: a larger image is reduced by averaging f × f blocks (a block
// counts when all its pixels do). The mean is unchanged; the maxima and the edges become those of a coarser scale,
// the scale of the test photographs (0.2 to 2 megapixels, but for the 8-megapixel raw file).
constexpr std::size_t kStatisticalPixels = 2000000;

struct Reduced {
  RgbImage image;
  std::vector<std::uint8_t> usable;
};
Reduced reduced(const RgbImage& image, std::span<const std::uint8_t> usable) {
  const int f = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(image.pixel_count()) / kStatisticalPixels)));
  if (f <= 1) return {image, std::vector<std::uint8_t>(usable.begin(), usable.end())};
  Reduced r;
  r.image.width = image.width / f;
  r.image.height = image.height / f;
  r.image.rgb.assign(3 * r.image.pixel_count(), 0.0f);
  r.usable.assign(r.image.pixel_count(), 1);
  for (int y = 0; y < r.image.height * f; ++y)
    for (int x = 0; x < r.image.width * f; ++x) {
      const std::size_t p = static_cast<std::size_t>(y) * static_cast<std::size_t>(image.width) + static_cast<std::size_t>(x);
      const std::size_t q = static_cast<std::size_t>(y / f) * static_cast<std::size_t>(r.image.width) + static_cast<std::size_t>(x / f);
      if (!usable[p]) r.usable[q] = 0;
      for (std::size_t c = 0; c < 3; ++c) r.image.rgb[3 * q + c] += image.rgb[3 * p + c] / static_cast<float>(f * f);
    }
  return r;
}

// Each statistical method: the light's colour under its assumption about the world's surfaces. Its uncertainty
// joins how far that assumption fails on real scenes (method_prior_deg) with the block bootstrap's spread — how much
// the answer depends on which parts of the scene are in view.
void estimate_statistical(const RgbImage& full, std::span<const std::uint8_t> full_usable, IlluminantAnalysis& out) {
  const Reduced r = reduced(full, full_usable);
  const RgbImage& image = r.image;
  const std::vector<std::uint8_t>& usable = r.usable;
  for (const MinkowskiSettings& method : baseline_methods()) {
    IlluminantEstimate e;
    e.method = method.name;
    const BaselineEstimate b = baseline_estimate(image.rgb, image.width, image.height, usable, method);
    if (b.pixels == 0) {
      e.reliable = false;
      e.unreliable_reason = "no pixel counts: every pixel is clipped, black or not finite";
      out.statistical.push_back(std::move(e));
      continue;
    }
    e.rgb = positive(b.rgb);
    e.uncertainty_deg = std::hypot(method_prior_deg(method.name), b.uncertainty_deg);
    if (out.known) e.error_deg = angular_error_deg(e.rgb, *out.known);
    if (out.camera_white) e.camera_angle_deg = angular_error_deg(e.rgb, *out.camera_white);
    out.statistical.push_back(std::move(e));
  }
}

// An estimate whose 2σ is wider than kReliableTwoSigmaDeg says too little of the light to build on (on a photograph,
// where the priors make σ mean what it says); one whose σ passes 90° fixes no direction at all, and states none.
void refuse_if_too_uncertain(IlluminantEstimate& e, bool photograph) {
  if (!e.uncertainty_deg) return;
  if (*e.uncertainty_deg > 90) {
    e.reliable = false;
    e.unreliable_reason = fmt::format("its standard error ({:.0f}°) passes 90°: the evidence fixes no direction", *e.uncertainty_deg);
    e.uncertainty_deg.reset();
    return;
  }
  if (!photograph || !e.reliable || 2 * *e.uncertainty_deg <= kReliableTwoSigmaDeg) return;
  e.reliable = false;
  e.unreliable_reason = fmt::format("its 2σ ({:.1f}°) is wider than {:.0f}°", 2 * *e.uncertainty_deg, kReliableTwoSigmaDeg);
}

// Which estimate is used, and why the others are not.
std::string choice_text(const IlluminantAnalysis& out) {
  const ChoiceRule& rule = choice_rule();
  const IlluminantEstimate& chosen = out.best();
  std::string why_not;
  for (const auto* e : {out.planes ? &*out.planes : nullptr, out.highlight_lines ? &*out.highlight_lines : nullptr,
                        out.iic ? &*out.iic : nullptr}) {
    if (!e || e == &chosen) continue;
    if (!e->reliable) why_not += fmt::format("; the {} estimate is not used: {}", e->method, e->unreliable_reason);
    else if (out.photograph && e->uncertainty_deg && *e->uncertainty_deg > rule.max_physics_sigma_deg)
      why_not += fmt::format("; the {} estimate (± {:.2f}°) is not used: its standard error is above {:.1f}°", e->method,
                             *e->uncertainty_deg, rule.max_physics_sigma_deg);
  }
  auto sigma = [](const IlluminantEstimate& e) { return e.uncertainty_deg.value_or(0.0); };
  const auto& lines = out.highlight_lines;
  if (out.planes && &chosen == &*out.planes)
    return fmt::format("dichromatic planes: every dichromatic object's plane holds the light's colour, and {} planes "
                       "meet in one direction (± {:.2f}°){}{}", out.planes->regions.size(), sigma(chosen),
                       !lines || !lines->reliable ? ""
                       : !lines->systematic.empty()
                           ? fmt::format(", preferred to the highlight lines (± {:.2f}°): {}", sigma(*lines), lines->systematic)
                           : fmt::format(", the first choice when reliable; the highlight lines (± {:.2f}°) agree with "
                                         "them within their errors", sigma(*lines)),
                       why_not);
  if (lines && &chosen == &*lines)
    return fmt::format("highlight lines: a highlight branch adds the light's colour (± {:.2f}°){}", sigma(chosen), why_not);
  if (out.iic && &chosen == &*out.iic)
    return fmt::format("inverse-intensity chromaticity: the highlights' lines meet at the light's chromaticity (± {:.2f}°){}",
                       sigma(chosen), why_not);
  const auto method = std::find_if(baseline_methods().begin(), baseline_methods().end(),
                                   [&](const MinkowskiSettings& m) { return m.name == chosen.method; });
  if (!out.photograph)
    return fmt::format("{}, a statistical method: no physics estimate is reliable{}. It gives the light's colour if {}",
                       chosen.method, why_not, method == baseline_methods().end() ? "its assumption holds" : method->assumption);
  return fmt::format("{}, a statistical method: no physics estimate is reliable with a standard error within {:.1f}°{}. It "
                     "gives the light's colour if {}; the rule fitted on the test set of photographs falls back on it (the "
                     "least mean error there), and its uncertainty (± {:.2f}°) is its error's spread there with the "
                     "bootstrap's over this image", chosen.method, rule.max_physics_sigma_deg, why_not,
                     method == baseline_methods().end() ? "its assumption holds" : method->assumption, sigma(chosen));
}

}  // namespace

const ChoiceRule& choice_rule() {
  static const ChoiceRule rule{8.0, "shades of grey"};
  return rule;
}

double method_prior_deg(const std::string& method) {
  static const std::vector<std::pair<std::string, double>> priors = {
      {"dichromatic planes", 15.8}, {"highlight lines", 9.0}, {"inverse-intensity chromaticity", 12.9},
      {"grey world", 8.2}, {"white patch", 11.0}, {"shades of grey", 5.3}, {"grey edge 1", 9.1}, {"grey edge 2", 10.5}};
  for (const auto& [name, sigma] : priors)
    if (name == method) return sigma;
  return 0.0;
}

const IlluminantEstimate& choose(const IlluminantAnalysis& a, const ChoiceRule& rule) {
  for (const auto* e : {&a.planes, &a.highlight_lines, &a.iic})
    if (*e && (*e)->reliable && (*e)->uncertainty_deg && (!a.photograph || *(*e)->uncertainty_deg <= rule.max_physics_sigma_deg))
      return **e;
  for (const IlluminantEstimate& e : a.statistical)
    if (e.method == rule.fallback) return e;
  return a.statistical.front();
}

const IlluminantEstimate& IlluminantAnalysis::best() const { return choose(*this, choice_rule()); }

std::vector<const IlluminantEstimate*> IlluminantAnalysis::all() const {
  std::vector<const IlluminantEstimate*> list;
  for (const auto* e : {&planes, &highlight_lines, &iic})
    if (*e) list.push_back(&**e);
  for (const IlluminantEstimate& e : statistical) list.push_back(&e);
  return list;
}

IlluminantAnalysis estimate_illuminant(const std::vector<RegionAnalysis>& regions, const RgbImage& image,
                                       const IlluminantContext& context) {
  IlluminantAnalysis out;
  out.photograph = context.photograph;
  if (context.known) out.known = context.known->normalized();
  if (context.camera_white) out.camera_white = context.camera_white->normalized();
  const std::string& assumed_curve = context.assumed_curve;
  std::vector<std::uint8_t> usable = usable_pixels(image, context);
  find_lights(image, context.pixels, context.high_levels, usable, out);
  const Evidence evidence = gather_evidence(regions, context.high_levels, out.light_regions, out.notes);
  estimate_from_lines(evidence, out);
  estimate_from_planes(evidence, out);
  cross_check(evidence.normals.size(), out);
  estimate_from_iic(image, context, usable, out);
  if (context.photograph)
    for (auto* e : {&out.planes, &out.highlight_lines, &out.iic})
      if (*e && (*e)->uncertainty_deg) (*e)->uncertainty_deg = std::hypot(*(*e)->uncertainty_deg, method_prior_deg((*e)->method));
  for (auto* e : {&out.planes, &out.highlight_lines, &out.iic}) {
    refuse_if_uninformative(*e);
    if (*e) refuse_if_too_uncertain(**e, context.photograph);
  }
  // A plane through black is one only in the true linear light: a response curve that was guessed, not declared,
  // tilts every plane alike when it is wrong, which their agreement cannot show.
  if (out.planes && !assumed_curve.empty() && out.planes->reliable) {
    out.planes->reliable = false;
    out.planes->unreliable_reason = fmt::format("the response curve was assumed ({}), not declared: a dichromatic plane passes "
                                                "through black only in the true linear light, and a wrong curve tilts every "
                                                "plane alike, which their agreement cannot show", assumed_curve);
  }
  estimate_statistical(image, usable, out);
  for (IlluminantEstimate& e : out.statistical) refuse_if_too_uncertain(e, context.photograph);
  out.choice = choice_text(out);
  return out;
}

}  // namespace ct::analyzer
