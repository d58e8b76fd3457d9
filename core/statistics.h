// SPDX-License-Identifier: Apache-2.0
#pragma once
// The statistics every part uses: quantiles, the mean with its standard error, and the k-sigma factors that
// tests compare Monte Carlo estimates with.

#include <cstddef>
#include <span>
#include <vector>

namespace ct {

// The q-quantile of `values` (q in [0, 1], clamped), by one rule everywhere: the nearest rank below, the element
// of 0-based rank ⌊q·(n − 1)⌋ in ascending order (numpy's method="lower"). It is always one of the values, never
// an interpolation, so a white or an exposure keyed on it is a pixel's own. 0 for no values. The in-place form
// reorders `values` (std::nth_element) instead of copying them.
double quantile_in_place(std::span<double> values, double q);
double quantile_in_place(std::span<float> values, double q);
double quantile(std::vector<double> values, double q);
double quantile(std::vector<float> values, double q);

// The sample mean of independent values and its standard error, √(s²/n) with the unbiased variance s²
// (divisor n − 1). One value: its standard error is unknown and given as 0; none: both 0.
struct MeanAndError {
  double mean = 0, standard_error = 0;
};
MeanAndError mean_and_standard_error(std::span<const double> values);

// k-sigma factors: a check that an estimate lies within k standard errors of its expectation fails by chance (a
// normal error, two-sided) with probability 2.7·10⁻³ at k = 3, 6.3·10⁻⁵ at 4 and 5.7·10⁻⁷ at 5. Choose by how
// many checks run together, so that the whole suite rarely fails by chance.
inline constexpr double kSigmasOneCheck = 3;     // a single comparison
inline constexpr double kSigmasPerItem = 4;      // one per band, object or cell: tens to hundreds together
inline constexpr double kSigmasManyChecks = 5;   // thousands together (per pixel, per sample size, per seed)

}  // namespace ct
