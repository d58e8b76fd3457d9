// SPDX-License-Identifier: Apache-2.0
// The simulator end to end: the output layout the analyzer relies on, streaming, determinism, supersampling,
// automatic exposure, and TIFF/PNG output.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include <OpenImageIO/imageio.h>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/spectral_exr.h"
#include "tests/core/spectral_exr_fixtures.h"
#include "tests/sensor_sim/sensor_test_util.h"

namespace ct {
namespace {

namespace fs = std::filesystem;

// The analyzer's contract (docs/sensor.md, "Output"): R, G, B; linear.R/G/B; <component>.R/G/B for each input
// component; display.R/G/B; object_id with chromatrace.objects; chromatrace.sensor, .components, .units,
// .display and the camera's numbers (black and white level, dark signal, read noise, bits, noise, ADC).
TEST(Pipeline, ExrOutputFollowsTheLayoutContract) {
  test::TempDir dir;
  const test::ComponentImage image = test::make_component_image(9, 7, 3);
  test::write_image(dir.file("in.exr"), image, 7);
  const Json patch = {{"exposure", {{"time_s", 0.05}}},
                      {"noise", {{"enabled", true}, {"read_e", 1.0}}},
                      {"adc", {{"enabled", true}, {"gain_dn_per_e", 0.01}, {"bits", 14}}}};
  const sensor::SensorConfig config = test::config_of(patch);
  test::run_sensor(dir.file("in.exr"), dir.file("out.exr"), config);

  SpectralExrReader reader(dir.file("out.exr"));
  const SpectralExrInfo& info = reader.info();
  std::vector<std::string> expected = {"R",        "G",        "B",         "linear.R",  "linear.G",
                                       "linear.B", "object_id", "display.R", "display.G", "display.B"};
  for (const std::string& c : image.layout.components)
    for (const char* rgb : {".R", ".G", ".B"}) expected.push_back(c + rgb);
  std::sort(expected.begin(), expected.end());
  std::vector<std::string> channels;
  for (const ExrChannel& c : info.channels) {
    channels.push_back(c.name);
    EXPECT_EQ(c.type, c.name.starts_with("display.") ? ExrPixelType::Half : ExrPixelType::Float) << c.name;
  }
  EXPECT_EQ(channels, expected);
  EXPECT_EQ(info.metadata.at("chromatrace.components"), fmt::format("{}", fmt::join(image.layout.components, ",")));
  EXPECT_EQ(info.object_names, image.layout.object_names);
  EXPECT_EQ(info.metadata.at("chromatrace.renderer"), "test");  // the renderer's description travels on
  std::vector<std::int32_t> ids(9 * 7);
  reader.read_object_ids(0, 7, ids);
  EXPECT_EQ(ids, image.object_ids);

  // chromatrace.sensor is the effective configuration: it reads back as the same settings.
  Json effective = Json::parse(info.metadata.at("chromatrace.sensor"));
  ASSERT_EQ(effective["notes"].size(), 1u);  // cos⁴ off: no camera in the header
  effective.erase("notes");
  Json again = sensor::config_json(test::config_of(effective));
  again.erase("notes");
  EXPECT_EQ(again.dump(), effective.dump());
  EXPECT_EQ(effective["adc"]["bits"], 14);
  const nlohmann::json units = nlohmann::json::parse(info.metadata.at("chromatrace.units"));
  EXPECT_EQ(units["RGB"]["unit"], "DN");
  EXPECT_EQ(units["linear"]["unit"], "e-");
  EXPECT_EQ(units["RGB"]["channels"], nlohmann::json({"X", "Y", "Z"}));
  // No full well: the white level is the ADC's top code; K·I_d·T = 0 without dark current; K·σ_read.
  EXPECT_EQ(info.metadata.at("chromatrace.black_level"), "0");
  EXPECT_EQ(info.metadata.at("chromatrace.white_level"), "16383");
  EXPECT_EQ(info.metadata.at("chromatrace.dark_signal"), "0");
  EXPECT_EQ(info.metadata.at("chromatrace.read_noise"), "0.01");
  EXPECT_EQ(info.metadata.at("chromatrace.bits"), "14");
  EXPECT_EQ(info.metadata.at("chromatrace.noise"), "1");
  EXPECT_EQ(info.metadata.at("chromatrace.adc"), "1");
  EXPECT_EQ(info.metadata.at("chromatrace.signal"), "DN");
  EXPECT_TRUE(nlohmann::json::parse(info.metadata.at("chromatrace.display")).contains("white_balance"));

  // Stages 1–3 are linear: the path types sum to the total's linear signal (float rounding of ~8 terms).
  const test::RgbLayer linear = test::read_rgb(dir.file("out.exr"), "linear");
  std::vector<test::RgbLayer> parts;
  for (const std::string& c : image.layout.components) parts.push_back(test::read_rgb(dir.file("out.exr"), c));
  for (std::size_t i = 0; i < linear.values.size(); ++i) {
    double sum = 0;
    for (const auto& p : parts) sum += p.values[i];
    EXPECT_NEAR(sum / linear.values[i], 1.0, 1e-5);
  }
}

TEST(Pipeline, ThreadsAndBlocksDoNotChangeAnyLayer) {
  test::TempDir dir;
  const test::ComponentImage image = test::make_component_image(22, 19, 9);
  test::write_image(dir.file("in.exr"), image, 19);
  const Json patch = {{"preset", "smartphone"},
                      {"spectral_response", {{"camera", "sony_ilce_9"}}},
                      {"exposure", {{"time_s", "auto"}}},
                      {"pixel", {{"supersample", 2}}},
                      {"optics", {{"fov_deg", 50}}},
                      {"rendering", {{"enabled", true}, {"curve", "srgb"}, {"white_balance", "D65"}}}};
  const sensor::SensorConfig config = test::config_of(patch);
  test::run_sensor(dir.file("in.exr"), dir.file("a.exr"), config, 1, 100);
  test::run_sensor(dir.file("in.exr"), dir.file("b.exr"), config, 2, 1);
  test::run_sensor(dir.file("in.exr"), dir.file("c.exr"), config, 2, 4);
  for (const std::string layer : {"", "linear", "glossy_direct", "display"}) {
    const auto a = test::read_rgb(dir.file("a.exr"), layer).values;
    EXPECT_EQ(a, test::read_rgb(dir.file("b.exr"), layer).values) << layer;
    EXPECT_EQ(a, test::read_rgb(dir.file("c.exr"), layer).values) << layer;
  }
  // Another noise seed is another frame.
  sensor::SensorConfig other = config;
  other.noise.seed = 1;
  test::run_sensor(dir.file("in.exr"), dir.file("d.exr"), other);
  EXPECT_NE(test::read_rgb(dir.file("a.exr")).values, test::read_rgb(dir.file("d.exr")).values);
}

// k×k rendered pixels average into one sensor pixel (cos⁴ off); the odd last column is dropped; a sensor
// pixel's object id is the most frequent of its rendered pixels.
TEST(Pipeline, SupersamplingAveragesRenderedPixels) {
  test::TempDir dir;
  const Bands bands = Bands::uniform(500, 600, 100);
  test::write_radiance(dir.file("in.exr"), bands, 5, 4,
                       [](int x, int y, std::size_t) { return static_cast<float>(1 + x + 10 * y); });
  test::run_sensor(dir.file("in.exr"), dir.file("one.exr"), test::config_of(Json::object()));
  const auto report =
      test::run_sensor(dir.file("in.exr"), dir.file("two.exr"), test::config_of({{"pixel", {{"supersample", 2}}}}));
  const test::RgbLayer one = test::read_rgb(dir.file("one.exr")), two = test::read_rgb(dir.file("two.exr"));
  ASSERT_EQ(two.width, 2);
  ASSERT_EQ(two.height, 2);
  EXPECT_NE(std::find(report.notes.begin(), report.notes.end(),
                      "supersample 2: the last 1 column(s) and 0 row(s) are dropped"),
            report.notes.end());
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 2; ++x)
      for (int c = 0; c < 3; ++c) {
        const double mean = (one.at(2 * x, 2 * y, c) + one.at(2 * x + 1, 2 * y, c) + one.at(2 * x, 2 * y + 1, c) +
                             one.at(2 * x + 1, 2 * y + 1, c)) /
                            4;
        EXPECT_NEAR(two.at(x, y, c) / mean, 1.0, 1e-6);
      }

  test::ComponentImage ids = test::make_component_image(4, 2, 1);
  ids.object_ids = {5, 5, 1, 2, 5, 3, 2, 1};  // blocks {5, 5, 5, 3} and {1, 2, 2, 1}
  test::write_image(dir.file("ids.exr"), ids, 2);
  test::run_sensor(dir.file("ids.exr"), dir.file("ids_out.exr"), test::config_of({{"pixel", {{"supersample", 2}}}}));
  SpectralExrReader reader(dir.file("ids_out.exr"));
  std::vector<std::int32_t> out(2);
  reader.read_object_ids(0, 1, out);
  EXPECT_EQ(out, (std::vector<std::int32_t>{5, 1}));
}

// Automatic exposure puts the chosen percentile of the brightest channel at `auto_level` of saturation.
TEST(Pipeline, AutoExposureReachesTheRequestedLevel) {
  test::TempDir dir;
  const Bands bands = Bands::uniform(400, 700, 30);
  constexpr int n = 100;
  test::write_radiance(dir.file("ramp.exr"), bands, n, 1, [](int x, int, std::size_t) { return float(x + 1); });
  const Json patch = {{"exposure", {{"time_s", "auto"}, {"auto_percentile", 50}, {"auto_level", 0.5}}},
                      {"full_well", {{"enabled", true}, {"electrons", 8000}}}};
  const auto report = test::run_sensor(dir.file("ramp.exr"), dir.file("out.exr"), test::config_of(patch));
  const test::RgbLayer linear = test::read_rgb(dir.file("out.exr"), "linear");
  // The 50th percentile (nearest rank below, index ⌊0.5·99⌋ = 49) is pixel 49 (radiance 50): brightest channel
  // at 4000 e⁻.
  const double brightest = std::max({linear.at(49, 0, 0), linear.at(49, 0, 1), linear.at(49, 0, 2)});
  EXPECT_NEAR(brightest, 4000.0, 4000.0 * 1e-6);
  EXPECT_GT(report.exposure_s, 0);
  // "scale" multiplies the automatic time.
  Json doubled = patch;
  doubled["exposure"]["scale"] = 2.0;
  const auto twice = test::run_sensor(dir.file("ramp.exr"), dir.file("out2.exr"), test::config_of(doubled));
  EXPECT_NEAR(twice.exposure_s / report.exposure_s, 2.0, 1e-12);
}

std::vector<unsigned char> bytes_of(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

// PNG and TIFF hold the final image only: 16-bit digital numbers unchanged, or rendered values in 8/16 bits; a
// PNG without a rendering intent holds the display rendering.
TEST(Pipeline, TiffAndPngHoldTheFinalImage) {
  test::TempDir dir;
  test::write_radiance(dir.file("in.exr"), Bands::uniform(400, 700, 100), 6, 4, [](int x, int y, std::size_t b) {
    return static_cast<float>(0.1 * (x + 1) + 0.05 * y + 0.01 * static_cast<double>(b));
  });
  const Json raw = {{"adc", {{"enabled", true}, {"gain_dn_per_e", 1e-3}, {"black_level_dn", 64}, {"bits", 12}}}};
  test::run_sensor(dir.file("in.exr"), dir.file("raw.tif"), test::config_of(raw));
  test::run_sensor(dir.file("in.exr"), dir.file("raw.exr"), test::config_of(raw));
  const test::RgbLayer dn = test::read_rgb(dir.file("raw.exr"));
  auto tif = OIIO::ImageInput::open(dir.file("raw.tif").string());
  ASSERT_TRUE(tif);
  EXPECT_EQ(tif->spec().format, OIIO::TypeDesc::UINT16);
  std::vector<std::uint16_t> codes(dn.values.size());
  ASSERT_TRUE(tif->read_image(0, 0, 0, 3, OIIO::TypeDesc::UINT16, codes.data()));
  EXPECT_EQ(std::vector<float>(codes.begin(), codes.end()), dn.values);
  EXPECT_GT(*std::max_element(codes.begin(), codes.end()), 64);

  Json rendered = raw;
  rendered["rendering"] = {{"enabled", true}, {"curve", "srgb"}};
  test::run_sensor(dir.file("in.exr"), dir.file("out.png"), test::config_of(rendered));
  const std::vector<unsigned char> png = bytes_of(dir.file("out.png"));
  ASSERT_GE(png.size(), 26u);
  EXPECT_EQ(std::string(png.begin() + 1, png.begin() + 4), "PNG");
  EXPECT_EQ(png[24], 8);  // bit depth in IHDR
  rendered["rendering"]["output_bits"] = 16;
  test::run_sensor(dir.file("in.exr"), dir.file("out16.png"), test::config_of(rendered));
  EXPECT_EQ(bytes_of(dir.file("out16.png"))[24], 16);

  // Without a rendering intent of the user's, a PNG is the picture for people: the display rendering, as the
  // EXR's display layer holds it (there as half floats, so a code may differ by one where half rounding meets
  // a code's edge).
  test::run_sensor(dir.file("in.exr"), dir.file("picture.png"), test::config_of(raw));
  auto picture = OIIO::ImageInput::open(dir.file("picture.png").string());
  ASSERT_TRUE(picture);
  EXPECT_EQ(picture->spec().format, OIIO::TypeDesc::UINT8);
  std::vector<std::uint8_t> shown(dn.values.size());
  ASSERT_TRUE(picture->read_image(0, 0, 0, 3, OIIO::TypeDesc::UINT8, shown.data()));
  const test::RgbLayer display = test::read_rgb(dir.file("raw.exr"), "display");
  ASSERT_EQ(display.values.size(), shown.size());
  for (std::size_t i = 0; i < shown.size(); ++i)
    EXPECT_LE(std::abs(int(shown[i]) - int(std::lround(255 * display.values[i]))), 1) << i;

  // In electrons with the display rendering off there are no codes to store: an error naming the file, and no
  // file.
  try {
    test::run_sensor(dir.file("in.exr"), dir.file("e.png"), test::config_of({{"display", {{"enabled", false}}}}));
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("e.png: a TIFF or PNG holds integer codes"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(dir.file("e.png")));
}

}  // namespace
}  // namespace ct
