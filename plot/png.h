// SPDX-License-Identifier: Apache-2.0
#pragma once
// A plot as PNG bytes, for a file or a page that embeds it.

#include <string>

#include <opencv2/core.hpp>

namespace ct::plot {

// The PNG encoding of an 8-bit image (BGR, BGRA or grey); std::runtime_error if OpenCV cannot encode it.
std::string encode_png(const cv::Mat& image);

}  // namespace ct::plot
