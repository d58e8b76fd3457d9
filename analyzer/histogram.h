// SPDX-License-Identifier: Apache-2.0
#pragma once
// 3D colour histograms of a region's samples, their three 2D projections and the rg-chromaticity
// histogram.
//
// A histogram has `bins` equal bins per channel over [lo, hi] (per channel); a value at hi falls in the
// last bin, values outside are clamped into the edge bins. Cells are kept sparse (occupied cells only,
// sorted by index) because a large bin count (256³ = 16.7 M cells) is mostly empty; counting goes through
// a dense array up to 256³ cells when the samples are not far fewer than the cells, and through sorting
// the samples' cell indices otherwise.

#include <array>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

namespace ct::analyzer {

struct HistogramSpec {
  int bins = 64;
  std::array<double, 3> lo{0, 0, 0};
  std::array<double, 3> hi{1, 1, 1};
  // Float images whose brightest pixels lie far above the rest (a sun, a lamp in an HDR photograph): the range
  // ends above the 99.9th percentile instead, and the pixels beyond it are outliers, counted into the last bins.
  bool robust = false;
  std::size_t outliers = 0;    // pixels with a channel above hi
  double outlier_max = 0;      // the largest value among them
  double full_max = 0;         // the largest finite value (the range's end when not robust)
};

// The range of an image's samples, the same for the three channels: integer images [0, full scale]; float
// images [min(0, smallest), largest] (HDR values above 1 included) — unless the largest pixel value (a pixel's
// brightest channel) is more than kRobustRatio times the 99.9th percentile of the pixels' values, when the range
// ends at kRobustMargin times that percentile and the pixels above it are counted as outliers, so that a few
// extreme pixels do not squeeze every other pixel into one cell. `full_scale` <= 0 means float.
inline constexpr double kRobustRatio = 4.0, kRobustMargin = 1.25, kRobustQuantile = 0.999;
HistogramSpec histogram_spec(std::span<const float> rgb, int bins, double full_scale);

struct HistogramCell {
  std::uint32_t index = 0;  // (r · bins + g) · bins + b
  std::uint32_t count = 0;
};

struct Histogram3 {
  HistogramSpec spec;
  std::vector<HistogramCell> cells;  // occupied cells, by increasing index
  std::uint64_t total = 0;
  std::uint32_t max_count = 0;

  // The bin of each channel for a cell index.
  std::array<int, 3> bin_of(std::uint32_t index) const;
};

// Counts samples [i][channel]; threads as core/parallel.h (counts do not depend on it).
Histogram3 histogram_3d(std::span<const float> rgb, const HistogramSpec& spec, int threads);

// log10(1 + count): the density scale of plots and the report (a few highlight pixels stay visible beside
// a body colour holding most of the region).
double log_density(std::uint32_t count);

// A dense bins × bins histogram, [a][b].
struct Histogram2 {
  int bins = 0;
  std::vector<std::uint32_t> counts;
  std::uint32_t max_count = 0;
};

// The projections onto the RG, RB and GB planes (sums over the third channel), in that order.
std::array<Histogram2, 3> projections(const Histogram3& histogram);

// rg-chromaticity r = R/(R+G+B), g = G/(R+G+B) over [0, 1]², [r][g]; samples with R+G+B <= 0 have no
// chromaticity and are left out.
Histogram2 chromaticity_histogram(std::span<const float> rgb, int bins);

}  // namespace ct::analyzer
