// SPDX-License-Identifier: Apache-2.0
// measure_delta_e: ΔE00 between two spectral EXR renders. Apart from plan.cpp so that plan's model, which
// `chromatrace check-scene` runs, is linked without OpenEXR (chromatrace_plan_model).
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <optional>

#include <fmt/core.h>

#include "core/band_plan.h"
#include "core/colour.h"
#include "core/error.h"
#include "core/spectral_exr.h"
#include "core/render_delta_e.h"
#include "plan/plan.h"
#include "reference_tracer/render.h"
#include "sensor_sim/spectral_response.h"

namespace ct::plan {

Measurement measure_delta_e(const std::filesystem::path& test, const std::filesystem::path& reference,
                            const Scene& scene, const std::string& camera, const std::filesystem::path& white_from) {
  const sensor::CameraCurves curves = sensor::camera_curves(camera, {"r", "g", "b"}, "--camera");
  SpectralExrReader ra(test), rb(reference);
  std::optional<SpectralExrReader> rw;
  if (!white_from.empty()) rw.emplace(white_from);
  SpectralExrReader& white_reader = rw ? *rw : rb;
  const SpectralExrInfo &ia = ra.info(), &ib = rb.info(), &iw = white_reader.info();
  for (const auto& [info, file] : {std::pair{&ia, &test}, std::pair{&iw, &white_from}})
    if (info->width != ib.width || info->height != ib.height)
      throw InputError(fmt::format("{}: {}x{} pixels but {} has {}x{}", file->string(), info->width, info->height,
                                   reference.string(), ib.width, ib.height));
  auto tristimuli = [&](SpectralExrReader& r) {
    const std::vector<float> v = r.read_layer(r.info().total());
    return sensor::camera_tristimulus(v, r.info().bands, curves,
                                      static_cast<std::size_t>(r.info().width) * r.info().height);
  };
  const std::vector<Vec3d> xa = tristimuli(ra), xb = tristimuli(rb);
  const std::vector<Vec3d> xw = rw ? tristimuli(*rw) : xb;
  std::vector<std::int32_t> ids(xa.size(), 0);
  if (iw.has_object_ids) white_reader.read_object_ids(0, iw.height, ids);
  const auto first_light = static_cast<std::int32_t>(scene.objects.size()) + 1;
  // The white: the scene's light through the observer over the white reference's band range.
  const PiecewiseLinearSpectrum light = scene_light_spectrum(scene);
  WhitePolicy policy;
  const double lo = iw.bands.min_wavelength(), hi = iw.bands.max_wavelength();
  for (int c = 0; c < 3; ++c) policy.light[c] = integral_of_product(light, curves.curves[c], lo, hi);
  const Vec3d white = white_point(
      xw, near_emitters(ids, iw.width, iw.height, [&](std::int32_t id) { return id >= first_light; }), policy);
  return delta_e_between(xa, xb, white);
}

namespace {

// The white a render's pixels are compared under (measure_delta_e's policy): the scene's light at the level of
// `level`'s surfaces, those on or next to an emitter left out.
Vec3d white_of(const std::vector<Vec3d>& level, const std::vector<std::int32_t>& ids, int width, int height,
               const Scene& scene, const Bands& bands, const sensor::CameraCurves& curves) {
  const auto first_light = static_cast<std::int32_t>(scene.objects.size()) + 1;
  const PiecewiseLinearSpectrum light = scene_light_spectrum(scene);
  WhitePolicy policy;
  for (int c = 0; c < 3; ++c)
    policy.light[c] = integral_of_product(light, curves.curves[c], bands.min_wavelength(), bands.max_wavelength());
  return white_point(level, near_emitters(ids, width, height, [&](std::int32_t id) { return id >= first_light; }),
                     policy);
}

// Each pixel's ΔE00 between two renders' tristimulus values under `white`.
std::vector<double> pixel_differences(const std::vector<Vec3d>& a, const std::vector<Vec3d>& b, const Vec3d& white) {
  // ΔE00 in its linear regime: between m − ε·d/2 and m + ε·d/2 (m the pair's mean, d their difference), over ε.
  // The mean ΔE00 of a large difference grows more slowly than the difference (CIELAB's cube root, ΔE00's
  // compression of chroma), so a pilot's few samples would understate the noisier renderer's part; linearised,
  // it scales as the noise's standard deviation at any number of samples.
  constexpr double kEpsilon = 1e-3;
  std::vector<double> de;
  for (std::size_t p = 0; p < a.size(); ++p) {
    Vec3d lo{}, hi{};
    for (int c = 0; c < 3; ++c) {
      const double m = 0.5 * (a[p][c] + b[p][c]), d = b[p][c] - a[p][c];
      lo[c] = m - 0.5 * kEpsilon * d;
      hi[c] = m + 0.5 * kEpsilon * d;
    }
    de.push_back(delta_e_2000(xyz_to_lab(lo, white), xyz_to_lab(hi, white)) / kEpsilon);
  }
  return de;
}

// Their mean and its standard error over the pixels.
std::pair<double, double> mean_and_error(const std::vector<double>& de) {
  const double n = static_cast<double>(de.size());
  const double mean = n > 0 ? std::accumulate(de.begin(), de.end(), 0.0) / n : 0.0;
  double var = 0;
  for (double x : de) var += (x - mean) * (x - mean);
  return {mean, n > 1 ? std::sqrt(var / (n - 1) / n) : 0.0};
}

std::pair<double, double> mean_difference(const std::vector<Vec3d>& a, const std::vector<Vec3d>& b, const Vec3d& white) {
  return mean_and_error(pixel_differences(a, b, white));
}

// The mean of `de` over each object's pixels, and their number.
std::map<std::int32_t, std::pair<double, std::size_t>> means_by_object(const std::vector<double>& de,
                                                                       const std::vector<std::int32_t>& ids) {
  std::map<std::int32_t, std::pair<double, std::size_t>> sums;
  for (std::size_t p = 0; p < de.size() && p < ids.size(); ++p) {
    auto& [sum, n] = sums[ids[p]];
    sum += de[p], ++n;
  }
  for (auto& [id, s] : sums) s.first /= static_cast<double>(s.second);
  return sums;
}

int integer_metadata(const SpectralExrInfo& info, const std::string& key) {
  const auto it = info.metadata.find(key);
  if (it == info.metadata.end()) throw InputError(fmt::format("{}: {}: missing", info.file, key));
  std::size_t used = 0;
  int v = 0;
  try {
    v = std::stoi(it->second, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != it->second.size() || v < 1)
    throw InputError(fmt::format("{}: {}: \"{}\" is not one number of samples (a pilot renders every band group alike)",
                                 info.file, key, it->second));
  return v;
}

}  // namespace

NoiseRatio measure_cycles_noise(const Scene& scene, const std::filesystem::path& a, const std::filesystem::path& b,
                                const std::string& camera, int threads) {
  const sensor::CameraCurves curves = sensor::camera_curves(camera, {"r", "g", "b"}, "--camera");
  SpectralExrReader ra(a), rb(b);
  const SpectralExrInfo &ia = ra.info(), &ib = rb.info();
  for (const SpectralExrInfo* info : {&ia, &ib}) {
    const auto renderer = info->metadata.find("chromatrace.renderer");
    if (renderer == info->metadata.end() || !renderer->second.starts_with("Cycles"))
      throw InputError(fmt::format("{}: chromatrace.renderer: not a Cycles render (\"{}\"); a pilot is rendered by "
                                   "Cycles through the Blender add-on",
                                   info->file, renderer == info->metadata.end() ? "" : renderer->second));
  }
  if (ib.width != ia.width || ib.height != ia.height)
    throw InputError(fmt::format("{}: {}x{} pixels but {} has {}x{}", ib.file, ib.width, ib.height, ia.file, ia.width,
                                 ia.height));
  if (!(ib.bands == ia.bands)) throw InputError(fmt::format("{}: other bands than {}", ib.file, ia.file));
  NoiseRatio out;
  out.edges_nm = ia.bands.edges();
  out.samples = integer_metadata(ia, "chromatrace.samples");
  if (integer_metadata(ib, "chromatrace.samples") != out.samples)
    throw InputError(fmt::format("{}: chromatrace.samples: {} but {} has {}", ib.file, ib.metadata.at("chromatrace.samples"),
                                 ia.file, out.samples));
  if (ia.metadata.count("chromatrace.seed") && ib.metadata.count("chromatrace.seed") &&
      ia.metadata.at("chromatrace.seed") == ib.metadata.at("chromatrace.seed"))
    throw InputError(fmt::format("{}: chromatrace.seed: {} is also the seed of {} (the same samples twice: no noise to "
                                 "measure)", ib.file, ib.metadata.at("chromatrace.seed"), ia.file));
  const std::size_t pixels = static_cast<std::size_t>(ia.width) * static_cast<std::size_t>(ia.height);
  const std::vector<float> va = ra.read_layer(ia.total()), vb = rb.read_layer(ib.total());
  auto tristimuli = [&](const std::vector<float>& v) { return sensor::camera_tristimulus(v, ia.bands, curves, pixels); };
  std::vector<std::int32_t> ids(pixels, 0);
  if (ia.has_object_ids) ra.read_object_ids(0, ia.height, ids);
  const std::vector<Vec3d> xa = tristimuli(va);
  const Vec3d cycles_white = white_of(xa, ids, ia.width, ia.height, scene, ia.bands, curves);
  const std::vector<double> cycles_de = pixel_differences(xa, tristimuli(vb), cycles_white);
  const auto [cycles, cycles_se] = mean_and_error(cycles_de);
  // Each group's part, and each pair's: the first pilot with those groups' bands taken from the second.
  const std::size_t nb = ia.bands.size(), groups = cycles_band_groups(nb);
  const std::vector<std::vector<std::size_t>> members = cycles_render_groups(nb);
  auto swapped = [&](std::size_t g, std::size_t h) {
    std::vector<float> hybrid = va;
    for (std::size_t p = 0; p < pixels; ++p)
      for (std::size_t b = 0; b < nb; ++b)
        if (const std::size_t of = cycles_band_group_of(nb, b); of == g || of == h)
          hybrid[p * nb + b] = vb[p * nb + b];
    const double e = mean_difference(xa, tristimuli(hybrid), cycles_white).first;
    return e * e;
  };
  std::vector<double> single(groups);
  for (std::size_t g = 0; g < groups; ++g) single[g] = swapped(g, g);
  out.group_shares.assign(groups * groups, 0.0);
  double sum = 0;
  for (std::size_t g = 0; g < groups; ++g)
    for (std::size_t h = 0; h < groups; ++h) {
      double& d = out.group_shares[g * groups + h];
      d = g == h ? single[g] : h < g ? out.group_shares[h * groups + g] : 0.5 * (swapped(g, h) - single[g] - single[h]);
      sum += d;
    }
  for (double& d : out.group_shares) d = sum > 0 ? d / sum : 0.0;
  // Each group as the guide of a guided render: every band reconstructed from it takes its noise relative to its
  // signal, δ_g(p) = Σ_b (a_b − b_b) / √2 over Σ_b (a_b + b_b) / 2 (b the group's bands), as a factor common to all
  // bands (|δ| ≤ √2: the pilots' values are not negative). Its ΔE00 is that between x̄ · (1 ∓ δ_g / 2), x̄ the pilots'
  // mean, linearised as pixel_differences does, since it scales as the guide's noise at any samples; under the white
  // at the level of x̄. Averaged over the image's pixels (lights' own left out) and over the pixels of each object
  // that holds kPilotObjectPixels, then over the image and those objects, each once.
  const auto first_light = static_cast<std::int32_t>(scene.objects.size()) + 1;
  {
    std::vector<float> mean(va.size());
    for (std::size_t i = 0; i < va.size(); ++i) mean[i] = 0.5f * (va[i] + vb[i]);
    const std::vector<Vec3d> xm = tristimuli(mean);
    const Vec3d white = white_of(xm, ids, ia.width, ia.height, scene, ia.bands, curves);
    std::vector<std::int32_t> lit = ids;  // −1 on a light's own pixels
    for (std::int32_t& id : lit)
      if (id >= first_light) id = -1;
    out.group_guided_delta_e.assign(groups, 0.0);
    for (std::size_t g = 0; g < groups; ++g) {
      std::vector<Vec3d> lo(pixels), hi(pixels);
      for (std::size_t p = 0; p < pixels; ++p) {
        double d = 0, m = 0;
        for (std::size_t b : members[g]) {
          d += double{va[p * nb + b]} - vb[p * nb + b];
          m += 0.5 * (double{va[p * nb + b]} + vb[p * nb + b]);
        }
        const double delta = m > 0 ? d / std::sqrt(2.0) / m : 0.0;
        for (int c = 0; c < 3; ++c) lo[p][c] = xm[p][c] * (1 - delta / 2), hi[p][c] = xm[p][c] * (1 + delta / 2);
      }
      const std::vector<double> de = pixel_differences(lo, hi, white);
      double image = 0;
      std::size_t n = 0, counted = 1;  // the image, then each object
      for (std::size_t p = 0; p < pixels; ++p)
        if (lit[p] >= 0) image += de[p], ++n;
      double sum = n > 0 ? image / static_cast<double>(n) : 0.0;
      for (const auto& [id, s] : means_by_object(de, lit))
        if (id > 0 && s.second >= kPilotObjectPixels) sum += s.first, ++counted;
      out.group_guided_delta_e[g] = sum / static_cast<double>(counted);
    }
  }
  // The tracer alike: the pilots' size, bands and samples.
  Scene s = scene;
  s.camera.width = ia.width;
  s.camera.height = ia.height;
  rt::RenderOptions o;
  o.samples = out.samples;
  o.bands = ia.bands;
  o.mode = SpectralMode::Bands;
  o.components = rt::ComponentSelection::parse("none");
  o.threads = threads;
  o.progress = false;
  std::array<std::vector<Vec3d>, 2> tracer;
  std::vector<std::int32_t> tracer_ids;
  for (std::uint64_t seed : {1, 2}) {
    o.seed = seed;
    const rt::RenderedImage image = rt::render(s, o);
    tracer[seed - 1] = sensor::camera_tristimulus(image.layers[0], ia.bands, curves, pixels);
    tracer_ids = image.object_ids;
  }
  const std::vector<double> tracer_de =
      pixel_differences(tracer[0], tracer[1], white_of(tracer[0], tracer_ids, ia.width, ia.height, scene, ia.bands, curves));
  const auto [traced, traced_se] = mean_and_error(tracer_de);
  if (!(traced > 0))
    throw InputError(fmt::format("{}: the tracer's renders of {} at its size and samples show no noise to compare with",
                                 ia.file, scene.source));
  out.pixel_noise = cycles_de;
  out.width = ia.width;
  out.height = ia.height;
  out.cycles = cycles;
  out.tracer = traced;
  out.tracer_at_one = traced / std::sqrt(2.0) * std::sqrt(static_cast<double>(out.samples));
  out.ratio = cycles / traced;
  out.se = out.ratio * std::hypot(cycles_se / std::max(cycles, 1e-300), traced_se / traced);
  // Each object's ratio over the image's, where both sides hold enough of its pixels to judge it.
  if (ia.has_object_ids) {
    const auto on_cycles = means_by_object(cycles_de, ids), on_tracer = means_by_object(tracer_de, tracer_ids);
    for (const auto& [id, c] : on_cycles) {
      const auto t = on_tracer.find(id);
      if (id <= 0 || t == on_tracer.end() || c.second < kPilotObjectPixels || t->second.second < kPilotObjectPixels ||
          !(t->second.first > 0) || !(out.ratio > 0))
        continue;
      out.object_ratio[id] = c.first / t->second.first / out.ratio;
    }
  }
  return out;
}

}  // namespace ct::plan
