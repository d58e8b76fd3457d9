#include "analyzer/gamma_fit.h"

#include <algorithm>
#include <cmath>

namespace ct::analyzer {
namespace {

constexpr std::size_t kMaxPoints = 4000;

double straightness(const std::vector<Vec3>& points, double inverse_gamma) {
  std::vector<Vec3> y(points.size());
  for (std::size_t i = 0; i < points.size(); ++i)
    for (int c = 0; c < 3; ++c) y[i][c] = std::pow(points[i][c], inverse_gamma);
  const Vec3 values = principal_axes_of(y, About::Mean).values;
  return values[0] > 0 ? (values[1] + values[2]) / values[0] : 0.0;
}

}  // namespace

std::optional<GammaFit> fit_gamma(const std::vector<Vec3>& points) {
  std::vector<Vec3> positive;
  double largest = 0;
  for (const Vec3& p : points)
    if (p.minCoeff() > 0) positive.push_back(p), largest = std::max(largest, p.maxCoeff());
  if (positive.size() < 10) return std::nullopt;
  GammaFit fit;
  fit.used = positive.size();
  // An even stride keeps the search cheap on big regions; a common scale keeps pow() well conditioned.
  const std::size_t stride = (positive.size() + kMaxPoints - 1) / kMaxPoints;
  std::vector<Vec3> sample;
  for (std::size_t i = 0; i < positive.size(); i += stride) sample.push_back(positive[i] / largest);

  // Coarse grid over log γ, then golden-section search in the bracket around the best grid point.
  const double lo = std::log(0.2), hi = std::log(5.0);
  constexpr int kGrid = 48;
  auto cost = [&](double log_gamma) { return straightness(sample, std::exp(-log_gamma)); };
  int best = 0;
  double best_cost = std::numeric_limits<double>::max();
  for (int k = 0; k <= kGrid; ++k) {
    const double c = cost(lo + (hi - lo) * k / kGrid);
    if (c < best_cost) best_cost = c, best = k;
  }
  double a = lo + (hi - lo) * std::max(0, best - 1) / kGrid, b = lo + (hi - lo) * std::min(kGrid, best + 1) / kGrid;
  const double r = (std::sqrt(5.0) - 1) / 2;
  double x1 = b - r * (b - a), x2 = a + r * (b - a), f1 = cost(x1), f2 = cost(x2);
  for (int k = 0; k < 60; ++k) {
    if (f1 < f2) b = x2, x2 = x1, f2 = f1, x1 = b - r * (b - a), f1 = cost(x1);
    else a = x1, x1 = x2, f1 = f2, x2 = a + r * (b - a), f2 = cost(x2);
  }
  fit.gamma = std::exp(0.5 * (a + b));
  fit.straightness_as_is = straightness(sample, 1.0);
  fit.straightness_linearised = straightness(sample, 1.0 / fit.gamma);
  return fit;
}

}  // namespace ct::analyzer
