// SPDX-License-Identifier: Apache-2.0
// What `chromatrace` loads to start: --help, --version and check-scene run in the front executable, which links
// no image library (cli/front.cpp); every other command line is handed over, unchanged, to the full program.
// The shared libraries a run loads are read from the dynamic loader's own report (LD_DEBUG=files), which names
// every library it maps, dlopen'ed ones included, in the front and, after the hand-over (execv), in the full
// program.
#include <algorithm>
#include <filesystem>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/cli/run_command.h"
#include "tests/cli/text_files.h"

namespace ct {
namespace {

namespace fs = std::filesystem;

using test::kMinimal;
const std::string kScenes = std::string(CHROMATRACE_SOURCE_DIR) + "/scenes";

struct TracedRun {
  test::CommandResult result;
  std::set<std::string> libraries;  // file names of the shared libraries the loader mapped
  std::string err;                  // stderr without the loader's lines
};

// Runs chromatrace with LD_DEBUG=files in its environment only (through env(1)).
TracedRun run_traced(const std::vector<std::string>& args) {
  std::vector<std::string> env_args = {"LD_DEBUG=files", CHROMATRACE_EXE};
  env_args.insert(env_args.end(), args.begin(), args.end());
  TracedRun run{test::run_program("/usr/bin/env", env_args), {}, {}};
  // The loader's lines start with its process id and a tab; "file=NAME [0];  generating link map" for each
  // library it maps (needed or opened with dlopen; a library it only looks for and does not find has none).
  const std::regex loader_line(R"(^\s*\d+:\t.*)");
  const std::regex mapped(R"(file=(\S+) \[\d+\];\s+generating link map)");
  std::istringstream lines(run.result.err);
  for (std::string line; std::getline(lines, line);) {
    if (!std::regex_match(line, loader_line)) {
      run.err += line + "\n";
      continue;
    }
    std::smatch m;
    if (std::regex_search(line, m, mapped)) run.libraries.insert(fs::path(m[1].str()).filename().string());
  }
  return run;
}

bool loads(const TracedRun& run, const std::string& prefix) {
  return std::any_of(run.libraries.begin(), run.libraries.end(),
                     [&](const std::string& name) { return name.rfind(prefix, 0) == 0; });
}

// The image libraries (and Debian's OpenImageIO's first dependencies) that the front must not load.
const std::vector<std::string> kImageLibraries = {"libOpenImageIO", "libopencv", "libOpenEXR", "libIlmThread",
                                                  "libraw",         "libtiff",   "libavcodec"};

void expect_no_image_library(const TracedRun& run, const std::string& what) {
  // The report is there at all: the front's own libraries are in it.
  EXPECT_TRUE(loads(run, "libfmt")) << what << ": no loader report in\n" << run.result.err;
  for (const std::string& lib : kImageLibraries) EXPECT_FALSE(loads(run, lib)) << what << " loads " << lib;
  // What the front links, and nothing else: fmt, TBB and Embree (check-scene's warnings run plan's model, which
  // traces rays; bench/README.md, "Start-up"), TBB's allocator (which TBB opens itself), the C++ runtime and the C
  // library (and the sanitisers' runtimes in that build).
  const std::set<std::string> allowed = {"libfmt",   "libtbb", "libembree3", "libstdc++", "libm",
                                         "libgcc_s", "libc",   "libtbbmalloc", "libasan", "libubsan"};
  for (const std::string& name : run.libraries)
    EXPECT_TRUE(allowed.count(name.substr(0, name.find('.')))) << what << " loads " << name;
}

TEST(Startup, HelpAndVersionLoadNoImageLibrary) {
  const TracedRun help = run_traced({"--help"});
  EXPECT_EQ(help.result.exit_code, 0);
  EXPECT_EQ(help.result.out.rfind("chromatrace: simulate how an image was made", 0), 0u) << help.result.out;
  EXPECT_NE(help.result.out.find("  prepare-texture  "), std::string::npos) << help.result.out;
  expect_no_image_library(help, "--help");

  const TracedRun version = run_traced({"--version"});
  EXPECT_EQ(version.result.exit_code, 0);
  EXPECT_EQ(version.result.out, "chromatrace 0.1.0\n");
  expect_no_image_library(version, "--version");

  const TracedRun none = run_traced({});
  EXPECT_EQ(none.result.exit_code, 2);
  EXPECT_EQ(none.err, "chromatrace: error: A subcommand is required\n");
  expect_no_image_library(none, "no subcommand");
}

TEST(Startup, CheckSceneLoadsNoImageLibrary) {
  const TracedRun text = run_traced({"check-scene", kMinimal.string()});
  EXPECT_EQ(text.result.exit_code, 0) << text.err;
  EXPECT_EQ(text.result.out.rfind(kMinimal.string() + ": valid scene \"minimal\"\n", 0), 0u) << text.result.out;
  expect_no_image_library(text, "check-scene");

  const TracedRun json = run_traced({"check-scene", "--json", kMinimal.string()});
  ASSERT_EQ(json.result.exit_code, 0) << json.err;
  EXPECT_EQ(nlohmann::json::parse(json.result.out)["scene"]["objects"], 2);
  expect_no_image_library(json, "check-scene --json");

  const TracedRun series = run_traced({"check-scene", "--quiet", kScenes + "/paper/series.json"});
  EXPECT_EQ(series.result.exit_code, 0) << series.err;
  EXPECT_EQ(series.result.out, "");
  expect_no_image_library(series, "check-scene on a series");

  const TracedRun help = run_traced({"check-scene", "--help"});
  EXPECT_EQ(help.result.exit_code, 0);
  EXPECT_NE(help.result.out.find("--emit-sensor"), std::string::npos) << help.result.out;
  expect_no_image_library(help, "check-scene --help");
}

TEST(Startup, CheckSceneErrorsLoadNoImageLibrary) {
  const TracedRun missing = run_traced({"check-scene", "/nonexistent/scene.json"});
  EXPECT_EQ(missing.result.exit_code, 2);
  EXPECT_EQ(missing.err, "chromatrace check-scene: error: /nonexistent/scene.json: cannot open file\n");
  expect_no_image_library(missing, "check-scene on a missing file");

  const std::string bad = std::string(CHROMATRACE_TEST_DATA) + "/scenes/bad/negative_radius.json";
  const TracedRun invalid = run_traced({"check-scene", bad});
  EXPECT_EQ(invalid.result.exit_code, 2);
  EXPECT_EQ(invalid.err.rfind("chromatrace check-scene: error: " + bad + ": ", 0), 0u) << invalid.err;
  EXPECT_EQ(std::count(invalid.err.begin(), invalid.err.end(), '\n'), 1) << invalid.err;
  expect_no_image_library(invalid, "check-scene on a bad scene");

  const TracedRun usage = run_traced({"check-scene"});
  EXPECT_EQ(usage.result.exit_code, 2);
  EXPECT_EQ(usage.err, "chromatrace check-scene: error: file is required\n");
  expect_no_image_library(usage, "check-scene without a file");
}

// A scene with an image texture is checked by the full program (its texels are read with OpenImageIO): the
// same answer as for any scene, and this is where the report shows OpenImageIO loaded, so the checks above can
// fail.
TEST(Startup, ImageTexturesAndOtherCommandsAreHandedOver) {
  const TracedRun textured = run_traced({"check-scene", kScenes + "/textured/textured.json"});
  EXPECT_EQ(textured.result.exit_code, 0) << textured.err;
  EXPECT_EQ(textured.result.out.rfind(kScenes + "/textured/textured.json: valid scene", 0), 0u);
  EXPECT_TRUE(loads(textured, "libOpenImageIO"));

  const std::string missing_texture = std::string(CHROMATRACE_TEST_DATA) + "/scenes/bad/missing_texture.json";
  const TracedRun bad = run_traced({"check-scene", missing_texture});
  EXPECT_EQ(bad.result.exit_code, 2);
  EXPECT_EQ(bad.err.rfind("chromatrace check-scene: error: " + missing_texture + ": ", 0), 0u) << bad.err;
  EXPECT_EQ(std::count(bad.err.begin(), bad.err.end(), '\n'), 1) << bad.err;

  // argv is handed over unchanged: the usage line names the command the user ran.
  const TracedRun help = run_traced({"render", "--help"});
  EXPECT_EQ(help.result.exit_code, 0) << help.err;
  EXPECT_EQ(help.result.out.rfind("Render a scene with the reference spectral path tracer\nUsage: " +
                                      std::string(CHROMATRACE_EXE) + " render ",
                                  0),
            0u)
      << help.result.out;
  EXPECT_TRUE(loads(help, "libOpenImageIO"));
}

TEST(Startup, HandedOverCommandsKeepTheirExitCodes) {
  const fs::path dir = fs::temp_directory_path() / ("chromatrace-startup-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string out = (dir / "r.exr").string();
  const test::CommandResult render = test::run_chromatrace(
      {"render", kMinimal.string(), "-o", out, "--resolution", "8x6", "--spp", "1", "--bands", "400:700:100", "--quiet"});
  EXPECT_EQ(render.exit_code, 0) << render.err;  // stderr: the warning that 1 sample is noisy
  const test::CommandResult info = test::run_chromatrace({"info", "--json", out});
  ASSERT_EQ(info.exit_code, 0) << info.err;
  const nlohmann::json described = nlohmann::json::parse(info.out);
  EXPECT_EQ(described["width"], 8);
  EXPECT_EQ(described["height"], 6);

  const test::CommandResult missing = test::run_chromatrace({"render", "/nonexistent/scene.json", "-o", out});
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_EQ(missing.err, "chromatrace render: error: /nonexistent/scene.json: cannot open file\n");
  const test::CommandResult usage = test::run_chromatrace({"render", kMinimal.string(), "--no-such-option"});
  EXPECT_EQ(usage.exit_code, 2);
  EXPECT_EQ(usage.err.rfind("chromatrace render: error: ", 0), 0u) << usage.err;
  const test::CommandResult not_a_number = test::run_chromatrace({"render", kMinimal.string(), "-o", out, "--spp", "abc"});
  EXPECT_EQ(not_a_number.exit_code, 2);
  EXPECT_EQ(not_a_number.err.rfind("chromatrace render: error: ", 0), 0u) << not_a_number.err;
  EXPECT_NE(not_a_number.err.find("--spp"), std::string::npos) << not_a_number.err;
  fs::remove_all(dir);
}

// Both executables describe the same command: the front's --help is the full program's (but for the path in
// the usage line, which is argv[0]).
TEST(Startup, FrontHelpIsTheFullPrograms) {
  const std::string full = CHROMATRACE_FULL_EXE;
  const test::CommandResult front_help = test::run_chromatrace({"--help"});
  test::CommandResult full_help = test::run_program(full, {"--help"});
  ASSERT_EQ(full_help.exit_code, 0);
  const std::string usage = "Usage: " + full + " ";
  ASSERT_NE(full_help.out.find(usage), std::string::npos) << full_help.out;
  full_help.out.replace(full_help.out.find(usage), usage.size(), "Usage: " + std::string(CHROMATRACE_EXE) + " ");
  EXPECT_EQ(front_help.out, full_help.out);
}

}  // namespace
}  // namespace ct
