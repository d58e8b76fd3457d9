// SPDX-License-Identifier: Apache-2.0
#include "calibrate/spatial.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace ct::calibrate {
namespace {

// σ per frequency k = 1 … n/2 of `lines` sequences of length n, each read with stride `step` from `start(line)`:
// √(mean over the lines of |DFT_k|² / n), the DFT of the deviations from the image's mean.
std::vector<double> spectrum(const std::vector<double>& values, std::size_t lines, std::size_t n, auto at) {
  const std::size_t half = n / 2;
  std::vector<double> cosines(n), sines(n), power(half + 1, 0.0);
  for (std::size_t j = 0; j < n; ++j) {
    const double phase = 2 * std::numbers::pi * static_cast<double>(j) / static_cast<double>(n);
    cosines[j] = std::cos(phase), sines[j] = std::sin(phase);
  }
  std::vector<double> line(n);
  for (std::size_t l = 0; l < lines; ++l) {
    for (std::size_t j = 0; j < n; ++j) line[j] = values[at(l, j)];
    for (std::size_t k = 1; k <= half; ++k) {
      double re = 0, im = 0;
      for (std::size_t j = 0; j < n; ++j) {
        const std::size_t w = (k * j) % n;
        re += line[j] * cosines[w], im -= line[j] * sines[w];
      }
      power[k] += (re * re + im * im) / static_cast<double>(n);
    }
  }
  std::vector<double> sigma;
  for (std::size_t k = 1; k <= half; ++k) sigma.push_back(std::sqrt(power[k] / static_cast<double>(lines)));
  return sigma;
}

}  // namespace

SpatialCurves spatial_curves(const Plane& image, double scale, double temporal_variance_of_mean) {
  const auto M = static_cast<std::size_t>(image.height), N = static_cast<std::size_t>(image.width);
  double mean = 0;
  for (const double v : image.values) mean += v;
  mean /= static_cast<double>(image.values.size());
  std::vector<double> d(image.values.size());
  for (std::size_t i = 0; i < d.size(); ++i) d[i] = (image.values[i] - mean) * scale;

  SpatialCurves c;
  c.spectrum_horizontal = spectrum(d, M, N, [&](std::size_t row, std::size_t j) { return row * N + j; });
  c.spectrum_vertical = spectrum(d, N, M, [&](std::size_t column, std::size_t j) { return j * N + column; });
  c.temporal_floor = std::sqrt(std::max(0.0, temporal_variance_of_mean)) * std::abs(scale);
  c.profile_horizontal.assign(N, 0.0);
  c.profile_vertical.assign(M, 0.0);
  for (std::size_t i = 0; i < M; ++i)
    for (std::size_t j = 0; j < N; ++j) {
      c.profile_horizontal[j] += d[i * N + j] / static_cast<double>(M);
      c.profile_vertical[i] += d[i * N + j] / static_cast<double>(N);
    }

  // The histogram over ±(the largest deviation), 128 bins a side at most; the accumulated one at each bin's edge.
  double largest = 0;
  for (const double v : d) largest = std::max(largest, std::abs(v));
  if (largest > 0) {
    constexpr int kBins = 256;
    const double width = 2 * largest / kBins;
    std::vector<double> counts(kBins, 0.0);
    for (const double v : d) counts[static_cast<std::size_t>(std::clamp(static_cast<int>((v + largest) / width), 0, kBins - 1))] += 1;
    for (int b = 0; b < kBins; ++b)
      if (counts[static_cast<std::size_t>(b)] > 0) c.histogram.emplace_back(-largest + (b + 0.5) * width, counts[static_cast<std::size_t>(b)]);
    std::vector<double> magnitudes(d.size());
    for (std::size_t i = 0; i < d.size(); ++i) magnitudes[i] = std::abs(d[i]);
    std::sort(magnitudes.begin(), magnitudes.end());
    for (int b = 0; b <= kBins / 2; ++b) {
      const double x = b * width;
      const auto at_least = static_cast<double>(magnitudes.end() - std::lower_bound(magnitudes.begin(), magnitudes.end(), x));
      if (at_least > 0) c.accumulated.emplace_back(x, 100 * at_least / static_cast<double>(d.size()));
    }
  }
  return c;
}

}  // namespace ct::calibrate
