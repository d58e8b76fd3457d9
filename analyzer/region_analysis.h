// SPDX-License-Identifier: Apache-2.0
#pragma once
// One region of one RGB layer, analysed: its histogram and its cluster shape, judged in the context of
// the whole layer (histogram range, clipping levels, quantisation).

#include <array>
#include <cstdint>
#include <optional>
#include <string>

#include "analyzer/bend_cause.h"
#include "analyzer/cluster_shape.h"
#include "analyzer/histogram.h"
#include "analyzer/image_input.h"
#include "analyzer/noise_level.h"
#include "analyzer/regions.h"

namespace ct::analyzer {

struct AnalyzeOptions {
  int bins = 64;
  int threads = 0;
  std::uint64_t seed = 1;
  ShapeCriteria criteria;
  // The camera's calibrated noise for the final layer, in its digital numbers (cmd_analyze checks the units), instead
  // of the noise measured on the image.
  std::optional<CameraNoiseModel> camera_noise;
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
  ImageNoise noise;                // the layer's noise, once for every region (analyzer/noise_level.h)
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
  // The γ fitted to the values as stored against the curve the input declared (when both are known).
  std::optional<GammaComparison> declared_gamma;
  // What bends the cluster, when it is bent (analyzer/bend_cause.h); never for the whole image, which mixes every cluster.
  std::optional<BendCause> bend;
};

// The context of the same layer with its response curve undone (`linear`, from linear_light()): the clipping
// levels go through the curve's inverse, the noise is measured on `linear`, and the quantisation step, uneven in
// linear light, is left to the measured noise.
LayerContext linear_light_context(const LayerContext& stored, const RgbImage& linear, const ToneCurve& curve, double full_scale);

// Compares the region's cluster as stored with its cluster in linear light: where the light's cluster is a line
// or a plane, and as stored it spreads off that flat by more than the noise, a spread that undoing the curve
// removes (its variance relative to the cluster's length falls to gamma_straightening), the structure the
// histogram shows is the curve's bend, and the class becomes gamma (docs/analyze.md).
void apply_tone_curve(RegionAnalysis& stored, ClusterShape linear, const ToneCurve& curve, const ShapeCriteria& criteria);

// The regions' indices by decreasing pixel count (equal counts in their order): the order a person reads them in.
std::vector<std::size_t> regions_by_size(const std::vector<RegionAnalysis>& regions);

RegionAnalysis analyse_region(const RgbImage& layer, const LayerContext& context, const Region& region,
                              const AnalyzeOptions& options);

}  // namespace ct::analyzer
