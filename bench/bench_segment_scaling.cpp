// SPDX-License-Identifier: Apache-2.0
// The segmentation's time against the number of pixels and of parts: segment_image (analyzer/segmentation.h) on
// synthetic mosaics — K Voronoi cells (seeds jittered on a grid, deterministic for the seed), each a random colour
// shaded by its own gradient, a quarter of them with a white highlight, and noise that grows as the square root of
// the signal — at several sizes, the working size set to the image's so that every pixel is segmented. Prints the
// seconds, the working pixels, the parts after step 4 (linear colour clusters, what steps 5 and 6 work on) and the
// segments, with the time per pixel and per part, and the time per pixel against the first case's (the baseline,
// run first in the same process: a cost near-linear in pixels and parts keeps that ratio near 1). Then the
// photographs given with --image (by default skimage's rocket.jpg, when python3-skimage is installed) at each
// --photo-sizes, through select_regions as analyze --segment runs it. Draws the seconds against the working pixels,
// and the seconds per working megapixel against the parts, to a PNG chart.
//
//   bench_segment_scaling [--sizes MP,...] [--cells K,...] [--noise SIGMA] [--image FILE]... [--photo-sizes MP,...]
//                         [--chart FILE]
//
// Defaults: --sizes 0.0625,0.125,0.25,0.5,1 --cells 64,1024,16384 --noise 0.01 --photo-sizes 0.06,0.12,0.25,0.5
// --chart segment_scaling.png.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include <fmt/core.h>
#include <opencv2/imgproc.hpp>

#include "analyzer/analysis.h"
#include "analyzer/segmentation.h"
#include "core/file_io.h"
#include "core/random.h"
#include "plot/png.h"
#include "plot/text.h"
#include "plot/ticks.h"

namespace {

using ct::analyzer::RgbImage;
using ct::analyzer::Segmentation;

// K ≈ `cells` Voronoi cells over width × height: linear RGB in [0, 1], deterministic for a seed.
RgbImage mosaic(int width, int height, int cells, double noise, std::uint64_t seed) {
  const int gx = std::max(1, static_cast<int>(std::lround(std::sqrt(cells * double(width) / height)))),
            gy = std::max(1, static_cast<int>(std::lround(double(cells) / gx)));
  const double cw = double(width) / gx, ch = double(height) / gy;
  struct Cell {
    double x, y;             // seed
    double colour[3];        // body colour
    double gx, gy, base;     // shading: base + gx·(x − seed) + gy·(y − seed), per cell width
    double highlight = 0;    // peak of the white highlight at the seed (0: none)
  };
  std::vector<Cell> cell(static_cast<std::size_t>(gx * gy));
  for (int j = 0; j < gy; ++j)
    for (int i = 0; i < gx; ++i) {
      ct::Random r(seed, static_cast<std::uint64_t>(j * gx + i));
      Cell& c = cell[static_cast<std::size_t>(j * gx + i)];
      c.x = (i + 0.15 + 0.7 * r.uniform()) * cw;
      c.y = (j + 0.15 + 0.7 * r.uniform()) * ch;
      for (double& v : c.colour) v = 0.1 + 0.9 * r.uniform();
      c.base = 0.25 + 0.5 * r.uniform();
      c.gx = (r.uniform() - 0.5) * 0.4 / cw;
      c.gy = (r.uniform() - 0.5) * 0.4 / ch;
      if (r.uniform() < 0.25) c.highlight = 0.2 + 0.3 * r.uniform();
    }
  RgbImage image;
  image.width = width;
  image.height = height;
  image.rgb.resize(static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 3);
  for (int y = 0; y < height; ++y) {
    ct::Random r(seed ^ 0x5eedu, static_cast<std::uint64_t>(y));
    const int cy = std::min(gy - 1, static_cast<int>(y / ch));
    for (int x = 0; x < width; ++x) {
      const int cx = std::min(gx - 1, static_cast<int>(x / cw));
      const Cell* best = nullptr;
      double d2 = 1e300;
      for (int j = std::max(0, cy - 2); j <= std::min(gy - 1, cy + 2); ++j)
        for (int i = std::max(0, cx - 2); i <= std::min(gx - 1, cx + 2); ++i) {
          const Cell& c = cell[static_cast<std::size_t>(j * gx + i)];
          const double d = (x + 0.5 - c.x) * (x + 0.5 - c.x) + (y + 0.5 - c.y) * (y + 0.5 - c.y);
          if (d < d2) d2 = d, best = &c;
        }
      const double shade = std::clamp(best->base + best->gx * (x + 0.5 - best->x) + best->gy * (y + 0.5 - best->y), 0.05, 1.0);
      const double spot = best->highlight * std::exp(-d2 / (0.08 * cw * ch));
      float* v = &image.rgb[(static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x)) * 3];
      for (int k = 0; k < 3; ++k) {
        // Gaussian noise (Box–Muller) proportional to the square root of the signal, as shot noise is.
        const double u1 = std::max(1e-300, r.uniform()), u2 = r.uniform();
        const double g = std::sqrt(-2 * std::log(u1)) * std::cos(2 * M_PI * u2);
        const double signal = shade * best->colour[k] + spot;
        v[k] = static_cast<float>(signal + noise * std::sqrt(signal) * g);
      }
    }
  }
  return image;
}

struct Run {
  std::string name;
  std::size_t pixels = 0, parts = 0, segments = 0;  // working pixels; parts after step 4; segments
  int cells = 0;                                    // K (0 for a photograph)
  double seconds = 0;
};

std::vector<double> parse_list(const char* text) {
  std::vector<double> out;
  for (const char* p = text; *p;) {
    char* end = nullptr;
    out.push_back(std::strtod(p, &end));
    if (end == p) break;
    p = *end == ',' ? end + 1 : end;
  }
  return out;
}

std::size_t segments_of(const Segmentation& s) {
  return static_cast<std::size_t>(std::count_if(s.regions.begin(), s.regions.end(), [](const auto& r) { return r.source == "segment"; }));
}

// An axis over the values: logarithmic, padded by 8 % of their span (half a decade for a single value), or linear
// from 0 to a nice step above the largest.
struct Axis {
  double lo, hi;
  int a, b;  // pixels of lo and hi
  bool log = true;
  double at(double v) const {
    return log ? a + (b - a) * (std::log10(v) - std::log10(lo)) / (std::log10(hi) - std::log10(lo)) : a + (b - a) * (v - lo) / (hi - lo);
  }
  std::vector<double> ticks() const { return log ? ct::plot::log_ticks(lo, hi) : ct::plot::linear_ticks(lo, hi).values; }
  std::string label(double v) const { return log ? ct::plot::log_tick_label(v) : ct::plot::linear_ticks(lo, hi).label(v); }
};

Axis log_axis(const std::vector<double>& values, int a, int b) {
  const auto [mn, mx] = std::minmax_element(values.begin(), values.end());
  double lo = std::log10(*mn), hi = std::log10(*mx);
  const double pad = hi - lo < 0.2 ? 0.5 : 0.08 * (hi - lo);
  return {std::pow(10.0, lo - pad), std::pow(10.0, hi + pad), a, b};
}

Axis linear_axis(const std::vector<double>& values, int a, int b) {
  const ct::plot::NiceRange r = ct::plot::nice_range(0, *std::max_element(values.begin(), values.end()) * 1.05, 5);
  return {0, r.hi, a, b, false};
}

const cv::Scalar kWhite(255, 255, 255), kInk(40, 40, 40), kSoft(120, 120, 120), kGrid(228, 228, 228);
const cv::Scalar kSeries[] = {cv::Scalar(178, 114, 0), cv::Scalar(0, 94, 213), cv::Scalar(115, 158, 0), cv::Scalar(167, 121, 204),
                              cv::Scalar(0, 159, 230), cv::Scalar(66, 66, 220)};

// One panel, the mosaics joined per K, the photographs as squares. By pixels: the seconds against the working
// pixels, with the slopes of a cost linear (dashed) and quadratic (dotted) in the pixels through the baseline. By
// parts: the seconds per working megapixel against the parts after step 4 (flat for a cost linear in the pixels
// that the parts do not raise).
void panel(cv::Mat& img, cv::Rect box, const std::vector<Run>& runs, const std::vector<int>& cells, bool by_parts, const std::string& title) {
  using ct::plot::Align;
  using ct::plot::put_text;
  const auto x_of = [&](const Run& r) { return double(by_parts ? std::max<std::size_t>(1, r.parts) : r.pixels); };
  const auto y_of = [&](const Run& r) { return by_parts ? r.seconds / (1e-6 * double(r.pixels)) : r.seconds; };
  std::vector<double> xs, ys;
  for (const Run& r : runs) xs.push_back(x_of(r)), ys.push_back(y_of(r));
  const int left = box.x + 70, right = box.x + box.width - 14, top = box.y + 40, bottom = box.y + box.height - 50;
  const Axis x = log_axis(xs, left, right), y = by_parts ? linear_axis(ys, bottom, top) : log_axis(ys, bottom, top);
  put_text(img, title, {left, box.y + 24}, 0.52, kInk);
  for (double t : ct::plot::log_ticks(x.lo, x.hi)) {
    const int px = static_cast<int>(std::lround(x.at(t)));
    cv::line(img, {px, top}, {px, bottom}, kGrid, 1);
    put_text(img, ct::plot::log_tick_label(t), {px, bottom + 20}, 0.42, kInk, Align::Centre);
  }
  for (double t : y.ticks()) {
    const int py = static_cast<int>(std::lround(y.at(t)));
    cv::line(img, {left, py}, {right, py}, kGrid, 1);
    put_text(img, y.label(t), {left - 7, py + 5}, 0.42, kInk, Align::Right);
  }
  cv::rectangle(img, {left, top}, {right, bottom}, kInk, 1);
  put_text(img, by_parts ? "parts after step 4 (log scale)" : "working pixels (log scale)", {(left + right) / 2, bottom + 42}, 0.46, kInk, Align::Centre);
  cv::Mat label(22, bottom - top, CV_8UC3, kWhite);
  put_text(label, by_parts ? "seconds per working megapixel" : "seconds (log scale)", {label.cols / 2, 16}, 0.46, kInk, Align::Centre);
  cv::rotate(label, label, cv::ROTATE_90_COUNTERCLOCKWISE);
  label.copyTo(img(cv::Rect(box.x + 4, top, label.cols, label.rows)));
  cv::Mat plot = img(cv::Rect(left + 1, top + 1, right - left - 1, bottom - top - 1));
  const cv::Point origin(left + 1, top + 1);
  const auto point = [&](double vx, double vy) {
    return cv::Point(static_cast<int>(std::lround(x.at(vx))), static_cast<int>(std::lround(y.at(vy)))) - origin;
  };
  // Reference slopes through the baseline (the first run).
  const double x0 = x_of(runs.front()), y0 = y_of(runs.front());
  for (int power : {1, 2}) {
    if (by_parts) break;
    const cv::Point a = point(x.lo, y0 * std::pow(x.lo / x0, power)), b = point(x.hi, y0 * std::pow(x.hi / x0, power));
    const double length = std::hypot(b.x - a.x, b.y - a.y);
    const int dash = power == 1 ? 8 : 3;
    for (double s = 0; s < length; s += 2 * dash) {
      const double t0 = s / length, t1 = std::min(1.0, (s + dash) / length);
      cv::line(plot, {static_cast<int>(a.x + t0 * (b.x - a.x)), static_cast<int>(a.y + t0 * (b.y - a.y))},
               {static_cast<int>(a.x + t1 * (b.x - a.x)), static_cast<int>(a.y + t1 * (b.y - a.y))}, kSoft, 1, cv::LINE_AA);
    }
  }
  for (std::size_t k = 0; k < cells.size(); ++k) {
    const cv::Scalar colour = kSeries[k % std::size(kSeries)];
    std::vector<const Run*> line;
    for (const Run& r : runs)
      if (r.cells == cells[k]) line.push_back(&r);
    std::sort(line.begin(), line.end(), [&](const Run* a, const Run* b) { return x_of(*a) < x_of(*b); });
    for (std::size_t i = 0; i + 1 < line.size(); ++i)
      cv::line(plot, point(x_of(*line[i]), y_of(*line[i])), point(x_of(*line[i + 1]), y_of(*line[i + 1])), colour, 2, cv::LINE_AA);
    for (const Run* r : line) cv::circle(plot, point(x_of(*r), y_of(*r)), 5, colour, cv::FILLED, cv::LINE_AA);
  }
  for (const Run& r : runs)
    if (r.cells == 0) {
      const cv::Point p = point(x_of(r), y_of(r));
      cv::rectangle(plot, p - cv::Point(5, 5), p + cv::Point(5, 5), kInk, cv::FILLED, cv::LINE_AA);
    }
}

cv::Mat chart(const std::vector<Run>& runs, const std::vector<int>& cells) {
  using ct::plot::put_text;
  const int W = 1260, H = 560, legend = 210;
  cv::Mat img(H, W, CV_8UC3, kWhite);
  put_text(img, "Segmentation time against the working pixels and the parts (segment_image, bench_segment_scaling)", {20, 28}, 0.6, kInk);
  const int pw = (W - legend) / 2;
  panel(img, cv::Rect(0, 40, pw, H - 40), runs, cells, false, "against the working pixels");
  panel(img, cv::Rect(pw, 40, pw, H - 40), runs, cells, true, "per working megapixel, against the parts after step 4");
  int ly = 110;
  const int lx = W - legend + 10;
  for (std::size_t k = 0; k < cells.size(); ++k, ly += 24) {
    cv::circle(img, {lx + 6, ly}, 5, kSeries[k % std::size(kSeries)], cv::FILLED, cv::LINE_AA);
    put_text(img, fmt::format("mosaic, K = {}", cells[k]), {lx + 20, ly + 5}, 0.45, kInk);
  }
  if (std::any_of(runs.begin(), runs.end(), [](const Run& r) { return r.cells == 0; })) {
    cv::rectangle(img, cv::Point(lx + 1, ly - 5), cv::Point(lx + 11, ly + 5), kInk, cv::FILLED);
    put_text(img, "photograph", {lx + 20, ly + 5}, 0.45, kInk);
    ly += 24;
  }
  ly += 10;
  for (int dash : {8, 3}) {
    for (int s = 0; s < 30; s += 2 * dash) cv::line(img, {lx + s, ly}, {lx + std::min(30, s + dash), ly}, kSoft, 1);
    put_text(img, dash == 8 ? "linear cost" : "quadratic cost", {lx + 38, ly + 5}, 0.45, kInk);
    ly += 20;
  }
  put_text(img, "in the pixels, through", {lx + 38, ly + 5}, 0.4, kSoft);
  put_text(img, "the first mosaic (left)", {lx + 38, ly + 21}, 0.4, kSoft);
  return img;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<double> sizes = {0.0625, 0.125, 0.25, 0.5, 1.0}, photo_sizes = {0.06, 0.12, 0.25, 0.5};
  std::vector<int> cells = {64, 1024, 16384};
  std::vector<std::string> images;
  double noise = 0.01;
  std::string chart_file = "segment_scaling.png";
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const char* value = i + 1 < argc ? argv[i + 1] : nullptr;
    if (!value) {
      std::fprintf(stderr, "%s: missing value\n", arg.c_str());
      return 2;
    }
    ++i;
    if (arg == "--sizes") sizes = parse_list(value);
    else if (arg == "--photo-sizes") photo_sizes = parse_list(value);
    else if (arg == "--cells") {
      cells.clear();
      for (double k : parse_list(value)) cells.push_back(static_cast<int>(k));
    } else if (arg == "--noise") noise = std::strtod(value, nullptr);
    else if (arg == "--image") images.emplace_back(value);
    else if (arg == "--chart") chart_file = value;
    else {
      std::fprintf(stderr, "usage: bench_segment_scaling [--sizes MP,...] [--cells K,...] [--noise SIGMA] [--image FILE]... "
                           "[--photo-sizes MP,...] [--chart FILE]\n");
      return 2;
    }
  }
  if (images.empty() && std::filesystem::exists("/usr/lib/python3/dist-packages/skimage/data/rocket.jpg"))
    images.emplace_back("/usr/lib/python3/dist-packages/skimage/data/rocket.jpg");

  std::vector<Run> runs;
  fmt::print("{:<36} {:>9} {:>8} {:>9} {:>9} {:>9} {:>9}  {}\n", "case", "pixels", "parts", "segments", "seconds", "us/pixel",
             "us/part", "us/pixel vs the baseline (first row)");
  const auto report = [&](const Run& r) {
    const double per_pixel = 1e6 * r.seconds / double(r.pixels), per_part = 1e6 * r.seconds / double(std::max<std::size_t>(1, r.parts));
    const double base = 1e6 * runs.front().seconds / double(runs.front().pixels);
    fmt::print("{:<36} {:>9} {:>8} {:>9} {:>9.3f} {:>9.3f} {:>9.1f}  {:.2f}x\n", r.name, r.pixels, r.parts, r.segments, r.seconds, per_pixel,
               per_part, per_pixel / base);
    std::fflush(stdout);
  };
  for (const int k : cells)
    for (const double mp : sizes) {
      const int height = std::max(8, static_cast<int>(std::lround(std::sqrt(mp * 1e6 / 1.5)))), width = static_cast<int>(std::lround(1.5 * height));
      const RgbImage image = mosaic(width, height, k, noise, 42);
      ct::analyzer::SegmentationOptions options;
      options.working_megapixels = static_cast<double>(image.pixel_count()) / 1e6;  // every pixel segmented
      const Segmentation s = ct::analyzer::segment_image(image, std::nullopt, 1.0, 0.0, options);
      Run r{fmt::format("mosaic K={} {}x{}", k, width, height), static_cast<std::size_t>(s.working_width) * static_cast<std::size_t>(s.working_height),
            s.parts, segments_of(s), k, s.seconds};
      runs.push_back(r);
      report(r);
    }
  for (const std::string& file : images) {
    const ct::analyzer::AnalysisImage input = ct::analyzer::read_analysis_image(file);
    for (const double mp : photo_sizes) {
      ct::analyzer::RegionOptions options;
      options.segment = true;
      options.segmentation.working_megapixels = mp;
      Segmentation s;
      const std::vector<ct::analyzer::Region> regions = ct::analyzer::select_regions(input, input.image, options, &s);
      const Run r{fmt::format("{} --segment-size {}", std::filesystem::path(file).filename().string(), mp),
                  static_cast<std::size_t>(s.working_width) * static_cast<std::size_t>(s.working_height), s.parts,
                  static_cast<std::size_t>(std::count_if(regions.begin(), regions.end(), [](const auto& g) { return g.source == "segment"; })), 0,
                  s.seconds};
      runs.push_back(r);
      report(r);
    }
  }
  if (runs.empty()) {
    std::fprintf(stderr, "bench_segment_scaling: nothing to run\n");
    return 2;
  }
  ct::write_file_atomically(chart_file, ct::plot::encode_png(chart(runs, cells)));
  fmt::print("chart: {}\n", chart_file);
  return 0;
}
