// SPDX-License-Identifier: Apache-2.0
// Sensor settings: presets, patches in order, and errors that name the document and the JSON path.
#include <gtest/gtest.h>

#include <fstream>

#include "core/error.h"
#include "sensor_sim/config.h"
#include "tests/core/spectral_exr_fixtures.h"
#include "tests/sensor_sim/sensor_test_util.h"

namespace ct {
namespace {

namespace fs = std::filesystem;
using sensor::ConfigPatch;

std::string error_of(const std::vector<ConfigPatch>& patches) {
  try {
    sensor::resolve_config(patches);
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(SensorConfig, PresetsResolveAndReadBackThroughTheirJson) {
  for (const std::string& name : sensor::preset_names()) {
    const sensor::SensorConfig config = test::config_of({{"preset", name}});
    EXPECT_EQ(config.preset, name);
    const Json json = sensor::config_json(config);
    EXPECT_EQ(sensor::config_json(test::config_of(json)).dump(), json.dump()) << name;
  }
  const sensor::SensorConfig ideal = test::config_of(Json::object());
  EXPECT_EQ(ideal.response.curves.name, "cie1931");
  EXPECT_FALSE(ideal.noise.enabled || ideal.adc.enabled || ideal.full_well.enabled || ideal.rendering.enabled);
  EXPECT_FALSE(sensor::saturation_electrons(ideal));
  const sensor::SensorConfig canon = test::config_of({{"preset", "canon_eos_5d_mkiii"}});
  EXPECT_EQ(canon.adc.bits, 14);
  EXPECT_EQ(canon.full_well.electrons, 67684.0);
  EXPECT_DOUBLE_EQ(*sensor::saturation_electrons(canon), (16383.0 - 2048.0) / 0.2118);
}

TEST(SensorConfig, LaterPatchesWinAndTheLastPresetIsTheBase) {
  const sensor::SensorConfig c = sensor::resolve_config({
      {{{"preset", "smartphone"}, {"noise", {{"read_e", 4.0}}}}, "a.json"},
      {{{"preset", "machine_vision_ccd"}}, "--preset"},
      {{{"exposure", {{"time_s", 0.5}}}}, "--exposure-s"},
  });
  EXPECT_EQ(c.preset, "machine_vision_ccd");
  EXPECT_EQ(c.noise.read_e, 4.0);  // a.json's setting outlives the change of preset
  EXPECT_EQ(c.adc.bits, 12);       // from the CCD preset
  EXPECT_EQ(*c.exposure.time_s, 0.5);
}

TEST(SensorConfig, ErrorsNameTheDocumentAndThePath) {
  const struct {
    Json patch;
    std::string message;
  } cases[] = {
      {{{"adc", {{"bits", 40}}}}, "cam.json: adc.bits: must be <= 32, got 40"},
      {{{"exposure", {{"time_s", -0.01}}}}, "cam.json: exposure.time_s: must be > 0, got -0.01"},
      {{{"exposure", {{"time_s", "soon"}}}}, "cam.json: exposure.time_s: must be a time in seconds or \"auto\""},
      {{{"noise", {{"read_noise", 3}}}}, "cam.json: noise.read_noise: unknown key"},
      {{{"spectral_response", {{"camera", "leica_m"}}}},
       "cam.json: spectral_response.camera: unknown camera \"leica_m\""},
      {{{"preset", "hubble"}}, "cam.json: preset: unknown preset \"hubble\""},
      {{{"cfa", {{"enabled", true}}}}, "cam.json: cfa.enabled: the colour filter array needs the ADC"},
      {{{"cfa", {{"enabled", true}, {"demosaic", "vng"}}}, {"adc", {{"enabled", true}, {"bits", 12}}}},
       "cam.json: cfa.demosaic: vng demosaicing takes at most 8-bit digital numbers, but adc.bits is 12"},
      {{{"adc", {{"enabled", true}, {"bits", 8}, {"black_level_dn", 255}}}},
       "cam.json: adc.black_level_dn: must be below the ADC's top code 255"},
      {{{"rendering", {{"output_bits", 12}}}}, "cam.json: rendering.output_bits: must be 8, 16 or null, got 12"},
      {{{"rendering", {{"white_balance", "D42"}}}}, "cam.json: rendering.white_balance:"},
      {{{"cfa", {{"pattern", "RGBG"}}}}, "cam.json: cfa.pattern: must be one of RGGB, BGGR, GRBG, GBRG"},
      {Json::array(), "cam.json: must be a JSON object"},
  };
  for (const auto& c : cases) {
    const std::string message = error_of({{c.patch, "cam.json"}});
    EXPECT_EQ(message.find(c.message), 0u) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
  // A patch that is fine on its own is named when a later one breaks the combination.
  const std::string combined = error_of({{{{"adc", {{"enabled", true}, {"bits", 12}}}}, "cam.json"},
                                         {{{"cfa", {{"enabled", true}, {"demosaic", "vng"}}}}, "--set"}});
  EXPECT_EQ(combined.find("--set: cfa.demosaic: vng"), 0u) << combined;
}

TEST(SensorConfig, CsvPathsInAFileAreRelativeToIt) {
  test::TempDir dir;
  fs::create_directories(dir.file("cams"));
  test::write_flat_camera(dir.file("cams"));
  std::ofstream(dir.file("cams/sensor.json"))
      << R"({"spectral_response": {"camera": "flat_camera.csv", "basis": "photon"}})";
  const sensor::SensorConfig c = sensor::resolve_config({sensor::read_config_patch(dir.file("cams/sensor.json"))});
  EXPECT_EQ(c.response.camera, dir.file("cams/flat_camera.csv").string());
  EXPECT_EQ(c.response.curves.curves[0](500), 1.0);
  const std::string missing = error_of({{{{"spectral_response", {{"camera", "nowhere/cam.csv"}}}}, "--camera"}});
  EXPECT_EQ(missing.find("--camera: spectral_response.camera: nowhere/cam.csv"), 0u) << missing;
}

}  // namespace
}  // namespace ct
