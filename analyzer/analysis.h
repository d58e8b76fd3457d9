// SPDX-License-Identifier: Apache-2.0
#pragma once
// A whole analysis: which regions, each region's histogram, shape and light-path explanation, and the
// illuminant estimated from all of them. analysis_json.h, plots.h and report.h present the result.

#include <optional>
#include <string>
#include <vector>

#include "analyzer/explain.h"
#include "analyzer/image_input.h"  // LabelImage
#include "analyzer/interpretation.h"
#include "analyzer/illuminant.h"
#include "analyzer/region_analysis.h"
#include "analyzer/segmentation.h"

namespace ct::analyzer {

struct RegionOptions {
  std::string labels;               // a channel of the image ("object_id") or a label image file; "" = object_id if present
  bool no_labels = false;           // ignore the image's object ids
  std::vector<std::string> masks;   // mask image files (non-zero = in)
  // Labels and masks already in memory (the Python module's arrays), named as their regions are: label k, mask <name>.
  std::optional<LabelImage> label_image;
  std::vector<std::pair<std::string, LabelImage>> mask_images;
  std::vector<Rect> rects;
  bool segment = false;             // automatic segmentation
  SegmentationOptions segmentation;
};

// The whole image first, then labels (id 0, "no object", left out unless the file names it), masks (files, then
// images in memory), rectangles and segments (by decreasing size, then the unassigned pixels as a region of their
// own), in that order. Label and mask images must match the image's size (InputError naming the file otherwise).
// With options.segment and `segmentation`, the segmentation's label map and numbers are kept there (its
// regions are moved into the result); with `progress`, the segmentation shows a progress bar on stderr.
std::vector<Region> select_regions(const AnalysisImage& input, const RgbImage& layer, const RegionOptions& options,
                                   Segmentation* segmentation = nullptr, bool progress = false);

struct ImageAnalysis {
  std::string file;
  std::string layer;  // "final", "linear" or a component
  int width = 0, height = 0;
  ImageEncoding encoding;  // of the analysed layer
  LayerContext context;
  AnalyzeOptions options;
  std::vector<Region> regions;
  std::vector<RegionAnalysis> results;            // one per region
  std::vector<std::optional<Explanation>> explanations;  // one per region; empty without component layers
  IlluminantAnalysis illuminant;
  std::vector<Interpretation> interpretations;  // one per region: what its cluster says, in words and numbers
  std::vector<std::string> notes;  // what a person should know (non-finite pixels, empty regions …)
  std::optional<Segmentation> segmentation;  // with --segment: the label map and its numbers
};

// progress: shows a bar on stderr over the regions.
ImageAnalysis analyse_image(const AnalysisImage& input, const std::string& layer, std::vector<Region> regions,
                            const AnalyzeOptions& options, const std::optional<Vec3>& known_illuminant, bool progress);

}  // namespace ct::analyzer
