// SPDX-License-Identifier: Apache-2.0
#include "series/figure.h"

#include <array>
#include <cctype>
#include <map>
#include <string>
#include <vector>

#include <fmt/core.h>
#include <fmt/format.h>

#include "core/file_io.h"
#include "core/html_text.h"
#include "core/json_input.h"
#include "plot/png.h"
#include "plot/ticks.h"
#include "series/figure_data.h"
#include "series/figure_raster.h"

namespace ct::series {
namespace fs = std::filesystem;
namespace {

// Points per histogram plot at most (a deterministic subsample beyond).
constexpr std::size_t kMaxPoints = 40000;

// A relative link: each path segment percent-encoded where it must be.
std::string href(std::string_view path) {
  std::string out;
  for (const unsigned char c : path) {
    if (std::isalnum(c) || c == '/' || c == '-' || c == '_' || c == '.' || c == '~') out += static_cast<char>(c);
    else out += fmt::format("%{:02X}", c);
  }
  return out;
}

std::string data_uri(std::string_view png) { return "data:image/png;base64," + base64(png); }

std::string mark(bool ok) {
  return ok ? R"(<span class="mark ok" title="as expected">✔</span>)" : R"(<span class="mark bad" title="not as expected">✗</span>)";
}

std::string options_text(const Json& result, bool for_raster) {
  std::vector<std::string> parts;
  if (!result.is_object() || !result.contains("options") || !result["options"].is_object()) return "";
  const Json& o = result["options"];
  if (o.contains("renderer") && o["renderer"].is_string()) parts.push_back("renderer " + o["renderer"].get<std::string>());
  if (o.contains("resolution") && o["resolution"].is_array() && o["resolution"].size() == 2)
    parts.push_back(fmt::format("{} {} {} px", o["resolution"][0].dump(-1, ' ', false, kReplaceInvalidUtf8), for_raster ? "x" : "×", o["resolution"][1].dump(-1, ' ', false, kReplaceInvalidUtf8)));
  if (o.contains("spp") && o["spp"].is_number()) parts.push_back(fmt::format("{} paths per pixel", o["spp"].dump(-1, ' ', false, kReplaceInvalidUtf8)));
  if (o.contains("seed") && o["seed"].is_number()) parts.push_back(fmt::format("seed {}", o["seed"].dump(-1, ' ', false, kReplaceInvalidUtf8)));
  if (o.contains("components") && o["components"].is_string()) parts.push_back("components " + o["components"].get<std::string>());
  return fmt::format("{}", fmt::join(parts, for_raster ? ", " : " · "));
}

std::string string_of(const Json& result, const char* key) {
  return result.is_object() && result.contains(key) && result[key].is_string() ? result[key].get<std::string>() : "";
}

const char* kStyle = R"(
:root { color-scheme: light; }
* { box-sizing: border-box; }
body { margin: 0; padding: 18px 16px 40px; font: 14px/1.45 "DejaVu Sans", "Helvetica Neue", Arial, sans-serif; color: #1e1e1e; background: #f4f4f2; }
h1 { font-size: 22px; margin: 0 0 6px; }
h2 { font-size: 19px; margin: 28px 0 4px; }
h3.caption { font-size: 15px; margin: 0 0 6px; line-height: 1.3; }
p { margin: 4px 0; max-width: 1400px; }
.run { color: #444; }
.about { color: #555; font-size: 13px; }
.figure-note { color: #555; font-size: 13px; margin-bottom: 10px; }
.panels { display: grid; grid-template-columns: repeat(auto-fill, 452px); gap: 12px; align-items: start; }
.panel { background: #fff; border: 1px solid #d6d6d2; border-radius: 4px; padding: 10px; width: 452px; }
.panel-head { min-height: 9.8em; }
.panel.missing { color: #777; }
.variant-name { font-family: "DejaVu Sans Mono", monospace; font-size: 13px; font-weight: bold; }
.description { color: #444; font-size: 13px; margin: 2px 0 8px; }
figure { margin: 0; text-align: center; }
figure img.camera { image-rendering: pixelated; border: 1px solid #ccc; max-width: 100%; height: auto; }
figcaption { color: #666; font-size: 12px; }
img.plot { display: block; margin: 8px auto 0; border: 1px solid #e2e2e0; max-width: 100%; height: auto; }
.plot-note { color: #666; font-size: 12px; margin: 2px 0 0; }
table { border-collapse: collapse; }
table.findings { width: 100%; margin-top: 10px; font-size: 13px; }
table.findings th, table.findings td { text-align: left; padding: 2px 4px; border-bottom: 1px solid #eee; vertical-align: top; }
table.findings td.paths { color: #555; font-size: 12px; border-bottom: 1px solid #ddd; padding-left: 14px; }
.mark { font-weight: bold; }
.mark.ok { color: #1d7a1d; }
.mark.bad { color: #b3261e; }
.error { color: #b3261e; white-space: pre-wrap; }
.links { margin-top: 8px; font-size: 13px; }
a { color: #1a55a8; }
table.variants { background: #fff; border: 1px solid #d6d6d2; font-size: 13px; margin-top: 8px; }
table.variants th, table.variants td { padding: 4px 8px; border-bottom: 1px solid #e6e6e3; text-align: left; vertical-align: top; }
table.variants th { background: #ecece8; }
table.variants tr.first td { border-top: 2px solid #d0d0cc; }
table.variants img { image-rendering: pixelated; border: 1px solid #ccc; }
code { font-family: "DejaVu Sans Mono", monospace; font-size: 12.5px; }
)";

// One object's rows in a panel: expected, found and mark; the light paths below.
std::string findings_table(const VariantView& v) {
  if (v.findings.empty()) return R"(<p class="description">No expectations for this variant.</p>)";
  std::string html = R"(<table class="findings"><tr><th>object</th><th>expected</th><th>found</th><th></th></tr>)";
  for (const FindingView& f : v.findings) {
    const std::string object = f.target != f.object && f.target != "image" && !f.target.empty()
                                   ? fmt::format("{} <span class=\"description\">({})</span>", escape_html(f.object), escape_html(f.target))
                                   : escape_html(f.object);
    html += fmt::format("<tr class=\"finding\" data-ok=\"{}\"><td>{}</td><td>{}</td><td><b>{}</b></td><td>{}</td></tr>", f.ok ? 1 : 0,
                        object, escape_html(expected_text(f)), escape_html(f.found), mark(f.ok));
    if (!f.explanation.empty())
      html += fmt::format("<tr><td class=\"paths\" colspan=\"4\">light paths: {}</td></tr>", escape_html(f.explanation));
  }
  return html + "</table>";
}

std::string plot_note(const VariantView& v) {
  const HistogramPoints& p = v.points;
  std::string note = fmt::format("Cube shown: 0 to {} in each channel [{}]. ", plot::tick_label(p.hi, p.step), escape_html(p.units));
  if (p.lo != 0)
    note = fmt::format("Cube shown: {} to {} in each channel [{}]. ", plot::tick_label(p.lo, p.step), plot::tick_label(p.hi, p.step),
                       escape_html(p.units));
  if (p.beyond > 0)
    note += p.lamps_beyond == p.beyond ? fmt::format("{} px of lamps seen directly lie beyond it and are not drawn. ", p.beyond)
                                       : fmt::format("{} px lie beyond it and are not drawn ({} of them lamps seen directly). ", p.beyond,
                                                     p.lamps_beyond);
  if (p.non_finite > 0) note += fmt::format("{} NaN/infinite px left out. ", p.non_finite);
  note += fmt::format("Principal axes 1 and 2 hold {:.1f} % and {:.1f} % of the variance.", 100 * v.plane.share[0], 100 * v.plane.share[1]);
  return note;
}

// A panel: the paper's caption (or the variant's name), the variant, its image, plots and findings.
std::string panel_html(const std::string& panel, const VariantView* v) {
  const std::string caption = panel.empty() ? "" : panel_caption(panel);
  if (!v)
    return fmt::format(R"(<section class="panel missing" data-missing="{}"><h3 class="caption">{}</h3><p>No variant of this run reproduces this panel.</p></section>)",
                       escape_html(panel), escape_html(caption));
  std::string html = panel.empty()
                         ? fmt::format(R"(<section class="panel" data-variant="{}">)", escape_html(v->name))
                         : fmt::format(R"(<section class="panel" data-panel="{}" data-variant="{}">)", escape_html(panel), escape_html(v->name));
  html += R"(<div class="panel-head">)";
  if (!caption.empty()) html += fmt::format(R"(<h3 class="caption">{}</h3>)", escape_html(caption));
  html += fmt::format(R"(<div class="variant-name">{}</div><p class="description">{}</p></div>)", escape_html(v->name), escape_html(v->description));
  if (!v->ok) return html + fmt::format(R"(<p class="error">This variant failed: {}</p></section>)", escape_html(v->error));
  if (!v->image_error.empty()) {
    html += fmt::format(R"(<p class="error">Its images cannot be shown: {}</p>)", escape_html(v->image_error));
  } else {
    const cv::Size shown = display_size(v->camera, 288);
    html += fmt::format(R"(<figure><img class="camera" src="{}" width="{}" height="{}" alt="camera image of {}"><figcaption>camera image as a person sees it (camera.png), {} × {} px</figcaption></figure>)",
                        data_uri(v->camera_png), shown.width, shown.height, escape_html(v->name), v->camera.cols, v->camera.rows);
    html += fmt::format(R"(<img class="plot oblique" src="{}" width="{}" height="{}" alt="3D colour histogram of {}, oblique view">)",
                        data_uri(v->oblique_png), v->oblique.cols, v->oblique.rows, escape_html(v->name));
    html += fmt::format(R"(<img class="plot projection" src="{}" width="{}" height="{}" alt="colour histogram of {} projected on its principal plane">)",
                        data_uri(v->projection_png), v->projection.cols, v->projection.rows, escape_html(v->name));
    html += fmt::format(R"(<p class="plot-note">{}</p>)", plot_note(*v));
  }
  html += findings_table(*v);
  html += R"(<p class="links">)";
  if (!v->report.empty())
    html += fmt::format(R"(<a class="report" href="{}">analysis report</a> (every region, rotatable 3D histogram))", href(v->report));
  if (!v->preview.empty()) html += fmt::format(R"( · <a href="{}">camera.png</a>)", href(v->preview));
  if (!v->analysis.empty()) html += fmt::format(R"( · <a href="{}">analysis.json</a>)", href(v->analysis));
  return html + "</p></section>";
}

// The table of every variant: per expectation, expected and found.
std::string variants_table(const fs::path& dir, const std::vector<VariantView>& variants) {
  std::string html = R"(<table class="variants"><tr><th>variant</th><th>figure</th><th>image</th><th>target</th><th>expected</th><th>found</th><th></th><th>files</th></tr>)";
  for (const VariantView& v : variants) {
    const std::string thumb = [&] {
      const std::string png = thumbnail_png(dir, v, 64);
      return png.empty() ? std::string() : fmt::format(R"(<img src="{}" alt="{}">)", data_uri(png), escape_html(v.name));
    }();
    const std::string figure = escape_html(fmt::format("{}", fmt::join(v.figure, ", ")));
    const std::string name = fmt::format(R"(<span class="variant-name">{}</span><br><span class="description">{}</span>)", escape_html(v.name),
                                         escape_html(v.description));
    if (!v.ok) {
      html += fmt::format(R"(<tr class="first" data-variant="{}"><td>{}</td><td>{}</td><td>{}</td><td colspan="5" class="error">failed: {}</td></tr>)",
                          escape_html(v.name), name, figure, thumb, escape_html(v.error));
      continue;
    }
    // Group the findings by expectation (target), in order.
    std::vector<std::vector<const FindingView*>> groups;
    for (const FindingView& f : v.findings) {
      if (groups.empty() || groups.back().front()->target != f.target || groups.back().front()->any_of != f.any_of) groups.emplace_back();
      groups.back().push_back(&f);
    }
    const std::size_t rows = std::max<std::size_t>(1, groups.size());
    std::string files;
    if (!v.report.empty()) files += fmt::format(R"(<a class="report" href="{}">report</a>)", href(v.report));
    if (!v.preview.empty()) files += fmt::format(R"(<br><a href="{}">camera.png</a>)", href(v.preview));
    if (!v.camera_exr.empty()) files += fmt::format(R"(<br><a href="{}">camera.exr</a>)", href(v.camera_exr));
    const std::string head = fmt::format(R"(<td rowspan="{0}">{1}<br><span class="description">{2} of {3} expectations met</span></td><td rowspan="{0}">{4}</td><td rowspan="{0}">{5}</td>)",
                                         rows, name, v.met, v.expectations, figure, thumb);
    if (groups.empty()) {
      html += fmt::format(R"(<tr class="first" data-variant="{}">{}<td colspan="4">no expectations</td><td>{}</td></tr>)", escape_html(v.name), head, files);
      continue;
    }
    for (std::size_t g = 0; g < groups.size(); ++g) {
      const auto& group = groups[g];
      bool ok = true;
      std::vector<std::string> found;
      for (const FindingView* f : group) {
        ok = ok && f->ok;
        if (group.size() > 1)
          found.push_back(fmt::format("{} <b>{}</b>&nbsp;{}", escape_html(f->object), escape_html(f->found), mark(f->ok)));
        else if (f->object == f->target)
          found.push_back(fmt::format("<b>{}</b>", escape_html(f->found)));
        else
          found.push_back(fmt::format("{} <b>{}</b>", escape_html(f->object), escape_html(f->found)));
      }
      html += fmt::format(R"(<tr{} data-variant="{}">{}<td>{}</td><td>{}</td><td>{}</td><td>{}</td>{}</tr>)", g == 0 ? R"( class="first")" : "",
                          escape_html(v.name), g == 0 ? head : "", escape_html(group.front()->target),
                          escape_html(expected_text(*group.front())), fmt::join(found, ", "), mark(ok),
                          g == 0 ? fmt::format(R"(<td rowspan="{}">{}</td>)", rows, files) : "");
    }
  }
  return html + "</table>";
}

void write_png(const fs::path& file, const cv::Mat& image) { write_file_atomically(file, plot::encode_png(image)); }

}  // namespace

void write_figure_page(const std::filesystem::path& dir, const Json& result) {
  std::vector<VariantView> variants = read_variants(result);

  // The paper's panels: the first variant that names a panel shows it.
  std::map<std::string, std::size_t> panel_of;
  for (std::size_t i = 0; i < variants.size(); ++i)
    for (const std::string& p : variants[i].figure)
      if (!panel_caption(p).empty() && !panel_of.count(p)) panel_of[p] = i;
  const bool figures = !panel_of.empty();
  std::vector<bool> shown(variants.size(), !figures);
  for (const auto& [panel, i] : panel_of) shown[i] = true;
  for (std::size_t i = 0; i < variants.size(); ++i)
    if (shown[i]) load_images(variants[i], dir, kMaxPoints);

  const std::string series = string_of(result, "series");
  const std::string options = options_text(result, false);
  int met = 0, total = 0, failed = 0;
  for (const VariantView& v : variants) met += v.met, total += v.expectations, failed += v.ok ? 0 : 1;

  std::string html = "<!doctype html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
                     "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">";
  html += fmt::format("<title>chromatrace series {}: figures</title><style>{}</style></head><body>", escape_html(series), kStyle);
  html += fmt::format(R"(<header><h1>Series “{}”</h1><p>{}</p>)", escape_html(series), escape_html(string_of(result, "description")));
  html += fmt::format(R"(<p class="run">{}{}{} variants · {} of {} expectations met{} · <a href="series.json">series.json</a></p>)",
                      escape_html(options), options.empty() ? "" : " · ", variants.size(), met, total,
                      failed > 0 ? fmt::format(" · <span class=\"error\">{} failed</span>", failed) : "");
  html += R"(<p class="about">The figures follow Peng, Lafortune, Greenberg and Sobel, <i>Use of Computer Graphic Simulation to Explain Color Histogram Structure</i>: )"
          R"(each panel is one variant of the series, its camera image and the colour histogram of the <b>whole image</b>. )"
          R"(Points are the image's pixels in their display colour (the pixel's colour in camera.png), up to 40 000 of them (an even, deterministic subsample beyond). )"
          R"(The cube spans one range for R, G and B, set by the surfaces (lamps seen directly, whose light is mostly the emission component, do not set it). )"
          R"(The oblique view shows the RGB cube with black at the bottom and the achromatic axis R = G = B (dashed) upright. )"
          R"(The projection is onto the plane of the two largest principal axes of the plotted points (the plane that shows the most of their spread), )"
          R"(with equal scales on both axes; its inset shows the R, G and B directions as they project. )"
          R"(Below, each object's class as the analyzer found it, against the classes the series expects, and the light paths that carry its light.</p></header>)";

  std::array<std::string, 2> raster_files = {"figure3.png", "figure4.png"};
  const std::string subtitle = fmt::format("Reproduced with chromatrace, series {}{}{}. Histograms: every pixel of the image, in its display colour; "
                                           "the projection is onto the image's two largest principal axes.",
                                           series, options.empty() ? "" : ": ", options_text(result, true));
  for (const int figure : {3, 4}) {
    // The paper's four panels, then those beyond the paper that a variant reproduces.
    std::vector<std::pair<std::string, const VariantView*>> panels;
    bool any = false;
    for (const std::string& name : figure_panels(figure)) {
      const auto it = panel_of.find(name);
      panels.emplace_back(name, it == panel_of.end() ? nullptr : &variants[it->second]);
      any = any || it != panel_of.end();
    }
    for (const std::string& name : extra_panels(figure))
      if (const auto it = panel_of.find(name); it != panel_of.end()) panels.emplace_back(name, &variants[it->second]);
    const fs::path raster = dir / raster_files[figure - 3];
    if (!any) {
      std::error_code ignored;
      fs::remove(raster, ignored);  // a figure of an earlier run in this directory would no longer match
      continue;
    }
    write_png(raster, figure_raster(figure, panels, subtitle));
    html += fmt::format(R"(<section class="figure" id="figure-{0}"><h2>{1}.</h2><p class="figure-note">From left to right, as in the paper; also as one image: <a href="{2}">{2}</a>.</p><div class="panels">)",
                        figure, escape_html(figure_title(figure)), raster_files[figure - 3]);
    for (const auto& [name, variant] : panels) html += panel_html(name, variant);
    html += "</div></section>";
  }
  if (!figures) {
    html += R"(<section class="figure" id="variants-panels"><h2>Variants</h2><div class="panels">)";
    for (const VariantView& v : variants) html += panel_html("", &v);
    html += "</div></section>";
  }
  html += fmt::format(R"(<section id="variants"><h2>Every variant of the series</h2>{}</section>)", variants_table(dir, variants));
  html += "</body></html>\n";
  write_file_atomically(dir / "index.html", html);
}

}  // namespace ct::series
