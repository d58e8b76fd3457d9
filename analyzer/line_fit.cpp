// SPDX-License-Identifier: Apache-2.0
#include "analyzer/line_fit.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>

#include "core/random.h"

namespace ct::analyzer {
namespace {

constexpr int kIterations = 400;
constexpr int kRefinements = 4;

std::vector<std::size_t> within(const std::vector<Vec3>& points, const std::vector<std::size_t>& candidates,
                                const Line& line, double distance) {
  std::vector<std::size_t> in;
  for (const std::size_t i : candidates)
    if (line.distance(points[i]) <= distance) in.push_back(i);
  return in;
}

}  // namespace

Line fit_line(const std::vector<Vec3>& points, const std::vector<std::size_t>& subset) {
  Line line;
  line.inliers = subset.size();
  if (subset.empty()) return line;
  const PrincipalAxes a = principal_axes_of(points, About::Mean, subset);
  line.point = a.mean;
  line.direction = a.axes.col(0);
  if (line.direction.sum() < 0) line.direction = -line.direction;
  line.t_min = std::numeric_limits<double>::max();
  line.t_max = std::numeric_limits<double>::lowest();
  double squares = 0;
  for (const std::size_t i : subset) {
    const double t = line.position(points[i]);
    line.t_min = std::min(line.t_min, t);
    line.t_max = std::max(line.t_max, t);
    squares += std::pow(line.distance(points[i]), 2);
  }
  line.rms = std::sqrt(squares / static_cast<double>(subset.size()));
  return line;
}

std::optional<LineSearch> find_line(const std::vector<Vec3>& points, const std::vector<std::size_t>& candidates,
                                    double max_distance, double min_distance, std::uint64_t seed) {
  if (candidates.size() < 2) return std::nullopt;
  Random random(seed, candidates.size());
  const auto pick = [&] {
    return candidates[std::min(candidates.size() - 1, static_cast<std::size_t>(random.uniform() * static_cast<double>(candidates.size())))];
  };
  // The candidates gathered once, coordinate by coordinate in single precision, so that counting a trial's
  // inliers is one vectorised pass over contiguous arrays. A point x is within max_distance of the line through
  // a along the unit u when |(x − a) × u|² ≤ max_distance² (the cross product has no cancellation, so single
  // precision holds it to about 1e-7 of the distance).
  const std::size_t n = candidates.size();
  std::vector<float> xs(n), ys(n), zs(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3& p = points[candidates[i]];
    xs[i] = static_cast<float>(p[0]), ys[i] = static_cast<float>(p[1]), zs[i] = static_cast<float>(p[2]);
  }
  const float limit = static_cast<float>(max_distance * max_distance);
  constexpr std::size_t kBlock = 4096;  // a trial stops when its remaining points cannot beat the best
  std::size_t best_count = 0;
  Line best;
  for (int k = 0; k < kIterations; ++k) {
    const Vec3& a = points[pick()];
    const Vec3& b = points[pick()];
    const Vec3 d = b - a;
    if (d.norm() <= max_distance) continue;  // too close to fix a direction
    const Vec3 u = d.normalized();
    const float ax = static_cast<float>(a[0]), ay = static_cast<float>(a[1]), az = static_cast<float>(a[2]);
    const float ux = static_cast<float>(u[0]), uy = static_cast<float>(u[1]), uz = static_cast<float>(u[2]);
    std::size_t count = 0;
    for (std::size_t start = 0; start < n && count + (n - start) > best_count; start += kBlock) {
      const std::size_t end = std::min(n, start + kBlock);
      std::int32_t in = 0;
      for (std::size_t i = start; i < end; ++i) {
        const float vx = xs[i] - ax, vy = ys[i] - ay, vz = zs[i] - az;
        const float cx = vy * uz - vz * uy, cy = vz * ux - vx * uz, cz = vx * uy - vy * ux;
        in += (cx * cx + cy * cy + cz * cz <= limit) ? 1 : 0;
      }
      count += static_cast<std::size_t>(in);
    }
    if (count > best_count) {
      best_count = count;
      best.point = a;
      best.direction = u;
    }
  }
  if (best_count < 2) return std::nullopt;
  LineSearch result;
  result.inliers = within(points, candidates, best, max_distance);
  double distance = max_distance;
  for (int r = 0; r < kRefinements && result.inliers.size() >= 2; ++r) {
    result.line = fit_line(points, result.inliers);
    distance = std::clamp(3.0 * result.line.rms, min_distance, distance);
    std::vector<std::size_t> narrowed = within(points, candidates, result.line, distance);
    if (narrowed.size() < 2 || narrowed == result.inliers) break;
    result.inliers = std::move(narrowed);
  }
  result.line = fit_line(points, result.inliers);
  return result;
}

double line_angle_degrees(const Vec3& a, const Vec3& b) {
  const double c = std::min(1.0, std::abs(a.normalized().dot(b.normalized())));
  return std::acos(c) * 180.0 / std::numbers::pi;
}

std::pair<double, double> closest_parameters(const Line& a, const Line& b) {
  const Vec3 w = a.point - b.point;
  const double bb = a.direction.dot(b.direction), d = a.direction.dot(w), e = b.direction.dot(w);
  const double denom = 1.0 - bb * bb;
  if (denom < 1e-12) return {0.0, e};  // parallel: any pair; take a's point
  return {(bb * e - d) / denom, (e - bb * d) / denom};
}

}  // namespace ct::analyzer
