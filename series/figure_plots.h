#pragma once
// The figure page's histogram plots (series/figure.h): the whole image's colour histogram as an oblique view
// of the RGB cube and as a projection onto the plane of its two largest principal axes. Points are drawn in
// their display colour (the pixel's colour in camera.png) on white, with ticks, numbers and axis names with
// units. Drawn with OpenCV; also the text helpers the figure's raster images share.

#include <array>
#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "analyzer/image_input.h"

namespace ct::series {

// What the numbers of R, G, B are, in a few words for axis labels ("linear, 1 = white", "linear DN",
// "1 * I^0.45, 1 = white"), from the sensor's chromatrace.units attribute of `exr`; for a file without it,
// "DN" (integer files) or "file values".
std::string channel_units(const std::filesystem::path& exr, const analyzer::AnalysisImage& input);

// The points a histogram plot draws: the whole image (final R, G, B), every pixel inside the cube shown, or a
// deterministic subsample of them when there are more than max_points.
//
// The cube is [lo, hi]³, one range for the three channels. hi is the 99.95th percentile of the pixels'
// brightest channel, leaving out lamps seen directly (pixels whose linear signal is more than half the
// `emission` component, when the file has both layers), rounded up to a whole tick step; lo is 0 unless
// values go below it. A lamp or a rare outlier would otherwise push every surface into a corner.
struct HistogramPoints {
  std::vector<Eigen::Vector3d> rgb;  // in drawing order (a fixed pseudo-random permutation)
  std::vector<cv::Vec3b> bgr;        // each point's display colour
  double lo = 0, hi = 1, step = 0.2;  // the cube and its tick step
  std::size_t pixels = 0;          // the image's pixels
  std::size_t non_finite = 0;      // NaN or infinite: left out
  std::size_t in_range = 0;        // finite pixels inside the cube (drawn, or left out by the subsample)
  std::size_t beyond = 0;          // finite pixels outside the cube: not drawn
  std::size_t lamps_beyond = 0;    // of those, lamps seen directly
  std::string units;               // channel_units
};

HistogramPoints gather_points(const analyzer::AnalysisImage& input, const cv::Mat& display_bgr, std::string units,
                              std::size_t max_points);

// The two largest principal axes of the points (unit vectors; the first oriented so that its components sum
// to ≥ 0, the second so that its largest component is positive) and the share of the variance each holds.
struct PrincipalPlane {
  std::array<Eigen::Vector3d, 2> axis;
  std::array<double, 2> share{0, 0};
};
PrincipalPlane principal_plane(const HistogramPoints& points);

constexpr int kPlotWidth = 430, kPlotHeight = 430;

// 8-bit BGR, kPlotWidth × kPlotHeight: the RGB cube seen obliquely (black at the bottom, the achromatic axis
// upright), ticks on its edges.
cv::Mat oblique_plot(const HistogramPoints& points);
// 8-bit BGR, kPlotWidth × kPlotHeight: the points projected onto the principal plane, equal scales on both
// axes, with the projected R, G, B directions.
cv::Mat projection_plot(const HistogramPoints& points, const PrincipalPlane& plane);

// ---- Text on images (OpenCV's Hershey font draws ASCII only) -----------------------------------------------

// `text` with typographic characters replaced by ASCII (— → -, × → x, ✔ → ok, …) and any other non-ASCII
// character by '?'.
std::string ascii(std::string_view text);

enum class Align { Left, Centre, Right };
// Draws `text` (made ascii) with its baseline at `at.y`; returns its width in pixels.
int put_text(cv::Mat& img, std::string_view text, cv::Point at, double scale, const cv::Scalar& colour,
             Align align = Align::Left, int thickness = 1);
int text_width(std::string_view text, double scale, int thickness = 1);
// Greedy word wrap to lines no wider than `width` pixels.
std::vector<std::string> wrap_text(std::string_view text, int width, double scale, int thickness = 1);
// A tick (✔) or a cross (✗) glyph in a size × size box whose lower-left corner is `at`.
void draw_mark(cv::Mat& img, cv::Point at, int size, bool ok);

// Tick steps of 1, 2 or 5 × 10^k, and their labels.
double nice_step(double span, int intervals);
std::string tick_label(double value, double step);

}  // namespace ct::series
