// SPDX-License-Identifier: Apache-2.0
#include "core/statistics.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace ct {

namespace {

template <typename T>
double lower_rank_quantile(std::span<T> values, double q) {
  if (values.empty()) return 0.0;
  const auto rank = static_cast<std::size_t>(std::floor(std::clamp(q, 0.0, 1.0) * static_cast<double>(values.size() - 1)));
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(rank), values.end());
  return static_cast<double>(values[rank]);
}

}  // namespace

double quantile_in_place(std::span<double> values, double q) { return lower_rank_quantile(values, q); }
double quantile_in_place(std::span<float> values, double q) { return lower_rank_quantile(values, q); }
double quantile(std::vector<double> values, double q) { return lower_rank_quantile(std::span<double>(values), q); }
double quantile(std::vector<float> values, double q) { return lower_rank_quantile(std::span<float>(values), q); }

MeanAndError mean_and_standard_error(std::span<const double> values) {
  MeanAndError out;
  if (values.empty()) return out;
  const auto n = static_cast<double>(values.size());
  out.mean = std::accumulate(values.begin(), values.end(), 0.0) / n;
  if (values.size() < 2) return out;
  double ss = 0;
  for (const double x : values) ss += (x - out.mean) * (x - out.mean);
  out.standard_error = std::sqrt(ss / (n - 1) / n);
  return out;
}

}  // namespace ct
