#include "series/figure_plots.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <numbers>
#include <numeric>

#include <Eigen/Eigenvalues>
#include <OpenImageIO/imageio.h>
#include <fmt/core.h>
#include <opencv2/imgproc.hpp>

#include "core/json_input.h"
#include "series/preview.h"

namespace ct::series {
namespace {

using Vec3 = Eigen::Vector3d;

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
  const std::string s = ascii(text);
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

// ---- Text ---------------------------------------------------------------------------------------------------

std::string ascii(std::string_view text) {
  static const std::pair<std::string_view, std::string_view> replacements[] = {
      {"\u2014", "-"}, {"\u2013", "-"}, {"\u2212", "-"}, {"\u00d7", "x"},  {"\u2192", "->"}, {"\u2018", "'"},
      {"\u2019", "'"}, {"\u201c", "\""}, {"\u201d", "\""}, {"\u2026", "..."}, {"\u2714", "ok"}, {"\u2717", "x"},
      {"\u00b3", "^3"}, {"\u00b2", "^2"}, {"\u00b0", " deg"}, {"\u03b3", "gamma"}, {"\u2265", ">="}, {"\u2264", "<="},
      {"\u00e9", "e"}, {"\u00a0", " "}, {"\u2009", " "}, {"\u202f", " "}};
  std::string out;
  for (std::size_t i = 0; i < text.size();) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    if (c < 0x80) {
      out += static_cast<char>(c);
      ++i;
      continue;
    }
    bool replaced = false;
    for (const auto& [from, to] : replacements)
      if (text.substr(i, from.size()) == from) {
        out += to;
        i += from.size();
        replaced = true;
        break;
      }
    if (replaced) continue;
    // Any other character: one '?' for its whole UTF-8 sequence.
    out += '?';
    ++i;
    while (i < text.size() && (static_cast<unsigned char>(text[i]) & 0xC0) == 0x80) ++i;
  }
  return out;
}

namespace {

// Text split into runs; an exponent ("^0.45", "^-2") is a raised run, as the font has no usable caret.
struct Run {
  std::string text;
  bool raised = false;
};

std::vector<Run> runs_of(std::string_view text) {
  const std::string s = ascii(text);
  std::vector<Run> runs(1);
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s[i] == '^' && i + 1 < s.size() && (std::isdigit(static_cast<unsigned char>(s[i + 1])) || s[i + 1] == '-' || s[i + 1] == '.')) {
      Run exponent{"", true};
      std::size_t j = i + 1;
      while (j < s.size() && (std::isdigit(static_cast<unsigned char>(s[j])) || s[j] == '.' || (j == i + 1 && s[j] == '-'))) exponent.text += s[j++];
      runs.push_back(std::move(exponent));
      runs.push_back({});
      i = j - 1;
      continue;
    }
    runs.back().text += s[i];
  }
  return runs;
}

constexpr double kRaisedScale = 0.72;

}  // namespace

int text_width(std::string_view text, double scale, int thickness) {
  int width = 0, baseline = 0;
  for (const Run& run : runs_of(text))
    if (!run.text.empty())
      width += cv::getTextSize(run.text, kFont, run.raised ? scale * kRaisedScale : scale, thickness, &baseline).width + (run.raised ? 1 : 0);
  return width;
}

int put_text(cv::Mat& img, std::string_view text, cv::Point at, double scale, const cv::Scalar& colour, Align align,
             int thickness) {
  const int width = text_width(text, scale, thickness);
  if (align == Align::Centre) at.x -= width / 2;
  if (align == Align::Right) at.x -= width;
  int baseline = 0;
  const int raise = static_cast<int>(std::lround(cv::getTextSize("0", kFont, scale, thickness, &baseline).height * 0.45));
  for (const Run& run : runs_of(text)) {
    if (run.text.empty()) continue;
    const double s = run.raised ? scale * kRaisedScale : scale;
    cv::putText(img, run.text, at - cv::Point(0, run.raised ? raise : 0), kFont, s, colour, thickness, cv::LINE_AA);
    at.x += cv::getTextSize(run.text, kFont, s, thickness, &baseline).width + (run.raised ? 1 : 0);
  }
  return width;
}

std::vector<std::string> wrap_text(std::string_view text, int width, double scale, int thickness) {
  std::vector<std::string> lines;
  std::string line;
  std::size_t i = 0;
  while (i < text.size()) {
    const std::size_t space = std::min(text.find(' ', i), text.size());
    const std::string word(text.substr(i, space - i));
    i = space + 1;
    if (word.empty()) continue;
    const std::string candidate = line.empty() ? word : line + " " + word;
    if (!line.empty() && text_width(candidate, scale, thickness) > width) {
      lines.push_back(line);
      line = word;
    } else {
      line = candidate;
    }
  }
  if (!line.empty()) lines.push_back(line);
  return lines;
}

void draw_mark(cv::Mat& img, cv::Point at, int size, bool ok) {
  if (ok) {
    const cv::Scalar green(40, 140, 30);
    cv::line(img, at + cv::Point(1, -size / 2), at + cv::Point(size / 3, -1), green, 2, cv::LINE_AA);
    cv::line(img, at + cv::Point(size / 3, -1), at + cv::Point(size, -size), green, 2, cv::LINE_AA);
  } else {
    const cv::Scalar red(30, 30, 200);
    cv::line(img, at + cv::Point(1, -size + 1), at + cv::Point(size - 1, -1), red, 2, cv::LINE_AA);
    cv::line(img, at + cv::Point(1, -1), at + cv::Point(size - 1, -size + 1), red, 2, cv::LINE_AA);
  }
}

double nice_step(double span, int intervals) {
  if (!(span > 0) || !std::isfinite(span)) return 1;
  const double raw = span / std::max(1, intervals);
  const double magnitude = std::pow(10.0, std::floor(std::log10(raw)));
  const double norm = raw / magnitude;
  return magnitude * (norm < 1.5 ? 1 : norm < 3 ? 2 : norm < 7 ? 5 : 10);
}

std::string tick_label(double value, double step) {
  const int decimals = std::max(0, -static_cast<int>(std::floor(std::log10(step) + 1e-9)));
  if (std::abs(value) < step * 1e-6) value = 0;
  return fmt::format("{:.{}f}", value, decimals);
}

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
  const double span = data_hi > data_lo ? data_hi - data_lo : 1.0;
  out.step = nice_step(span, 4);
  out.lo = std::floor(data_lo / out.step + 1e-6) * out.step;
  out.hi = std::max(out.lo + out.step, std::ceil((data_lo + span) / out.step - 1e-6) * out.step);

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

PrincipalPlane principal_plane(const HistogramPoints& points) {
  PrincipalPlane plane;
  plane.axis = {Vec3(1, 1, 1).normalized(), Vec3(1, 0, -1).normalized()};
  if (points.rgb.size() < 3) return plane;
  Vec3 mean = Vec3::Zero();
  for (const Vec3& x : points.rgb) mean += x;
  mean /= static_cast<double>(points.rgb.size());
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (const Vec3& x : points.rgb) covariance += (x - mean) * (x - mean).transpose();
  covariance /= static_cast<double>(points.rgb.size());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance);
  const Vec3 values = solver.eigenvalues();  // ascending
  const double total = values.sum();
  if (!(total > 0)) return plane;
  Vec3 first = solver.eigenvectors().col(2), second = solver.eigenvectors().col(1);
  if (first.sum() < 0) first = -first;
  Eigen::Index largest = 0;
  second.cwiseAbs().maxCoeff(&largest);
  if (second[largest] < 0) second = -second;
  plane.axis = {first, second};
  plane.share = {values[2] / total, values[1] / total};
  return plane;
}

// ---- The oblique view -------------------------------------------------------------------------------------

namespace {

// The unit cube [0, 1]³ (the shown range scaled) seen from azimuth 35°, elevation 25°, as the analyzer's plots:
// black is the lowest corner, the achromatic axis upright, R to the right, G to the left, B up.
class Oblique {
 public:
  Oblique(const cv::Rect& area) {
    const double az = 35 * std::numbers::pi / 180, el = 25 * std::numbers::pi / 180;
    right_ = Vec3(std::cos(az), -std::sin(az), 0);
    up_ = Vec3(std::sin(az) * std::sin(el), std::cos(az) * std::sin(el), std::cos(el));
    towards_viewer_ = right_.cross(up_);
    if (towards_viewer_.dot(Vec3(-0.5, -0.5, 0)) < 0) towards_viewer_ = -towards_viewer_;  // black is nearest
    double x0 = 1e9, x1 = -1e9, y0 = 1e9, y1 = -1e9;
    for (int bits = 0; bits < 8; ++bits) {
      const Vec3 c = corner(bits) - Vec3::Constant(0.5);
      x0 = std::min(x0, c.dot(right_)), x1 = std::max(x1, c.dot(right_));
      y0 = std::min(y0, c.dot(up_)), y1 = std::max(y1, c.dot(up_));
    }
    scale_ = std::min(area.width / (x1 - x0), area.height / (y1 - y0));
    origin_ = cv::Point2d(area.x + area.width / 2.0 - scale_ * (x0 + x1) / 2, area.y + area.height / 2.0 + scale_ * (y0 + y1) / 2);
  }
  static Vec3 corner(int bits) { return Vec3(bits & 1 ? 1 : 0, bits & 2 ? 1 : 0, bits & 4 ? 1 : 0); }
  cv::Point2d at(const Vec3& q) const {
    const Vec3 c = q - Vec3::Constant(0.5);
    return origin_ + cv::Point2d(scale_ * c.dot(right_), -scale_ * c.dot(up_));
  }
  double nearness(const Vec3& q) const { return (q - Vec3::Constant(0.5)).dot(towards_viewer_); }

 private:
  Vec3 right_, up_, towards_viewer_;
  double scale_ = 1;
  cv::Point2d origin_;
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
  for (int k = 0;; ++k) {
    const double value = points.lo + k * points.step;
    if (value > points.hi + 1e-9 * range) break;
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

  for (int a = 0; a < 8; ++a)
    for (int bit = 0; bit < 3; ++bit) {
      const int b = a | (1 << bit);
      if (b != a) cv::line(img, rounded(view.at(Oblique::corner(a))), rounded(view.at(Oblique::corner(b))), kEdge, 1, cv::LINE_AA);
    }
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

cv::Mat projection_plot(const HistogramPoints& points, const PrincipalPlane& plane) {
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
  const double step = nice_step(std::max(va1 - va0, vb1 - vb0), 5);
  for (double v = std::ceil(va0 / step) * step; v <= va1 + 1e-9 * step; v += step) {
    const int x = static_cast<int>(std::lround(to_pixel({v, 0}).x));
    cv::line(img, {x, area.y}, {x, area.y + area.height}, kGrid, 1);
    cv::line(img, {x, area.y + area.height}, {x, area.y + area.height + 5}, kInk, 1);
    put_text(img, tick_label(v, step), {x, area.y + area.height + 20}, kTick, kInk, Align::Centre);
  }
  for (double v = std::ceil(vb0 / step) * step; v <= vb1 + 1e-9 * step; v += step) {
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
