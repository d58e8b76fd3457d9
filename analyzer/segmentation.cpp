#include "analyzer/segmentation.h"

#include <algorithm>
#include <cmath>

#include <fmt/core.h>
#include <opencv2/imgproc.hpp>

namespace ct::analyzer {

std::vector<Region> segment_regions(const RgbImage& layer, const SegmentationOptions& options) {
  const int w = layer.width, h = layer.height;
  const std::size_t n = layer.pixel_count();
  std::vector<double> brightness(n);
  for (std::size_t p = 0; p < n; ++p) {
    const double s = static_cast<double>(layer.rgb[p * 3]) + layer.rgb[p * 3 + 1] + layer.rgb[p * 3 + 2];
    brightness[p] = std::isfinite(s) ? s : 0.0;
  }
  std::vector<double> sorted = brightness;
  const auto k = static_cast<std::ptrdiff_t>(0.9 * static_cast<double>(n - 1));
  std::nth_element(sorted.begin(), sorted.begin() + k, sorted.end());
  const double dark = options.dark_fraction * sorted[static_cast<std::size_t>(k)];

  // Chromaticity as 8-bit colour, the input pyrMeanShiftFiltering takes.
  cv::Mat chroma(h, w, CV_8UC3, cv::Scalar::all(0));
  std::vector<std::uint8_t> lit(n, 0);
  for (std::size_t p = 0; p < n; ++p) {
    if (!(brightness[p] > dark) || brightness[p] <= 0) continue;
    lit[p] = 1;
    auto* c = chroma.ptr<cv::Vec3b>(static_cast<int>(p / static_cast<std::size_t>(w))) + p % static_cast<std::size_t>(w);
    for (int i = 0; i < 3; ++i)
      (*c)[i] = cv::saturate_cast<std::uint8_t>(255.0 * std::clamp(layer.rgb[p * 3 + static_cast<std::size_t>(i)] / brightness[p], 0.0, 1.0));
  }
  cv::Mat filtered;
  cv::pyrMeanShiftFiltering(chroma, filtered, options.spatial_radius, options.colour_radius * 255.0, 1);

  const double tolerance = options.step_tolerance * 255.0;
  auto close = [&](std::size_t a, std::size_t b) {
    const auto& ca = filtered.ptr<cv::Vec3b>(static_cast<int>(a / static_cast<std::size_t>(w)))[a % static_cast<std::size_t>(w)];
    const auto& cb = filtered.ptr<cv::Vec3b>(static_cast<int>(b / static_cast<std::size_t>(w)))[b % static_cast<std::size_t>(w)];
    double d2 = 0;
    for (int i = 0; i < 3; ++i) d2 += std::pow(double(ca[i]) - double(cb[i]), 2);
    return d2 <= tolerance * tolerance;
  };
  std::vector<std::int32_t> label(n, -1);
  std::vector<Region> regions;
  std::vector<std::uint32_t> stack;
  for (std::size_t seed = 0; seed < n; ++seed) {
    if (!lit[seed] || label[seed] >= 0) continue;
    const auto id = static_cast<std::int32_t>(regions.size());
    Region r{"", "segment", id, {}};
    stack.assign(1, static_cast<std::uint32_t>(seed));
    label[seed] = id;
    while (!stack.empty()) {
      const std::uint32_t p = stack.back();
      stack.pop_back();
      r.pixels.push_back(p);
      const std::size_t x = p % static_cast<std::size_t>(w);
      const std::size_t neighbours[4] = {x > 0 ? p - 1 : n, x + 1 < static_cast<std::size_t>(w) ? p + 1 : n,
                                         p >= static_cast<std::size_t>(w) ? p - w : n, p + w < n ? p + w : n};
      for (const std::size_t q : neighbours)
        if (q < n && lit[q] && label[q] < 0 && close(p, q)) label[q] = id, stack.push_back(static_cast<std::uint32_t>(q));
    }
    std::sort(r.pixels.begin(), r.pixels.end());
    regions.push_back(std::move(r));
  }
  std::vector<Region> kept;
  for (Region& r : regions)
    if (r.pixels.size() >= options.min_pixels) {
      r.label = static_cast<std::int64_t>(kept.size()) + 1;
      r.name = fmt::format("segment {}", r.label);
      kept.push_back(std::move(r));
    }
  return kept;
}

}  // namespace ct::analyzer
