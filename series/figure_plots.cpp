// SPDX-License-Identifier: Apache-2.0
#include "series/figure_plots.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include <OpenImageIO/imageio.h>
#include <fmt/core.h>
#include <opencv2/imgproc.hpp>

#include "core/json_input.h"
#include "plot/oblique_cube.h"
#include "plot/text.h"
#include "plot/ticks.h"
#include "series/preview.h"

namespace ct::series {
namespace {

using Vec3 = Eigen::Vector3d;
using plot::Align;
using plot::put_text;
using plot::text_width;
using plot::tick_label;

const cv::Scalar kWhite(255, 255, 255), kInk(40, 40, 40), kSoftInk(95, 95, 95), kEdge(190, 190, 190),
    kGrid(232, 232, 232), kOutline(175, 175, 175);
// The channels' colours for axes and labels (BGR), dark enough to read on white.
const cv::Scalar kChannel[3] = {cv::Scalar(40, 40, 200), cv::Scalar(40, 150, 40), cv::Scalar(200, 70, 40)};
constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;
constexpr double kTick = 0.42, kLabel = 0.45, kTitle = 0.5;

cv::Point rounded(const cv::Point2d& p) { return {static_cast<int>(std::lround(p.x)), static_cast<int>(std::lround(p.y))}; }

// A point: a small square in the point's colour; light colours get a grey rim first so they show on white.
void draw_point(cv::Mat& img, cv::Point2d at, const cv::Vec3b& bgr, int size) {
  const cv::Point p(static_cast<int>(std::floor(at.x)) - size / 2, static_cast<int>(std::floor(at.y)) - size / 2);
  const double luma = 0.114 * bgr[0] + 0.587 * bgr[1] + 0.299 * bgr[2];
  if (luma > 215) cv::rectangle(img, p - cv::Point(1, 1), p + cv::Point(size, size), kOutline, cv::FILLED);
  cv::rectangle(img, p, p + cv::Point(size - 1, size - 1), cv::Scalar(bgr[0], bgr[1], bgr[2]), cv::FILLED);
}

int point_size(std::size_t count) { return count > 20000 ? 2 : count > 4000 ? 3 : 4; }

void draw_dashed(cv::Mat& img, cv::Point2d a, cv::Point2d b, const cv::Scalar& colour, double dash = 6) {
  const double length = std::hypot(b.x - a.x, b.y - a.y);
  const int n = std::max(1, static_cast<int>(length / dash));
  for (int k = 0; k < n; k += 2) {
    const double t0 = static_cast<double>(k) / n, t1 = std::min(1.0, static_cast<double>(k + 1) / n);
    cv::line(img, rounded(a + (b - a) * t0), rounded(a + (b - a) * t1), colour, 1, cv::LINE_AA);
  }
}

// Text centred on `centre` (both ways).
void put_centred(cv::Mat& img, std::string_view text, cv::Point2d centre, double scale, const cv::Scalar& colour) {
  int baseline = 0;
  const int height = cv::getTextSize("0", kFont, scale, 1, &baseline).height;
  put_text(img, text, rounded(centre + cv::Point2d(-text_width(text, scale) / 2.0, height / 2.0)), scale, colour);
}

// Text turned 90° counter-clockwise (read bottom to top), centred on `centre`.
void put_vertical(cv::Mat& img, std::string_view text, cv::Point centre, double scale, const cv::Scalar& colour) {
  int baseline = 0;
  const std::string s = plot::ascii(text);
  const cv::Size size = cv::getTextSize(s, kFont, scale, 1, &baseline);
  cv::Mat strip(size.height + baseline + 4, size.width + 4, CV_8UC3, kWhite);
  cv::putText(strip, s, cv::Point(2, size.height + 2), kFont, scale, colour, 1, cv::LINE_AA);
  cv::Mat turned;
  cv::rotate(strip, turned, cv::ROTATE_90_COUNTERCLOCKWISE);
  cv::Rect where(centre.x - turned.cols / 2, centre.y - turned.rows / 2, turned.cols, turned.rows);
  where &= cv::Rect(0, 0, img.cols, img.rows);
  if (where.empty()) return;
  cv::Mat target = img(where);
  cv::min(target, turned(cv::Rect(where.x - (centre.x - turned.cols / 2), where.y - (centre.y - turned.rows / 2),
                                  where.width, where.height)),
          target);
}

// Text no wider than `width`: the scale is reduced as far as needed.
void put_fitted(cv::Mat& img, std::string_view text, cv::Point at, double scale, const cv::Scalar& colour, int width,
                Align align = Align::Left) {
  while (scale > 0.3 && text_width(text, scale) > width) scale -= 0.01;
  put_text(img, text, at, scale, colour, align);
}

std::string count(std::size_t n) {
  std::string digits = std::to_string(n), out;
  for (std::size_t i = 0; i < digits.size(); ++i) {
    if (i > 0 && (digits.size() - i) % 3 == 0) out += ' ';
    out += digits[i];
  }
  return out;
}

// "0.41 R + 0.78 G - 0.47 B"
std::string combination(const Vec3& axis) {
  static const char* names[3] = {"R", "G", "B"};
  std::string s;
  for (int c = 0; c < 3; ++c) {
    const double v = axis[c];
    if (c == 0) s += fmt::format("{}{:.2f} {}", v < 0 ? "-" : "", std::abs(v), names[c]);
    else s += fmt::format(" {} {:.2f} {}", v < 0 ? "-" : "+", std::abs(v), names[c]);
  }
  return s;
}

// How many points of the pixel-space area `box` holds.
std::size_t points_in(const std::vector<cv::Point2d>& at, const cv::Rect& box) {
  std::size_t n = 0;
  for (const cv::Point2d& p : at) n += box.contains(cv::Point(static_cast<int>(p.x), static_cast<int>(p.y))) ? 1 : 0;
  return n;
}

}  // namespace

// ---- Units and points -----------------------------------------------------------------------------------------

std::string channel_units(const std::filesystem::path& exr, const analyzer::AnalysisImage& input) {
  std::string text;
  if (auto in = OIIO::ImageInput::open(exr.string())) {
    text = in->spec().get_string_attribute("chromatrace.units");
    in->close();
  }
  if (!text.empty()) {
    const Json units = Json::parse(text, nullptr, false);
    if (!units.is_discarded() && units.is_object() && units.contains("RGB") && units["RGB"].is_object()) {
      const Json& rgb = units["RGB"];
      auto string_of = [&](const char* key) { return rgb.contains(key) && rgb[key].is_string() ? rgb[key].get<std::string>() : ""; };
      const std::string unit = string_of("unit"), curve = string_of("curve");
      if (unit == "normalised") return fmt::format("{}, 1 = white", curve.empty() ? "linear" : curve);
      if (unit == "DN") {
        const int bits = rgb.contains("bits") && rgb["bits"].is_number_integer() ? rgb["bits"].get<int>() : 0;
        return bits > 0 ? fmt::format("linear {}-bit DN", bits) : "linear DN";
      }
      if (!unit.empty()) return "linear " + unit;
    }
  }
  return input.encoding.integer ? "DN" : "file values";
}

HistogramPoints gather_points(const analyzer::AnalysisImage& input, const cv::Mat& display_bgr, std::string units,
                              std::size_t max_points) {
  const analyzer::RgbImage& image = input.image;
  HistogramPoints out;
  out.units = std::move(units);
  out.pixels = image.pixel_count();
  const std::size_t n = out.pixels;

  // Lamps seen directly: their light is mostly the emission component.
  std::vector<std::uint8_t> lamp(n, 0);
  const analyzer::RgbImage* emission = find_layer(input, "emission");
  if (emission && input.linear && emission->pixel_count() == n && input.linear->pixel_count() == n)
    for (std::size_t p = 0; p < n; ++p) {
      const float e = emission->rgb[3 * p] + emission->rgb[3 * p + 1] + emission->rgb[3 * p + 2];
      const float t = input.linear->rgb[3 * p] + input.linear->rgb[3 * p + 1] + input.linear->rgb[3 * p + 2];
      lamp[p] = t > 0 && e > 0.5f * t ? 1 : 0;
    }

  auto finite = [&](std::size_t p) {
    return std::isfinite(image.rgb[3 * p]) && std::isfinite(image.rgb[3 * p + 1]) && std::isfinite(image.rgb[3 * p + 2]);
  };
  std::vector<float> top, bottom, top_all;
  for (std::size_t p = 0; p < n; ++p) {
    if (!finite(p)) {
      ++out.non_finite;
      continue;
    }
    const float* x = &image.rgb[3 * p];
    const float hi = std::max({x[0], x[1], x[2]}), lo = std::min({x[0], x[1], x[2]});
    top_all.push_back(hi);
    if (lamp[p]) continue;
    top.push_back(hi);
    bottom.push_back(lo);
  }
  if (top.empty()) top = top_all;  // nothing but lamps
  const double data_hi = quantile(top, 0.9995), data_lo = std::min(0.0, quantile(bottom, 0.0005));
  const plot::NiceRange cube = plot::nice_range(data_lo, data_hi, 4);
  out.lo = cube.lo;
  out.hi = cube.hi;
  out.step = cube.step;

  std::vector<std::size_t> inside;
  for (std::size_t p = 0; p < n; ++p) {
    if (!finite(p)) continue;
    const float* x = &image.rgb[3 * p];
    bool in = true;
    for (int c = 0; c < 3; ++c) in = in && x[c] >= out.lo && x[c] <= out.hi;
    if (in) {
      inside.push_back(p);
    } else {
      ++out.beyond;
      out.lamps_beyond += lamp[p];
    }
  }
  out.in_range = inside.size();

  // A fixed permutation k ↦ k·s mod N with s near N/φ and coprime to N: the first max_points of it are an
  // even, deterministic subsample, and drawing in its order does not favour any part of the image.
  const std::size_t m = std::min(inside.size(), std::max<std::size_t>(1, max_points));
  if (!inside.empty()) {
    const std::size_t count = inside.size();
    std::size_t s = std::max<std::size_t>(1, static_cast<std::size_t>(std::llround(static_cast<double>(count) * 0.6180339887)));
    while (std::gcd(s, count) != 1) ++s;
    const bool colours = display_bgr.type() == CV_8UC3 && display_bgr.cols == image.width && display_bgr.rows == image.height;
    out.rgb.reserve(m);
    out.bgr.reserve(m);
    for (std::size_t k = 0; k < m; ++k) {
      const std::size_t p = inside[static_cast<std::size_t>((static_cast<unsigned __int128>(k) * s) % count)];
      const float* x = &image.rgb[3 * p];
      out.rgb.emplace_back(x[0], x[1], x[2]);
      if (colours) {
        out.bgr.push_back(display_bgr.at<cv::Vec3b>(static_cast<int>(p / static_cast<std::size_t>(image.width)),
                                                    static_cast<int>(p % static_cast<std::size_t>(image.width))));
      } else {
        cv::Vec3b c;
        for (int ch = 0; ch < 3; ++ch)
          c[2 - ch] = cv::saturate_cast<std::uint8_t>(255 * (x[ch] - out.lo) / (out.hi - out.lo));
        out.bgr.push_back(c);
      }
    }
  }
  return out;
}

// ---- The oblique view -------------------------------------------------------------------------------------

namespace {

// The unit cube [0, 1]³ (the shown range scaled) seen obliquely (plot/oblique_cube.h) and placed on the plot.
class Oblique {
 public:
  explicit Oblique(const cv::Rect& area) : placement_(plot::fit_cube(view_, area)) {}
  cv::Point2d at(const Vec3& q) const { return placement_.at(view_, q); }
  double nearness(const Vec3& q) const { return view_.nearness(q); }

 private:
  plot::ObliqueCube view_;
  plot::CubePlacement placement_;
};

// Ticks along the cube edge from corner a to corner b (unit coordinates), for the channel values lo…hi,
// marked on the side away from the cube's centre; labels every tick unless skip_first.
void edge_ticks(cv::Mat& img, const Oblique& view, const Vec3& a, const Vec3& b, const HistogramPoints& points,
                bool skip_first) {
  const cv::Point2d pa = view.at(a), pb = view.at(b), centre = view.at(Vec3::Constant(0.5));
  cv::Point2d d = pb - pa;
  d *= 1.0 / std::max(1e-9, std::hypot(d.x, d.y));
  cv::Point2d normal(d.y, -d.x);
  const cv::Point2d middle = (pa + pb) * 0.5;
  if (normal.dot(middle - centre) < 0) normal = -normal;
  const double range = points.hi - points.lo;
  const std::vector<double> values = plot::multiples_in(points.lo, points.hi, points.step);
  for (std::size_t k = 0; k < values.size(); ++k) {
    const double value = values[k];
    const double t = (value - points.lo) / range;
    const cv::Point2d p = pa + (pb - pa) * t;
    cv::line(img, rounded(p), rounded(p + normal * 5), kInk, 1, cv::LINE_AA);
    if (k == 0 && skip_first) continue;
    const std::string label = tick_label(value, points.step);
    // Far enough out that a long label does not touch the edge, however the edge runs.
    const double half = text_width(label, kTick) / 2.0;
    put_centred(img, label, p + normal * (11 + half * std::abs(normal.x)), kTick, kInk);
  }
}

}  // namespace

cv::Mat oblique_plot(const HistogramPoints& points) {
  cv::Mat img(kPlotHeight, kPlotWidth, CV_8UC3, kWhite);
  put_text(img, "3D colour histogram: the RGB cube, oblique", {10, 20}, kTitle, kInk);
  const Oblique view(cv::Rect(62, 48, kPlotWidth - 62 - 50, kPlotHeight - 48 - 92));
  const double range = points.hi - points.lo;
  auto unit = [&](const Vec3& x) { return ((x.array() - points.lo) / range).matrix().eval(); };

  plot::draw_cube_edges(img, [&](const Vec3& q) { return rounded(view.at(q)); }, [](const plot::CubeEdge&) { return kEdge; });
  draw_dashed(img, view.at(Vec3::Zero()), view.at(Vec3::Ones()), kEdge);
  // The axes from black in their channels' colours, under the points.
  for (int c = 0; c < 3; ++c)
    cv::line(img, rounded(view.at(Vec3::Zero())), rounded(view.at(Vec3::Unit(c))), kChannel[c], 2, cv::LINE_AA);

  // Far points first, so that near ones cover them.
  std::vector<std::size_t> order(points.rgb.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::vector<double> depth(points.rgb.size());
  for (std::size_t i = 0; i < points.rgb.size(); ++i) depth[i] = view.nearness(unit(points.rgb[i]));
  std::stable_sort(order.begin(), order.end(), [&](std::size_t i, std::size_t j) { return depth[i] < depth[j]; });
  const int size = point_size(points.rgb.size());
  for (const std::size_t i : order) draw_point(img, view.at(unit(points.rgb[i])), points.bgr[i], size);

  // Ticks: R and G on the bottom edges from black, B on the left upright edge (at G's far end).
  edge_ticks(img, view, Vec3::Zero(), Vec3::Unit(0), points, false);
  edge_ticks(img, view, Vec3::Zero(), Vec3::Unit(1), points, true);
  edge_ticks(img, view, Vec3::Unit(1), Vec3(0, 1, 1), points, true);
  const cv::Point2d r_end = view.at(Vec3(1.09, 0, 0)), g_end = view.at(Vec3(0, 1.09, 0)), b_end = view.at(Vec3(0, 1, 1.1));
  put_centred(img, "R", r_end + cv::Point2d(6, 0), kTitle, kChannel[0]);
  put_centred(img, "G", g_end + cv::Point2d(-14, 8), kTitle, kChannel[1]);
  put_centred(img, "B", b_end, kTitle, kChannel[2]);
  put_text(img, "R=G=B", rounded(view.at(Vec3(1, 1, 1)) + cv::Point2d(6, 4)), kTick, kSoftInk);

  put_fitted(img, fmt::format("axes: camera R, G, B [{}]", points.units), {10, kPlotHeight - 50}, kLabel, kInk, kPlotWidth - 20);
  put_text(img,
           points.rgb.size() == points.in_range
               ? fmt::format("{} px drawn: every pixel inside the cube", count(points.rgb.size()))
               : fmt::format("{} of the {} px inside the cube drawn (even subsample)", count(points.rgb.size()), count(points.in_range)),
           {10, kPlotHeight - 30}, kTick, kSoftInk);
  if (points.beyond > 0)
    put_text(img,
             points.lamps_beyond == points.beyond
                 ? fmt::format("{} px beyond it, all lamps seen directly", count(points.beyond))
                 : fmt::format("{} px beyond it ({} of them lamps seen directly)", count(points.beyond), count(points.lamps_beyond)),
             {10, kPlotHeight - 12}, kTick, kSoftInk);
  return img;
}

// ---- The projection ---------------------------------------------------------------------------------------

cv::Mat projection_plot(const HistogramPoints& points, const plot::PrincipalPlane& plane) {
  cv::Mat img(kPlotHeight, kPlotWidth, CV_8UC3, kWhite);
  put_text(img, fmt::format("Projection on PC1, PC2 ({:.0f} % of the variance)", 100 * (plane.share[0] + plane.share[1])),
           {10, 20}, kTitle, kInk);
  const cv::Rect area(72, 36, kPlotWidth - 72 - 14, kPlotHeight - 36 - 100);

  // Coordinates along the two axes, black included; one scale for both.
  std::vector<cv::Point2d> xy;
  xy.reserve(points.rgb.size());
  double a0 = 0, a1 = 0, b0 = 0, b1 = 0;
  for (const Vec3& x : points.rgb) {
    const cv::Point2d p(plane.axis[0].dot(x), plane.axis[1].dot(x));
    xy.push_back(p);
    a0 = std::min(a0, p.x), a1 = std::max(a1, p.x), b0 = std::min(b0, p.y), b1 = std::max(b1, p.y);
  }
  const double fallback = points.hi - points.lo;
  const double span_a = a1 - a0 > 0 ? a1 - a0 : fallback, span_b = b1 - b0 > 0 ? b1 - b0 : fallback;
  const double scale = std::min(area.width / span_a, area.height / span_b) / 1.08;
  const double ca = (a0 + a1) / 2, cb = (b0 + b1) / 2;
  const double va0 = ca - area.width / (2 * scale), va1 = ca + area.width / (2 * scale);
  const double vb0 = cb - area.height / (2 * scale), vb1 = cb + area.height / (2 * scale);
  auto to_pixel = [&](const cv::Point2d& p) {
    return cv::Point2d(area.x + (p.x - va0) * scale, area.y + area.height - (p.y - vb0) * scale);
  };

  // Grid and ticks: one step for both axes (the scales are equal).
  const double step = plot::nice_step(std::max(va1 - va0, vb1 - vb0), 5);
  for (const double v : plot::multiples_in(va0, va1, step)) {
    const int x = static_cast<int>(std::lround(to_pixel({v, 0}).x));
    cv::line(img, {x, area.y}, {x, area.y + area.height}, kGrid, 1);
    cv::line(img, {x, area.y + area.height}, {x, area.y + area.height + 5}, kInk, 1);
    put_text(img, tick_label(v, step), {x, area.y + area.height + 20}, kTick, kInk, Align::Centre);
  }
  for (const double v : plot::multiples_in(vb0, vb1, step)) {
    const int y = static_cast<int>(std::lround(to_pixel({0, v}).y));
    cv::line(img, {area.x, y}, {area.x + area.width, y}, kGrid, 1);
    cv::line(img, {area.x - 5, y}, {area.x, y}, kInk, 1);
    put_text(img, tick_label(v, step), {area.x - 8, y + 5}, kTick, kInk, Align::Right);
  }

  std::vector<cv::Point2d> at;
  at.reserve(xy.size());
  for (const cv::Point2d& p : xy) at.push_back(to_pixel(p));
  cv::Mat inner = img(area);
  const int size = point_size(points.rgb.size());
  for (std::size_t i = 0; i < at.size(); ++i)
    draw_point(inner, at[i] - cv::Point2d(area.x, area.y), points.bgr[i], size);
  cv::rectangle(img, area, kInk, 1);

  // Black, and the projected R, G, B directions in the emptiest corner.
  const cv::Point black = rounded(to_pixel({0, 0}));
  cv::drawMarker(img, black, cv::Scalar(0, 0, 0), cv::MARKER_CROSS, 14, 2, cv::LINE_AA);
  const int bw = 92, bh = 104;
  const cv::Rect corners[4] = {{area.x + 2, area.y + 2, bw, bh},
                               {area.x + area.width - bw - 2, area.y + 2, bw, bh},
                               {area.x + 2, area.y + area.height - bh - 2, bw, bh},
                               {area.x + area.width - bw - 2, area.y + area.height - bh - 2, bw, bh}};
  std::size_t best = 0, fewest = points_in(at, corners[0]) + points_in({to_pixel({0, 0})}, corners[0]) * 1000;
  for (std::size_t k = 1; k < 4; ++k) {
    const std::size_t n = points_in(at, corners[k]) + points_in({to_pixel({0, 0})}, corners[k]) * 1000;
    if (n < fewest) best = k, fewest = n;
  }
  const cv::Rect rose = corners[best];
  cv::rectangle(img, rose, kWhite, cv::FILLED);
  cv::rectangle(img, rose, kEdge, 1);
  const cv::Point2d hub(rose.x + rose.width / 2.0, rose.y + 16 + (rose.height - 16) / 2.0);
  static const char* names[3] = {"R", "G", "B"};
  for (int c = 0; c < 3; ++c) {
    const cv::Point2d d(plane.axis[0][c], -plane.axis[1][c]);  // a unit channel vector, projected (y down)
    const cv::Point2d tip = hub + d * 28.0;
    cv::arrowedLine(img, rounded(hub), rounded(tip), kChannel[c], 2, cv::LINE_AA, 0, 0.25);
    const double length = std::hypot(d.x, d.y);
    put_centred(img, names[c], hub + (length > 0.05 ? d * (28.0 + 9 / length) : cv::Point2d(0, 0)), kTick, kChannel[c]);
  }
  put_text(img, "R,G,B axes", {rose.x + 4, rose.y + 12}, 0.36, kSoftInk);

  // Axis names; their unit is the channels'.
  put_fitted(img, "PC1 = " + combination(plane.axis[0]), {area.x + area.width / 2, area.y + area.height + 42}, kLabel, kInk,
             kPlotWidth - 20, Align::Centre);
  put_vertical(img, "PC2 = " + combination(plane.axis[1]), {16, area.y + area.height / 2}, kLabel, kInk);
  put_fitted(img, fmt::format("units: camera R, G, B [{}]", points.units), {10, kPlotHeight - 30}, kLabel, kInk, kPlotWidth - 20);
  put_text(img, "equal scales on both axes; the cross marks black (0, 0, 0)", {10, kPlotHeight - 10}, kTick, kSoftInk);
  return img;
}

}  // namespace ct::series
