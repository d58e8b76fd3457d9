// SPDX-License-Identifier: Apache-2.0
#include "plot/png.h"

#include <stdexcept>
#include <vector>

#include <opencv2/imgcodecs.hpp>

namespace ct::plot {

std::string encode_png(const cv::Mat& image) {
  std::vector<unsigned char> bytes;
  if (!cv::imencode(".png", image, bytes)) throw std::runtime_error("PNG encoding failed");
  return std::string(bytes.begin(), bytes.end());
}

}  // namespace ct::plot
