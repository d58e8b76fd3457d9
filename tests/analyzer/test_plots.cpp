// SPDX-License-Identifier: Apache-2.0
// Plots and the report a person can read: the unit of the values said, and the regions listed by size with their
// pixel counts (the tick values on every axis: tests/plot/test_ticks.cpp).
#include <algorithm>
#include <regex>
#include <string>
#include <vector>

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "analyzer/plots.h"
#include "core/file_io.h"
#include "tests/cli/run_command.h"
#include "tests/core/spectral_exr_fixtures.h"

namespace ct::test {
namespace {

using namespace ct::analyzer;

// An 8-bit PNG without a colour space is sRGB-encoded codes: the plots and the report say so; the report lists
// the regions by size with their pixel counts, and analysis.json gives that order.
TEST(Plots, ReportListsRegionsBySizeAndSaysTheUnit) {
  TempDir dir;
  const int w = 64, h = 32;
  std::vector<std::uint8_t> pixels;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      pixels.insert(pixels.end(), {static_cast<std::uint8_t>(40 + 3 * x), static_cast<std::uint8_t>(30 + 2 * x), static_cast<std::uint8_t>(20 + y)});
  OIIO::ImageSpec spec(w, h, 3, OIIO::TypeDesc::UINT8);
  auto out = OIIO::ImageOutput::create(dir.file("ramp.png").string());
  ASSERT_TRUE(out && out->open(dir.file("ramp.png").string(), spec) && out->write_image(OIIO::TypeDesc::UINT8, pixels.data()) && out->close());
  // Given small, large, middle: 4×4 = 16, 40×20 = 800, 10×10 = 100 pixels.
  const CommandResult r = run_chromatrace({"analyze", dir.file("ramp.png").string(), "-o", dir.file("o").string(), "-q", "--rect", "0,0,4,4",
                                           "--rect", "10,5,40,20", "--rect", "50,2,10,10"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json a = nlohmann::json::parse(read_file(dir.file("o") / "analysis.json"));
  EXPECT_EQ(a["regions_by_size"], nlohmann::json::array({0, 2, 3, 1}));  // the whole image (2,048 px) first
  const std::string html = read_file(dir.file("o") / "report.html");
  const std::regex row(R"re(<tr data-region="(\d+)"><td>[^<]*</td><td>[^<]*</td><td>[^<]*</td><td>(\d+)</td>)re");
  std::vector<int> order, counts;
  for (auto it = std::sregex_iterator(html.begin(), html.end(), row); it != std::sregex_iterator(); ++it)
    order.push_back(std::stoi((*it)[1])), counts.push_back(std::stoi((*it)[2]));
  EXPECT_EQ(order, (std::vector<int>{0, 2, 3, 1}));
  EXPECT_EQ(counts, (std::vector<int>{2048, 800, 100, 16}));
  EXPECT_NE(html.find("8-bit codes as stored (0 to 255), encoded by the sRGB curve: not proportional to light"), std::string::npos);
  // The plots: 2 × 2 panels of 390 px under a 48 px title.
  auto in = OIIO::ImageInput::open((dir.file("o") / "plots" / "region-00.png").string());
  ASSERT_TRUE(in);
  EXPECT_EQ(in->spec().width, 780);
  EXPECT_EQ(in->spec().height, 828);
}

// A clipped cluster's shape is measured on its samples off the faces: the report gives those, named so, not the
// unmeasured statistics of the whole as zeros.
TEST(Plots, AClippedRegionsSummaryIsOfItsSamplesOffTheFaces) {
  TempDir dir;
  const int w = 64, h = 32;
  std::vector<std::uint8_t> pixels;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)  // red reaches 255 at x = 32 and stays there: half the image on R's upper face
      pixels.insert(pixels.end(), {static_cast<std::uint8_t>(std::min(255, 8 * x)), static_cast<std::uint8_t>(4 * x + 2 * (y % 3)), static_cast<std::uint8_t>(2 * x + (y % 2))});
  OIIO::ImageSpec spec(w, h, 3, OIIO::TypeDesc::UINT8);
  auto out = OIIO::ImageOutput::create(dir.file("clipped.png").string());
  ASSERT_TRUE(out && out->open(dir.file("clipped.png").string(), spec) && out->write_image(OIIO::TypeDesc::UINT8, pixels.data()) && out->close());
  const CommandResult r = run_chromatrace({"analyze", dir.file("clipped.png").string(), "-o", dir.file("o").string(), "-q"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json a = nlohmann::json::parse(read_file(dir.file("o") / "analysis.json"));
  ASSERT_EQ(a["regions"][0]["shape"]["class"], "clipped");
  const std::string html = read_file(dir.file("o") / "report.html");
  EXPECT_NE(html.find("off the faces"), std::string::npos);
  EXPECT_EQ(html.find("\"linearity / planarity / scattering\""), std::string::npos);
  EXPECT_EQ(html.find("\"noise σ along axes\""), std::string::npos);
  // The PNG's curve is undone: the numbers under the class in linear light say they are in linear light.
  EXPECT_EQ(html.find("\"linearity / planarity / scattering (linear light)\""), std::string::npos);
  EXPECT_EQ(html.find("\"noise σ along axes (linear light)\""), std::string::npos);
  EXPECT_NE(html.find("\"noise σ along axes, off the faces (linear light)\""), std::string::npos);
}

}  // namespace
}  // namespace ct::test
