// SPDX-License-Identifier: Apache-2.0
#include "study/charts.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <fmt/core.h>
#include <opencv2/imgproc.hpp>

#include "core/file_io.h"
#include "plot/png.h"
#include "plot/text.h"
#include "plot/ticks.h"

namespace ct::study {
namespace {
namespace fs = std::filesystem;
using plot::Align;
using plot::log_tick_label;
using plot::log_ticks;
using plot::put_text;
using plot::text_width;

const cv::Scalar kWhite(255, 255, 255), kInk(40, 40, 40), kSoft(120, 120, 120), kGrid(228, 228, 228);

// Knobs in legend order, with their colours (BGR, a colour-blind-safe categorical set).
const std::vector<std::pair<std::string, cv::Scalar>>& knob_colours() {
  static const std::vector<std::pair<std::string, cv::Scalar>> colours = {
      {"base", cv::Scalar(30, 30, 30)},      {"bands", cv::Scalar(178, 114, 0)},   {"fitted", cv::Scalar(115, 158, 0)},
      {"samples", cv::Scalar(0, 159, 230)},  {"bounces", cv::Scalar(167, 121, 204)}, {"mode", cv::Scalar(0, 94, 213)},
      {"planned", cv::Scalar(66, 66, 220)},  {"guided", cv::Scalar(150, 40, 120)}};
  return colours;
}

cv::Scalar colour_of(const std::string& knob) {
  for (const auto& [k, c] : knob_colours())
    if (k == knob) return c;
  return kSoft;
}

// A short label beside a marker.
std::string short_label(const Setting& s) {
  if (s.knob == "base") return "base";
  if (s.knob == "bands") return fmt::format("{} bands", s.bands.size());
  if (s.knob == "fitted") return s.value;  // "4 fitted for 1": plans for different targets may share a count
  if (s.knob == "samples") return fmt::format("{} spp", s.samples);
  if (s.knob == "bounces") return fmt::format("{} bounce{}", s.max_bounces, s.max_bounces == 1 ? "" : "s");
  if (s.knob == "planned") return "planned";
  if (s.knob == "guided") return "guided";
  return s.value;
}

struct LogAxis {
  double lo, hi;  // values
  int a, b;       // pixels of lo and hi
  double at(double v) const {
    return a + (b - a) * (std::log10(v) - std::log10(lo)) / (std::log10(hi) - std::log10(lo));
  }
};

}  // namespace

LogRange log_range(std::vector<double> values, double floor) {
  for (double& v : values) v = std::max(v, floor);
  LogRange r{floor, floor * 10, {}};
  if (!values.empty()) {
    auto [mn, mx] = std::minmax_element(values.begin(), values.end());
    const double lo = std::log10(*mn), hi = std::log10(*mx);
    const double pad = hi - lo < 0.2 ? 0.5 : 0.1 * (hi - lo);
    r.lo = std::pow(10.0, lo - pad), r.hi = std::pow(10.0, hi + pad);
  }
  // Where fewer than two of 1, 2 and 5 times a power of ten fall inside, log_ticks gives the powers of ten just
  // outside: the axis reaches them, so that its ticks are on it.
  r.ticks = log_ticks(r.lo, r.hi);
  r.lo = std::min(r.lo, r.ticks.front()), r.hi = std::max(r.hi, r.ticks.back());
  r.ticks = log_ticks(r.lo, r.hi);
  return r;
}

namespace {

double value_of(const SettingResult& r, ChartValue value) {
  switch (value) {
    case ChartValue::MeanDe00: return r.mean;
    case ChartValue::P95De00: return r.p95;
    case ChartValue::DirectionDeg: return r.max_direction_deg.value_or(0.0);
    case ChartValue::SystematicRms: return r.systematic_rms;
  }
  return 0;
}

void draw_marker(cv::Mat& img, cv::Point p, const cv::Scalar& colour, bool square, bool cross, int r) {
  if (cross) {
    cv::line(img, p + cv::Point(-r, -r), p + cv::Point(r, r), colour, 2, cv::LINE_AA);
    cv::line(img, p + cv::Point(-r, r), p + cv::Point(r, -r), colour, 2, cv::LINE_AA);
  } else if (square) {
    cv::rectangle(img, p - cv::Point(r, r), p + cv::Point(r, r), colour, cv::FILLED, cv::LINE_AA);
  } else {
    cv::circle(img, p, r, colour, cv::FILLED, cv::LINE_AA);
  }
}

}  // namespace

cv::Mat chart(const StudyResult& result, ChartValue value) {
  const int W = 980, H = 640, left = 96, right = 236, top = 64, bottom = 78;
  cv::Mat img(H, W, CV_8UC3, kWhite);
  const char* title = value == ChartValue::MeanDe00        ? "Mean colour error against render cost"
                      : value == ChartValue::P95De00       ? "95th-percentile colour error against render cost"
                      : value == ChartValue::SystematicRms ? "Systematic colour error (bands, bounces, mode) against render cost"
                                                           : "Largest turn of an object's principal direction against render cost";
  put_text(img, title, {left, 30}, 0.62, kInk, Align::Left, 1);
  put_text(img, fmt::format("{}: each setting against the reference ({})", fs::path(result.scene).filename().string(),
                            result.reference.value),
           {left, 50}, 0.42, kSoft);

  std::vector<const SettingResult*> shown;
  for (const SettingResult& r : result.settings)
    if (r.ok && r.cpu_s > 0 && (value != ChartValue::SystematicRms || r.systematic_measurable)) shown.push_back(&r);
  std::vector<double> xs, ys;
  const double floor = value == ChartValue::DirectionDeg ? 0.01 : value == ChartValue::SystematicRms ? 0.05 : 1e-3;
  for (const SettingResult* r : shown) {
    xs.push_back(r->cpu_s);
    ys.push_back(value_of(*r, value));
    if (value == ChartValue::SystematicRms) ys.push_back(std::max(r->systematic_rms_hi, floor));
  }
  if (value != ChartValue::DirectionDeg) ys.push_back(1.0);  // the ΔE00 = 1 line is always in view
  const LogRange xr = log_range(xs, 1e-3), yr = log_range(ys, floor);
  const LogAxis x{xr.lo, xr.hi, left, W - right}, y{yr.lo, yr.hi, H - bottom, top};

  // Grid, ticks and their values.
  for (double t : xr.ticks) {
    const int px = static_cast<int>(std::lround(x.at(t)));
    cv::line(img, {px, top}, {px, H - bottom}, kGrid, 1);
    cv::line(img, {px, H - bottom}, {px, H - bottom + 5}, kInk, 1);
    put_text(img, log_tick_label(t), {px, H - bottom + 22}, 0.45, kInk, Align::Centre);
  }
  for (double t : yr.ticks) {
    const int py = static_cast<int>(std::lround(y.at(t)));
    cv::line(img, {left, py}, {W - right, py}, kGrid, 1);
    cv::line(img, {left - 5, py}, {left, py}, kInk, 1);
    put_text(img, log_tick_label(t), {left - 9, py + 5}, 0.45, kInk, Align::Right);
  }
  cv::rectangle(img, {left, top}, {W - right, H - bottom}, kInk, 1);
  put_text(img, "render CPU time (seconds, log scale)", {(left + W - right) / 2, H - 24}, 0.5, kInk, Align::Centre);
  const std::string ylabel = value == ChartValue::MeanDe00        ? "mean dE00 (log scale)"
                             : value == ChartValue::P95De00       ? "95th-percentile dE00 (log scale)"
                             : value == ChartValue::SystematicRms ? "systematic rms dE00 (log scale)"
                                                                  : "largest direction change (degrees, log scale)";
  cv::Mat label(24, H - top - bottom, CV_8UC3, kWhite);
  put_text(label, ylabel, {label.cols / 2, 17}, 0.5, kInk, Align::Centre);
  cv::rotate(label, label, cv::ROTATE_90_COUNTERCLOCKWISE);
  label.copyTo(img(cv::Rect(8, top, label.cols, label.rows)));

  cv::Mat plot = img(cv::Rect(left + 1, top + 1, W - right - left - 1, H - bottom - top - 1));
  const cv::Point origin(left + 1, top + 1);
  auto point = [&](const SettingResult& r) {
    return cv::Point(static_cast<int>(std::lround(x.at(r.cpu_s))), static_cast<int>(std::lround(y.at(std::max(value_of(r, value), floor)))));
  };
  std::vector<cv::Rect> taken;  // markers and labels placed so far (plot coordinates)
  if (value != ChartValue::DirectionDeg) {
    const int py = static_cast<int>(std::lround(y.at(1.0)));
    for (int px = left; px < W - right; px += 8) cv::line(img, {px, py}, {std::min(px + 3, W - right), py}, kSoft, 1);
    put_text(img, "dE00 = 1", {W - right - 6, py - 6}, 0.42, kSoft, Align::Right);
    const int w = text_width("dE00 = 1", 0.42);
    taken.emplace_back(cv::Point(W - right - 6 - w, py - 18) - origin, cv::Size(w, 14));
  }
  // The Pareto front (of mean ΔE00 against CPU seconds) as a staircase, on every chart.
  std::vector<const SettingResult*> front;
  for (const SettingResult* r : shown)
    if (r->pareto) front.push_back(r);
  std::sort(front.begin(), front.end(), [](auto* a, auto* b) { return a->cpu_s < b->cpu_s; });
  if (value == ChartValue::MeanDe00)
    for (std::size_t i = 0; i + 1 < front.size(); ++i) {
      const cv::Point a = point(*front[i]) - origin, b = point(*front[i + 1]) - origin;
      cv::line(plot, a, {b.x, a.y}, cv::Scalar(150, 150, 150), 2, cv::LINE_AA);
      cv::line(plot, {b.x, a.y}, b, cv::Scalar(150, 150, 150), 2, cv::LINE_AA);
    }
  if (value == ChartValue::SystematicRms)
    for (const SettingResult* r : shown) {
      const int px = point(*r).x - origin.x;
      const int lo = static_cast<int>(std::lround(y.at(std::max(r->systematic_rms_lo, floor)))) - origin.y;
      const int hi = static_cast<int>(std::lround(y.at(std::max(r->systematic_rms_hi, floor)))) - origin.y;
      cv::line(plot, {px, lo}, {px, hi}, colour_of(r->setting.knob), 1, cv::LINE_AA);
      for (int e : {lo, hi}) cv::line(plot, {px - 4, e}, {px + 4, e}, colour_of(r->setting.knob), 1, cv::LINE_AA);
    }
  for (const SettingResult* r : shown) taken.emplace_back(point(*r) - origin - cv::Point(7, 7), cv::Size(14, 14));
  for (const SettingResult* r : shown) {
    const cv::Point p = point(*r) - origin;
    const bool changed = r->classes_kept < static_cast<int>(r->objects.size());
    if (r->pareto) cv::circle(plot, p, 11, kInk, 1, cv::LINE_AA);
    draw_marker(plot, p, colour_of(r->setting.knob), r->setting.renderer == series::Renderer::Cycles,
                value == ChartValue::DirectionDeg && changed, 6);
    // The label in the first free place of: right, left, above right, below right, above left, below left; in
    // none, the first of them inside the plot (else right of the marker anyway).
    const std::string text = short_label(r->setting);
    const int w = text_width(text, 0.4), h = 12;
    const cv::Point offsets[] = {{10, 4}, {-10 - w, 4}, {8, -10}, {8, 18}, {-8 - w, -10}, {-8 - w, 18}};
    std::optional<cv::Rect> place, first_inside;
    for (const cv::Point& o : offsets) {
      const cv::Rect candidate(p + o - cv::Point(0, h), cv::Size(w, h));
      const bool inside = candidate.x >= 0 && candidate.y >= 0 && candidate.br().x < plot.cols && candidate.br().y < plot.rows;
      const bool free = std::none_of(taken.begin(), taken.end(), [&](const cv::Rect& t) { return (t & candidate).area() > 0; });
      if (inside && !first_inside) first_inside = candidate;
      if (inside && free) {
        place = candidate;
        break;
      }
    }
    if (!place) place = first_inside.value_or(cv::Rect(p + offsets[0] - cv::Point(0, h), cv::Size(w, h)));
    taken.push_back(*place);
    put_text(plot, text, {place->x, place->y + h}, 0.4, kInk);
  }

  // Legend.
  int ly = top + 10;
  const int lx = W - right + 18;
  for (const auto& [knob, colour] : knob_colours()) {
    bool used = false;
    for (const SettingResult* r : shown) used = used || r->setting.knob == knob;
    if (!used) continue;
    draw_marker(img, {lx + 6, ly}, colour, false, false, 6);
    put_text(img, knob == "base" ? "the scene's settings" : knob == "planned" ? "chromatrace plan" : knob,
             {lx + 20, ly + 5}, 0.45, kInk);
    ly += 24;
  }
  ly += 8;
  draw_marker(img, {lx + 6, ly}, kSoft, false, false, 6);
  put_text(img, "tracer", {lx + 20, ly + 5}, 0.45, kInk);
  ly += 24;
  draw_marker(img, {lx + 6, ly}, kSoft, true, false, 6);
  put_text(img, "Cycles", {lx + 20, ly + 5}, 0.45, kInk);
  ly += 24;
  cv::circle(img, {lx + 6, ly}, 11, kInk, 1, cv::LINE_AA);
  put_text(img, "Pareto front", {lx + 20, ly + 5}, 0.45, kInk);
  put_text(img, "(CPU time, mean dE00)", {lx + 20, ly + 22}, 0.4, kSoft);
  ly += 44;
  if (value == ChartValue::DirectionDeg) {
    draw_marker(img, {lx + 6, ly}, kSoft, false, true, 6);
    put_text(img, "an object's class", {lx + 20, ly + 5}, 0.45, kInk);
    put_text(img, "differs from the reference", {lx + 20, ly + 22}, 0.4, kSoft);
  }
  return img;
}

void write_charts(const fs::path& dir, const StudyResult& result) {
  const std::pair<const char*, ChartValue> charts[] = {{"error_vs_cost.png", ChartValue::MeanDe00},
                                                       {"p95_vs_cost.png", ChartValue::P95De00},
                                                       {"systematic_vs_cost.png", ChartValue::SystematicRms},
                                                       {"structure_vs_cost.png", ChartValue::DirectionDeg}};
  for (const auto& [name, value] : charts) write_file_atomically(dir / name, plot::encode_png(chart(result, value)));
}

}  // namespace ct::study
