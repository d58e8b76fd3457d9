// SPDX-License-Identifier: Apache-2.0
// Histograms and moments: counts, ranges for integer and HDR float images, sparse and dense counting
// agree, projections and chromaticity, accurate moments of large 16-bit data, thread independence.
#include <cmath>
#include <map>
#include <random>

#include <gtest/gtest.h>

#include "analyzer/histogram.h"
#include "analyzer/moments.h"

namespace ct::test {
namespace {

using namespace ct::analyzer;

std::vector<float> random_samples(std::size_t n, double scale, std::uint32_t seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<float> u(0.0f, static_cast<float>(scale));
  std::vector<float> v(n * 3);
  for (float& x : v) x = u(random);
  return v;
}

TEST(Histogram, CountsEverySampleOnce) {
  const std::vector<float> rgb = random_samples(10000, 1.0, 1);
  const Histogram3 h = histogram_3d(rgb, histogram_spec(rgb, 16, 0), 2);
  std::uint64_t total = 0;
  for (const HistogramCell& c : h.cells) total += c.count;
  EXPECT_EQ(total, 10000u);
  EXPECT_EQ(h.total, 10000u);
  EXPECT_TRUE(std::is_sorted(h.cells.begin(), h.cells.end(), [](auto& a, auto& b) { return a.index < b.index; }));
}

// An HDR image whose few brightest pixels (a sun) lie far above the rest: the range ends at 1.25 × the 99.9th
// percentile of the pixels' brightest channels, and the pixels above it are counted as outliers; without such
// pixels, or with too few pixels to tell, the range is the full one.
TEST(Histogram, ExtremePixelsOfAnHdrImageAreOutliers) {
  std::vector<float> rgb;
  for (int i = 0; i < 10000; ++i) {
    const float v = static_cast<float>(i % 100) / 100.0f;  // the scene: up to 0.99
    rgb.insert(rgb.end(), {v, 0.5f * v, 0.25f * v});
  }
  const HistogramSpec plain = histogram_spec(rgb, 64, 0);
  EXPECT_FALSE(plain.robust);
  EXPECT_FLOAT_EQ(static_cast<float>(plain.hi[0]), 0.99f);
  for (int i = 0; i < 5; ++i) rgb.insert(rgb.end(), {20000.0f, 18000.0f + i, 15000.0f});  // the sun: 0.05 %
  const HistogramSpec sunny = histogram_spec(rgb, 64, 0);
  EXPECT_TRUE(sunny.robust);
  EXPECT_FLOAT_EQ(static_cast<float>(sunny.hi[0]), 1.25f * 0.99f);
  EXPECT_EQ(sunny.outliers, 5u);
  EXPECT_EQ(sunny.outlier_max, 20000.0);
  EXPECT_EQ(sunny.full_max, 20000.0);
  // The scene's pixels now spread over the bins instead of sharing the first one.
  const Histogram3 h = histogram_3d(rgb, sunny, 1);
  EXPECT_GT(h.cells.size(), 50u);
  const std::vector<float> few(rgb.end() - 300, rgb.end());  // 100 pixels: no percentile
  EXPECT_FALSE(histogram_spec(few, 64, 0).robust);
}

TEST(Histogram, RangesFollowTheEncoding) {
  const std::vector<float> hdr = {0.5f, 2.0f, 7.5f, 0.0f, 0.1f, 0.2f};
  const HistogramSpec f = histogram_spec(hdr, 8, 0);
  EXPECT_EQ(f.hi[0], 7.5);  // HDR values above 1 are kept, one range for all channels
  EXPECT_EQ(f.hi[2], 7.5);
  const HistogramSpec i = histogram_spec(hdr, 8, 65535);
  EXPECT_EQ(i.hi[1], 65535);
  // The top value lands in the last bin, not past it.
  const Histogram3 h = histogram_3d(hdr, f, 1);
  EXPECT_EQ(h.bin_of(h.cells.back().index), (std::array<int, 3>{0, 2, 7}));
}

TEST(Histogram, SparseCountingAgreesWithDense) {
  const std::vector<float> rgb = random_samples(200000, 255.0, 2);
  // 512 bins count by sorting, 64 densely; merging 8×8×8 cells of the first must give the second.
  HistogramSpec fine = histogram_spec(rgb, 512, 255), coarse = histogram_spec(rgb, 64, 255);
  const Histogram3 a = histogram_3d(rgb, fine, 2), b = histogram_3d(rgb, coarse, 2);
  std::map<std::uint32_t, std::uint32_t> merged;
  for (const HistogramCell& c : a.cells) {
    const auto bin = a.bin_of(c.index);
    merged[static_cast<std::uint32_t>(((bin[0] / 8) * 64 + bin[1] / 8) * 64 + bin[2] / 8)] += c.count;
  }
  ASSERT_EQ(merged.size(), b.cells.size());
  for (const HistogramCell& c : b.cells) EXPECT_EQ(merged[c.index], c.count);
}

TEST(Histogram, ProjectionsAndChromaticity) {
  const std::vector<float> rgb = {1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1, 0, 0, 0};
  const Histogram3 h = histogram_3d(rgb, histogram_spec(rgb, 2, 0), 1);
  const auto p = projections(h);
  EXPECT_EQ(p[0].counts[1 * 2 + 0], 1u);  // RG plane: (R high, G low) from the red sample
  EXPECT_EQ(p[0].counts[0], 2u);          // blue and black
  const Histogram2 c = chromaticity_histogram(rgb, 3);
  std::uint32_t total = 0;
  for (auto v : c.counts) total += v;
  EXPECT_EQ(total, 4u);  // black has no chromaticity
  EXPECT_EQ(c.counts[1 * 3 + 1], 1u);  // white: r = g = 1/3
}

TEST(Moments, AccurateForLarge16BitValuesAndThreadIndependent) {
  // A constant offset of 60000 with a small spread: naive sums of squares would cancel badly.
  std::vector<float> rgb(3 * 300000);
  for (std::size_t i = 0; i < rgb.size(); ++i) rgb[i] = 60000.0f + static_cast<float>((i * 7919) % 11);
  const Moments one = moments(rgb, 1), two = moments(rgb, 2);
  EXPECT_EQ(one.mean, two.mean);
  EXPECT_EQ(one.covariance, two.covariance);
  double mean = 0, var = 0;
  for (std::size_t i = 0; i < rgb.size(); i += 3) mean += rgb[i];
  mean /= 300000;
  for (std::size_t i = 0; i < rgb.size(); i += 3) var += (rgb[i] - mean) * (rgb[i] - mean);
  var /= 300000;
  EXPECT_NEAR(one.mean[0], mean, 1e-9 * mean);
  EXPECT_NEAR(one.covariance(0, 0), var, 1e-9 * var);
}

}  // namespace
}  // namespace ct::test
