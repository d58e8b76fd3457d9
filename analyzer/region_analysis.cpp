#include "analyzer/region_analysis.h"

#include <algorithm>
#include <cmath>

#include "analyzer/noise_level.h"

namespace ct::analyzer {

LayerContext layer_context(const RgbImage& layer, const ImageEncoding& encoding, int bins) {
  LayerContext c;
  c.spec = histogram_spec(layer.rgb, bins, encoding.integer ? encoding.full_scale : 0.0);
  if (encoding.integer) c.quantisation_sigma = 1.0 / std::sqrt(12.0);
  c.clipping.low.fill(encoding.lowest_code());
  if (const auto white = encoding.clipping_level()) {
    c.high_levels.fill(*white - 3.0 * encoding.read_noise.value_or(0.0));
    c.high_levels_source = "white level";
    c.clipping.known_high = true;
    if (encoding.integer) {  // the integer range less the black level
      c.spec.lo.fill(0.0);
      c.spec.hi.fill(*white);
    }
  } else if (encoding.integer) {
    c.high_levels.fill(encoding.full_scale - (encoding.black_subtracted ? encoding.black_level.value_or(0.0) : 0.0));
    c.high_levels_source = "full scale";
    c.clipping.known_high = true;
    if (encoding.black_subtracted) {
      c.spec.lo.fill(0.0);
      c.spec.hi = c.high_levels;
    }
  } else {
    c.high_levels_source = "channel maxima";
    // A float file has no format limit; a simulated sensor's clipping shows as many pixels at the
    // channel's largest value.
    c.high_levels.fill(-std::numeric_limits<double>::infinity());
    for (std::size_t i = 0; i < layer.rgb.size(); ++i)
      if (std::isfinite(layer.rgb[i])) c.high_levels[i % 3] = std::max<double>(c.high_levels[i % 3], layer.rgb[i]);
    // A channel that is nowhere above 0 has no upper face to clip on.
    for (double& level : c.high_levels)
      if (!(level > 0)) level = std::numeric_limits<double>::infinity();
  }
  return c;
}

RegionAnalysis analyse_region(const RgbImage& layer, const LayerContext& context, const Region& region,
                              const AnalyzeOptions& options) {
  RegionAnalysis a;
  a.name = region.name;
  a.source = region.source;
  a.label = region.label;
  a.pixels = region.pixels.size();
  const RegionSamples samples = gather_samples(layer, region);
  a.non_finite = samples.non_finite;
  a.histogram = histogram_3d(samples.rgb, context.spec, options.threads);
  const std::vector<float> differences = neighbour_differences(layer, samples, options.max_noise_pairs);
  ShapeContext shape{differences, context.quantisation_sigma, context.high_levels, context.clipping, options.seed, options.threads,
                     options.criteria};
  a.shape = analyse_shape(samples.rgb, shape);
  if (a.pixels == 0) a.shape.reason = "the region is empty: no shape measured";
  else if (samples.size() == 0) a.shape.reason = "every pixel of the region is NaN or infinite: no shape measured";
  return a;
}

}  // namespace ct::analyzer
