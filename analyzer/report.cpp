// SPDX-License-Identifier: Apache-2.0
#include "analyzer/report.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

#include "analyzer/plots.h"
#include "analyzer/viewer_bundle.h"
#include "core/colour.h"
#include "core/html_text.h"
#include "core/json_input.h"
#include "core/statistics.h"
#include "plot/png.h"
#include "plot/ticks.h"

namespace ct::analyzer {
namespace {

using nlohmann::json;

template <class T>
std::string base64_of(const std::vector<T>& values) {  // little-endian, as typed arrays read them on x86 and ARM
  return base64(std::string_view(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T)));
}

// Inside <script>, "</" would end the element early; "<\/" means the same to JavaScript (the viewer's own code).
std::string script_safe(std::string text) {
  for (std::size_t at = text.find("</"); at != std::string::npos; at = text.find("</", at + 3)) text.replace(at, 2, "<\\/");
  return text;
}

// JSON inside <script>: every "<" as \u003c (JSON has "<" only in strings), so that no text in it (a name from a
// file's header) can end the element or turn the HTML parser's script states ("<!--<script>" would swallow the
// element's end and the viewer after it).
std::string json_script_safe(const std::string& json) {
  std::string out;
  out.reserve(json.size());
  for (const char c : json) out += c == '<' ? std::string("\\u003c") : std::string(1, c);
  return out;
}

struct Display {
  int width = 0, height = 0;
  double scale = 1;  // display pixels per image pixel
};

Display display_size(int width, int height) {
  const double scale = std::min(1.0, static_cast<double>(kReportImageSize) / std::max(width, height));
  return {std::max(1, static_cast<int>(std::lround(width * scale))), std::max(1, static_cast<int>(std::lround(height * scale))), scale};
}

// The image as 8-bit sRGB for the page: the sensor's display layer (display.R/G/B, already sRGB-encoded in
// [0, 1]) when the file has one and the final image is analysed; else integer files up to their clipping
// level (the camera's white level less black, or full scale); float files scaled so that the 99.5th percentile
// of the brightest channel is white, then sRGB-encoded.
std::string image_png(const AnalysisImage& input, const RgbImage& layer, const ImageAnalysis& a, const Display& d) {
  const bool display = a.layer == "final" && input.display && input.display->width == layer.width &&
                       input.display->height == layer.height;
  const RgbImage& shown_layer = display ? *input.display : layer;
  double white = 1.0;
  if (!display && a.encoding.integer) white = a.encoding.clipping_level().value_or(a.encoding.full_scale);
  if (!display && !a.encoding.integer) {
    std::vector<float> brightest;
    for (std::size_t p = 0; p < layer.pixel_count(); ++p) {
      const float m = std::max({layer.rgb[p * 3], layer.rgb[p * 3 + 1], layer.rgb[p * 3 + 2]});
      if (std::isfinite(m)) brightest.push_back(m);
    }
    white = quantile_in_place(brightest, 0.995);  // 0 for none
  }
  if (!(white > 0)) white = 1;
  const bool encode = !display && !a.encoding.integer;
  cv::Mat full(shown_layer.height, shown_layer.width, CV_8UC3);
  for (int y = 0; y < shown_layer.height; ++y)
    for (int x = 0; x < shown_layer.width; ++x) {
      const std::size_t p = static_cast<std::size_t>(y) * static_cast<std::size_t>(shown_layer.width) + static_cast<std::size_t>(x);
      cv::Vec3b& out = full.at<cv::Vec3b>(y, x);
      for (int c = 0; c < 3; ++c) {
        double v = shown_layer.rgb[p * 3 + static_cast<std::size_t>(c)] / white;
        v = std::isfinite(v) ? std::clamp(v, 0.0, 1.0) : 0.0;
        out[2 - c] = cv::saturate_cast<std::uint8_t>(255.0 * (encode ? srgb_encode(v) : v));
      }
    }
  cv::Mat shown;
  if (d.scale < 1) cv::resize(full, shown, cv::Size(d.width, d.height), 0, 0, cv::INTER_AREA);
  else shown = full;
  return "data:image/png;base64," + base64(plot::encode_png(shown));
}

// The segmentation's label map at the page's size, each segment in a colour of its own (hues a golden angle apart,
// so that neighbouring labels differ), unassigned pixels dark grey; "" without a segmentation.
std::string segment_map_png(const ImageAnalysis& a, const Display& d) {
  if (!a.segmentation) return "";
  const Segmentation& s = *a.segmentation;
  const std::uint16_t last = s.labels.empty() ? 0 : *std::max_element(s.labels.begin(), s.labels.end());
  cv::Mat palette(1, last + 1, CV_8UC3);  // OpenCV's 8-bit HSV: hue in [0, 180)
  for (int k = 0; k <= last; ++k)
    palette.at<cv::Vec3b>(0, k) = cv::Vec3b(static_cast<std::uint8_t>(std::fmod(k * 137.50776, 360.0) / 2.0), 170, 230);
  cv::cvtColor(palette, palette, cv::COLOR_HSV2BGR);
  palette.at<cv::Vec3b>(0, 0) = cv::Vec3b(40, 40, 40);
  cv::Mat shown(d.height, d.width, CV_8UC3);
  for (int y = 0; y < d.height; ++y)
    for (int x = 0; x < d.width; ++x) {
      const int sx = std::min(s.width - 1, static_cast<int>((x + 0.5) / d.scale));
      const int sy = std::min(s.height - 1, static_cast<int>((y + 0.5) / d.scale));
      const std::uint16_t k = s.labels[static_cast<std::size_t>(sy) * static_cast<std::size_t>(s.width) + static_cast<std::size_t>(sx)];
      shown.at<cv::Vec3b>(y, x) = palette.at<cv::Vec3b>(0, k);
    }
  return "data:image/png;base64," + base64(plot::encode_png(shown));
}

// Per displayed pixel: the index of the smallest region that holds it (the whole image, 0, if none other).
std::vector<std::uint16_t> label_map(const ImageAnalysis& a, const Display& d) {
  std::vector<std::uint16_t> smallest(static_cast<std::size_t>(a.width) * static_cast<std::size_t>(a.height), 0);
  std::vector<std::size_t> order(std::min<std::size_t>(a.regions.size(), 65535));
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t i, std::size_t j) { return a.regions[i].pixels.size() > a.regions[j].pixels.size(); });
  for (const std::size_t i : order)
    for (const std::uint32_t p : a.regions[i].pixels) smallest[p] = static_cast<std::uint16_t>(i);
  std::vector<std::uint16_t> shown(static_cast<std::size_t>(d.width) * static_cast<std::size_t>(d.height));
  for (int y = 0; y < d.height; ++y)
    for (int x = 0; x < d.width; ++x) {
      const int sx = std::min(a.width - 1, static_cast<int>((x + 0.5) / d.scale));
      const int sy = std::min(a.height - 1, static_cast<int>((y + 0.5) / d.scale));
      shown[static_cast<std::size_t>(y) * static_cast<std::size_t>(d.width) + static_cast<std::size_t>(x)] =
          smallest[static_cast<std::size_t>(sy) * static_cast<std::size_t>(a.width) + static_cast<std::size_t>(sx)];
    }
  return shown;
}

json unit(const Vec3& x, const HistogramSpec& s) {
  return json::array({(x[0] - s.lo[0]) / (s.hi[0] - s.lo[0]), (x[1] - s.lo[1]) / (s.hi[1] - s.lo[1]), (x[2] - s.lo[2]) / (s.hi[2] - s.lo[2])});
}

json fits_json(const ClusterShape& s, const HistogramSpec& spec) {
  if (&off_the_faces(s) != &s) return fits_json(off_the_faces(s), spec);  // the fits of the pixels off the faces
  json lines = json::array(), curve = json::array(), plane = json::array();
  auto add = [&](const Line& l, const char* kind) { lines.push_back({{"from", unit(l.at(l.t_min), spec)}, {"to", unit(l.at(l.t_max), spec)}, {"kind", kind}}); };
  if (s.line) add(*s.line, "line");
  if (s.two_lines && (s.shape == ShapeClass::L || s.shape == ShapeClass::SkewedT)) add(s.two_lines->body, "body"), add(s.two_lines->highlight, "highlight");
  if (s.body_only && s.shape == ShapeClass::P) add(s.body_only->line, "body");
  if (s.curve && (s.shape == ShapeClass::Curved || s.shape == ShapeClass::Gamma))
    for (int k = 0; k <= 32; ++k) curve.push_back(unit(s.curve->at(s.curve->t_min + (s.curve->t_max - s.curve->t_min) * k / 32.0), spec));
  if (s.plane && s.significant_axes >= 2) {
    const Vec3 m = s.moments.mean, u = 2 * s.sigma[0] * s.moments.axes.col(0), v = 2 * s.sigma[1] * s.moments.axes.col(1);
    for (const Vec3& c : {Vec3(m - u - v), Vec3(m + u - v), Vec3(m + u + v), Vec3(m - u + v)}) plane.push_back(unit(c, spec));
  }
  return {{"lines", lines}, {"curve", curve}, {"plane", plane}};
}

std::string rgb_text(const Vec3& v) { return fmt::format("({:.4g}, {:.4g}, {:.4g})", v[0], v[1], v[2]); }
std::string percent(double v) { return fmt::format("{:.1f} %", 100 * v); }

// The numbers a person reads first; analysis.json has them all. They are of the cluster the heading names: in
// linear light when a curve encoded the file (its class leads), with the mean as stored beside it and the clipping
// measured on the stored values, where it happened.
json summary(const RegionAnalysis& r, const std::optional<Explanation>& e) {
  const ClusterShape& s = r.linear_light ? *r.linear_light : r.shape;
  const std::string light = r.linear_light ? " (linear light)" : "";
  json rows = json::array();
  auto row = [&](std::string key, std::string value) { rows.push_back({std::move(key), std::move(value)}); };
  row("pixels", fmt::format("{} ({} valid)", r.pixels, s.samples));
  if (s.samples > 0) {
    row("mean" + light, rgb_text(s.moments.mean));
    if (r.linear_light) row("mean (as stored)", rgb_text(r.shape.moments.mean));
    row("σ along axes" + light, rgb_text(s.sigma));
    // A clipped cluster's shape is measured on its samples off the faces (analysis.json: `unclipped`).
    if (s.shape != ShapeClass::Clipped) {
      row("noise σ along axes" + light, rgb_text(s.noise_sigma));
      row("linearity / planarity / scattering" + light, fmt::format("{:.3f} / {:.3f} / {:.3f}", s.linearity, s.planarity, s.scattering));
    } else if (const ClusterShape& u = off_the_faces(s); &u != &s) {
      row("off the faces", fmt::format("{} ({} samples)", class_name(u.shape), u.samples));
      row("noise σ along axes, off the faces" + light, rgb_text(u.noise_sigma));
      row("linearity / planarity / scattering, off the faces" + light, fmt::format("{:.3f} / {:.3f} / {:.3f}", u.linearity, u.planarity, u.scattering));
    }
  }
  // Directions are unit colours; a line's is a colour only inside the positive octant (its components are in
  // analysis.json either way).
  auto direction = [](const Vec3& v) { return v.minCoeff() >= 0 ? rgb_text(v) : std::string("outside the positive octant: no colour"); };
  if (s.line) row("line direction" + light, direction(s.line->direction));
  if (s.two_lines && (s.shape == ShapeClass::L || s.shape == ShapeClass::SkewedT)) {
    row("body line" + light, direction(s.two_lines->body.direction));
    row("highlight line" + light, direction(s.two_lines->highlight.direction));
    row("highlight leaves body line at", percent(s.two_lines->junction_on_body));
    row("angle between lines", fmt::format("{:.1f}°", s.two_lines->angle_deg));
  }
  if (s.plane && s.significant_axes >= 2) row("thickness off plane / noise" + light, fmt::format("{:.2f}", s.sigma[2] / std::max(1e-300, s.noise_sigma[2])));
  if (s.curve && (s.shape == ShapeClass::Curved || s.shape == ShapeClass::Gamma)) row("bend (sagitta / chord)" + light, fmt::format("{:.3f}", s.curve->bend));
  if (r.shape.gamma && r.shape.shape == ShapeClass::Gamma) {
    const GammaFit& g = *r.shape.gamma;
    row("γ (as stored)", gamma_at_bound(g.gamma)               ? fmt::format("not measured: the fit lies at the edge of the searched range ({:g} to {:g})", kGammaMin, kGammaMax)
                         : g.gamma_se ? fmt::format("{:.3f} ± {:.3f}", g.gamma, *g.gamma_se)
                                      : fmt::format("{:.3f}", g.gamma));
  }
  if (const auto& c = r.declared_gamma)
    row("γ against the declared curve", c->measured ? fmt::format("{}: fitted {:.3f}, declared {} ≈ {:.3f}, {:.1f} standard errors apart (agreement: at most {:g})",
                                                                  c->agree ? "agree" : "disagree", c->fitted, c->declared, c->declared_gamma,
                                                                  c->difference_in_se, kGammaAgreement)
                                                    : fmt::format("not measured: {} (declared {} ≈ {:.3f})", c->not_measured, c->declared, c->declared_gamma));
  if (r.bend) row("what bends it", r.bend->summary);
  if (!r.shape.clipping.faces.empty()) row("clipped (as stored)", percent(r.shape.clipping.fraction));
  if (r.linear_light) row("class of the values as stored", std::string(class_name(r.shape.shape)));
  if (e) {
    if (e->direct_share) row("direct / indirect", percent(*e->direct_share) + " / " + percent(e->indirect_share.value_or(0)));
    if (e->diffuse_share) row("diffuse / glossy", percent(*e->diffuse_share) + " / " + percent(e->glossy_share.value_or(0)));
    if (e->off_structure) row("off-" + e->off_structure->structure + " spread from indirect light", percent(e->off_structure->indirect_share));
    for (const FamilyShares& f : e->families)
      for (const ComponentShare& c : f.components) row(c.name, percent(c.energy_share));
  }
  return rows;
}

json region_json(const RgbImage& layer, const ImageAnalysis& a, std::size_t i, const Display& d, const std::vector<int>& dominant,
                 std::size_t max_points) {
  const RegionAnalysis& r = a.results[i];
  const ClusterShape& light = r.linear_light ? *r.linear_light : r.shape;  // the class in linear light leads
  const RegionSamples samples = gather_samples(layer, a.regions[i]);
  const HistogramSpec spec = display_range(a, samples);
  const std::size_t stride = std::max<std::size_t>(1, (samples.size() + max_points - 1) / std::max<std::size_t>(1, max_points));
  std::vector<std::uint16_t> rgb, pixels;
  std::vector<std::uint8_t> component;
  for (std::size_t k = 0; k < samples.size(); k += stride) {
    for (std::size_t c = 0; c < 3; ++c) {
      const double q = (samples.rgb[k * 3 + c] - spec.lo[c]) / (spec.hi[c] - spec.lo[c]);
      rgb.push_back(static_cast<std::uint16_t>(std::lround(65535 * std::clamp(q, 0.0, 1.0))));
    }
    const std::uint32_t p = samples.pixels[k];
    pixels.push_back(static_cast<std::uint16_t>(std::min<double>(d.width - 1, (p % static_cast<std::uint32_t>(a.width) + 0.5) * d.scale)));
    pixels.push_back(static_cast<std::uint16_t>(std::min<double>(d.height - 1, (p / static_cast<std::uint32_t>(a.width) + 0.5) * d.scale)));
    if (!dominant.empty()) component.push_back(static_cast<std::uint8_t>(std::clamp(dominant[p], 0, 255)));
  }
  json points = {{"rgb", base64_of(rgb)}, {"pixels", base64_of(pixels)}};
  if (!dominant.empty()) points["component"] = base64_of(component);
  const std::optional<Explanation> none;
  // Tick values along each channel's edge from black: the position in the shown cube (0 … 1) and the value.
  json ticks = json::array();
  for (int c = 0; c < 3; ++c) {
    json channel = json::array();
    const plot::Ticks t = plot::linear_ticks(spec.lo[c], spec.hi[c], 2);
    for (const double v : t.values) channel.push_back({(v - spec.lo[c]) / (spec.hi[c] - spec.lo[c]), t.label(v)});
    ticks.push_back(std::move(channel));
  }
  return {{"name", r.name},
          {"pixels", r.pixels},
          {"range", {spec.lo[0], spec.hi[0]}},
          {"ranges", {{spec.lo[0], spec.hi[0]}, {spec.lo[1], spec.hi[1]}, {spec.lo[2], spec.hi[2]}}},
          {"ticks", ticks},
          {"class", class_name(light.shape)},
          {"class_as_stored", r.linear_light ? json(class_name(r.shape.shape)) : json(nullptr)},
          {"reason", light.reason},
          {"explanation", i < a.interpretations.size() ? interpretation_text(a.interpretations[i]) : std::string()},
          {"points", points},
          {"fits", fits_json(r.shape, spec)},
          {"summary", summary(r, i < a.explanations.size() ? a.explanations[i] : none)}};
}

constexpr const char* kStyle = R"css(
body { margin: 0; font: 14px/1.4 system-ui, sans-serif; background: #111; color: #ddd; }
header { padding: 10px 16px; border-bottom: 1px solid #333; }
header h1 { font-size: 17px; margin: 0 0 4px; }
main { display: flex; gap: 16px; padding: 12px 16px; flex-wrap: wrap; }
#image-pane { flex: 1 1 420px; max-width: 640px; }
#image-wrap { position: relative; line-height: 0; }
#image, #overlay, #segments { width: 100%; image-rendering: pixelated; }
#overlay { position: absolute; left: 0; top: 0; height: 100%; cursor: crosshair; }
#histogram-pane { flex: 1 1 480px; }
#histogram { position: relative; width: 100%; height: 520px; border: 1px solid #333; }
#selection { position: absolute; display: none; border: 1px dashed #f0f; background: rgba(255,0,255,0.08); pointer-events: none; }
#region-list { display: flex; flex-wrap: wrap; gap: 4px; margin-top: 8px; }
#region-list button { background: #222; color: #ddd; border: 1px solid #444; padding: 3px 8px; cursor: pointer; }
#region-list button.current { border-color: #f0f; color: #fff; }
#details table, #illuminant table { border-collapse: collapse; }
#region-table { border-collapse: collapse; font-size: 13px; }
#region-table th, #region-table td { text-align: left; padding: 1px 10px 1px 0; font-weight: normal; }
#region-table th { color: #999; }
#details th, #details td, #illuminant th, #illuminant td { text-align: left; padding: 1px 10px 1px 0; font-weight: normal; }
#details th, #illuminant th { color: #999; }
.class { font-size: 18px; color: #fff; margin: 0; }
.explanation { max-width: 60em; }
.hint { color: #888; font-size: 12px; }
)css";

}  // namespace

std::string report_html(const AnalysisImage& input, const ImageAnalysis& a, std::size_t max_points, bool beside_files) {
  const RgbImage& layer = select_layer(input, a.layer);
  const Display d = display_size(a.width, a.height);
  const std::vector<int> dominant = input.components.empty() ? std::vector<int>{} : dominant_component_map(input);
  json regions = json::array();
  for (std::size_t i = 0; i < a.results.size(); ++i) regions.push_back(region_json(layer, a, i, d, dominant, max_points));
  json colours = json::array();
  for (std::size_t k = 0; k < input.components.size(); ++k) {
    const cv::Scalar c = component_colour(k);
    colours.push_back({c[0], c[1], c[2]});
  }
  const ValueUnit unit = value_unit(a);
  // The regions by size, with their pixel counts: readable without the viewer.
  std::string region_table = "<table id=\"region-table\"><tr><th>region</th><th>class in linear light</th><th>as stored</th>"
                             "<th>pixels</th><th>share of the image</th></tr>";
  for (const std::size_t i : regions_by_size(a.results)) {
    const RegionAnalysis& r = a.results[i];
    region_table += fmt::format("<tr data-region=\"{}\"><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>", i,
                                escape_html(r.name), class_name(r.linear_light ? r.linear_light->shape : r.shape.shape),
                                r.linear_light ? class_name(r.shape.shape) : "the same (linear values)", r.pixels,
                                percent(static_cast<double>(r.pixels) / std::max(1.0, static_cast<double>(a.width) * a.height)));
  }
  region_table += "</table>";
  const json data = {{"display", {{"width", d.width}, {"height", d.height}}},
                     {"unit", unit.axis},
                     {"encodeSrgb", !a.encoding.integer},
                     {"labels", base64_of(label_map(a, d))},
                     {"componentColours", colours},
                     {"regions", regions}};

  std::string illuminant = "<table>";
  const IlluminantAnalysis& il = a.illuminant;
  for (const IlluminantEstimate* e : il.all()) {
    std::string against;
    if (e->error_deg) against += fmt::format("{:.2f}° from the known illuminant. ", *e->error_deg);
    if (e->camera_angle_deg) against += fmt::format("{:.2f}° from the camera's white balance. ", *e->camera_angle_deg);
    if (e != &il.best()) against += fmt::format("{:.2f}° from the chosen estimate. ", angular_error_deg(e->rgb, il.best().rgb));
    illuminant += fmt::format("<tr><th>{}{}</th><td>{}</td><td>{}</td><td>{}{}</td></tr>", escape_html(e->method),
                              e == &il.best() ? " (chosen)" : "", rgb_text(e->rgb),
                              e->uncertainty_deg ? fmt::format("± {:.2f}° (standard error)", *e->uncertainty_deg) : "no uncertainty",
                              (e->reliable ? "reliable. " : "unreliable: " + escape_html(e->unreliable_reason) + ". ") +
                                  (e->systematic.empty() ? "" : "Systematic: " + escape_html(e->systematic) + ". "),
                              against);
  }
  for (std::size_t k = 0; k < std::min(il.lights.size(), kLightsNamed); ++k) {
    const LightInView& l = il.lights[k];
    // A light clipped in a channel has lost that channel's top: its colour is cut, not the light's.
    const std::string what = l.clipped ? fmt::format("clipped in {} of its pixels: its colour is cut, no reference", l.clipped)
                                       : std::string("a reference");
    illuminant += fmt::format("<tr><th>{}, seen directly or mirrored</th><td>{}</td><td>{}</td><td>a light in view or its "
                              "mirror image ({} pixels, up to {:.0f} times the image's median brightness), left out of every "
                              "estimate. {:.2f}° from the chosen estimate.</td></tr>", escape_html(l.name), rgb_text(l.rgb),
                              what, l.pixels, l.brightness, angular_error_deg(l.rgb, il.best().rgb));
  }
  if (il.lights.size() > kLightsNamed)
    illuminant += fmt::format("<tr><th>{} dimmer lights or mirror images</th><td></td><td></td><td>listed in analysis.json "
                              "(lights_in_view), left out of every estimate</td></tr>", il.lights.size() - kLightsNamed);
  if (il.camera_white)
    illuminant += fmt::format("<tr><th>camera's as-shot white balance</th><td>{}</td><td>a reference</td><td>the light the camera "
                              "assumed, not a measurement</td></tr>", rgb_text(*il.camera_white));
  illuminant += "</table>";
  if (!il.choice.empty()) illuminant += "<p>Chosen: " + escape_html(il.choice) + "</p>";
  for (const std::string& n : il.notes) illuminant += "<p class=\"hint\">" + escape_html(n) + "</p>";
  std::string notes;
  for (const std::string& n : a.notes) notes += "<p class=\"hint\">" + escape_html(n) + "</p>";
  std::string legend;
  for (std::size_t k = 0; k < input.components.size(); ++k) {
    if (std::find(dominant.begin(), dominant.end(), static_cast<int>(k)) == dominant.end()) continue;  // another family's
    const cv::Scalar c = component_colour(k);
    legend += fmt::format("<span style=\"color: rgb({},{},{})\">■</span> {} ", c[2], c[1], c[0], escape_html(input.components[k].name));
  }

  return fmt::format(
      R"html(<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<title>chromatrace analysis — {title}</title>
<style>{style}</style>
</head>
<body data-ready="0">
<header>
<h1>chromatrace analysis — {title}</h1>
<div>{width}×{height}, layer {layer}, {regions} region{plural}. {numbers}</div>
<div class="hint">Values: {unit}.</div>
{notes}
</header>
<main>
<section id="image-pane">
<div id="image-wrap" data-selected-pixels="0"><img id="image" alt="analysed image" src="{image}"><canvas id="overlay"></canvas></div>
<p class="hint">Click a region in the image, or pick one below.</p>
<div id="region-list"></div>
{segments}<h2>Regions by size</h2>
{region_table}
<h2>Illuminant</h2>
<div id="illuminant">{illuminant}</div>
</section>
<section id="histogram-pane">
<div id="histogram" data-points-drawn="0" data-region="-1"><div id="selection"></div></div>
<p class="hint">Drag to rotate, scroll to zoom; shift-drag a rectangle to highlight those points' pixels in the image.
Colour: <select id="colour-mode"><option value="own">own colour</option><option value="component">dominant component</option></select> {legend}</p>
<div id="details"></div>
</section>
</main>
<script id="analysis-data" type="application/json">{data}</script>
<script>{bundle}</script>
</body>
</html>
)html",
      fmt::arg("title", escape_html(std::filesystem::path(a.file).filename().string())), fmt::arg("style", kStyle),
      fmt::arg("width", a.width), fmt::arg("height", a.height), fmt::arg("layer", escape_html(a.layer)),
      fmt::arg("regions", a.results.size()), fmt::arg("plural", a.results.size() == 1 ? "" : "s"),
      fmt::arg("numbers", beside_files ? R"(Numbers: <a href="analysis.json">analysis.json</a>, plots in <a href="plots/">plots/</a>.)"
                                       : "Numbers: the analysis's data (analysis.json's content)."),
      fmt::arg("notes", notes),
      fmt::arg("segments", a.segmentation ? fmt::format("<h2>Segments</h2>\n<img id=\"segments\" alt=\"segment map\" src=\"{}\">\n"
                                                        "<p class=\"hint\">Segment k in a colour of its own, unassigned pixels dark grey.</p>\n",
                                                        segment_map_png(a, d))
                                          : std::string()),
      fmt::arg("image", image_png(input, layer, a, d)), fmt::arg("illuminant", illuminant), fmt::arg("legend", legend),
      fmt::arg("unit", escape_html(unit.description)), fmt::arg("region_table", region_table),
      fmt::arg("data", json_script_safe(data.dump(-1, ' ', false, kReplaceInvalidUtf8))), fmt::arg("bundle", script_safe(std::string(viewer_bundle()))));
}

}  // namespace ct::analyzer
