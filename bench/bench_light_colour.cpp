// SPDX-License-Identifier: Apache-2.0
// What each estimate of the light's colour costs on a 24-megapixel photograph, beside the analyzer's 3-D histogram of
// the same pixels in the same process (absolute times on a shared machine are noisy; the ratio is what to read).
//
//   bench_light_colour [PHOTO] [--width W] [--height H] [--repeats N]
//
// PHOTO (default tests/data/photos/building.jpg, from the source directory) is read as the analyzer reads it, taken to
// linear light and resized to W × H (6000 × 4000) by bilinear interpolation. Timed, best of N runs each:
//   histogram              analyzer::histogram_3d of every pixel, 64 bins a side: the baseline
//   <statistical method>   analyzer::baseline_estimate with its 200-resample block bootstrap
//   lights in view         analyzer::find_lights_in_view
//   inverse-intensity      analyzer::estimate_iic over 64 blocks of the image taken as its surfaces, each thinned to
//                          200 000 pixels as the analysis thins a segment (a segmentation's regions cost the same)
//   as the analysis runs   analyzer::estimate_illuminant without regions: the lights in view and the statistical
//                          methods on the image reduced to 2 megapixels
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <functional>
#include <string>

#include <fmt/core.h>
#include <opencv2/imgproc.hpp>

#include "analyzer/analysis_image.h"
#include "analyzer/colour_constancy.h"
#include "analyzer/histogram.h"
#include "analyzer/iic.h"
#include "analyzer/illuminant.h"
#include "analyzer/image_input.h"
#include "analyzer/lights_in_view.h"

namespace {

double best_seconds(int repeats, const std::function<void()>& run) {
  double best = 1e300;
  for (int r = 0; r < repeats; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    run();
    best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  return best;
}

}  // namespace

int main(int argc, char** argv) {
  std::string photo = std::string(CHROMATRACE_SOURCE_DIR) + "/tests/data/photos/building.jpg";
  int width = 6000, height = 4000, repeats = 3;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--width") && i + 1 < argc) width = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--height") && i + 1 < argc) height = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--repeats") && i + 1 < argc) repeats = std::atoi(argv[++i]);
    else photo = argv[i];
  }
  using namespace ct::analyzer;
  const RgbImage linear = linear_light(read_analysis_image(photo));
  cv::Mat small(linear.height, linear.width, CV_32FC3, const_cast<float*>(linear.rgb.data())), big;
  cv::resize(small, big, cv::Size(width, height), 0, 0, cv::INTER_LINEAR);
  RgbImage image{width, height, std::vector<float>(big.ptr<float>(), big.ptr<float>() + 3 * static_cast<std::size_t>(width) * height)};
  fmt::print("{} resized to {} × {} ({:.1f} megapixels), best of {}\n", photo, width, height, width * height / 1e6, repeats);

  const HistogramSpec spec = histogram_spec(image.rgb, 64, 1.0);
  const double baseline = best_seconds(repeats, [&] { histogram_3d(image.rgb, spec, 0); });
  fmt::print("| {:<32} | {:>8.3f} s | {:>6.2f} × |\n", "histogram (baseline)", baseline, 1.0);
  const std::vector<std::uint8_t> usable;  // every finite pixel
  for (const MinkowskiSettings& m : baseline_methods()) {
    const double t = best_seconds(repeats, [&] { baseline_estimate(image.rgb, width, height, usable, m); });
    fmt::print("| {:<32} | {:>8.3f} s | {:>6.2f} × |\n", m.name, t, t / baseline);
  }
  const double lights = best_seconds(repeats, [&] { find_lights_in_view(image, usable); });
  fmt::print("| {:<32} | {:>8.3f} s | {:>6.2f} × |\n", "lights in view", lights, lights / baseline);
  std::vector<std::vector<float>> blocks(64);
  const std::size_t stride = std::max<std::size_t>(1, (image.pixel_count() / 64 + 199999) / 200000);
  std::vector<std::size_t> seen(64, 0);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const std::size_t b = static_cast<std::size_t>(8 * (8 * y / height) + 8 * x / width), p = 3 * (static_cast<std::size_t>(y) * width + x);
      if (seen[b]++ % stride == 0) blocks[b].insert(blocks[b].end(), &image.rgb[p], &image.rgb[p] + 3);
    }
  std::vector<IicSurface> surfaces;
  for (const auto& b : blocks) surfaces.push_back({b});
  const double iic = best_seconds(repeats, [&] { estimate_iic(surfaces); });
  fmt::print("| {:<32} | {:>8.3f} s | {:>6.2f} × |\n", "inverse-intensity chromaticity", iic, iic / baseline);
  const double all = best_seconds(repeats, [&] { estimate_illuminant({}, image, IlluminantContext{}); });
  fmt::print("| {:<32} | {:>8.3f} s | {:>6.2f} × |\n", "as the analysis runs (no regions)", all, all / baseline);
}
