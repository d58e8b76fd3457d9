// SPDX-License-Identifier: Apache-2.0
// A write that fails for want of space (a file-size limit, as a full disk does) exits 1 and leaves nothing
// at a final path, with the previous output intact; an output location the user cannot write in is bad input
// (exit 2) for every command (docs/errors.md, "Outputs that cannot be written").
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "tests/cli/run_command.h"
#include "tests/cli/text_files.h"
#include "tests/core/spectral_exr_fixtures.h"

namespace ct {
namespace {

namespace fs = std::filesystem;
using test::line_count;
using test::read_text;
using test::run_chromatrace;
using test::write_text;

using test::kMinimal;

// chromatrace with these arguments in a child whose files may grow to `kib` KiB, SIGXFSZ ignored.
test::CommandResult run_with_file_size_limit(int kib, const std::vector<std::string>& args) {
  return test::run_program_with_file_size_limit(CHROMATRACE_EXE, args, kib);
}

// The names in `dir` (hidden ones included), sorted.
std::vector<std::string> names_in(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir)) names.push_back(entry.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

TEST(OutOfSpace, SensorImagesAreNeverLeftTruncatedAndThePreviousFileStays) {
  test::TempDir in, out;
  test::ComponentImage image = test::make_component_image(128, 96, 5);
  image.layout.attributes["chromatrace.camera"] =
      R"({"horizontal_fov_deg": 50, "vertical_fov_deg": 38.6, "resolution": [128, 96]})";
  const fs::path input = in.file("scene.exr");
  test::write_image(input, image, 32);
  for (const char* name : {"camera.exr", "camera.png", "camera.tif"}) {
    const fs::path target = out.file(name);
    std::ofstream(target) << "the previous image";
    const auto r = run_with_file_size_limit(
        8, {"sensor", input.string(), "-o", target.string(), "--preset", "smartphone", "--exposure-s", "auto",
            "--quiet"});
    EXPECT_EQ(r.exit_code, 1) << name << ": " << r.err;
    EXPECT_EQ(line_count(r.err), 1) << r.err;
    EXPECT_NE(r.err.find(target.string()), std::string::npos) << r.err;
    EXPECT_EQ(read_text(target), "the previous image") << name;
    EXPECT_EQ(names_in(out.path()).size(), 1u) << name << ": a temporary file is left";
    fs::remove(target);
    // Without the limit the same command writes the file: the limit is what failed above.
    const auto ok = run_chromatrace({"sensor", input.string(), "-o", target.string(), "--preset", "smartphone",
                                     "--exposure-s", "auto", "--quiet"});
    EXPECT_EQ(ok.exit_code, 0) << ok.err;
    EXPECT_GT(fs::file_size(target), 8u * 1024u) << name;
    fs::remove(target);
  }
}

TEST(OutOfSpace, AnalyzeAndExportMeshesLeaveNoPartialDirectory) {
  test::TempDir dir;
  const fs::path image = dir.file("image.exr");
  std::vector<test::RawChannel> rgb = {test::constant_channel("R", 64, 64, 0.5), test::constant_channel("G", 64, 64, 0.25),
                                       test::constant_channel("B", 64, 64, 0.125)};
  for (std::size_t i = 0; i < rgb[0].values.size(); ++i) rgb[0].values[i] = 0.2f + 0.6f * static_cast<float>(i % 64) / 64;
  test::write_raw_exr(image, 64, 64, rgb);
  const fs::path outputs = dir.file("outputs");
  fs::create_directory(outputs);
  const fs::path analysis = outputs / "analysis", meshes = outputs / "meshes";
  const std::vector<std::string> analyze = {"analyze", image.string(), "-o", analysis.string(), "--quiet"};
  const std::vector<std::string> export_meshes = {"export-meshes", kMinimal.string(), meshes.string(), "--quiet"};

  // New directories: none is left, nor any staging directory beside it.
  for (const auto& args : {analyze, export_meshes}) {
    const auto r = run_with_file_size_limit(1, args);
    EXPECT_EQ(r.exit_code, 1) << args[0] << ": " << r.err;
    EXPECT_EQ(line_count(r.err), 1) << r.err;
    EXPECT_TRUE(names_in(outputs).empty()) << args[0];
  }
  // Existing directories: what they held stays as it was.
  for (const auto& args : {analyze, export_meshes}) {
    const auto r = run_chromatrace(args);
    ASSERT_EQ(r.exit_code, 0) << args[0] << ": " << r.err;
  }
  const std::string floor = read_text(meshes / "001_floor.ply");
  const std::vector<std::string> analysis_names = names_in(analysis), mesh_names = names_in(meshes);
  std::ofstream(analysis / "analysis.json") << "the previous analysis";
  std::ofstream(meshes / "001_floor.ply") << "the previous mesh";
  for (const auto& args : {analyze, export_meshes}) {
    const auto r = run_with_file_size_limit(1, args);
    EXPECT_EQ(r.exit_code, 1) << args[0] << ": " << r.err;
  }
  EXPECT_EQ(read_text(analysis / "analysis.json"), "the previous analysis");
  EXPECT_EQ(read_text(meshes / "001_floor.ply"), "the previous mesh");
  EXPECT_EQ(names_in(analysis), analysis_names);
  EXPECT_EQ(names_in(meshes), mesh_names);
  EXPECT_EQ(names_in(outputs), (std::vector<std::string>{"analysis", "meshes"}));
  // And a complete run replaces them.
  for (const auto& args : {analyze, export_meshes}) EXPECT_EQ(run_chromatrace(args).exit_code, 0) << args[0];
  EXPECT_NE(read_text(analysis / "analysis.json").find("\"regions\""), std::string::npos);
  EXPECT_EQ(read_text(meshes / "001_floor.ply"), floor);
}

TEST(OutOfSpace, AnOutputLocationThatCannotBeWrittenIsBadInputForEveryCommand) {
  test::TempDir dir;
  const fs::path locked = dir.file("locked");
  fs::create_directory(locked);
  // As root, permissions do not stop writes: run the commands as nobody, for whom a root-owned directory is
  // not writable; otherwise take the write permission away.
  const bool root = ::geteuid() == 0;
  if (!root) fs::permissions(locked, fs::perms::owner_write, fs::perm_options::remove);
  fs::permissions(dir.path(), fs::perms::all, fs::perm_options::add);
  const fs::path image = dir.file("image.exr");
  test::write_raw_exr(image, 8, 8,
                      {test::constant_channel("S0.500,000000nm", 8, 8, 1), test::constant_channel("S0.600,000000nm", 8, 8, 1)});
  fs::permissions(image, fs::perms::all, fs::perm_options::add);
  const std::string where = ": cannot write in directory " + locked.string() + ": ";
  const struct {
    std::vector<std::string> args;
    std::string output;
  } cases[] = {
      {{"render", kMinimal.string(), "-o", (locked / "r.exr").string()}, (locked / "r.exr").string()},
      {{"sensor", image.string(), "-o", (locked / "c.png").string()}, (locked / "c.png").string()},
      {{"analyze", image.string(), "-o", (locked / "a").string()}, (locked / "a").string()},
      {{"export-meshes", kMinimal.string(), (locked / "m").string()}, (locked / "m").string()},
      {{"analyze", image.string(), "-o", locked.string()}, locked.string()},
  };
  for (const auto& c : cases) {
    std::vector<std::string> args = c.args;
    const auto r = root ? test::run_program("/usr/bin/setpriv",
                                            [&] {
                                              std::vector<std::string> a = {"--reuid=65534", "--regid=65534",
                                                                            "--clear-groups", CHROMATRACE_EXE};
                                              a.insert(a.end(), args.begin(), args.end());
                                              return a;
                                            }())
                        : run_chromatrace(args);
    EXPECT_EQ(r.exit_code, 2) << c.args[0] << ": " << r.err;
    EXPECT_EQ(line_count(r.err), 1) << r.err;
    EXPECT_NE(r.err.find(c.output + where), std::string::npos) << r.err;
  }
  EXPECT_TRUE(names_in(locked).empty());
}

}  // namespace
}  // namespace ct
