// SPDX-License-Identifier: Apache-2.0
#pragma once
// The oblique view of the RGB cube that the histogram plots share (analyzer/plots.h, series/figure_plots.h): the
// unit cube [0, 1]³ (the shown range scaled) seen from azimuth 35°, elevation 25°, from above and from black's side:
// black is the lowest corner, white the highest, R runs to the right, G to the left and B up; the nearest corner
// is blue, the farthest yellow. With the cube's corners and edges, its placement on an image and the drawing of
// its edges (OpenCV).

#include <array>
#include <functional>

#include <Eigen/Core>
#include <opencv2/core.hpp>

namespace ct::plot {

class ObliqueCube {
 public:
  static constexpr double kAzimuthDeg = 35, kElevationDeg = 25;
  ObliqueCube();
  // Where q (unit-cube coordinates) is seen: (right, up) from the cube's centre, in edge lengths.
  Eigen::Vector2d project(const Eigen::Vector3d& q) const;
  // How near to the viewer q lies, in edge lengths from the plane through the cube's centre: drawing far points
  // first lets near ones cover them.
  double nearness(const Eigen::Vector3d& q) const;

 private:
  Eigen::Vector3d right_, up_, towards_viewer_;
};

// Corner `bits` of the unit cube: channel c is 1 where bit c is set (0 is black, 7 white).
Eigen::Vector3d cube_corner(int bits);

// An edge of the cube: from corner `from` along `channel` to corner from | 1 << channel.
struct CubeEdge {
  int from = 0, channel = 0;
  int to() const { return from | (1 << channel); }
};
// The 12 edges: from each corner (0 … 7) along each channel it lacks, so the three from black come first.
const std::array<CubeEdge, 12>& cube_edges();

// The view placed on an image: `scale` pixels per edge length, the cube's centre at pixel `centre`, y down.
struct CubePlacement {
  double scale = 1;
  cv::Point2d centre;
  cv::Point2d at(const ObliqueCube& view, const Eigen::Vector3d& q) const;
};
// The largest placement whose projected corners fit inside `area`, centred in it.
CubePlacement fit_cube(const ObliqueCube& view, const cv::Rect& area);

// Draws the 12 edges in cube_edges() order, each an anti-aliased line between the pixels `at` gives its two
// corners (unit-cube coordinates), in `colour(edge)`.
void draw_cube_edges(cv::Mat& img, const std::function<cv::Point(const Eigen::Vector3d&)>& at,
                     const std::function<cv::Scalar(const CubeEdge&)>& colour, int thickness = 1);

}  // namespace ct::plot
