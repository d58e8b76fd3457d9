// Plots and the report a person can read: tick values at round numbers on every axis, the unit of the values
// said, and the regions listed by size with their pixel counts.
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

void expect_ticks(double lo, double hi, const std::vector<double>& expected) {
  const std::vector<double> ticks = axis_ticks(lo, hi);
  ASSERT_EQ(ticks.size(), expected.size()) << lo << " to " << hi;
  for (std::size_t k = 0; k < ticks.size(); ++k) EXPECT_NEAR(ticks[k], expected[k], 1e-12 * (hi - lo)) << lo << " to " << hi;
}

// The step is (hi − lo) / 5 rounded to 1, 2, 5 or 10 × 10^n (below 1.5 → 1, 3 → 2, 7 → 5); the ticks are its
// multiples in range.
TEST(Plots, AxisTicksAreRoundNumbersInsideTheRange) {
  expect_ticks(0, 255, {0, 50, 100, 150, 200, 250});                             // 51 = 5.1 × 10 → 50
  expect_ticks(0, 1, {0, 0.2, 0.4, 0.6, 0.8, 1});                                // 0.2
  expect_ticks(0, 65535, {0, 10000, 20000, 30000, 40000, 50000, 60000});         // 13107 = 1.31 × 10^4 → 10000
  expect_ticks(0.013, 0.087, {0.02, 0.03, 0.04, 0.05, 0.06, 0.07, 0.08});        // 0.0148 → 0.01
  expect_ticks(-1, 1, {-1, -0.5, 0, 0.5, 1});                                    // 0.4 → 0.5
  EXPECT_TRUE(axis_ticks(1, 1).empty());
  EXPECT_TRUE(axis_ticks(0, std::numeric_limits<double>::infinity()).empty());
  EXPECT_EQ(tick_label(100, 0, 255), "100");
  EXPECT_EQ(tick_label(0.4, 0, 1), "0.4");
  EXPECT_EQ(tick_label(0.06, 0.013, 0.087), "0.06");
  EXPECT_EQ(tick_label(0, -1, 1), "0.0");
  EXPECT_EQ(tick_label(40000, 0, 65535), "40000");
}

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

}  // namespace
}  // namespace ct::test
