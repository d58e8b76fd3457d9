// SPDX-License-Identifier: Apache-2.0
#include "analyzer/plots.h"

#include <algorithm>
#include <cmath>

#include <fmt/core.h>
#include <opencv2/imgproc.hpp>

#include "core/colour.h"
#include "plot/oblique_cube.h"
#include "plot/ticks.h"

namespace ct::analyzer {
namespace {

constexpr int kPanel = 390, kTitle = 48;
// Each projection's frame: a square `kInner` wide, with room on the left for the vertical axis's tick values,
// above it for that axis's name, below it for the horizontal axis's ticks and name, right of it for a colour scale.
constexpr int kLeft = 58, kTop = 46, kInner = 280;
constexpr int kCaption = 24;  // the 3D view's caption line at the bottom of its panel
constexpr int k3dTicks = 2;   // tick intervals along each edge of the 3D view (its edges are short)
constexpr std::size_t kMaxPoints = 40000;
const cv::Scalar kBackground(28, 28, 28), kFrame(90, 90, 90), kText(225, 225, 225), kDim(160, 160, 160);
const cv::Scalar kBodyColour(255, 255, 255), kHighlightColour(0, 220, 255), kCurveColour(255, 255, 0), kPlaneColour(255, 0, 255);
constexpr int kProjectionAxes[3][2] = {{0, 1}, {0, 2}, {1, 2}};
constexpr const char* kChannel[3] = {"R", "G", "B"};

cv::Point panel_origin(int panel) { return {(panel % 2) * kPanel, kTitle + (panel / 2) * kPanel}; }

// Where overlays of a panel may go: a projection's frame, the 3D view's whole panel.
cv::Rect clip_rect(int panel) {
  const cv::Point o = panel_origin(panel);
  return panel < 3 ? cv::Rect(o.x + kLeft, o.y + kTop, kInner + 1, kInner + 1) : cv::Rect(o.x, o.y, kPanel, kPanel - kCaption);
}

// `align`: −1 left, 0 centred, 1 right of `at`; `boxed`: on a patch of background, readable over points.
void text(cv::Mat& img, const std::string& s, cv::Point at, double scale, const cv::Scalar& colour, int align = -1, bool boxed = false) {
  int baseline = 0;
  const cv::Size size = cv::getTextSize(s, cv::FONT_HERSHEY_SIMPLEX, scale, 1, &baseline);
  if (align == 0) at.x -= size.width / 2;
  if (align == 1) at.x -= size.width;
  if (boxed) cv::rectangle(img, at + cv::Point(-2, baseline), at + cv::Point(size.width + 2, -size.height - 2), kBackground, cv::FILLED);
  cv::putText(img, s, at, cv::FONT_HERSHEY_SIMPLEX, scale, colour, 1, cv::LINE_AA);
}

// Where a colour goes in a panel: panels 0–2 are projections (x channel, y channel), panel 3 the oblique view of
// the cube (plot/oblique_cube.h). Values beyond the range (a robust HDR range's outliers) are drawn at its edge,
// as the histogram counts them.
class Frame {
 public:
  explicit Frame(const HistogramSpec& spec) : spec_(spec) {}
  Vec3 unit(const Vec3& x) const {
    Vec3 q;
    for (int c = 0; c < 3; ++c) q[c] = (x[c] - spec_.lo[c]) / (spec_.hi[c] - spec_.lo[c]);
    return q;
  }
  // `clamp`: points are held inside the range; fits are not (they are cut at the panel's edge instead).
  cv::Point2f at(const Vec3& x, int panel, bool clamp = false) const {
    Vec3 q = unit(x);
    if (clamp) q = q.cwiseMax(0.0).cwiseMin(1.0);
    return at_unit(q, panel);
  }
  // A point given in unit-cube coordinates (the range scaled to [0, 1]³).
  cv::Point2f at_unit(const Vec3& q, int panel) const {
    const cv::Point o = panel_origin(panel);
    const cv::Point2f origin(static_cast<float>(o.x), static_cast<float>(o.y));
    if (panel < 3) {
      return origin + cv::Point2f(static_cast<float>(kLeft + q[kProjectionAxes[panel][0]] * kInner),
                                  static_cast<float>(kTop + kInner - q[kProjectionAxes[panel][1]] * kInner));
    }
    const Eigen::Vector2d p = view_.project(q);
    const double scale = kInner / 1.75;  // the cube's projected diagonal fits the panel
    return origin + cv::Point2f(static_cast<float>(kPanel / 2 + scale * p.x()), static_cast<float>(kPanel / 2 + 8 - scale * p.y()));
  }

 private:
  HistogramSpec spec_;
  plot::ObliqueCube view_;
};

// Tick values and axis names with their unit on every projection, ticks along the three edges from black in the
// 3D view, and the channel colours on those edges so that the view's orientation reads at a glance.
void draw_axes(cv::Mat& img, const Frame& frame, const HistogramSpec& spec, const std::string& unit) {
  for (int p = 0; p < 3; ++p) {
    const cv::Point o = panel_origin(p);
    const int x0 = o.x + kLeft, y0 = o.y + kTop, x1 = x0 + kInner, y1 = y0 + kInner;
    cv::rectangle(img, cv::Point(x0, y0), cv::Point(x1, y1), kFrame, 1);
    for (int axis = 0; axis < 2; ++axis) {
      const int c = kProjectionAxes[p][axis];
      const plot::Ticks ticks = plot::linear_ticks(spec.lo[c], spec.hi[c]);
      for (const double t : ticks.values) {
        const double f = (t - spec.lo[c]) / (spec.hi[c] - spec.lo[c]);
        const std::string label = ticks.label(t);
        if (axis == 0) {
          const int x = x0 + static_cast<int>(std::lround(f * kInner));
          cv::line(img, cv::Point(x, y1), cv::Point(x, y1 + 4), kDim, 1);
          text(img, label, cv::Point(x, y1 + 17), 0.36, kDim, 0);
        } else {
          const int y = y1 - static_cast<int>(std::lround(f * kInner));
          cv::line(img, cv::Point(x0 - 4, y), cv::Point(x0, y), kDim, 1);
          text(img, label, cv::Point(x0 - 6, y + 4), 0.36, kDim, 1);
        }
      }
    }
    text(img, fmt::format("{} ({})", kChannel[kProjectionAxes[p][0]], unit), cv::Point(x0 + kInner / 2, y1 + 36), 0.42, kText, 0);
    text(img, fmt::format("{} ({})", kChannel[kProjectionAxes[p][1]], unit), cv::Point(o.x + 8, y0 - 10), 0.42, kText);
  }
  // The cube's edges in the 3D view, those from black in their channels' colours.
  const cv::Scalar from_black[3] = {cv::Scalar(60, 60, 255), cv::Scalar(60, 220, 60), cv::Scalar(255, 60, 60)};
  plot::draw_cube_edges(
      img, [&](const Vec3& q) { return cv::Point(frame.at_unit(q, 3)); },
      [&](const plot::CubeEdge& e) { return e.from == 0 ? from_black[e.channel] : kFrame; });
}

// The 3D view's tick values and axis names, drawn over the points.
void draw_3d_labels(cv::Mat& img, const Frame& frame, const HistogramSpec& spec, const std::string& unit) {
  const Vec3 lo(spec.lo[0], spec.lo[1], spec.lo[2]), hi(spec.hi[0], spec.hi[1], spec.hi[2]);
  const cv::Point2f centre = frame.at(0.5 * (lo + hi), 3);
  for (int c = 0; c < 3; ++c) {
    const plot::Ticks ticks = plot::linear_ticks(lo[c], hi[c], k3dTicks);
    for (const double t : ticks.values) {
      // Black's own value is written once, at the red edge.
      if (c > 0 && t - lo[c] < 0.08 * (hi[c] - lo[c])) continue;
      Vec3 x = lo;
      x[c] = t;
      const cv::Point2f at = frame.at(x, 3), away = at - centre;
      const cv::Point2f out = away * (1.0f / std::max(1.0f, std::hypot(away.x, away.y)));
      cv::line(img, at, at + 4 * out, kDim, 1, cv::LINE_AA);
      const cv::Point2f label = at + 16 * out;
      text(img, ticks.label(t), cv::Point(cvRound(label.x), cvRound(label.y) + 4), 0.33, kDim, 0, true);
    }
    const cv::Point2f end = frame.at_unit(plot::cube_corner(1 << c), 3), away = end - centre;
    const cv::Point2f name = end + away * (34.0f / std::max(1.0f, std::hypot(away.x, away.y)));
    text(img, kChannel[c], cv::Point(cvRound(name.x), cvRound(name.y) + 4), 0.5, kText, 0, true);
  }
  const cv::Point o = panel_origin(3);
  text(img, fmt::format("3D view; axes: {}", unit), cv::Point(o.x + kPanel / 2, o.y + kPanel - 8), 0.38, kDim, 0);
}

// Drawn into each panel's own view of the image (clip_rect), so that fits reaching past the range are cut at a
// projection's frame, or the 3D view's panel.
void draw_polyline(cv::Mat& img, const Frame& frame, const std::vector<Vec3>& points, const cv::Scalar& colour, int thickness) {
  for (int p = 0; p < 4; ++p) {
    const cv::Rect clip = clip_rect(p);
    cv::Mat panel = img(clip);
    const cv::Point2f shift(static_cast<float>(clip.x), static_cast<float>(clip.y));
    for (std::size_t i = 1; i < points.size(); ++i)
      cv::line(panel, frame.at(points[i - 1], p) - shift, frame.at(points[i], p) - shift, colour, thickness, cv::LINE_AA);
  }
}

void draw_circle(cv::Mat& img, const Frame& frame, const Vec3& x, const cv::Scalar& colour) {
  for (int p = 0; p < 4; ++p) {
    const cv::Rect clip = clip_rect(p);
    cv::Mat panel = img(clip);
    cv::circle(panel, frame.at(x, p) - cv::Point2f(static_cast<float>(clip.x), static_cast<float>(clip.y)), 4, colour, 1, cv::LINE_AA);
  }
}

void draw_fits(cv::Mat& img, const Frame& frame, const ClusterShape& s) {
  // A clipped cluster shows the fits of its pixels off the faces.
  if (&off_the_faces(s) != &s) return draw_fits(img, frame, off_the_faces(s));
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
    draw_circle(img, frame, s.two_lines->junction, kHighlightColour);
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

// The colour-map index (0–255) of a cell whose log_density is `d` when the panel's largest is `top`: 40 for
// none, 255 for the largest.
double density_index(double d, double top) { return 40 + 215 * d / std::max(1e-9, top); }

std::string count_label(double count) {
  if (count < 1e4) return fmt::format("{:.0f}", count);
  return count < 1e6 ? fmt::format("{:.0f}k", count / 1e3) : fmt::format("{:.1f}M", count / 1e6);
}

// The scale of a density panel: the colour of 1 … max_count pixels per cell, on log10(1 + count) as drawn.
void draw_colour_bar(cv::Mat& img, cv::Point at, int height, std::uint32_t max_count) {
  const double top = log_density(max_count), bottom = log_density(1);
  auto y_of = [&](double d) { return at.y + height - 1 - static_cast<int>(std::lround((d - bottom) / std::max(1e-9, top - bottom) * (height - 1))); };
  for (int y = 0; y < height; ++y) {
    const double d = top > bottom ? bottom + (top - bottom) * (height - 1 - y) / std::max(1, height - 1) : top;
    cv::line(img, cv::Point(at.x, at.y + y), cv::Point(at.x + 9, at.y + y), viridis(density_index(d, top) / 255), 1);
  }
  cv::rectangle(img, at, at + cv::Point(9, height - 1), kFrame, 1);
  text(img, "px/cell", at + cv::Point(-4, -8), 0.32, kDim);
  const int top_y = y_of(top);
  text(img, count_label(max_count), cv::Point(at.x + 12, top_y + 4), 0.32, kDim);
  for (double c = 1; c < max_count; c *= 10) {
    const int y = y_of(log_density(static_cast<std::uint32_t>(c)));
    if (y - top_y < 12) break;
    text(img, count_label(c), cv::Point(at.x + 12, y + 4), 0.32, kDim);
  }
}

// Each projection's own 2D log-density, as an image filling the panel's frame, with its colour scale.
void draw_projection_densities(cv::Mat& img, const Histogram3& histogram) {
  const auto p = projections(histogram);
  const int bins = histogram.spec.bins;
  for (int k = 0; k < 3; ++k) {
    cv::Mat cell(bins, bins, CV_8UC1, cv::Scalar(0));
    const double top = log_density(p[k].max_count);
    for (int a = 0; a < bins; ++a)
      for (int b = 0; b < bins; ++b) {
        const std::uint32_t c = p[k].counts[static_cast<std::size_t>(a * bins + b)];
        if (c > 0) cell.at<std::uint8_t>(bins - 1 - b, a) = cv::saturate_cast<std::uint8_t>(density_index(log_density(c), top));
      }
    cv::Mat resized, coloured;
    cv::resize(cell, resized, cv::Size(kInner, kInner), 0, 0, cv::INTER_NEAREST);
    cv::applyColorMap(resized, coloured, cv::COLORMAP_VIRIDIS);
    coloured.setTo(kBackground, resized == 0);
    const cv::Point o = panel_origin(k);
    coloured.copyTo(img(cv::Rect(o.x + kLeft, o.y + kTop, kInner, kInner)));
    draw_colour_bar(img, cv::Point(o.x + kLeft + kInner + 8, o.y + kTop), kInner, std::max<std::uint32_t>(1, p[k].max_count));
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

ValueUnit value_unit(const ImageAnalysis& a) {
  if (a.layer != "final")
    return {"linear camera value", fmt::format("the {} layer: linear camera signal, in the file's units", a.layer)};
  const ImageEncoding& e = a.encoding;
  const bool encoded = e.curve && !e.curve->linear();
  const std::string black = e.black_subtracted ? ", black level subtracted" : "";
  if (e.integer) {
    if (encoded)
      return {fmt::format("{}-bit code, {}-encoded", e.bits, e.curve->srgb ? "sRGB" : "gamma"),
              fmt::format("{}-bit codes as stored (0 to {:g}), encoded by {}: not proportional to light{}", e.bits, e.full_scale,
                          e.curve->describe(), black)};
    return {fmt::format("{}-bit code, linear", e.bits),
            fmt::format("{}-bit codes as stored (0 to {:g}), linear camera values (proportional to light){}", e.bits, e.full_scale, black)};
  }
  if (encoded)
    return {"encoded value", fmt::format("values as stored, encoded by {}: not proportional to light{}", e.curve->describe(), black)};
  return {"linear value", fmt::format("linear camera values in the file's units (proportional to light){}", black)};
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
  const ValueUnit unit = value_unit(analysis);
  draw_axes(img, frame, spec, unit.axis);

  // Cell counts for density colouring of the 3D view, looked up by cell index.
  const double top = log_density(histogram.max_count);
  auto density_of = [&](const Vec3& x) {
    std::uint32_t index = 0;
    for (int c = 0; c < 3; ++c)
      index = index * static_cast<std::uint32_t>(spec.bins) +
              static_cast<std::uint32_t>(std::clamp(static_cast<int>((x[c] - spec.lo[c]) / (spec.hi[c] - spec.lo[c]) * spec.bins), 0, spec.bins - 1));
    const auto it = std::lower_bound(histogram.cells.begin(), histogram.cells.end(), index,
                                     [](const HistogramCell& cell, std::uint32_t i) { return cell.index < i; });
    return it != histogram.cells.end() && it->index == index ? log_density(it->count) : 0.0;
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
      colour = viridis(density_index(density_of(x), top) / 255);
    } else {
      const int k = components.dominant.empty() ? -1 : components.dominant[samples.pixels[i]];
      colour = k < 0 ? kFrame : component_colour(static_cast<std::size_t>(k));
    }
    // The density projections are drawn as images already; points go on the 3D view only.
    for (int p = colouring == PlotColouring::Density ? 3 : 0; p < 4; ++p) {
      const cv::Point2f at = frame.at(x, p, true);
      cv::rectangle(img, cv::Point(cvFloor(at.x), cvFloor(at.y)), cv::Point(cvFloor(at.x) + 1, cvFloor(at.y) + 1), colour, cv::FILLED);
    }
  }
  draw_fits(img, frame, r.shape);
  draw_3d_labels(img, frame, spec, unit.axis);

  if (colouring == PlotColouring::Density)  // the 3D view's points: the density of their 3D cell
    draw_colour_bar(img, panel_origin(3) + cv::Point(kPanel - 44, 70), 200, std::max<std::uint32_t>(1, histogram.max_count));

  std::string title = fmt::format("{}  |  {}  |  {} px", r.name, class_name(r.shape.shape), r.shape.samples);
  if (colouring == PlotColouring::Density) title += "  |  colour: pixels per histogram cell (log scale)";
  if (colouring == PlotColouring::Component) title += "  |  colour: dominant light-path component";
  text(img, title, cv::Point(8, 20), 0.5, kText);
  std::string subtitle = "axes: " + unit.description;
  if (spec.robust) subtitle += fmt::format("; values beyond {:.4g} drawn at the edge", spec.hi[0]);
  text(img, subtitle, cv::Point(8, 40), 0.38, kDim);
  if (colouring == PlotColouring::Component) {
    // The legend names the components that dominate somewhere in the image (one family's members).
    std::vector<bool> shown(components.names.size(), false);
    for (const int k : components.dominant)
      if (k >= 0) shown[static_cast<std::size_t>(k)] = true;
    int row = 0;
    for (std::size_t k = 0; k < components.names.size(); ++k) {
      if (!shown[k]) continue;
      const cv::Point at(kPanel + 10, kTitle + kPanel + 30 + 16 * row++);
      cv::rectangle(img, at + cv::Point(0, -9), at + cv::Point(9, 0), component_colour(k), cv::FILLED);
      cv::putText(img, components.names[k], at + cv::Point(14, 0), cv::FONT_HERSHEY_SIMPLEX, 0.4, kText, 1, cv::LINE_AA);
    }
  }
  return img;
}

}  // namespace ct::analyzer
