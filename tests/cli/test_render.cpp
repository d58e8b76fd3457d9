// SPDX-License-Identifier: Apache-2.0
// `chromatrace render` end to end: a real render through the executable, and bad input.
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <sstream>
#include <string>

#include <fmt/core.h>

#include "core/file_io.h"
#include "core/spectral_exr.h"
#include "tests/cli/run_command.h"
#include "tests/cli/text_files.h"

namespace ct {
namespace {

namespace fs = std::filesystem;
using test::run_chromatrace;

using test::kPaperBox;

class RenderCommand : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / fmt::format("ct-render-{}-{}", ::getpid(), counter_++);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
  static inline int counter_ = 0;
};

using test::line_count;

TEST_F(RenderCommand, WritesASpectralExrWithComponentsAndObjectIds) {
  const fs::path out = dir_ / "box.exr";
  const auto r = run_chromatrace({"render", kPaperBox, "-o", out.string(), "--spp", "2", "--resolution", "32x24",
                                  "--bands", "400:700:20", "--components", "all", "--max-bounces", "3", "--quiet"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  // --quiet: no progress; all that is said is what the settings leave out (2 paths per pixel), one warning a line.
  std::istringstream lines(r.err);
  for (std::string line; std::getline(lines, line);) EXPECT_EQ(line.rfind("chromatrace render: warning: ", 0), 0u) << r.err;
  SpectralExrReader reader(out);
  const SpectralExrInfo& info = reader.info();
  EXPECT_EQ(info.width, 32);
  EXPECT_EQ(info.height, 24);
  EXPECT_EQ(info.bands.size(), 15u);
  EXPECT_TRUE(info.has_object_ids);
  EXPECT_EQ(info.object_names.at(6), "sphere");
  for (const char* c : {"emission", "diffuse_direct", "glossy_indirect", "light.ceiling", "bounce.0", "bounce.3"})
    EXPECT_NE(info.find_layer(c, SpectralQuantity::S0), nullptr) << c;
  EXPECT_EQ(info.metadata.at("chromatrace.samples"), "2");

  const auto check = run_chromatrace({"info", "--check", out.string()});
  EXPECT_EQ(check.exit_code, 0) << check.out << check.err;
}

TEST_F(RenderCommand, BadInputGetsExitTwoAndOneLineNamingTheField) {
  const fs::path out = dir_ / "out.exr";
  struct Case {
    std::vector<std::string> args;
    std::string must_mention;
  };
  const std::vector<Case> cases = {
      {{"render", (dir_ / "missing.json").string(), "-o", out.string()}, "missing.json"},
      {{"render", kPaperBox, "-o", out.string(), "--spp", "0"}, "--spp"},
      {{"render", kPaperBox, "-o", out.string(), "--max-bounces", "-2"}, "--max-bounces"},
      {{"render", kPaperBox, "-o", out.string(), "--bands", "380:785:10"}, "--bands"},
      {{"render", kPaperBox, "-o", out.string(), "--spectral-mode", "rgb"}, "--spectral-mode"},
      {{"render", kPaperBox, "-o", out.string(), "--components", "paths,colours"}, "--components"},
      {{"render", kPaperBox, "-o", out.string(), "--resolution", "64"}, "--resolution"},
      {{"render", kPaperBox, "-o", out.string(), "--time-limit", "-1"}, "--time-limit"},
      {{"render", kPaperBox, "-o", out.string(), "--threads", "-3"}, "--threads"},
      {{"render", kPaperBox, "-o", (dir_ / "no/such/dir/out.exr").string(), "--spp", "1", "--resolution", "4x4"}, "out.exr"},
      {{"render", kPaperBox}, "--output"},
      {{"render", kPaperBox, "-o", out.string(), "--no-such-option"}, "--no-such-option"},
      {{"render", kPaperBox, "-o", out.string(), "--seeds", "0"}, "--seeds"},
      {{"render", kPaperBox, "-o", out.string(), "--seeds", "5", "--spp", "4"}, "--seeds"},
      {{"render", kPaperBox, "-o", out.string(), "--seeds", "4", "--part", "4"}, "--part"},
      {{"render", kPaperBox, "-o", out.string(), "--part", "0"}, "--part"},
  };
  for (const Case& c : cases) {
    const auto r = run_chromatrace(c.args);
    EXPECT_EQ(r.exit_code, 2) << c.must_mention << ": " << r.err;
    EXPECT_EQ(line_count(r.err), 1) << r.err;
    EXPECT_NE(r.err.find(c.must_mention), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(out)) << c.must_mention;
  }
  // Nothing half-written is left in the output directory.
  EXPECT_TRUE(fs::is_empty(dir_));
}

// render --seeds K renders K parts and combines them (reference_tracer/seed_split.h): the same bytes as the parts
// rendered one by one with --part and joined by combine, and no scratch files left beside the output.
TEST_F(RenderCommand, SeedSplitEqualsItsPartsCombinedAndLeavesOnlyTheOutput) {
  const std::vector<std::string> split = {kPaperBox, "--spp", "7", "--resolution", "16x12", "--seeds", "3", "--quiet"};
  const fs::path out = dir_ / "split.exr";
  std::vector<std::string> args = {"render", "-o", out.string()};
  args.insert(args.end(), split.begin(), split.end());
  const auto r = run_chromatrace(args);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(std::vector<fs::path>(fs::directory_iterator(dir_), fs::directory_iterator()), std::vector<fs::path>{out});

  fs::create_directories(dir_ / "parts");
  std::vector<std::string> combine = {"combine", "--quiet", "-o", (dir_ / "combined.exr").string()};
  for (int part = 0; part < 3; ++part) {
    const fs::path file = dir_ / "parts" / fmt::format("p{}.exr", part);
    std::vector<std::string> one = {"render", "-o", file.string(), "--part", std::to_string(part)};
    one.insert(one.end(), split.begin(), split.end());
    const auto p = run_chromatrace(one);
    ASSERT_EQ(p.exit_code, 0) << p.err;
    combine.push_back(file.string());
  }
  const auto c = run_chromatrace(combine);
  ASSERT_EQ(c.exit_code, 0) << c.err;
  EXPECT_TRUE(read_file(out) == read_file(dir_ / "combined.exr"));
}

TEST_F(RenderCommand, BadTexturesAndEnvironmentsGetExitTwoAndOneLineNamingTheFileAndField) {
  const std::string bad = std::string(CHROMATRACE_TEST_DATA) + "/scenes/bad/";
  const fs::path out = dir_ / "out.exr";
  struct Case {
    std::string scene;
    std::vector<std::string> must_mention;
  };
  const std::vector<Case> cases = {
      {"missing_texture.json", {"materials.wood.reflectance.texture", "textures/wood.png", "cannot open file"}},
      {"texture_on_mesh_without_uvs.json", {"objects[0].shape.file", "tetrahedron_no_uvs.ply", "tetra", "texture"}},
      {"environment_not_an_image.json", {"environment.radiance.texture", "wavelengths_not_increasing.csv"}},
      {"environment_rotation_without_texture.json", {"environment.rotation_deg"}},
  };
  for (const Case& c : cases) {
    const auto r = run_chromatrace({"render", bad + c.scene, "-o", out.string(), "--spp", "1", "--quiet"});
    EXPECT_EQ(r.exit_code, 2) << c.scene << ": " << r.err;
    EXPECT_EQ(line_count(r.err), 1) << r.err;
    for (const std::string& word : c.must_mention) EXPECT_NE(r.err.find(word), std::string::npos) << word << " in " << r.err;
    EXPECT_FALSE(fs::exists(out)) << c.scene;
  }
}

}  // namespace
}  // namespace ct
