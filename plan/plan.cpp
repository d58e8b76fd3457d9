// SPDX-License-Identifier: Apache-2.0
#include "plan/plan.h"

#include <algorithm>
#include <functional>
#include <cmath>
#include <limits>
#include <numeric>
#include <optional>
#include <set>

#include <Eigen/Dense>
#include <fmt/core.h>

#include "core/band_plan.h"
#include "core/colour.h"
#include "core/error.h"
#include "core/geometry.h"
#include "core/random.h"
#include "core/statistics.h"
#include "core/render_delta_e.h"
#include "plan/radiosity.h"
#include "plan/spectral_check.h"
#include "reference_tracer/accel.h"
#include "reference_tracer/render.h"
#include "sensor_sim/spectral_response.h"

namespace ct::plan {

namespace {

// A pixel of the preview: its object id and the luminance of each (bounce order, lobe).
struct Pixel {
  std::int32_t id = 0;
  std::size_t index = 0;  // in the preview image
  std::vector<std::array<double, 2>> y;  // [k][lobe]: lobe 0 diffuse (k = 0: emission), 1 glossy
  double total = 0;
  bool near_light = false;  // on or next to a light (core/render_delta_e.h, near_emitters)
};

// A reference depth's tail: 1 % of the luminance is a mean ΔE00 of about 0.25 at mid grey (L* ∝ Y^⅓, so
// ΔL* ≈ (L* + 16)/3 · ΔY/Y ≈ 25 · ΔY/Y), the quarter of a target of 1 that plan gives the bounce limit.
constexpr double kNegligibleShare = 0.01;
constexpr int kMaxReferenceBounces = 64;
// Rays per surface and side for the transfer factors: a factor's standard error is at most 1/(2·√4096) ≈ 0.008.
constexpr int kTransferRays = 4096;

// The low-resolution preview render (bands mode, every component) and the observer's weights of its bands.
struct Preview {
  Scene scene;  // the scene at the preview's size and the model's depth
  rt::RenderOptions options;
  rt::RenderedImage image;
  std::array<std::vector<double>, 3> weights;  // [channel][band]
  std::size_t pixels() const { return static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height); }
  // Tristimulus values of pixel p of a layer.
  Vec3d colour(const std::vector<float>& layer, std::size_t p) const {
    const std::size_t nb = image.bands.size();
    Vec3d x{};
    for (int c = 0; c < 3; ++c)
      for (std::size_t b = 0; b < nb; ++b) x[c] += weights[c][b] * layer[p * nb + b];
    return x;
  }
};

class Model {
 public:
  // The model's truth is exact spectra at the scene's own bounce limit or, given `reference_bounces` > 0, at that
  // many events or more: as many as it takes for the mean albedo's powers to fall to kNegligibleShare (the light
  // left beyond them is at most that share of what went before), at most kMaxReferenceBounces.
  Model(const Scene& scene, const PlanOptions& options, std::vector<std::string>& notes, int reference_bounces = 0);

  // Mean and 95th percentile of ΔE00 of a plan (bands, bounce limit) against exact spectra at depth(); the band
  // values turned into colours through a reconstruction fitted to the plan's own template spectra
  // (fit_reconstruction) when the model fits one (reconstructs()), else as a step function. `fitted` receives it.
  std::pair<double, double> evaluate(const std::vector<int>& edges, int max_bounces) const {
    return evaluate(edges, max_bounces, reconstruct_, nullptr);
  }
  std::pair<double, double> evaluate(const std::vector<int>& edges, int max_bounces, bool reconstruct,
                                     BandReconstruction* fitted) const;
  // Mean ΔE00 of the preview's noise (a realisation of one render's) in those of the bands `edges` (grid indices)
  // that `carry` marks, the others noiseless, the band values read as the plan reads them, on exact colours: their
  // part in the noise's colour error.
  double band_noise(const std::vector<int>& edges, int max_bounces, const std::vector<bool>& carry) const;
  // What the mean ΔE00 of a plan's bands and bounce limit with Cycles' noise (and a reference's) added pixel by pixel
  // needs, which does not change with the samples: each of the preview's pixels' ΔE00 of the bands (evaluate's) and
  // where each noise is — Cycles' as `cycles_noise` (per preview pixel: the pilots'; empty: the preview's own) has
  // it, the reference's where the preview has it. Where the noise is strong (dim pixels, a highlight) is seldom where
  // the bands miss (the sky seen directly, one colour of a texture), and the mean of the sum is then above the
  // quadrature of the means (Minkowski's inequality): docs/plan.md, "Bands and noise, pixel by pixel".
  struct PixelErrors {
    std::vector<double> bands, cycles, tracer;
    std::size_t pixel_count = 0;
    // The mean ΔE00 with Cycles' noise at a mean of `noise` and the reference's at `reference`
    // (pixel_by_pixel_mean).
    double mean(double noise, double reference = 0) const {
      return pixel_by_pixel_mean(bands, cycles, noise, tracer, reference, pixel_count);
    }
  };
  PixelErrors pixel_errors(const std::vector<int>& edges, int max_bounces, const std::vector<double>& cycles_noise) const;
  bool reconstructs() const { return reconstruct_; }
  std::pair<double, double> evaluate_exact(int max_bounces) const;  // exact spectra, truncated bounces
  // Per surface id: the mean ΔE00 over its pixels of the preview of a plan's bands and bounce limit, as evaluate's
  // (0 for an id with no lit pixel).
  std::vector<double> evaluate_by_id(const std::vector<int>& edges, int max_bounces) const;
  // Per surface id: one preview's noise as mean ΔE00 over its lit pixels (as preview_noise() over the image), and
  // how many lit pixels it has in the preview.
  const std::vector<double>& preview_noise_by_id() const { return preview_noise_by_id_; }
  const std::vector<std::size_t>& pixels_by_id() const { return pixels_by_id_; }

  const std::vector<int>& grid_edges() const { return grid_edges_; }  // candidate edge positions (grid indices)
  int lo() const { return grid_.lo; }
  int depth() const { return kmax_; }  // the truth's bounce limit
  const std::vector<Pixel>& pixels() const { return pixels_; }
  double hit_fraction() const { return hit_fraction_; }
  // Mean ΔE00 of the preview's Monte Carlo noise (one render against the truth) and its paths per pixel.
  double preview_noise() const { return preview_noise_; }
  int preview_samples() const { return preview_samples_; }
  std::array<int, 2> preview_size() const { return preview_size_; }
  double mean_albedo() const { return mean_albedo_; }

 private:
  // The steps of the constructor, in order.
  sensor::CameraCurves set_grid(const Scene& scene, const PlanOptions& options, std::vector<std::string>& notes,
                                int reference_bounces);
  void set_surfaces(const Scene& scene, const std::vector<TriangleMesh>& meshes, const PlanOptions& options,
                    std::vector<std::string>& notes, int reference_bounces);
  void set_exact_templates();
  Preview render_preview(const Scene& scene, const PlanOptions& options, const sensor::CameraCurves& curves) const;
  void read_preview(const Preview& preview, const std::vector<bool>& near_light);
  void set_white(const Preview& preview, const std::vector<bool>& near_light);
  void measure_preview_noise(const Preview& preview);

  // Templates of a band plan (tristimulus values at unit luminance, [id][k][lobe]) and the weights that turn its
  // band values into tristimulus values ([channel][band]; with a fitted reconstruction, through it).
  struct BandedTemplates {
    Templates templates;
    std::array<std::vector<double>, 3> weights;
  };
  BandedTemplates banded_templates(const std::vector<int>& edges, int max_bounces, bool reconstruct,
                                   BandReconstruction* fitted) const;
  // Tristimulus noise per preview pixel: the realisation of one preview render's noise averaged into the bands
  // `edges` (grid indices), each band's times its scale, through `weights` (in the preview's units).
  std::vector<Vec3d> noise_tristimulus(const std::vector<int>& edges, const std::array<std::vector<double>, 3>& weights,
                                       const std::vector<double>& band_scale) const;
  // Mean and 95th percentile over the preview's pixels of ΔE00 against the exact colours, `noise` (per preview
  // pixel) added to the tested colours.
  // `per_pixel` receives each of pixels_' ΔE00.
  std::pair<double, double> score(const Templates& templates, int max_bounces,
                                  const std::vector<Vec3d>* noise = nullptr, std::vector<double>* by_id = nullptr,
                                  std::vector<double>* per_pixel = nullptr) const;
  std::optional<BandReconstruction> fit_reconstruction(const TemplateSpectra& banded, const std::vector<int>& edges,
                                                       int max_bounces) const;
  // Appends to `t` (tristimulus values, not yet at unit luminance) the templates of the textured surfaces' colours, in
  // a basis: `spectra` the surfaces' template spectra, `in_basis` a spectrum's values in it, `weight` its observer
  // weights. A colour sees its surface's irradiance: its diffuse spectrum is the surface's times R_c / R_o (0 where
  // R_o is); its emission and glossy lobe are the surface's.
  void add_colour_templates(Templates& t, const TemplateSpectra& spectra,
                            const std::function<std::vector<double>(const Sampled&)>& in_basis,
                            const std::array<std::vector<double>, 3>& weight) const;

  Grid grid_;
  int kmax_ = 0;
  Observer obs_;
  Sampled light_, albedo_, environment_;
  bool has_environment_ = false;
  std::vector<Surface> surfaces_;  // by object id (0: background)
  Transfer transfer_;
  Templates exact_;  // [id][k][lobe], scaled to Y = 1
  std::vector<std::vector<std::array<double, 2>>> exact_y_;
  TemplateSpectra exact_spectra_;                         // [id][k][lobe], 1 nm samples
  std::vector<std::vector<std::array<double, 2>>> share_;  // [id][k][lobe]: Σ over pixels of the luminance share
  bool reconstruct_ = false;
  std::vector<Pixel> pixels_;
  // What each pixel is scored as (per pixel; lab_exact_ their exact colours): itself, or on a textured surface one of
  // the texture's colours (Surface::colours; set_white), with the pixel's luminance of each (bounce order, lobe)
  // times the colour's over the surface's.
  struct Sample {
    std::size_t id;  // template id: a surface's, or one of its colours' (after the surfaces)
    std::vector<std::array<double, 2>> y;  // [k][lobe]
  };
  std::vector<Sample> samples_;
  // Template ids of the textured surfaces' colours (after the surfaces'): per surface id, its colours' (empty: one
  // spectrum).
  std::vector<std::vector<std::size_t>> colour_ids_;
  bool has_colours() const { return exact_.size() > surfaces_.size(); }
  std::vector<Vec3d> lab_exact_;
  // A realisation of one preview render's noise in the totals, [pixel][preview band] ((a − b)/√2 of two renders
  // with different seeds), and the preview's band edges.
  std::vector<float> noise_;
  std::vector<double> preview_edges_nm_;
  double preview_units_ = 1;  // the preview's weights over the observer's integrals
  Vec3d white_{};
  std::vector<int> grid_edges_;
  double hit_fraction_ = 0, mean_albedo_ = 0, preview_noise_ = 0;
  std::vector<double> preview_noise_by_id_;
  std::vector<double> preview_pixel_noise_;  // each preview pixel's ΔE00 between its two renders, over √2
  std::vector<std::size_t> pixels_by_id_;
  int preview_samples_ = 0;
  std::size_t pixel_count_ = 0;
  std::array<int, 2> preview_size_{0, 0};  // width, height
};

Model::Model(const Scene& scene, const PlanOptions& options, std::vector<std::string>& notes, int reference_bounces) {
  const sensor::CameraCurves curves = set_grid(scene, options, notes, reference_bounces);
  const std::vector<TriangleMesh> meshes = scene_meshes(scene);
  set_surfaces(scene, meshes, options, notes, reference_bounces);
  transfer_ = transfer_factors(scene, meshes, kTransferRays);
  set_exact_templates();
  const Preview preview = render_preview(scene, options, curves);
  const auto first_light = static_cast<std::int32_t>(scene.objects.size()) + 1;
  const std::vector<bool> near_light = near_emitters(preview.image.object_ids, preview.image.width, preview.image.height,
                                                     [&](std::int32_t id) { return id >= first_light; });
  read_preview(preview, near_light);
  set_white(preview, near_light);
  measure_preview_noise(preview);
}

// The 1 nm grid over the scene's bands, the truth's depth (before the mean albedo extends it), the observer on the
// grid and the candidate band edges: the range's ends and the multiples of the edge step inside it.
sensor::CameraCurves Model::set_grid(const Scene& scene, const PlanOptions& options, std::vector<std::string>& notes,
                                     int reference_bounces) {
  const Bands& sb = scene.render.bands;
  grid_.lo = static_cast<int>(std::ceil(sb.min_wavelength() - 1e-9));
  grid_.hi = static_cast<int>(std::floor(sb.max_wavelength() + 1e-9));
  if (grid_.hi - grid_.lo < 2) throw InputError(fmt::format("{}: render.bands: range too narrow to plan", scene.source));
  kmax_ = reference_bounces > 0 ? reference_bounces : scene.render.max_bounces;

  sensor::CameraCurves curves = sensor::camera_curves(options.camera, {"r", "g", "b"}, "--camera");
  if (sb.min_wavelength() < curves.min_wavelength() - 1e-9 || sb.max_wavelength() > curves.max_wavelength() + 1e-9)
    notes.push_back(fmt::format("the camera {} has curves over {:g}-{:g} nm only: it sees nothing of the bands beyond",
                                curves.name, curves.min_wavelength(), curves.max_wavelength()));
  for (int c = 0; c < 3; ++c) obs_[c] = grid_.sample([&](double nm) { return curves.curves[c](nm); });

  const double step = options.edge_step_nm;
  grid_edges_.push_back(0);
  for (double nm = std::ceil((grid_.lo + 1e-9) / step) * step; nm < grid_.hi - 1e-9; nm += step)
    if (nm > grid_.lo + 1e-9) grid_edges_.push_back(static_cast<int>(std::lround(nm)) - grid_.lo);
  grid_edges_.push_back(grid_.hi - grid_.lo);
  return curves;
}

// The light, the surfaces (plan/radiosity.h), the mean albedo and, for a reference depth, how deep the truth goes.
void Model::set_surfaces(const Scene& scene, const std::vector<TriangleMesh>& meshes, const PlanOptions& options,
                         std::vector<std::string>& notes, int reference_bounces) {
  const PiecewiseLinearSpectrum light = scene_light_spectrum(scene);
  light_ = grid_.sample([&](double nm) { return light(nm); });
  SceneSurfaces s = scene_surfaces(scene, meshes, grid_, light_, options.reconstruction, notes);
  reconstruct_ = options.reconstruction && !s.textured;
  surfaces_ = std::move(s.surfaces);
  albedo_ = std::move(s.mean_albedo);
  environment_ = std::move(s.environment);
  has_environment_ = s.has_environment;
  const double ysum = std::accumulate(obs_[1].v.begin(), obs_[1].v.end(), 0.0);
  double y = 0;
  for (std::size_t i = 0; i < albedo_.v.size(); ++i) y += albedo_.v[i] * obs_[1].v[i];
  mean_albedo_ = ysum > 0 ? y / ysum : 0;
  if (reference_bounces > 0 && mean_albedo_ > 0 && mean_albedo_ < 1)
    kmax_ = std::clamp(static_cast<int>(std::ceil(std::log(kNegligibleShare) / std::log(mean_albedo_))), kmax_,
                       std::max(kmax_, kMaxReferenceBounces));
  else if (reference_bounces > 0 && mean_albedo_ >= 1)
    kmax_ = std::max(kmax_, kMaxReferenceBounces);
}

// Exact templates (1 nm samples), scaled so that their luminance (second channel) is 1.
void Model::set_exact_templates() {
  const std::size_t ids = surfaces_.size();
  Basis exact;
  for (int c = 0; c < 3; ++c) {
    exact.weight[c] = obs_[c].v;
    for (std::size_t i = 0; i < exact.weight[c].size(); ++i) exact.weight[c][i] *= trapezoid_weight(i, exact.weight[c].size());
  }
  const std::vector<double> zero(grid_.n(), 0.0);
  for (const Surface& s : surfaces_) {
    exact.emission.push_back(s.emission.v);
    exact.diffuse.push_back(s.diffuse.v);
    exact.glossy.push_back(s.glossy.v);
    exact.albedo.push_back(s.albedo.v.empty() ? zero : s.albedo.v);
  }
  exact.light = light_.v;
  exact.mean_albedo = albedo_.v;
  if (has_environment_) exact.environment = environment_.v;
  exact_ = bounce_templates(exact, transfer_, kmax_, &exact_spectra_);
  colour_ids_.assign(ids, {});
  std::size_t next = ids;
  for (std::size_t id = 0; id < ids; ++id)
    for (std::size_t c = 0; c < surfaces_[id].colours.size(); ++c) colour_ids_[id].push_back(next++);
  add_colour_templates(exact_, exact_spectra_, [](const Sampled& f) { return f.v; }, exact.weight);
  const std::size_t all = exact_.size();
  exact_y_.assign(all, std::vector<std::array<double, 2>>(static_cast<std::size_t>(kmax_) + 1, {0.0, 0.0}));
  for (std::size_t id = 0; id < all; ++id)
    for (int k = 0; k <= kmax_; ++k)
      for (int lobe = 0; lobe < 2; ++lobe) {
        Vec3d& x = exact_[id][k][lobe];
        exact_y_[id][k][lobe] = x[1];
        if (x[1] > 0) x = {x[0] / x[1], 1.0, x[2] / x[1]};
        else x = {0.0, 0.0, 0.0};
      }
}

void Model::add_colour_templates(Templates& t, const TemplateSpectra& spectra,
                                 const std::function<std::vector<double>(const Sampled&)>& in_basis,
                                 const std::array<std::vector<double>, 3>& weight) const {
  const std::size_t ids = surfaces_.size();
  for (std::size_t id = 0; id < ids; ++id) {
    if (colour_ids_[id].empty()) continue;
    const std::vector<double> base = in_basis(surfaces_[id].diffuse);
    for (const auto& [share, spectrum] : surfaces_[id].colours) {
      const std::vector<double> r = in_basis(spectrum);
      std::vector<std::array<Vec3d, 2>> x = t[id];
      for (std::size_t k = 1; k < x.size(); ++k) {
        const std::vector<double>& f = spectra[id][k][0];
        Vec3d v{};
        for (int c = 0; c < 3; ++c)
          for (std::size_t i = 0; i < f.size(); ++i)
            if (base[i] > 0) v[c] += f[i] * r[i] / base[i] * weight[c][i];
        x[k][0] = v;
      }
      t.push_back(std::move(x));
    }
  }
}

// The preview: the scene at options.preview_size pixels on its longer side, to the model's depth, every component.
Preview Model::render_preview(const Scene& scene, const PlanOptions& options, const sensor::CameraCurves& curves) const {
  Preview p{scene, {}, {}, {}};
  p.scene.render.max_bounces = kmax_;
  const int w = scene.camera.width, h = scene.camera.height;
  const int size = std::max(1, options.preview_size);
  Camera& camera = p.scene.camera;
  if (w >= h) {
    camera.width = std::min(w, size);
    camera.height = std::max(1, static_cast<int>(std::lround(static_cast<double>(h) * camera.width / w)));
  } else {
    camera.height = std::min(h, size);
    camera.width = std::max(1, static_cast<int>(std::lround(static_cast<double>(w) * camera.height / h)));
  }
  p.options.samples = options.preview_samples;
  p.options.mode = SpectralMode::Bands;
  p.options.components = rt::ComponentSelection::parse("all");
  p.options.threads = options.threads;
  p.options.progress = false;
  p.image = rt::render(p.scene, p.options);
  const auto q = sensor::photon_response(p.image.bands, curves, sensor::ResponseBasis::Energy, 1.0,
                                         PiecewiseLinearSpectrum::constant(1.0));
  for (int c = 0; c < 3; ++c) p.weights[c].assign(q[c].begin(), q[c].end());
  return p;
}

// Each lit pixel's object and luminance per (bounce order, lobe), from the preview's components; the share of
// each template in the image.
void Model::read_preview(const Preview& preview, const std::vector<bool>& near_light) {
  const rt::RenderedImage& img = preview.image;
  const std::size_t nb = img.bands.size(), N = preview.pixels(), ids = surfaces_.size();
  auto layer = [&](const std::string& name) -> const std::vector<float>* {
    for (std::size_t i = 0; i < img.components.size(); ++i)
      if (img.components[i] == name) return &img.layers[i + 1];
    return nullptr;
  };
  auto lum = [&](const std::vector<float>* l, std::size_t p) {
    if (!l) return 0.0;
    double s = 0;
    for (std::size_t b = 0; b < nb; ++b) s += preview.weights[1][b] * (*l)[p * nb + b];
    return s;
  };
  const auto *dd = layer("diffuse_direct"), *gd = layer("glossy_direct"), *di = layer("diffuse_indirect"),
             *gi = layer("glossy_indirect");
  pixel_count_ = N;
  preview_size_ = {preview.image.width, preview.image.height};
  std::size_t hits = 0;
  for (std::size_t p = 0; p < N; ++p) {
    Pixel px;
    px.index = p;
    px.id = img.object_ids[p];
    px.near_light = near_light[p];
    if (px.id < 0 || static_cast<std::size_t>(px.id) >= ids) px.id = 0;
    if (px.id != 0) ++hits;
    px.y.assign(static_cast<std::size_t>(kmax_) + 1, {0.0, 0.0});
    const double ydi = std::max(0.0, lum(di, p)), ygi = std::max(0.0, lum(gi, p));
    const double glossy_share = ydi + ygi > 0 ? ygi / (ydi + ygi) : 0.0;
    for (int k = 0; k <= kmax_; ++k) {
      const double yk = std::max(0.0, lum(layer(fmt::format("bounce.{}", k)), p));
      if (k == 0) px.y[0] = {yk, 0.0};
      else if (k == 1) px.y[1] = {std::max(0.0, lum(dd, p)), std::max(0.0, lum(gd, p))};
      else px.y[static_cast<std::size_t>(k)] = {yk * (1 - glossy_share), yk * glossy_share};
    }
    // A glossy lobe the surface does not have (edge pixels): count it as diffuse.
    const Surface& s = surfaces_[static_cast<std::size_t>(px.id)];
    for (int k = 1; k <= kmax_; ++k) {
      auto& y = px.y[static_cast<std::size_t>(k)];
      if (exact_y_[static_cast<std::size_t>(px.id)][k][1] <= 0) y = {y[0] + y[1], 0.0};
      if (exact_y_[static_cast<std::size_t>(px.id)][k][0] <= 0) y = {0.0, y[0] + y[1]};
    }
    if (exact_y_[static_cast<std::size_t>(px.id)][0][0] <= 0 && !s.emitter) px.y[0] = {0.0, 0.0};
    for (const auto& y : px.y) px.total += y[0] + y[1];
    if (px.total > 0) pixels_.push_back(std::move(px));
  }
  hit_fraction_ = N ? static_cast<double>(hits) / static_cast<double>(N) : 0;
  share_.assign(ids, std::vector<std::array<double, 2>>(static_cast<std::size_t>(kmax_) + 1, {0.0, 0.0}));
  for (const Pixel& px : pixels_)
    for (int k = 0; k <= kmax_; ++k)
      for (int lobe = 0; lobe < 2; ++lobe) share_[px.id][k][lobe] += px.y[k][lobe] / px.total;
}

// The exact colours of the preview's pixels and the white (core/render_delta_e.h: the scene's light at the level of
// the exact image, unlit pixels black, lights and their neighbours left out).
void Model::set_white(const Preview& preview, const std::vector<bool>& near_light) {
  samples_.clear();
  std::vector<std::size_t> seen(surfaces_.size(), 0);  // pixels of each surface so far
  for (const Pixel& px : pixels_) {
    const auto id = static_cast<std::size_t>(px.id);
    if (colour_ids_[id].empty()) {
      samples_.push_back({id, px.y});
    } else {
      // The n-th pixel of a textured surface shows the colour whose interval of the cumulative shares holds
      // frac(½ + n/φ): a low-discrepancy walk, so that every colour gets its share of the surface's pixels, spread
      // over them, at the cost of one sample a pixel.
      const double u = std::fmod(0.5 + static_cast<double>(seen[id]++) * 0.6180339887498949, 1.0);
      const auto& colours = surfaces_[id].colours;
      std::size_t c = 0;
      for (double sum = colours[0].first; c + 1 < colours.size() && sum <= u; sum += colours[++c].first) {
      }
      const std::size_t cid = colour_ids_[id][c];
      Sample sample{cid, px.y};
      for (int k = 0; k <= kmax_; ++k)
        for (int lobe = 0; lobe < 2; ++lobe) {
          const double base = exact_y_[id][k][lobe];
          sample.y[k][lobe] *= base > 0 ? exact_y_[cid][k][lobe] / base : 0.0;
        }
      samples_.push_back(std::move(sample));
    }
  }
  std::vector<Vec3d> xyz(samples_.size());
  std::vector<Vec3d> level(preview.pixels(), Vec3d{});
  for (std::size_t p = 0; p < pixels_.size(); ++p) {
    const Sample& s = samples_[p];
    Vec3d x{};
    for (int k = 0; k <= kmax_; ++k)
      for (int lobe = 0; lobe < 2; ++lobe)
        for (int c = 0; c < 3; ++c) x[c] += s.y[k][lobe] * exact_[s.id][k][lobe][c];
    xyz[p] = x;
    level[pixels_[p].index] = x;
  }
  WhitePolicy policy;
  policy.light = tristimulus(light_.v, obs_);
  white_ = white_point(level, near_light, policy);
  lab_exact_.resize(samples_.size());
  for (std::size_t p = 0; p < samples_.size(); ++p) lab_exact_[p] = xyz_to_lab(xyz[p], white_);
}

// Noise: a second preview with the next seed. The two differ by noise alone, of twice the variance of either;
// while noise is small against the colour, ΔE00 grows in proportion to its standard deviation, so one render's
// noise is the mean ΔE00 between the two / √2 and falls as 1/√(paths per pixel). (a − b)/√2 is kept as a
// realisation of one render's noise, for the share of each band in it.
void Model::measure_preview_noise(const Preview& preview) {
  rt::RenderOptions options = preview.options;
  options.components = rt::ComponentSelection::parse("none");
  options.seed = preview.scene.render.seed + 1;
  const rt::RenderedImage second = rt::render(preview.scene, options);
  const std::size_t N = preview.pixels();
  std::vector<Vec3d> a(N), b(N);
  for (std::size_t p = 0; p < N; ++p) {
    a[p] = preview.colour(preview.image.layers[0], p);
    b[p] = preview.colour(second.layers[0], p);
  }
  preview_noise_ = N ? delta_e_between(a, b, white_).mean / std::sqrt(2.0) : 0.0;
  preview_pixel_noise_.resize(N);
  for (std::size_t p = 0; p < N; ++p)
    preview_pixel_noise_[p] = delta_e_2000(xyz_to_lab(a[p], white_), xyz_to_lab(b[p], white_)) / std::sqrt(2.0);
  preview_noise_by_id_.assign(surfaces_.size(), 0.0);
  pixels_by_id_.assign(surfaces_.size(), 0);
  for (const Pixel& px : pixels_) {
    preview_noise_by_id_[px.id] += delta_e_2000(xyz_to_lab(a[px.index], white_), xyz_to_lab(b[px.index], white_));
    ++pixels_by_id_[px.id];
  }
  for (std::size_t id = 0; id < surfaces_.size(); ++id)
    if (pixels_by_id_[id]) preview_noise_by_id_[id] /= std::sqrt(2.0) * static_cast<double>(pixels_by_id_[id]);
  preview_samples_ = preview.image.samples;
  const std::vector<float>&la = preview.image.layers[0], &lb = second.layers[0];
  noise_.resize(la.size());
  for (std::size_t i = 0; i < la.size(); ++i) noise_[i] = static_cast<float>((double{la[i]} - lb[i]) / std::sqrt(2.0));
  preview_edges_nm_ = preview.image.bands.edges();
  // The preview's weights are the observer's integrals over its bands times a constant (the camera model's units,
  // sensor_sim/spectral_response.h); the preview's bands cover the grid.
  const double observer = Grid::integral(obs_[1], 0, grid_.hi - grid_.lo);
  const double preview_sum = std::accumulate(preview.weights[1].begin(), preview.weights[1].end(), 0.0);
  preview_units_ = observer > 0 ? preview_sum / observer : 1.0;
}

std::vector<Vec3d> Model::noise_tristimulus(const std::vector<int>& edges,
                                            const std::array<std::vector<double>, 3>& weights,
                                            const std::vector<double>& band_scale) const {
  const std::size_t nbp = preview_edges_nm_.size() - 1, nb = edges.size() - 1;
  const std::vector<float>& noise = noise_;
  const std::size_t N = nbp ? noise.size() / nbp : 0;
  // A band's value is the mean over its range: the preview bands' values weighted by their overlap with it.
  std::vector<std::vector<double>> overlap(nb, std::vector<double>(nbp, 0.0));
  for (std::size_t b = 0; b < nb; ++b) {
    const double lo = grid_.lo + edges[b], hi = grid_.lo + edges[b + 1];
    for (std::size_t j = 0; j < nbp; ++j) {
      const double o = std::min(hi, preview_edges_nm_[j + 1]) - std::max(lo, preview_edges_nm_[j]);
      if (o > 0) overlap[b][j] = o / (hi - lo) * band_scale[b];
    }
  }
  std::vector<Vec3d> out(N, Vec3d{});
  for (std::size_t p = 0; p < N; ++p)
    for (std::size_t b = 0; b < nb; ++b) {
      double v = 0;
      for (std::size_t j = 0; j < nbp; ++j) v += overlap[b][j] * noise[p * nbp + j];
      for (int c = 0; c < 3; ++c) out[p][c] += weights[c][b] * v;
    }
  return out;
}

std::pair<double, double> Model::score(const Templates& templates, int max_bounces,
                                        const std::vector<Vec3d>* noise, std::vector<double>* by_id,
                                        std::vector<double>* per_pixel) const {
  std::vector<double> de(pixels_.size());
  for (std::size_t p = 0; p < pixels_.size(); ++p) {
    const Sample& s = samples_[p];
    Vec3d x{};
    for (int k = 0; k <= std::min(max_bounces, kmax_); ++k)
      for (int lobe = 0; lobe < 2; ++lobe)
        for (int c = 0; c < 3; ++c) x[c] += s.y[k][lobe] * templates[s.id][k][lobe][c];
    if (noise)
      for (int c = 0; c < 3; ++c) x[c] += (*noise)[pixels_[p].index][c];
    de[p] = delta_e_2000(lab_exact_[p], xyz_to_lab(x, white_));
  }
  if (per_pixel) *per_pixel = de;
  if (by_id) {
    by_id->assign(surfaces_.size(), 0.0);
    std::vector<std::size_t> count(surfaces_.size(), 0);
    for (std::size_t p = 0; p < pixels_.size(); ++p) (*by_id)[pixels_[p].id] += de[p], ++count[pixels_[p].id];
    for (std::size_t id = 0; id < count.size(); ++id)
      if (count[id]) (*by_id)[id] /= static_cast<double>(count[id]);
  }
  const double sum = std::accumulate(de.begin(), de.end(), 0.0);
  de.resize(pixel_count_, 0.0);  // unlit pixels: no error
  return {pixel_count_ ? sum / static_cast<double>(pixel_count_) : 0.0, quantile(de, 0.95)};
}

std::pair<double, double> Model::evaluate_exact(int max_bounces) const { return score(exact_, max_bounces); }

std::vector<double> Model::evaluate_by_id(const std::vector<int>& edges, int max_bounces) const {
  std::vector<double> by_id;
  score(banded_templates(edges, max_bounces, reconstruct_, nullptr).templates, std::min(max_bounces, kmax_), nullptr,
        &by_id);
  return by_id;
}

// The reconstruction that best turns the band values of the model's templates into their exact spectra: 1 nm
// fine bands over the model's grid, the matrix R minimising Σ_t w_t·|a_t − R·b_t|² over the templates t up to the
// bounce limit (b_t their band values and a_t their exact 1 nm averages, both at unit luminance; w_t the
// template's share of the preview's pixels), pulled towards the step function S (each fine band takes its band's
// value) by a ridge λ of 10⁻³ of B·W·Bᵀ's mean diagonal: R = (A·W·Bᵀ + λS)(B·W·Bᵀ + λI)⁻¹. The ridge decides what
// the templates leave open (bands no template tells apart, a band of a narrow-band light) and keeps R from the
// large alternating entries that would turn a few per cent of noise in the band values into a visible colour
// error; on the paper box it raises the predicted error of 4 bands from 0.44 to 0.47, and under a narrow-band LED
// it takes the largest entry from 10 to 1.7. For a free matrix this minimiser is the same whatever weights the
// wavelengths get, so the one fit serves every observer and camera. Entries are rounded to float, as the bands
// hold them (Bands::with_reconstruction), so that the prediction uses the matrix the renders carry. None when no
// template reaches a pixel of the preview (nothing to fit to).
std::optional<BandReconstruction> Model::fit_reconstruction(const TemplateSpectra& banded, const std::vector<int>& edges,
                                                              int max_bounces) const {
  const std::size_t nb = banded.front().front()[0].size(), fine = grid_.n() - 1;
  Eigen::MatrixXd g = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(nb), static_cast<Eigen::Index>(nb));
  Eigen::MatrixXd h = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(fine), static_cast<Eigen::Index>(nb));
  Eigen::VectorXd b(static_cast<Eigen::Index>(nb)), a(static_cast<Eigen::Index>(fine));
  for (std::size_t id = 0; id < banded.size(); ++id)
    for (int k = 0; k <= std::min(max_bounces, kmax_); ++k)
      for (int lobe = 0; lobe < 2; ++lobe) {
        const double y = exact_y_[id][k][lobe], w = share_[id][k][lobe];
        if (!(y > 0) || !(w > 0)) continue;
        const std::vector<double>& s = exact_spectra_[id][k][lobe];
        for (std::size_t i = 0; i < nb; ++i) b[static_cast<Eigen::Index>(i)] = banded[id][k][lobe][i] / y;
        for (std::size_t j = 0; j < fine; ++j) a[static_cast<Eigen::Index>(j)] = 0.5 * (s[j] + s[j + 1]) / y;
        g.noalias() += w * b * b.transpose();
        h.noalias() += w * a * b.transpose();
      }
  if (!(g.trace() > 0)) return std::nullopt;
  const double lambda = 1e-3 * g.trace() / static_cast<double>(nb);
  g.diagonal().array() += lambda;
  for (std::size_t i = 0; i < nb; ++i)
    for (int j = edges[i]; j < edges[i + 1]; ++j) h(j, static_cast<Eigen::Index>(i)) += lambda;
  const Eigen::LDLT<Eigen::MatrixXd> solver(g);
  Eigen::MatrixXd r = solver.solve(h.transpose()).transpose();  // fine × nb (g is symmetric)
  // The lights (and a uniform environment) as they are: every emitter's own spectrum is reconstructed exactly, so
  // that a light seen directly, and the white a camera balances to, keep their colour however few pixels show
  // them. The least-squares fit under the constraints R·c_l = d_l is R₀ + (D − R₀C)(CᵀG⁻¹C)⁻¹CᵀG⁻¹; with as many
  // emitter spectra as bands or more, the constraints would fix R alone, and the fit stays unconstrained.
  std::vector<std::size_t> emitters;
  for (std::size_t id = 0; id < surfaces_.size(); ++id)
    if ((surfaces_[id].emitter || (id == 0 && has_environment_)) && exact_y_[id][0][0] > 0) emitters.push_back(id);
  if (!emitters.empty() && emitters.size() < nb) {
    const auto count = static_cast<Eigen::Index>(emitters.size());
    Eigen::MatrixXd c(static_cast<Eigen::Index>(nb), count), d(static_cast<Eigen::Index>(fine), count);
    for (Eigen::Index l = 0; l < count; ++l) {
      const std::size_t id = emitters[static_cast<std::size_t>(l)];
      const double y = exact_y_[id][0][0];
      const std::vector<double>& sp = exact_spectra_[id][0][0];
      for (std::size_t i = 0; i < nb; ++i) c(static_cast<Eigen::Index>(i), l) = banded[id][0][0][i] / y;
      for (std::size_t j = 0; j < fine; ++j) d(static_cast<Eigen::Index>(j), l) = 0.5 * (sp[j] + sp[j + 1]) / y;
    }
    const Eigen::MatrixXd gc = solver.solve(c);  // G⁻¹C
    Eigen::MatrixXd m = c.transpose() * gc;       // CᵀG⁻¹C
    m.diagonal().array() += 1e-12 * m.trace() / static_cast<double>(count);
    r += (d - r * c) * m.ldlt().solve(gc.transpose());
  }
  BandReconstruction out;
  out.lo_nm = grid_.lo;
  out.step_nm = 1;
  out.fine = fine;
  out.matrix.resize(fine * nb);
  for (std::size_t j = 0; j < fine; ++j)
    for (std::size_t i = 0; i < nb; ++i)
      out.matrix[j * nb + i] = static_cast<float>(r(static_cast<Eigen::Index>(j), static_cast<Eigen::Index>(i)));
  return out;
}

std::pair<double, double> Model::evaluate(const std::vector<int>& edges, int max_bounces, bool reconstruct,
                                          BandReconstruction* fitted) const {
  return score(banded_templates(edges, max_bounces, reconstruct, fitted).templates, std::min(max_bounces, kmax_));
}

double Model::band_noise(const std::vector<int>& edges, int max_bounces, const std::vector<bool>& carry) const {
  const BandedTemplates b = banded_templates(edges, max_bounces, reconstruct_, nullptr);
  std::array<std::vector<double>, 3> weights = b.weights;  // in the preview's units, as the colours are
  for (auto& w : weights)
    for (double& x : w) x *= preview_units_;
  std::vector<double> scale(carry.size());
  for (std::size_t i = 0; i < carry.size(); ++i) scale[i] = carry[i] ? 1.0 : 0.0;
  const std::vector<Vec3d> noise = noise_tristimulus(edges, weights, scale);
  return score(exact_, kmax_, &noise).first;
}

Model::PixelErrors Model::pixel_errors(const std::vector<int>& edges, int max_bounces,
                                      const std::vector<double>& cycles_noise) const {
  PixelErrors e;
  score(banded_templates(edges, max_bounces, reconstruct_, nullptr).templates, std::min(max_bounces, kmax_), nullptr,
        nullptr, &e.bands);
  // Each pair's difference per pixel is one draw of the noise there, as a render's error is one draw.
  const std::vector<double>& tracer = preview_pixel_noise_;
  const std::vector<double>& cycles = cycles_noise.size() == tracer.size() ? cycles_noise : tracer;
  e.cycles.resize(pixels_.size());
  e.tracer.resize(pixels_.size());
  for (std::size_t p = 0; p < pixels_.size(); ++p)
    e.cycles[p] = cycles[pixels_[p].index], e.tracer[p] = tracer[pixels_[p].index];
  e.pixel_count = pixel_count_;
  return e;
}

Model::BandedTemplates Model::banded_templates(const std::vector<int>& edges, int max_bounces, bool reconstruct,
                                               BandReconstruction* fitted) const {
  const std::size_t nb = edges.size() - 1;
  const int K = std::min(max_bounces, kmax_);
  auto averages = [&](const Sampled& f) {
    std::vector<double> v(nb);
    for (std::size_t b = 0; b < nb; ++b) v[b] = Grid::average(f, edges[b], edges[b + 1]);
    return v;
  };
  Basis banded;
  for (int c = 0; c < 3; ++c) {
    banded.weight[c].resize(nb);
    for (std::size_t b = 0; b < nb; ++b) banded.weight[c][b] = Grid::integral(obs_[c], edges[b], edges[b + 1]);
  }
  for (const Surface& s : surfaces_) {
    banded.emission.push_back(averages(s.emission));
    banded.diffuse.push_back(averages(s.diffuse));
    banded.glossy.push_back(averages(s.glossy));
    banded.albedo.push_back(s.albedo.v.empty() ? std::vector<double>(nb, 0.0) : averages(s.albedo));
  }
  banded.light = averages(light_);
  banded.mean_albedo = averages(albedo_);
  if (has_environment_) banded.environment = averages(environment_);
  TemplateSpectra spectra;
  auto t = bounce_templates(banded, transfer_, K, reconstruct || has_colours() ? &spectra : nullptr);
  const std::optional<BandReconstruction> fit = reconstruct ? fit_reconstruction(spectra, edges, K) : std::nullopt;
  if (fit) {
    // The observer's weights of the reconstructed spectrum (band_weights with 1 nm fine bands), and the templates
    // through them.
    const BandReconstruction& r = *fit;
    for (int c = 0; c < 3; ++c) {
      std::fill(banded.weight[c].begin(), banded.weight[c].end(), 0.0);
      for (std::size_t j = 0; j < r.fine; ++j) {
        const double f = Grid::integral(obs_[c], static_cast<int>(j), static_cast<int>(j) + 1);
        for (std::size_t i = 0; i < nb; ++i) banded.weight[c][i] += r.matrix[j * nb + i] * f;
      }
    }
    for (std::size_t id = 0; id < t.size(); ++id)
      for (int k = 0; k <= K; ++k)
        for (int lobe = 0; lobe < 2; ++lobe)
          for (int c = 0; c < 3; ++c) {
            double x = 0;
            for (std::size_t i = 0; i < nb; ++i) x += spectra[id][k][lobe][i] * banded.weight[c][i];
            t[id][k][lobe][c] = x;
          }
    if (fitted) *fitted = r;  // else it stays empty (fine = 0): read as a step function
  }
  add_colour_templates(t, spectra, averages, banded.weight);
  for (std::size_t id = 0; id < t.size(); ++id)
    for (int k = 0; k <= K; ++k)
      for (int lobe = 0; lobe < 2; ++lobe) {
        const double y = exact_y_[id][k][lobe];
        Vec3d& x = t[id][k][lobe];
        if (y > 0) x = {x[0] / y, x[1] / y, x[2] / y};
        else x = {0.0, 0.0, 0.0};
      }
  return {std::move(t), banded.weight};
}

// Coordinate descent over the candidate positions of each inner edge (indices into grid_edges): each edge in
// turn moves to the best position between its neighbours that is a multiple of `stride` candidates away and at
// most `window` candidates away, until a sweep changes nothing.
std::pair<std::vector<std::size_t>, double> descend(const Model& model, std::vector<std::size_t> idx, int bounces,
                                                    std::size_t stride, std::size_t window) {
  const auto& cand = model.grid_edges();
  auto edges_of = [&](const std::vector<std::size_t>& ix) {
    std::vector<int> e(ix.size());
    for (std::size_t i = 0; i < ix.size(); ++i) e[i] = cand[ix[i]];
    return e;
  };
  double best = model.evaluate(edges_of(idx), bounces).first;
  for (int sweep = 0; sweep < 12; ++sweep) {
    bool improved = false;
    for (std::size_t i = 1; i + 1 < idx.size(); ++i) {
      const std::size_t start = idx[i];
      std::size_t keep = start;
      const std::size_t lo = std::max(idx[i - 1] + 1, start > window ? start - window : 0);
      const std::size_t hi = std::min(idx[i + 1] - 1, start + window);
      for (std::size_t c = start - ((start - lo) / stride) * stride; c <= hi; c += stride) {
        if (c == start) continue;
        idx[i] = c;
        const double v = model.evaluate(edges_of(idx), bounces).first;
        if (v < best - 1e-12) {
          best = v;
          keep = c;
          improved = true;
        }
      }
      idx[i] = keep;
    }
    if (!improved) break;
  }
  return {idx, best};
}

// Coarse to fine: strides of 10, 5, 2 and 1 nm (those that are whole multiples of the edge step), the first over
// the whole range, each later one within twice the previous stride.
std::pair<std::vector<std::size_t>, double> fit(const Model& model, const std::vector<std::size_t>& start, int bounces,
                                                double edge_step) {
  std::vector<std::size_t> strides;
  for (double nm : {10.0, 5.0, 2.0}) {
    const double r = nm / edge_step;
    if (r > 1 && std::abs(r - std::round(r)) < 1e-9) strides.push_back(static_cast<std::size_t>(std::lround(r)));
  }
  strides.push_back(1);
  std::pair<std::vector<std::size_t>, double> out{start, 0.0};
  std::size_t window = std::numeric_limits<std::size_t>::max() / 4;
  for (std::size_t stride : strides) {
    out = descend(model, out.first, bounces, stride, window);
    window = 2 * stride;
  }
  return out;
}

// Splits the widest bands (in candidate steps) until there are `bands` bands.
std::vector<std::size_t> split_widest(std::vector<std::size_t> idx, std::size_t bands) {
  while (idx.size() - 1 < bands) {
    std::size_t widest = 0;
    for (std::size_t b = 1; b + 1 < idx.size(); ++b)
      if (idx[b + 1] - idx[b] > idx[widest + 1] - idx[widest]) widest = b;
    if (idx[widest + 1] - idx[widest] < 2) break;
    idx.insert(idx.begin() + static_cast<std::ptrdiff_t>(widest) + 1, (idx[widest] + idx[widest + 1]) / 2);
  }
  return idx;
}

// Monte Carlo noise: the preview's, as mean ΔE00, falls as 1/√(paths per pixel).
double noise_at(const Model& model, int samples) {
  return model.preview_noise() * std::sqrt(static_cast<double>(model.preview_samples()) / std::max(1, samples));
}
// The paths per pixel at which the noise alone is predicted at the target.
int samples_for(const Model& model, double target) {
  return std::max(1, static_cast<int>(std::ceil(model.preview_samples() * std::pow(model.preview_noise() / target, 2))));
}

// Cycles' samples per band group for the bands `edges` (grid indices) at the bounce limit K, whose bands and
// bounces alone are predicted at `bands_error`. Cycles' noise is `ratio` times the tracer's at equal samples, and the
// tracer's falls as 1/√samples from its noise at one sample, at_one: measured beside the pilots where they are given
// (PlanOptions::cycles_pilot_tracer_noise_at_one), else the preview's (noise_at). How it is shared between the groups is a G × G matrix
// s (summing to 1): s_gg a group's own part, s_gh (g ≠ h) the part of two groups' correlated noise (Cycles traces
// the same paths for every group with the same seed, so their noise is correlated over the samples they share). With
// N_g samples a group the noise is ratio · at_one · √(Σ_gh s_gh / max(N_g, N_h)) (two groups share the samples of
// the fewer: their covariance falls with the more), and it adds to the bands' error as the square root of the sum of
// squares. Measured on two Cycles pilots (measure_cycles_noise) s has all its terms; else plan's model gives the
// diagonal alone, each group's part in the preview's noise (Model::band_noise). On the paper box under D65 the
// pilots measure the two groups' own parts at 0.80 and 0.44 of the whole and their pair term at −0.12 (twice:
// noise common to every band moves lightness more than hue), which favours an even split (docs/plan.md). The samples are the
// fewest in all for the target: a search over the groups' proportions (each a quarter of the most or more: the
// plan's observer is not the only camera its render will meet), the scale then set by the budget, and no group under
// `min_samples` (those Cycles' noise was measured at: below them it is not the measured ratio's). Empty when the
// bands and bounces alone miss the target.
struct CyclesNoise {
  std::size_t groups = 0;
  std::vector<double> share;  // s, G × G row by row
  bool measured = false;      // from Cycles' pilots, else from plan's model (diagonal)
  double ratio = 1, at_one = 0;  // Cycles over the tracer; the tracer's noise at 1 sample
  // Σ_gh s_gh / max(n_g, n_h): the noise's variance at samples n in units of (ratio · at_one)².
  template <typename T>
  double variance(const std::vector<T>& n) const {
    double v = 0;
    for (std::size_t g = 0; g < groups; ++g)
      for (std::size_t h = 0; h < groups; ++h)
        v += share[g * groups + h] / static_cast<double>(std::max(n[g], n[h]));
    return v;
  }
  double at(const std::vector<int>& samples) const { return ratio * at_one * std::sqrt(std::max(0.0, variance(samples))); }
};
CyclesNoise cycles_noise(const Model& model, const std::vector<int>& edges, int max_bounces, double ratio,
                         const PlanOptions& options) {
  const std::size_t nb = edges.size() - 1, groups = (nb + 2) / 3;
  CyclesNoise n;
  n.groups = groups;
  n.ratio = ratio;
  n.at_one = options.cycles_pilot_tracer_noise_at_one > 0 ? options.cycles_pilot_tracer_noise_at_one : noise_at(model, 1);
  // Shares measured on Cycles' pilots of these very bands.
  bool measured = options.cycles_group_shares.size() == groups * groups &&
                  options.cycles_group_shares_edges_nm.size() == nb + 1;
  for (std::size_t i = 0; measured && i <= nb; ++i)
    measured = std::abs(options.cycles_group_shares_edges_nm[i] - (model.lo() + edges[i])) < 1e-6;
  if (measured) {
    n.share = options.cycles_group_shares;
    n.measured = true;
    return n;
  }
  n.share.assign(groups * groups, 0.0);
  double sum = 0;
  const std::vector<std::vector<std::size_t>> members = cycles_render_groups(nb);
  for (std::size_t g = 0; g < groups; ++g) {
    std::vector<bool> carry(nb, false);
    for (std::size_t b : members[g]) carry[b] = true;
    sum += n.share[g * groups + g] = std::pow(model.band_noise(edges, max_bounces, carry), 2);
  }
  for (std::size_t g = 0; g < groups; ++g)
    n.share[g * groups + g] = sum > 0 ? n.share[g * groups + g] / sum : 1.0 / static_cast<double>(groups);
  return n;
}
std::vector<int> cycles_samples_for(const CyclesNoise& noise, double bands_error, double target, int min_samples) {
  if (!(bands_error < target)) return {};
  const double budget = std::sqrt(target * target - bands_error * bands_error);
  // Proportions w (N_g = k·w_g): k = (ratio · at_one / budget)² · variance(w) meets the budget, at a cost of k·Σw.
  auto cost = [&](const std::vector<double>& w) {
    return noise.variance(w) * std::accumulate(w.begin(), w.end(), 0.0);
  };
  std::vector<double> w(noise.groups, 1.0);
  double best = cost(w);
  for (double step : {1.25, 1.1, 1.03, 1.01}) {
    for (bool improved = true; improved;) {
      improved = false;
      for (std::size_t g = 0; g < w.size(); ++g)
        for (double f : {step, 1 / step}) {
          std::vector<double> t = w;
          t[g] *= f;
          const double top = *std::max_element(t.begin(), t.end());
          if (*std::min_element(t.begin(), t.end()) < 0.25 * top - 1e-12) continue;
          if (const double c = cost(t); c < best - 1e-12) {
            best = c;
            w = t;
            improved = true;
          }
        }
    }
  }
  const double k = std::pow(noise.ratio * noise.at_one / budget, 2) * noise.variance(w);
  std::vector<int> samples(w.size());
  for (std::size_t g = 0; g < w.size(); ++g)
    samples[g] = std::max(min_samples, static_cast<int>(std::ceil(k * w[g] - 1e-9)));
  return samples;
}

// A plan's bands' errors per pixel and where the noise is (Model::pixel_errors): Cycles' where the pilots have it
// (PlanOptions::cycles_pixel_noise, where they are of the preview's size), else where the preview has it.
Model::PixelErrors pixel_errors_of(const Model& model, const std::vector<int>& edges, int max_bounces,
                                   const PlanOptions& options) {
  const bool pilots = std::array{options.cycles_pixel_noise_width, options.cycles_pixel_noise_height} ==
                          model.preview_size() &&
                      options.cycles_pixel_noise.size() == static_cast<std::size_t>(options.cycles_pixel_noise_width) *
                                                               static_cast<std::size_t>(options.cycles_pixel_noise_height);
  return model.pixel_errors(edges, max_bounces, pilots ? options.cycles_pixel_noise : std::vector<double>{});
}

// A tracer reference's noise at `paths` per pixel: the tracer's at one path over √paths.
double reference_noise(const CyclesNoise& noise, int paths) {
  return paths > 0 ? noise.at_one / std::sqrt(static_cast<double>(paths)) : 0.0;
}

// `samples` (cycles_samples_for's, from the quadrature law) raised by one factor for every group until the mean
// ΔE00 of bands and noise added pixel by pixel, with a reference's noise of `reference` mean ΔE00, is at most the
// target: the fewest such, to a sample.
std::vector<int> raised_for_joint(const Model::PixelErrors& errors, const CyclesNoise& noise, std::vector<int> samples,
                                  double target, double reference) {
  auto joint = [&](const std::vector<int>& n) { return errors.mean(noise.at(n), reference); };
  if (samples.empty() || joint(samples) <= target) return samples;
  auto times = [&](double f) {
    std::vector<int> n(samples);
    for (int& x : n) x = static_cast<int>(std::ceil(x * f - 1e-9));
    return n;
  };
  double lo = 1, hi = 2;
  while (joint(times(hi)) > target) {
    lo = hi, hi *= 2;
    if (hi > 1 << 16) return {};  // the bands' error alone is within the target, but not by a margin noise leaves
  }
  const int most = *std::max_element(samples.begin(), samples.end());
  while ((hi - lo) * most > 1) {
    const double mid = 0.5 * (lo + hi);
    (joint(times(mid)) > target ? lo : hi) = mid;
  }
  return times(hi);
}

// The luminance fraction that arrives after more than k events, k = 0 .. the model's depth − 1, over the preview;
// with `surfaces_only`, over the pixels not on or next to a light (where the light's own emission does not count).
std::vector<double> energy_after(const Model& model, bool surfaces_only = false) {
  const int kmax = model.depth();
  std::vector<double> per_k(static_cast<std::size_t>(kmax) + 1, 0.0);
  for (const Pixel& px : model.pixels())
    if (!(surfaces_only && px.near_light))
      for (int k = 0; k <= kmax; ++k) per_k[k] += px.y[k][0] + px.y[k][1];
  const double total = std::accumulate(per_k.begin(), per_k.end(), 0.0);
  std::vector<double> out;
  for (int k = 0; k < kmax; ++k) {
    double left = 0;
    for (int j = k + 1; j <= kmax; ++j) left += per_k[j];
    out.push_back(total > 0 ? left / total : 0.0);
  }
  return out;
}

// The fewest bounces whose truncation alone costs at most a quarter of the target (the rest is the bands').
int bounces_for(const Model& model, double target) {
  const int kmax = model.depth();
  for (int k = 1; k <= kmax; ++k)
    if (model.evaluate_exact(k).first <= 0.25 * target) return k;
  return kmax;
}

// Each surface seen by at least kObjectPixels lit pixels of the preview (fewer hold too little of its noise to
// judge): its bands' and bounces' error (its pixels' mean ΔE00), and its noise as its share of the image's (its
// pixels' noise in the preview over the image's, times its own Cycles-to-tracer ratio over the image's where the
// pilots measured it) at the planned samples, in quadrature. Where one is predicted
// above the object limit, every group's samples grow by the same factor until none is (the noise falls as
// 1/√samples); a surface whose bands and bounces alone exceed it is said in a note.
constexpr std::size_t kObjectPixels = 16;
void limit_objects(Plan& plan, const Scene& scene, const Model& model, const std::vector<int>& edges,
                   const CyclesNoise& noise, const PlanOptions& options) {
  const double limit = options.object_target_de00 > 0 ? options.object_target_de00 : 2 * options.target_de00;
  plan.object_target_de00 = limit;
  const std::vector<double> bands = model.evaluate_by_id(edges, plan.max_bounces);
  const std::vector<double>& noise_by_id = model.preview_noise_by_id();
  auto name = [&](std::size_t id) {
    return id <= scene.objects.size() ? scene.objects[id - 1].name : scene.lights[id - scene.objects.size() - 1].name;
  };
  const double image_noise = model.preview_noise();
  // Its own Cycles-to-tracer noise ratio over the image's, where the pilots measured it above 1: it only raises an
  // object's prediction. Measured on a few tens of the pilots' pixels it is uncertain, and the limit is one-sided:
  // taken below 1 too, it left the paper box's ceiling at 2.26 where the image's ratio held it to 1.97.
  auto cycles_ratio_of = [&](std::size_t id) {
    const auto measured = options.cycles_object_noise_ratio.find(static_cast<std::int32_t>(id));
    return measured != options.cycles_object_noise_ratio.end() ? std::max(1.0, measured->second) : 1.0;
  };
  double factor = 1;  // on the samples
  std::vector<std::pair<std::size_t, double>> judged;  // id, its noise at the planned samples
  for (std::size_t id = 1; id < bands.size(); ++id) {
    if (model.pixels_by_id()[id] < kObjectPixels || !(image_noise > 0)) continue;
    const double own = noise.at(plan.cycles_samples) * noise_by_id[id] / image_noise * cycles_ratio_of(id);
    judged.emplace_back(id, own);
    if (bands[id] >= limit) {
      plan.notes.push_back(fmt::format("{}: its bands and bounces alone are predicted at a mean ΔE00 of {:.2f}, above "
                                       "the object limit {:g}", name(id), bands[id], limit));
      continue;
    }
    factor = std::max(factor, std::pow(own / std::sqrt(limit * limit - bands[id] * bands[id]), 2));
  }
  if (factor > 1 + 1e-9) {
    for (int& n : plan.cycles_samples) n = static_cast<int>(std::ceil(n * factor - 1e-9));
    plan.object_samples_factor = factor;
  }
  for (const auto& [id, own] : judged)
    plan.objects.push_back({name(id), static_cast<int>(id), model.pixels_by_id()[id], bands[id],
                            std::hypot(bands[id], own / std::sqrt(factor)), noise_by_id[id] / image_noise,
                            cycles_ratio_of(id)});
}

}  // namespace

double pixel_by_pixel_mean(const std::vector<double>& bands, const std::vector<double>& noise, double noise_mean,
                           const std::vector<double>& reference, double reference_mean, std::size_t pixel_count) {
  if (pixel_count == 0) return 0.0;
  auto scale = [&](const std::vector<double>& level, double mean) {
    const double sum = std::accumulate(level.begin(), level.end(), 0.0);
    return sum > 0 ? mean * static_cast<double>(pixel_count) / sum : 0.0;
  };
  const double c = scale(noise, noise_mean), t = scale(reference, reference_mean);
  double sum = 0;
  for (std::size_t p = 0; p < bands.size(); ++p)
    sum += std::sqrt(bands[p] * bands[p] + std::pow(c * noise[p], 2) + std::pow(t * reference[p], 2));
  return sum / static_cast<double>(pixel_count);
}

PiecewiseLinearSpectrum scene_light_spectrum(const Scene& scene) {
  std::vector<double> nm, v;
  for (int l = 300; l <= 900; ++l) nm.push_back(l);
  v.assign(nm.size(), 0.0);
  const std::vector<TriangleMesh> meshes = scene_meshes(scene);
  bool any = false;
  for (std::size_t i = 0; i < scene.lights.size(); ++i) {
    const TriangleMesh& mesh = meshes[scene.objects.size() + i];
    const PiecewiseLinearSpectrum e = emitted_mean_radiance(scene.lights[i], mesh);
    for (std::size_t j = 0; j < nm.size(); ++j) v[j] += surface_area(mesh) * e(nm[j]);
    any = true;
  }
  if (scene.environment) {
    Bounds all;
    for (const TriangleMesh& m : meshes)
      for (const Vec3& p : m.positions) all.extend(p);
    const double radius = all.empty() ? 1.0 : std::max(1e-6, 0.5 * (all.hi - all.lo).norm());
    const PiecewiseLinearSpectrum e = mean_environment_radiance(*scene.environment);
    for (std::size_t j = 0; j < nm.size(); ++j) v[j] += 4 * M_PI * radius * radius * e(nm[j]);
    any = true;
  }
  if (!any) std::fill(v.begin(), v.end(), 1.0);  // no light at all: equal energy
  const double peak = *std::max_element(v.begin(), v.end());
  if (peak > 0)
    for (double& x : v) x /= peak;
  return PiecewiseLinearSpectrum(nm, v);
}

Plan make_plan(const Scene& scene, const PlanOptions& options) {
  if (!(options.target_de00 > 0))
    throw InputError(fmt::format("--target-de00: must be > 0, got {:g}", options.target_de00));
  if (!(options.edge_step_nm >= 1))
    throw InputError(fmt::format("--edge-step: must be >= 1 nm, got {:g}", options.edge_step_nm));
  if (scene.render.max_bounces < 1)
    throw InputError(fmt::format("{}: render.max_bounces: {} leaves nothing to plan (needs >= 1)", scene.source,
                                 scene.render.max_bounces));
  Plan plan;
  const Model model(scene, options, plan.notes);
  const int kmax = model.depth();
  plan.noise_at_scene_samples = noise_at(model, scene.render.samples);
  plan.samples = samples_for(model, options.target_de00);
  plan.noise_at_samples = noise_at(model, plan.samples);
  plan.energy_after = energy_after(model);
  plan.max_bounces = bounces_for(model, options.target_de00);
  plan.predicted_bounce_only = model.evaluate_exact(plan.max_bounces).first;

  // Bands: the fewest (multiples of 3 for Cycles) whose fitted edges meet the target.
  const auto& cand = model.grid_edges();
  const std::size_t cells = cand.size() - 1;
  const std::size_t step = options.renderer == Renderer::Cycles ? 3 : 1;
  const std::size_t max_bands = std::min<std::size_t>(cells, 60);
  std::vector<std::size_t> previous{0, cells};
  std::vector<std::size_t> best_idx;
  double best_value = std::numeric_limits<double>::infinity();
  // For Cycles the counts after the first taken are weighed too, while their samples in all fall: more bands leave
  // the noise more of the target, at a render per three of them.
  const bool cycles = options.renderer == Renderer::Cycles;
  const double ratio = options.cycles_noise_ratio > 0 ? options.cycles_noise_ratio : kCyclesNoiseRatio;
  auto total = [](const std::vector<int>& n) { return std::accumulate(n.begin(), n.end(), 0L); };
  bool chosen = false;
  std::vector<int> chosen_samples;
  for (std::size_t n = step; n <= max_bands; n += step) {
    std::vector<std::size_t> uniform(n + 1);
    for (std::size_t i = 0; i <= n; ++i) uniform[i] = (i * cells + n / 2) / n;
    uniform.erase(std::unique(uniform.begin(), uniform.end()), uniform.end());
    auto [a_idx, a_val] = fit(model, uniform, plan.max_bounces, options.edge_step_nm);
    auto [b_idx, b_val] = fit(model, split_widest(previous, n), plan.max_bounces, options.edge_step_nm);
    if (b_val < a_val) {
      a_idx = b_idx;
      a_val = b_val;
    }
    previous = a_idx;
    BandTrial trial;
    trial.bands = static_cast<int>(a_idx.size() - 1);
    trial.predicted_mean = a_val;
    std::vector<int> trial_edges;
    for (std::size_t i : a_idx) {
      trial.edges_nm.push_back(model.lo() + cand[i]);
      trial_edges.push_back(cand[i]);
    }
    // A count that meets the target is taken unless the warnings before a render (check-scene, render) would
    // name its bands: the mean over the image can hide one surface whose colour the bands cannot hold.
    bool taken = false;
    if (a_val <= options.target_de00) {
      BandReconstruction r;
      model.evaluate(trial_edges, plan.max_bounces, model.reconstructs(), &r);
      Bands b = Bands::from_edges(trial.edges_nm, "plan");
      if (r.fine > 0) b = b.with_reconstruction(std::move(r), "plan");
      const auto warnings = check_band_plan(scene, b, SpectralMode::Bands, 2.0, options.renderer == Renderer::Tracer);
      if (warnings.empty()) taken = true;
      else trial.refused = warnings.front().message;
    }
    plan.trials.push_back(trial);
    if (!chosen) {
      best_idx = a_idx;
      best_value = a_val;
    }
    if (!taken) {
      if (chosen) break;
      continue;
    }
    if (!cycles) {
      chosen = true;
      break;
    }
    const int min_samples = options.cycles_min_samples > 0 ? options.cycles_min_samples : kCyclesMinSamples;
    const CyclesNoise trial_noise = cycles_noise(model, trial_edges, plan.max_bounces, ratio, options);
    // Planned for what compare measures against a tracer reference, its noise is part of the error to hold.
    const double reference =
        options.target_against_reference ? reference_noise(trial_noise, options.reference_samples) : 0.0;
    const std::vector<int> samples = raised_for_joint(
        pixel_errors_of(model, trial_edges, plan.max_bounces, options), trial_noise,
        cycles_samples_for(trial_noise, std::hypot(a_val, reference), options.target_de00, min_samples),
        options.target_de00, reference);
    plan.trials.back().cycles_samples = samples;
    const bool cheaper = !samples.empty() && (chosen_samples.empty() || total(samples) < total(chosen_samples));
    if (!chosen || cheaper) {
      best_idx = a_idx;
      best_value = a_val;
      chosen_samples = samples;
    }
    // Stop at the first count that costs more than the one before it (or, with none feasible yet, keep looking).
    if (chosen && !cheaper && !chosen_samples.empty()) break;
    chosen = true;
  }
  plan.cycles_samples = chosen_samples;
  plan.target_met = chosen && best_value <= options.target_de00 && (!cycles || !plan.cycles_samples.empty());
  std::vector<int> edges;
  std::vector<double> edges_nm;
  for (std::size_t i : best_idx) {
    edges.push_back(cand[i]);
    edges_nm.push_back(model.lo() + cand[i]);
  }
  plan.bands = Bands::from_edges(edges_nm, "plan");
  BandReconstruction reconstruction;
  std::tie(plan.predicted_mean, plan.predicted_p95) =
      model.evaluate(edges, plan.max_bounces, model.reconstructs(), &reconstruction);
  if (reconstruction.fine > 0) plan.bands = plan.bands.with_reconstruction(std::move(reconstruction), "plan");
  plan.predicted_band_only = model.evaluate(edges, kmax).first;
  if (cycles && !plan.cycles_samples.empty()) {
    CyclesNoise noise = cycles_noise(model, edges, plan.max_bounces, ratio, options);
    limit_objects(plan, scene, model, edges, noise, options);
    const auto& n = plan.cycles_samples;
    // Bands and noise added pixel by pixel at the ratio `noise` holds, against a reference of `reference` mean ΔE00
    // of noise if given.
    const Model::PixelErrors errors = pixel_errors_of(model, edges, plan.max_bounces, options);
    auto with = [&](double reference = 0) { return errors.mean(noise.at(n), reference); };
    plan.cycles_noise_ratio = ratio;
    plan.tracer_noise_at_one = noise.at_one;
    plan.tracer_noise_from_pilots = options.cycles_pilot_tracer_noise_at_one > 0;
    for (std::size_t g = 0; g < noise.groups; ++g) plan.cycles_noise_shares.push_back(noise.share[g * noise.groups + g]);
    if (noise.measured) plan.cycles_noise_pair_shares = noise.share;
    plan.cycles_noise_shares_measured = noise.measured;
    if (noise.measured && options.cycles_group_guided_delta_e.size() == noise.groups) {
      plan.cycles_group_guided_delta_e = options.cycles_group_guided_delta_e;
      const auto& r = plan.cycles_group_guided_delta_e;
      plan.cycles_guide_group = static_cast<int>(std::min_element(r.begin(), r.end()) - r.begin());
    }
    plan.cycles_noise_only = noise.at(n);
    plan.cycles_predicted_mean = with();
    plan.cycles_predicted_in_quadrature = std::hypot(plan.predicted_mean, plan.cycles_noise_only);
    // The range: the ratio's (measured on the pilots, or over the test scenes), and the noise model's own accuracy.
    std::array<double, 2> range = options.cycles_noise_ratio_range;
    if (!(options.cycles_noise_ratio > 0)) range = {kCyclesNoiseRatioLow, kCyclesNoiseRatioHigh};
    if (!(range[1] > 0)) range = {ratio, ratio};
    // Against a tracer reference of N paths, its noise too (the tracer's at one path over √N).
    const double reference = reference_noise(noise, options.reference_samples);
    if (reference > 0) plan.cycles_predicted_against_reference = with(reference);
    noise.ratio = range[0] / (1 + kCyclesNoiseModelAccuracy);
    plan.cycles_predicted_low = with();
    if (reference > 0) plan.cycles_against_reference_low = with(reference);
    noise.ratio = range[1] * (1 + kCyclesNoiseModelAccuracy);
    plan.cycles_predicted_high = with();
    if (reference > 0) plan.cycles_against_reference_high = with(reference);
  }
  {
    std::vector<int> scene_edges;
    for (double e : scene.render.bands.edges()) scene_edges.push_back(static_cast<int>(std::lround(e)) - model.lo());
    bool on_grid = true;
    for (std::size_t i = 0; i < scene_edges.size(); ++i)
      on_grid = on_grid && std::abs(scene.render.bands.edges()[i] - (model.lo() + scene_edges[i])) < 1e-9;
    plan.scene_bands_predicted_mean = on_grid ? model.evaluate(scene_edges, kmax, false, nullptr).first
                                              : std::numeric_limits<double>::quiet_NaN();
  }
  if (!plan.target_met && best_value <= options.target_de00)
    plan.notes.push_back(fmt::format("no plan of up to {} bands holds every surface's colour: {}", best_idx.size() - 1,
                                     plan.trials.back().refused));
  else if (!plan.target_met)
    plan.notes.push_back(fmt::format("no plan of up to {} bands reaches the target: the best predicts {:.3g}",
                                     best_idx.size() - 1, best_value));
  for (const BandTrial& t : plan.trials)
    if (!t.refused.empty() && plan.target_met)
      plan.notes.push_back(fmt::format("{} bands meet the target on average but not taken: {}", t.bands, t.refused));

  // Cost.
  auto groups = [](std::size_t n) { return static_cast<int>((n + 2) / 3); };
  plan.cycles_band_groups = groups(plan.bands.size());
  plan.cycles_bounce_variants = options.bounce_components ? plan.max_bounces + 1 : 1;
  plan.cycles_renders = plan.cycles_band_groups * plan.cycles_bounce_variants + 1;
  plan.scene_cycles_renders =
      groups(scene.render.bands.size()) * (options.bounce_components ? kmax + 1 : 1) + 1;
  // Tracer: time ∝ scattering events traced × (a fixed cost per event + a cost per band), the fixed cost worth
  // kTracerEventBands bands (the paper box, 64×64, 64 paths per pixel, one thread: 40 bands 0.8 s, 8 bands 0.6 s,
  // 4 bands 0.58 s); events per path: the camera ray, then one per bounce while the path survives (Russian
  // roulette from the third event with survival ≈ the mean albedo).
  constexpr double kTracerEventBands = 64.0;
  auto events = [&](int K) {
    double e = 1, alive = model.hit_fraction();
    for (int k = 1; k <= K; ++k) {
      if (k >= 3) alive *= std::min(0.95, model.mean_albedo());
      e += alive;
    }
    return e;
  };
  plan.tracer_relative_time = events(plan.max_bounces) * (kTracerEventBands + static_cast<double>(plan.bands.size())) /
                              (events(kmax) * (kTracerEventBands + static_cast<double>(scene.render.bands.size())));
  return plan;
}

SettingsPrediction predict_settings(const Scene& scene, int max_bounces, int samples, const PlanOptions& options) {
  if (!(options.target_de00 > 0))
    throw InputError(fmt::format("--target-de00: must be > 0, got {:g}", options.target_de00));
  std::vector<std::string> notes;
  const Model model(scene, options, notes, std::max(1, max_bounces));
  SettingsPrediction p;
  p.max_bounces = max_bounces;
  p.samples = samples;
  p.reference_bounces = model.depth();
  const std::vector<double> after = energy_after(model, true);
  p.share_beyond = max_bounces < static_cast<int>(after.size()) ? after[static_cast<std::size_t>(max_bounces)] : 0.0;
  p.bounce_de00 = model.evaluate_exact(max_bounces).first;
  p.bounces_for_target = bounces_for(model, options.target_de00);
  p.noise_de00 = noise_at(model, samples);
  p.samples_for_target = samples_for(model, options.target_de00);
  return p;
}

Json bands_document(const Plan& plan) { return band_plan_document(plan.bands, plan.cycles_samples); }

Json report_document(const Plan& plan, const Scene& scene, const PlanOptions& options) {
  Json j;
  j["format"] = "chromatrace-plan/1";
  j["scene"] = scene.source;
  j["target_de00"] = options.target_de00;
  j["camera"] = options.camera;
  j["renderer"] = options.renderer == Renderer::Cycles ? "cycles" : "tracer";
  j["target_met"] = plan.target_met;
  Json s;
  s["bands"] = band_plan_document(plan.bands.without_reconstruction());  // the matrix is in the band-plan file
  if (const BandReconstruction* r = plan.bands.reconstruction())
    s["reconstruction"] = {{"fitted", true}, {"lo_nm", r->lo_nm}, {"step_nm", r->step_nm}, {"fine_bands", r->fine}};
  else
    s["reconstruction"] = {{"fitted", false}};
  s["band_count"] = plan.bands.size();
  s["max_bounces"] = plan.max_bounces;
  s["samples"] = plan.samples;
  s["samples_from"] = "tracer paths per pixel for a mean ΔE00 of Monte Carlo noise at the target, at the preview's pixel size";
  if (!plan.cycles_samples.empty()) s["cycles_samples"] = plan.cycles_samples;
  j["settings"] = s;
  Json p;
  p["mean_de00"] = plan.predicted_mean;
  p["p95_de00"] = plan.predicted_p95;
  p["bands_only_mean_de00"] = plan.predicted_band_only;
  p["bounces_only_mean_de00"] = plan.predicted_bounce_only;
  if (std::isfinite(plan.scene_bands_predicted_mean)) p["scene_bands_mean_de00"] = plan.scene_bands_predicted_mean;
  else p["scene_bands_mean_de00"] = nullptr;
  p["noise_mean_de00_at_planned_samples"] = plan.noise_at_samples;
  p["noise_mean_de00_at_scene_samples"] = plan.noise_at_scene_samples;
  p["energy_after_bounces"] = plan.energy_after;
  if (!plan.cycles_samples.empty()) {
    Json c{{"samples_per_band_group", plan.cycles_samples},
           {"mean_de00", plan.cycles_predicted_mean},
           {"mean_de00_range", {plan.cycles_predicted_low, plan.cycles_predicted_high}},
           {"noise_only_mean_de00", plan.cycles_noise_only},
           {"mean_de00_in_quadrature", plan.cycles_predicted_in_quadrature},
           {"noise_ratio_to_tracer", plan.cycles_noise_ratio},
           {"tracer_noise_at_one_sample", plan.tracer_noise_at_one},
           {"tracer_noise_from", plan.tracer_noise_from_pilots ? "the tracer's renders beside the Cycles pilots (their size and samples)"
                                                               : "the preview (its paths per pixel)"},
           {"noise_share_per_band_group", plan.cycles_noise_shares},
           {"noise_shares_between_band_groups", plan.cycles_noise_pair_shares},
           {"noise_shares_from", plan.cycles_noise_shares_measured ? "the Cycles pilots" : "plan's model of the preview's noise"},
           {"guided_delta_e_per_band_group", plan.cycles_group_guided_delta_e},
           {"guide_band_group", plan.cycles_guide_group >= 0 ? Json(plan.cycles_guide_group) : Json(nullptr)},
           {"noise_ratio_from", options.cycles_noise_ratio > 0
                                    ? (options.cycles_noise_ratio_from.empty() ? std::string("--cycles-noise-ratio")
                                                                               : options.cycles_noise_ratio_from)
                                    : std::string("the median over the test scenes; the range over them")}};
    if (options.reference_samples > 0)
      c["against_tracer_reference"] = Json{
          {"samples", options.reference_samples},
          {"the_target", options.target_against_reference},  // the samples were planned for this, not the mean above
          {"mean_de00", plan.cycles_predicted_against_reference},
          {"mean_de00_range", {plan.cycles_against_reference_low, plan.cycles_against_reference_high}}};
    c["object_limit_mean_de00"] = plan.object_target_de00;
    c["samples_raised_for_objects"] = plan.object_samples_factor;
    Json objects = Json::array();
    for (const Plan::ObjectPrediction& o : plan.objects) {
      Json j{{"name", o.name}, {"object_id", o.id}, {"preview_pixels", o.preview_pixels},
             {"bands_only_mean_de00", o.bands_only}, {"mean_de00", o.predicted_mean},
             {"noise_to_image_noise", o.noise_scale}, {"cycles_noise_ratio_to_image", o.cycles_ratio}};
      if (options.reference_samples > 0)
        j["against_tracer_reference_mean_de00"] =
            std::hypot(o.predicted_mean, plan.tracer_noise_at_one * o.noise_scale / std::sqrt(options.reference_samples));
      objects.push_back(j);
    }
    c["objects"] = objects;
    p["cycles"] = c;
  }
  Json trials = Json::array();
  for (const BandTrial& t : plan.trials) {
    Json trial{{"bands", t.bands}, {"mean_de00", t.predicted_mean}, {"edges_nm", t.edges_nm},
               {"refused", t.refused.empty() ? Json() : Json(t.refused)}};
    if (options.renderer == Renderer::Cycles && t.refused.empty() && t.predicted_mean <= options.target_de00)
      trial["cycles_samples"] = t.cycles_samples.empty() ? Json() : Json(t.cycles_samples);
    trials.push_back(trial);
  }
  p["band_counts_tried"] = trials;
  j["prediction"] = p;
  Json c;
  c["cycles_band_groups"] = plan.cycles_band_groups;
  c["cycles_bounce_variants"] = plan.cycles_bounce_variants;
  c["cycles_renders"] = plan.cycles_renders;
  c["scene_cycles_renders"] = plan.scene_cycles_renders;
  c["tracer_relative_time"] = plan.tracer_relative_time;
  j["cost"] = c;
  j["scene_settings"] = Json{{"band_count", scene.render.bands.size()}, {"max_bounces", scene.render.max_bounces},
                             {"samples", scene.render.samples}};
  j["notes"] = plan.notes;
  return j;
}

}  // namespace ct::plan
