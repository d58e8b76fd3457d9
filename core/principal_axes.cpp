// SPDX-License-Identifier: Apache-2.0
#include "core/principal_axes.h"

#include <algorithm>

#include <Eigen/Eigenvalues>

namespace ct {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;

void principal_axes(const Mat3& symmetric, Vec3& eigenvalues, Mat3& axes) {
  const Eigen::SelfAdjointEigenSolver<Mat3> solver(symmetric);
  // Eigen sorts increasing; reverse to largest first.
  for (int k = 0; k < 3; ++k) {
    eigenvalues[k] = std::max(0.0, solver.eigenvalues()[2 - k]);
    Vec3 v = solver.eigenvectors().col(2 - k);
    Eigen::Index largest = 0;
    v.cwiseAbs().maxCoeff(&largest);
    if (v[largest] < 0) v = -v;
    axes.col(k) = v;
  }
}

PrincipalAxes principal_axes_of(std::span<const Vec3> points, About about, std::span<const std::size_t> subset) {
  PrincipalAxes a;
  const auto each = [&](auto&& f) {
    if (subset.empty())
      for (const Vec3& x : points) f(x);
    else
      for (const std::size_t i : subset) f(points[i]);
  };
  each([&](const Vec3& x) {
    a.mean += x;
    ++a.count;
  });
  if (a.count == 0) return a;
  a.mean /= static_cast<double>(a.count);
  const Vec3 origin = about == About::Mean ? a.mean : Vec3::Zero();
  Mat3 moment = Mat3::Zero();
  each([&](const Vec3& x) { moment += (x - origin) * (x - origin).transpose(); });
  principal_axes(moment / static_cast<double>(a.count), a.values, a.axes);
  return a;
}

}  // namespace ct
