// SPDX-License-Identifier: Apache-2.0
#pragma once
// The analysis directory: analysis.json, histograms/region-NN.json, plots/region-NN[-density|-components].png,
// report.html and, with segmentation, labels.png (16-bit grey: 0 unassigned, k segment k; --labels reads it
// back), each written atomically (core/file_io.h).

#include <filesystem>
#include <optional>
#include <vector>

#include "analyzer/analysis.h"

namespace ct::analyzer {

struct OutputOptions {
  bool plots = true;
  bool report = true;
  std::size_t report_points = 20000;  // points per region in report.html
  std::optional<std::size_t> plot_limit = std::nullopt;  // plots for this many of the largest regions (none: all)
};

// Which regions get plots: the `limit` largest (ties: the earlier), all without a limit.
std::vector<bool> plotted_regions(const ImageAnalysis& analysis, std::optional<std::size_t> limit);

// Creates `dir` (its parent must exist: InputError otherwise) and writes every file into it.
void write_analysis(const std::filesystem::path& dir, const AnalysisImage& input, const ImageAnalysis& analysis,
                    const OutputOptions& options);

}  // namespace ct::analyzer
