// SPDX-License-Identifier: Apache-2.0
#pragma once
// The plane a histogram is projected onto (series/figure_plots.h, projection_plot): that of the points' two
// largest principal axes about their mean (core/principal_axes.h), oriented for reading.

#include <array>
#include <span>

#include <Eigen/Core>

namespace ct::plot {

// The two largest principal axes (unit vectors; the first oriented so that its components sum to ≥ 0, brighter
// to the right, the second so that its largest-magnitude component is positive) and the share of the variance
// each holds. Fewer than three points, or no spread: the achromatic axis and (1, 0, −1)/√2, with no share.
struct PrincipalPlane {
  std::array<Eigen::Vector3d, 2> axis;
  std::array<double, 2> share{0, 0};
};
PrincipalPlane principal_plane(std::span<const Eigen::Vector3d> points);

}  // namespace ct::plot
