// SPDX-License-Identifier: Apache-2.0
#include "analyzer/gamma_fit.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include <fmt/format.h>

#include "core/colour.h"
#include "core/statistics.h"

namespace ct::analyzer {
namespace {

constexpr std::size_t kMaxPoints = 4000;

// The variance off the flat, relative to the variance in it: (λ2 + λ3) / λ1 for a line, λ3 / (λ1 + λ2) for a plane.
double straightness(const std::vector<Vec3>& points, double inverse_gamma, GammaFlat flat) {
  std::vector<Vec3> y(points.size());
  for (std::size_t i = 0; i < points.size(); ++i)
    for (int c = 0; c < 3; ++c) y[i][c] = std::pow(points[i][c], inverse_gamma);
  const Vec3 values = principal_axes_of(y, About::Mean).values;
  if (flat == GammaFlat::Plane) return values[0] + values[1] > 0 ? values[2] / (values[0] + values[1]) : 0.0;
  return values[0] > 0 ? (values[1] + values[2]) / values[0] : 0.0;
}

}  // namespace

namespace {

// The γ whose inverse makes `sample` straightest: a coarse grid over log γ, then golden-section search in the
// bracket around the best grid point.
double best_gamma(const std::vector<Vec3>& sample, GammaFlat flat) {
  const double lo = std::log(kGammaMin), hi = std::log(kGammaMax);
  constexpr int kGrid = 48;
  auto cost = [&](double log_gamma) { return straightness(sample, std::exp(-log_gamma), flat); };
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
  return std::exp(0.5 * (a + b));
}

// The positive samples, an even stride of at most kMaxPoints of them, scaled to a largest value of 1 (a common
// scale keeps pow() well conditioned); `used` gets the number of positive samples.
std::vector<Vec3> gamma_sample(const std::vector<Vec3>& points, std::size_t& used) {
  std::vector<Vec3> positive;
  double largest = 0;
  for (const Vec3& p : points)
    if (p.minCoeff() > 0) positive.push_back(p), largest = std::max(largest, p.maxCoeff());
  used = positive.size();
  std::vector<Vec3> sample;
  if (positive.empty()) return sample;
  const std::size_t stride = (positive.size() + kMaxPoints - 1) / kMaxPoints;
  for (std::size_t i = 0; i < positive.size(); i += stride) sample.push_back(positive[i] / largest);
  return sample;
}

}  // namespace

std::optional<GammaFit> fit_gamma(const std::vector<Vec3>& points, GammaFlat flat) {
  GammaFit fit;
  fit.flat = flat;
  const std::vector<Vec3> sample = gamma_sample(points, fit.used);
  if (fit.used < 10) return std::nullopt;
  fit.gamma = best_gamma(sample, flat);
  std::vector<double> values;
  for (const Vec3& p : points)
    if (p.minCoeff() > 0) values.insert(values.end(), {p[0], p[1], p[2]});
  fit.lo = quantile_in_place(values, 0.02);
  fit.hi = quantile_in_place(values, 0.98);
  fit.straightness_as_is = straightness(sample, 1.0, flat);
  fit.straightness_linearised = straightness(sample, 1.0 / fit.gamma, flat);
  return fit;
}

double gamma_standard_error(const std::vector<Vec3>& points, std::uint64_t seed, GammaFlat flat) {
  std::size_t used = 0;
  const std::vector<Vec3> sample = gamma_sample(points, used);
  if (sample.size() < 10) return std::numeric_limits<double>::quiet_NaN();
  constexpr int kReplicates = 16;
  constexpr std::size_t kResample = 1000;
  const std::size_t m = std::min(kResample, sample.size());
  std::uint64_t state = seed * 0x9E3779B97F4A7C15ull + 1;
  const auto next = [&] {  // splitmix64
    std::uint64_t z = (state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  };
  std::vector<double> gammas;
  std::vector<Vec3> resample(m);
  for (int r = 0; r < kReplicates; ++r) {
    for (Vec3& p : resample) p = sample[next() % sample.size()];
    gammas.push_back(best_gamma(resample, flat));
  }
  double mean = 0, var = 0;
  for (const double g : gammas) mean += g / kReplicates;
  for (const double g : gammas) var += (g - mean) * (g - mean) / (kReplicates - 1);
  // Resamples of m points spread as √(1/m); the fit used all of the sample's n points.
  return std::sqrt(var) * std::sqrt(static_cast<double>(m) / static_cast<double>(sample.size()));
}

double srgb_effective_gamma(double lo, double hi) {
  constexpr int kSteps = 64;
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (int k = 0; k <= kSteps; ++k) {
    const double y = std::log(lo) + (std::log(hi) - std::log(lo)) * k / kSteps;  // ln I'
    const double x = std::log(srgb_decode(std::exp(y)));                          // ln I
    sx += x, sy += y, sxx += x * x, sxy += x * y;
  }
  const double n = kSteps + 1;
  return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

std::optional<GammaComparison> compare_gamma(const GammaFit& fit, const ToneCurve& declared, double full_scale) {
  if (!fit.gamma_se || !(*fit.gamma_se > 0)) return std::nullopt;
  GammaComparison c;
  c.declared = declared.describe();
  const double lo = std::clamp(fit.lo / full_scale, 1e-6, 1.0), hi = std::clamp(fit.hi / full_scale, 1e-6, 1.0);
  c.declared_gamma = declared.srgb ? (hi > lo ? srgb_effective_gamma(lo, hi) : 1 / 2.2) : declared.gamma;
  c.fitted = fit.gamma;
  c.se = *fit.gamma_se;
  c.difference_in_se = std::abs(c.fitted - c.declared_gamma) / c.se;
  if (gamma_at_bound(c.fitted))
    c.not_measured = fmt::format("the best fit lies at the edge of the searched range ({:g} to {:g}): no power curve straightens the "
                                 "cluster better than another, as for a line through black, which stays a line under any γ",
                                 kGammaMin, kGammaMax);
  else if (c.fitted - 2 * c.se <= kGammaMin || c.fitted + 2 * c.se >= kGammaMax)
    c.not_measured = fmt::format("its uncertainty (± {:.3g}) reaches past the searched range ({:g} to {:g})", c.se, kGammaMin, kGammaMax);
  c.measured = c.not_measured.empty();
  c.agree = c.measured && c.difference_in_se <= kGammaAgreement;
  return c;
}

}  // namespace ct::analyzer
