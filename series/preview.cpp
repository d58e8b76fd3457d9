// SPDX-License-Identifier: Apache-2.0
#include "series/preview.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/colour.h"
#include "core/file_io.h"
#include "plot/png.h"

namespace ct::series {
namespace {

cv::Mat encode(const analyzer::RgbImage& image, const float gains[3], bool srgb) {
  cv::Mat out(image.height, image.width, CV_8UC3);
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      const std::size_t i = 3 * (static_cast<std::size_t>(y) * image.width + x);
      auto& px = out.at<cv::Vec3b>(y, x);
      for (int c = 0; c < 3; ++c) {
        double v = std::isfinite(image.rgb[i + c]) ? std::clamp(image.rgb[i + c] * gains[c], 0.0f, 1.0f) : 0.0;
        if (srgb) v = srgb_encode(v);
        px[2 - c] = static_cast<unsigned char>(std::lround(255 * v));
      }
    }
  return out;
}

}  // namespace

const analyzer::RgbImage* find_layer(const analyzer::AnalysisImage& input, std::string_view name) {
  for (const analyzer::ComponentLayer& c : input.components)
    if (c.name == name) return &c.image;
  return nullptr;
}

cv::Mat preview_image(const analyzer::AnalysisImage& input) {
  if (input.display) {
    const float ones[3] = {1, 1, 1};
    return encode(*input.display, ones, false);
  }
  const analyzer::RgbImage& image = input.linear ? *input.linear : input.image;
  const analyzer::RgbImage* emission = input.linear ? find_layer(input, "emission") : nullptr;
  const auto sum = [](const analyzer::RgbImage& im, std::size_t p) { return im.rgb[3 * p] + im.rgb[3 * p + 1] + im.rgb[3 * p + 2]; };
  // Surfaces only: a lamp seen directly would set the exposure and the white otherwise.
  std::vector<std::size_t> surfaces;
  for (std::size_t p = 0; p < image.pixel_count(); ++p)
    if (!emission || sum(*emission, p) <= 0.5f * sum(image, p)) surfaces.push_back(p);
  // White balance on the brightest 2 % of the surface pixels (by channel sum), skipping the brightest 0.5 %.
  std::vector<float> sums;
  for (const std::size_t p : surfaces) sums.push_back(sum(image, p));
  const double lo = quantile(sums, 0.975), hi = quantile(sums, 0.995);
  double mean[3] = {0, 0, 0};
  for (const std::size_t p : surfaces)
    if (sum(image, p) >= lo && sum(image, p) <= hi)
      for (int c = 0; c < 3; ++c) mean[c] += image.rgb[3 * p + c];
  float gains[3] = {1, 1, 1};
  if (mean[0] > 0 && mean[1] > 0 && mean[2] > 0)
    for (int c = 0; c < 3; ++c) gains[c] = static_cast<float>(mean[1] / mean[c]);
  std::vector<float> brightest;
  for (const std::size_t p : surfaces)
    brightest.push_back(std::max({image.rgb[3 * p] * gains[0], image.rgb[3 * p + 1] * gains[1], image.rgb[3 * p + 2] * gains[2]}));
  const double level = quantile(brightest, 0.99);
  if (level > 0)
    for (float& g : gains) g = static_cast<float>(g * 0.9 / level);
  return encode(image, gains, true);
}

void write_preview_png(const std::filesystem::path& file, const analyzer::AnalysisImage& input) {
  write_file_atomically(file, plot::encode_png(preview_image(input)));
}

}  // namespace ct::series
