// SPDX-License-Identifier: Apache-2.0
#include "analyzer/interpretation.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <numbers>
#include <numeric>

#include <fmt/format.h>

#include "core/geometry.h"

namespace ct::analyzer {
namespace {

// The premises a class's process rests on, measured before it is described.
struct Premises {
  std::optional<BlackReach> body;  // where the body line passes black (none: no line)
  bool body_is_colour = false;     // its direction lies in the positive octant
  std::optional<bool> light_highlight;  // the highlight branch is the light's colour (none: no branch, or no light to say)
  std::size_t top_pixels = 0;      // samples at a channel's top level (a sheen's, though too few for a face)
  bool cut_at_top = false;         // the cluster described is the part below faces at the top: its bright end was cut
  bool body_reaches() const { return body && body->reaches && body_is_colour; }
  bool body_misses() const { return body && body->measured && !body->reaches; }
};

// What the class stands for physically, in the dichromatic reflection model and the camera — of this cluster:
// where its line does not reach black, or its highlight is not the light's colour, the words say so.
Statement process_of(ShapeClass c, const Premises& p) {
  const std::string body = p.body_reaches() ? "body reflection (a line from black along the body colour)"
                           : p.body_misses() ? "a line of one colour that does not reach black (below)"
                                             : "a line of one colour";
  const bool light = p.light_highlight.value_or(false);
  const std::string added = light ? "surface reflection adding the light's own colour"
                                  : "a second line of another colour, not shown to be the light's (below)";
  const auto statement = [](std::string kind, std::string text, std::vector<std::string> claims = {}) {
    return Statement{std::move(kind), std::move(text), std::move(claims)};
  };
  std::vector<std::string> highlight_claims;
  if (p.body_reaches()) highlight_claims.push_back("reaches_black");
  if (p.body_misses()) highlight_claims.push_back("misses_black");
  if (p.light_highlight) highlight_claims.push_back(light ? "light_highlight" : "not_light_highlight");
  const std::string highlight_kind = light ? "process.light_highlight" : p.light_highlight ? "process.highlight" : "process.highlight_unknown";
  switch (c) {
    case ShapeClass::None: return statement("process.none", "no cluster was measured, so no process can be named");
    case ShapeClass::Clipped:
      return statement("process.clipped", "the sensor or the file clipped the light: where a channel reached its limit the colour was "
                                          "cut off, and the cluster lies flattened on faces of the RGB cube");
    case ShapeClass::Mixed: return statement("process.mixed", "pixels at the edge of two objects average their colours (the pixel's area)");
    case ShapeClass::Point:
      return statement("process.point", "one colour at one brightness: an evenly lit patch, with no spread beyond noise along any axis",
                       {"within_noise"});
    case ShapeClass::Linear:
      if (p.body_misses())
        return statement("process.offset_line",
                         "one colour whose brightness changes with the shading, on a straight line that does not reach black: body "
                         "(matte) reflection with a colour added to every pixel (below)", {"misses_black"});
      if (!p.body_reaches())
        return statement("process.line", "one colour whose brightness changes with the shading: a straight line (below)");
      if (p.cut_at_top)
        return statement("process.matte_below_clipping", "body (matte) reflection: one colour whose brightness changes with the "
                                                         "shading, a line from black along the body colour, cut where it reached the "
                                                         "clipping level", {"reaches_black", "top_clipped"});
      if (p.top_pixels > 0)
        return statement("process.matte", "body (matte) reflection: one colour whose brightness changes with the shading, a line from "
                                          "black along the body colour, with a sheen cut off at the top too small to shape the cluster "
                                          "(below)", {"reaches_black", "top_clipped"});
      return statement("process.matte_alone", "body (matte) reflection alone: one colour whose brightness changes with the shading, a "
                                              "line from black along the body colour", {"reaches_black", "no_top_clipping"});
    case ShapeClass::ThickenedLine:
      return statement("process.thickened_line", "matte shading of one colour, thickened all along its line: other colours added in "
                                                 "proportion (interreflected light, texture) or noise");
    case ShapeClass::L:
      return statement(highlight_kind,
                       body + " and, at its bright end, " + added +
                           (light ? ": the dichromatic model's L, a sharp highlight on a glossy object" : ": the shape of the dichromatic model's L"),
                       highlight_claims);
    case ShapeClass::SkewedT:
      return statement(highlight_kind,
                       body + " and " + added + ", leaving the body line part-way along it" +
                           (light ? ": a highlight where the body is not at its brightest" : ""),
                       highlight_claims);
    case ShapeClass::Fork:
      return statement("process.fork", "two lines from near black: one surface lit by two lights of different colours, or two surfaces");
    case ShapeClass::Gamma: return statement("process.gamma", "the camera's response curve bent a cluster that is straight in the light");
    case ShapeClass::Curved:
      return statement("process.curved", "a bent cluster (the \"banana\"): light whose colour changes with brightness — interreflection "
                                         "whose share falls as the direct light grows, mixing at edges, or a camera curve");
    case ShapeClass::Thickened:
      return statement("process.thickened", "a plane with spread off it: interreflection from surfaces of other colours, "
                                            "texture, a second light, or noise");
    case ShapeClass::Volume:
      return statement("process.volume", "colours spread in three directions: several body colours (texture, several objects) or "
                                         "several lights");
    case ShapeClass::P:
      return statement(highlight_kind,
                       body + " and a broad area on one side of it: " +
                           (light ? "surface reflection of the light's colour spread over a wide lobe"
                                  : "a second colour spread over an area, not shown to be the light's (below)"),
                       highlight_claims);
    case ShapeClass::Superposed: return statement("process.superposed", "the structures of several lights of different colours, added");
    case ShapeClass::Planar:
      return statement("process.planar", "a cluster in a plane, without separate lines: body and surface reflection mixed (the "
                                         "dichromatic plane), or two body colours");
  }
  return {};
}

// "a P", "an L", "a linear cluster": the class as a noun.
std::string class_article(ShapeClass c) {
  const std::string name(class_name(c));
  switch (c) {
    case ShapeClass::L: return "an L";
    case ShapeClass::P: case ShapeClass::SkewedT: return "a " + name;
    default: return "a " + name + " cluster";
  }
}

Vec3 unit(const Vec3& v) { return v.sum() < 0 ? Vec3(-v.normalized()) : v.normalized(); }

// The body reflection's line: the body line of a two-line fit, else the robust body line, else the line.
const Line* body_line_of(const ClusterShape& s) {
  if (s.two_lines && (s.shape == ShapeClass::L || s.shape == ShapeClass::SkewedT)) return &s.two_lines->body;
  if (s.body_only) return &s.body_only->line;
  if (s.line) return &*s.line;
  return nullptr;
}

// A direction is a colour only inside the positive octant: no light adds a negative amount of a channel.
bool is_colour(const Vec3& v) { return v.minCoeff() >= 0; }

std::string negative_channels(const Vec3& v) {
  std::vector<std::string> names;
  for (int c = 0; c < 3; ++c)
    if (v[c] < 0) names.emplace_back(1, "RGB"[c]);
  return fmt::format("{}", fmt::join(names, " and "));
}


// (+ 0.0 turns a −0 into 0: a direction in the positive octant is never printed with a minus sign.)
std::string rgb3(const Vec3& v) { return fmt::format("({:.3f}, {:.3f}, {:.3f})", v[0] + 0.0, v[1] + 0.0, v[2] + 0.0); }

// A direction's words: its components where it is a colour, else which channels are negative — never a negative
// number called a colour.
std::string colour_words(const Vec3& v) { return is_colour(v) ? rgb3(v) : "a direction with negative " + negative_channels(v) + " (no colour)"; }

// The highlight branch as measured: where it points, whether that is a colour, and whether it is the light's.
struct Branch {
  Vec3 direction = Vec3::Zero();
  bool colour = false;
  std::optional<double> light_angle_deg, allowed_deg;  // from the light's colour; within allowed_deg it is the light's
  std::optional<bool> light;  // none when there is no reliable light to compare with
};

std::optional<Branch> measure_branch(const ClusterShape& s, const IlluminantEstimate& light, const ShapeCriteria& criteria) {
  const bool two_lines = s.two_lines && (s.shape == ShapeClass::L || s.shape == ShapeClass::SkewedT || s.shape == ShapeClass::P);
  if (!two_lines && !s.highlight_branch) return std::nullopt;
  Branch b;
  // The branch's colour by regression when measured (highlight_branch.h), else the highlight line's direction.
  b.direction = unit(s.highlight_branch ? s.highlight_branch->direction : s.two_lines->highlight.direction);
  b.colour = is_colour(b.direction);
  if (light.rgb.norm() > 0 && b.colour) {
    b.light_angle_deg = angular_error_deg(b.direction, light.rgb);
    // Twice the two directions' combined standard error, never below the angle that tells two directions apart.
    // The regression's standard error, else the highlight line's own: its direction is known to rms / (√n · the
    // spread along it), the spread of points evenly along its length being length / √12.
    double branch_se = 0;
    if (s.highlight_branch) {
      branch_se = s.highlight_branch->uncertainty_deg;
    } else {
      const Line& h = s.two_lines->highlight;
      const double spread = (h.t_max - h.t_min) / std::sqrt(12.0);
      branch_se = spread > 0 ? std::atan2(h.rms, std::sqrt(std::max<double>(1, static_cast<double>(h.inliers))) * spread) * kDegreesPerRadian : 90.0;
    }
    b.allowed_deg = std::max(criteria.min_line_angle_deg, 2 * std::hypot(branch_se, light.uncertainty_deg.value_or(0.0)));
    if (light.reliable) b.light = *b.light_angle_deg <= *b.allowed_deg;
  } else if (!b.colour) {
    b.light = false;
  }
  return b;
}

// The highlight branch: where it points, how far from the light's colour and whether that is the light's, where it
// leaves the body line and how far it reaches.
void describe_highlight(const ClusterShape& s, const Branch& b, const RegionAnalysis& region, const IlluminantEstimate& light,
                        Interpretation& out) {
  const bool two_lines = s.two_lines && (s.shape == ShapeClass::L || s.shape == ShapeClass::SkewedT || s.shape == ShapeClass::P);
  const std::size_t off = s.highlight_branch ? s.highlight_branch->samples : 0;
  if (!b.colour) {
    out.findings.push_back({"highlight.not_a_colour",
                            fmt::format("Its pixels off the body line{} spread along a direction with negative {}: no reflection adds a "
                                        "negative amount of light, so they are no highlight of one colour but colours of another kind — "
                                        "a texture, a second body colour, or another object in the region.",
                                        off ? fmt::format(" ({} of them)", off) : "", negative_channels(b.direction)),
                            {"not_light_highlight"}});
    return;
  }
  out.highlight_direction = b.direction;
  if (two_lines) {
    const Line& h = s.two_lines->highlight;
    const Line& body = s.two_lines->body;
    const double body_top = std::max(body.at(body.t_max).norm(), body.at(body.t_min).norm());
    const double highlight_top = std::max(h.at(h.t_max).norm(), h.at(h.t_min).norm());
    if (body_top > 0) out.highlight_reach = highlight_top / body_top;
  }
  std::string kind = "highlight.no_light";
  std::vector<std::string> claims;
  std::string sentence = fmt::format("Its highlight branch points along {}", rgb3(b.direction));
  if (b.light_angle_deg) {
    out.highlight_light_angle_deg = b.light_angle_deg;
    sentence += fmt::format(", {:.1f}° from the light's colour", *b.light_angle_deg);
    if (s.highlight_branch) sentence += fmt::format(" (± {:.1f}°, from {} pixels off the body line)", s.highlight_branch->uncertainty_deg, off);
    if (light.method == "highlight lines" && std::find(light.regions.begin(), light.regions.end(), region.name) != light.regions.end())
      sentence += light.regions.size() == 1 ? " — it is the light's estimate itself" : " — one of the branches the light's estimate averages";
    if (!b.light) {
      kind = "highlight.light_unknown";
      sentence += ": the light's colour is too uncertain to say whether it is the light's";
    } else if (*b.light) {
      kind = "highlight.light", claims = {"light_highlight"};
      sentence += fmt::format(": within {:.1f}° (twice their combined standard error, at least the angle that tells two "
                              "directions apart), so it is consistent with surface reflection of the light's colour", *b.allowed_deg);
    } else {
      kind = "highlight.not_light", claims = {"not_light_highlight"};
      sentence += fmt::format(": more than the {:.1f}° within which it would be the light's, so it is not the light's colour reflected "
                              "at the surface — a second light of another colour, or another colour in the region", *b.allowed_deg);
    }
  }
  if (two_lines) sentence += fmt::format("; it leaves the body line {:.0f} % along it", 100 * s.two_lines->junction_on_body);
  if (out.highlight_reach) sentence += fmt::format(" and reaches {:.2f} × the body line's brightest colour", *out.highlight_reach);
  // Read on the samples below a clipping level: what lay beyond it is cut off, so the branch is of its dimmer part.
  if (reaches_the_top(region.shape.clipping))
    sentence += "; its brightest part is clipped, so this is the branch below the clipping level, and where the cut "
                "was the highlight's colour is not known";
  out.findings.push_back({kind, sentence + ".", claims});
}

// A segment whose colour one direction stands for several objects — the light's colour, or a colour whose weaker
// channels lie at black — and a segment of several separate areas.
void describe_shared_colour(const RegionAnalysis& region, const Region& pixels, int width, const IlluminantAnalysis& illuminant,
                            const ShapeCriteria& criteria, Interpretation& out) {
  if (region.source == "segment") out.separate_areas = separate_areas(pixels, width);
  bool light_coloured = false;
  // Only a light known to within the angle that tells two directions apart can say a colour is the light's: the
  // most precise reliable measurement, if its standard error is that small. The colour is the body colour where
  // one is quoted, else the mean colour.
  const IlluminantEstimate* sharp = nullptr;
  for (const auto* e : {illuminant.planes ? &*illuminant.planes : nullptr, illuminant.highlight_lines ? &*illuminant.highlight_lines : nullptr})
    if (e && e->reliable && e->uncertainty_deg && *e->uncertainty_deg <= criteria.min_line_angle_deg &&
        (!sharp || *e->uncertainty_deg < *sharp->uncertainty_deg))
      sharp = e;
  const std::optional<Vec3> colour = out.body_colour ? out.body_colour : out.mean_colour;
  if (sharp && colour && region.source != "image") {
    const double apart = angular_error_deg(*colour, sharp->rgb);
    const double near = std::max(criteria.min_line_angle_deg, 2 * *sharp->uncertainty_deg);
    light_coloured = apart <= near;
    if (light_coloured)
      out.findings.push_back({"light_coloured",
                              fmt::format("Its {} lies {:.1f}° from the light's colour as the {} measure it (± {:.1f}°): it is the "
                                          "light itself, or surfaces that return it unchanged — white and grey cloth, plates, glass "
                                          "and metal — which all share one colour direction, so a segment of this colour may hold "
                                          "several of them, touching or not.",
                                          out.body_colour ? "body colour" : "mean colour", apart, sharp->method, *sharp->uncertainty_deg),
                              {"light_coloured"}});
  }
  // Most of its pixels at black in some channels (as many as make it clipped): there only the channels above black
  // measure the colour, and colours that differ in the others look alike — dim pixels under the file's black, or
  // bright ones of a colour beyond what the file holds.
  const Clipping& clipping = region.shape.clipping;
  std::string at_black;
  if (region.source == "segment" && only_at_black(clipping) && clipping.fraction >= criteria.black_faces_fraction) {
    std::vector<std::string> channels;
    for (const ClippedFace& f : clipping.faces) channels.push_back(std::string(1, "RGB"[f.channel]));
    // The channel with most pixels at black, face or not.
    const auto most = static_cast<std::size_t>(std::max_element(clipping.at_black.begin(), clipping.at_black.end()) - clipping.at_black.begin());
    at_black = fmt::format("{}", fmt::join(channels, " or "));
    const double median = clipping.black_brightest_median[most];
    if (median < kDimShare * clipping.top)
      out.findings.push_back({"at_black.dim",
                              fmt::format("{:.0f} % of its pixels have {} at black, and they are dim (the median of their brightest "
                                          "channel is {:.4g}, under a quarter of {:.4g}): there only the channels above black measure "
                                          "their colour, so dim surfaces whose colours differ in {} look alike, and a segment of such "
                                          "pixels may hold several dark objects, touching or not.",
                                          100 * clipping.fraction, at_black, median, clipping.top, at_black),
                              {"at_black_dim"}});
    else
      out.findings.push_back({"at_black.bright",
                              fmt::format("{:.0f} % of its pixels have {} at black although they are bright (the median of their "
                                          "brightest channel is {:.4g}, of {:.4g}): a saturated colour beyond what the file holds, cut "
                                          "at black, so colours that differ in {} alone look alike here, and a segment of such pixels "
                                          "may hold several objects of such colours, touching or not.",
                                          100 * clipping.fraction, at_black, median, clipping.top, at_black),
                              {"at_black_bright"}});
  }
  if (out.separate_areas > 1)
    out.findings.push_back({"separate_areas",
                            fmt::format("This segment is {} separate areas (each at least 1 % of it): the segmentation groups pixels by "
                                        "colour direction, and {} share this one, so it joins them.", out.separate_areas,
                                        light_coloured      ? "objects of the light's colour — white cloth, glass, plates, metal, lamps — all"
                                        : !at_black.empty() ? "objects that differ only in " + at_black
                                                            : "several objects"),
                            {}});
}

// What the numbers cannot tell.
void describe_uncertainty(const RegionAnalysis& region, const IlluminantEstimate& light, const std::optional<Explanation>& explanation,
                          const ShapeCriteria& criteria, Interpretation& out) {
  const bool have_light = light.rgb.norm() > 0;
  if (!have_light) out.uncertain.push_back("no estimate of the light's colour: every angle to it is missing");
  else if (!light.reliable) out.uncertain.push_back("the light's colour is uncertain: " + light.unreliable_reason);
  else if (light.uncertainty_deg)
    out.uncertain.push_back(fmt::format("the light's colour has a standard error of {:.1f}°, so angles to it are uncertain by as much",
                                        *light.uncertainty_deg));
  if (!explanation && out.thickness_over_noise && *out.thickness_over_noise > criteria.noise_factor)
    out.uncertain.push_back("which of interreflection, texture or a second light thickens it: a photograph has no light-path layers to tell");
  if (region.source == "segment")
    out.uncertain.push_back("the segment's edges: it is made by colour direction, so it may hold parts of other objects of its colour or miss its own darkest pixels");
}

}  // namespace

BlackReach black_reach(const Line& line, double min_line_angle_deg) {
  BlackReach r;
  const Vec3 d = line.direction.normalized();
  const double along = line.point.dot(d);  // the centroid's position along the line, from its closest point to black
  r.miss = (line.point - along * d).norm();
  const double top = along + std::max(line.t_max, line.t_min);  // the brightest end (the direction points brighter)
  r.angle_deg = std::atan2(r.miss, top) * kDegreesPerRadian;
  // The closest point's standard error: the centroid's (rms / √n across the line) and the tilt's, carried from the
  // centroid to the closest point (a direction's standard error is rms / (√n · the spread along the line)).
  const double n = std::max<double>(1, static_cast<double>(line.inliers));
  const double length = line.t_max - line.t_min;
  const double se = length > 0 ? line.rms / std::sqrt(n) * std::sqrt(1 + 12 * along * along / (length * length))
                               : std::numeric_limits<double>::infinity();
  r.uncertainty_deg = std::atan2(se, std::hypot(r.miss, top)) * kDegreesPerRadian;
  r.allowed_deg = std::max(min_line_angle_deg, 2 * r.uncertainty_deg);
  // A line known no better than the angle that tells two directions apart cannot say where it passes black.
  r.measured = std::isfinite(se) && r.uncertainty_deg <= min_line_angle_deg;
  r.reaches = r.measured && r.angle_deg <= r.allowed_deg;
  return r;
}

std::size_t separate_areas(const Region& r, int width) {
  const std::vector<std::uint32_t>& p = r.pixels;
  if (p.empty() || width <= 0) return 0;
  std::vector<std::size_t> parent(p.size());
  std::iota(parent.begin(), parent.end(), std::size_t{0});
  auto root = [&](std::size_t i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  auto join = [&](std::size_t i, std::size_t j) {
    const std::size_t a = root(i), b = root(j);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  };
  // The pixels are sorted, so the left neighbour is the one before and the one above is found by a pointer that
  // only moves forward: one pass, no search.
  const auto w = static_cast<std::uint32_t>(width);
  std::size_t up = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (i > 0 && p[i] % w > 0 && p[i - 1] == p[i] - 1) join(i, i - 1);
    if (p[i] >= w) {
      while (p[up] < p[i] - w) ++up;
      if (p[up] == p[i] - w) join(i, up);
    }
  }
  std::vector<std::size_t> size(p.size(), 0);
  for (std::size_t i = 0; i < p.size(); ++i) ++size[root(i)];
  const double least = 0.01 * static_cast<double>(p.size());
  return static_cast<std::size_t>(std::count_if(size.begin(), size.end(), [&](std::size_t n) { return n > 0 && static_cast<double>(n) >= least; }));
}

Interpretation interpret_region(const RegionAnalysis& region, const Region& pixels, int width,
                                const IlluminantAnalysis& illuminant, const ImageEncoding& encoding,
                                const std::optional<Explanation>& explanation, const ShapeCriteria& criteria) {
  Interpretation out;
  const ClusterShape& whole = region.linear_light ? *region.linear_light : region.shape;
  out.light_class = std::string(class_name(whole.shape));
  out.stored_class = std::string(class_name(region.shape.shape));
  // A clipped cluster is read on the samples off its faces: what the light made there is whole.
  const ClusterShape& s = off_the_faces(whole);
  const bool clipped = &s != &whole;
  out.curve = encoding.curve ? encoding.curve->describe() : "not known";
  const IlluminantEstimate& light = illuminant.best();
  const bool have_light = light.rgb.norm() > 0;
  if (have_light && s.samples > 0) {
    out.light_colour = unit(light.rgb);
    out.light_method = light.method + (light.reliable ? "" : " (unreliable)");
  }
  // The premises of the process: where the body line passes black, whether the highlight is the light's, and
  // whether any pixel reached the top (clipping happens to the values as stored).
  Premises premises;
  const Line* body_line = s.samples > 0 ? body_line_of(s) : nullptr;
  if (body_line) {
    premises.body = black_reach(*body_line, criteria.min_line_angle_deg);
    premises.body_is_colour = is_colour(unit(body_line->direction));
    out.body_reach = premises.body;
  }
  const std::optional<Branch> branch = s.samples > 0 ? measure_branch(s, light, criteria) : std::nullopt;
  if (branch) premises.light_highlight = branch->light;
  const ClusterShape& stored = region.shape;
  if (stored.clipping.known_high)
    for (const std::size_t n : stored.clipping.at_top) premises.top_pixels += n;
  // The process.
  const Statement whole_process = process_of(whole.shape, premises);
  out.process = whole_process.text;
  out.process_kind = whole_process.kind;
  out.process_claims = whole_process.claims;
  if (whole.shape == ShapeClass::Clipped && only_at_black(region.shape.clipping))
    out.process = "the file holds channels at their lowest value, below which the colour was cut off — a saturated "
                  "colour outside the file's gamut, or dim pixels under its black — and the cluster lies flattened on faces "
                  "of the RGB cube";
  if (clipped) {
    Premises below = premises;
    below.cut_at_top = reaches_the_top(stored.clipping);
    const Statement rest = process_of(s.shape, below);
    out.process += fmt::format("; off the faces, its {} pixels are {}: {}", s.samples, class_article(s.shape), rest.text);
    out.process_rest_kind = rest.kind;
    out.process_claims = rest.claims;
  }
  if (s.samples == 0) {
    out.uncertain.push_back(s.reason);
    return out;
  }
  // The body colour, of a line that reaches black; else the mean colour, and why the line is no body colour.
  if (s.moments.mean.norm() > 0) out.mean_colour = unit(s.moments.mean);
  const std::string to_light = [&](const std::optional<Vec3>& c) {
    return c && out.light_colour ? fmt::format(", {:.1f}° from the light's colour {} ({})", angular_error_deg(*c, *out.light_colour),
                                               colour_words(*out.light_colour), out.light_method)
                                 : std::string();
  }(out.mean_colour);
  if (premises.body_reaches()) {
    out.body_colour = unit(body_line->direction);
    std::string sentence = fmt::format("Body colour {} (unit RGB, linear): its line reaches black (it passes {:.1f}° from it, seen from "
                                       "its brightest end; within {:.1f}° it reaches it)", rgb3(*out.body_colour), premises.body->angle_deg,
                                       premises.body->allowed_deg);
    if (out.light_colour) {
      out.body_light_angle_deg = angular_error_deg(*out.body_colour, *out.light_colour);
      sentence += fmt::format(", {:.1f}° from the light's colour {} ({})", *out.body_light_angle_deg, colour_words(*out.light_colour),
                              out.light_method);
    }
    out.findings.push_back({"body_colour", sentence + ".", {"reaches_black"}});
  } else if (premises.body) {
    const std::string mean = out.mean_colour ? fmt::format("Its mean colour is {} (unit RGB, linear){}.", colour_words(*out.mean_colour), to_light)
                                             : std::string();
    const char* what = s.two_lines && body_line == &s.two_lines->body ? "body line" : "line";
    if (!premises.body->measured)
      out.findings.push_back({"body_reach_unknown",
                              fmt::format("Its {} is too short or too scattered to tell where it passes black (its angle from black is "
                                          "known to ± {:.1f}°, more than the {:g}° that tell two directions apart), so its direction is not "
                                          "quoted as a body colour. {}", what, premises.body->uncertainty_deg, criteria.min_line_angle_deg, mean),
                              {}});
    else if (!premises.body->reaches)
      out.findings.push_back({"no_body_colour",
                              fmt::format("Its {} does not reach black: it passes {:.3g} from black ({:.2f} × the length of its mean "
                                          "colour), {:.1f}° seen from its brightest end, beyond the {:.1f}° within which it would, so its "
                                          "direction is no body colour — a colour added to every pixel (a black level or flare, light of "
                                          "another colour over all of it) or a second light shifts it. {}",
                                          what, premises.body->miss, premises.body->miss / std::max(1e-300, s.moments.mean.norm()),
                                          premises.body->angle_deg, premises.body->allowed_deg, mean),
                              {"misses_black"}});
    else
      out.findings.push_back({"no_body_colour.not_a_colour",
                              fmt::format("Its {} reaches black but points along a direction with negative {}, which is no colour. {}",
                                          what, negative_channels(unit(body_line->direction)), mean),
                              {"reaches_black_not_a_colour"}});
  } else if (out.mean_colour) {
    out.findings.push_back({"mean_colour", fmt::format("Its colour is {} (unit RGB, linear){}.", colour_words(*out.mean_colour), to_light), {}});
  }
  // The dichromatic plane: spanned by the body colour and the light's — unless the cluster is thicker than its noise
  // off it, which no single plane of the model is.
  const bool planar = s.significant_axes >= 2 && s.black_plane;
  // (None for a noise-free image: there is no noise to be thick against.)
  const std::optional<double> thickness = s.plane && s.significant_axes >= 2 && s.noise_sigma[2] > 0
                                              ? std::optional<double>(s.sigma[2] / s.noise_sigma[2]) : std::nullopt;
  const bool thick = thickness && *thickness > criteria.noise_factor;
  if (planar && out.light_colour && !light.reliable) {
    out.light_off_plane_deg = std::asin(std::min(1.0, std::abs(s.black_plane->normal.normalized().dot(*out.light_colour)))) * kDegreesPerRadian;
    out.findings.push_back({"plane.light_unknown",
                            fmt::format("Its plane through black lies {:.1f}° from the light's colour, which is too uncertain to say "
                                        "whether the plane holds it.", *out.light_off_plane_deg),
                            {}});
  } else if (planar && out.light_colour && thickness) {
    out.light_off_plane_deg = std::asin(std::min(1.0, std::abs(s.black_plane->normal.normalized().dot(*out.light_colour)))) * kDegreesPerRadian;
    const double allowed = std::max(criteria.min_line_angle_deg, 2 * light.uncertainty_deg.value_or(0.0));
    const bool holds = *out.light_off_plane_deg <= allowed;
    // How far the cluster lies off that plane, in units of its noise across it: the model's plane passes black.
    const double off_black_plane = s.black_plane->rms / s.noise_sigma[2];
    std::string sentence = fmt::format("Its plane through black holds the light's colour within {:.1f}°", *out.light_off_plane_deg);
    std::string kind = "plane.off_model";
    std::vector<std::string> claims = {"off_model_plane", thick ? "thick" : "flat"};
    if (holds && !thick && off_black_plane <= criteria.noise_factor) {
      kind = "plane.model", claims = {"on_model_plane"};
      sentence += fmt::format(" (at most {:.1f}°), and the cluster lies within {:.1f} × its noise of that plane: a plane spanned by this "
                              "colour and the light's, as the dichromatic model has it", allowed, off_black_plane);
    } else if (holds && thick) {
      sentence += fmt::format(" (at most {:.1f}°), but the cluster is {:.1f} × as thick as its noise off its plane: no single plane of "
                              "the dichromatic model, other colours are added (below)", allowed, *thickness);
    } else if (holds) {
      sentence += fmt::format(" (at most {:.1f}°), but the cluster lies {:.1f} × its noise off that plane (its rms distance): it is flat, "
                              "but its plane does not pass black, so it is no plane of the dichromatic model — a colour added to every "
                              "pixel shifts it", allowed, off_black_plane);
    } else {
      sentence += fmt::format(": more than the {:.1f}° within which it would lie in it, so the plane is not spanned by this colour "
                              "and this light alone", allowed);
    }
    out.findings.push_back({kind, sentence + ".", claims});
  }
  if (branch) describe_highlight(s, *branch, region, light, out);
  // Clipping: the faces, and every pixel at a limit that too few of make a face (a sheen's).
  out.clipped_fraction = stored.clipping.fraction;
  bool high_face[3] = {false, false, false}, low_face[3] = {false, false, false};
  if (!stored.clipping.faces.empty()) {
    std::vector<std::string> faces;
    for (const ClippedFace& f : stored.clipping.faces) {
      (f.high ? high_face : low_face)[f.channel] = true;
      out.clipped_faces.push_back(fmt::format("{} {} at {:.4g}", "RGB"[f.channel], f.high ? "high" : "low", f.level));
      faces.push_back(fmt::format("{} ({:.1f} %)", out.clipped_faces.back(), 100 * f.fraction));
    }
    std::string sentence = fmt::format("{:.1f} % of its pixels are clipped: {}", 100 * stored.clipping.fraction, fmt::join(faces, ", "));
    // Enough of it at black to be clipped, yet under black_faces_fraction: the class was read off the faces.
    if (only_at_black(stored.clipping) && stored.clipping.fraction >= criteria.clipped_fraction &&
        whole.shape != ShapeClass::Clipped && stored.shape != ShapeClass::Clipped)
      sentence += fmt::format(" — only at black, in fewer than {:g} % of them, so its class is that of the pixels off the faces",
                              100 * criteria.black_faces_fraction);
    out.findings.push_back({"clipping.faces", sentence + ".", {}});
  }
  std::vector<std::string> few;
  for (int c = 0; c < 3; ++c) {
    const auto k = static_cast<std::size_t>(c);
    if (stored.clipping.known_high && stored.clipping.at_top[k] > 0 && !high_face[c])
      few.push_back(fmt::format("{} pixel{} ({:.2g} %) with {} at its top", stored.clipping.at_top[k], stored.clipping.at_top[k] == 1 ? "" : "s",
                                100.0 * static_cast<double>(stored.clipping.at_top[k]) / static_cast<double>(stored.samples), "RGB"[c]));
    if (stored.clipping.at_black[k] > 0 && !low_face[c])
      few.push_back(fmt::format("{} pixel{} ({:.2g} %) with {} at black", stored.clipping.at_black[k], stored.clipping.at_black[k] == 1 ? "" : "s",
                                100.0 * static_cast<double>(stored.clipping.at_black[k]) / static_cast<double>(stored.samples), "RGB"[c]));
  }
  if (!few.empty()) {
    bool top = false;
    for (int c = 0; c < 3; ++c) top = top || (stored.clipping.known_high && stored.clipping.at_top[static_cast<std::size_t>(c)] > 0 && !high_face[c]);
    out.findings.push_back({"clipping.few",
                            fmt::format("Clipped, though too few to flatten a face (under {:.1f} %, or spread too little): {}{}.",
                                        100 * kFaceFraction, fmt::join(few, ", "),
                                        top ? " — at the top, a sheen or the peak of a highlight cut off" : ""),
                            top ? std::vector<std::string>{"top_clipped"} : std::vector<std::string>{}});
  }
  if (stored.clipping.faces.empty() && few.empty()) out.findings.push_back({"clipping.none", "No pixel of it lies on a clipping level.", {"nothing_clipped"}});
  // Thickness beyond the noise.
  if (thickness) {
    out.thickness_over_noise = thickness;
    std::string sentence = fmt::format("Off its plane it is {:.1f} × as thick as its noise", *thickness);
    if (thick) {
      sentence += fmt::format(" (more than {:g} ×): a dichromatic surface under one light would lie in its plane, so other "
                              "colours are added — ", criteria.noise_factor);
      if (explanation && explanation->off_structure)
        sentence += fmt::format("the render's components put {:.0f} % of that spread on indirect light (interreflection)",
                                100 * explanation->off_structure->indirect_share);
      else
        sentence += "light interreflected from surfaces of other colours, a texture of several body colours, or a second "
                    "light of another colour would explain it";
    } else {
      sentence += fmt::format(" (at most {:g} ×): flat within its noise", criteria.noise_factor);
    }
    out.findings.push_back({thick ? "thickness.thick" : "thickness.flat", sentence + ".", {thick ? "thick" : "flat"}});
  }
  describe_shared_colour(region, pixels, width, illuminant, criteria, out);
  if (out.light_colour && out.mean_colour) out.mean_light_angle_deg = angular_error_deg(*out.mean_colour, *out.light_colour);
  // γ: quoted as a measurement only when the fit is one.
  if (const auto& g = region.declared_gamma) {
    out.declared_gamma = g->declared_gamma;
    if (g->measured) {
      out.fitted_gamma = g->fitted;
      out.fitted_gamma_se = g->se;
      out.findings.push_back({"gamma.measured",
                              fmt::format("The file declares {} (γ ≈ {:.3f}); its values fit γ = {:.3f} ± {:.3f}: {}.", out.curve,
                                          *out.declared_gamma, g->fitted, g->se, g->agree ? "they agree" : "they disagree"),
                              {"gamma_measured"}});
    } else {
      out.findings.push_back({"gamma.not_measured",
                              fmt::format("The file declares {} (γ ≈ {:.3f}); its values do not measure γ: {}.", out.curve,
                                          *out.declared_gamma, g->not_measured),
                              {"gamma_not_measured"}});
    }
  } else {
    out.findings.push_back({"curve",
                            fmt::format("The values are {}{}.", encoding.curve && !encoding.curve->linear() ? "encoded by " : "",
                                        encoding.curve ? (encoding.curve->linear() ? "linear, as the file declares" : out.curve)
                                                       : "of an unknown curve"),
                            {}});
  }
  if (region.linear_light && region.linear_light->shape != region.shape.shape)
    out.findings.push_back({"stored_class", fmt::format("As stored, the curve makes it {}.", out.stored_class), {}});
  // The light paths of a render, and what bends it.
  if (explanation && explanation->direct_share)
    out.findings.push_back({"light_paths",
                            fmt::format("Light paths: {:.0f} % direct, {:.0f} % indirect{}.", 100 * *explanation->direct_share,
                                        100 * explanation->indirect_share.value_or(0),
                                        explanation->glossy_share ? fmt::format("; {:.0f} % diffuse, {:.0f} % glossy",
                                                                                100 * explanation->diffuse_share.value_or(0), 100 * *explanation->glossy_share)
                                                                  : ""),
                            {}});
  if (region.bend) out.findings.push_back({"bend", "It is " + region.bend->summary + ".", {}});
  describe_uncertainty(region, light, explanation, criteria, out);
  return out;
}

std::string interpretation_text(const Interpretation& i) {
  std::string text = fmt::format("{} in linear light", i.light_class);
  if (i.stored_class != i.light_class) text += fmt::format(" ({} as stored)", i.stored_class);
  text += ": " + i.process + ".";
  for (const Statement& f : i.findings) text += " " + f.text;
  if (!i.uncertain.empty()) text += " Uncertain: " + fmt::format("{}", fmt::join(i.uncertain, "; ")) + ".";
  return text;
}

}  // namespace ct::analyzer
