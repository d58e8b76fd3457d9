// SPDX-License-Identifier: Apache-2.0
#pragma once
// The camera image as a person would look at it, for the figure page: the sensor's display layer (the
// camera's rendering intent, docs/sensor.md) when the file has one; otherwise the noise-free linear camera
// signal (or the final image), white-balanced on its brightest surfaces, exposed so that the 99th percentile
// of the surfaces' brightest channel sits at 0.9 (pixels lit mostly by the `emission` component, lamps seen
// directly, set neither), and sRGB-encoded.

#include <filesystem>
#include <string_view>
#include <vector>

#include <opencv2/core.hpp>

#include "analyzer/image_input.h"
#include "core/statistics.h"  // quantile, which the figure's plots use too

namespace ct::series {

// A component layer of the file by name (`emission`, `light.key` …); nullptr when it has none.
const analyzer::RgbImage* find_layer(const analyzer::AnalysisImage& input, std::string_view name);

// 8-bit BGR (OpenCV's order).
cv::Mat preview_image(const analyzer::AnalysisImage& input);

// preview_image written atomically as a PNG.
void write_preview_png(const std::filesystem::path& file, const analyzer::AnalysisImage& input);

}  // namespace ct::series
