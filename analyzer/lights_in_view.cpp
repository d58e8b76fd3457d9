// SPDX-License-Identifier: Apache-2.0
#include "analyzer/lights_in_view.h"

#include <algorithm>
#include <cmath>

#include <fmt/core.h>
#include <opencv2/imgproc.hpp>

namespace ct::analyzer {

LightsInView find_lights_in_view(const RgbImage& image, std::span<const std::uint8_t> counted, const std::array<double, 3>& high_levels) {
  LightsInView out;
  const std::size_t n = image.pixel_count();
  out.mask.assign(n, 0);
  std::vector<float> brightness(n, 0.0f);
  std::vector<float> values;
  for (std::size_t p = 0; p < n; ++p) {
    const float b = (image.rgb[3 * p] + image.rgb[3 * p + 1] + image.rgb[3 * p + 2]) / 3.0f;
    brightness[p] = std::isfinite(b) ? b : 0.0f;
    if (std::isfinite(b) && b > 0 && (counted.empty() || counted[p])) values.push_back(b);
  }
  if (values.empty()) return out;
  auto quantile = [&](double q) {
    const auto at = values.begin() + static_cast<std::ptrdiff_t>(q * static_cast<double>(values.size() - 1));
    std::nth_element(values.begin(), at, values.end());
    return static_cast<double>(*at);
  };
  out.median_brightness = quantile(0.5);
  out.lit_brightness = quantile(0.95);
  const double median = out.median_brightness;
  out.seed_level = std::max(kLightSeed * median, kLightOverLit * out.lit_brightness);
  const double grow_level = std::max(kLightGrow * median, out.lit_brightness);
  // Hysteresis: the components of the pixels above the lower level that hold a pixel above the upper one.
  cv::Mat grow(image.height, image.width, CV_8U);
  for (std::size_t p = 0; p < n; ++p) grow.data[p] = brightness[p] >= grow_level ? 1 : 0;
  cv::Mat labels;
  const int count = cv::connectedComponents(grow, labels, 8, CV_32S);
  std::vector<std::size_t> brightest(static_cast<std::size_t>(count), n);
  for (std::size_t p = 0; p < n; ++p) {
    const int l = labels.at<int>(static_cast<int>(p));
    if (l == 0) continue;
    std::size_t& b = brightest[static_cast<std::size_t>(l)];
    if (b == n || brightness[p] > brightness[b]) b = p;
  }
  cv::Mat light = cv::Mat::zeros(image.height, image.width, CV_8U);
  std::vector<int> kept(static_cast<std::size_t>(count), 0);
  for (int l = 1; l < count; ++l)
    if (brightest[static_cast<std::size_t>(l)] < n && brightness[brightest[static_cast<std::size_t>(l)]] >= out.seed_level)
      kept[static_cast<std::size_t>(l)] = 1;
  for (std::size_t p = 0; p < n; ++p) light.data[p] = kept[static_cast<std::size_t>(labels.at<int>(static_cast<int>(p)))] ? 255 : 0;
  cv::dilate(light, light, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * kLightMargin + 1, 2 * kLightMargin + 1)));
  // Each light with its margin, as the dilation joined them.
  cv::Mat joined;
  const int lights = cv::connectedComponents(light, joined, 8, CV_32S);
  std::vector<LightInView> found(static_cast<std::size_t>(std::max(lights - 1, 0)));
  std::vector<std::size_t> peak(found.size(), n);
  for (std::size_t p = 0; p < n; ++p) {
    const int l = joined.at<int>(static_cast<int>(p));
    if (l == 0) continue;
    out.mask[p] = 1;
    LightInView& f = found[static_cast<std::size_t>(l - 1)];
    ++f.pixels;
    const Vec3 v(image.rgb[3 * p], image.rgb[3 * p + 1], image.rgb[3 * p + 2]);
    if (v.allFinite()) f.rgb += v;
    if (v[0] >= high_levels[0] || v[1] >= high_levels[1] || v[2] >= high_levels[2]) ++f.clipped;
    std::size_t& b = peak[static_cast<std::size_t>(l - 1)];
    if (b == n || brightness[p] > brightness[b]) b = p;
  }
  for (std::size_t k = 0; k < found.size(); ++k) {
    LightInView& f = found[k];
    f.x = static_cast<int>(peak[k] % static_cast<std::size_t>(image.width));
    f.y = static_cast<int>(peak[k] / static_cast<std::size_t>(image.width));
    f.brightness = brightness[peak[k]] / median;
    f.name = fmt::format("light at ({}, {})", f.x, f.y);
    if (f.rgb.sum() < 0) f.rgb = -f.rgb;
    if (f.rgb.norm() > 0) f.rgb.normalize();
  }
  std::stable_sort(found.begin(), found.end(), [](const LightInView& a, const LightInView& b) { return a.brightness > b.brightness; });
  out.lights = std::move(found);
  return out;
}

}  // namespace ct::analyzer
