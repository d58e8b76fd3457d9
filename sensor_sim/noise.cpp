// SPDX-License-Identifier: Apache-2.0
#include "sensor_sim/noise.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

namespace ct::sensor {
namespace {

// ln k! — exact for k < 10, Stirling's series for lgamma(k + 1) above (error below 1e-10, far under the
// precision PTRS needs); std::lgamma writes the global signgam, so it is not used from worker threads.
double log_factorial(std::uint64_t k) {
  static const std::array<double, 10> table = [] {
    std::array<double, 10> t{};
    for (std::size_t i = 1; i < t.size(); ++i) t[i] = t[i - 1] + std::log(static_cast<double>(i));
    return t;
  }();
  if (k < table.size()) return table[k];
  const double n = static_cast<double>(k) + 1.0;
  const double n2 = n * n;
  return (n - 0.5) * std::log(n) - n + 0.5 * std::log(2.0 * std::numbers::pi) +
         (1.0 / 12.0 - (1.0 / 360.0 - 1.0 / (1260.0 * n2)) / n2) / n;
}

// Random streams of one pixel channel: temporal and fixed-pattern draws never share a stream, even when the
// two seeds are equal.
std::uint64_t stream(std::uint64_t pixel, int channel, bool fixed_pattern) {
  return 2 * (3 * pixel + static_cast<std::uint64_t>(channel)) + (fixed_pattern ? 1 : 0);
}

}  // namespace

std::uint64_t poisson(double mean, Random& random) {
  if (!(mean > 0)) return 0;
  if (mean < 10) {
    // Knuth's multiplication method: count uniforms until their product falls below e^-mean.
    const double limit = std::exp(-mean);
    std::uint64_t k = 0;
    for (double product = random.uniform(); product > limit; product *= random.uniform()) ++k;
    return k;
  }
  // PTRS (Hörmann 1993), with the constants of the paper.
  const double slam = std::sqrt(mean);
  const double log_mean = std::log(mean);
  const double b = 0.931 + 2.53 * slam;
  const double a = -0.059 + 0.02483 * b;
  const double inv_alpha = 1.1239 + 1.1328 / (b - 3.4);
  const double v_r = 0.9277 - 3.6224 / (b - 2);
  for (;;) {
    const double u = random.uniform() - 0.5;
    const double v = random.uniform();
    const double us = 0.5 - std::abs(u);
    const double k = std::floor((2 * a / us + b) * u + mean + 0.43);
    if (us >= 0.07 && v <= v_r) return static_cast<std::uint64_t>(k);
    if (k < 0 || (us < 0.013 && v > us)) continue;
    if (std::log(v) + std::log(inv_alpha) - std::log(a / (us * us) + b) <=
        -mean + k * log_mean - log_factorial(static_cast<std::uint64_t>(k)))
      return static_cast<std::uint64_t>(k);
  }
}

double standard_normal(Random& random) {
  const double u1 = 1.0 - random.uniform();  // in (0, 1]: the logarithm stays finite
  const double u2 = random.uniform();
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
}

// The fixed-pattern draws of a whole row or column (gain, then offset), on streams no pixel uses (pixel streams lie
// below 2^62 for any image the pixel budget allows).
std::pair<double, double> line_pattern(const NoiseConfig& noise, bool column, std::uint32_t line, int channel, double gain,
                                       double offset) {
  if (gain <= 0 && offset <= 0) return {0.0, 0.0};
  const std::uint64_t base = column ? (std::uint64_t{3} << 62) : (std::uint64_t{2} << 62);
  Random random(noise.pattern_seed, base + 3 * std::uint64_t{line} + static_cast<std::uint64_t>(channel));
  const double g = gain * standard_normal(random);
  return {g, offset * standard_normal(random)};
}

double read_out_electrons(const NoiseConfig& noise, const FullWellConfig& full_well, double exposure_s, double photo_e,
                          const PixelSite& site, int channel) {
  const std::uint64_t pixel = site.index;
  const double dark_e = noise.dark_current_e_per_s * exposure_s;
  double e = photo_e + dark_e;
  double read = 0;
  if (noise.enabled) {
    double prnu = 0, dsnu = 0;
    if (noise.prnu > 0 || noise.dsnu_e > 0) {
      Random pattern(noise.pattern_seed, stream(pixel, channel, true));
      prnu = noise.prnu * standard_normal(pattern);
      dsnu = noise.dsnu_e * standard_normal(pattern);
    }
    const auto [row_gain, row_offset] = line_pattern(noise, false, site.row, channel, noise.prnu_row, noise.dsnu_row_e);
    const auto [column_gain, column_offset] = line_pattern(noise, true, site.column, channel, noise.prnu_column, noise.dsnu_column_e);
    prnu += row_gain + column_gain;
    dsnu += row_offset + column_offset;
    Random temporal(noise.seed, stream(pixel, channel, false));
    const double mean = (1.0 + prnu) * photo_e + dark_e;
    e = (noise.shot ? static_cast<double>(poisson(mean, temporal)) : mean) + dsnu;
    if (noise.read_e > 0) read = noise.read_e * standard_normal(temporal);
  }
  if (full_well.enabled) e = std::min(e, full_well.electrons);
  return e + read;
}

}  // namespace ct::sensor
