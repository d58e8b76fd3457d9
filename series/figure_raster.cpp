// SPDX-License-Identifier: Apache-2.0
#include "series/figure_raster.h"

#include <algorithm>

#include <fmt/core.h>
#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "plot/text.h"

namespace ct::series {
namespace {

using plot::Align;
using plot::draw_mark;
using plot::put_text;
using plot::wrap_text;

const cv::Scalar kPageWhite(255, 255, 255), kPageInk(30, 30, 30), kPageSoftInk(100, 100, 100), kRule(200, 200, 200),
    kError(30, 30, 180);
constexpr int kPad = 10, kGap = 14, kColumn = kPlotWidth + 2 * kPad, kCameraBox = 288, kLine = 20;

// Draws one panel's column into `img` at x (or, with img empty, only measures it); returns its height.
int draw_panel(cv::Mat* img, int x, int top, const std::string& panel, const VariantView* v) {
  int y = top;
  const int width = kColumn - 2 * kPad;
  for (const std::string& line : wrap_text(panel_caption(panel), width, 0.58, 1)) {
    y += 22;
    if (img) put_text(*img, line, {x + kPad, y}, 0.58, kPageInk, Align::Left, 1);
  }
  if (!v) {
    y += kLine + 4;
    if (img) put_text(*img, "no variant of this run reproduces this panel", {x + kPad, y}, 0.45, kPageSoftInk);
    return y - top + kPad;
  }
  y += kLine;
  if (img) put_text(*img, "variant " + v->name, {x + kPad, y}, 0.45, kPageSoftInk);
  const std::string error = !v->ok ? "failed: " + v->error : !v->image_error.empty() ? "cannot show: " + v->image_error : "";
  if (!error.empty()) {
    for (const std::string& line : wrap_text(error, width, 0.45)) {
      y += kLine;
      if (img) put_text(*img, line, {x + kPad, y}, 0.45, kError);
    }
    return y - top + kPad;
  }

  y += 10;
  const cv::Size shown = display_size(v->camera, kCameraBox);
  if (img) {
    cv::Mat scaled;
    cv::resize(v->camera, scaled, shown, 0, 0, shown.width >= v->camera.cols ? cv::INTER_NEAREST : cv::INTER_AREA);
    scaled.copyTo((*img)(cv::Rect(x + (kColumn - shown.width) / 2, y, shown.width, shown.height)));
  }
  y += shown.height + 6;
  if (img) put_text(*img, fmt::format("camera image, {} x {} px", v->camera.cols, v->camera.rows), {x + kColumn / 2, y + 12}, 0.42, kPageSoftInk,
                    Align::Centre);
  y += 22;
  for (const cv::Mat* plot : {&v->oblique, &v->projection}) {
    if (img) plot->copyTo((*img)(cv::Rect(x + kPad, y, plot->cols, plot->rows)));
    y += plot->rows + 6;
  }

  // Per object: expected and found, with a mark.
  y += 4;
  if (img) cv::line(*img, {x + kPad, y}, {x + kColumn - kPad, y}, kRule, 1);
  y += 4;
  for (const FindingView& f : v->findings) {
    const std::string object = f.target != f.object && f.target != "image" && !f.target.empty()
                                   ? fmt::format("{} ({})", f.object, f.target)
                                   : f.object;
    const std::string text = fmt::format("{}: expected {}, found {}", object, expected_text(f), f.found);
    // A long expectation (a bend cause, the paper's word) wraps within the column.
    const std::vector<std::string> lines = wrap_text(text, width - 18, 0.45);
    for (std::size_t k = 0; k < lines.size(); ++k) {
      y += k == 0 ? kLine : kLine - 4;
      if (!img) continue;
      put_text(*img, lines[k], {x + kPad + 18, y}, 0.45, kPageInk);
      if (k == 0) draw_mark(*img, {x + kPad, y}, 12, f.ok);
    }
  }
  if (v->findings.empty()) {
    y += kLine;
    if (img) put_text(*img, "no expectations", {x + kPad, y}, 0.45, kPageSoftInk);
  }
  return y - top + kPad;
}

}  // namespace

cv::Mat figure_raster(int figure, const std::vector<std::pair<std::string, const VariantView*>>& panels, const std::string& subtitle) {
  const int n = static_cast<int>(panels.size());
  const int width = n * kColumn + (n - 1) * kGap + 2 * kPad;
  const std::vector<std::string> title = wrap_text(figure_title(figure) + ".", width - 2 * kPad, 0.75, 2);
  const std::vector<std::string> sub = wrap_text(subtitle, width - 2 * kPad, 0.5);
  int top = kPad + 4;
  top += static_cast<int>(title.size()) * 30 + static_cast<int>(sub.size()) * 22 + 10;
  int height = 0;
  for (const auto& [name, variant] : panels) height = std::max(height, draw_panel(nullptr, 0, top, name, variant));
  cv::Mat img(top + height + kPad, width, CV_8UC3, kPageWhite);
  int y = kPad + 4;
  for (const std::string& line : title) put_text(img, line, {kPad, y += 30}, 0.75, kPageInk, Align::Left, 2);
  for (const std::string& line : sub) put_text(img, line, {kPad, y += 22}, 0.5, kPageSoftInk);
  for (int k = 0; k < n; ++k) {
    const int x = kPad + k * (kColumn + kGap);
    if (k > 0) cv::line(img, {x - kGap / 2, top + 8}, {x - kGap / 2, top + height - 8}, kRule, 1);
    draw_panel(&img, x, top, panels[static_cast<std::size_t>(k)].first, panels[static_cast<std::size_t>(k)].second);
  }
  return img;
}

}  // namespace ct::series
