// SPDX-License-Identifier: Apache-2.0
// The analyzer's histogram and cluster descriptors on a 24-megapixel 16-bit image, beside OpenCV's
// calcHist of the same image in the same process (absolute times on a shared machine are noisy; the ratio
// is what to read).
//
//   bench_analyzer [--width W] [--height H] [--bins B] [--repeats N]
//
// Timed, best of N runs each:
//   calcHist            cv::calcHist, 3 channels, B bins each over [0, 65536), on the CV_16UC3 image
//   histogram           analyzer::histogram_3d on the same pixels as float samples (the analyzer's input)
//   histogram+moments   histogram_3d and moments (mean, covariance, principal axes): the descriptors
//   full region         analyse_region: histogram, noise level, moments, line/plane/curve fits, class
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <functional>
#include <string>

#include <fmt/core.h>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "analyzer/histogram.h"
#include "analyzer/moments.h"
#include "analyzer/region_analysis.h"
#include "core/random.h"

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

// A dichromatic-looking test image: shading along x, a highlight blob, and noise, in 16 bits.
cv::Mat make_image(int width, int height) {
  cv::Mat image(height, width, CV_16UC3);
  for (int y = 0; y < height; ++y) {
    ct::Random random(7, static_cast<std::uint64_t>(y));
    auto* row = image.ptr<cv::Vec3w>(y);
    for (int x = 0; x < width; ++x) {
      const double shade = 0.1 + 0.8 * x / width, dx = x - 0.6 * width, dy = y - 0.4 * height;
      const double highlight = 0.3 * std::exp(-(dx * dx + dy * dy) / (0.02 * width * width));
      const double body[3] = {0.8, 0.45, 0.25};
      for (int c = 0; c < 3; ++c)
        row[x][c] = cv::saturate_cast<std::uint16_t>(60000 * (shade * body[c] + highlight) + 400 * (random.uniform() - 0.5));
    }
  }
  return image;
}

}  // namespace

int main(int argc, char** argv) {
  int width = 6000, height = 4000, bins = 64, repeats = 5;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string flag = argv[i];
    const int value = std::atoi(argv[i + 1]);
    if (flag == "--width") width = value;
    else if (flag == "--height") height = value;
    else if (flag == "--bins") bins = value;
    else if (flag == "--repeats") repeats = value;
    else return std::fprintf(stderr, "unknown option %s\n", argv[i]), 2;
  }
  const cv::Mat image = make_image(width, height);
  ct::analyzer::RgbImage samples{width, height, std::vector<float>(image.total() * 3)};
  image.reshape(1, 1).convertTo(cv::Mat(1, static_cast<int>(samples.rgb.size()), CV_32F, samples.rgb.data()), CV_32F);
  ct::analyzer::HistogramSpec spec;
  spec.bins = bins;
  spec.hi = {65535, 65535, 65535};

  cv::Mat hist;
  const int channels[] = {0, 1, 2}, sizes[] = {bins, bins, bins};
  const float range[] = {0, 65536};
  const float* ranges[] = {range, range, range};
  const double calchist = best_seconds(repeats, [&] { cv::calcHist(&image, 1, channels, cv::Mat(), hist, 3, sizes, ranges); });

  fmt::print("{}×{} 16-bit RGB ({:.1f} Mpixel), {}³ bins, best of {}; OpenCV {} with {} threads\n", width, height,
             width * double(height) * 1e-6, bins, repeats, CV_VERSION, cv::getNumThreads());
  fmt::print("{:<28}{:>10}{:>12}{:>14}\n", "", "threads", "seconds", "vs calcHist");
  fmt::print("{:<28}{:>10}{:>12.3f}{:>13.2f}x\n", "calcHist", cv::getNumThreads(), calchist, 1.0);
  for (const int threads : {1, 2}) {
    const double h = best_seconds(repeats, [&] { ct::analyzer::histogram_3d(samples.rgb, spec, threads); });
    const double hm = best_seconds(repeats, [&] {
      ct::analyzer::histogram_3d(samples.rgb, spec, threads);
      ct::analyzer::moments(samples.rgb, threads);
    });
    fmt::print("{:<28}{:>10}{:>12.3f}{:>13.2f}x\n", "histogram", threads, h, h / calchist);
    fmt::print("{:<28}{:>10}{:>12.3f}{:>13.2f}x\n", "histogram+moments", threads, hm, hm / calchist);
  }
  ct::analyzer::AnalyzeOptions options;
  options.bins = bins;
  const ct::analyzer::LayerContext context = ct::analyzer::layer_context(samples, {true, 16, 65535}, bins);
  const ct::analyzer::Region whole = ct::analyzer::whole_image_region(width, height);
  std::string shape;
  const double full = best_seconds(std::min(repeats, 2), [&] {
    shape = ct::analyzer::class_name(ct::analyzer::analyse_region(samples, context, whole, options).shape.shape);
  });
  fmt::print("{:<28}{:>10}{:>12.3f}{:>13.2f}x   (class: {})\n", "full region analysis", 2, full, full / calchist, shape);
  // Check that both count the same pixels, so the comparison is fair.
  std::uint64_t total = 0;
  for (auto it = hist.begin<float>(); it != hist.end<float>(); ++it) total += static_cast<std::uint64_t>(*it);
  if (total != image.total()) return std::fprintf(stderr, "calcHist counted %llu pixels\n", static_cast<unsigned long long>(total)), 1;
  return 0;
}
