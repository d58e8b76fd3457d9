// SPDX-License-Identifier: Apache-2.0
#pragma once
// The figure page's histogram plots (series/figure.h): the whole image's colour histogram as an oblique view
// of the RGB cube and as a projection onto the plane of its two largest principal axes. Points are drawn in
// their display colour (the pixel's colour in camera.png) on white, with ticks, numbers and axis names with
// units. Drawn with OpenCV and the plotting kit (plot/).

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "analyzer/image_input.h"
#include "plot/principal_plane.h"

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
// values go below it (plot/ticks.h, nice_range). A lamp or a rare outlier would otherwise push every surface into
// a corner.
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

constexpr int kPlotWidth = 430, kPlotHeight = 430;

// 8-bit BGR, kPlotWidth × kPlotHeight: the RGB cube seen obliquely (black at the bottom, the achromatic axis
// upright: plot/oblique_cube.h), ticks on its edges.
cv::Mat oblique_plot(const HistogramPoints& points);
// 8-bit BGR, kPlotWidth × kPlotHeight: the points projected onto their principal plane (plot::principal_plane of
// points.rgb), equal scales on both axes, with the projected R, G, B directions.
cv::Mat projection_plot(const HistogramPoints& points, const plot::PrincipalPlane& plane);

}  // namespace ct::series
