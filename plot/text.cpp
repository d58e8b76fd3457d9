// SPDX-License-Identifier: Apache-2.0
#include "plot/text.h"

#include <cctype>
#include <utility>

#include <opencv2/imgproc.hpp>

namespace ct::plot {
namespace {

constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;

}  // namespace

std::string ascii(std::string_view text) {
  static const std::pair<std::string_view, std::string_view> replacements[] = {
      {"\u2014", "-"}, {"\u2013", "-"}, {"\u2212", "-"}, {"\u00d7", "x"},  {"\u2192", "->"}, {"\u2018", "'"},
      {"\u2019", "'"}, {"\u201c", "\""}, {"\u201d", "\""}, {"\u2026", "..."}, {"\u2714", "ok"}, {"\u2717", "x"},
      {"\u00b3", "^3"}, {"\u00b2", "^2"}, {"\u00b0", " deg"}, {"\u03b3", "gamma"}, {"\u2265", ">="}, {"\u2264", "<="},
      {"\u00e9", "e"}, {"\u00a0", " "}, {"\u2009", " "}, {"\u202f", " "}};
  std::string out;
  for (std::size_t i = 0; i < text.size();) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    if (c < 0x80) {
      out += static_cast<char>(c);
      ++i;
      continue;
    }
    bool replaced = false;
    for (const auto& [from, to] : replacements)
      if (text.substr(i, from.size()) == from) {
        out += to;
        i += from.size();
        replaced = true;
        break;
      }
    if (replaced) continue;
    // Any other character: one '?' for its whole UTF-8 sequence.
    out += '?';
    ++i;
    while (i < text.size() && (static_cast<unsigned char>(text[i]) & 0xC0) == 0x80) ++i;
  }
  return out;
}

namespace {

// Text split into runs; an exponent ("^0.45", "^-2") is a raised run, as the font has no usable caret.
struct Run {
  std::string text;
  bool raised = false;
};

std::vector<Run> runs_of(std::string_view text) {
  const std::string s = ascii(text);
  std::vector<Run> runs(1);
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s[i] == '^' && i + 1 < s.size() && (std::isdigit(static_cast<unsigned char>(s[i + 1])) || s[i + 1] == '-' || s[i + 1] == '.')) {
      Run exponent{"", true};
      std::size_t j = i + 1;
      while (j < s.size() && (std::isdigit(static_cast<unsigned char>(s[j])) || s[j] == '.' || (j == i + 1 && s[j] == '-'))) exponent.text += s[j++];
      runs.push_back(std::move(exponent));
      runs.push_back({});
      i = j - 1;
      continue;
    }
    runs.back().text += s[i];
  }
  return runs;
}

constexpr double kRaisedScale = 0.72;

}  // namespace

int text_width(std::string_view text, double scale, int thickness) {
  int width = 0, baseline = 0;
  for (const Run& run : runs_of(text))
    if (!run.text.empty())
      width += cv::getTextSize(run.text, kFont, run.raised ? scale * kRaisedScale : scale, thickness, &baseline).width + (run.raised ? 1 : 0);
  return width;
}

int put_text(cv::Mat& img, std::string_view text, cv::Point at, double scale, const cv::Scalar& colour, Align align,
             int thickness) {
  const int width = text_width(text, scale, thickness);
  if (align == Align::Centre) at.x -= width / 2;
  if (align == Align::Right) at.x -= width;
  int baseline = 0;
  const int raise = static_cast<int>(std::lround(cv::getTextSize("0", kFont, scale, thickness, &baseline).height * 0.45));
  for (const Run& run : runs_of(text)) {
    if (run.text.empty()) continue;
    const double s = run.raised ? scale * kRaisedScale : scale;
    cv::putText(img, run.text, at - cv::Point(0, run.raised ? raise : 0), kFont, s, colour, thickness, cv::LINE_AA);
    at.x += cv::getTextSize(run.text, kFont, s, thickness, &baseline).width + (run.raised ? 1 : 0);
  }
  return width;
}

std::vector<std::string> wrap_text(std::string_view text, int width, double scale, int thickness) {
  std::vector<std::string> lines;
  std::string line;
  std::size_t i = 0;
  while (i < text.size()) {
    const std::size_t space = std::min(text.find(' ', i), text.size());
    const std::string word(text.substr(i, space - i));
    i = space + 1;
    if (word.empty()) continue;
    const std::string candidate = line.empty() ? word : line + " " + word;
    if (!line.empty() && text_width(candidate, scale, thickness) > width) {
      lines.push_back(line);
      line = word;
    } else {
      line = candidate;
    }
  }
  if (!line.empty()) lines.push_back(line);
  return lines;
}

void draw_mark(cv::Mat& img, cv::Point at, int size, bool ok) {
  if (ok) {
    const cv::Scalar green(40, 140, 30);
    cv::line(img, at + cv::Point(1, -size / 2), at + cv::Point(size / 3, -1), green, 2, cv::LINE_AA);
    cv::line(img, at + cv::Point(size / 3, -1), at + cv::Point(size, -size), green, 2, cv::LINE_AA);
  } else {
    const cv::Scalar red(30, 30, 200);
    cv::line(img, at + cv::Point(1, -size + 1), at + cv::Point(size - 1, -1), red, 2, cv::LINE_AA);
    cv::line(img, at + cv::Point(1, -1), at + cv::Point(size - 1, -size + 1), red, 2, cv::LINE_AA);
  }
}

}  // namespace ct::plot
