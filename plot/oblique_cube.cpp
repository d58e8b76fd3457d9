// SPDX-License-Identifier: Apache-2.0
#include "plot/oblique_cube.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <Eigen/Geometry>
#include <opencv2/imgproc.hpp>

namespace ct::plot {

using Vec3 = Eigen::Vector3d;

ObliqueCube::ObliqueCube() {
  const double az = kAzimuthDeg * std::numbers::pi / 180, el = kElevationDeg * std::numbers::pi / 180;
  // The screen's axes, right and up, for the cube centred at the origin.
  right_ = Vec3(std::cos(az), -std::sin(az), 0);
  up_ = Vec3(std::sin(az) * std::sin(el), std::cos(az) * std::sin(el), std::cos(el));
  // (−sin az cos el, −cos az cos el, sin el): the viewer is above the cube, on black's side of it.
  towards_viewer_ = right_.cross(up_);
}

Eigen::Vector2d ObliqueCube::project(const Vec3& q) const {
  const Vec3 c = q - Vec3::Constant(0.5);
  return {c.dot(right_), c.dot(up_)};
}

double ObliqueCube::nearness(const Vec3& q) const { return (q - Vec3::Constant(0.5)).dot(towards_viewer_); }

Vec3 cube_corner(int bits) { return Vec3(bits & 1 ? 1 : 0, bits & 2 ? 1 : 0, bits & 4 ? 1 : 0); }

const std::array<CubeEdge, 12>& cube_edges() {
  static const std::array<CubeEdge, 12> edges = [] {
    std::array<CubeEdge, 12> e;
    std::size_t k = 0;
    for (int from = 0; from < 8; ++from)
      for (int channel = 0; channel < 3; ++channel)
        if (!(from & (1 << channel))) e[k++] = {from, channel};
    return e;
  }();
  return edges;
}

cv::Point2d CubePlacement::at(const ObliqueCube& view, const Vec3& q) const {
  const Eigen::Vector2d p = view.project(q);
  return centre + cv::Point2d(scale * p.x(), -scale * p.y());
}

CubePlacement fit_cube(const ObliqueCube& view, const cv::Rect& area) {
  double x0 = 1e9, x1 = -1e9, y0 = 1e9, y1 = -1e9;
  for (int bits = 0; bits < 8; ++bits) {
    const Eigen::Vector2d p = view.project(cube_corner(bits));
    x0 = std::min(x0, p.x()), x1 = std::max(x1, p.x());
    y0 = std::min(y0, p.y()), y1 = std::max(y1, p.y());
  }
  CubePlacement placement;
  placement.scale = std::min(area.width / (x1 - x0), area.height / (y1 - y0));
  placement.centre = cv::Point2d(area.x + area.width / 2.0 - placement.scale * (x0 + x1) / 2,
                                 area.y + area.height / 2.0 + placement.scale * (y0 + y1) / 2);
  return placement;
}

void draw_cube_edges(cv::Mat& img, const std::function<cv::Point(const Vec3&)>& at,
                     const std::function<cv::Scalar(const CubeEdge&)>& colour, int thickness) {
  for (const CubeEdge& e : cube_edges())
    cv::line(img, at(cube_corner(e.from)), at(cube_corner(e.to())), colour(e), thickness, cv::LINE_AA);
}

}  // namespace ct::plot
