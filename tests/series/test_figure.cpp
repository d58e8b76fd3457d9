// SPDX-License-Identifier: Apache-2.0
// The figure page (series/figure.h) from hand-made series results: variants that failed, a variant whose files
// are gone, a series without figure panels, the figure images and the histogram points' range and subsample.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include <OpenImageIO/imageio.h>
#include <opencv2/imgcodecs.hpp>

#include "core/file_io.h"
#include "core/json_input.h"
#include "series/figure.h"
#include "series/figure_data.h"
#include "series/figure_plots.h"

namespace ct::series {
namespace {
namespace fs = std::filesystem;

class FigurePage : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("chromatrace-figure-test-" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "-" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // A 32 × 32 float EXR: a grey ramp on the left half, a red ramp on the right, and one very bright pixel.
  void write_camera(const std::string& variant, bool with_png = true) {
    fs::create_directories(dir_ / variant / "analysis");
    const int w = 32, h = 32;
    std::vector<float> rgb(static_cast<std::size_t>(w * h * 3));
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        float* p = &rgb[static_cast<std::size_t>((y * w + x) * 3)];
        const float t = static_cast<float>(y) / (h - 1) * 0.4f;
        if (x < w / 2) p[0] = p[1] = p[2] = t;
        else p[0] = t, p[1] = 0.3f * t, p[2] = 0.2f * t;
      }
    rgb[0] = rgb[1] = rgb[2] = 50.0f;  // an outlier: it must not set the range
    auto out = OIIO::ImageOutput::create((dir_ / variant / "camera.exr").string());
    ASSERT_TRUE(out);
    OIIO::ImageSpec spec(w, h, 3, OIIO::TypeDesc::FLOAT);
    spec.channelnames = {"R", "G", "B"};
    ASSERT_TRUE(out->open((dir_ / variant / "camera.exr").string(), spec));
    ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, rgb.data()));
    out->close();
    if (with_png) {
      cv::Mat png(h, w, CV_8UC3, cv::Scalar(40, 80, 200));
      cv::imwrite((dir_ / variant / "camera.png").string(), png);
    }
    write_file_atomically(dir_ / variant / "analysis" / "report.html", "<!doctype html>");
  }

  static Json ok_variant(const std::string& name, Json figure) {
    return {{"name", name},
            {"description", "a <test> variant"},
            {"figure", figure},
            {"ok", true},
            {"size", {32, 32}},
            {"sensor", {{"file", name + "/camera.exr"}}},
            {"preview", name + "/camera.png"},
            {"analysis", {{"file", name + "/analysis/analysis.json"}, {"report", name + "/analysis/report.html"}}},
            {"expect",
             {{{"target", "walls"},
               {"any_of", {"linear"}},
               {"ok", false},
               {"objects",
                {{{"object", "floor"}, {"found", "linear"}, {"ok", true}, {"explanation", "diffuse_direct 100 %"}},
                 {{"object", "back_wall"}, {"found", "planar"}, {"ok", false}}}}}}},
            {"expectations_met", 0},
            {"expectations", 1}};
  }

  static Json series(Json variants) {
    return {{"format", "chromatrace-series-result/1"},
            {"series", "test"},
            {"description", "hand-made"},
            {"options", {{"renderer", "tracer"}, {"components", "paths"}}},
            {"variants", variants}};
  }

  std::string page() const { return read_file(dir_ / "index.html"); }

  fs::path dir_;
};

std::size_t occurrences(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + what.size())) ++n;
  return n;
}

TEST_F(FigurePage, SeriesWithoutPanelsShowsEveryVariantInAGridAndFailuresWithTheirError) {
  write_camera("a");
  const Json failed = {{"name", "b"}, {"description", ""}, {"figure", Json::array()}, {"ok", false}, {"error", "render: <boom>"}};
  write_figure_page(dir_, series({ok_variant("a", Json::array()), failed}));
  const std::string html = page();
  EXPECT_EQ(occurrences(html, "<section class=\"panel\""), 2u);
  EXPECT_EQ(occurrences(html, "data-panel="), 0u);
  EXPECT_NE(html.find("render: &lt;boom&gt;"), std::string::npos);
  EXPECT_NE(html.find("a &lt;test&gt; variant"), std::string::npos);
  EXPECT_NE(html.find("href=\"a/analysis/report.html\""), std::string::npos);
  EXPECT_EQ(occurrences(html, "class=\"plot "), 2u);
  EXPECT_EQ(html.find("src=\"a/"), std::string::npos) << "images are embedded, not linked";
  EXPECT_EQ(html.find("http"), std::string::npos);
  EXPECT_FALSE(fs::exists(dir_ / "figure3.png"));
  EXPECT_FALSE(fs::exists(dir_ / "figure4.png"));
  for (const auto& entry : fs::directory_iterator(dir_)) EXPECT_EQ(entry.path().extension(), entry.is_directory() ? "" : ".html");
}

TEST_F(FigurePage, PanelsMakeFigureImagesAndMissingPanelsArePlaceholders) {
  write_camera("a");
  write_camera("c", false);  // no camera.png: the preview is made anew
  write_file_atomically(dir_ / "figure4.png", "stale");
  write_figure_page(dir_, series({ok_variant("a", {"3a"}), ok_variant("c", {"3c", "3a"})}));
  const std::string html = page();
  EXPECT_EQ(occurrences(html, "data-panel=\"3a\""), 1u);
  EXPECT_NE(html.find("data-panel=\"3a\" data-variant=\"a\""), std::string::npos) << "the first variant naming a panel shows it";
  EXPECT_NE(html.find("data-panel=\"3c\" data-variant=\"c\""), std::string::npos);
  EXPECT_EQ(occurrences(html, "data-missing="), 2u);  // 3b and 3d
  EXPECT_NE(html.find("(a) Diffusely reflecting surfaces under direct illumination"), std::string::npos);
  const cv::Mat figure3 = cv::imread((dir_ / "figure3.png").string());
  ASSERT_FALSE(figure3.empty());
  EXPECT_GT(figure3.cols, 4 * kPlotWidth);
  EXPECT_GT(figure3.rows, 2 * kPlotHeight);
  EXPECT_FALSE(fs::exists(dir_ / "figure4.png")) << "a figure of an earlier run is removed";
  EXPECT_EQ(html.find("Figure 4"), std::string::npos);
}

TEST_F(FigurePage, AVariantWhoseFilesAreGoneShowsWhyAndThePageIsStillWritten) {
  write_figure_page(dir_, series({ok_variant("gone", {"4a"})}));
  const std::string html = page();
  EXPECT_NE(html.find("Its images cannot be shown"), std::string::npos);
  EXPECT_NE(html.find("camera.exr"), std::string::npos);
  EXPECT_TRUE(fs::exists(dir_ / "figure4.png"));
}

TEST(FigurePoints, TheRangeIgnoresARareOutlierAndTheSubsampleIsDeterministic) {
  analyzer::AnalysisImage input;
  input.image.width = 100;
  input.image.height = 100;
  input.image.rgb.resize(100 * 100 * 3);
  for (std::size_t p = 0; p < 10000; ++p)
    for (int c = 0; c < 3; ++c) input.image.rgb[p * 3 + c] = 0.0483f * static_cast<float>(p) / 9999.0f;
  input.image.rgb[0] = 100.0f;
  const HistogramPoints all = gather_points(input, cv::Mat(), "file values", 100000);
  EXPECT_DOUBLE_EQ(all.lo, 0.0);
  EXPECT_NEAR(all.hi, 0.05, 1e-12);
  EXPECT_NEAR(all.step, 0.01, 1e-12);
  EXPECT_EQ(all.beyond, 1u);
  EXPECT_EQ(all.rgb.size(), 9999u);
  const HistogramPoints some = gather_points(input, cv::Mat(), "file values", 1000);
  const HistogramPoints again = gather_points(input, cv::Mat(), "file values", 1000);
  ASSERT_EQ(some.rgb.size(), 1000u);
  EXPECT_EQ(some.in_range, 9999u);
  for (std::size_t i = 0; i < some.rgb.size(); ++i) EXPECT_EQ(some.rgb[i], again.rgb[i]);
  // An even subsample: it reaches both ends of the ramp.
  double lo = 1, hi = 0;
  for (const auto& x : some.rgb) lo = std::min(lo, x[0]), hi = std::max(hi, x[0]);
  EXPECT_LT(lo, 0.001);
  EXPECT_GT(hi, 0.047);
}

}  // namespace
}  // namespace ct::series
