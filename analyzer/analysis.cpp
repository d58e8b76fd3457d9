// SPDX-License-Identifier: Apache-2.0
#include "analyzer/analysis.h"

#include <algorithm>
#include <cmath>

#include <fmt/core.h>

#include "analyzer/edge_mixing.h"
#include "analyzer/superposition.h"
#include "core/error.h"
#include "core/parallel.h"
#include "core/progress.h"

namespace ct::analyzer {
namespace {

// The clipping levels a highlight line can run into: the camera's white level or an integer file's full scale.
// Channel maxima are no level a highlight was cut at (every highlight reaches its own maximum).
std::array<double, 3> known_levels(const LayerContext& context) {
  return context.clipping.known_high ? context.high_levels : std::array<double, 3>{kNoLevel, kNoLevel, kNoLevel};
}

IlluminantContext illuminant_context(const AnalysisImage& input, const LayerContext& layer, const std::vector<Region>& regions,
                                     const std::optional<Vec3>& known, const std::optional<Vec3>& camera_white) {
  IlluminantContext c;
  // A render made by chromatrace names its objects or its light paths, or carries its noise-free linear signal.
  c.photograph = !input.linear && input.components.empty() && input.object_ids.empty();
  c.known = known;
  c.high_levels = known_levels(layer);
  c.low_levels = layer.clipping.low;
  c.camera_white = camera_white;
  c.pixels = regions;
  return c;
}

void check_size(const LabelImage& image, const RgbImage& layer, const std::string& file) {
  if (image.width != layer.width || image.height != layer.height)
    throw InputError(fmt::format("{}: is {}×{}, the image is {}×{}", file, image.width, image.height, layer.width, layer.height));
}

// How far a region's own values confirm the declared curve's γ, where they can: the γ whose inverse flattens the
// stored values again into the flat the light made, with its bootstrap standard error, compared with the declared
// one (gamma_against_declared). The flat is a plane for a dichromatic object (L, skewed-T, fork, P, planar in linear
// light: a per-channel power bends it even through black), or a line the curve bent (class gamma). A line that stays
// a line carries no information on γ (a line through black stays one under any power).
void confirm_declared_gamma(RegionAnalysis& r, const RgbImage& stored, const Region& region, const ToneCurve& curve,
                            double full_scale, const AnalyzeOptions& options) {
  if (r.shape.gamma || !r.linear_light || r.shape.shape == ShapeClass::Clipped) return;
  std::optional<GammaFlat> flat;
  switch (r.linear_light->shape) {
    case ShapeClass::L: case ShapeClass::SkewedT: case ShapeClass::Fork: case ShapeClass::P: case ShapeClass::Planar:
      flat = GammaFlat::Plane; break;
    case ShapeClass::Linear:
      if (r.shape.shape == ShapeClass::Gamma) flat = GammaFlat::Line;
      break;
    default: break;
  }
  if (!flat) return;
  const RegionSamples samples = gather_samples(stored, region);
  const std::size_t n = samples.size(), stride = (n + options.criteria.max_points - 1) / std::max<std::size_t>(1, options.criteria.max_points);
  std::vector<Vec3> points;
  for (std::size_t i = 0; i < n; i += std::max<std::size_t>(1, stride))
    points.emplace_back(samples.rgb[i * 3], samples.rgb[i * 3 + 1], samples.rgb[i * 3 + 2]);
  std::optional<GammaFit> fit = fit_gamma(points, *flat);
  if (!fit) return;
  fit->gamma_se = gamma_standard_error(points, options.seed, *flat);
  r.shape.gamma = fit;
  r.declared_gamma = compare_gamma(*fit, curve, full_scale);
}

}  // namespace

std::vector<Region> select_regions(const AnalysisImage& input, const RgbImage& layer, const RegionOptions& options,
                                   Segmentation* segmentation, bool progress) {
  std::vector<Region> regions{whole_image_region(layer.width, layer.height)};
  auto append = [&](std::vector<Region> more) { std::move(more.begin(), more.end(), std::back_inserter(regions)); };
  // Id 0 is "no object" by convention, unless the file gives it a name.
  const std::vector<std::int32_t> skip = input.object_names.contains(0) ? std::vector<std::int32_t>{} : std::vector<std::int32_t>{0};
  if (options.labels == "object_id" || (options.labels.empty() && !options.no_labels && !input.object_ids.empty())) {
    if (input.object_ids.empty()) throw InputError(fmt::format("{}: --labels object_id: the image has no object_id channel", input.file));
    append(label_regions(input.object_ids, "object", input.object_names, skip));
  } else if (!options.labels.empty()) {
    const LabelImage labels = read_label_image(options.labels);
    check_size(labels, layer, options.labels);
    append(label_regions(labels.labels, "label", {}, {0}));
  } else if (options.label_image) {
    check_size(*options.label_image, layer, "labels");
    append(label_regions(options.label_image->labels, "label", {}, {0}));
  }
  for (const std::string& m : options.masks) {
    const LabelImage mask = read_label_image(m);
    check_size(mask, layer, m);
    regions.push_back(mask_region(mask, fmt::format("mask {}", std::filesystem::path(m).filename().string())));
  }
  for (const auto& [name, mask] : options.mask_images) {
    check_size(mask, layer, "mask " + name);
    regions.push_back(mask_region(mask, "mask " + name));
  }
  for (const Rect& r : options.rects) regions.push_back(rect_region(r, layer.width, layer.height));
  if (options.segment) {
    // In linear light: the final layer's curve is undone (the other layers are linear); clipped pixels are
    // those at the clipping level of an integer file.
    const bool final_layer = &layer == &input.image;
    const ImageEncoding& e = input.encoding;
    const std::optional<ToneCurve> curve = final_layer ? e.curve : std::nullopt;
    const double clip = final_layer && e.integer ? e.clipping_level().value_or(e.full_scale) : 0.0;
    Segmentation s = segment_image(layer, curve, e.integer ? e.full_scale : 1.0, clip, options.segmentation, progress);
    append(std::move(s.regions));
    s.regions.clear();
    if (segmentation) *segmentation = std::move(s);
  }
  return regions;
}

ImageAnalysis analyse_image(const AnalysisImage& input, const std::string& layer, std::vector<Region> regions,
                            const AnalyzeOptions& options, const std::optional<Vec3>& known_illuminant, bool progress) {
  ImageAnalysis a;
  a.file = input.file;
  a.layer = layer.empty() ? "final" : layer;
  const RgbImage& pixels = select_layer(input, layer);
  a.width = pixels.width;
  a.height = pixels.height;
  a.encoding = a.layer == "final" ? input.encoding : ImageEncoding{};
  a.context = layer_context(pixels, a.encoding, options.bins);
  if (options.camera_noise && a.layer == "final") use_camera_noise(a.context.noise, pixels, *options.camera_noise);
  if (const HistogramSpec& spec = a.context.spec; spec.robust)
    a.notes.push_back(fmt::format("{} pixel{} ({:.3g} % of the image) reach {:.4g}, more than {} times the {:g}th "
                                  "percentile of the pixels' values: the histograms and plots end at {:.4g} and count "
                                  "them in their last bins, so the rest of the image is not squeezed into one cell "
                                  "(the shapes are measured on every value)",
                                  spec.outliers, spec.outliers == 1 ? "" : "s",
                                  100.0 * static_cast<double>(spec.outliers) / static_cast<double>(std::max<std::size_t>(1, pixels.pixel_count())),
                                  spec.outlier_max, kRobustRatio, 100 * kRobustQuantile, spec.hi[0]));
  a.options = options;
  a.regions = std::move(regions);
  // Values encoded by a known non-linear curve are analysed twice: as stored (what the histogram shows) and in
  // linear light (what the light did); the illuminant is estimated from the light.
  const std::optional<ToneCurve> curve =
      a.encoding.curve && !a.encoding.curve->linear() ? a.encoding.curve : std::nullopt;
  const double full_scale = a.encoding.integer ? a.encoding.full_scale : 1.0;
  const RgbImage linear = curve ? linear_light(input) : RgbImage{};
  const LayerContext linear_context = curve ? linear_light_context(a.context, linear, *curve, full_scale) : LayerContext{};
  Progress bar("analyze", a.regions.size(), progress);
  a.results.resize(a.regions.size());
  if (!input.components.empty()) a.explanations.resize(a.regions.size());
  auto analyse = [&](std::size_t i, const AnalyzeOptions& opts) {
    const Region& r = a.regions[i];
    RegionAnalysis result = analyse_region(pixels, a.context, r, opts);
    if (const ClusterShape& s = result.shape; a.encoding.curve && s.gamma)
      result.declared_gamma = compare_gamma(*s.gamma, *a.encoding.curve, full_scale);
    if (curve) {
      ClusterShape light = analyse_region(linear, linear_context, r, opts).shape;
      // The whole image mixes every cluster: its class only describes; the curve's bend is judged per object.
      if (r.source == "image") result.linear_light = std::move(light);
      else {
        apply_tone_curve(result, std::move(light), *curve, opts.criteria);
        confirm_declared_gamma(result, pixels, r, *curve, full_scale, opts);
      }
    }
    EdgeMixing mixing;
    if (r.source == "labels" && !input.object_ids.empty()) {
      // Mixing turns a colour's direction; the noise that matters is across the cluster's first axis (along it,
      // neighbouring pixels differ by shading as well as by noise).
      const double noise = std::hypot(result.shape.noise_sigma[1], result.shape.noise_sigma[2]);
      if (input.encoding.pixel_area.value_or(true)) {
        mixing = find_edge_mixing(pixels, input.object_ids, r, static_cast<std::int32_t>(r.label), noise);
        apply_edge_mixing(result, mixing, pixels, a.context, r, opts, input.object_names);
      } else {  // point-sampled pixels hold one surface's colour each: nothing mixes at an edge
        result.shape.decisions.push_back({"pixels integrate an area (chromatrace.pixel_area)", 0.0, 1.0, false});
      }
    }
    if (!input.components.empty()) a.explanations[i] = explain_region(input, r);
    if (r.source != "image")
      result.bend = find_bend_cause(input, pixels, r, result.shape, result.linear_light ? &*result.linear_light : nullptr,
                                    mixing.mixed, opts.criteria);
    // The light-group layers are the linear camera signal of each luminaire's light; the test reads them, not
    // the analysed layer, so it holds whatever curve encoded the final image. A layer that is one component
    // is no superposition.
    const bool whole_light = a.layer == "final" || a.layer == "linear";
    if (const auto superposition = whole_light ? find_superposition(input, r, opts.criteria) : std::nullopt)
      apply_superposition(result.shape, *superposition, opts.criteria);
    a.results[i] = std::move(result);
    bar.advance();
  };
  // Regions holding a large share of the image (the whole image) are analysed one at a time with every thread;
  // the others side by side, one thread each, largest first (each region's analysis is mostly serial, and its
  // results do not depend on the thread count), so that memory stays near that of one large region.
  const std::size_t total = std::max<std::size_t>(1, pixels.pixel_count());
  std::vector<std::size_t> side_by_side;
  for (std::size_t i = 0; i < a.regions.size(); ++i) {
    if (4 * a.regions[i].pixels.size() > total) analyse(i, options);
    else side_by_side.push_back(i);
  }
  std::stable_sort(side_by_side.begin(), side_by_side.end(),
                   [&](std::size_t x, std::size_t y) { return a.regions[x].pixels.size() > a.regions[y].pixels.size(); });
  AnalyzeOptions one = options;
  one.threads = 1;
  parallel_for(side_by_side.size(), options.threads, [&](std::size_t k) { analyse(side_by_side[k], one); });
  bar.finish();
  if (curve) {
    std::vector<RegionAnalysis> light = a.results;
    for (RegionAnalysis& r : light) r.shape = *r.linear_light;
    a.illuminant = estimate_illuminant(light, linear, illuminant_context(input, linear_context, a.regions, known_illuminant, input.camera_white));
    a.notes.push_back(fmt::format("R, G, B were encoded by {} ({}): classes are of the "
                                  "values as stored, each region's class in linear light is given beside it, and "
                                  "the illuminant is estimated in linear light", curve->describe(),
                                  a.encoding.curve_source.empty() ? "the file's chromatrace.curve_*" : a.encoding.curve_source));
  } else {
    a.illuminant = estimate_illuminant(a.results, pixels,
                                       illuminant_context(input, a.context, a.regions, known_illuminant,
                                                          a.layer == "final" || a.layer == "linear" ? input.camera_white : std::nullopt));
  }
  const std::optional<Explanation> no_explanation;
  for (std::size_t i = 0; i < a.results.size(); ++i)
    a.interpretations.push_back(interpret_region(a.results[i], a.regions[i], a.width, a.illuminant, a.encoding,
                                                 i < a.explanations.size() ? a.explanations[i] : no_explanation, options.criteria));
  for (const std::string& note : input.notes) a.notes.push_back(note);
  // The whole image's left-out pixels, less those set aside while reading (said above).
  const std::size_t set_aside = a.layer == "final" ? input.transparent_pixels + input.negative_pixels : 0;
  const std::size_t non_finite = (a.results.empty() ? 0 : a.results.front().non_finite) - std::min(set_aside, a.results.empty() ? 0 : a.results.front().non_finite);
  if (non_finite > 0)
    a.notes.push_back(fmt::format("{} pixel{} NaN or infinite: left out of every histogram", non_finite, non_finite == 1 ? " is" : "s are"));
  for (const RegionAnalysis& r : a.results)
    if (r.shape.shape == ShapeClass::None) a.notes.push_back(fmt::format("{}: {}", r.name, r.shape.reason));
  return a;
}

}  // namespace ct::analyzer
