// SPDX-License-Identifier: Apache-2.0
#include "analyzer/region_analysis.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include <fmt/core.h>


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
  // The mask's taps adjacent when the file says each pixel's noise is its own; else as far apart as the measured
  // correlation of the noise calls for.
  std::optional<SpacingChoice> choice;
  if (!encoding.independent_pixel_noise()) choice = choose_noise_spacing(layer, c.clipping.low, c.high_levels, encoding.integer ? 1.0 : 0.0);
  c.noise = estimate_image_noise(layer, c.clipping.low, c.high_levels, c.quantisation_sigma, choice ? choice->spacing : 1);
  c.noise.spacing_choice = choice;
  return c;
}

LayerContext linear_light_context(const LayerContext& stored, const RgbImage& linear, const ToneCurve& curve, double full_scale) {
  LayerContext c = stored;
  for (double& level : c.high_levels)
    if (std::isfinite(level)) level = curve.decode(level, full_scale);
  for (int k = 0; k < 3; ++k) {
    c.spec.lo[k] = curve.decode(stored.spec.lo[k], full_scale);
    c.spec.hi[k] = curve.decode(stored.spec.hi[k], full_scale);
  }
  c.clipping.low.fill(curve.decode(stored.clipping.low[0], full_scale));
  c.quantisation_sigma = 0;
  c.noise = estimate_image_noise(linear, c.clipping.low, c.high_levels, 0.0, stored.noise.spacing);
  c.noise.spacing_choice = stored.noise.spacing_choice;
  return c;
}

void apply_tone_curve(RegionAnalysis& stored, ClusterShape linear, const ToneCurve& curve, const ShapeCriteria& k) {
  ClusterShape& s = stored.shape;
  // The flat the light's cluster lies in: a line (d = 1) or a plane (d = 2). Other classes (no samples, one
  // colour, clipped faces, volumes) have no flat for the curve to bend, and a gamma class is already the curve's.
  int d = 0;
  switch (linear.shape) {
    case ShapeClass::Linear: d = 1; break;
    case ShapeClass::L: case ShapeClass::SkewedT: case ShapeClass::Fork: case ShapeClass::P: case ShapeClass::Planar:
      d = 2; break;
    default: break;
  }
  if (d > 0 && s.shape != ShapeClass::Gamma && s.shape != ShapeClass::Clipped && s.samples == linear.samples) {
    const auto axis = static_cast<Eigen::Index>(d);
    // The spread off that flat as stored, against the noise along that axis …
    const double off = s.sigma[axis], noise = s.noise_sigma[axis];
    const bool significant = off > k.noise_factor * noise;
    s.decisions.push_back({fmt::format("spread off the light's {} as stored / noise", d == 1 ? "line" : "plane"),
                           off / std::max(1e-300, noise), k.noise_factor, significant});
    // … and what is left of it, relative to the cluster's length, once the curve is undone.
    const double stored_relative = off / std::max(1e-300, s.sigma[0]);
    const double linear_relative = linear.sigma[axis] / std::max(1e-300, linear.sigma[0]);
    const double left = linear_relative * linear_relative / std::max(1e-300, stored_relative * stored_relative);
    const bool straightened = left <= k.gamma_straightening;
    if (significant)
      s.decisions.push_back({"relative off-flat variance in linear light / as stored", left, k.gamma_straightening, straightened});
    if (significant && straightened) {
      s.reason = fmt::format("{} bends the {} cluster of linear light off its {} (by {:.2g} of its length as stored)",
                             curve.describe(), class_name(linear.shape), d == 1 ? "line" : "plane", stored_relative);
      s.shape = ShapeClass::Gamma;
    }
  }
  stored.linear_light = std::move(linear);
}

std::vector<std::size_t> regions_by_size(const std::vector<RegionAnalysis>& regions) {
  std::vector<std::size_t> order(regions.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return regions[a].pixels > regions[b].pixels; });
  return order;
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
  ShapeContext shape{&context.noise, context.quantisation_sigma, context.high_levels, context.clipping, options.seed, options.threads,
                     options.criteria};
  a.shape = analyse_shape(samples.rgb, shape);
  if (a.pixels == 0) a.shape.reason = "the region is empty: no shape measured";
  else if (samples.size() == 0) a.shape.reason = "every pixel of the region is NaN or infinite: no shape measured";
  return a;
}

}  // namespace ct::analyzer
