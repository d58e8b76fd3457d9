// SPDX-License-Identifier: Apache-2.0
#pragma once
// The principal axes of a set of 3-vectors (colours, normals): the eigen-decomposition of their moment matrix,
// about their mean or about the origin. The analyzer's line and plane fits and the plots' principal plane use it.

#include <cstddef>
#include <span>

#include <Eigen/Core>

namespace ct {

// The eigen-decomposition of a symmetric 3×3 matrix, largest eigenvalue first (negative ones, rounding noise,
// set to 0), each eigenvector's sign chosen so that its largest-magnitude component is positive (a stable,
// printable orientation).
void principal_axes(const Eigen::Matrix3d& symmetric, Eigen::Vector3d& eigenvalues, Eigen::Matrix3d& axes);

// The principal axes of a set of points, about their mean (a cluster's own axes: lines and planes anywhere) or
// about the origin, black for colours (the second moments Σ x xᵀ / n: lines and planes through black, the
// dichromatic model's).
enum class About { Mean, Black };
struct PrincipalAxes {
  std::size_t count = 0;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();     // the points' mean (also when taken about black)
  Eigen::Vector3d values = Eigen::Vector3d::Zero();   // eigenvalues of the moment matrix divided by count, largest first
  Eigen::Matrix3d axes = Eigen::Matrix3d::Identity(); // column k: the unit eigenvector of values[k], oriented as principal_axes()
};
// Of every point, or of points[i] for i in `subset` when it is given.
PrincipalAxes principal_axes_of(std::span<const Eigen::Vector3d> points, About about, std::span<const std::size_t> subset = {});

}  // namespace ct
