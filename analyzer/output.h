#pragma once
// The analysis directory: analysis.json, histograms/region-NN.json, plots/region-NN[-density|-components].png
// and report.html, each written atomically (core/file_io.h).

#include <filesystem>

#include "analyzer/analysis.h"

namespace ct::analyzer {

struct OutputOptions {
  bool plots = true;
  bool report = true;
  std::size_t report_points = 20000;  // points per region in report.html
};

// Creates `dir` (its parent must exist: InputError otherwise) and writes every file into it.
void write_analysis(const std::filesystem::path& dir, const AnalysisImage& input, const ImageAnalysis& analysis,
                    const OutputOptions& options);

}  // namespace ct::analyzer
