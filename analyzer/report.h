// SPDX-License-Identifier: Apache-2.0
#pragma once
// report.html: one self-contained page (it opens offline, from file://) with the image beside a rotatable
// 3D histogram of the selected region. It inlines the viewer bundle (analyzer/web/viewer.js with three.js),
// the image as a PNG data: URI, each region's points and fits as JSON, and a per-pixel map of the smallest
// region holding each pixel, so that a click in the image selects that region.

#include <string>

#include "analyzer/analysis.h"

namespace ct::analyzer {

// max_points: points per region in the 3D view, an even stride over larger regions. beside_files: the page lies in
// the analysis directory and links analysis.json and plots/; without it (a page shown on its own, as the Python
// module's notebook display) it says where the numbers are instead.
std::string report_html(const AnalysisImage& input, const ImageAnalysis& analysis, std::size_t max_points, bool beside_files = true);

// The page's image and maps are at most this many pixels on the long side.
inline constexpr int kReportImageSize = 1024;

}  // namespace ct::analyzer
