// SPDX-License-Identifier: Apache-2.0
#include "plot/principal_plane.h"

#include "core/principal_axes.h"

namespace ct::plot {

PrincipalPlane principal_plane(std::span<const Eigen::Vector3d> points) {
  PrincipalPlane plane;
  plane.axis = {Eigen::Vector3d(1, 1, 1).normalized(), Eigen::Vector3d(1, 0, -1).normalized()};
  if (points.size() < 3) return plane;
  const PrincipalAxes a = principal_axes_of(points, About::Mean);
  const double total = a.values.sum();
  if (!(total > 0)) return plane;
  Eigen::Vector3d first = a.axes.col(0);
  if (first.sum() < 0) first = -first;
  plane.axis = {first, a.axes.col(1)};
  plane.share = {a.values[0] / total, a.values[1] / total};
  return plane;
}

}  // namespace ct::plot
