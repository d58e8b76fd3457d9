// SPDX-License-Identifier: Apache-2.0
#include "analyzer/histogram.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "core/parallel.h"
#include "core/statistics.h"

namespace ct::analyzer {
namespace {

// Dense counting up to this many cells (64 MiB of counters per thread): clearing and scanning them costs
// less than sorting 24 M cell indices.
constexpr std::uint64_t kDenseCells = 256ull * 256ull * 256ull;

struct BinMap {
  std::array<float, 3> lo, scale;
  int last;

  explicit BinMap(const HistogramSpec& s) : last(s.bins - 1) {
    for (int c = 0; c < 3; ++c) {
      const double width = s.hi[c] - s.lo[c];
      lo[c] = static_cast<float>(s.lo[c]);
      scale[c] = width > 0 ? static_cast<float>(s.bins / width) : 0.0f;
    }
  }
  int bin(float v, int c) const {
    const float f = (v - lo[c]) * scale[c];
    // Clamp in float first: a huge value must not overflow the int conversion.
    return static_cast<int>(std::clamp(f, 0.0f, static_cast<float>(last)));
  }
  std::uint32_t index(const float* v) const {
    const auto b = static_cast<std::uint32_t>(last + 1);
    return (static_cast<std::uint32_t>(bin(v[0], 0)) * b + static_cast<std::uint32_t>(bin(v[1], 1))) * b +
           static_cast<std::uint32_t>(bin(v[2], 2));
  }
};

}  // namespace

HistogramSpec histogram_spec(std::span<const float> rgb, int bins, double full_scale) {
  HistogramSpec spec;
  spec.bins = bins;
  if (full_scale > 0) {
    spec.hi = {full_scale, full_scale, full_scale};
    spec.full_max = full_scale;
    return spec;
  }
  std::array<double, 3> lo{0, 0, 0}, hi{0, 0, 0};
  std::vector<float> brightest;  // per pixel, its largest finite channel
  brightest.reserve(rgb.size() / 3);
  for (std::size_t i = 0; i + 2 < rgb.size(); i += 3) {
    float top = -std::numeric_limits<float>::infinity();
    for (std::size_t c = 0; c < 3; ++c) {
      const double v = rgb[i + c];
      if (!std::isfinite(v)) continue;
      lo[c] = std::min(lo[c], v);
      hi[c] = std::max(hi[c], v);
      top = std::max(top, rgb[i + c]);
    }
    if (std::isfinite(top)) brightest.push_back(top);
  }
  // One range for all three channels keeps the cube a cube: angles and shapes are not distorted.
  const double low = *std::min_element(lo.begin(), lo.end()), high = *std::max_element(hi.begin(), hi.end());
  spec.full_max = high;
  spec.lo.fill(low);
  spec.hi.fill(high > low ? high : low + 1.0);
  if (brightest.size() < 1000) return spec;  // too few pixels for a 99.9th percentile
  const double top = quantile_in_place(brightest, kRobustQuantile);
  if (!(top > 0) || high <= kRobustRatio * top) return spec;
  spec.robust = true;
  spec.hi.fill(kRobustMargin * top);
  for (std::size_t i = 0; i + 2 < rgb.size(); i += 3)
    for (std::size_t c = 0; c < 3; ++c)
      if (std::isfinite(rgb[i + c]) && rgb[i + c] > spec.hi[0]) {
        ++spec.outliers;
        spec.outlier_max = std::max(spec.outlier_max, static_cast<double>(rgb[i + c]));
        break;
      }
  return spec;
}

std::array<int, 3> Histogram3::bin_of(std::uint32_t index) const {
  const auto b = static_cast<std::uint32_t>(spec.bins);
  return {static_cast<int>(index / (b * b)), static_cast<int>(index / b % b), static_cast<int>(index % b)};
}

Histogram3 histogram_3d(std::span<const float> rgb, const HistogramSpec& spec, int threads) {
  Histogram3 h;
  h.spec = spec;
  const std::size_t n = rgb.size() / 3;
  h.total = n;
  const BinMap map(spec);
  const std::uint64_t cells = static_cast<std::uint64_t>(spec.bins) * spec.bins * spec.bins;
  // Sorting wins when the cells far outnumber the samples (small regions), and beyond kDenseCells.
  const bool dense = cells <= kDenseCells && cells <= 8 * n + 65536;
  // A dense piece should count at least as many samples as it has cells: clearing and merging its
  // counters would cost more than the thread saves.
  const std::size_t per_piece = std::max<std::size_t>(65536, dense ? cells : 0);
  const std::size_t pieces = std::max<std::size_t>(1, std::min<std::size_t>(thread_count(threads), n / per_piece));
  auto piece_range = [&](std::size_t p) { return std::pair{n * p / pieces, n * (p + 1) / pieces}; };

  if (dense) {
    std::vector<std::vector<std::uint32_t>> partial(pieces);
    parallel_for(pieces, threads, [&](std::size_t p) {
      std::vector<std::uint32_t>& counts = partial[p];
      counts.assign(cells, 0);
      const auto [i0, i1] = piece_range(p);
      for (std::size_t i = i0; i < i1; ++i) ++counts[map.index(&rgb[i * 3])];
    });
    for (std::size_t p = 1; p < pieces; ++p)
      for (std::size_t c = 0; c < cells; ++c) partial[0][c] += partial[p][c];
    for (std::size_t c = 0; c < cells; ++c)
      if (partial[0][c] != 0) h.cells.push_back({static_cast<std::uint32_t>(c), partial[0][c]});
  } else {
    std::vector<std::uint32_t> index(n);
    parallel_for(pieces, threads, [&](std::size_t p) {
      const auto [i0, i1] = piece_range(p);
      for (std::size_t i = i0; i < i1; ++i) index[i] = map.index(&rgb[i * 3]);
    });
    std::sort(index.begin(), index.end());
    for (std::size_t i = 0; i < n;) {
      std::size_t j = i;
      while (j < n && index[j] == index[i]) ++j;
      h.cells.push_back({index[i], static_cast<std::uint32_t>(j - i)});
      i = j;
    }
  }
  for (const HistogramCell& c : h.cells) h.max_count = std::max(h.max_count, c.count);
  return h;
}

double log_density(std::uint32_t count) { return std::log10(1.0 + count); }

std::array<Histogram2, 3> projections(const Histogram3& histogram) {
  const int b = histogram.spec.bins;
  std::array<Histogram2, 3> out;
  for (Histogram2& p : out) p = {b, std::vector<std::uint32_t>(static_cast<std::size_t>(b) * b, 0), 0};
  for (const HistogramCell& c : histogram.cells) {
    const auto [r, g, bl] = histogram.bin_of(c.index);
    out[0].counts[static_cast<std::size_t>(r * b + g)] += c.count;
    out[1].counts[static_cast<std::size_t>(r * b + bl)] += c.count;
    out[2].counts[static_cast<std::size_t>(g * b + bl)] += c.count;
  }
  for (Histogram2& p : out) p.max_count = *std::max_element(p.counts.begin(), p.counts.end());
  return out;
}

Histogram2 chromaticity_histogram(std::span<const float> rgb, int bins) {
  Histogram2 h{bins, std::vector<std::uint32_t>(static_cast<std::size_t>(bins) * bins, 0), 0};
  for (std::size_t i = 0; i + 2 < rgb.size(); i += 3) {
    const double sum = static_cast<double>(rgb[i]) + rgb[i + 1] + rgb[i + 2];
    if (!(sum > 0)) continue;
    const int r = std::clamp(static_cast<int>(rgb[i] / sum * bins), 0, bins - 1);
    const int g = std::clamp(static_cast<int>(rgb[i + 1] / sum * bins), 0, bins - 1);
    ++h.counts[static_cast<std::size_t>(r * bins + g)];
  }
  h.max_count = *std::max_element(h.counts.begin(), h.counts.end());
  return h;
}

}  // namespace ct::analyzer
