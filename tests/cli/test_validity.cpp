// SPDX-License-Identifier: Apache-2.0
// Input that the renderers cannot represent, and files that claim more than they hold, are refused with one
// line naming the field (docs/errors.md, "Ranges the renderers represent" and "Files that claim more than
// they hold"), end to end through the executable.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <future>
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

// minimal.json with `from` replaced by `to` (which must occur once).
std::string edited_minimal(const std::string& from, const std::string& to) {
  std::string scene = read_text(kMinimal);
  const std::size_t at = scene.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  EXPECT_EQ(scene.find(from, at + 1), std::string::npos) << from;
  return scene.replace(at, from.size(), to);
}

struct Case {
  std::vector<std::string> args;
  std::string says;
};

// Each case: exit 2, one line on stderr holding `says`. Run side by side: each start costs dynamic linking.
void expect_refused(const std::vector<Case>& cases) {
  std::vector<std::future<test::CommandResult>> results;
  for (const Case& c : cases) results.push_back(std::async(std::launch::async, run_chromatrace, c.args));
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const auto r = results[i].get();
    EXPECT_EQ(r.exit_code, 2) << cases[i].says << ": " << r.err;
    EXPECT_EQ(line_count(r.err), 1) << r.err;
    EXPECT_NE(r.err.find(cases[i].says), std::string::npos) << "expected \"" << cases[i].says << "\" in " << r.err;
  }
}

const std::string kFloor = R"("corner": [-1, -1, 0], "edge1": [2, 0, 0])";

TEST(Validity, GeometryAndRadianceBeyondWhatTheRenderersRepresentAreRefused) {
  test::TempDir dir;
  const auto scene = [&](const std::string& name, const std::string& text) {
    write_text(dir.file(name), text);
    return dir.file(name).string();
  };
  const std::string beyond = " m from the origin, beyond the ±1000000 m the renderers represent (32-bit floats)";
  write_text(dir.file("far.ply"),
             "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
             "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 1099511627776\n3 0 1 2\n");
  const std::string far_mesh = edited_minimal(
      R"({"type": "sphere", "center": [0, 0, 0.3], "radius": 0.3, "segments": 16})", R"({"type": "mesh", "file": "far.ply"})");
  const std::string out = dir.file("out.exr").string();
  const std::string corner_far = scene("corner.json", edited_minimal(kFloor, R"("corner": [-1e25, -1, 0], "edge1": [2, 0, 0])"));
  expect_refused({
      // The quad of the report: render aborted on Embree's ray.valid() assertion.
      {{"check-scene", corner_far}, "corner.json: objects[0].shape.corner: reaches 1e+25" + beyond},
      {{"render", corner_far, "-o", out}, "corner.json: objects[0].shape.corner: reaches 1e+25" + beyond},
      {{"check-scene", scene("edge.json", edited_minimal(kFloor, R"("corner": [-1, -1, 0], "edge1": [2e7, 0, 0])"))},
       "edge.json: objects[0].shape: reaches 19999999" + beyond},
      {{"check-scene", scene("radius.json", edited_minimal(R"("radius": 0.3)", R"("radius": 1e9)"))},
       "radius.json: objects[1].shape: reaches 1000000000.3" + beyond},
      {{"check-scene", scene("camera.json", edited_minimal(R"("position": [0, -3, 1])", R"("position": [0, -3e6, 1])"))},
       "camera.json: camera.position: reaches 3000000" + beyond},
      {{"check-scene", scene("mesh.json", far_mesh)},
       "mesh.json: objects[1].shape.file: " + dir.file("far.ply").string() + ": a vertex reaches 1099511627776" + beyond},
      // The light of the report: render wrote NaN and Inf that info then refused.
      {{"check-scene", scene("light.json", edited_minimal(R"("scale": 5)", R"("scale": 1e300)"))},
       "light.json: lights[0].scale: the peak radiance 1 times the scale 1e+300 is 1e+300 W m⁻² sr⁻¹ nm⁻¹, beyond "
       "the 1e+20 the renderers represent (32-bit floats)"},
      {{"check-scene",
        scene("samples.json", edited_minimal(R"({"blackbody_k": 3000}, "scale": 5)",
                                             R"({"samples": [[400, 1e19], [700, 3e19]]}, "scale": 5)"))},
       "samples.json: lights[0].scale: the peak radiance 3e+19 times the scale 5 is 1.5e+20"},
  });
  EXPECT_FALSE(fs::exists(out));
  // Just inside the bounds is accepted.
  const auto inside = run_chromatrace(
      {"check-scene", scene("inside.json", edited_minimal(kFloor, R"("corner": [-1e6, -1, 0], "edge1": [2, 0, 0])"))});
  EXPECT_EQ(inside.exit_code, 0) << inside.err;
}

// A scanline EXR whose data window is patched after writing: the file keeps its 2 x 2 pixels of data.
void patch_data_window(const fs::path& file, int x_max, int y_max) {
  std::string bytes = read_text(file);
  const std::string key("dataWindow\0box2i\0", 17);
  const std::size_t at = bytes.find(key);
  ASSERT_NE(at, std::string::npos);
  const std::int32_t window[4] = {0, 0, x_max, y_max};
  std::memcpy(bytes.data() + at + key.size() + 4, window, sizeof window);  // after the attribute's size
  write_text(file, bytes);
}

TEST(Validity, FilesThatClaimMoreThanTheyHoldAreRefused) {
  test::TempDir dir;
  const fs::path wide = dir.file("wide.exr"), tall = dir.file("tall.exr");
  for (const fs::path& file : {wide, tall})
    test::write_raw_exr(file, 2, 2,
                        {test::constant_channel("S0.500,000000nm", 2, 2, 1),
                         test::constant_channel("S0.600,000000nm", 2, 2, 1)});
  patch_data_window(wide, 49999, 1);  // 100 000 pixels, 4 of them stored
  patch_data_window(tall, 1, 49999);
  const fs::path ids = dir.file("ids.exr");
  std::vector<test::RawChannel> channels = {test::constant_channel("S0.500,000000nm", 2, 2, 1),
                                            test::constant_channel("object_id", 2, 2, 1)};
  channels[1].values[3] = 1.5f;
  test::write_raw_exr(ids, 2, 2, channels);
  write_text(dir.file("one_row.csv"), "wavelength_nm,value\n550,0.5\n");
  write_text(dir.file("one_value.csv"), "wavelength_nm,a,b\n500,0.5,\n550,0.5,0.25\n600,0.5,\n");
  const std::string one_row = edited_minimal(R"({"samples": [[400, 0.7], [700, 0.8]], "extend": "clamp"})",
                                             R"({"csv": "one_row.csv"})");
  write_text(dir.file("one_row.json"), one_row);
  write_text(dir.file("one_value.json"),
             edited_minimal(R"({"samples": [[400, 0.7], [700, 0.8]], "extend": "clamp"})",
                            R"({"csv": "one_value.csv", "column": "b"})"));
  const std::string out = dir.file("analysis").string();
  const fs::path image = dir.file("image.exr");
  test::write_raw_exr(image, 4, 4,
                      {test::constant_channel("R", 4, 4, 0.5), test::constant_channel("G", 4, 4, 0.25),
                       test::constant_channel("B", 4, 4, 0.125)});
  expect_refused({
      {{"info", wide.string()},
       wide.string() + ": pixel data, rows 0-1: 15 stored bytes, which cannot hold their 800000 bytes; the data "
                       "window (50000x2 pixels) claims more than the file holds"},
      // Here the chunk table itself runs past the end of the file: 3125 chunks claimed, 1 stored.
      {{"info", tall.string()}, tall.string() + ": pixel data, rows 0-15: no chunk for them"},
      {{"info", "--check", ids.string()},
       ids.string() + ": channel object_id: value 1.5 at pixel (1, 1) is not an object id (a whole number in [0, 16777216])"},
      {{"check-scene", dir.file("one_row.json").string()},
       "one_row.json: spectra.white.csv: " + dir.file("one_row.csv").string() +
           ": column \"value\" has 1 value, at 550 nm; a spectrum needs at least 2"},
      {{"check-scene", dir.file("one_value.json").string()},
       ": column \"b\" has 1 value, at 550 nm; a spectrum needs at least 2"},
      {{"analyze", image.string(), "-o", out, "--rect", "0,0,2147483648,1"},
       "--rect: expected x,y,width,height (whole numbers within ±2147483647) with width, height >= 0, got "
       "\"0,0,2147483648,1\""},
  });
  // A rectangle far outside the image is an empty region (as any rectangle outside it is), not an overflow.
  const auto far = run_chromatrace({"analyze", image.string(), "-o", out, "--rect", "2147483647,2147483647,10,10"});
  ASSERT_EQ(far.exit_code, 0) << far.err;
  EXPECT_NE(read_text(dir.file("analysis") / "analysis.json").find("the region is empty"), std::string::npos);
}

// Found by fuzz_spectral_exr: a header with a channel of pixel type -3070 and no data window kept OpenEXR's C++
// reader busy for 15 s and 1.2 GB before it gave up; OpenEXR's C reader refuses it at once, naming the channel.
TEST(Validity, ACorruptExrHeaderIsRefusedByItsFirstFault) {
  const fs::path file = fs::path(CHROMATRACE_SOURCE_DIR) / "tests" / "fuzz" / "regressions" / "spectral_exr" /
                        "timeout-invalid-pixel-type-header.exr";
  // And a string attribute that claims 1 GB in a file of 6 kB: the C++ reader allocated it.
  const fs::path big = file.parent_path() / "timeout-string-attribute-of-1-gb.exr";
  expect_refused({{{"info", file.string()},
                   file.string() + ": unreadable OpenEXR header: Invalid pixel type specified (-3070) adding channel "
                                   "'S0.435,000000nm' to list"},
                  {{"info", big.string()},
                   big.string() + ": unreadable OpenEXR header: Attribute 'renderTime', type 'string': Invalid size "
                                  "1073741825"}});
}

// A negative radiance was called "the image is black" by the automatic exposure, and the default preset took it.
TEST(Validity, NegativeRadianceIsNamedNotTakenForABlackImage) {
  test::TempDir dir;
  const fs::path image = dir.file("negative.exr");
  std::vector<test::RawChannel> channels = {test::constant_channel("S0.500,000000nm", 4, 4, 1),
                                            test::constant_channel("S0.600,000000nm", 4, 4, 1)};
  channels[1].values[7] = -1.0f;
  test::write_raw_exr(image, 4, 4, channels);
  const std::string out = dir.file("out.exr").string();
  const std::string says =
      image.string() + ": channel S0.600,000000nm: value -1 at pixel (3, 1) is negative: a radiance is >= 0";
  expect_refused({{{"sensor", image.string(), "-o", out, "--quiet"}, says},
                  {{"sensor", image.string(), "-o", out, "--quiet", "--exposure-s", "auto"}, says}});
  EXPECT_FALSE(fs::exists(out));
}

}  // namespace
}  // namespace ct
