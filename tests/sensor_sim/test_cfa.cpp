// SPDX-License-Identifier: Apache-2.0
// Stage 4: the Bayer pattern, OpenCV's demosaicing, and blocks that overlap so that their borders do not show.
#include <gtest/gtest.h>

#include <cmath>

#include "sensor_sim/cfa.h"
#include "tests/core/spectral_exr_fixtures.h"
#include "tests/sensor_sim/sensor_test_util.h"

namespace ct {
namespace {

using sensor::BayerPattern;
using sensor::DemosaicMethod;

TEST(Cfa, PatternsNameTheTopLeftTileRowByRow) {
  const struct {
    BayerPattern pattern;
    int tile[2][2];
  } cases[] = {{BayerPattern::RGGB, {{0, 1}, {1, 2}}},
               {BayerPattern::BGGR, {{2, 1}, {1, 0}}},
               {BayerPattern::GRBG, {{1, 0}, {2, 1}}},
               {BayerPattern::GBRG, {{1, 2}, {0, 1}}}};
  for (const auto& c : cases)
    for (int y = 0; y < 6; ++y)
      for (int x = 0; x < 6; ++x) EXPECT_EQ(sensor::cfa_channel(c.pattern, x, y), c.tile[y % 2][x % 2]);
}

// A uniform colour is what every method must give back exactly, whichever row the block starts on (the
// pattern's phase) — which also shows that each pattern reaches OpenCV under the right name.
TEST(Cfa, UniformColourSurvivesMosaicAndDemosaicing) {
  const float colour[3] = {200, 120, 40};
  constexpr int width = 12, rows = 10;
  for (const BayerPattern pattern : {BayerPattern::RGGB, BayerPattern::BGGR, BayerPattern::GRBG, BayerPattern::GBRG})
    for (const DemosaicMethod method : {DemosaicMethod::Bilinear, DemosaicMethod::Vng, DemosaicMethod::EdgeAware})
      for (const int y0 : {0, 1}) {
        std::vector<float> mosaic(width * rows), rgb(width * rows * 3);
        for (int y = 0; y < rows; ++y)
          for (int x = 0; x < width; ++x) mosaic[y * width + x] = colour[sensor::cfa_channel(pattern, x, y0 + y)];
        sensor::demosaic(mosaic, width, rows, y0, pattern, method, 8, rgb);
        for (int y = 2; y < rows - 2; ++y)
          for (int x = 2; x < width - 2; ++x)
            for (int c = 0; c < 3; ++c)
              ASSERT_EQ(rgb[(y * width + x) * 3 + c], colour[c])
                  << sensor::pattern_name(pattern) << " " << sensor::demosaic_name(method) << " y0=" << y0 << " at "
                  << x << "," << y << " channel " << c;
      }
}

// Demosaicing reads neighbouring rows, so the simulator demosaics each block with the context rows of
// demosaic_context: the image must not depend on where the blocks end, for any method, with noise and a
// textured scene.
TEST(Cfa, BlockSizeDoesNotChangeTheImage) {
  test::TempDir dir;
  const Bands bands = Bands::uniform(400, 700, 50);
  constexpr int width = 40, height = 37;
  test::write_radiance(dir.file("in.exr"), bands, width, height, [](int x, int y, std::size_t b) {
    return static_cast<float>(1.0 +
                              std::sin(0.7 * x + 1.3 * y + static_cast<double>(b)) * ((x / 5 + y / 4) % 2 ? 0.9 : 0.3));
  });
  for (const std::string method : {"bilinear", "vng", "edge_aware"}) {
    const Json patch = {{"spectral_response", {{"camera", "canon_eos_5d"}}},
                        {"exposure", {{"time_s", "auto"}}},
                        {"cfa", {{"enabled", true}, {"pattern", "GRBG"}, {"demosaic", method}}},
                        {"noise", {{"enabled", true}, {"read_e", 2.0}}},
                        {"adc", {{"enabled", true}, {"bits", method == "vng" ? 8 : 12}, {"gain_dn_per_e", 0.05}}}};
    const sensor::SensorConfig config = test::config_of(patch);
    test::run_sensor(dir.file("in.exr"), dir.file("whole.exr"), config, 1, height);
    const test::RgbLayer whole = test::read_rgb(dir.file("whole.exr"));
    for (const int rows : {1, 2, 3, 5, 8}) {
      std::filesystem::remove(dir.file("blocks.exr"));
      test::run_sensor(dir.file("in.exr"), dir.file("blocks.exr"), config, 2, rows);
      EXPECT_EQ(test::read_rgb(dir.file("blocks.exr")).values, whole.values) << method << ", " << rows << " rows";
    }
  }
}

}  // namespace
}  // namespace ct
