#include "analyzer/interpretation.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>

#include <fmt/format.h>

namespace ct::analyzer {
namespace {

constexpr double kDeg = 180.0 / std::numbers::pi;

// What the class stands for physically, in the dichromatic reflection model and the camera.
std::string process_of(ShapeClass c) {
  switch (c) {
    case ShapeClass::None: return "no cluster was measured, so no process can be named";
    case ShapeClass::Clipped:
      return "the sensor or the file clipped the light: where a channel reached its limit the colour was cut off, "
             "and the cluster lies flattened on faces of the RGB cube";
    case ShapeClass::Mixed: return "pixels at the edge of two objects average their colours (the pixel's area)";
    case ShapeClass::Point: return "one colour at one brightness: an evenly lit patch, with no spread beyond noise";
    case ShapeClass::Linear:
      return "body (matte) reflection alone: one colour whose brightness changes with the shading, a line from black "
             "along the body colour";
    case ShapeClass::ThickenedLine:
      return "matte shading of one colour, thickened all along its line: other colours added in proportion "
             "(interreflected light, texture) or noise";
    case ShapeClass::L:
      return "body reflection (a line from black along the body colour) and, at its bright end, surface reflection "
             "adding the light's own colour: the dichromatic model's L, a sharp highlight on a glossy object";
    case ShapeClass::SkewedT:
      return "body reflection and a highlight that leaves the body line part-way along it: surface reflection of "
             "the light's colour where the body is not at its brightest";
    case ShapeClass::Fork:
      return "two lines from near black: one surface lit by two lights of different colours, or two surfaces";
    case ShapeClass::Gamma: return "the camera's response curve bent a cluster that is straight in the light";
    case ShapeClass::Curved:
      return "a bent cluster (the \"banana\"): light whose colour changes with brightness — interreflection whose share "
             "falls as the direct light grows, mixing at edges, or a camera curve";
    case ShapeClass::Thickened:
      return "a plane of body and surface reflection, with spread off it: interreflection from surfaces of other "
             "colours, texture, a second light, or noise";
    case ShapeClass::Volume:
      return "colours spread in three directions: several body colours (texture, several objects) or several lights";
    case ShapeClass::P:
      return "body reflection and a broad highlight: surface reflection of the light's colour spread over a wide lobe, "
             "filling an area of the dichromatic plane on one side of the body line";
    case ShapeClass::Superposed: return "the structures of several lights of different colours, added";
    case ShapeClass::Planar:
      return "a cluster in a plane through black: body and surface reflection mixed (the dichromatic plane) without "
             "separate lines";
  }
  return "";
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

// The body reflection's direction: the body line of a two-line fit, else the robust body line, else the line.
std::optional<Vec3> body_of(const ClusterShape& s) {
  if (s.two_lines && (s.shape == ShapeClass::L || s.shape == ShapeClass::SkewedT)) return unit(s.two_lines->body.direction);
  if (s.body_only) return unit(s.body_only->line.direction);
  if (s.line) return unit(s.line->direction);
  if (s.samples > 0 && s.moments.mean.norm() > 0) return unit(s.moments.mean);
  return std::nullopt;
}

// 4-connected parts of the region holding at least 1 % of its pixels.
std::size_t separate_areas(const Region& r, int width) {
  const std::vector<std::uint32_t>& p = r.pixels;
  if (p.empty() || width <= 0) return 0;
  std::vector<std::size_t> parent(p.size());
  std::iota(parent.begin(), parent.end(), std::size_t{0});
  auto root = [&](std::size_t i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  auto join = [&](std::size_t i, std::uint32_t neighbour) {
    const auto it = std::lower_bound(p.begin(), p.end(), neighbour);
    if (it == p.end() || *it != neighbour) return;
    const std::size_t a = root(i), b = root(static_cast<std::size_t>(it - p.begin()));
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  };
  const auto w = static_cast<std::uint32_t>(width);
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (p[i] % w > 0) join(i, p[i] - 1);
    if (p[i] >= w) join(i, p[i] - w);
  }
  std::vector<std::size_t> size(p.size(), 0);
  for (std::size_t i = 0; i < p.size(); ++i) ++size[root(i)];
  const double least = 0.01 * static_cast<double>(p.size());
  return static_cast<std::size_t>(std::count_if(size.begin(), size.end(), [&](std::size_t n) { return n > 0 && static_cast<double>(n) >= least; }));
}

std::string rgb3(const Vec3& v) { return fmt::format("({:.3f}, {:.3f}, {:.3f})", v[0], v[1], v[2]); }

// The highlight branch: where it points, how far from the light's colour, where it leaves the body line and how
// far it reaches.
void describe_highlight(const ClusterShape& s, const RegionAnalysis& region, const IlluminantEstimate& light, Interpretation& out) {
  const bool two_lines = s.two_lines && (s.shape == ShapeClass::L || s.shape == ShapeClass::SkewedT || s.shape == ShapeClass::P);
  if (two_lines || s.highlight_branch) {
    // The branch's colour by regression when measured (highlight_branch.h), else the highlight line's direction.
    out.highlight_direction = s.highlight_branch ? unit(s.highlight_branch->direction) : unit(s.two_lines->highlight.direction);
    if (two_lines) {
      const Line& h = s.two_lines->highlight;
      const Line& b = s.two_lines->body;
      const double body_top = std::max(b.at(b.t_max).norm(), b.at(b.t_min).norm());
      const double highlight_top = std::max(h.at(h.t_max).norm(), h.at(h.t_min).norm());
      if (body_top > 0) out.highlight_reach = highlight_top / body_top;
    }
    std::string sentence = fmt::format("Its highlight branch points along {}", rgb3(*out.highlight_direction));
    if (out.light_colour) {
      out.highlight_light_angle_deg = angular_error_deg(*out.highlight_direction, *out.light_colour);
      sentence += fmt::format(", {:.1f}° from the light's colour", *out.highlight_light_angle_deg);
    if (s.highlight_branch) sentence += fmt::format(" (± {:.1f}°, from {} pixels off the body line)", s.highlight_branch->uncertainty_deg, s.highlight_branch->samples);
    if (light.method == "highlight lines" && std::find(light.regions.begin(), light.regions.end(), region.name) != light.regions.end())
      sentence += light.regions.size() == 1 ? " — it is the light's estimate itself" : " — one of the branches the light's estimate averages";
    }
    if (two_lines) sentence += fmt::format(", leaves the body line {:.0f} % along it", 100 * s.two_lines->junction_on_body);
    if (out.highlight_reach) sentence += fmt::format(" and reaches {:.2f} × the body line's brightest colour", *out.highlight_reach);
    // Read on the samples below a clipping level: what lay beyond it is cut off, so the branch is of its dimmer part.
    if (reaches_the_top(region.shape.clipping))
      sentence += "; its brightest part is clipped, so this is the branch below the clipping level, and where the cut "
                  "was the highlight's colour is not known";
    out.findings.push_back(sentence + ".");
  }
}

// A segment whose colour one direction stands for several objects — the light's colour, or a dim colour whose
// weaker channels lie at black — and a segment of several separate areas.
void describe_shared_colour(const ClusterShape& s, const RegionAnalysis& region, const Region& pixels, int width,
                            const IlluminantAnalysis& illuminant, const ShapeCriteria& criteria, Interpretation& out) {
  if (region.source == "segment") out.separate_areas = separate_areas(pixels, width);
  bool light_coloured = false;
  if (out.light_colour && s.moments.mean.norm() > 0) out.mean_light_angle_deg = angular_error_deg(s.moments.mean, *out.light_colour);
  // Only a light known to within the angle that tells two directions apart can say a colour is the light's: the
  // most precise reliable measurement, if its standard error is that small.
  const IlluminantEstimate* sharp = nullptr;
  for (const auto* e : {illuminant.planes ? &*illuminant.planes : nullptr, illuminant.highlight_lines ? &*illuminant.highlight_lines : nullptr})
    if (e && e->reliable && e->uncertainty_deg && *e->uncertainty_deg <= criteria.min_line_angle_deg &&
        (!sharp || *e->uncertainty_deg < *sharp->uncertainty_deg))
      sharp = e;
  if (sharp && out.body_colour && region.source != "image") {
    const double apart = angular_error_deg(*out.body_colour, sharp->rgb);
    const double near = std::max(criteria.min_line_angle_deg, 2 * *sharp->uncertainty_deg);
    light_coloured = apart <= near;
    if (light_coloured)
      out.findings.push_back(fmt::format("Its body colour lies {:.1f}° from the light's colour as the {} measure it (± {:.1f}°): it "
                                         "is the light itself, or surfaces that return it unchanged — white and grey cloth, "
                                         "plates, glass and metal — which all share one colour direction, so a segment of this "
                                         "colour may hold several of them, touching or not.",
                                         apart, sharp->method, *sharp->uncertainty_deg));
  }
  // Most of its pixels at black in some channels (as many as make it clipped): there only the channels above black
  // measure the colour, and dim surfaces that differ in the others look alike.
  const Clipping& clipping = region.shape.clipping;
  std::string at_black;
  if (region.source == "segment" && only_at_black(clipping) && clipping.fraction >= criteria.black_faces_fraction) {
    std::vector<std::string> channels;
    for (const ClippedFace& f : clipping.faces) channels.push_back(std::string(1, "RGB"[f.channel]));
    at_black = fmt::format("{}", fmt::join(channels, " or "));
    out.findings.push_back(fmt::format("{:.0f} % of its pixels have {} at black: there only the channels above black measure "
                                       "their colour, so dim surfaces whose colours differ in {} look alike, and a segment of "
                                       "such pixels may hold several dark objects, touching or not.",
                                       100 * clipping.fraction, at_black, at_black));
  }
  if (out.separate_areas > 1)
    out.findings.push_back(fmt::format("This segment is {} separate areas (each at least 1 % of it): the segmentation groups "
                                       "pixels by colour direction, and {} share this one, so it joins them.", out.separate_areas,
                                       light_coloured      ? "objects of the light's colour — white cloth, glass, plates, the flames — all"
                                       : !at_black.empty() ? "dim objects that differ only in " + at_black
                                                           : "several objects"));
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

Interpretation interpret_region(const RegionAnalysis& region, const Region& pixels, int width,
                                const IlluminantAnalysis& illuminant, const ImageEncoding& encoding,
                                const std::optional<Explanation>& explanation, const ShapeCriteria& criteria) {
  Interpretation out;
  const ClusterShape& whole = region.linear_light ? *region.linear_light : region.shape;
  out.light_class = std::string(class_name(whole.shape));
  out.stored_class = std::string(class_name(region.shape.shape));
  out.process = process_of(whole.shape);
  // A clipped cluster is read on the samples off its faces: what the light made there is whole.
  const ClusterShape& s = off_the_faces(whole);
  const bool clipped = &s != &whole;
  if (whole.shape == ShapeClass::Clipped && only_at_black(region.shape.clipping))
    out.process = "the file holds channels at their lowest value, below which the colour was cut off — a saturated "
                  "colour outside the file's gamut, or dim pixels under its black — and the cluster lies flattened on faces "
                  "of the RGB cube";
  if (clipped)
    out.process += fmt::format("; off the faces, its {} pixels are {}: {}", s.samples, class_article(s.shape), process_of(s.shape));
  out.curve = encoding.curve ? encoding.curve->describe() : "not known";
  if (s.samples == 0) {
    out.uncertain.push_back(s.reason);
    return out;
  }
  const IlluminantEstimate& light = illuminant.best();
  const bool have_light = light.rgb.norm() > 0;
  if (have_light) {
    out.light_colour = unit(light.rgb);
    out.light_method = light.method + (light.reliable ? "" : " (unreliable)");
  }
  // The body colour and the light's.
  out.body_colour = body_of(s);
  if (out.body_colour && out.light_colour) {
    out.body_light_angle_deg = angular_error_deg(*out.body_colour, *out.light_colour);
    out.findings.push_back(fmt::format("Body colour {} (unit RGB, linear), {:.1f}° from the light's colour {} ({}).",
                                       rgb3(*out.body_colour), *out.body_light_angle_deg, rgb3(*out.light_colour), out.light_method));
  } else if (out.body_colour) {
    out.findings.push_back(fmt::format("Body colour {} (unit RGB, linear).", rgb3(*out.body_colour)));
  }
  // The dichromatic plane: spanned by the body colour and the light's.
  const bool planar = s.significant_axes >= 2 && s.black_plane;
  if (planar && out.light_colour) {
    out.light_off_plane_deg = std::asin(std::min(1.0, std::abs(s.black_plane->normal.normalized().dot(*out.light_colour)))) * kDeg;
    out.findings.push_back(fmt::format("Its dichromatic plane through black (normal {}) holds the light's colour within "
                                       "{:.1f}°{}.", rgb3(s.black_plane->normal), *out.light_off_plane_deg,
                                       *out.light_off_plane_deg <= criteria.min_line_angle_deg
                                           ? ": a plane spanned by this body colour and the light's, as the dichromatic model has it"
                                           : fmt::format(": more than the {:g}° two directions need to be told apart, so the plane "
                                                         "is not spanned by this body colour and this light alone", criteria.min_line_angle_deg)));
  }
  describe_highlight(s, region, light, out);
  // Clipping.
  const ClusterShape& stored = region.shape;  // clipping happens to the values as stored, at the file's levels
  out.clipped_fraction = stored.clipping.fraction;
  if (!stored.clipping.faces.empty()) {
    std::vector<std::string> faces;
    for (const ClippedFace& f : stored.clipping.faces) {
      out.clipped_faces.push_back(fmt::format("{} {} at {:.4g}", "RGB"[f.channel], f.high ? "high" : "low", f.level));
      faces.push_back(fmt::format("{} ({:.1f} %)", out.clipped_faces.back(), 100 * f.fraction));
    }
    std::string sentence = fmt::format("{:.1f} % of its pixels are clipped: {}", 100 * stored.clipping.fraction, fmt::join(faces, ", "));
    // Enough of it at black to be clipped, yet under black_faces_fraction: the class was read off the faces.
    if (only_at_black(stored.clipping) && stored.clipping.fraction >= criteria.clipped_fraction &&
        whole.shape != ShapeClass::Clipped && stored.shape != ShapeClass::Clipped)
      sentence += " — only at black, in fewer than half of them, so its class is that of the pixels off the faces";
    out.findings.push_back(sentence + ".");
  } else {
    out.findings.push_back("No pixel of it lies on a clipping level.");
  }
  // Thickness beyond the noise.
  if (s.plane && s.significant_axes >= 2) {
    out.thickness_over_noise = s.sigma[2] / std::max(1e-300, s.noise_sigma[2]);
    const bool thick = *out.thickness_over_noise > criteria.noise_factor;
    std::string sentence = fmt::format("Off its plane it is {:.1f} × as thick as its noise", *out.thickness_over_noise);
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
    out.findings.push_back(sentence + ".");
  }
  describe_shared_colour(s, region, pixels, width, illuminant, criteria, out);
  // γ.
  if (region.declared_gamma) {
    out.declared_gamma = region.declared_gamma->declared_gamma;
    out.fitted_gamma = region.declared_gamma->fitted;
    out.fitted_gamma_se = region.declared_gamma->se;
    out.findings.push_back(fmt::format("The file declares {} (γ ≈ {:.3f}); its values fit γ = {:.3f} ± {:.3f}: {}.", out.curve,
                                       *out.declared_gamma, *out.fitted_gamma, *out.fitted_gamma_se,
                                       region.declared_gamma->agree ? "they agree" : "they disagree"));
  } else {
    out.findings.push_back(fmt::format("The values are {}{}.", encoding.curve && !encoding.curve->linear() ? "encoded by " : "",
                                       encoding.curve ? (encoding.curve->linear() ? "linear, as the file declares" : out.curve)
                                                      : "of an unknown curve"));
  }
  if (region.linear_light && region.linear_light->shape != region.shape.shape)
    out.findings.push_back(fmt::format("As stored, the curve makes it {}.", out.stored_class));
  // The light paths of a render, and what bends it.
  if (explanation) {
    if (explanation->direct_share)
      out.findings.push_back(fmt::format("Light paths: {:.0f} % direct, {:.0f} % indirect{}.", 100 * *explanation->direct_share,
                                         100 * explanation->indirect_share.value_or(0),
                                         explanation->glossy_share ? fmt::format("; {:.0f} % diffuse, {:.0f} % glossy",
                                                                                 100 * explanation->diffuse_share.value_or(0), 100 * *explanation->glossy_share)
                                                                   : ""));
  }
  if (region.bend) out.findings.push_back("It is " + region.bend->summary + ".");
  describe_uncertainty(region, light, explanation, criteria, out);
  return out;
}

std::string interpretation_text(const Interpretation& i) {
  std::string text = fmt::format("{} in linear light", i.light_class);
  if (i.stored_class != i.light_class) text += fmt::format(" ({} as stored)", i.stored_class);
  text += ": " + i.process + ".";
  for (const std::string& f : i.findings) text += " " + f;
  if (!i.uncertain.empty()) text += " Uncertain: " + fmt::format("{}", fmt::join(i.uncertain, "; ")) + ".";
  return text;
}

}  // namespace ct::analyzer
