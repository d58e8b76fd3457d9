#include "analyzer/plots.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/core.h>
#include <opencv2/imgproc.hpp>

#include "core/colour.h"

namespace ct::analyzer {
namespace {

constexpr int kPanel = 320, kMargin = 26, kTitle = 30;
constexpr std::size_t kMaxPoints = 40000;
const cv::Scalar kBackground(28, 28, 28), kFrame(90, 90, 90), kText(225, 225, 225);
const cv::Scalar kBodyColour(255, 255, 255), kHighlightColour(0, 220, 255), kCurveColour(255, 255, 0), kPlaneColour(255, 0, 255);

// Where a colour goes in a panel: panels 0–2 are projections (x channel, y channel), panel 3 the 3D view.
class Frame {
 public:
  explicit Frame(const HistogramSpec& spec) : spec_(spec) {
    const double az = 35 * std::numbers::pi / 180, el = 25 * std::numbers::pi / 180;
    // Screen axes of the oblique view: right and up, for the cube centred at the origin.
    right_ = Vec3(std::cos(az), -std::sin(az), 0);
    up_ = Vec3(std::sin(az) * std::sin(el), std::cos(az) * std::sin(el), std::cos(el));
  }
  Vec3 unit(const Vec3& x) const {
    Vec3 q;
    for (int c = 0; c < 3; ++c) q[c] = (x[c] - spec_.lo[c]) / (spec_.hi[c] - spec_.lo[c]);
    return q;
  }
  cv::Point2f at(const Vec3& x, int panel) const {
    const cv::Point2f origin(static_cast<float>((panel % 2) * kPanel), static_cast<float>(kTitle + (panel / 2) * kPanel));
    const double inner = kPanel - 2 * kMargin;
    const Vec3 q = unit(x);
    if (panel < 3) {
      static constexpr int axes[3][2] = {{0, 1}, {0, 2}, {1, 2}};
      return origin + cv::Point2f(static_cast<float>(kMargin + q[axes[panel][0]] * inner),
                                  static_cast<float>(kPanel - kMargin - q[axes[panel][1]] * inner));
    }
    const Vec3 c = q - Vec3::Constant(0.5);
    const double scale = inner / 1.75;  // the cube's projected diagonal fits the panel
    return origin + cv::Point2f(static_cast<float>(kPanel / 2 + scale * c.dot(right_)),
                                static_cast<float>(kPanel / 2 - scale * c.dot(up_)));
  }

 private:
  HistogramSpec spec_;
  Vec3 right_, up_;
};

void draw_axes(cv::Mat& img, const Frame& frame, const HistogramSpec& spec) {
  static const char* names[3][2] = {{"R", "G"}, {"R", "B"}, {"G", "B"}};
  for (int p = 0; p < 3; ++p) {
    const cv::Point2f o(static_cast<float>((p % 2) * kPanel), static_cast<float>(kTitle + (p / 2) * kPanel));
    cv::rectangle(img, o + cv::Point2f(kMargin, kMargin), o + cv::Point2f(kPanel - kMargin, kPanel - kMargin), kFrame, 1);
    cv::putText(img, names[p][0], o + cv::Point2f(kPanel / 2, kPanel - 7), cv::FONT_HERSHEY_SIMPLEX, 0.45, kText, 1, cv::LINE_AA);
    cv::putText(img, names[p][1], o + cv::Point2f(6, kPanel / 2), cv::FONT_HERSHEY_SIMPLEX, 0.45, kText, 1, cv::LINE_AA);
  }
  const Vec3 lo(spec.lo[0], spec.lo[1], spec.lo[2]), hi(spec.hi[0], spec.hi[1], spec.hi[2]);
  auto corner = [&](int bits) { return Vec3(bits & 1 ? hi[0] : lo[0], bits & 2 ? hi[1] : lo[1], bits & 4 ? hi[2] : lo[2]); };
  for (int a = 0; a < 8; ++a)
    for (int bit = 0; bit < 3; ++bit) {
      const int b = a | (1 << bit);
      if (b == a) continue;
      // Edges from black carry the channel's colour, so the view's orientation reads at a glance.
      const cv::Scalar colour = a == 0 ? cv::Scalar(bit == 2 ? 255 : 60, bit == 1 ? 220 : 60, bit == 0 ? 255 : 60) : kFrame;
      cv::line(img, frame.at(corner(a), 3), frame.at(corner(b), 3), colour, 1, cv::LINE_AA);
    }
  for (int c = 0; c < 3; ++c)
    cv::putText(img, names[c == 2 ? 1 : 0][c == 0 ? 0 : 1], frame.at(corner(1 << c), 3) + cv::Point2f(4, 4), cv::FONT_HERSHEY_SIMPLEX, 0.45,
                kText, 1, cv::LINE_AA);
}

// Drawn into each panel's own view of the image, so that fits reaching past the cube are cut at its edge.
void draw_polyline(cv::Mat& img, const Frame& frame, const std::vector<Vec3>& points, const cv::Scalar& colour, int thickness) {
  for (int p = 0; p < 4; ++p) {
    const cv::Point origin((p % 2) * kPanel, kTitle + (p / 2) * kPanel);
    cv::Mat panel = img(cv::Rect(origin, cv::Size(kPanel, kPanel)));
    const cv::Point2f shift(static_cast<float>(origin.x), static_cast<float>(origin.y));
    for (std::size_t i = 1; i < points.size(); ++i)
      cv::line(panel, frame.at(points[i - 1], p) - shift, frame.at(points[i], p) - shift, colour, thickness, cv::LINE_AA);
  }
}

void draw_fits(cv::Mat& img, const Frame& frame, const ClusterShape& s) {
  // A clipped cluster shows the fits of its pixels off the faces.
  if (!s.unclipped.empty()) return draw_fits(img, frame, s.unclipped.front());
  auto segment = [&](const Line& l, const cv::Scalar& colour) { draw_polyline(img, frame, {l.at(l.t_min), l.at(l.t_max)}, colour, 2); };
  if (s.plane && s.significant_axes >= 2) {
    // The principal plane's patch: ±2σ along the first two axes about the mean.
    const Vec3 m = s.moments.mean, a = 2 * s.sigma[0] * s.moments.axes.col(0), b = 2 * s.sigma[1] * s.moments.axes.col(1);
    draw_polyline(img, frame, {m - a - b, m + a - b, m + a + b, m - a + b, m - a - b}, kPlaneColour, 1);
  }
  if (s.line) segment(*s.line, kBodyColour);
  if (s.two_lines && (s.shape == ShapeClass::L || s.shape == ShapeClass::SkewedT || s.shape == ShapeClass::Fork)) {
    segment(s.two_lines->body, kBodyColour);
    segment(s.two_lines->highlight, kHighlightColour);
    for (int p = 0; p < 4; ++p) cv::circle(img, frame.at(s.two_lines->junction, p), 4, kHighlightColour, 1, cv::LINE_AA);
  } else if (s.body_only && s.shape == ShapeClass::P) {
    segment(s.body_only->line, kBodyColour);
  }
  if (s.curve && (s.shape == ShapeClass::Curved || s.shape == ShapeClass::Gamma)) {
    std::vector<Vec3> points;
    for (int k = 0; k <= 32; ++k) points.push_back(s.curve->at(s.curve->t_min + (s.curve->t_max - s.curve->t_min) * k / 32.0));
    draw_polyline(img, frame, points, kCurveColour, 2);
  }
}

cv::Scalar viridis(double f) {
  static const cv::Mat table = [] {
    cv::Mat ramp(1, 256, CV_8UC1), coloured;
    for (int i = 0; i < 256; ++i) ramp.at<std::uint8_t>(0, i) = static_cast<std::uint8_t>(i);
    cv::applyColorMap(ramp, coloured, cv::COLORMAP_VIRIDIS);
    return coloured;
  }();
  const cv::Vec3b c = table.at<cv::Vec3b>(0, static_cast<int>(std::lround(255 * std::clamp(f, 0.0, 1.0))));
  return cv::Scalar(c[0], c[1], c[2]);
}

// Each projection's own 2D log-density, as an image filling the panel's frame.
void draw_projection_densities(cv::Mat& img, const Histogram3& histogram) {
  const auto p = projections(histogram);
  const int bins = histogram.spec.bins, inner = kPanel - 2 * kMargin;
  for (int k = 0; k < 3; ++k) {
    cv::Mat cell(bins, bins, CV_8UC1, cv::Scalar(0));
    const double top = log_density(p[k].max_count);
    for (int a = 0; a < bins; ++a)
      for (int b = 0; b < bins; ++b) {
        const std::uint32_t c = p[k].counts[static_cast<std::size_t>(a * bins + b)];
        if (c > 0) cell.at<std::uint8_t>(bins - 1 - b, a) = cv::saturate_cast<std::uint8_t>(40 + 215 * log_density(c) / std::max(1e-9, top));
      }
    cv::Mat resized, coloured;
    cv::resize(cell, resized, cv::Size(inner, inner), 0, 0, cv::INTER_NEAREST);
    cv::applyColorMap(resized, coloured, cv::COLORMAP_VIRIDIS);
    coloured.setTo(kBackground, resized == 0);
    coloured.copyTo(img(cv::Rect((k % 2) * kPanel + kMargin, kTitle + (k / 2) * kPanel + kMargin, inner, inner)));
  }
}

}  // namespace

std::string_view colouring_name(PlotColouring colouring) {
  switch (colouring) {
    case PlotColouring::Own: return "own";
    case PlotColouring::Density: return "density";
    case PlotColouring::Component: return "component";
  }
  return "own";
}

cv::Scalar component_colour(std::size_t k) {
  static const cv::Scalar palette[] = {{75, 25, 230}, {75, 180, 60}, {25, 225, 255}, {200, 130, 0}, {48, 130, 245}, {180, 30, 145},
                                       {240, 240, 70}, {230, 50, 240}, {60, 245, 210}, {212, 190, 250}, {128, 128, 0}, {255, 190, 220}};
  return palette[k % std::size(palette)];
}

HistogramSpec display_range(const ImageAnalysis& analysis, const RegionSamples& samples) {
  if (analysis.encoding.integer || samples.size() == 0) return analysis.context.spec;
  return histogram_spec(samples.rgb, analysis.context.spec.bins, 0.0);
}

cv::Mat plot_region(const RgbImage& layer, const ImageAnalysis& analysis, std::size_t region, PlotColouring colouring,
                    const ComponentMap& components) {
  const RegionAnalysis& r = analysis.results[region];
  const RegionSamples samples = gather_samples(layer, analysis.regions[region]);
  const HistogramSpec spec = display_range(analysis, samples);
  const Frame frame(spec);
  cv::Mat img(kTitle + 2 * kPanel, 2 * kPanel, CV_8UC3, kBackground);
  // The density of the region in its display range (its analysis histogram spans the whole image's).
  const Histogram3 histogram = colouring == PlotColouring::Density ? histogram_3d(samples.rgb, spec, analysis.options.threads) : Histogram3{};
  if (colouring == PlotColouring::Density) draw_projection_densities(img, histogram);
  draw_axes(img, frame, spec);

  // Cell counts for density colouring of the 3D view, looked up by cell index.
  const double top = log_density(histogram.max_count);
  auto density_of = [&](const Vec3& x) {
    std::uint32_t index = 0;
    for (int c = 0; c < 3; ++c)
      index = index * static_cast<std::uint32_t>(spec.bins) +
              static_cast<std::uint32_t>(std::clamp(static_cast<int>((x[c] - spec.lo[c]) / (spec.hi[c] - spec.lo[c]) * spec.bins), 0, spec.bins - 1));
    const auto it = std::lower_bound(histogram.cells.begin(), histogram.cells.end(), index,
                                     [](const HistogramCell& cell, std::uint32_t i) { return cell.index < i; });
    return it != histogram.cells.end() && it->index == index ? log_density(it->count) / std::max(1e-9, top) : 0.0;
  };
  const bool encode = !analysis.encoding.integer;  // float values are linear: shown through the sRGB curve
  const std::size_t stride = std::max<std::size_t>(1, (samples.size() + kMaxPoints - 1) / kMaxPoints);
  for (std::size_t i = 0; i < samples.size(); i += stride) {
    const Vec3 x(samples.rgb[i * 3], samples.rgb[i * 3 + 1], samples.rgb[i * 3 + 2]);
    cv::Scalar colour;
    if (colouring == PlotColouring::Own) {
      const Vec3 q = frame.unit(x);
      for (int c = 0; c < 3; ++c) {
        const double v = std::clamp(q[c], 0.0, 1.0);
        colour[2 - c] = 255 * (encode ? srgb_encode(v) : v);
      }
    } else if (colouring == PlotColouring::Density) {
      colour = viridis(0.15 + 0.85 * density_of(x));
    } else {
      const int k = components.dominant.empty() ? -1 : components.dominant[samples.pixels[i]];
      colour = k < 0 ? kFrame : component_colour(static_cast<std::size_t>(k));
    }
    // The density projections are drawn as images already; points go on the 3D view only.
    for (int p = colouring == PlotColouring::Density ? 3 : 0; p < 4; ++p) {
      const cv::Point2f at = frame.at(x, p);
      cv::rectangle(img, cv::Point(cvFloor(at.x), cvFloor(at.y)), cv::Point(cvFloor(at.x) + 1, cvFloor(at.y) + 1), colour, cv::FILLED);
    }
  }
  draw_fits(img, frame, r.shape);

  std::string title = fmt::format("{}  |  {}  |  {} px", r.name, class_name(r.shape.shape), r.shape.samples);
  if (colouring != PlotColouring::Own) title += fmt::format("  |  colour: {}", colouring_name(colouring));
  cv::putText(img, title, cv::Point(8, 20), cv::FONT_HERSHEY_SIMPLEX, 0.5, kText, 1, cv::LINE_AA);
  if (colouring == PlotColouring::Component) {
    // The legend names the components that dominate somewhere in the image (one family's members).
    std::vector<bool> shown(components.names.size(), false);
    for (const int k : components.dominant)
      if (k >= 0) shown[static_cast<std::size_t>(k)] = true;
    int row = 0;
    for (std::size_t k = 0; k < components.names.size(); ++k) {
      if (!shown[k]) continue;
      const cv::Point at(kPanel + 10, kTitle + kPanel + 18 + 16 * row++);
      cv::rectangle(img, at + cv::Point(0, -9), at + cv::Point(9, 0), component_colour(k), cv::FILLED);
      cv::putText(img, components.names[k], at + cv::Point(14, 0), cv::FONT_HERSHEY_SIMPLEX, 0.4, kText, 1, cv::LINE_AA);
    }
  }
  return img;
}

}  // namespace ct::analyzer
