// SPDX-License-Identifier: Apache-2.0
// End to end: `chromatrace check-scene` on the shipped scenes, the series and every bad test scene.
#include <algorithm>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/cli/run_command.h"
#include "tests/core/bad_scenes.h"

namespace ct {
namespace {

const std::string kScenes = std::string(CHROMATRACE_SOURCE_DIR) + "/scenes";

TEST(CheckScene, ShippedScenesAreValid) {
  for (const std::string scene : {"paper/box.json", "cornell_box/cornell_box.json", "textured/textured.json",
                                  "glossy_lights/glossy_lights.json"}) {
    const test::CommandResult r = test::run_chromatrace({"check-scene", kScenes + "/" + scene});
    EXPECT_EQ(r.exit_code, 0) << scene << ": " << r.err;
    EXPECT_EQ(r.err, "") << scene;
    EXPECT_EQ(r.out.rfind(kScenes + "/" + scene + ": valid scene", 0), 0u) << r.out;
  }
}

TEST(CheckScene, JsonSummary) {
  const test::CommandResult r =
      test::run_chromatrace({"check-scene", "--json", kScenes + "/cornell_box/cornell_box.json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json report = nlohmann::json::parse(r.out);
  EXPECT_EQ(report["valid"], true);
  EXPECT_EQ(report["format"], "chromatrace-scene/1");
  const nlohmann::json& scene = report["scene"];
  EXPECT_EQ(scene["objects"], 7);
  EXPECT_EQ(scene["lights"], 1);
  EXPECT_EQ(scene["triangles"], 36);  // 5 wall quads + 2 blocks of 6 quads + the light, 2 triangles each
  EXPECT_NEAR(scene["camera"]["focal_length_mm"].get<double>(), 35.0, 1e-4);
  EXPECT_EQ(scene["render"]["bands"]["count"], 30);
}

TEST(CheckScene, SeriesChecksEveryVariant) {
  const test::CommandResult r =
      test::run_chromatrace({"check-scene", "--json", "--threads", "2", kScenes + "/paper/series.json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json report = nlohmann::json::parse(r.out);
  EXPECT_EQ(report["format"], "chromatrace-series/1");
  ASSERT_EQ(report["variants"].size(), 13u);
  EXPECT_EQ(report["variants"][0]["name"], "1-lambert-direct");
  EXPECT_EQ(report["variants"][0]["scene"]["render"]["max_bounces"], 1);
}

TEST(CheckScene, QuietPrintsNothingWhenValid) {
  const test::CommandResult r = test::run_chromatrace({"check-scene", "--quiet", kScenes + "/paper/box.json"});
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_EQ(r.out, "");
  EXPECT_EQ(r.err, "");
}

TEST(CheckScene, BadScenesExit2WithOneLineNamingFileAndPath) {
  for (const test::BadScene& bad : test::bad_scenes()) {
    const test::CommandResult r = test::run_chromatrace({"check-scene", test::bad_scenes_dir() + "/" + bad.file});
    EXPECT_EQ(r.exit_code, 2) << bad.file;
    EXPECT_EQ(r.err, "chromatrace check-scene: error: " + test::expected_message(bad) + "\n") << bad.file;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << bad.file;
    EXPECT_EQ(r.out, "") << bad.file;
  }
}

TEST(CheckScene, MissingFileAndUsage) {
  const test::CommandResult missing = test::run_chromatrace({"check-scene", "/nonexistent/scene.json"});
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_EQ(missing.err, "chromatrace check-scene: error: /nonexistent/scene.json: cannot open file\n");
  EXPECT_EQ(test::run_chromatrace({"check-scene"}).exit_code, 2);
}

}  // namespace
}  // namespace ct
