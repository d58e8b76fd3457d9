// SPDX-License-Identifier: Apache-2.0
#include "analyzer/highlight_branch.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <Eigen/Eigenvalues>

#include "core/geometry.h"
#include "core/statistics.h"

namespace ct::analyzer {
namespace {

struct Slope {
  double kappa = 0, se = 0;  // y = α + κ x
  bool ok = false;
};

Slope regress(const std::vector<double>& x, const std::vector<double>& y) {
  Slope s;
  const double n = static_cast<double>(x.size());
  if (x.size() < 3) return s;
  double mx = 0, my = 0;
  for (std::size_t i = 0; i < x.size(); ++i) mx += x[i], my += y[i];
  mx /= n, my /= n;
  double sxx = 0, sxy = 0;
  for (std::size_t i = 0; i < x.size(); ++i) sxx += (x[i] - mx) * (x[i] - mx), sxy += (x[i] - mx) * (y[i] - my);
  if (!(sxx > 0)) return s;
  s.kappa = sxy / sxx;
  double residuals = 0;
  for (std::size_t i = 0; i < x.size(); ++i) residuals += std::pow(y[i] - my - s.kappa * (x[i] - mx), 2);
  s.se = std::sqrt(residuals / (n - 2) / sxx);
  s.ok = true;
  return s;
}

// The direction κ·body + e, unit, oriented with a positive component sum.
Vec3 direction_of(double kappa, const Vec3& body, const Vec3& e) {
  const Vec3 v = (kappa * body + e).normalized();
  return v.sum() < 0 ? Vec3(-v) : v;
}

}  // namespace

std::optional<HighlightBranch> highlight_branch(const std::vector<Vec3>& points, const Line& body_line,
                                                const std::vector<std::size_t>& off_body) {
  if (off_body.size() < 10) return std::nullopt;
  const Vec3 body = body_line.direction.normalized();
  // The parts off the body line (about black: the body line of a dichromatic object passes through it), and
  // their principal direction e, oriented towards where they lie.
  std::vector<Vec3> across;
  Mat3 scatter = Mat3::Zero();
  Vec3 sum = Vec3::Zero();
  for (const std::size_t i : off_body) {
    const Vec3& c = points[i];
    across.push_back(c - c.dot(body) * body);
    scatter += across.back() * across.back().transpose();
    sum += across.back();
  }
  const Eigen::SelfAdjointEigenSolver<Mat3> eigen(scatter / static_cast<double>(across.size()));
  Vec3 e = eigen.eigenvectors().col(2).normalized();
  if (e.dot(sum) < 0) e = -e;
  const double major = std::sqrt(std::max(0.0, eigen.eigenvalues()[2])), minor = std::sqrt(std::max(0.0, eigen.eigenvalues()[1]));
  std::vector<double> x, y;
  for (std::size_t k = 0; k < off_body.size(); ++k) {
    x.push_back(across[k].dot(e));
    y.push_back(points[off_body[k]].dot(body));
  }
  const Slope all = regress(x, y);
  if (!all.ok) return std::nullopt;
  // The lower and upper halves of the highlight, by distance from the body line: the median (the nearest rank
  // below, ct::quantile) and what lies below it, and the rest; of an even count of distinct distances, n/2 each.
  const double median = quantile(x, 0.5);
  std::vector<double> xl, yl, xu, yu;
  for (std::size_t k = 0; k < x.size(); ++k) (x[k] <= median ? xl : xu).push_back(x[k]), (x[k] <= median ? yl : yu).push_back(y[k]);
  const Slope lower = regress(xl, yl), upper = regress(xu, yu);
  HighlightBranch b;
  b.direction = direction_of(all.kappa, body, e);
  b.samples = off_body.size();
  // κ = cot φ, φ the angle between the light and the body line: dφ = dκ / (1 + κ²); e tilts out of the plane by
  // about minor / (major √n).
  const double n = static_cast<double>(off_body.size());
  const double from_kappa = all.se / (1 + all.kappa * all.kappa);
  const double from_e = minor / (std::max(major, 1e-300) * std::sqrt(n));
  b.statistical_deg = std::hypot(from_kappa, from_e) * kDegreesPerRadian;
  if (lower.ok && upper.ok) {
    const double c = std::clamp(direction_of(lower.kappa, body, e).dot(direction_of(upper.kappa, body, e)), -1.0, 1.0);
    b.halves_deg = std::acos(c) * kDegreesPerRadian;
  }
  b.uncertainty_deg = std::hypot(b.statistical_deg, b.halves_deg / 2);
  return b;
}

}  // namespace ct::analyzer
