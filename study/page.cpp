// SPDX-License-Identifier: Apache-2.0
#include "study/page.h"

#include <fstream>
#include <sstream>
#include <string>

#include <fmt/core.h>

#include "core/file_io.h"
#include "core/html_text.h"
#include "plot/png.h"
#include "study/charts.h"

namespace ct::study {
namespace {
namespace fs = std::filesystem;

std::string optional_deg(const std::optional<double>& v) { return v ? fmt::format("{:.2f}°", *v) : "–"; }

std::string image_tag(const StudyResult& result, ChartValue value, const char* alt) {
  return fmt::format("<img alt=\"{}\" src=\"data:image/png;base64,{}\">", alt,
                     base64(plot::encode_png(chart(result, value))));
}

}  // namespace

void write_page(const fs::path& file, const StudyResult& result) {
  std::ostringstream h;
  const std::string scene = escape_html(fs::path(result.scene).filename().string());
  h << "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>chromatrace study: " << scene
    << "</title>\n<style>body{font:14px/1.45 system-ui,sans-serif;margin:24px;color:#222;max-width:1200px}"
       "table{border-collapse:collapse;margin:12px 0}td,th{border-bottom:1px solid #ddd;padding:4px 8px;text-align:right}"
       "th{background:#f4f4f4}td.l,th.l{text-align:left}tr.pareto td{background:#f3f8ee}.bad{color:#b00}.ok{color:#070}"
       "img{max-width:100%;border:1px solid #eee;margin:6px 0}.note{color:#555}</style></head><body>\n";
  h << "<h1>Speed against accuracy: " << scene << "</h1>\n";
  h << "<p>Each setting is the scene's own render settings with one knob changed (<em>planned</em>: every knob as "
       "<code>chromatrace plan</code> chose it for a mean ΔE00 of 1; <em>guided</em>, with <code>--guided</code>: the "
       "planned Cycles setting with its band group of most samples guiding the others, rendered with fewer), rendered twice with two seeds, seen by an ideal "
       "noise-free camera and analysed. It is compared with the <strong>reference</strong>: "
    << escape_html(result.reference.value) << " (" << fmt::format("{:.1f}", result.reference_cpu_s)
    << " CPU seconds). ΔE00 is over every pixel of the image, through the observer, in CIELAB under the light's "
       "white. The <em>noise</em> is the two seeds' rms ΔE00 over √2; the <em>systematic</em> part (bands, bounces, "
       "mode, renderer) is what is left of the rms once the noise of the setting and of the reference are taken out "
       "(independent errors add as squares), with the range of ±2 standard errors in brackets: a systematic error "
       "smaller than its range is hidden by the noise at this size and these samples. Rows shaded green are on the Pareto front: no other setting is both "
       "cheaper and more accurate.</p>\n";
  h << image_tag(result, ChartValue::MeanDe00, "mean ΔE00 against CPU seconds") << "\n";
  h << image_tag(result, ChartValue::P95De00, "95th-percentile ΔE00 against CPU seconds") << "\n";
  h << image_tag(result, ChartValue::SystematicRms, "systematic rms ΔE00 against CPU seconds") << "\n";
  h << image_tag(result, ChartValue::DirectionDeg, "largest direction change against CPU seconds") << "\n";
  h << "<table><tr><th class=l>setting</th><th class=l>knob</th><th class=l>value</th><th>bands</th><th>samples</th>"
       "<th>bounces</th><th>CPU s</th><th>wall s</th><th>renders</th><th>mean ΔE00</th><th>p95 ΔE00</th>"
       "<th>noise rms</th><th>systematic rms</th><th>classes kept</th><th>largest turn</th><th>illuminant turn</th>"
       "<th class=l>analysis</th></tr>\n";
  for (const SettingResult& r : result.settings) {
    const Setting& s = r.setting;
    h << "<tr" << (r.pareto ? " class=pareto" : "") << "><td class=l>" << escape_html(s.name) << "</td><td class=l>"
      << escape_html(s.knob) << "</td><td class=l>" << escape_html(s.value) << "</td>";
    if (!r.ok) {
      h << "<td class='l bad' colspan=14>failed: " << escape_html(r.error) << "</td></tr>\n";
      continue;
    }
    const bool all_kept = r.classes_kept == static_cast<int>(r.objects.size());
    std::string changed;
    for (const ObjectFinding& f : r.objects)
      if (!f.same) changed += fmt::format("{}{}: {} (reference {})", changed.empty() ? "" : "; ", f.object, f.cls, f.reference_cls);
    h << fmt::format("<td>{}</td><td>{}</td><td>{}</td><td>{:.2f}</td><td>{:.2f}</td><td>{}</td><td>{:.2f}</td>"
                     "<td>{:.2f}</td><td>{:.2f}</td>{}",
                     s.bands.size(), s.samples, s.max_bounces, r.cpu_s, r.wall_s, r.renders, r.mean, r.p95,
                     r.noise_rms,
                     r.systematic_measurable
                         ? fmt::format("<td>{:.2f} <small>({:.2f}–{:.2f})</small></td>", r.systematic_rms,
                                       r.systematic_rms_lo, r.systematic_rms_hi)
                         : std::string("<td title=\"the noise is too large to split the error\">–</td>"));
    h << "<td class=" << (all_kept ? "ok" : "bad") << " title=\"" << escape_html(changed) << "\">" << r.classes_kept
      << " of " << r.objects.size() << "</td><td>" << optional_deg(r.max_direction_deg) << "</td><td>"
      << optional_deg(r.illuminant_deg)
      << (r.illuminant_method != r.reference_illuminant_method ? " <span class=bad>(" + escape_html(r.illuminant_method) + ")</span>" : "")
      << "</td><td class=l><a href=\"runs/" << escape_html(s.name) << "/analysis/report.html\">report</a></td></tr>\n";
  }
  h << "</table>\n<p class=note>Every number is in <a href=\"study.json\">study.json</a>; each setting's renders, "
       "camera images and analyses are under <code>runs/</code>, its band plan under <code>plans/</code>.</p>\n";
  for (const std::string& note : result.notes) h << "<p class=note>" << escape_html(note) << "</p>\n";
  h << "</body></html>\n";
  write_file_atomically(file, h.str());
}

}  // namespace ct::study
