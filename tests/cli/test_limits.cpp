// SPDX-License-Identifier: Apache-2.0
// Sizes checked against documented ceilings and the machine's memory before anything is allocated
// (docs/errors.md, "Sizes and memory"), end to end through the executable.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "tests/cli/run_command.h"
#include "tests/cli/text_files.h"
#include "tests/core/spectral_exr_fixtures.h"

namespace ct {
namespace {

namespace fs = std::filesystem;
using test::line_count;
using test::run_chromatrace;
using test::write_text;

using test::kMinimal;


// ---- sizes checked before allocating --------------------------------------------------------------

TEST(Limits, SizesBeyondTheLimitsAreRefusedBeforeAllocating) {
  test::TempDir dir;
  // A PNG of 68 bytes whose header declares 60000 x 60000 RGB pixels.
  const char giant_png[] =
      "\x89\x50\x4e\x47\x0d\x0a\x1a\x0a\x00\x00\x00\x0d\x49\x48\x44\x52\x00\x00\xea\x60\x00\x00\xea\x60\x08\x02"
      "\x00\x00\x00\x0f\xb0\xe2\x15\x00\x00\x00\x0b\x49\x44\x41\x54\x78\x9c\x63\x60\x80\x01\x00\x00\x0a\x00\x01"
      "\x7f\x80\x74\x5e\x00\x00\x00\x00\x49\x45\x4e\x44\xae\x42\x60\x82";
  const fs::path giant = dir.file("giant.png");
  write_text(giant, std::string(giant_png, sizeof giant_png - 1));
  ASSERT_EQ(fs::file_size(giant), 68u);
  // A PLY whose header declares 4e9 vertices, followed by three and a face: 26 bytes, room for 4 vertices.
  write_text(dir.file("giant.ply"),
             "ply\nformat ascii 1.0\nelement vertex 4000000000\nproperty float x\nproperty float y\nproperty float z\n"
             "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  std::string scene = test::read_text(kMinimal);
  const std::size_t objects = scene.find("\"objects\": [") + 12;
  scene.insert(objects, R"({"name": "giant", "material": "wall", "shape": {"type": "mesh", "file": "giant.ply"}},)");
  write_text(dir.file("giant_mesh.json"), scene);
  const std::string minimal = kMinimal.string();
  const std::string out = dir.file("out.exr").string();
  const std::string too_many = "is larger than the limit of 65536 pixels a side";
  const struct {
    std::vector<std::string> args;
    std::string says;
  } cases[] = {
      {{"render", minimal, "-o", out, "--bands", "380:780:0.0001"},
       "--bands: 0.0001 nm bands over 380–780 nm are 4000000 bands, more than the limit of 2000"},
      {{"render", minimal, "-o", out, "--resolution", "1000000000x1000000000"},
       "--resolution: 1000000000x1000000000 " + too_many},
      {{"render", minimal, "-o", out, "--resolution", "64x99999999999999999999"},
       "--resolution: 64x99999999999999999999 " + too_many},
      {{"render", minimal, "-o", out, "--resolution", "65536x65536", "--bands", "380:780:1"},
       "the image (65536x65536 pixels, 400 bands, 7 layers: the resolution, --bands and --components): needs 4.81e+04 "
       "GB of memory, more than this machine's"},
      {{"analyze", giant.string(), "-o", dir.file("analysis").string()},
       giant.string() + ": image of 60000x60000 pixels, more than the limit of 2^30 (1073741824) pixels"},
      {{"prepare-texture", giant.string(), "--kind", "reflectance", "--bands", "400:700:100", "-o", dir.file("cache").string()},
       giant.string() + ": image of 60000x60000 pixels, more than the limit of 2^30 (1073741824) pixels"},
      {{"check-scene", dir.file("giant_mesh.json").string()},
       "giant.ply: element vertex declares 4000000000 entries, more than the 4 that the rest of the file can hold"},
  };
  for (const auto& c : cases) {
    const auto r = run_chromatrace(c.args);
    EXPECT_EQ(r.exit_code, 2) << c.says << ": " << r.err;
    EXPECT_EQ(line_count(r.err), 1) << r.err;
    EXPECT_NE(r.err.find(c.says), std::string::npos) << "expected \"" << c.says << "\" in " << r.err;
  }
  for (const auto& entry : fs::directory_iterator(dir.path()))  // nothing started, nothing left
    EXPECT_NE(entry.path().extension(), ".tmp") << entry.path();
  EXPECT_FALSE(fs::exists(out));
}

}  // namespace
}  // namespace ct
