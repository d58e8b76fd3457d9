// SPDX-License-Identifier: Apache-2.0
#pragma once
// Text on plots and figures drawn with OpenCV (series' figure, study's charts): OpenCV's Hershey font draws ASCII
// only, so typographic characters are replaced, and an exponent written with a caret ("10^5", "I^0.45") is drawn
// raised and smaller.

#include <string>
#include <string_view>
#include <vector>

#include <opencv2/core.hpp>

namespace ct::plot {

// `text` with typographic characters replaced by ASCII (— → -, × → x, ✔ → ok, …) and any other non-ASCII
// character by '?'.
std::string ascii(std::string_view text);

enum class Align { Left, Centre, Right };
// Draws `text` (made ascii) with its baseline at `at.y`; returns its width in pixels.
int put_text(cv::Mat& img, std::string_view text, cv::Point at, double scale, const cv::Scalar& colour,
             Align align = Align::Left, int thickness = 1);
int text_width(std::string_view text, double scale, int thickness = 1);
// Greedy word wrap to lines no wider than `width` pixels.
std::vector<std::string> wrap_text(std::string_view text, int width, double scale, int thickness = 1);
// A tick (✔) or a cross (✗) glyph in a size × size box whose lower-left corner is `at`.
void draw_mark(cv::Mat& img, cv::Point at, int size, bool ok);

}  // namespace ct::plot
