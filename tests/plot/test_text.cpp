// SPDX-License-Identifier: Apache-2.0
// Text on OpenCV images: what the Hershey font cannot draw is replaced, an exponent is raised, lines wrap within
// their width; PNG bytes decode to the image.
#include <string>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "plot/png.h"
#include "plot/text.h"

namespace ct::plot {
namespace {

TEST(PlotText, AsciiReplacesWhatTheFontCannotDraw) {
  EXPECT_EQ(ascii("a — b × c → d"), "a - b x c -> d");
  EXPECT_EQ(ascii("λ"), "?");
  EXPECT_EQ(ascii("m² ≥ 1"), "m^2 >= 1");
}

// "10^5" is "10" at full size and "5" at 0.72 of it, a pixel apart.
TEST(PlotText, AnExponentIsDrawnSmaller) {
  int baseline = 0;
  const int ten = cv::getTextSize("10", cv::FONT_HERSHEY_SIMPLEX, 0.5, 1, &baseline).width;
  const int five = cv::getTextSize("5", cv::FONT_HERSHEY_SIMPLEX, 0.5 * 0.72, 1, &baseline).width;
  EXPECT_EQ(text_width("10^5", 0.5), ten + five + 1);
  EXPECT_EQ(text_width("105", 0.5), cv::getTextSize("105", cv::FONT_HERSHEY_SIMPLEX, 0.5, 1, &baseline).width);
}

TEST(PlotText, WrapKeepsEveryLineWithinItsWidth) {
  const std::string text = "the quick brown fox jumps over the lazy dog and keeps running along the river bank";
  const int width = 120;
  const std::vector<std::string> lines = wrap_text(text, width, 0.45);
  ASSERT_GT(lines.size(), 2u);
  std::string joined;
  for (const std::string& line : lines) {
    EXPECT_LE(text_width(line, 0.45), width) << line;
    joined += (joined.empty() ? "" : " ") + line;
  }
  EXPECT_EQ(joined, text);
}

TEST(PlotText, AlignmentMovesTheTextByItsWidth) {
  cv::Mat left(30, 200, CV_8UC3, cv::Scalar(0, 0, 0)), right = left.clone();
  const int w = put_text(left, "abc", {50, 20}, 0.5, cv::Scalar(255, 255, 255));
  EXPECT_EQ(put_text(right, "abc", {50 + w, 20}, 0.5, cv::Scalar(255, 255, 255), Align::Right), w);
  EXPECT_EQ(cv::norm(left, right, cv::NORM_INF), 0);
}

TEST(PlotPng, BytesDecodeToTheImage) {
  cv::Mat img(7, 5, CV_8UC3);
  cv::randu(img, cv::Scalar::all(0), cv::Scalar::all(255));
  const std::string png = encode_png(img);
  ASSERT_GT(png.size(), 8u);
  EXPECT_EQ(png.substr(1, 3), "PNG");
  const cv::Mat back = cv::imdecode(cv::Mat(1, static_cast<int>(png.size()), CV_8UC1, const_cast<char*>(png.data())), cv::IMREAD_UNCHANGED);
  EXPECT_EQ(cv::norm(img, back, cv::NORM_INF), 0);
}

}  // namespace
}  // namespace ct::plot
