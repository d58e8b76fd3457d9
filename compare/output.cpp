// SPDX-License-Identifier: Apache-2.0
// compare.json, compare.png, compare.html and the verdict (compare.h, docs/compare.md).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <stdexcept>

#include <fmt/core.h>
#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "compare/compare.h"
#include "core/colour.h"
#include "core/error.h"
#include "core/file_io.h"
#include "core/html_text.h"
#include "core/json_input.h"
#include "plot/png.h"

namespace ct::cmp {
namespace {

using nlohmann::json;

json number(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

json side_json(const SideSummary& s) {
  return {{"files", s.files}, {"renderer", s.renderer}, {"samples", s.samples}, {"seeds", s.seeds}};
}

std::string band_label(const Cell& cell) { return fmt::format("{:g}-{:g} nm", cell.lo_nm, cell.hi_nm); }

// Failing cells first, then by |z|.
std::vector<const Cell*> worst_cells(const Comparison& c) {
  std::vector<const Cell*> cells;
  for (const Cell& cell : c.cells) cells.push_back(&cell);
  std::stable_sort(cells.begin(), cells.end(), [](const Cell* x, const Cell* y) {
    if (x->pass != y->pass) return !x->pass;
    const double zx = std::isfinite(x->z) ? std::abs(x->z) : 1e300, zy = std::isfinite(y->z) ? std::abs(y->z) : 1e300;
    return zx > zy;
  });
  return cells;
}

std::string ratio_text(const Cell& cell) {
  if (!cell.ratio) return fmt::format("A {:.4g} vs B 0", cell.mean_a);
  return fmt::format("{:.4f} ± {:.4f}", *cell.ratio, cell.se_ratio.value_or(0));
}

std::string z_text(double z) { return std::isfinite(z) ? fmt::format("{:+.1f}", z) : std::string(z > 0 ? "+inf" : "-inf"); }

json to_json(const Comparison& c) {
  json cells = json::array();
  for (const Cell& cell : c.cells)
    cells.push_back({{"object_id", cell.object_id},
                     {"object", cell.object},
                     {"brdf", cell.brdf},
                     {"component", cell.component},
                     {"band", cell.band},
                     {"band_nm", {cell.lo_nm, cell.hi_nm}},
                     {"pixels", cell.pixels},
                     {"mean_a", cell.mean_a},
                     {"mean_b", cell.mean_b},
                     {"se_a", cell.se_a},
                     {"se_b", cell.se_b},
                     {"se", cell.se},
                     {"ratio", cell.ratio ? number(*cell.ratio) : json(nullptr)},
                     {"se_ratio", cell.se_ratio ? number(*cell.se_ratio) : json(nullptr)},
                     {"z", number(cell.z)},
                     {"tolerance", cell.tolerance},
                     {"pass", cell.pass}});
  // Per object: cells, failures and the worst |z|.
  json objects = json::array();
  std::map<std::int32_t, json> by_id;
  std::vector<std::int32_t> order;
  for (const Cell& cell : c.cells) {
    auto [it, fresh] = by_id.try_emplace(cell.object_id, json{{"object_id", cell.object_id},
                                                              {"object", cell.object},
                                                              {"brdf", cell.brdf},
                                                              {"pixels", cell.pixels},
                                                              {"tolerance", cell.tolerance},
                                                              {"cells", 0},
                                                              {"failed", 0},
                                                              {"max_abs_z", 0.0}});
    if (fresh) order.push_back(cell.object_id);
    json& o = it->second;
    o["cells"] = o["cells"].get<int>() + 1;
    if (!cell.pass) o["failed"] = o["failed"].get<int>() + 1;
    const double az = std::abs(cell.z);
    if (!std::isfinite(az)) o["max_abs_z"] = nullptr;
    else if (!o["max_abs_z"].is_null() && az > o["max_abs_z"].get<double>()) o["max_abs_z"] = az;
  }
  for (std::int32_t id : order) {
    json& o = by_id[id];
    if (id < 0) o["delta_e00_mean"] = c.delta_e_mean;
    else if (const auto found = c.delta_e_by_object.find(id); found != c.delta_e_by_object.end())
      o["delta_e00_mean"] = found->second;
    objects.push_back(o);
  }
  return {{"format", "chromatrace-compare/1"},
          {"a", side_json(c.a)},
          {"b", side_json(c.b)},
          {"scene", c.scene_name},
          {"width", c.width},
          {"height", c.height},
          {"bands", {{"edges_nm", c.bands.edges()}}},
          {"components", c.components},
          {"components_only_in_a", c.only_a},
          {"components_only_in_b", c.only_b},
          {"pixels", c.pixels_mode},
          {"object_id_mismatch_pixels", c.id_mismatch_pixels},
          {"tolerance", c.tolerance_mode},
          {"sigmas", c.sigmas},
          {"standard_error", c.se_method},
          {"image", {{"camera", c.camera},
                     {"colour", c.colour},
                     {"white", c.white},
                     {"delta_e00", {{"mean", c.delta_e_mean}, {"p95", c.delta_e_p95}, {"max", c.delta_e_max}}}}},
          {"verdict", {{"cells", c.cells.size()}, {"failed", c.failed}, {"agree", c.failed == 0}}},
          {"objects", objects},
          {"cells", cells}};
}

cv::Vec3b to_bgr8(double r, double g, double b) {
  auto enc = [](double v) { return cv::saturate_cast<uchar>(255.0 * srgb_encode(std::clamp(v, 0.0, 1.0)) + 0.5); };
  return {enc(b), enc(g), enc(r)};
}

// A | B | difference | ΔE00, each panel scaled up by whole pixels, with labels.
std::string png(const Comparison& c) {
  const int W = c.width, H = c.height;
  const int s = std::max(1, (256 + std::max(W, H) - 1) / std::max(W, H));
  const int pw = W * s, ph = H * s, gap = 6, top = 22;
  cv::Mat img(ph + top, 4 * pw + 3 * gap, CV_8UC3, cv::Scalar(40, 40, 40));
  std::vector<double> diffs;
  for (std::size_t i = 0; i < c.rgb_a.size(); ++i) diffs.push_back(std::abs(double(c.rgb_a[i]) - c.rgb_b[i]));
  std::vector<double> sorted = diffs;
  std::sort(sorted.begin(), sorted.end());
  const double dmax = std::max(sorted.empty() ? 0.0 : sorted[std::size_t(0.99 * double(sorted.size() - 1))], 1e-12);
  std::vector<double> de = c.delta_e;
  std::sort(de.begin(), de.end());
  const double emax = std::max(2.0, de.empty() ? 0.0 : de[std::size_t(0.99 * double(de.size() - 1))]);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const std::size_t p = std::size_t(y) * W + x;
      const float* a = &c.rgb_a[p * 3];
      const float* b = &c.rgb_b[p * 3];
      cv::Vec3b px[4];
      px[0] = to_bgr8(a[0], a[1], a[2]);
      px[1] = to_bgr8(b[0], b[1], b[2]);
      auto signed_level = [&](int k) {
        return cv::saturate_cast<uchar>(127.5 + 127.5 * std::clamp((double(a[k]) - b[k]) / dmax, -1.0, 1.0));
      };
      px[2] = cv::Vec3b(signed_level(2), signed_level(1), signed_level(0));
      const double t = std::clamp(c.delta_e[p] / emax, 0.0, 1.0);  // black → red → yellow → white
      px[3] = cv::Vec3b(cv::saturate_cast<uchar>(255 * std::clamp(3 * t - 2, 0.0, 1.0)),
                        cv::saturate_cast<uchar>(255 * std::clamp(3 * t - 1, 0.0, 1.0)),
                        cv::saturate_cast<uchar>(255 * std::clamp(3 * t, 0.0, 1.0)));
      for (int panel = 0; panel < 4; ++panel)
        img(cv::Rect(panel * (pw + gap) + x * s, top + y * s, s, s)).setTo(cv::Scalar(px[panel][0], px[panel][1], px[panel][2]));
    }
  const std::string labels[4] = {"A", "B", fmt::format("A-B (+-{:.2g})", dmax), fmt::format("dE00 (0-{:.2g})", emax)};
  for (int panel = 0; panel < 4; ++panel)
    cv::putText(img, labels[panel], cv::Point(panel * (pw + gap) + 2, 16), cv::FONT_HERSHEY_SIMPLEX, 0.45,
                cv::Scalar(230, 230, 230), 1, cv::LINE_AA);
  return plot::encode_png(img);
}

std::string html(const Comparison& c, const std::string& png_bytes) {
  std::string rows;
  for (const Cell* cell : worst_cells(c))
    rows += fmt::format(
        "<tr class=\"{}\"><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{:.6g} ± {:.2g}</td>"
        "<td>{:.6g} ± {:.2g}</td><td>{}</td><td>{}</td><td>{:g} %</td><td>{}</td></tr>\n",
        cell->pass ? "pass" : "fail", escape_html(cell->object), escape_html(cell->brdf), escape_html(cell->component),
        band_label(*cell), cell->pixels, cell->mean_a, cell->se_a, cell->mean_b, cell->se_b, escape_html(ratio_text(*cell)),
        z_text(cell->z), cell->tolerance * 100, cell->pass ? "pass" : "FAIL");
  return fmt::format(
      R"(<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>chromatrace compare: {scene}</title>
<style>body{{font-family:sans-serif;margin:1.5em}} table{{border-collapse:collapse;font-size:13px}}
td,th{{border:1px solid #ccc;padding:2px 6px;text-align:right}} td:nth-child(-n+4){{text-align:left}}
tr.fail{{background:#fdd}} .verdict{{font-size:1.2em;font-weight:bold}} img{{image-rendering:pixelated;max-width:100%}}</style>
</head><body>
<h1>chromatrace compare: {scene}</h1>
<p class="verdict" id="verdict">{verdict}</p>
<p><b>A</b>: {a_files} — {a_renderer}, {a_samples} samples, seeds {a_seeds}<br>
<b>B</b>: {b_files} — {b_renderer}, {b_samples} samples, seeds {b_seeds}<br>
{w}×{h} pixels, {bands} bands {lo:g}–{hi:g} nm; components {components}; pixels: {pixels} ({mismatch} pixels with different
object ids left out); tolerance {tolerance}, plus {sigmas:g} standard errors.</p>
<p>ΔE00 through {camera}, white: {white}: mean {de_mean:.3f}, 95th percentile {de_p95:.3f}, max {de_max:.3f}.</p>
<img alt="A | B | A-B | ΔE00" src="data:image/png;base64,{png}">
<h2>Cells (object × component × band), failures and largest |z| first</h2>
<table id="cells"><tr><th>object</th><th>BRDF</th><th>component</th><th>band</th><th>pixels</th><th>mean A ± se</th>
<th>mean B ± se</th><th>A/B ± se</th><th>z</th><th>tolerance</th><th></th></tr>
{rows}</table>
</body></html>
)",
      fmt::arg("scene", escape_html(c.scene_name)), fmt::arg("verdict", escape_html(c.failed == 0 ? fmt::format("agree: all {} cells within tolerance", c.cells.size()) : fmt::format("disagree: {} of {} cells beyond tolerance", c.failed, c.cells.size()))),
      fmt::arg("a_files", escape_html(fmt::format("{}", fmt::join(c.a.files, ", ")))),
      fmt::arg("a_renderer", escape_html(c.a.renderer)), fmt::arg("a_samples", escape_html(c.a.samples)),
      fmt::arg("a_seeds", escape_html(c.a.seeds)),
      fmt::arg("b_files", escape_html(fmt::format("{}", fmt::join(c.b.files, ", ")))),
      fmt::arg("b_renderer", escape_html(c.b.renderer)), fmt::arg("b_samples", escape_html(c.b.samples)),
      fmt::arg("b_seeds", escape_html(c.b.seeds)), fmt::arg("w", c.width), fmt::arg("h", c.height),
      fmt::arg("bands", c.bands.size()), fmt::arg("lo", c.bands.min_wavelength()), fmt::arg("hi", c.bands.max_wavelength()),
      fmt::arg("components", escape_html(fmt::format("{}", fmt::join(c.components, ", ")))),
      fmt::arg("pixels", c.pixels_mode), fmt::arg("mismatch", c.id_mismatch_pixels),
      fmt::arg("tolerance", escape_html(c.tolerance_mode)), fmt::arg("sigmas", c.sigmas), fmt::arg("camera", escape_html(c.camera)),
      fmt::arg("white", escape_html(c.white)), fmt::arg("de_mean", c.delta_e_mean), fmt::arg("de_p95", c.delta_e_p95), fmt::arg("de_max", c.delta_e_max),
      fmt::arg("png", base64(png_bytes)), fmt::arg("rows", rows));
}

}  // namespace

void write_outputs(const Comparison& c, const std::filesystem::path& dir) {
  std::vector<std::filesystem::path> inputs(c.a.files.begin(), c.a.files.end());
  inputs.insert(inputs.end(), c.b.files.begin(), c.b.files.end());
  check_output_directory(dir, inputs);
  // Everything is formed before anything is written, into a staging directory moved into place when complete
  // (compare.json last), so that no run leaves compare.json without its page.
  const std::string json_text = to_json(c).dump(1, ' ', false, kReplaceInvalidUtf8) + "\n";
  const std::string png_bytes = png(c);
  const std::string html_text = html(c, png_bytes);
  StagedDirectory staged(dir, {"compare.json"});
  write_file_atomically(staged.path() / "compare.png", png_bytes);
  write_file_atomically(staged.path() / "compare.html", html_text);
  write_file_atomically(staged.path() / "compare.json", json_text);
  staged.commit();
}

std::string verdict(const Comparison& c, std::size_t max_lines) {
  std::string out = fmt::format("compare {}: A {} ({}, {} samples) vs B {} ({}, {} samples)\n", c.scene_name,
                                fmt::join(c.a.files, ","), c.a.renderer, c.a.samples, fmt::join(c.b.files, ","),
                                c.b.renderer, c.b.samples);
  out += fmt::format("  {}×{}, {} bands {:g}-{:g} nm, {} components, pixels {} ({} with different ids left out)\n",
                     c.width, c.height, c.bands.size(), c.bands.min_wavelength(), c.bands.max_wavelength(),
                     c.components.size(), c.pixels_mode, c.id_mismatch_pixels);
  out += fmt::format("  standard errors from {}\n", c.se_method);
  out += fmt::format("  ΔE00 ({}, white: {}): mean {:.3f}, 95th percentile {:.3f}, max {:.3f}\n", c.camera, c.white,
                     c.delta_e_mean, c.delta_e_p95, c.delta_e_max);
  const auto cells = worst_cells(c);
  if (c.failed == 0) {
    out += fmt::format("  AGREE: all {} cells (object × component × band) within tolerance ({}, + {:g} SE)", c.cells.size(),
                       c.tolerance_mode, c.sigmas);
    // The largest finite |z|: a cell exact on both sides (a lamp seen directly, no standard error) whose values differ
    // has an infinite z, passes on the tolerance alone and is not quoted.
    const auto noisy = std::find_if(cells.begin(), cells.end(), [](const Cell* cell) { return std::isfinite(cell->z); });
    if (noisy != cells.end())
      out += fmt::format("; largest |z| {} ({} {} {})", z_text((*noisy)->z), (*noisy)->object, (*noisy)->component,
                         band_label(**noisy));
    out += "\n";
    return out;
  }
  out += fmt::format("  DISAGREE: {} of {} cells beyond tolerance ({}, + {:g} SE):\n", c.failed, c.cells.size(),
                     c.tolerance_mode, c.sigmas);
  std::size_t shown = 0;
  for (const Cell* cell : cells) {
    if (cell->pass || shown == max_lines) break;
    out += fmt::format("    {:<16} {:<18} {:>14}  A/B {}  z {}\n", cell->object, cell->component, band_label(*cell),
                       ratio_text(*cell), z_text(cell->z));
    ++shown;
  }
  if (shown < c.failed) out += fmt::format("    … and {} more (compare.json, compare.html)\n", c.failed - shown);
  return out;
}

}  // namespace ct::cmp
