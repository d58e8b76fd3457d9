// SPDX-License-Identifier: Apache-2.0
// Outputs never destroy inputs and never replace special files; JSON numbers beyond a double and
// directories given as files are bad input — for every command, end to end through the executable.
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/core.h>

#include "tests/cli/run_command.h"
#include "tests/cli/text_files.h"
#include "tests/core/image_fixtures.h"
#include "tests/core/spectral_exr_fixtures.h"

namespace ct {
namespace {

namespace fs = std::filesystem;
using test::line_count;
using test::run_chromatrace;
using test::write_text;


// A scene that reads a mesh, a CSV table and a texture beside it.
constexpr const char* kScene = R"({
  "format": "chromatrace-scene/1",
  "spectra": {"grey": {"csv": "grey.csv"}},
  "materials": {
    "wall": {"type": "lambert", "reflectance": "grey"},
    "board": {"type": "lambert", "reflectance": {"texture": "board.png"}}
  },
  "objects": [
    {"name": "floor", "material": "board", "shape": {"type": "quad", "corner": [-1, -1, 0], "edge1": [2, 0, 0], "edge2": [0, 2, 0]}},
    {"name": "tri", "material": "wall", "shape": {"type": "mesh", "file": "tri.ply"}}
  ],
  "lights": [
    {"name": "lamp", "shape": {"type": "quad", "corner": [-0.2, -0.2, 2], "edge1": [0, 0.4, 0], "edge2": [0.4, 0, 0]},
     "radiance": {"blackbody_k": 3000}, "scale": 5}
  ],
  "camera": {"position": [0, -3, 1], "look_at": [0, 0, 0.5], "fov_deg": 40, "resolution": [8, 6]}
})";

constexpr const char* kTriangle = R"(ply
format ascii 1.0
element vertex 3
property float x
property float y
property float z
element face 1
property list uchar int vertex_indices
end_header
-0.5 0 0.1
0.5 0 0.1
0 0 0.8
3 0 1 2
)";

class Outputs : public ::testing::Test {
 protected:
  void SetUp() override {
    scene_ = dir_.file("scene.json");
    write_text(scene_, kScene);
    write_text(dir_.file("grey.csv"), "wavelength_nm,value\n380,0.5\n780,0.5\n");
    write_text(dir_.file("tri.ply"), kTriangle);
    test::write_test_image(dir_.file("board.png"), 2, 2, {1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1});
    test::ComponentImage image = test::make_component_image(8, 6, 5);
    exr_ = dir_.file("render.exr");
    test::write_image(exr_, image, 6);
  }

  // The spellings of an output that all name `input`: the path itself, with "./" in it, a symbolic link to
  // it and a hard link to it.
  std::vector<fs::path> spellings_of(const fs::path& input) const {
    const std::string name = input.filename().string();
    const fs::path soft = dir_.file("soft-" + name), hard = dir_.file("hard-" + name);
    if (!fs::exists(fs::symlink_status(soft))) fs::create_symlink(input, soft);
    if (!fs::exists(hard)) fs::create_hard_link(input, hard);
    return {input, input.parent_path() / "." / input.filename(), soft, hard};
  }

  // Runs `args` with "-o OUTPUT" (or OUTPUT as the last argument) for every spelling of `input`: exit 2, one
  // line naming the output as given and the input, and the input's bytes unchanged.
  void expect_input_kept(std::vector<std::string> args, const fs::path& input, const std::string& input_as_named,
                         bool positional = false) const {
    const std::string before = test::read_text(input);
    ASSERT_FALSE(before.empty()) << input;
    for (const fs::path& output : spellings_of(input)) {
      std::vector<std::string> all = args;
      if (!positional) all.push_back("-o");
      all.push_back(output.string());
      const auto r = run_chromatrace(all);
      EXPECT_EQ(r.exit_code, 2) << output << ": " << r.err;
      EXPECT_EQ(line_count(r.err), 1) << r.err;
      EXPECT_NE(r.err.find(output.string() + ": is the same file as the input " + input_as_named), std::string::npos)
          << r.err;
      EXPECT_EQ(test::read_text(input), before) << output;
    }
  }

  // `args` + "-o OUTPUT" for a FIFO, a link to it and a directory: exit 2, one line naming it, nothing replaced.
  void expect_special_outputs_refused(const std::vector<std::string>& args) const {
    const fs::path fifo = dir_.file("pipe.exr");
    if (!fs::exists(fifo)) {
      ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
    }
    const fs::path link = dir_.file("to-pipe.exr");
    if (!fs::exists(fs::symlink_status(link))) fs::create_symlink(fifo, link);
    const fs::path directory = dir_.file("out.exr");
    fs::create_directories(directory);
    const struct {
      fs::path output;
      std::string says;
    } cases[] = {{fifo, ": is a FIFO"}, {link, ": links to " + fifo.string() + ", which is a FIFO"},
                 {directory, ": is a directory"}};
    for (const auto& c : cases) {
      std::vector<std::string> all = args;
      all.push_back("-o");
      all.push_back(c.output.string());
      const auto r = run_chromatrace(all);
      EXPECT_EQ(r.exit_code, 2) << c.output << ": " << r.err;
      EXPECT_EQ(line_count(r.err), 1) << r.err;
      EXPECT_NE(r.err.find(c.output.string() + c.says), std::string::npos) << r.err;
    }
    EXPECT_TRUE(fs::is_fifo(fifo));
    EXPECT_TRUE(fs::is_symlink(fs::symlink_status(link)));
    EXPECT_TRUE(fs::is_directory(directory) && fs::is_empty(directory));
  }

  test::TempDir dir_;
  fs::path scene_, exr_;
};

// ---- outputs that are inputs ------------------------------------------------------------------------

TEST_F(Outputs, RenderKeepsTheSceneAndEveryFileItReads) {
  const std::vector<std::string> render = {"render", scene_.string(), "--spp", "1", "--quiet"};
  expect_input_kept(render, scene_, scene_.string());
  expect_input_kept(render, dir_.file("tri.ply"), dir_.file("tri.ply").string());
  expect_input_kept(render, dir_.file("grey.csv"), dir_.file("grey.csv").string());
  expect_input_kept(render, dir_.file("board.png"), dir_.file("board.png").string());
  // The scene still renders, and through a link the render replaces the link's target.
  write_text(dir_.file("old.exr"), "old");
  fs::create_symlink("old.exr", dir_.file("latest.exr"));
  const auto r = run_chromatrace({"render", scene_.string(), "--spp", "1", "--quiet", "-o", dir_.file("latest.exr").string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::is_symlink(fs::symlink_status(dir_.file("latest.exr"))));
  EXPECT_EQ(test::read_text(dir_.file("old.exr")).substr(0, 4), "\x76\x2f\x31\x01");  // now an OpenEXR file
}

TEST_F(Outputs, SensorKeepsItsInputConfigAndCameraCsv) {
  expect_input_kept({"sensor", exr_.string(), "--quiet"}, exr_, exr_.string());
  write_text(dir_.file("sensor.exr"), R"({"format": "chromatrace-sensor/1"})");  // a config with an image's name
  expect_input_kept({"sensor", exr_.string(), "--config", dir_.file("sensor.exr").string(), "--quiet"},
                    dir_.file("sensor.exr"), dir_.file("sensor.exr").string());
}

TEST_F(Outputs, AnalyzeKeepsItsImageAndMasks) {
  const fs::path png = test::write_test_image(dir_.file("photo.png"), 2, 2, {1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1});
  expect_input_kept({"analyze", png.string(), "--quiet"}, png, png.string());
  // An image where analyze writes analysis.json.
  fs::create_directories(dir_.file("out"));
  test::write_test_image(dir_.file("out/analysis.png"), 2, 2, std::vector<float>(12, 0.5f));
  const std::string before = test::read_text(dir_.file("out/analysis.png"));
  fs::create_symlink("analysis.png", dir_.file("out/analysis.json"));
  const auto r = run_chromatrace({"analyze", png.string(), "--mask", dir_.file("out/analysis.json").string(), "-o",
                                  dir_.file("out").string(), "--quiet"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_EQ(line_count(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("out/analysis.json: is the same file as the input " + dir_.file("out/analysis.json").string()),
            std::string::npos)
      << r.err;
  EXPECT_EQ(test::read_text(dir_.file("out/analysis.png")), before);
}

TEST_F(Outputs, ExportMeshesAndPrepareTextureKeepTheirInputs) {
  // export-meshes writes 002_tri.ply for the object "tri": the scene's own mesh, if it were called so.
  std::string scene = kScene;
  scene.replace(scene.find("\"tri.ply\""), 9, "\"002_tri.ply\"");
  write_text(dir_.file("by_name.json"), scene);
  fs::copy_file(dir_.file("tri.ply"), dir_.file("002_tri.ply"));
  const auto r = run_chromatrace({"export-meshes", dir_.file("by_name.json").string(), dir_.path().string(), "--quiet"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_EQ(line_count(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("002_tri.ply: is the same file as the input " + dir_.file("002_tri.ply").string()),
            std::string::npos)
      << r.err;
  EXPECT_EQ(test::read_text(dir_.file("002_tri.ply")), kTriangle);
  EXPECT_FALSE(fs::exists(dir_.file("001_floor.ply")));  // refused before anything was written
  expect_input_kept({"export-meshes", scene_.string()}, scene_, scene_.string(), true);

  const fs::path png = dir_.file("board.png");
  expect_input_kept({"prepare-texture", png.string(), "--kind", "reflectance", "--bands", "400:700:100", "--quiet"},
                    png, png.string());
}

TEST_F(Outputs, SeriesKeepsItsFileAndScenes) {
  const fs::path data = fs::path(CHROMATRACE_TEST_DATA) / "scenes";
  const fs::path run = dir_.file("run");
  fs::create_directories(run / "a");
  fs::copy_file(data / "series_merge.json", run / "series.json");
  fs::copy_file(data / "minimal.json", run / "minimal.json");
  fs::copy_file(data / "series_merge.json", run / "a" / "s.json");
  fs::copy_file(data / "minimal.json", run / "a" / "minimal.json");
  const std::string series = test::read_text(run / "series.json"), scene = test::read_text(run / "minimal.json");
  const struct {
    fs::path file;
    std::string says;
  } cases[] = {
      // The run writes series.json at the top of its directory, and everything of variant "a" under a/.
      {run / "series.json",
       (run / "series.json").string() + ": is the same file as the input " + (run / "series.json").string()},
      {run / "a" / "s.json", run.string() + ": the input " + (run / "a" / "minimal.json").string() + " is in " +
                                 (run / "a").string() + ", which the series writes"},
  };
  for (const auto& c : cases) {
    const auto r = run_chromatrace({"series", c.file.string(), "-o", run.string(), "--quiet"});
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_EQ(line_count(r.err), 1) << r.err;
    EXPECT_NE(r.err.find(c.says), std::string::npos) << "expected \"" << c.says << "\" in " << r.err;
  }
  EXPECT_EQ(test::read_text(run / "series.json"), series);
  EXPECT_EQ(test::read_text(run / "a" / "s.json"), series);
  EXPECT_EQ(test::read_text(run / "minimal.json"), scene);
  EXPECT_EQ(test::read_text(run / "a" / "minimal.json"), scene);
}

// ---- special files -------------------------------------------------------------------------------

TEST_F(Outputs, FifosLinksToThemAndDirectoriesAreRefusedBeforeAnyWork) {
  expect_special_outputs_refused({"render", scene_.string(), "--spp", "1", "--quiet"});
  expect_special_outputs_refused({"sensor", exr_.string(), "--quiet"});
}

TEST_F(Outputs, ADeviceIsRefused) {
  // A device node of our own with the null device's numbers (never a real device path): needs CAP_MKNOD.
  const fs::path device = dir_.file("null.exr");
  if (::mknod(device.c_str(), S_IFCHR | 0666, makedev(1, 3)) != 0) {
    GTEST_SKIP() << "cannot create a device node here";
  }
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"render", scene_.string(), "--spp", "1", "--quiet", "-o", device.string()},
        std::vector<std::string>{"sensor", exr_.string(), "--quiet", "-o", device.string()}}) {
    const auto r = run_chromatrace(args);
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_EQ(line_count(r.err), 1) << r.err;
    EXPECT_NE(r.err.find(device.string() + ": is a character device"), std::string::npos) << r.err;
    EXPECT_TRUE(fs::is_character_file(device));
  }
}

// ---- JSON numbers beyond a double, directories given as files -----------------------------------------

TEST_F(Outputs, AJsonNumberBeyondADoubleIsBadInputNamingFileAndField) {
  const std::string range = "is out of range";
  std::string scene = kScene;
  scene.replace(scene.find("\"scale\": 5"), 10, "\"scale\": 1e999");
  write_text(dir_.file("big.json"), scene);
  write_text(dir_.file("sensor.json"), "{\"format\": \"chromatrace-sensor/1\", \"noise\": {\"read_e\": -1e999}}");
  write_text(dir_.file("plan.json"), "{\"format\": \"chromatrace-bands/1\", \"edges_nm\": [400, 1e400]}");
  write_text(dir_.file("spectra.json"), "{\"format\": \"chromatrace-spectra/1\", \"spectra\": {\"x\": {\"constant\": 2e308}}}");
  write_text(dir_.file("series.json"), "{\"format\": \"chromatrace-series/1\", \"base\": \"scene.json\", \"variants\": 1e999}");
  write_text(dir_.file("manifest.json"), "{\"format\": \"chromatrace-assemble/1\", \"edges_nm\": [1e999]}");
  const std::string out = dir_.file("out.exr").string();
  const struct {
    std::vector<std::string> args;
    std::string says;
  } cases[] = {
      {{"check-scene", dir_.file("big.json").string()}, "big.json: line 14, column 50: lights[0].scale: number 1e999 "},
      {{"render", dir_.file("big.json").string(), "-o", out}, "big.json: line 14, column 50: lights[0].scale: number 1e999 "},
      {{"sensor", exr_.string(), "--config", dir_.file("sensor.json").string(), "-o", out},
       "sensor.json: line 1, column 56: noise.read_e: number -1e999 "},
      {{"scene-bands", (fs::path(CHROMATRACE_TEST_DATA) / "scenes" / "minimal.json").string(), "--bands-file", dir_.file("plan.json").string()},
       "plan.json: line 1, column 53: edges_nm[1]: number 1e400 "},
      {{"scene-bands", dir_.file("spectra.json").string()}, "spectra.json: line 1, column 67: spectra.x.constant: number 2e308 "},
      {{"series", dir_.file("series.json").string(), "-o", dir_.file("series").string()},
       "series.json: line 1, column 70: variants: number 1e999 "},
      {{"assemble", dir_.file("manifest.json").string(), "-o", out}, "manifest.json: line 1, column 51: edges_nm[0]: number 1e999 "},
  };
  for (const auto& c : cases) {
    const auto r = run_chromatrace(c.args);
    EXPECT_EQ(r.exit_code, 2) << c.says << ": " << r.err;
    EXPECT_EQ(line_count(r.err), 1) << r.err;
    EXPECT_NE(r.err.find(c.says + range), std::string::npos) << "expected \"" << c.says << "\" in " << r.err;
    EXPECT_FALSE(fs::exists(out));
  }
}

TEST_F(Outputs, ADirectoryGivenAsAFileIsCalledADirectory) {
  fs::create_directories(dir_.file("scenes"));
  fs::create_directories(dir_.file("grey_dir.csv"));
  std::string scene = kScene;
  scene.replace(scene.find("\"grey.csv\""), 10, "\"grey_dir.csv\"");
  write_text(dir_.file("csv_dir.json"), scene);
  const std::string out = dir_.file("out.exr").string();
  const struct {
    std::vector<std::string> args;
    std::string says;
  } cases[] = {
      {{"check-scene", dir_.file("scenes").string()}, dir_.file("scenes").string() + ": is a directory, not a file"},
      {{"render", dir_.file("scenes").string(), "-o", out}, dir_.file("scenes").string() + ": is a directory, not a file"},
      {{"check-scene", dir_.file("csv_dir.json").string()},
       "spectra.grey.csv: " + dir_.file("grey_dir.csv").string() + ": is a directory, not a file"},
      {{"sensor", exr_.string(), "--config", dir_.file("scenes").string(), "-o", out},
       dir_.file("scenes").string() + ": is a directory, not a file"},
  };
  for (const auto& c : cases) {
    const auto r = run_chromatrace(c.args);
    EXPECT_EQ(r.exit_code, 2) << c.says << ": " << r.err;
    EXPECT_EQ(line_count(r.err), 1) << r.err;
    EXPECT_NE(r.err.find(c.says), std::string::npos) << "expected \"" << c.says << "\" in " << r.err;
  }
}

}  // namespace
}  // namespace ct
