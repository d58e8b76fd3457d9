// SPDX-License-Identifier: Apache-2.0
// Guided reconstruction (core/guided.h) on images whose answers are known: a band that is exactly a multiple
// of the guide comes back exactly; noise of known variance shrinks by the window's averaging; a step in the
// ratio is refused; the families add up to the total afterwards; and the thresholds are the normal's.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>

#include "core/guided.h"
#include "core/random.h"
#include "core/statistics.h"

namespace ct {
namespace {

// A w × h image of four bands, one object, no components: band b at pixel (x, y) is shading(x, y) · ratio(b),
// and band 3 is then given `noise` (Gaussian, of standard deviation noise · its value).
GuidedImage shaded(int w, int h, double step_ratio, double noise, std::uint64_t seed) {
  GuidedImage image{w, h, 4, {}, {std::vector<float>(static_cast<std::size_t>(w) * h * 4)}, {}, {}};
  Random random(seed, 0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const double shading = 0.2 + 0.8 * std::exp(-((x - w / 2.0) * (x - w / 2.0) + (y - h / 3.0) * (y - h / 3.0)) / 400.0);
      const double ratios[4] = {1.0, 0.7, 0.4, x < w / 2 ? 0.5 : step_ratio};
      for (int b = 0; b < 4; ++b) {
        double v = shading * ratios[b];
        if (b == 3 && noise > 0) {
          const double u1 = 1.0 - random.uniform(), u2 = random.uniform();
          v *= 1.0 + noise * std::sqrt(-2 * std::log(u1)) * std::cos(2 * std::numbers::pi * u2);
        }
        image.layers[0][(static_cast<std::size_t>(y) * w + x) * 4 + b] = static_cast<float>(v);
      }
    }
  return image;
}

// Bands 0-2 guide band 3; the images here have no textures, so every layer may be reconstructed.
GuidedOptions options(bool unfactored_layers = true) {
  GuidedOptions o;
  o.guide_bands = {0, 1, 2};
  o.guided_bands = {3};
  o.unfactored_layers = unfactored_layers;
  return o;
}
const GuidedOptions kOptions = options();

TEST(Guided, ABandThatIsAMultipleOfTheGuideComesBackExactly) {
  GuidedImage image = shaded(64, 48, 0.5, 0.0, 1);
  const GuidedImage before = image;
  const GuidedReport report = reconstruct_guided(image, kOptions);
  ASSERT_EQ(report.verdicts.size(), 1u);
  EXPECT_FALSE(report.verdicts[0].refused);
  for (std::size_t i = 0; i < image.layers[0].size(); ++i)
    EXPECT_NEAR(image.layers[0][i], before.layers[0][i], 1e-6 * before.layers[0][i]) << i;
}

TEST(Guided, NoiseShrinksByTheWindowsAveraging) {
  // With a noiseless guide and a constant ratio, t̂ = g · Σt / Σg: the relative noise of a ratio over the window's
  // n = (2r + 1)² pixels, about noise / √n where the shading is nearly flat (the image's bottom rows).
  const double noise = 0.2;
  GuidedImage image = shaded(96, 96, 0.5, noise, 7);
  const GuidedImage clean = shaded(96, 96, 0.5, 0.0, 7);
  const GuidedReport report = reconstruct_guided(image, kOptions);
  EXPECT_EQ(report.refused(), 0u);
  double before = 0, after = 0, n = 0;
  for (int y = 70; y < 88; ++y)
    for (int x = 8; x < 88; ++x) {
      const std::size_t i = (static_cast<std::size_t>(y) * 96 + x) * 4 + 3;
      const double truth = clean.layers[0][i];
      after += std::pow(image.layers[0][i] / truth - 1, 2);
      before += noise * noise;
      n += 1;
    }
  const double window = std::pow(2.0 * kOptions.radius + 1, 2);
  // The relative variance after is noise² / window (within the scatter of its estimate over n correlated
  // pixels; bounded by twice that, and far below the noise before).
  EXPECT_LT(after / n, 2.0 * noise * noise / window);
  EXPECT_GT(after / n, 0.25 * noise * noise / window);
  EXPECT_NEAR(before / n, noise * noise, 1e-12);
}

TEST(Guided, AStepInTheRatioIsRefusedAndKeepsItsValues) {
  // Band 3's ratio jumps from 0.5 to 1.5 half-way across, which the guide does not show: the window straddling
  // the step gives a ratio between the two, many standard errors off.
  for (const std::uint64_t seed : {1, 2, 3}) {
    GuidedImage image = shaded(64, 64, 1.5, 0.05, seed);
    const GuidedImage before = image;
    const GuidedReport report = reconstruct_guided(image, kOptions);
    ASSERT_EQ(report.verdicts.size(), 1u);
    EXPECT_TRUE(report.verdicts[0].refused) << "|z| " << report.verdicts[0].worst_z;
    EXPECT_EQ(image.layers[0], before.layers[0]);
    // And the same noise with no step is kept.
    GuidedImage smooth = shaded(64, 64, 0.5, 0.05, seed);
    EXPECT_EQ(reconstruct_guided(smooth, kOptions).refused(), 0u);
  }
}

TEST(Guided, FamiliesAddUpToTheTotalAfterwards) {
  // Two lights' components, each a different multiple of a shading, with noise in band 3 of each: reconstructed
  // apart, they no longer sum to the total until reconciled.
  GuidedImage a = shaded(48, 48, 0.5, 0.1, 11), b = shaded(48, 48, 0.9, 0.1, 12);
  GuidedImage image{48, 48, 4, {"emission", "diffuse_direct", "diffuse_indirect", "glossy_direct", "glossy_indirect",
                                "light.a", "light.b"},
                    {}, std::vector<std::int32_t>(48 * 48, 1), {}};
  const std::vector<float> zero(a.layers[0].size(), 0.0f);
  std::vector<float> total(a.layers[0].size());
  for (std::size_t i = 0; i < total.size(); ++i) total[i] = a.layers[0][i] + b.layers[0][i];
  // The path types: all diffuse_direct; the light groups: a and b.
  image.layers = {total, zero, total, zero, zero, zero, a.layers[0], b.layers[0]};
  reconstruct_guided(image, kOptions);
  for (std::size_t i = 3; i < total.size(); i += 4) {
    EXPECT_FLOAT_EQ(image.layers[0][i], image.layers[2][i]) << i;  // the total is the path types' sum
    EXPECT_NEAR(image.layers[6][i] + image.layers[7][i], image.layers[0][i], 1e-6 * image.layers[0][i]) << i;
  }
}

TEST(Guided, ATextureIsCarriedByItsColourFactorNotGuessedFromTheGuide) {
  // A texture whose band 3 varies from pixel to pixel independently of bands 0-2 (as a red print on a grey card
  // does under lights the guide bands see alike): as a product, its ratio to the guide jumps from pixel to pixel
  // like noise, which the test cannot tell from noise, so an unfactored layer is not reconstructed unless asked;
  // as light × colour, only the smooth light is reconstructed, and comes back exactly, times each pixel's own
  // colour.
  const GuidedImage light = shaded(64, 48, 0.5, 0.0, 1);
  GuidedImage product = light, factored = light;
  factored.colours = {std::vector<float>(light.layers[0].size())};
  Random random(5, 0);
  for (std::size_t i = 0; i < light.layers[0].size(); ++i) {
    const float colour = i % 4 == 3 ? static_cast<float>(0.2 + 0.7 * random.uniform()) : 0.6f;
    factored.colours[0][i] = colour;
    product.layers[0][i] = light.layers[0][i] * colour;
  }
  const GuidedImage expected = product;
  // Unfactored, by default, the product is left as it is.
  EXPECT_EQ(reconstruct_guided(product, options(false)).verdicts.size(), 0u);
  EXPECT_EQ(product.layers, expected.layers);
  EXPECT_EQ(reconstruct_guided(factored, options(false)).refused(), 0u);
  EXPECT_TRUE(factored.colours.empty());
  for (std::size_t i = 0; i < expected.layers[0].size(); ++i)
    EXPECT_NEAR(factored.layers[0][i], expected.layers[0][i], 1e-6 * expected.layers[0][i]) << i;
}

TEST(Guided, PixelsOnAnEdgeBetweenObjectsKeepTheirValues) {
  // Two objects side by side under one light, band 3 noisy: a pixel on their edge mixes both, and keeps its own
  // value, as a product or as light × colour (whose averages over a pixel's samples multiply to a value that
  // depends on the samples where the colour changes within the pixel); the pixels beside it are reconstructed.
  const GuidedImage noisy = shaded(64, 48, 0.5, 0.2, 3);
  std::vector<std::int32_t> ids(64 * 48);
  for (std::size_t p = 0; p < ids.size(); ++p) ids[p] = p % 64 < 32 ? 1 : 2;
  GuidedImage factored = noisy, product = noisy;
  factored.object_ids = product.object_ids = ids;
  factored.colours = {std::vector<float>(noisy.layers[0].size(), 0.5f)};
  reconstruct_guided(factored, options(false));
  reconstruct_guided(product, options(true));
  for (int y = 8; y < 40; ++y)
    for (const int x : {29, 31, 32, 34}) {
      const std::size_t i = (static_cast<std::size_t>(y) * 64 + x) * 4 + 3;
      const bool edge = x == 31 || x == 32;
      EXPECT_EQ(product.layers[0][i] == noisy.layers[0][i], edge) << x << "," << y;
      EXPECT_EQ(factored.layers[0][i] == 0.5f * noisy.layers[0][i], edge) << x << "," << y;
    }
}

TEST(Guided, OptionsThatDoNotFitTheImageAreRefusedByName) {
  GuidedImage image = shaded(16, 16, 0.5, 0.0, 1);
  EXPECT_THROW(reconstruct_guided(image, GuidedOptions{{}, {3}}), std::invalid_argument);
  EXPECT_THROW(reconstruct_guided(image, GuidedOptions{{0, 1}, {4}}), std::invalid_argument);
  EXPECT_THROW(reconstruct_guided(image, GuidedOptions{{0, 1}, {1}}), std::invalid_argument);
}

TEST(Guided, ThresholdsAreTheNormalDistributions) {
  EXPECT_NEAR(two_sided_normal_threshold(0.05), 1.959964, 1e-6);
  EXPECT_NEAR(two_sided_normal_threshold(2.7e-3), 3.0, 2e-3);
  EXPECT_NEAR(two_sided_normal_threshold(1e-4), 3.890592, 1e-6);
}

}  // namespace
}  // namespace ct
