#pragma once
// One region of one RGB layer, analysed: its histogram and its cluster shape, judged in the context of
// the whole layer (histogram range, clipping levels, quantisation).

#include <array>
#include <cstdint>
#include <optional>
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
  // The cluster in linear light, when the analysed values were encoded by a known non-linear response curve
  // (ImageEncoding::curve): the class the light itself gives, before the curve bent it.
  std::optional<ClusterShape> linear_light;
};

// The context of the same layer with its response curve undone (linear_light()): the clipping levels go
// through the curve's inverse, and the quantisation step, uneven in linear light, is left to the measured noise.
LayerContext linear_light_context(const LayerContext& stored, const ToneCurve& curve, double full_scale);

// Compares the region's cluster as stored with its cluster in linear light: where the light's cluster is a line
// or a plane, and as stored it spreads off that flat by more than the noise, a spread that undoing the curve
// removes (its variance relative to the cluster's length falls to gamma_straightening), the structure the
// histogram shows is the curve's bend, and the class becomes gamma (docs/analyze.md).
void apply_tone_curve(RegionAnalysis& stored, ClusterShape linear, const ToneCurve& curve, const ShapeCriteria& criteria);

RegionAnalysis analyse_region(const RgbImage& layer, const LayerContext& context, const Region& region,
                              const AnalyzeOptions& options);

}  // namespace ct::analyzer
