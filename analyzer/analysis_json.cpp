// SPDX-License-Identifier: Apache-2.0
#include "analyzer/analysis_json.h"

#include <cmath>

#include <fmt/core.h>

namespace ct::analyzer {
namespace {

using nlohmann::json;

json vec(const Vec3& v) { return json::array({v[0], v[1], v[2]}); }
json mat(const Mat3& m) {
  json rows = json::array();
  for (int r = 0; r < 3; ++r) rows.push_back(vec(m.row(r).transpose()));
  return rows;
}
json axes(const Mat3& m) {  // columns are the axes; listed one axis per entry
  json list = json::array();
  for (int c = 0; c < 3; ++c) list.push_back(vec(m.col(c)));
  return list;
}

json line_json(const Line& l) {
  return {{"point", vec(l.point)},   {"direction", vec(l.direction)}, {"t_min", l.t_min},
          {"t_max", l.t_max},        {"start", vec(l.at(l.t_min))},   {"end", vec(l.at(l.t_max))},
          {"inliers", l.inliers},    {"rms", l.rms}};
}

json plane_json(const Plane& p) { return {{"normal", vec(p.normal)}, {"offset", p.offset}, {"rms", p.rms}}; }

template <class T, class F>
json optional_json(const std::optional<T>& v, F&& f) {
  return v ? f(*v) : json(nullptr);
}

json estimate_json(const IlluminantEstimate& e) {
  json j = {{"method", e.method}, {"rgb", vec(e.rgb)}, {"regions", e.regions}};
  j["error_deg"] = e.error_deg ? json(*e.error_deg) : json(nullptr);
  j["uncertainty_deg"] = e.uncertainty_deg ? json(*e.uncertainty_deg) : json(nullptr);
  j["systematic"] = e.systematic.empty() ? json(nullptr) : json(e.systematic);
  j["reliable"] = e.reliable;
  j["unreliable_reason"] = e.reliable ? json(nullptr) : json(e.unreliable_reason);
  j["camera_angle_deg"] = e.camera_angle_deg ? json(*e.camera_angle_deg) : json(nullptr);
  return j;
}

json interpretation_json(const Interpretation& i) {
  auto opt = [](const std::optional<double>& v) { return v ? json(*v) : json(nullptr); };
  auto opt_vec = [](const std::optional<Vec3>& v) { return v ? vec(*v) : json(nullptr); };
  json findings = json::array(), statements = json::array();
  for (const Statement& f : i.findings) {
    findings.push_back(f.text);
    statements.push_back({{"kind", f.kind}, {"text", f.text}, {"claims", f.claims}});
  }
  return {{"text", interpretation_text(i)},
          {"class_in_linear_light", i.light_class},
          {"class_as_stored", i.stored_class},
          {"process", i.process},
          {"body_colour", opt_vec(i.body_colour)},
          {"light_colour", opt_vec(i.light_colour)},
          {"light_method", i.light_method},
          {"body_light_angle_deg", opt(i.body_light_angle_deg)},
          {"light_off_plane_deg", opt(i.light_off_plane_deg)},
          {"highlight_direction", opt_vec(i.highlight_direction)},
          {"highlight_light_angle_deg", opt(i.highlight_light_angle_deg)},
          {"highlight_reach", opt(i.highlight_reach)},
          {"clipped_fraction", i.clipped_fraction},
          {"clipped_faces", i.clipped_faces},
          {"thickness_over_noise", opt(i.thickness_over_noise)},
          {"mean_light_angle_deg", opt(i.mean_light_angle_deg)},
          {"separate_areas", i.separate_areas},
          {"curve", i.curve},
          {"declared_gamma", opt(i.declared_gamma)},
          {"fitted_gamma", opt(i.fitted_gamma)},
          {"fitted_gamma_se", opt(i.fitted_gamma_se)},
          {"findings", findings},
          {"statements", statements},
          {"process_kind", i.process_kind},
          {"process_claims", i.process_claims},
          {"process_rest_kind", i.process_rest_kind.empty() ? json(nullptr) : json(i.process_rest_kind)},
          {"mean_colour", opt_vec(i.mean_colour)},
          {"body_reach", i.body_reach ? json{{"miss", i.body_reach->miss}, {"angle_deg", i.body_reach->angle_deg},
                                             {"uncertainty_deg", i.body_reach->uncertainty_deg}, {"allowed_deg", i.body_reach->allowed_deg},
                                             {"reaches", i.body_reach->reaches}}
                                      : json(nullptr)},
          {"uncertain", i.uncertain}};
}

json explanation_json(const Explanation& e) {
  json families = json::array();
  for (const FamilyShares& f : e.families) {
    json components = json::array();
    for (const ComponentShare& c : f.components)
      components.push_back({{"name", c.name}, {"energy_share", c.energy_share}, {"dominant_pixels", c.dominant_pixels}});
    families.push_back({{"family", family_name(f.family)}, {"components", components}});
  }
  auto number = [](const std::optional<double>& v) { return v ? json(*v) : json(nullptr); };
  return {{"families", families},
          {"direct_share", number(e.direct_share)},
          {"indirect_share", number(e.indirect_share)},
          {"diffuse_share", number(e.diffuse_share)},
          {"glossy_share", number(e.glossy_share)},
          {"off_structure", optional_json(e.off_structure,
                                          [](const OffStructure& o) {
                                            return json{{"structure", o.structure},
                                                        {"direction", vec(o.direction)},
                                                        {"rms_total", o.rms_total},
                                                        {"rms_direct", o.rms_direct},
                                                        {"indirect_share", o.indirect_share}};
                                          })},
          {"notes", e.notes}};
}

// What the camera did to the analysed numbers (docs/analyze.md, "Input"): its black level and the shift it
// and the dark current cause, whether the black level was subtracted, its white level.
json input_json(const ImageAnalysis& a) {
  const ImageEncoding& e = a.encoding;
  const auto number = [](const std::optional<double>& v) { return v ? json(*v) : json(nullptr); };
  const auto triple = [](const std::optional<double>& v) { return v ? json::array({*v, *v, *v}) : json(nullptr); };
  // Black level and mean dark signal move every pixel by the same vector along the grey axis: the histogram is
  // shifted, its shape unchanged (the paper: "only a shift").
  std::optional<double> shift, remaining;
  if (e.black_level || e.dark_signal) {
    shift = e.black_level.value_or(0.0) + e.dark_signal.value_or(0.0);
    remaining = e.dark_signal.value_or(0.0) + (e.black_subtracted ? 0.0 : e.black_level.value_or(0.0));
  }
  return {{"metadata", e.metadata.empty() ? json(nullptr) : json(e.metadata)},
          {"black_level", triple(e.black_level)},
          {"subtracted", e.black_subtracted},
          {"dark_signal", triple(e.dark_signal)},
          {"shift", triple(shift)},
          {"shift_length", shift ? json(std::sqrt(3.0) * std::abs(*shift)) : json(nullptr)},
          {"remaining_shift", triple(remaining)},
          {"white_level", number(e.white_level)},
          {"clipping_level", number(e.clipping_level())},
          {"read_noise", number(e.read_noise)},
          {"bits", e.adc_bits ? json(*e.adc_bits) : json(nullptr)},
          {"noise", e.noise ? json(*e.noise) : json(nullptr)},
          {"adc", e.adc ? json(*e.adc) : json(nullptr)},
          {"curve", e.curve ? json{{"description", e.curve->describe()},
                                   {"gamma", e.curve->srgb ? json(nullptr) : json(e.curve->gamma)},
                                   {"k", e.curve->srgb ? json(nullptr) : json(e.curve->k)},
                                   {"srgb", e.curve->srgb},
                                   {"linearised", !e.curve->linear()},
                                   {"source", e.curve_source}}
                            : json(nullptr)}};
}

}  // namespace

std::string region_stem(std::size_t index) { return fmt::format("region-{:02}", index); }

json shape_to_json(const ClusterShape& s) {
  json decisions = json::array();
  for (const Decision& d : s.decisions)
    decisions.push_back({{"test", d.test}, {"value", d.value}, {"threshold", d.threshold}, {"passed", d.passed}});
  json faces = json::array();
  for (const ClippedFace& f : s.clipping.faces)
    faces.push_back({{"channel", std::string(1, "RGB"[f.channel])}, {"side", f.high ? "high" : "low"}, {"level", f.level},
                     {"pixels", f.count}, {"fraction", f.fraction}});
  json j = {
      {"class", class_name(s.shape)},
      {"reason", s.reason},
      {"decisions", decisions},
      {"samples", s.samples},
      {"fit_points", s.fit_points},
      {"clipping", {{"fraction", s.clipping.fraction}, {"pixels", s.clipping.clipped}, {"faces", faces},
                    {"at_top", s.clipping.at_top}, {"at_black", s.clipping.at_black},
                    {"black_brightest_median", s.clipping.black_brightest_median}, {"top", s.clipping.top}}},
  };
  if (s.samples == 0) return j;
  j["mean"] = vec(s.moments.mean);
  j["covariance"] = mat(s.moments.covariance);
  j["eigenvalues"] = vec(s.moments.eigenvalues);
  j["axes"] = axes(s.moments.axes);
  j["sigma"] = vec(s.sigma);
  if (s.shape == ShapeClass::Clipped) {
    // The faces hold the cluster; nothing of its shape was measured (noise, dimensionality, lines, planes are
    // the unclipped part's, in "unclipped"), so those are null, not zero.
    const ClusterShape* rest = s.unclipped.empty() ? nullptr : &s.unclipped.front();
    for (const char* key : {"noise_sigma", "significant_axes", "linearity", "planarity", "scattering", "line", "body_line",
                            "two_lines", "plane", "dichromatic_plane", "curve", "gamma"})
      j[key] = nullptr;
    j["unclipped_class"] = rest ? json(class_name(rest->shape)) : json(nullptr);
    if (rest) j["unclipped"] = shape_to_json(*rest);
    return j;
  }
  j["noise_sigma"] = vec(s.noise_sigma);
  j["significant_axes"] = s.significant_axes;
  j["linearity"] = s.linearity;
  j["planarity"] = s.planarity;
  j["scattering"] = s.scattering;
  j["line"] = optional_json(s.line, line_json);
  j["body_line"] = optional_json(s.body_only, [](const LineSearch& b) { return line_json(b.line); });
  j["two_lines"] = optional_json(s.two_lines, [](const TwoLines& t) {
    return json{{"body", line_json(t.body)},
                {"highlight", line_json(t.highlight)},
                {"junction", vec(t.junction)},
                {"junction_on_body", t.junction_on_body},
                {"junction_on_highlight", t.junction_on_highlight},
                {"gap", t.gap},
                {"angle_deg", t.angle_deg},
                {"body_fraction", t.body_fraction},
                {"highlight_fraction", t.highlight_fraction}};
  });
  j["highlight_branch"] = optional_json(s.highlight_branch, [](const HighlightBranch& b) {
    return json{{"direction", vec(b.direction)}, {"samples", b.samples}, {"statistical_deg", b.statistical_deg},
                {"halves_deg", b.halves_deg}, {"uncertainty_deg", b.uncertainty_deg}};
  });
  j["plane"] = optional_json(s.plane, plane_json);
  j["dichromatic_plane"] = optional_json(s.black_plane, plane_json);
  if (s.plane) j["thickness_over_noise"] = s.sigma[2] / std::max(1e-300, s.noise_sigma[2]);
  j["curve"] = optional_json(s.curve, [](const PrincipalCurve& c) {
    json points = json::array();  // the curve itself, for drawing
    for (int k = 0; k <= 16; ++k) points.push_back(vec(c.at(c.t_min + (c.t_max - c.t_min) * k / 16.0)));
    return json{{"bend", c.bend},           {"curvature", c.curvature}, {"curve_rms", c.curve_rms},
                {"straight_rms", c.straight_rms}, {"explained", c.explained}, {"points", points}};
  });
  j["gamma"] = optional_json(s.gamma, [](const GammaFit& g) {
    return json{{"gamma", g.gamma},
                {"flattens", g.flat == GammaFlat::Plane ? "plane" : "line"},
                {"gamma_se", g.gamma_se ? json(*g.gamma_se) : json(nullptr)},
                {"straightness_as_is", g.straightness_as_is},
                {"straightness_linearised", g.straightness_linearised},
                {"used", g.used}};
  });
  if (!s.unclipped.empty()) j["unclipped"] = shape_to_json(s.unclipped.front());
  if (!s.clear_of_black.empty()) {
    const ClusterShape& c = s.clear_of_black.front();
    json levels = json::object();
    for (std::size_t k = 0; k < 3; ++k)
      if (!std::isnan(s.clear_levels[k])) levels[std::string(1, "RGB"[k])] = s.clear_levels[k];
    j["clear_of_black"] = {{"levels", levels}, {"samples", c.samples},
                           {"class", class_name(c.shape)}, {"dichromatic_plane", optional_json(c.black_plane, plane_json)}};
  }
  return j;
}

static json segmentation_json(const Segmentation& s) {
  const SegmentationOptions& o = s.options;
  auto per_channel = [](const Vec3& v) { return json::array({v[0], v[1], v[2]}); };
  return {{"method", "linear colour clusters extended over dichromatic planes (Klinker, Shafer & Kanade 1990)"},
          {"labels_file", "labels.png"},
          {"parameters", {{"working_megapixels", o.working_megapixels}, {"min_area", o.min_area}, {"tolerance", o.tolerance},
                          {"angle_deg", o.angle_deg}, {"dark", o.dark}}},
          {"working_size", {s.working_width, s.working_height}},
          {"noise", {{"model", "sigma_c(I)^2 = a_c + b_c * I + c_c * I^2 in the stored values at the working size (carried into linear light by the curve's slope), never below floor"},
                     {"estimator", "Immerkaer 1996, lower quartile per brightness band"},
                     {"a", per_channel(s.noise.a)}, {"b", per_channel(s.noise.b)}, {"c", per_channel(s.noise.c)}, {"floor", s.noise.floor},
                     {"pixels_used", s.noise.samples}}},
          {"valid_pixels", s.valid_pixels},
          {"unassigned_pixels", s.unassigned_pixels},
          {"unassigned_fraction", s.unassigned_fraction()},
          {"unassigned_dark_pixels", s.dark_pixels},
          {"unassigned_small_pixels", s.small_pixels},
          {"highlight_merges", s.highlight_merges},
          {"clipped_highlight_merges", s.clipped_merges}};
}

// Why the mask's taps are as far apart as they are.
static std::string spacing_reason(const ImageNoise& noise) {
  const auto& c = noise.spacing_choice;
  if (!c) return "the file says each pixel's three values were measured at it (chromatrace.cfa 0, or raw half size): taps adjacent";
  std::string reason;
  if (c->confirmed)
    reason = fmt::format("the noise's measured correlation shows it independent at {} pixel{} (residuals correlated with their "
                         "neighbours' {} pixel{} on within {} of -2/3, white noise's, beyond 2 standard errors)",
                         c->spacing, c->spacing == 1 ? "" : "s", c->spacing, c->spacing == 1 ? "" : "s", kSpacingTolerance);
  else
    reason = fmt::format("the noise's measured correlation does not show it independent at 1, 2 or 3 pixels (shared by neighbouring "
                         "pixels: demosaicing, compression, resampling, or too little noise to tell): taps {} pixels apart, the "
                         "farthest tried", c->spacing);
  if (c->correlated_beyond)
    reason += "; the noise is still shared at 3 pixels, so its sigma is a lower bound and clusters may look thicker than their noise";
  return reason;
}

// The noise every region's shape is judged against: per brightness band, σ along R, G and B.
static json image_noise_json(const ImageNoise& noise) {
  json spacing_tests = json::array();
  if (noise.spacing_choice)
    for (const SpacingTest& t : noise.spacing_choice->tests)
      spacing_tests.push_back({{"spacing", t.spacing}, {"measurable", t.measurable},
                               {"departure", t.measurable ? json(t.departure) : json(nullptr)},
                               {"standard_error", t.measurable ? json(t.standard_error) : json(nullptr)}});
  json bands = json::array();
  for (std::size_t k = 0; k < noise.bands.size(); ++k)
    bands.push_back({{"brightness", {noise.bands[k].lo, noise.bands[k].hi}},
                     {"sigma", {std::max(noise.floor, noise.band_sigma(k, Vec3::UnitX())), std::max(noise.floor, noise.band_sigma(k, Vec3::UnitY())),
                                std::max(noise.floor, noise.band_sigma(k, Vec3::UnitZ()))}}});
  if (noise.camera)
    return {{"estimator", fmt::format("the camera's calibration ({}): per channel K^2 (read^2 + DSNU^2) + 1/12 + K mu + (PRNU mu)^2 "
                                      "at each brightness band's mean signal mu (DN above black)",
                                      noise.camera->source)},
            {"camera",
             {{"gain_dn_per_e", noise.camera->gain_dn_per_e}, {"read_e", noise.camera->read_e}, {"dsnu_e", noise.camera->dsnu_e},
              {"prnu", noise.camera->prnu}}},
            {"brightness", "(R + G + B) / 3 in the analysed layer's units"},
            {"floor", noise.floor},
            {"bands", bands}};
  return {{"estimator", "Immerkaer 1996 over the whole image: 3x3 residuals of R, G, B, per brightness band the 3-sigma clipped "
                        "median of their projection (flat areas decide, not texture)"},
          {"spacing", noise.spacing},
          {"spacing_reason", spacing_reason(noise)},
          {"spacing_tests", spacing_tests},
          {"brightness", "(R + G + B) / 3 in the analysed layer's units"},
          {"pixels_used", noise.pixels},
          {"floor", noise.floor},
          {"bands", bands}};
}

json analysis_to_json(const ImageAnalysis& a, const std::vector<bool>& plotted) {
  json regions = json::array();
  for (std::size_t i = 0; i < a.results.size(); ++i) {
    const RegionAnalysis& r = a.results[i];
    const std::string stem = region_stem(i);
    json j = {{"index", i},
              {"name", r.name},
              {"source", r.source},
              {"label", r.label >= 0 ? json(r.label) : json(nullptr)},
              {"pixels", r.pixels},
              {"non_finite_pixels", r.non_finite},
              {"valid_pixels", r.shape.samples},
              {"occupied_bins", r.histogram.cells.size()},
              {"shape", shape_to_json(r.shape)},
              {"linear_light", r.linear_light ? shape_to_json(*r.linear_light) : json(nullptr)},
              {"gamma_against_declared", optional_json(r.declared_gamma, [](const GammaComparison& c) {
                 return json{{"declared_curve", c.declared}, {"declared_gamma", c.declared_gamma}, {"fitted_gamma", c.fitted},
                             {"gamma_se", c.se}, {"difference_in_se", c.difference_in_se}, {"agree", c.agree},
                             {"measured", c.measured}, {"not_measured", c.measured ? json(nullptr) : json(c.not_measured)},
                             {"rule", fmt::format("agree when |fitted - declared| <= {} gamma_se", kGammaAgreement)}};
               })},
              {"files", {{"histogram", "histograms/" + stem + ".json"},
                         {"plot", plotted.empty() || (i < plotted.size() && plotted[i]) ? json("plots/" + stem + ".png") : json(nullptr)}}}};
    j["interpretation"] = i < a.interpretations.size() ? interpretation_json(a.interpretations[i]) : json(nullptr);
    j["explanation"] = i < a.explanations.size() ? optional_json(a.explanations[i], explanation_json) : json(nullptr);
    j["bend_cause"] = optional_json(r.bend, [](const BendCause& b) {
      json tests = json::array();
      for (const BendTest& t : b.tests)
        tests.push_back({{"cause", t.cause}, {"without", t.without}, {"bend", t.bend}, {"straight", t.straight}});
      return json{{"bend", b.bend}, {"reference_bend", b.reference_bend}, {"tests", tests}, {"causes", b.causes},
                  {"straightened", b.straightened}, {"summary", b.summary}};
    });
    regions.push_back(std::move(j));
  }
  const HistogramSpec& spec = a.context.spec;
  const ShapeCriteria& k = a.options.criteria;
  const IlluminantAnalysis& il = a.illuminant;
  // Every estimate with the angle between it and the chosen one.
  const auto beside_chosen = [&](const IlluminantEstimate& e) {
    json j = estimate_json(e);
    j["angle_to_chosen_deg"] = angular_error_deg(e.rgb, il.best().rgb);
    return j;
  };
  return {{"format", kAnalysisFormat},
          {"image", {{"file", a.file}, {"width", a.width}, {"height", a.height}, {"layer", a.layer},
                     {"integer", a.encoding.integer}, {"bits", a.encoding.bits}, {"full_scale", a.encoding.full_scale}}},
          {"input", input_json(a)},
          {"histogram", {{"bins", spec.bins}, {"lo", spec.lo}, {"hi", spec.hi}, {"robust", spec.robust},
                         {"outliers", spec.robust ? json{{"pixels", spec.outliers}, {"max", spec.outlier_max},
                                                        {"rule", fmt::format("a pixel's brightest channel above {} × the "
                                                                             "{:g}th percentile", kRobustMargin,
                                                                             100 * kRobustQuantile)}}
                                                  : json(nullptr)},
                         {"full_max", spec.full_max}}},
          {"clipping_levels", a.context.high_levels},
          {"clipping_levels_source", a.context.high_levels_source},
          {"clipping_low_levels", a.context.clipping.low},
          {"quantisation_sigma", a.context.quantisation_sigma},
          {"image_noise", image_noise_json(a.context.noise)},
          {"criteria",
           {{"min_samples", k.min_samples},
            {"max_points", k.max_points},
            {"noise_factor", k.noise_factor},
            {"relative_floor", k.relative_floor},
            {"clipped_fraction", k.clipped_fraction},
            {"black_faces_fraction", k.black_faces_fraction},
            {"body_only_fraction", k.body_only_fraction},
            {"two_line_residual", k.two_line_residual},
            {"min_highlight_samples", k.min_highlight_samples},
            {"min_highlight_fraction", k.min_highlight_fraction},
            {"highlight_length", k.highlight_length},
            {"min_line_angle_deg", k.min_line_angle_deg},
            {"highlight_end", k.highlight_end},
            {"l_junction", k.l_junction},
            {"t_junction", k.t_junction},
            {"max_bend_for_straight", k.max_bend_for_straight},
            {"curve_residual", k.curve_residual},
            {"gamma_straightening", k.gamma_straightening},
            {"min_gamma_departure", k.min_gamma_departure},
            {"thickened_ratio", k.thickened_ratio},
            {"p_body_fraction", k.p_body_fraction},
            {"p_one_side", k.p_one_side},
            {"p_area_ratio", k.p_area_ratio},
            {"thick_line_ratio", k.thick_line_ratio},
            {"thick_line_coverage", k.thick_line_coverage},
            {"superposed_share", k.superposed_share},
            {"min_mixed_samples", k.min_mixed_samples}}},
          {"regions", regions},
          {"regions_by_size", regions_by_size(a.results)},
          {"segmentation", a.segmentation ? segmentation_json(*a.segmentation) : json(nullptr)},
          {"illuminant",
           {{"estimate", estimate_json(il.best())},
            {"choice", il.choice},
            {"highlight_lines", optional_json(il.highlight_lines, beside_chosen)},
            {"dichromatic_planes", optional_json(il.planes, beside_chosen)},
            {"inverse_intensity_chromaticity", optional_json(il.iic, beside_chosen)},
            {"statistical", [&] {
               json list = json::array();
               for (const IlluminantEstimate& e : il.statistical) list.push_back(beside_chosen(e));
               return list;
             }()},
            {"lights_in_view", [&] {
               json list = json::array();
               for (const LightInView& l : il.lights)
                 list.push_back({{"name", l.name}, {"x", l.x}, {"y", l.y}, {"rgb", vec(l.rgb)}, {"brightness", l.brightness},
                                 {"pixels", l.pixels}, {"clipped_pixels", l.clipped},
                                 {"angle_to_chosen_deg", angular_error_deg(l.rgb, il.best().rgb)}});
               return list;
             }()},
            {"light_regions", il.light_regions},
            {"known", optional_json(il.known, vec)},
            {"camera_white_balance", optional_json(il.camera_white, vec)},
            {"notes", il.notes}}},
          {"notes", a.notes}};
}

json histogram_to_json(const Histogram3& h, const Histogram2& chromaticity) {
  json cells = json::array();
  for (const HistogramCell& c : h.cells) {
    const auto bin = h.bin_of(c.index);
    cells.push_back({bin[0], bin[1], bin[2], c.count});
  }
  json projections = json::object();
  const auto p = analyzer::projections(h);
  const char* names[] = {"RG", "RB", "GB"};
  for (int k = 0; k < 3; ++k) projections[names[k]] = p[k].counts;
  return {{"bins", h.spec.bins},
          {"lo", h.spec.lo},
          {"hi", h.spec.hi},
          {"total", h.total},
          {"max_count", h.max_count},
          {"cells", cells},
          {"cells_format", "[r_bin, g_bin, b_bin, count]"},
          {"projections", projections},
          {"projections_format", "bins × bins counts, row = first channel, column = second"},
          {"chromaticity", {{"bins", chromaticity.bins}, {"counts", chromaticity.counts},
                            {"format", "bins × bins counts, row = r = R/(R+G+B), column = g = G/(R+G+B), over [0, 1]"}}}};
}

}  // namespace ct::analyzer
