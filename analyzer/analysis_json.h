// SPDX-License-Identifier: Apache-2.0
#pragma once
// analysis.json: every number of an analysis (docs/analyze.md, "analysis.json", lists each field), and
// the per-region histogram files it points to.

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "analyzer/analysis.h"

namespace ct::analyzer {

inline constexpr const char* kAnalysisFormat = "chromatrace-analysis/1";

nlohmann::json shape_to_json(const ClusterShape& shape);
// `plotted`: which regions have plots (files.plot null for the others); empty: all of them.
nlohmann::json analysis_to_json(const ImageAnalysis& analysis, const std::vector<bool>& plotted = {});
// The 3D histogram (sparse cells), its three projections and the rg-chromaticity histogram of a region.
nlohmann::json histogram_to_json(const Histogram3& histogram, const Histogram2& chromaticity);

// "region-03": the stem of a region's files (plots, histograms), by its index.
std::string region_stem(std::size_t index);

}  // namespace ct::analyzer
