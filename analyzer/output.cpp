// SPDX-License-Identifier: Apache-2.0
#include "analyzer/output.h"

#include <algorithm>
#include <numeric>

#include <fmt/core.h>

#include "analyzer/analysis_json.h"
#include "analyzer/plots.h"
#include "analyzer/report.h"
#include "core/error.h"
#include "core/file_io.h"
#include "core/json_input.h"
#include "plot/png.h"

namespace ct::analyzer {
namespace {

void write_png(const std::filesystem::path& file, const cv::Mat& image) { write_file_atomically(file, plot::encode_png(image)); }

}  // namespace

std::vector<bool> plotted_regions(const ImageAnalysis& analysis, std::optional<std::size_t> limit) {
  const std::size_t n = analysis.regions.size();
  if (!limit || *limit >= n) return std::vector<bool>(n, true);
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t i, std::size_t j) { return analysis.regions[i].pixels.size() > analysis.regions[j].pixels.size(); });
  std::vector<bool> plotted(n, false);
  for (std::size_t k = 0; k < *limit; ++k) plotted[order[k]] = true;
  return plotted;
}

void write_analysis(const std::filesystem::path& dir, const AnalysisImage& input, const ImageAnalysis& analysis,
                    const OutputOptions& options) {
  const std::filesystem::path parent = std::filesystem::absolute(dir).parent_path();
  if (!std::filesystem::is_directory(parent))
    throw InputError(fmt::format("{}: directory {} does not exist", dir.string(), parent.string()));
  if (std::filesystem::exists(dir) && !std::filesystem::is_directory(dir))
    throw InputError(fmt::format("{}: exists and is not a directory", dir.string()));
  std::filesystem::create_directories(dir / "histograms");
  if (options.plots) std::filesystem::create_directories(dir / "plots");

  const RgbImage& layer = select_layer(input, analysis.layer);
  ComponentMap components;
  if (options.plots && !input.components.empty()) {
    components.dominant = dominant_component_map(input);
    for (const ComponentLayer& c : input.components) components.names.push_back(c.name);
  }
  const std::vector<bool> plotted = plotted_regions(analysis, options.plot_limit);
  if (analysis.segmentation) {
    const Segmentation& s = *analysis.segmentation;
    cv::Mat labels(s.height, s.width, CV_16UC1);
    for (int y = 0; y < s.height; ++y)
      for (int x = 0; x < s.width; ++x)
        labels.at<std::uint16_t>(y, x) = static_cast<std::uint16_t>(s.labels[static_cast<std::size_t>(y) * static_cast<std::size_t>(s.width) + static_cast<std::size_t>(x)]);
    write_png(dir / "labels.png", labels);
  }
  for (std::size_t i = 0; i < analysis.results.size(); ++i) {
    const std::string stem = region_stem(i);
    const RegionSamples samples = gather_samples(layer, analysis.regions[i]);
    write_file_atomically(dir / "histograms" / (stem + ".json"),
                          histogram_to_json(analysis.results[i].histogram, chromaticity_histogram(samples.rgb, analysis.context.spec.bins)).dump(-1, ' ', false, kReplaceInvalidUtf8));
    if (!options.plots || !plotted[i]) continue;
    write_png(dir / "plots" / (stem + ".png"), plot_region(layer, analysis, i, PlotColouring::Own, components));
    write_png(dir / "plots" / (stem + "-density.png"), plot_region(layer, analysis, i, PlotColouring::Density, components));
    if (!components.dominant.empty())
      write_png(dir / "plots" / (stem + "-components.png"), plot_region(layer, analysis, i, PlotColouring::Component, components));
  }
  if (options.report) write_file_atomically(dir / "report.html", report_html(input, analysis, options.report_points));
  // Last, so that a complete analysis.json means a complete directory.
  write_file_atomically(dir / "analysis.json", analysis_to_json(analysis, options.plots ? plotted : std::vector<bool>(analysis.results.size(), false)).dump(1, ' ', false, kReplaceInvalidUtf8));
}

}  // namespace ct::analyzer
