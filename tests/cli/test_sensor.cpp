// SPDX-License-Identifier: Apache-2.0
// `chromatrace sensor` end to end: outputs in each format, and bad input.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <future>
#include <limits>

#include <nlohmann/json.hpp>

#include "core/spectral_exr.h"
#include "tests/cli/run_command.h"
#include "tests/cli/text_files.h"
#include "tests/core/spectral_exr_fixtures.h"

namespace ct {
namespace {

namespace fs = std::filesystem;
using test::run_chromatrace;

const fs::path kD65Emissive = fs::path(CHROMATRACE_TEST_DATA) / "spectral_exr_samples" / "spectral-exr_D65_emissive.exr";
const fs::path kMacbeth =
    fs::path(CHROMATRACE_TEST_DATA) / "spectral_exr_samples" / "spectral-exr_Macbeth_reflective.exr";

using test::line_count;

class SensorCommand : public ::testing::Test {
 protected:
  void SetUp() override {
    test::ComponentImage image = test::make_component_image(16, 12, 5);
    image.layout.attributes["chromatrace.camera"] =
        R"({"horizontal_fov_deg": 50, "vertical_fov_deg": 38.6, "resolution": [16, 12]})";
    input_ = inputs_.file("scene.exr");
    test::write_image(input_, image, 12);
  }
  test::TempDir inputs_, outputs_;
  fs::path input_;
};

TEST_F(SensorCommand, WritesExrTiffAndPng) {
  const fs::path exr = outputs_.file("camera.exr");
  const auto r = run_chromatrace({"sensor", input_.string(), "-o", exr.string(), "--preset", "canon_eos_5d_mkiii",
                                  "--exposure-s", "auto", "--seed", "3", "--quiet"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err, "");
  SpectralExrReader reader(exr);
  const SpectralExrInfo& info = reader.info();
  EXPECT_EQ(info.width, 16);
  EXPECT_TRUE(info.has_object_ids);
  for (const char* channel : {"R", "linear.G", "emission.B", "glossy_indirect.R"})
    EXPECT_TRUE(std::any_of(info.channels.begin(), info.channels.end(), [&](auto& c) { return c.name == channel; }))
        << channel;
  const auto sensor = nlohmann::json::parse(info.metadata.at("chromatrace.sensor"));
  EXPECT_EQ(sensor["preset"], "canon_eos_5d_mkiii");
  EXPECT_EQ(sensor["noise"]["seed"], 3);
  EXPECT_TRUE(sensor["exposure"]["time_s"].is_number());  // "auto", resolved

  const auto tif = run_chromatrace({"sensor", input_.string(), "-o", outputs_.file("camera.tif").string(), "--preset",
                                    "canon_eos_5d_mkiii", "--exposure-s", "auto", "--quiet"});
  EXPECT_EQ(tif.exit_code, 0) << tif.err;
  const auto png = run_chromatrace({"sensor", input_.string(), "-o", outputs_.file("camera.png").string(), "--preset",
                                    "smartphone", "--exposure-s", "auto", "--set", "rendering.enabled=true", "--set",
                                    "rendering.curve=srgb", "--set", "rendering.white_balance=\"D65\""});
  EXPECT_EQ(png.exit_code, 0) << png.err;
  EXPECT_NE(png.err.find("camera.png: 16x12 pixels"), std::string::npos) << png.err;
  EXPECT_TRUE(fs::exists(outputs_.file("camera.tif")) && fs::exists(outputs_.file("camera.png")));
}

TEST_F(SensorCommand, PrintsTheEffectiveConfiguration) {
  const auto r = run_chromatrace({"sensor", "--preset", "machine_vision_ccd", "--f-number", "2.8", "--print-config"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto config = nlohmann::json::parse(r.out);
  EXPECT_EQ(config["format"], "chromatrace-sensor/1");
  EXPECT_EQ(config["optics"]["f_number"], 2.8);
  EXPECT_EQ(config["adc"]["bits"], 12);
}

TEST_F(SensorCommand, BadInputGetsExitTwoAndOneLineNamingTheField) {
  const fs::path out = outputs_.file("out.exr");
  const fs::path rgb = inputs_.file("rgb.exr");
  test::write_raw_exr(rgb, 4, 4,
                      {test::constant_channel("R", 4, 4, 1), test::constant_channel("G", 4, 4, 1),
                       test::constant_channel("B", 4, 4, 1)});
  const fs::path nan = inputs_.file("nan.exr");
  std::vector<test::RawChannel> channels = {test::constant_channel("S0.500,000000nm", 4, 4, 1),
                                            test::constant_channel("S0.600,000000nm", 4, 4, 1)};
  channels[1].values[7] = std::numeric_limits<float>::quiet_NaN();
  test::write_raw_exr(nan, 4, 4, channels);
  const fs::path config = inputs_.file("sensor.json");
  std::ofstream(config) << R"({"noise": {"enabled": true, "read_noise": 3}})";
  const std::string in = input_.string();
  struct Case {
    std::vector<std::string> args;
    std::string must_mention;
  };
  const std::vector<Case> cases = {
      {{"sensor", rgb.string(), "-o", out.string()}, "rgb.exr: no spectral channels"},
      {{"sensor", kMacbeth.string(), "-o", out.string()}, "channels S0.<λ>nm: missing"},
      // Found while the pixels stream: after the progress bar's line, unless --quiet.
      {{"sensor", nan.string(), "-o", out.string(), "--quiet"},
       "nan.exr: channel S0.600,000000nm: value nan at pixel (3, 1) is not finite"},
      {{"sensor", kD65Emissive.string(), "-o", out.string(), "--camera", "nikon_d850"},
       "spectral-exr_D65_emissive.exr: bands 377.5-827.5 nm reach outside the camera curves of nikon_d850"},
      {{"sensor", in, "-o", out.string(), "--camera", "leica_m"}, "--camera: spectral_response.camera: unknown camera"},
      {{"sensor", in, "-o", out.string(), "--exposure-s", "-1"}, "--exposure-s: exposure.time_s: must be > 0"},
      {{"sensor", in, "-o", out.string(), "--exposure-s", "soon"}, "--exposure-s: must be a time in seconds"},
      {{"sensor", in, "-o", out.string(), "--set", "adc.bits=40"}, "--set adc.bits=40: adc.bits: must be <= 32"},
      {{"sensor", in, "-o", out.string(), "--preset", "hubble"}, "--preset: preset: unknown preset \"hubble\""},
      {{"sensor", in, "-o", out.string(), "--config", config.string()}, "sensor.json: noise.read_noise: unknown key"},
      {{"sensor", in, "-o", out.string(), "--cfa", "RGBG"}, "--cfa: cfa.pattern: must be one of"},
      {{"sensor", in, "-o", out.string(), "--set", "noise"}, "--set noise: expected KEY=VALUE"},
      {{"sensor", (inputs_.path() / "missing.exr").string(), "-o", out.string()}, "missing.exr"},
      {{"sensor", in, "-o", outputs_.file("out.jpg").string()}, "out.jpg: unknown output format"},
      {{"sensor", in, "-o", outputs_.file("e.png").string(), "--set", "display.enabled=false"},
       "e.png: a TIFF or PNG holds integer codes"},
      {{"sensor", in, "-o", (outputs_.path() / "no/such/dir/out.exr").string()}, "does not exist"},
      {{"sensor", in, "-o", out.string(), "--threads", "-2"}, "--threads"},
      {{"sensor", in}, "--output"},
  };
  // Run side by side: each start of the executable costs a few tenths of a second of dynamic linking.
  std::vector<std::future<test::CommandResult>> results;
  for (const Case& c : cases) results.push_back(std::async(std::launch::async, run_chromatrace, c.args));
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const Case& c = cases[i];
    const auto r = results[i].get();
    EXPECT_EQ(r.exit_code, 2) << c.must_mention << ": " << r.err;
    EXPECT_EQ(line_count(r.err), 1) << r.err;
    EXPECT_NE(r.err.find(c.must_mention), std::string::npos) << r.err;
  }
  // Nothing half-written is left in the output directory.
  EXPECT_TRUE(fs::is_empty(outputs_.path()));
}

// check-scene reads a series' sensor settings with the simulator's parser.
TEST_F(SensorCommand, CheckSceneValidatesASeriesSensorSettings) {
  const fs::path series = inputs_.file("series.json");
  std::ofstream(series) << R"({"format": "chromatrace-series/1", "base": ")"
                        << (fs::path(CHROMATRACE_TEST_DATA) / "scenes" / "minimal.json").string() << R"(",
    "variants": [{"name": "ok", "sensor": {"rendering": {"enabled": true, "gamma": 0.45}}},
                 {"name": "bad", "extends": "ok", "sensor": {"adc": {"bits": 64}}}]})";
  const auto r = run_chromatrace({"check-scene", series.string()});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("series.json: variants[1] \"bad\" sensor: adc.bits: must be <= 32, got 64"), std::string::npos)
      << r.err;
  EXPECT_EQ(line_count(r.err), 1) << r.err;
}

}  // namespace
}  // namespace ct
