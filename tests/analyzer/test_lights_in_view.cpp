// SPDX-License-Identifier: Apache-2.0
// Lights seen directly (analyzer/lights_in_view.h) on synthetic images whose lights are known: a lamp far brighter
// than the surfaces it lights is found with its margin, a white surface never is — also where a dark background holds
// the image's median down, so that only the 95th percentile shows the level of the lit surfaces.
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "analyzer/lights_in_view.h"

namespace ct::test {
namespace {

using analyzer::find_lights_in_view;
using analyzer::kLightMargin;
using analyzer::kLightOverLit;
using analyzer::kLightSeed;
using analyzer::LightsInView;
using analyzer::RgbImage;

// A width × height image of grey `level` (each pixel ± 10 %, uniformly, seeded), with rectangles painted over it.
struct Painter {
  RgbImage image;
  Painter(int width, int height, float level) {
    image.width = width, image.height = height;
    image.rgb.resize(3 * image.pixel_count());
    std::mt19937 generator(7);
    std::uniform_real_distribution<float> jitter(0.9f, 1.1f);
    for (float& v : image.rgb) v = level * jitter(generator);
  }
  // Fills [x0, x1) × [y0, y1) with one colour.
  void fill(int x0, int y0, int x1, int y1, float r, float g, float b) {
    for (int y = y0; y < y1; ++y)
      for (int x = x0; x < x1; ++x) {
        float* p = &image.rgb[3 * (static_cast<std::size_t>(y) * static_cast<std::size_t>(image.width) + static_cast<std::size_t>(x))];
        p[0] = r, p[1] = g, p[2] = b;
      }
  }
};

// Pixels of a w × h rectangle grown by the margin: OpenCV's 5 × 5 ellipse (a margin of 2) reaches 2 pixels sideways
// on its three middle rows and 2 up and down only in its middle column, so the rectangle grows to (w + 4)(h + 2)
// pixels and a row of w above and below.
std::size_t with_margin(int w, int h) {
  static_assert(kLightMargin == 2, "the count is worked out for a margin of 2");
  return static_cast<std::size_t>((w + 4) * (h + 2) + 2 * w);
}

TEST(LightsInView, ALampIsFoundWithItsMarginAndAWhiteSurfaceIsNot) {
  // A grey room at 0.1 with a white sheet at 0.9 (9 × the median, a white surface's ratio at most a few tens) and a
  // lamp of 6 × 4 pixels at 1000 × the median, of a warm colour.
  Painter p(200, 100, 0.1f);
  p.fill(20, 20, 60, 60, 0.9f, 0.9f, 0.9f);
  p.fill(120, 40, 126, 44, 120.0f, 100.0f, 80.0f);
  const LightsInView found = find_lights_in_view(p.image, {});
  ASSERT_EQ(found.lights.size(), 1u);
  const auto& lamp = found.lights.front();
  EXPECT_GE(lamp.x, 120);
  EXPECT_LT(lamp.x, 126);
  EXPECT_EQ(lamp.pixels, with_margin(6, 4));
  // Its colour is the mean of its pixels': the lamp's own with the room's grey in the margin.
  const double grey = 0.1, lamp_pixels = 24, margin_pixels = static_cast<double>(with_margin(6, 4)) - lamp_pixels;
  const analyzer::Vec3 expected = (lamp_pixels * analyzer::Vec3(120, 100, 80) + margin_pixels * analyzer::Vec3(grey, grey, grey)).normalized();
  EXPECT_LT((lamp.rgb - expected).norm(), 1e-3);  // the margin's ± 10 % moves it by under 1e-4
  for (int y = 20; y < 60; ++y)
    for (int x = 20; x < 60; ++x) EXPECT_EQ(found.mask[static_cast<std::size_t>(y * 200 + x)], 0);
}

TEST(LightsInView, ADarkBackgroundDoesNotMakeTheLitSurfacesLights) {
  // A night scene: 90 % of the frame a background at 0.001 (above black), 8 % a white napkin at 0.5 — 500 × the
  // median, which the median alone would call a light — and 2 % a flame at 50, 100 × the napkin.
  Painter p(100, 100, 0.001f);
  p.fill(0, 0, 100, 8, 0.5f, 0.45f, 0.4f);   // the napkin: rows 0–7
  p.fill(40, 50, 60, 60, 50.0f, 40.0f, 20.0f);  // the flame: 20 × 10 pixels, 2 %
  const LightsInView found = find_lights_in_view(p.image, {});
  EXPECT_GE(0.5 / found.median_brightness, kLightSeed);     // the median alone would call the napkin a light
  EXPECT_NEAR(found.lit_brightness, 0.45, 1e-6);            // the 95th percentile lies on the napkin
  EXPECT_DOUBLE_EQ(found.seed_level, kLightOverLit * found.lit_brightness);
  ASSERT_EQ(found.lights.size(), 1u);
  EXPECT_GE(found.lights.front().y, 50);
  EXPECT_EQ(found.lights.front().pixels, with_margin(20, 10));
  for (std::size_t q = 0; q < 800; ++q) EXPECT_EQ(found.mask[q], 0) << "the napkin's pixel " << q;
}

// A lamp that reaches a channel's clipping level has lost that channel's top: its pixels there are counted, and it is
// no reference.
TEST(LightsInView, AClippedLampCountsItsClippedPixels) {
  Painter p(200, 100, 0.1f);
  p.fill(120, 40, 126, 44, 120.0f, 100.0f, 80.0f);
  EXPECT_EQ(find_lights_in_view(p.image, {}).lights.front().clipped, 0u);  // no level known: nothing clipped
  const LightsInView found = find_lights_in_view(p.image, {}, {110.0, 1e9, 1e9});
  ASSERT_EQ(found.lights.size(), 1u);
  EXPECT_EQ(found.lights.front().clipped, 24u);  // the lamp's 6 × 4 pixels reach red's level, its margin does not
}

TEST(LightsInView, NoLightInAFlatImage) {
  Painter p(50, 50, 0.2f);
  const LightsInView found = find_lights_in_view(p.image, {});
  EXPECT_TRUE(found.lights.empty());
  EXPECT_NEAR(found.median_brightness, 0.2, 0.2 * 0.1);
}

}  // namespace
}  // namespace ct::test
