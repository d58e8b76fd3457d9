// SPDX-License-Identifier: Apache-2.0
// The thirteen families of a hostile sweep (docs/errors.md, "Every command: outputs, special files, JSON and
// files" and the sections after it), each with more than one instance, end to end through the executable: exit 2
// (or 1 for a failed write), one line, nothing written outside the output, no partial output, no hang.
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include <OpenImageIO/imageio.h>
#include <fmt/core.h>

#include "core/json_input.h"
#include "tests/cli/run_command.h"
#include "tests/cli/text_files.h"
#include "tests/core/image_fixtures.h"
#include "tests/core/spectral_exr_fixtures.h"

namespace ct {
namespace {

namespace fs = std::filesystem;
using test::line_count;
using test::read_text;
using test::run_chromatrace;
using test::write_text;

using test::kMinimal;

// chromatrace with a time limit: a command that waits on a special file is killed after `seconds` (exit 124).
test::CommandResult run_within(int seconds, const std::vector<std::string>& args) {
  std::vector<std::string> all = {std::to_string(seconds), CHROMATRACE_EXE};
  all.insert(all.end(), args.begin(), args.end());
  return test::run_program("/usr/bin/timeout", all);
}

// chromatrace under a shell's limits (`ulimit` arguments, e.g. "-f 16"), signals at their defaults: SIGXFSZ is
// not ignored here, as it is not in a user's shell.
test::CommandResult run_with_ulimit(const std::string& limit, const std::vector<std::string>& args) {
  std::vector<std::string> all = {"-c", "ulimit " + limit + " && exec \"$@\"", "sh", CHROMATRACE_EXE};
  all.insert(all.end(), args.begin(), args.end());
  return test::run_program("/bin/sh", all);
}

// The names in `dir` (hidden ones included), sorted.
std::vector<std::string> names_in(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir)) names.push_back(entry.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

// One line on stderr containing `says`, with the exit code `code`.
void expect_refused(const test::CommandResult& r, int code, const std::string& says, const std::string& what) {
  EXPECT_EQ(r.exit_code, code) << what << ": " << r.err;
  EXPECT_EQ(line_count(r.err), 1) << what << ": " << r.err;
  EXPECT_NE(r.err.find(says), std::string::npos) << what << ": " << r.err;
}

// A spectral render with a camera, as sensor and compare read it.
fs::path write_render(const test::TempDir& dir, const std::string& name, int width, int height) {
  test::ComponentImage image = test::make_component_image(width, height, 5);
  image.layout.attributes["chromatrace.camera"] = fmt::format(
      R"({{"horizontal_fov_deg": 50, "vertical_fov_deg": 38.6, "resolution": [{}, {}]}})", width, height);
  const fs::path path = dir.file(name);
  test::write_image(path, image, 8);
  return path;
}

// ---- 1: an output that is an input, or another output ---------------------------------------------------

TEST(HostileInput, PlanAndCheckSceneNeverWriteOverAnInputOrTheirOtherOutput) {
  test::TempDir dir;
  const fs::path scene = dir.file("s.json");
  fs::copy_file(kMinimal, scene);
  const std::string before = read_text(scene);
  fs::create_hard_link(scene, dir.file("hard.json"));
  fs::create_symlink(scene, dir.file("soft.json"));
  const fs::path plan = dir.file("p.json");
  const struct {
    std::vector<std::string> args;
    std::string says;
  } cases[] = {
      {{"plan", scene.string(), "-o", scene.string()}, scene.string() + ": is the same file as the input"},
      {{"plan", scene.string(), "--report", scene.string()}, scene.string() + ": is the same file as the input"},
      {{"plan", scene.string(), "-o", dir.file("hard.json").string()}, "hard.json: is the same file as the input"},
      {{"plan", scene.string(), "--report", dir.file("soft.json").string()}, "soft.json: is the same file as the input"},
      {{"plan", scene.string(), "-o", plan.string(), "--report", plan.string()},
       plan.string() + ": is the same file as the output " + plan.string()},
      {{"plan", scene.string(), "-o", plan.string(), "--report", (dir.path() / "." / "p.json").string()},
       "is the same file as the output " + plan.string()},
  };
  for (const auto& c : cases) {
    const auto r = run_chromatrace(c.args);
    expect_refused(r, 2, c.says, fmt::format("{}", fmt::join(c.args, " ")));
    EXPECT_EQ(read_text(scene), before);
    EXPECT_FALSE(fs::exists(plan));
  }
  // check-scene --emit and --emit-sensor of one series variant into one file.
  const fs::path series = fs::path(CHROMATRACE_TEST_DATA) / "scenes" / "series_merge.json";
  const auto r = run_chromatrace({"check-scene", series.string(), "--variant", "base", "--emit",
                                  dir.file("v.json").string(), "--emit-sensor", dir.file("v.json").string()});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_FALSE(fs::exists(dir.file("v.json")));
}

// ---- 2: names inside input files that would become paths ----------------------------------------------

TEST(HostileInput, SeriesVariantNamesStayInsideTheOutputDirectory) {
  test::TempDir dir;
  fs::copy_file(kMinimal, dir.file("minimal.json"));
  fs::create_directories(dir.file("out"));
  const struct {
    std::string name_json, says;
  } cases[] = {
      {R"("..")", R"(variants[0].name: ".." cannot be a file name)"},
      {R"("a/../../x")", R"(variants[0].name: "a/../../x" cannot be a file name: it holds a "/")"},
      {R"("/tmp/abs")", R"("/tmp/abs" cannot be a file name)"},
      {R"(".")", R"("." cannot be a file name)"},
      {R"("renders")", R"("renders" is a name series writes)"},
      {R"("a\nb")", R"("a\nb" cannot be a file name: it holds a control character)"},
  };
  for (const auto& c : cases) {
    const fs::path series = dir.file("series.json");
    write_text(series, R"({"format": "chromatrace-series/1", "base": "minimal.json", "variants": [{"name": )" +
                           c.name_json + "}]}");
    expect_refused(run_chromatrace({"check-scene", series.string()}), 2, c.says, "check-scene " + c.name_json);
    expect_refused(run_chromatrace({"series", series.string(), "-o", dir.file("out/run").string(), "--quiet"}), 2,
                   c.says, "series " + c.name_json);
    EXPECT_EQ(names_in(dir.path()), (std::vector<std::string>{"minimal.json", "out", "series.json"})) << c.name_json;
    EXPECT_TRUE(fs::is_empty(dir.file("out"))) << c.name_json;
  }
}

// ---- 3: images of every format OpenImageIO reads -----------------------------------------------------

TEST(HostileInput, AnalyzeReadsGifBmpTgaAndPnmWithoutCrashing) {
  test::TempDir dir;
  const fs::path seeds = fs::path(CHROMATRACE_SOURCE_DIR) / "tests" / "fuzz" / "seeds" / "image";
  for (const char* name : {"small.gif", "small.bmp", "small.tga", "grey.pnm"}) {
    const fs::path out = dir.file(std::string(name) + ".analysis");
    const auto r = run_chromatrace({"analyze", (seeds / name).string(), "-o", out.string(), "--quiet"});
    // A grey (one-channel) image is refused as bad input; the colour ones are analysed.
    if (std::string(name) == "grey.pnm") {
      expect_refused(r, 2, "needs channels R, G, B", name);
      EXPECT_FALSE(fs::exists(out));
    } else {
      EXPECT_EQ(r.exit_code, 0) << name << ": " << r.err;
      EXPECT_TRUE(fs::is_regular_file(out / "analysis.json")) << name;
    }
  }
}

// ---- 4: special files as inputs ------------------------------------------------------------------------

TEST(HostileInput, AFifoAsAnyInputIsRefusedAtOnceAndAPipeWithAWriterIsRead) {
  test::TempDir dir;
  const fs::path fifo = dir.file("pipe");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const fs::path render = write_render(dir, "r.exr", 8, 6);
  const std::string scene = read_text(kMinimal);
  const struct {
    std::vector<std::string> args;
    std::string says;
  } cases[] = {
      {{"info", fifo.string()}, fifo.string() + ": is a FIFO; this file is read only from a regular file"},
      {{"sensor", fifo.string(), "-o", dir.file("c.exr").string()}, fifo.string() + ": is a FIFO"},
      {{"compare", render.string(), fifo.string(), "-o", dir.file("cmp").string()}, fifo.string() + ": is a FIFO"},
      {{"check-scene", fifo.string()}, fifo.string() + ": is a FIFO that nothing writes to"},
      {{"sensor", render.string(), "-o", dir.file("c.exr").string(), "--config", fifo.string()},
       fifo.string() + ": is a FIFO that nothing writes to"},
      {{"analyze", fifo.string(), "-o", dir.file("an").string()}, fifo.string() + ": is a FIFO"},
  };
  for (const auto& c : cases) {
    const auto r = run_within(20, c.args);
    expect_refused(r, 2, c.says, fmt::format("{}", fmt::join(c.args, " ")));
  }
  // A pipe that something writes to is a stream to read: the scene arrives through it and checks.
  std::thread writer([&] { std::ofstream(fifo) << scene; });
  const auto r = run_within(20, {"check-scene", fifo.string()});
  writer.join();
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::is_fifo(fifo));
}

// ---- 5: unbounded reads ----------------------------------------------------------------------------------

TEST(HostileInput, ReadsFromAnEndlessDeviceStopAtTheLimit) {
  test::TempDir dir;
  const fs::path render = write_render(dir, "r.exr", 8, 6);
  std::string scene = read_text(kMinimal);
  write_text(dir.file("csv.json"),
             std::string(scene).replace(scene.find(R"({"samples")"), 0, R"({"csv": "/dev/zero"}, "x": )"));
  const std::string limit = "/dev/zero: more than the limit of 268435456 bytes (256 MiB)";
  const struct {
    std::vector<std::string> args;
    std::string says;
  } cases[] = {
      {{"check-scene", "/dev/zero"}, limit},
      {{"check-scene", dir.file("csv.json").string()}, "spectra.white.csv: " + limit},
      {{"sensor", render.string(), "-o", dir.file("c.exr").string(), "--config", "/dev/zero"}, limit},
      {{"render", kMinimal.string(), "--plan", "/dev/zero", "-o", dir.file("r2.exr").string()}, limit},
  };
  for (const auto& c : cases) {
    // Under a 1 GB address-space limit: the read must stop at 256 MiB, not grow to 4 GB.
    const auto r = run_with_ulimit("-v 3000000", c.args);
    expect_refused(r, 2, c.says, fmt::format("{}", fmt::join(c.args, " ")));
  }
  EXPECT_EQ(names_in(dir.path()), (std::vector<std::string>{"csv.json", "r.exr"}));
}

// ---- 6 and 7: image sizes, claimed or real ---------------------------------------------------------------

// A PNG of the given size whose header is complete and whose pixel data is one empty row (66 bytes in all).
void write_png_header(const fs::path& path, std::uint32_t width, std::uint32_t height) {
  const auto crc = [](const std::string& bytes) {
    std::uint32_t c = 0xffffffffu;
    for (const char ch : bytes) {
      c ^= static_cast<unsigned char>(ch);
      for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xedb88320u & (0u - (c & 1u)));
    }
    return c ^ 0xffffffffu;
  };
  const auto be32 = [](std::uint32_t v) {
    return std::string{static_cast<char>(v >> 24), static_cast<char>(v >> 16), static_cast<char>(v >> 8),
                       static_cast<char>(v)};
  };
  const auto chunk = [&](const std::string& type, const std::string& data) {
    return be32(static_cast<std::uint32_t>(data.size())) + type + data + be32(crc(type + data));
  };
  const std::string ihdr = be32(width) + be32(height) + std::string{8, 2, 0, 0, 0};  // 8-bit RGB
  const std::string idat = std::string("\x78\x9c\x63\x00\x00\x00\x01\x00\x01", 9);
  write_text(path, std::string("\x89PNG\r\n\x1a\n", 8) + chunk("IHDR", ihdr) + chunk("IDAT", idat) + chunk("IEND", ""));
}

TEST(HostileInput, AnImageHeaderClaimingMoreThanItsFileOrTheBudgetIsRefusedBeforeAllocating) {
  test::TempDir dir;
  write_png_header(dir.file("giant.png"), 32000, 32000);
  write_png_header(dir.file("claims.png"), 4000, 4000);
  ASSERT_EQ(fs::file_size(dir.file("giant.png")), 66u);
  const struct {
    fs::path file;
    std::string says;
  } cases[] = {
      {dir.file("giant.png"), "image of 32000x32000 pixels, 3 channels: needs 12.3 GB as floats, more than the budget of 1 GiB"},
      {dir.file("claims.png"), "image of 4000x4000 pixels, 3 channels: its header claims 48000000 bytes of samples, more than its 66 bytes can hold"},
  };
  for (const auto& c : cases) {
    // Refused from the header under a 1 GB address-space limit, within seconds.
    const auto r = run_with_ulimit("-v 3000000", {"analyze", c.file.string(), "-o", dir.file("an").string()});
    expect_refused(r, 2, c.says, c.file.string());
    EXPECT_FALSE(fs::exists(dir.file("an")));
  }
}

TEST(HostileInput, AValidImageBeyondTheMemoryBudgetIsRefusedAsAnalysedImageAndAsTexture) {
  test::TempDir dir;
  // 10000 x 10000 RGB, all zero: 2.5 MB of PNG whose floats would take 1.2 GB.
  const fs::path big = dir.file("big.png");
  {
    auto out = OIIO::ImageOutput::create(big.string());
    ASSERT_TRUE(out);
    ASSERT_TRUE(out->open(big.string(), OIIO::ImageSpec(10000, 10000, 3, OIIO::TypeDesc::UINT8)));
    const std::vector<unsigned char> row(30000, 0);
    for (int y = 0; y < 10000; ++y) ASSERT_TRUE(out->write_scanline(y, 0, OIIO::TypeDesc::UINT8, row.data()));
    ASSERT_TRUE(out->close());
  }
  const std::string says = "big.png: image of 10000x10000 pixels, 3 channels: needs 1.2 GB as floats, more than the budget of 1 GiB";
  expect_refused(run_with_ulimit("-v 3000000", {"analyze", big.string(), "-o", dir.file("an").string()}), 2, says,
                 "analyze");
  std::string scene = read_text(kMinimal);
  scene.replace(scene.find(R"("reflectance": "white")"), 22, R"("reflectance": {"texture": "big.png"})");
  write_text(dir.file("textured.json"), scene);
  expect_refused(run_with_ulimit("-v 3000000", {"check-scene", dir.file("textured.json").string()}), 2, says,
                 "check-scene");
  EXPECT_FALSE(fs::exists(dir.file("an")));
}

// ---- 8: numbers that overflow into the data -------------------------------------------------------------

TEST(HostileInput, OverflowingExposurePitchOrRadianceIsRefusedAndInfoFlagsNonFinitePixels) {
  test::TempDir dir;
  const fs::path render = write_render(dir, "r.exr", 8, 6);
  const fs::path out = dir.file("c.exr");
  const struct {
    std::vector<std::string> args;
    std::string says;
  } cases[] = {
      {{"sensor", render.string(), "-o", out.string(), "--exposure-scale", "1e308"}, "exposure.scale: must be at most 1e+06, got 1e+308"},
      {{"sensor", render.string(), "-o", out.string(), "--set", "pixel.pitch_um=1e200"}, "pixel.pitch_um: must be at most 10000, got 1e+200"},
      {{"sensor", render.string(), "-o", out.string(), "--set", "exposure.time_s=1e300"}, "exposure.time_s: must be at most 1e+06"},
  };
  for (const auto& c : cases) {
    expect_refused(run_chromatrace(c.args), 2, c.says, c.args.back());
    EXPECT_FALSE(fs::exists(out));
  }
  // Radiance of 3e38 in one band: the linear stage overflows a float, and says so.
  test::write_raw_exr(dir.file("hot.exr"), 4, 4,
                      {test::constant_channel("S0.500,000000nm", 4, 4, 3e38f),
                       test::constant_channel("S0.600,000000nm", 4, 4, 3e38f)});
  expect_refused(run_chromatrace({"sensor", dir.file("hot.exr").string(), "-o", out.string(), "--exposure-s", "1",
                                  "--quiet"}),
                 2, "are 4.25696e+46, beyond a float", "radiance 3e38");
  EXPECT_FALSE(fs::exists(out));
  // info on a camera RGB image holding Inf and NaN: flagged, exit 2.
  std::vector<float> values(16, 0.5f);
  values[5] = std::numeric_limits<float>::infinity();
  test::write_raw_exr(dir.file("rgb.exr"), 4, 4,
                      {{"R", values}, test::constant_channel("G", 4, 4, 0.5f),
                       test::constant_channel("B", 4, 4, std::numeric_limits<float>::quiet_NaN())});
  const auto r = run_chromatrace({"info", dir.file("rgb.exr").string()});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("rgb.exr: 16 NaN/Inf values in channel B (first at 0,0); 1 more channel has NaN/Inf"),
            std::string::npos)
      << r.err;
}

// ---- 9: a file-size limit, the signal at its default ----------------------------------------------------

TEST(HostileInput, AFileSizeLimitEndsInExitOneWithNoTemporaryFile) {
  test::TempDir dir, out;
  const fs::path render = write_render(dir, "r.exr", 64, 48);
  const struct {
    std::vector<std::string> args;
    std::string target;
  } cases[] = {
      {{"render", kMinimal.string(), "--spp", "16", "--quiet", "-o", out.file("out.exr").string()}, "out.exr"},
      {{"sensor", render.string(), "--quiet", "-o", out.file("c.tif").string(), "--preset", "smartphone", "--exposure-s", "auto"}, "c.tif"},
      {{"analyze", render.string(), "--quiet", "-o", out.file("an").string()}, "an"},
  };
  for (const auto& c : cases) {
    const auto r = run_with_ulimit("-f 16", c.args);
    EXPECT_EQ(r.exit_code, 1) << c.target << ": " << r.err;
    EXPECT_EQ(line_count(r.err), 1) << r.err;
    EXPECT_TRUE(fs::is_empty(out.path())) << c.target << ": " << fmt::format("{}", fmt::join(names_in(out.path()), " "));
  }
}

// ---- 10, 11: option values out of range, names too long --------------------------------------------------

TEST(HostileInput, OutOfRangeOptionsAndOverlongNamesAreBadInputNamingTheOption) {
  test::TempDir dir;
  const std::string long_name = dir.file(std::string(4097, 'a')).string();
  const std::string long_part = dir.file(std::string(300, 'b') + ".exr").string();
  const struct {
    std::vector<std::string> args;
    std::string says;
  } cases[] = {
      {{"render", kMinimal.string(), "--max-bounces", "2147483647", "-o", dir.file("r.exr").string()}, "--max-bounces: must be in [0, 1000], got 2147483647"},
      {{"series", (fs::path(CHROMATRACE_TEST_DATA) / "scenes" / "series_merge.json").string(), "--max-bounces", "5000", "-o", dir.file("s").string()}, "--max-bounces: must be in [0, 1000]"},
      {{"render", kMinimal.string(), "-o", long_name}, "the output path is"},
      {{"render", kMinimal.string(), "-o", long_part}, "a name in the output path is 304 bytes long"},
      {{"compare", kMinimal.string(), kMinimal.string(), "-o", long_name}, "the output path is"},
      {{"render", kMinimal.string(), "--time-limit", "nan", "-o", dir.file("r.exr").string()}, "--time-limit: must be a finite number of seconds >= 0"},
      {{"render", kMinimal.string(), "--time-limit", "inf", "-o", dir.file("r.exr").string()}, "--time-limit: must be a finite number of seconds >= 0"},
      {{"plan", kMinimal.string(), "--preview-spp", "2000000000", "-o", dir.file("p").string()}, "--preview-spp: must be 1 to 4096, got 2000000000"},
      {{"plan", kMinimal.string(), "--preview-size", "100000", "-o", dir.file("p").string()}, "--preview-size: must be 1 to 1024, got 100000"},
  };
  for (const auto& c : cases) expect_refused(run_chromatrace(c.args), 2, c.says, c.args[0]);
  EXPECT_TRUE(fs::is_empty(dir.path()));
}

// ---- 12: every error one line -----------------------------------------------------------------------------

TEST(HostileInput, LineBreaksInNamesAndLibraryMessagesStayOnOneLine) {
  test::TempDir dir;
  std::string scene = read_text(kMinimal);
  std::string names = scene;
  names.replace(names.find(R"("name": "ball")"), 14, R"("name": "fl\noor")");
  names.replace(names.find(R"("name": "floor")"), 15, R"("name": "fl\noor")");
  write_text(dir.file("names.json"), names);
  write_text(dir.file("csv.json"), std::string(scene).replace(scene.find(R"({"samples")"), 0,
                                                              R"({"csv": "no\nsuch.csv"}, "x": )"));
  const fs::path render = write_render(dir, "r.exr", 8, 6);
  write_text(dir.file("cut.png"), read_text(fs::path(CHROMATRACE_SOURCE_DIR) / "tests/fuzz/seeds/image/rgba.png").substr(0, 80));
  write_text(dir.file("cut.tif"), read_text(fs::path(CHROMATRACE_SOURCE_DIR) / "tests/fuzz/seeds/image/small16.tif").substr(0, 200));
  const struct {
    std::vector<std::string> args;
    std::string says;
  } cases[] = {
      {{"check-scene", dir.file("names.json").string()}, R"("fl\noor" is already the name of)"},
      {{"check-scene", dir.file("csv.json").string()}, R"(no\nsuch.csv)"},
      {{"sensor", render.string(), "-o", dir.file("no\ndir/c.exr").string()}, R"(no\ndir/c.exr: directory)"},
      {{"analyze", dir.file("cut.png").string(), "-o", dir.file("a1").string()}, "cut.png"},
      {{"analyze", dir.file("cut.tif").string(), "-o", dir.file("a2").string()}, "cut.tif"},
  };
  for (const auto& c : cases) expect_refused(run_chromatrace(c.args), 2, c.says, c.args[1]);
}

// An existing output this user may not write is refused, as cp refuses it, and left as it was: the rename that
// replaces a file needs only the directory's permission. Run as the unprivileged user nobody (root may write any file,
// and replaces it as cp does); skipped where this test cannot switch user.
TEST(HostileInput, AReadOnlyOutputIsNotReplaced) {
  if (::geteuid() != 0) GTEST_SKIP() << "needs root to run the command as another user";
  test::TempDir dir;
  fs::permissions(dir.path(), fs::perms::all);  // nobody may create files here
  const fs::path output = dir.file("locked.exr");
  write_text(output, "the user's file");
  fs::permissions(output, fs::perms::owner_read | fs::perms::group_read | fs::perms::others_read);
  std::vector<std::string> args = {"--reuid=65534", "--regid=65534", "--clear-groups", CHROMATRACE_EXE, "render", kMinimal.string(),
                                   "--spp", "1", "-o", output.string()};
  const auto r = test::run_program("/usr/bin/setpriv", args);
  expect_refused(r, 2, output.string() + ": exists and is not writable (Permission denied); it is not replaced", "render");
  EXPECT_EQ(read_text(output), "the user's file");
  EXPECT_EQ(std::distance(fs::directory_iterator(dir.path()), fs::directory_iterator()), 1);
}

// A series of 1001 chained variants (each extending the last): refused before any is read, where each would cost a
// parse and a preview render (about 16 ms each here: 5 000 of them took over a minute).
TEST(HostileInput, ASeriesOfMoreThanAThousandVariantsIsRefused) {
  test::TempDir dir;
  Json variants = Json::array({{{"name", "v0"}, {"patch", {{"render", {{"seed", 0}}}}}}});
  for (int i = 1; i <= 1000; ++i)
    variants.push_back({{"name", fmt::format("v{}", i)}, {"extends", fmt::format("v{}", i - 1)}, {"patch", {{"render", {{"seed", i}}}}}});
  write_text(dir.file("long.json"), Json({{"format", "chromatrace-series/1"}, {"base", kMinimal.string()}, {"variants", variants}}).dump());
  expect_refused(run_chromatrace({"check-scene", dir.file("long.json").string()}), 2,
                 "long.json: variants: 1001 variants; a series holds at most 1000 (split it into several)", "check-scene");
}

// An option that takes several values is given the words after it by the parser, even another option of the command:
// each such command line is named as what it is, one line, exit 2, nothing written (no "--output is required", no
// "--target-de00: cannot open file").
TEST(HostileInput, AnOptionTakenForAnothersValueIsNamed) {
  test::TempDir dir;
  const fs::path render = write_render(dir, "r.exr", 8, 6);
  const fs::path series = fs::path(CHROMATRACE_TEST_DATA) / "scenes" / "series_merge.json";
  const struct {
    std::vector<std::string> args;
    std::string says;
  } cases[] = {
      {{"analyze", render.string(), "--rect", "--quiet", "-o", dir.file("a").string()}, "--rect: no value given before the option --quiet"},
      {{"plan", kMinimal.string(), "--cycles-pilot", "--target-de00", "1", "-o", dir.file("p.json").string()},
       "--cycles-pilot: no value given before the option --target-de00"},
      {{"series", series.string(), "--variant", "-o", dir.file("s").string()}, "--variant: no value given before the option -o"},
      {{"sensor", render.string(), "--set", "-o", dir.file("x.exr").string()}, "--set: no value given before the option -o"},
  };
  for (const auto& c : cases) expect_refused(run_chromatrace(c.args), 2, "chromatrace " + c.args[0] + ": error: " + c.says, c.args[0]);
  EXPECT_EQ(std::distance(fs::directory_iterator(dir.path()), fs::directory_iterator()), 1);  // the render alone
}

// Linux allows any bytes in a file's name; JSON holds only UTF-8. An image whose name is not UTF-8 is analysed and
// compared like any other: its name in analysis.json and compare.json with U+FFFD for the byte, not a failed run.
TEST(HostileInput, AFileNameThatIsNotUtf8IsWrittenWithAReplacementCharacter) {
  test::TempDir dir;
  const fs::path image = dir.file("r\xff.exr");
  fs::copy_file(write_render(dir, "r.exr", 8, 6), image);
  const auto analysed = run_chromatrace({"analyze", image.string(), "-o", dir.file("a").string(), "-q", "--no-plots"});
  ASSERT_EQ(analysed.exit_code, 0) << analysed.err;
  EXPECT_NE(read_text(dir.file("a") / "analysis.json").find("r\xEF\xBF\xBD.exr"), std::string::npos);
  const auto compared = run_chromatrace({"compare", image.string(), image.string(), "-o", dir.file("c").string()});
  ASSERT_EQ(compared.exit_code, 0) << compared.err;
  EXPECT_NE(read_text(dir.file("c") / "compare.json").find("r\xEF\xBF\xBD.exr"), std::string::npos);
}

// ---- 13: outputs that appear whole or not at all ----------------------------------------------------------

TEST(HostileInput, CompareAndSensorLeaveNoPartialOrUnreadableOutput) {
  test::TempDir dir, out;
  const fs::path a = write_render(dir, "a.exr", 32, 24), b = write_render(dir, "b.exr", 32, 24);
  // compare cut short by a file-size limit: no directory, no staging directory.
  auto r = test::run_program_with_file_size_limit(CHROMATRACE_EXE,
                                                  {"compare", a.string(), b.string(), "-o", out.file("cmp").string(), "--quiet"}, 4);
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_TRUE(fs::is_empty(out.path())) << fmt::format("{}", fmt::join(names_in(out.path()), " "));
  // Into an existing directory: the previous files stay until all new ones are complete.
  fs::create_directories(out.file("cmp"));
  write_text(out.file("cmp/compare.json"), "previous");
  r = test::run_program_with_file_size_limit(CHROMATRACE_EXE,
                                             {"compare", a.string(), b.string(), "-o", out.file("cmp").string(), "--quiet"}, 4);
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_EQ(read_text(out.file("cmp/compare.json")), "previous");
  EXPECT_EQ(names_in(out.path()), std::vector<std::string>{"cmp"});
  r = run_chromatrace({"compare", a.string(), b.string(), "-o", out.file("cmp").string(), "--quiet"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(names_in(out.file("cmp")), (std::vector<std::string>{"compare.html", "compare.json", "compare.png"}));
  // A DNG under 22 pixels a side, which raw readers take for no raw image, is not written.
  for (const auto& [width, height] : {std::pair{16, 16}, std::pair{64, 21}}) {
    const fs::path small = write_render(dir, fmt::format("small{}x{}.exr", width, height), width, height);
    r = run_chromatrace({"sensor", small.string(), "-o", out.file("x.dng").string(), "--preset", "canon_eos_5d_mkiii",
                         "--exposure-s", "auto", "--quiet"});
    expect_refused(r, 2, fmt::format("x.dng: a DNG of {} x {} pixels: raw readers (LibRaw, dcraw) read none under 22",
                                     width, height), "dng");
    EXPECT_FALSE(fs::exists(out.file("x.dng")));
  }
  // At 22 x 22 it is written, and info reads it back.
  const fs::path least = write_render(dir, "least.exr", 22, 22);
  r = run_chromatrace({"sensor", least.string(), "-o", out.file("x.dng").string(), "--preset", "canon_eos_5d_mkiii",
                       "--exposure-s", "auto", "--quiet"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = run_chromatrace({"info", out.file("x.dng").string()});
  EXPECT_EQ(r.exit_code, 0) << r.err;
}

// ---- left open last time: far geometry, unknown commands ---------------------------------------------------

TEST(HostileInput, AQuadFarAwayIsRefusedBeforeRendering) {
  test::TempDir dir;
  std::string scene = read_text(kMinimal);
  write_text(dir.file("far.json"), std::string(scene).replace(scene.find("[-1, -1, 0]"), 11, "[1e25, -1, 0]"));
  write_text(dir.file("far_light.json"),
             std::string(scene).replace(scene.find("[-0.2, -0.2, 2]"), 15, "[-0.2, -3e7, 2]"));
  for (const char* name : {"far.json", "far_light.json"})
    for (const char* command : {"render", "check-scene"}) {
      std::vector<std::string> args = {command, dir.file(name).string()};
      if (std::string(command) == "render") args.insert(args.end(), {"-o", dir.file("r.exr").string()});
      expect_refused(run_chromatrace(args), 2, "beyond the ±1000000 m the renderers represent", name);
    }
  EXPECT_FALSE(fs::exists(dir.file("r.exr")));
}

TEST(HostileInput, AnUnknownCommandIsAnErrorNamingItAlsoWithHelp) {
  for (const std::string& exe : {std::string(CHROMATRACE_EXE), std::string(CHROMATRACE_FULL_EXE)})
    for (const std::vector<std::string>& args : std::vector<std::vector<std::string>>{
             {"develop"}, {"develop", "--help"}, {"develop", "info", "x.exr"}, {"Render", "-h"}}) {
      const auto r = test::run_program(exe, args);
      EXPECT_EQ(r.exit_code, 2) << exe << " " << args[0] << ": " << r.err;
      EXPECT_EQ(r.out, "") << exe << " " << args[0];
      EXPECT_EQ(line_count(r.err), 1) << r.err;
      EXPECT_NE(r.err.find("chromatrace: error: unknown command \"" + args[0] + "\""), std::string::npos) << r.err;
    }
}

}  // namespace
}  // namespace ct
