#pragma once
// One region of one RGB layer, analysed: its histogram and its cluster shape, judged in the context of
// the whole layer (histogram range, clipping levels, quantisation).

#include <array>
#include <cstdint>
#include <string>

#include "analyzer/cluster_shape.h"
#include "analyzer/histogram.h"
#include "analyzer/image_input.h"
#include "analyzer/regions.h"

namespace ct::analyzer {

struct AnalyzeOptions {
  int bins = 64;
  int threads = 0;
  std::uint64_t seed = 1;
  std::size_t max_noise_pairs = 200000;
  ShapeCriteria criteria;
};

// What every region of a layer shares.
struct LayerContext {
  HistogramSpec spec;
  // Clipping levels: from the camera's white level when the file gives it (less the subtracted black level
  // and 3σ of the read noise: a saturated pixel reads its white level less the read noise), else an integer
  // format's full scale, else each channel's largest value.
  std::array<double, 3> high_levels{};
  std::string high_levels_source = "";  // "white level", "full scale" or "channel maxima"
  ClippingRules clipping = {};          // known_high for the first two; the lower limits
  double quantisation_sigma = 0;   // 1/√12 digital numbers for integer files, else 0
};
// `encoding` is the file's for the final image; pass a default (float) encoding for the linear and
// component layers.
LayerContext layer_context(const RgbImage& layer, const ImageEncoding& encoding, int bins);

struct RegionAnalysis {
  std::string name, source;
  std::int64_t label = -1;
  std::size_t pixels = 0;      // in the region
  std::size_t non_finite = 0;  // of those, NaN or infinite: left out
  Histogram3 histogram;
  ClusterShape shape;
};

RegionAnalysis analyse_region(const RgbImage& layer, const LayerContext& context, const Region& region,
                              const AnalyzeOptions& options);

}  // namespace ct::analyzer
