// SPDX-License-Identifier: Apache-2.0
// The baseline of bench_segment.sh: OpenCV's mean-shift filtering (pyrMeanShiftFiltering, Comaniciu & Meer)
// of an 8-bit image, with the window the analyzer's former segmentation used (6 pixels, 3 % of full scale,
// one pyramid level). Prints the seconds of the filtering alone; the script measures the process's time and
// peak memory.
//
//   bench_meanshift IMAGE
#include <chrono>
#include <cstdio>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: bench_meanshift IMAGE\n");
    return 2;
  }
  const cv::Mat image = cv::imread(argv[1], cv::IMREAD_COLOR);
  if (image.empty()) {
    std::fprintf(stderr, "%s: cannot read\n", argv[1]);
    return 2;
  }
  const auto t0 = std::chrono::steady_clock::now();
  cv::Mat filtered;
  cv::pyrMeanShiftFiltering(image, filtered, 6, 0.03 * 255, 1);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("pyrMeanShiftFiltering %dx%d: %.2f s (OpenCV %s, %d threads)\n", image.cols, image.rows, seconds, CV_VERSION, cv::getNumThreads());
  return 0;
}
