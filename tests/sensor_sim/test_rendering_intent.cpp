// SPDX-License-Identifier: Apache-2.0
// Stage 6 and clipping: what the response curve does to histogram lines, and where over-exposure puts pixels.
#include <gtest/gtest.h>

#include <cmath>

#include "core/colour.h"
#include "core/spectral_exr.h"
#include "sensor_sim/rendering_intent.h"
#include "tests/core/spectral_exr_fixtures.h"
#include "tests/sensor_sim/sensor_test_util.h"

namespace ct {
namespace {

using Eigen::Vector3d;

sensor::RenderingIntent gamma_intent(double gamma) {
  sensor::RenderingIntent intent;
  intent.curve = sensor::ResponseCurve::Gamma;
  intent.gamma = gamma;
  intent.k = 1.3;
  intent.clip = false;
  return intent;
}

// Points t·d of a line through the origin become k·t^γ·d^γ (per channel): in log space log v_c = log k +
// γ log t + γ log d_c, parallel lines, so every log-ratio between channels is the same for every t — the
// image is again a line through the origin, only turned.
TEST(RenderingIntent, GammaKeepsALineThroughTheOriginALine) {
  const sensor::RenderingIntent intent = gamma_intent(0.45);
  const Vector3d d(0.8, 0.5, 0.2);
  const Vector3d first = sensor::render(intent, 0.01 * d);
  for (double t = 0.01; t <= 1.0; t += 0.07) {
    const Vector3d v = sensor::render(intent, t * d);
    EXPECT_NEAR(std::log(v[0] / v[1]), std::log(first[0] / first[1]), 1e-12);
    EXPECT_NEAR(std::log(v[2] / v[1]), std::log(first[2] / first[1]), 1e-12);
    EXPECT_NEAR(std::log(v[1]), std::log(1.3) + 0.45 * std::log(t * 0.5), 1e-12);
  }
}

// A line that misses the origin, o + t·d, does not stay a line: the log-ratios drift with t, by
// γ·(log((o_r + t d_r)/(o_g + t d_g)) − the same at t₀), which the test predicts exactly.
TEST(RenderingIntent, GammaBendsALineOffsetFromTheOrigin) {
  const sensor::RenderingIntent intent = gamma_intent(0.45);
  const Vector3d o(0.1, 0.1, 0.1), d(0.8, 0.5, 0.2);
  const Vector3d a = sensor::render(intent, o + 0.05 * d), b = sensor::render(intent, o + 0.9 * d);
  const double drift = std::log(b[0] / b[1]) - std::log(a[0] / a[1]);
  const double expected =
      0.45 * (std::log((0.1 + 0.9 * 0.8) / (0.1 + 0.9 * 0.5)) - std::log((0.1 + 0.05 * 0.8) / (0.1 + 0.05 * 0.5)));
  EXPECT_NEAR(drift, expected, 1e-12);
  EXPECT_GT(std::abs(drift), 0.1);  // a visible bend, not rounding
  // Halfway between the ends the curve leaves the chord: the bend of a cluster.
  const Vector3d mid = sensor::render(intent, o + 0.475 * d);
  EXPECT_GT((mid - (a + b) / 2).norm(), 1e-3);
}

TEST(RenderingIntent, SrgbCurveQuantisationAndWhiteBalance) {
  sensor::RenderingIntent intent;
  intent.curve = sensor::ResponseCurve::Srgb;
  intent.white = 200.0;
  intent.gains = Vector3d(2.0, 1.0, 0.5);
  intent.output_bits = 8;
  const Vector3d v = sensor::render(intent, Vector3d(20, 50, 300));
  EXPECT_DOUBLE_EQ(v[0], std::round(srgb_encode(0.2) * 255) / 255);
  EXPECT_DOUBLE_EQ(v[1], std::round(srgb_encode(0.25) * 255) / 255);
  EXPECT_DOUBLE_EQ(v[2], std::round(srgb_encode(0.75) * 255) / 255);
  intent.output_bits.reset();
  intent.matrix << 0, 1, 0, 1, 0, 0, 0, 0, 1;
  EXPECT_DOUBLE_EQ(sensor::render(intent, Vector3d(20, 50, 300))[0], srgb_encode(0.25));
}

// An over-exposed chart: each channel whose noise-free signal would exceed the ADC's range reads the top code
// (a face of the RGB cube), the others keep their values; so a red patch lands on the R = max face, a white one
// in the corner. Checked channel by channel against the linear signal.
TEST(RenderingIntent, OverExposureClipsOntoTheRightFacesOfTheCube) {
  test::TempDir dir;
  const Bands bands = Bands::uniform(400, 700, 100);  // blue, green, red thirds
  const float patches[4][3] = {{0.05f, 0.1f, 3.0f}, {0.05f, 3.0f, 0.1f}, {3.0f, 3.0f, 3.0f}, {0.2f, 0.2f, 0.2f}};
  test::write_radiance(dir.file("chart.exr"), bands, 4, 1, [&](int x, int, std::size_t b) { return patches[x][b]; });
  const Json patch = {{"spectral_response", {{"camera", "nikon_d850"}, {"outside_curve", "zero"}}},
                      {"exposure", {{"time_s", 0.02}}},
                      {"adc", {{"enabled", true}, {"gain_dn_per_e", 0.001}, {"black_level_dn", 0}, {"bits", 12}}}};
  test::run_sensor(dir.file("chart.exr"), dir.file("raw.exr"), test::config_of(patch));
  const test::RgbLayer raw = test::read_rgb(dir.file("raw.exr")),
                       linear = test::read_rgb(dir.file("raw.exr"), "linear");
  int clipped = 0, kept = 0;
  for (int x = 0; x < 4; ++x)
    for (int c = 0; c < 3; ++c) {
      const double analogue = 0.001 * linear.at(x, 0, c);
      if (analogue > 4095.5) {
        EXPECT_EQ(raw.at(x, 0, c), 4095.0f) << x << "," << c;
        ++clipped;
      } else {
        EXPECT_EQ(raw.at(x, 0, c), std::floor(analogue + 0.5)) << x << "," << c;
        ++kept;
      }
    }
  // The chart is exposed so that both happen: the red patch's R, the green patch's G and all of white clip,
  // grey and the weaker channels of the coloured patches do not.
  EXPECT_GE(clipped, 5);
  EXPECT_GE(kept, 3);
  EXPECT_EQ(raw.at(0, 0, 0), 4095.0f);
  EXPECT_EQ(raw.at(1, 0, 1), 4095.0f);

  // Through the rendering intent the same pixels sit on the faces of the unit cube.
  Json rendered = patch;
  rendered["rendering"] = {{"enabled", true}, {"curve", "gamma"}, {"gamma", 0.45}};
  test::run_sensor(dir.file("chart.exr"), dir.file("out.exr"), test::config_of(rendered));
  const test::RgbLayer out = test::read_rgb(dir.file("out.exr"));
  for (int x = 0; x < 4; ++x)
    for (int c = 0; c < 3; ++c) {
      EXPECT_EQ(out.at(x, 0, c) == 1.0f, raw.at(x, 0, c) == 4095.0f) << x << "," << c;
      EXPECT_NEAR(out.at(x, 0, c), std::pow(raw.at(x, 0, c) / 4095.0, 0.45), 1e-6);
    }
}

}  // namespace
}  // namespace ct
