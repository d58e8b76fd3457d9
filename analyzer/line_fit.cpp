#include "analyzer/line_fit.h"

#include <algorithm>
#include <cmath>
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
  std::size_t best_count = 0;
  Line best;
  for (int k = 0; k < kIterations; ++k) {
    const Vec3& a = points[pick()];
    const Vec3& b = points[pick()];
    const Vec3 d = b - a;
    if (d.norm() <= max_distance) continue;  // too close to fix a direction
    Line trial;
    trial.point = a;
    trial.direction = d.normalized();
    std::size_t count = 0;
    for (const std::size_t i : candidates) count += trial.distance(points[i]) <= max_distance;
    if (count > best_count) best_count = count, best = trial;
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
