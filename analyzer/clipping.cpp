// SPDX-License-Identifier: Apache-2.0
#include "analyzer/clipping.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "core/statistics.h"

namespace ct::analyzer {
Clipping find_clipping(std::span<const float> rgb, const std::array<double, 3>& high_levels, const ClippingRules& rules) {
  Clipping result;
  const std::size_t n = rgb.size() / 3;
  if (n == 0) return result;
  const auto& low = rules.low;
  // count[c][0] low face, count[c][1] high face
  std::array<std::array<std::size_t, 2>, 3> count{};
  auto side = [&](std::size_t i, int c) {
    const double v = rgb[i * 3 + static_cast<std::size_t>(c)];
    if (v >= high_levels[c]) return 1;
    if (v <= low[c] && (rgb[i * 3] > low[0] || rgb[i * 3 + 1] > low[1] || rgb[i * 3 + 2] > low[2])) return 0;
    return -1;
  };
  // The other two channels' extremes on each face: on a true clipping face they keep changing.
  std::array<std::array<std::array<float, 2>, 2>, 3> lo{}, hi{};
  for (auto& a : lo) for (auto& b : a) b.fill(std::numeric_limits<float>::max());
  for (auto& a : hi) for (auto& b : a) b.fill(std::numeric_limits<float>::lowest());
  // Per sample, the faces it lies on: bit 2c for channel c's lower face, bit 2c + 1 for its upper one.
  std::vector<std::uint8_t> sides(n, 0);
  for (std::size_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c)
      if (const int s = side(i, c); s >= 0) {
        sides[i] |= static_cast<std::uint8_t>(1u << (2 * c + s));
        ++count[c][s];
        for (int o = 1; o < 3; ++o) {
          const float v = rgb[i * 3 + static_cast<std::size_t>((c + o) % 3)];
          lo[c][s][o - 1] = std::min(lo[c][s][o - 1], v);
          hi[c][s][o - 1] = std::max(hi[c][s][o - 1], v);
        }
      }
  std::array<std::array<bool, 2>, 3> kept{};
  for (int c = 0; c < 3; ++c)
    for (int s = 0; s < 2; ++s) {
      const double fraction = static_cast<double>(count[c][s]) / static_cast<double>(n);
      if (count[c][s] < 3 || fraction < kFaceFraction) continue;
      if (!(s == 1 && rules.known_high)) {
        const double spread = std::max(hi[c][s][0] - lo[c][s][0], hi[c][s][1] - lo[c][s][1]);
        // A lower face's spread is measured against the other channels' own values on it: the image's levels, set
        // by its brightest parts (a lamp's flame in an HDR photograph), would call every dim region's lower face flat.
        const double range = s == 1 && std::abs(high_levels[c]) < 1e300 ? std::abs(high_levels[c] - low[c]) : 0.0;
        const double scale = std::max({range,
                                       static_cast<double>(std::abs(hi[c][s][0] - low[(c + 1) % 3])),
                                       static_cast<double>(std::abs(hi[c][s][1] - low[(c + 2) % 3]))});
        if (spread <= kFaceSpread * scale) continue;
      }
      kept[c][s] = true;
      result.faces.push_back({c, s == 1, s == 1 ? high_levels[c] : low[c], count[c][s], fraction});
    }
  for (int c = 0; c < 3; ++c) result.at_black[c] = count[c][0], result.at_top[c] = count[c][1];
  result.known_high = rules.known_high;
  for (const double level : high_levels)
    if (std::isfinite(level)) result.top = std::max(result.top, level);
  if (!(result.top > 0))
    for (std::size_t i = 0; i < n * 3; ++i)
      if (std::isfinite(rgb[i])) result.top = std::max(result.top, static_cast<double>(rgb[i]));
  for (int c = 0; c < 3; ++c) {
    if (count[c][0] == 0) continue;
    std::vector<double> brightest;
    brightest.reserve(count[c][0]);
    for (std::size_t i = 0; i < n; ++i)
      if (sides[i] & (1u << (2 * c))) brightest.push_back(std::max({rgb[i * 3], rgb[i * 3 + 1], rgb[i * 3 + 2]}));
    result.black_brightest_median[c] = quantile_in_place(brightest, 0.5);
  }
  std::uint8_t kept_faces = 0;
  for (int c = 0; c < 3; ++c)
    for (int s = 0; s < 2; ++s)
      if (kept[c][s]) kept_faces |= static_cast<std::uint8_t>(1u << (2 * c + s));
  result.on_face.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    result.on_face[i] = (sides[i] & kept_faces) != 0;
    result.clipped += result.on_face[i];
  }
  result.fraction = static_cast<double>(result.clipped) / static_cast<double>(n);
  return result;
}

bool reaches_the_top(const Clipping& c) {
  return std::any_of(c.faces.begin(), c.faces.end(), [](const ClippedFace& f) { return f.high; });
}

bool only_at_black(const Clipping& c) { return !c.faces.empty() && !reaches_the_top(c); }

ClearOfBlack clear_of_black(std::span<const float> rgb, const Clipping& clipping, const std::array<double, 3>& low) {
  ClearOfBlack out;
  const std::size_t n = rgb.size() / 3;
  auto at_black = [&](std::size_t i, std::size_t c) { return rgb[3 * i + c] <= low[c]; };
  std::vector<std::uint8_t> keep(n, 1);
  std::vector<double> sum(n);
  std::vector<int> bucket_of(n);
  // The samples are ordered by the sum in kBuckets buckets, log-spaced over six decades below the largest sum (those
  // below, and the sums at or under 0, share the lowest): linear time, and a level finer than a bin of samples.
  constexpr int kBuckets = 4096;
  std::vector<std::size_t> count(kBuckets), black(kBuckets);
  for (const ClippedFace& f : clipping.faces) {
    if (f.high) continue;
    const std::size_t c = static_cast<std::size_t>(f.channel);
    double top = 0;
    for (std::size_t i = 0; i < n; ++i) {
      sum[i] = static_cast<double>(rgb[3 * i + (c + 1) % 3]) + rgb[3 * i + (c + 2) % 3];
      top = std::max(top, std::isfinite(sum[i]) ? sum[i] : 0.0);
    }
    if (top <= 0) return out;
    const double floor = top * 1e-6, decades = std::log(top / floor);
    auto bucket = [&](double v) {
      if (!(v > floor)) return 0;
      return std::min(kBuckets - 1, static_cast<int>(std::log(v / floor) / decades * kBuckets));
    };
    std::fill(count.begin(), count.end(), 0);
    std::fill(black.begin(), black.end(), 0);
    for (std::size_t i = 0; i < n; ++i) {
      const int b = bucket_of[i] = bucket(sum[i]);
      ++count[static_cast<std::size_t>(b)];
      black[static_cast<std::size_t>(b)] += at_black(i, c) ? 1 : 0;
    }
    // From the top, bins of a 64th of the samples (at least 32; whole buckets): fine enough to place the level, large
    // enough to count a share. The lowest bucket of the last bin that passes is where the channel is clear.
    const std::size_t bin = std::max<std::size_t>(32, n / 64);
    int clear_from = kBuckets;  // no bucket yet
    std::size_t in_bin = 0, black_in_bin = 0;
    for (int b = kBuckets - 1; b >= 0; --b) {
      in_bin += count[static_cast<std::size_t>(b)];
      black_in_bin += black[static_cast<std::size_t>(b)];
      if (in_bin < bin && b > 0) continue;
      if (static_cast<double>(black_in_bin) > kClearShare * static_cast<double>(in_bin)) break;
      clear_from = b;
      in_bin = black_in_bin = 0;
    }
    if (clear_from == kBuckets) return out;
    double level = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < n; ++i) {
      if (bucket_of[i] < clear_from) keep[i] = 0;
      else level = std::min(level, sum[i]);
    }
    out.level[c] = level;
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (!keep[i] || at_black(i, 0) || at_black(i, 1) || at_black(i, 2)) continue;
    out.rgb.insert(out.rgb.end(), rgb.begin() + static_cast<std::ptrdiff_t>(3 * i), rgb.begin() + static_cast<std::ptrdiff_t>(3 * i + 3));
  }
  return out;
}

}  // namespace ct::analyzer
