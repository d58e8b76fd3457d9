// SPDX-License-Identifier: Apache-2.0
#include "calibrate/spatial.h"

#include <algorithm>
#include <cmath>

#include <opencv2/core.hpp>

namespace ct::calibrate {
namespace {

// σ per frequency k = 1 … n/2 along the rows of `lines` (one line per row, n values each): √(mean over the rows of
// |DFT_k|² / n), by OpenCV's FFT (a camera raw's planes hold thousands of rows of thousands of values).
std::vector<double> spectrum(const cv::Mat& lines) {
  cv::Mat transform;
  cv::dft(lines, transform, cv::DFT_ROWS | cv::DFT_COMPLEX_OUTPUT);
  const int n = lines.cols;
  std::vector<double> sigma;
  for (int k = 1; k <= n / 2; ++k) {
    double power = 0;
    for (int row = 0; row < lines.rows; ++row) {
      const cv::Vec2d v = transform.at<cv::Vec2d>(row, k);
      power += (v[0] * v[0] + v[1] * v[1]) / n;
    }
    sigma.push_back(std::sqrt(power / lines.rows));
  }
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
  const cv::Mat rows(static_cast<int>(M), static_cast<int>(N), CV_64F, d.data());
  c.spectrum_horizontal = spectrum(rows);
  c.spectrum_vertical = spectrum(rows.t());
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
