// SPDX-License-Identifier: Apache-2.0
// plan::check_band_plan: where a band plan cannot hold a scene's colours, said before rendering. Known answers:
// a smooth light and smooth reflectances (the paper box under D65) give nothing at the scene's 10 nm bands; a
// narrow-band LED (10 nm wide) and a narrow-band reflectance are named, with the right cause, at bands of 40–45 nm
// and not at 1 nm bands, where band averages follow every spectrum; the continuous mode has no band error. The
// commands that render say it: check-scene lists the warnings, render prints them before it renders.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "core/file_io.h"
#include "core/json_input.h"
#include "core/scene.h"
#include "plan/plan.h"
#include "plan/spectral_check.h"
#include "tests/cli/run_command.h"
#include "tests/plan/paper_box.h"

namespace ct {
namespace {

namespace fs = std::filesystem;
using test::kBox;

// The paper box with its lamp replaced by a blue LED (peak 450 nm, 10 nm full width at half maximum) or one
// material's reflectance by a narrow band (a 10 nm wide peak at 600 nm over 0.1).
Json box_with(bool led, bool narrow_paint) {
  Json doc = read_json(kBox);
  for_each_scene_path(doc, [&](Json& path) {
    if (fs::path(path.get<std::string>()).is_relative()) path = (kBox.parent_path() / path.get<std::string>()).string();
  });
  if (led) doc["spectra"]["lamp"] = Json{{"samples", {{430, 0.0}, {440, 0.0}, {450, 1.0}, {460, 0.0}, {470, 0.0}}}};
  if (narrow_paint)
    doc["materials"]["back_wall"]["reflectance"] =
        Json{{"samples", {{380, 0.1}, {590, 0.1}, {600, 0.9}, {610, 0.1}, {780, 0.1}}}};
  return doc;
}

using test::scene_of;

TEST(SpectralCheck, SmoothSpectraAtTenNanometresGiveNoWarning) {
  const Scene box = load_scene(kBox);
  EXPECT_TRUE(plan::check_band_plan(box, box.render.bands, SpectralMode::Bands).empty());
}

TEST(SpectralCheck, NarrowBandLightIsNamedAtWideBandsOnly) {
  const Scene s = scene_of(box_with(true, false));
  const auto wide = plan::check_band_plan(s, Bands::parse("380:780:40"), SpectralMode::Bands);
  ASSERT_FALSE(wide.empty());
  EXPECT_EQ(wide.front().light, "ceiling_lamp");
  EXPECT_TRUE(wide.front().light_is_cause);
  EXPECT_NE(wide.front().message.find("narrow peaks"), std::string::npos) << wide.front().message;
  EXPECT_NE(wide.front().message.find("10 bands of 40 nm"), std::string::npos) << wide.front().message;
  EXPECT_TRUE(plan::check_band_plan(s, Bands::parse("380:780:1"), SpectralMode::Bands).empty());
  EXPECT_TRUE(plan::check_band_plan(s, Bands::parse("380:780:40"), SpectralMode::Continuous).empty());
}

TEST(SpectralCheck, NarrowBandReflectanceIsNamedAsTheCause) {
  const Scene s = scene_of(box_with(false, true));
  // Nine uniform bands of 44.4 nm: an edge at 602.2 nm cuts the 10 nm peak (a peak inside one band, as with 40 nm
  // bands, keeps more of its colour).
  std::vector<double> nine;
  for (int i = 0; i <= 9; ++i) nine.push_back(380.0 + 400.0 * i / 9);
  const auto wide = plan::check_band_plan(s, Bands::from_edges(nine), SpectralMode::Bands);
  // Such bands are coarse for the box's other paints too; the narrow band is among the named, as the cause.
  const auto it = std::find_if(wide.begin(), wide.end(), [](const auto& w) { return w.material == "back_wall"; });
  ASSERT_NE(it, wide.end());
  EXPECT_FALSE(it->light_is_cause);
  EXPECT_NE(it->message.find("reflectance changes faster than the bands"), std::string::npos) << it->message;
  EXPECT_TRUE(plan::check_band_plan(s, Bands::parse("380:780:1"), SpectralMode::Bands).empty());
}

// Band values read through a reconstruction are judged through it. Under F11 the 6 bands `plan` fits with a
// reconstruction hold the lamp's and every paint's colour (nothing named), while the same edges read as a step
// function average the lamp's three peaks away (the lamp named).
TEST(SpectralCheck, AReconstructionIsPartOfTheBands) {
  Json doc = read_json(kBox);
  doc["spectra"]["lamp"] = Json{{"illuminant", "F11"}};
  const Scene s = parse_scene(doc, "box-f11.json", kBox.parent_path());
  plan::PlanOptions options;
  options.threads = 2;
  const plan::Plan p = plan::make_plan(s, options);
  ASSERT_NE(p.bands.reconstruction(), nullptr);
  EXPECT_TRUE(plan::check_band_plan(s, p.bands, SpectralMode::Bands).empty());
  const auto step = plan::check_band_plan(s, p.bands.without_reconstruction(), SpectralMode::Bands);
  ASSERT_FALSE(step.empty());
  EXPECT_EQ(step.front().light, "ceiling_lamp");
  EXPECT_TRUE(step.front().light_is_cause);
}

TEST(SpectralCheck, CheckSceneAndRenderSayIt) {
  const fs::path dir = fs::temp_directory_path() / ("ct-spectral-check-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  Json doc = box_with(true, false);
  doc["render"]["bands"] = "380:780:40";
  write_file_atomically(dir / "led.json", doc.dump(2));
  const auto check = test::run_chromatrace({"check-scene", (dir / "led.json").string()});
  EXPECT_EQ(check.exit_code, 0) << check.err;
  EXPECT_NE(check.out.find("warning    light \"ceiling_lamp\""), std::string::npos) << check.out;
  const auto render = test::run_chromatrace({"render", (dir / "led.json").string(), "-o", (dir / "r.exr").string(),
                                             "--resolution", "4x4", "--spp", "1", "-q"});
  EXPECT_EQ(render.exit_code, 0) << render.err;
  EXPECT_NE(render.err.find("chromatrace render: warning: light \"ceiling_lamp\""), std::string::npos) << render.err;
  // For Cycles (the Blender batch asks this way) the same lines, without the continuous mode Cycles does not have;
  // settings given as options are judged instead of the scene's: 1 nm bands hold the LED.
  const auto cycles = test::run_chromatrace({"check-scene", (dir / "led.json").string(), "--renderer", "cycles"});
  EXPECT_EQ(cycles.exit_code, 0) << cycles.err;
  EXPECT_NE(cycles.out.find("warning    light \"ceiling_lamp\""), std::string::npos) << cycles.out;
  EXPECT_NE(check.out.find("--spectral-mode continuous"), std::string::npos) << check.out;
  EXPECT_EQ(cycles.out.find("--spectral-mode"), std::string::npos) << cycles.out;
  const auto narrow = test::run_chromatrace({"check-scene", (dir / "led.json").string(), "--bands", "380:780:1"});
  EXPECT_EQ(narrow.exit_code, 0) << narrow.err;
  EXPECT_EQ(narrow.out.find("ceiling_lamp\":"), std::string::npos) << narrow.out;
  // Bad settings to judge: one line naming the option, exit 2.
  for (const std::vector<std::string>& bad : std::vector<std::vector<std::string>>{
           {"--samples", "0"}, {"--max-bounces", "-1"}, {"--renderer", "eevee"}, {"--bands", "380:780:0"}}) {
    std::vector<std::string> args = {"check-scene", (dir / "led.json").string()};
    args.insert(args.end(), bad.begin(), bad.end());
    const auto r = test::run_chromatrace(args);
    EXPECT_EQ(r.exit_code, 2) << bad[0];
    EXPECT_NE(r.err.find("error: " + bad[0] + ":"), std::string::npos) << r.err;
  }
  // Narrow bands: the same scene renders without a word about its bands.
  const auto fine = test::run_chromatrace({"render", (dir / "led.json").string(), "-o", (dir / "f.exr").string(),
                                           "--bands", "380:780:1", "--resolution", "4x4", "--spp", "1", "-q"});
  EXPECT_EQ(fine.exit_code, 0) << fine.err;
  EXPECT_EQ(fine.err.find("ceiling_lamp"), std::string::npos) << fine.err;  // (1 path per pixel: a noise warning)
  fs::remove_all(dir);
}

}  // namespace
}  // namespace ct
