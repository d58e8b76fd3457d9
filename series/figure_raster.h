// SPDX-License-Identifier: Apache-2.0
#pragma once
// figure3.png and figure4.png of the figure page (series/figure.h): the paper's four panels side by side, each
// with its caption, the camera image above, the oblique histogram and the principal-plane projection below,
// and per object the class expected and found.

#include <array>
#include <string>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

#include "series/figure_data.h"

namespace ct::series {

// 8-bit BGR. `panels` are {panel, the variant shown}: the paper's (a)–(d), the variant nullptr where no variant of
// the run reproduces that panel, then any extra panel a variant reproduces; `subtitle` says how the images were made.
cv::Mat figure_raster(int figure, const std::vector<std::pair<std::string, const VariantView*>>& panels, const std::string& subtitle);

}  // namespace ct::series
