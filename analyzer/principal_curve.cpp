// SPDX-License-Identifier: Apache-2.0
#include "analyzer/principal_curve.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Dense>

namespace ct::analyzer {
namespace {

constexpr int kTerms = 4;

double polynomial(const std::array<double, 4>& c, double s) { return c[0] + s * (c[1] + s * (c[2] + s * c[3])); }

}  // namespace

Vec3 PrincipalCurve::at(double t) const {
  const double half = std::max(1e-300, 0.5 * (t_max - t_min));
  const double s = (t - 0.5 * (t_min + t_max)) / half;
  return mean + t * axes.col(0) + polynomial(u, s) * axes.col(1) + polynomial(v, s) * axes.col(2);
}

PrincipalCurve fit_principal_curve(const std::vector<Vec3>& points, const Moments& moments) {
  PrincipalCurve c;
  c.mean = moments.mean;
  c.axes = moments.axes;
  const std::size_t n = points.size();
  if (n < kTerms + 1) return c;
  std::vector<Vec3> local(n);  // (t, u, v)
  c.t_min = std::numeric_limits<double>::max();
  c.t_max = std::numeric_limits<double>::lowest();
  for (std::size_t i = 0; i < n; ++i) {
    local[i] = c.axes.transpose() * (points[i] - c.mean);
    c.t_min = std::min(c.t_min, local[i][0]);
    c.t_max = std::max(c.t_max, local[i][0]);
  }
  const double mid = 0.5 * (c.t_min + c.t_max), half = std::max(1e-300, 0.5 * (c.t_max - c.t_min));
  // Least squares for both perpendicular coordinates at once, in the scaled variable s ∈ [−1, 1].
  Eigen::MatrixXd basis(n, kTerms), rhs(n, 2);
  for (std::size_t i = 0; i < n; ++i) {
    const double s = (local[i][0] - mid) / half;
    const auto r = static_cast<Eigen::Index>(i);
    basis.row(r) << 1.0, s, s * s, s * s * s;
    rhs.row(r) << local[i][1], local[i][2];
  }
  const Eigen::MatrixXd curve = basis.colPivHouseholderQr().solve(rhs);
  const Eigen::MatrixXd straight = basis.leftCols(2).colPivHouseholderQr().solve(rhs);
  for (int k = 0; k < kTerms; ++k) c.u[k] = curve(k, 0), c.v[k] = curve(k, 1);
  const double n_d = static_cast<double>(n);
  c.curve_rms = std::sqrt((rhs - basis * curve).squaredNorm() / n_d);
  c.straight_rms = std::sqrt((rhs - basis.leftCols(2) * straight).squaredNorm() / n_d);
  c.explained = c.straight_rms > 0 ? 1.0 - std::pow(c.curve_rms / c.straight_rms, 2) : 0.0;

  // Sagitta over chord, sampled along the curve.
  const Vec3 a = c.at(c.t_min), b = c.at(c.t_max);
  const double chord = (b - a).norm();
  if (chord > 0) {
    const Vec3 along = (b - a) / chord;
    double sagitta = 0;
    for (int k = 0; k <= 200; ++k) {
      const Vec3 d = c.at(c.t_min + (c.t_max - c.t_min) * k / 200.0) - a;
      sagitta = std::max(sagitta, (d - d.dot(along) * along).norm());
    }
    c.bend = sagitta / chord;
  }
  // κ = |x′ × x″| / |x′|³ at the middle (s = 0), with derivatives taken in t.
  const Vec3 first = c.axes.col(0) + (c.u[1] * c.axes.col(1) + c.v[1] * c.axes.col(2)) / half;
  const Vec3 second = 2.0 * (c.u[2] * c.axes.col(1) + c.v[2] * c.axes.col(2)) / (half * half);
  c.curvature = first.cross(second).norm() / std::pow(first.norm(), 3);
  return c;
}

}  // namespace ct::analyzer
