#include "plan/plan.h"

#include <algorithm>
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
#include "plan/spectral_check.h"
#include "reference_tracer/accel.h"
#include "reference_tracer/render.h"
#include "sensor_sim/spectral_response.h"

namespace ct::plan {

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  const std::size_t k = std::min(v.size() - 1, static_cast<std::size_t>(q * static_cast<double>(v.size() - 1) + 0.5));
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return v[k];
}

bool near_light(const std::vector<std::int32_t>& ids, int w, int h, std::size_t p, std::int32_t first_light) {
  const int x = static_cast<int>(p % static_cast<std::size_t>(w)), y = static_cast<int>(p / static_cast<std::size_t>(w));
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) {
      const int xx = x + dx, yy = y + dy;
      if (xx < 0 || yy < 0 || xx >= w || yy >= h) continue;
      if (ids[static_cast<std::size_t>(yy) * static_cast<std::size_t>(w) + static_cast<std::size_t>(xx)] >= first_light)
        return true;
    }
  return false;
}

namespace {

// A spectrum sampled every 1 nm on the model's grid, with its running integral (trapezoids).
struct Sampled {
  std::vector<double> v, cum;
};

// The 1 nm grid [lo, hi] (whole nm) on which the model evaluates spectra.
struct Grid {
  int lo = 380, hi = 780;
  std::size_t n() const { return static_cast<std::size_t>(hi - lo + 1); }

  Sampled sample(const std::function<double(double)>& f) const {
    Sampled s;
    s.v.resize(n());
    for (std::size_t i = 0; i < n(); ++i) s.v[i] = f(lo + static_cast<double>(i));
    finish(s);
    return s;
  }
  static void finish(Sampled& s) {
    s.cum.assign(s.v.size(), 0.0);
    for (std::size_t i = 1; i < s.v.size(); ++i) s.cum[i] = s.cum[i - 1] + 0.5 * (s.v[i - 1] + s.v[i]);
  }
  // Average over [a, b] (grid indices).
  static double average(const Sampled& s, int a, int b) { return (s.cum[b] - s.cum[a]) / (b - a); }
  static double integral(const Sampled& s, int a, int b) { return s.cum[b] - s.cum[a]; }
};

// Tristimulus values of a sampled spectrum through the observer (trapezoids on the 1 nm grid).
Vec3d tristimulus(const std::vector<double>& f, const std::array<Sampled, 3>& obs) {
  Vec3d out{};
  for (int c = 0; c < 3; ++c) {
    double s = 0;
    for (std::size_t i = 0; i < f.size(); ++i) {
      const double w = (i == 0 || i + 1 == f.size()) ? 0.5 : 1.0;
      s += w * f[i] * obs[c].v[i];
    }
    out[c] = s;
  }
  return out;
}

// Where light leaving each surface goes: for every object id o (objects, then lights), cosine-weighted rays
// from points spread uniformly over its area, on the side of its surface that receives the most light
// (then: that sees the most of the scene). hits[o][j]: the fraction reaching surface id j (0: none, the
// ray escapes); lit[o][l]: the fraction reaching the emitting side of light l. Radiosity with one patch per
// object: the irradiance on o after k bounces is Σ_j hits[o][j]·B_k−1,j (radiance units, a Lambertian
// sender), and the direct irradiance Σ_l lit[o][l]·E_l.
struct Transfer {
  std::vector<std::vector<double>> hits, lit;
};

Transfer transfer(const Scene& scene, const std::vector<TriangleMesh>& meshes, int samples) {
  std::vector<const TriangleMesh*> ptrs;
  for (const TriangleMesh& m : meshes) ptrs.push_back(&m);
  const rt::Accelerator accel(ptrs);
  const std::size_t ids = meshes.size() + 1, objects = scene.objects.size();
  Transfer t;
  t.hits.assign(ids, std::vector<double>(ids, 0.0));
  t.lit.assign(ids, std::vector<double>(scene.lights.size(), 0.0));
  for (std::size_t m = 0; m < meshes.size(); ++m) {
    const TriangleMesh& mesh = meshes[m];
    std::vector<double> cdf;
    double area = 0;
    for (std::size_t tri = 0; tri < mesh.triangles.size(); ++tri) cdf.push_back(area += triangle_area(mesh, tri));
    if (!(area > 0)) continue;
    std::array<std::vector<double>, 2> hits{std::vector<double>(ids, 0.0), std::vector<double>(ids, 0.0)};
    std::array<std::vector<double>, 2> lit{std::vector<double>(scene.lights.size(), 0.0),
                                           std::vector<double>(scene.lights.size(), 0.0)};
    Random rng(0x706c616eull, m);
    for (int i = 0; i < samples; ++i) {
      const double pick = rng.uniform() * area;
      const std::size_t tri = std::min<std::size_t>(
          static_cast<std::size_t>(std::upper_bound(cdf.begin(), cdf.end(), pick) - cdf.begin()), cdf.size() - 1);
      double u = rng.uniform(), v = rng.uniform();
      if (u + v > 1) u = 1 - u, v = 1 - v;
      const auto& ix = mesh.triangles[tri];
      const Vec3 p = (1 - u - v) * mesh.positions[ix[0]] + u * mesh.positions[ix[1]] + v * mesh.positions[ix[2]];
      const Vec3 n = face_normal(mesh, tri);
      if (n.squaredNorm() == 0) continue;
      const Vec3 a = std::abs(n.x()) > 0.5 ? Vec3(0, 1, 0) : Vec3(1, 0, 0);
      const Vec3 tx = n.cross(a).normalized(), ty = n.cross(tx);
      const double r1 = rng.uniform(), r2 = rng.uniform();
      const double rad = std::sqrt(r1), phi = 2 * M_PI * r2, z = std::sqrt(std::max(0.0, 1 - r1));
      for (int side = 0; side < 2; ++side) {
        const Vec3 ns = side == 0 ? n : Vec3(-n);
        const Vec3 dir = (rad * std::cos(phi) * tx + rad * std::sin(phi) * ty + z * ns).normalized();
        const auto hit = accel.intersect(rt::offset_origin(p, n, ns, accel.scale()), dir,
                                         std::numeric_limits<double>::infinity());
        if (!hit) {
          hits[side][0] += 1;
          continue;
        }
        const std::size_t id = hit->mesh + 1;
        hits[side][id] += 1;
        if (hit->mesh >= objects) {
          const std::size_t l = hit->mesh - objects;
          const Vec3 ln = face_normal(meshes[hit->mesh], hit->triangle);
          if (scene.lights[l].two_sided || dir.dot(ln) < 0) lit[side][l] += 1;
        }
      }
    }
    auto score = [&](int side) {
      double s = 0, seen = 0;
      for (double x : lit[side]) s += x;
      for (std::size_t j = 1; j < ids; ++j) seen += hits[side][j];
      return s + 1e-3 * seen;
    };
    const int side = score(1) > score(0) ? 1 : 0;
    for (std::size_t j = 0; j < ids; ++j) t.hits[m + 1][j] = hits[side][j] / samples;
    for (std::size_t l = 0; l < scene.lights.size(); ++l) t.lit[m + 1][l] = lit[side][l] / samples;
  }
  return t;
}

// What a surface of the scene contributes to the model.
struct Surface {
  Sampled emission;     // zero unless a light
  Sampled diffuse;      // R_o
  Sampled glossy;       // what a glossy bounce multiplies by
  Sampled albedo;       // what the surface sends on (diffuse + specular)
  bool emitter = false;
};

// The spectra of the model in one basis: 1 nm samples (exact) or band averages (a plan), with each basis
// element's weight in each observer channel.
struct Basis {
  std::array<std::vector<double>, 3> weight;
  std::vector<std::vector<double>> emission, diffuse, glossy, albedo;  // per surface id
  std::vector<double> light, mean_albedo, environment;
  std::size_t size() const { return light.size(); }
};

// The spectra behind the templates (in the basis), [id][k][lobe].
using TemplateSpectra = std::vector<std::vector<std::array<std::vector<double>, 2>>>;

// Tristimulus values of every (id, k, lobe) template: k = 0 the surface's own emission; k >= 1 what it reflects
// after k scattering events, by radiosity over the transfer factors; where that gives no light (a surface no
// sampled ray lit), the mean-albedo model E·R·ρ̄^(k−1). With `spectra`, also the spectrum behind each.

std::vector<std::vector<std::array<Vec3d, 2>>> templates(const Basis& b, const Transfer& t, int kmax,
                                                         TemplateSpectra* spectra = nullptr) {
  const std::size_t ids = b.emission.size(), n = b.size(), lights = t.lit.empty() ? 0 : t.lit[0].size();
  const std::size_t first_light = ids - lights;
  std::vector<std::vector<std::array<Vec3d, 2>>> out(ids, std::vector<std::array<Vec3d, 2>>(kmax + 1));
  auto project = [&](const std::vector<double>& f) {
    Vec3d x{};
    for (int c = 0; c < 3; ++c)
      for (std::size_t i = 0; i < n; ++i) x[c] += f[i] * b.weight[c][i];
    return x;
  };
  std::vector<std::vector<double>> irr(ids, std::vector<double>(n, 0.0)), sent(ids, std::vector<double>(n, 0.0));
  std::vector<double> f(n), fallback(n);
  if (spectra) spectra->assign(ids, std::vector<std::array<std::vector<double>, 2>>(kmax + 1, {std::vector<double>(n, 0.0), std::vector<double>(n, 0.0)}));
  for (std::size_t id = 0; id < ids; ++id) {
    out[id][0][0] = project(b.emission[id]);
    if (spectra) (*spectra)[id][0][0] = b.emission[id];
  }
  for (int k = 1; k <= kmax; ++k) {
    for (std::size_t o = 1; o < ids; ++o) {
      std::fill(irr[o].begin(), irr[o].end(), 0.0);
      if (k == 1) {
        for (std::size_t l = 0; l < lights; ++l)
          for (std::size_t i = 0; i < n; ++i) irr[o][i] += t.lit[o][l] * b.emission[first_light + l][i];
        if (!b.environment.empty())
          for (std::size_t i = 0; i < n; ++i) irr[o][i] += t.hits[o][0] * b.environment[i];
      } else {
        for (std::size_t j = 1; j < ids; ++j)
          if (t.hits[o][j] > 0)
            for (std::size_t i = 0; i < n; ++i) irr[o][i] += t.hits[o][j] * sent[j][i];
      }
    }
    for (std::size_t o = 0; o < ids; ++o)
      for (int lobe = 0; lobe < 2; ++lobe) {
        const auto& r = lobe == 0 ? b.diffuse[o] : b.glossy[o];
        for (std::size_t i = 0; i < n; ++i) {
          f[i] = o == 0 ? 0.0 : r[i] * irr[o][i];
          fallback[i] = b.light[i] * (o == 0 ? b.mean_albedo[i] : r[i]) * std::pow(b.mean_albedo[i], k - 1);
        }
        Vec3d x = project(f);
        const bool fell_back = !(x[1] > 0);
        if (fell_back) x = project(fallback);
        out[o][k][lobe] = x;
        if (spectra) (*spectra)[o][k][lobe] = fell_back ? fallback : f;
      }
    for (std::size_t o = 1; o < ids; ++o)
      for (std::size_t i = 0; i < n; ++i) sent[o][i] = b.albedo[o][i] * irr[o][i];
  }
  return out;
}

const SpectrumRef* diffuse_ref(const Material& m) {
  if (auto* l = std::get_if<LambertMaterial>(&m.model)) return &l->reflectance;
  if (auto* d = std::get_if<DichromaticMaterial>(&m.model)) return &d->diffuse;
  if (auto* r = std::get_if<MirrorMaterial>(&m.model)) return &r->reflectance;
  return nullptr;
}

// A pixel of the preview: its object id and the luminance of each (bounce order, lobe).
struct Pixel {
  std::int32_t id = 0;
  std::size_t index = 0;  // in the preview image
  std::vector<std::array<double, 2>> y;  // [k][lobe]: lobe 0 diffuse (k = 0: emission), 1 glossy
  double total = 0;
  bool near_light = false;  // on or next to a light (near_light())
};

// A reference depth's tail: 1 % of the luminance is a mean ΔE00 of about 0.25 at mid grey (L* ∝ Y^⅓, so
// ΔL* ≈ (L* + 16)/3 · ΔY/Y ≈ 25 · ΔY/Y), the quarter of a target of 1 that plan gives the bounce limit.
constexpr double kNegligibleShare = 0.01;
constexpr int kMaxReferenceBounces = 64;

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
  bool reconstructs() const { return reconstruct_; }
  std::pair<double, double> evaluate_exact(int max_bounces) const;  // exact spectra, truncated bounces

  const std::vector<int>& grid_edges() const { return grid_edges_; }  // candidate edge positions (grid indices)
  int lo() const { return grid_.lo; }
  int depth() const { return kmax_; }  // the truth's bounce limit
  const std::vector<Pixel>& pixels() const { return pixels_; }
  double hit_fraction() const { return hit_fraction_; }
  // Mean ΔE00 of the preview's Monte Carlo noise (one render against the truth) and its paths per pixel.
  double preview_noise() const { return preview_noise_; }
  int preview_samples() const { return preview_samples_; }
  double mean_albedo() const { return mean_albedo_; }

 private:
  std::pair<double, double> score(const std::vector<std::vector<std::array<Vec3d, 2>>>& templates, int max_bounces) const;
  std::optional<BandReconstruction> fit_reconstruction(const TemplateSpectra& banded, const std::vector<int>& edges,
                                                       int max_bounces) const;

  Grid grid_;
  int kmax_ = 0;
  std::array<Sampled, 3> obs_;
  Sampled light_, albedo_, environment_;
  bool has_environment_ = false;
  std::vector<Surface> surfaces_;  // by object id (0: background)
  Transfer transfer_;
  std::vector<std::vector<std::array<Vec3d, 2>>> exact_;  // [id][k][lobe], scaled to Y = 1
  std::vector<std::vector<std::array<double, 2>>> exact_y_;
  TemplateSpectra exact_spectra_;                         // [id][k][lobe], 1 nm samples
  std::vector<std::vector<std::array<double, 2>>> share_;  // [id][k][lobe]: Σ over pixels of the luminance share
  bool reconstruct_ = false;
  std::vector<Pixel> pixels_;
  std::vector<Vec3d> lab_exact_;
  Vec3d white_{};
  std::vector<int> grid_edges_;
  double hit_fraction_ = 0, mean_albedo_ = 0, preview_noise_ = 0;
  int preview_samples_ = 0;
  std::size_t pixel_count_ = 0;
};

Model::Model(const Scene& scene, const PlanOptions& options, std::vector<std::string>& notes, int reference_bounces) {
  const Bands& sb = scene.render.bands;
  grid_.lo = static_cast<int>(std::ceil(sb.min_wavelength() - 1e-9));
  grid_.hi = static_cast<int>(std::floor(sb.max_wavelength() + 1e-9));
  if (grid_.hi - grid_.lo < 2) throw InputError(fmt::format("{}: render.bands: range too narrow to plan", scene.source));
  kmax_ = reference_bounces > 0 ? reference_bounces : scene.render.max_bounces;

  const sensor::CameraCurves curves = sensor::camera_curves(options.camera, {"r", "g", "b"}, "--camera");
  if (sb.min_wavelength() < curves.min_wavelength() - 1e-9 || sb.max_wavelength() > curves.max_wavelength() + 1e-9)
    notes.push_back(fmt::format("the camera {} has curves over {:g}-{:g} nm only: it sees nothing of the bands beyond",
                                curves.name, curves.min_wavelength(), curves.max_wavelength()));
  for (int c = 0; c < 3; ++c) obs_[c] = grid_.sample([&](double nm) { return curves.curves[c](nm); });

  // Candidate edges: the range's ends and the multiples of the step inside it.
  const double step = options.edge_step_nm;
  grid_edges_.push_back(0);
  for (double nm = std::ceil((grid_.lo + 1e-9) / step) * step; nm < grid_.hi - 1e-9; nm += step)
    if (nm > grid_.lo + 1e-9) grid_edges_.push_back(static_cast<int>(std::lround(nm)) - grid_.lo);
  grid_edges_.push_back(grid_.hi - grid_.lo);

  reconstruct_ = options.reconstruction;
  auto spectrum_of = [&](const SpectrumRef& ref, const std::string& what) -> Sampled {
    if (ref.texture) {
      if (reconstruct_)
        notes.push_back(fmt::format("{} is an image texture, whose spectra the model does not hold: no reconstruction "
                                    "is fitted (the bands' values are read as a step function)", what));
      reconstruct_ = false;
      notes.push_back(fmt::format("{} is an image texture: modelled as a flat reflectance of 0.5", what));
      return grid_.sample([](double) { return 0.5; });
    }
    return grid_.sample([&](double nm) { return ref.spectrum(nm); });
  };
  const Sampled zero = grid_.sample([](double) { return 0.0; });
  const Sampled one = grid_.sample([](double) { return 1.0; });

  // The light spectrum and the mean albedo.
  const PiecewiseLinearSpectrum light = scene_light_spectrum(scene);
  light_ = grid_.sample([&](double nm) { return light(nm); });
  const std::vector<TriangleMesh> meshes = scene_meshes(scene);
  std::vector<double> albedo(grid_.n(), 0.0);
  double area_sum = 0;
  surfaces_.assign(static_cast<std::size_t>(scene.id_count()) + 1, Surface{zero, zero, zero, zero, false});
  surfaces_[0] = Surface{zero, zero, zero, zero, false};
  auto add_material = [&](std::size_t id, const Material& m, double area) {
    Surface& s = surfaces_[id];
    s.diffuse = spectrum_of(*diffuse_ref(m), fmt::format("materials.{}", m.name));
    double ks = 0;
    bool mirror = false;
    if (auto* d = std::get_if<DichromaticMaterial>(&m.model)) {
      ks = d->specular;
      s.glossy = one;
    } else if (std::holds_alternative<MirrorMaterial>(m.model)) {
      s.glossy = s.diffuse;
      s.diffuse = zero;
      mirror = true;
    }
    s.albedo.v.resize(albedo.size());
    for (std::size_t i = 0; i < albedo.size(); ++i) {
      s.albedo.v[i] = s.diffuse.v[i] + ks + (mirror ? s.glossy.v[i] : 0);
      albedo[i] += area * s.albedo.v[i];
    }
    Grid::finish(s.albedo);
    area_sum += area;
  };
  for (std::size_t o = 0; o < scene.objects.size(); ++o)
    add_material(o + 1, scene.materials[scene.objects[o].material], surface_area(meshes[o]));
  for (std::size_t l = 0; l < scene.lights.size(); ++l) {
    const std::size_t id = scene.objects.size() + l + 1;
    const Light& light_l = scene.lights[l];
    if (light_l.material) add_material(id, scene.materials[*light_l.material], surface_area(meshes[id - 1]));
    surfaces_[id].emitter = true;
    if (light_l.radiance.texture) {
      notes.push_back(fmt::format("lights[{}].radiance is an image texture: modelled as the scene's light", l));
      surfaces_[id].emission = light_;
    } else {
      const PiecewiseLinearSpectrum e = light_l.emitted_radiance();
      surfaces_[id].emission = grid_.sample([&](double nm) { return e(nm); });
    }
  }
  albedo_.v = albedo;
  for (double& a : albedo_.v) a /= std::max(area_sum, 1e-300);
  Grid::finish(albedo_);
  {
    const double ysum = std::accumulate(obs_[1].v.begin(), obs_[1].v.end(), 0.0);
    double s = 0;
    for (std::size_t i = 0; i < albedo_.v.size(); ++i) s += albedo_.v[i] * obs_[1].v[i];
    mean_albedo_ = ysum > 0 ? s / ysum : 0;
  }
  if (reference_bounces > 0 && mean_albedo_ > 0 && mean_albedo_ < 1)
    kmax_ = std::clamp(static_cast<int>(std::ceil(std::log(kNegligibleShare) / std::log(mean_albedo_))), kmax_,
                       std::max(kmax_, kMaxReferenceBounces));
  else if (reference_bounces > 0 && mean_albedo_ >= 1)
    kmax_ = std::max(kmax_, kMaxReferenceBounces);
  // The background: what the environment (or, in edge pixels, any surface) sends.
  surfaces_[0].emission = light_;
  surfaces_[0].diffuse = albedo_;
  surfaces_[0].glossy = albedo_;

  if (scene.environment) {
    has_environment_ = true;
    if (scene.environment->radiance.texture) {
      notes.push_back("environment.radiance is an image texture: modelled as the scene's light spectrum");
      environment_ = light_;
    } else {
      const PiecewiseLinearSpectrum e = scene.environment->radiance.spectrum.scaled(scene.environment->scale);
      environment_ = grid_.sample([&](double nm) { return e(nm); });
    }
    surfaces_[0].emission = environment_;
  }
  transfer_ = transfer(scene, meshes, 4096);

  // Exact templates, scaled so that their luminance (second channel) is 1.
  const std::size_t ids = surfaces_.size();
  Basis exact;
  for (int c = 0; c < 3; ++c) {
    exact.weight[c] = obs_[c].v;
    exact.weight[c].front() *= 0.5;
    exact.weight[c].back() *= 0.5;
  }
  for (const Surface& s : surfaces_) {
    exact.emission.push_back(s.emission.v);
    exact.diffuse.push_back(s.diffuse.v);
    exact.glossy.push_back(s.glossy.v);
    exact.albedo.push_back(s.albedo.v.empty() ? zero.v : s.albedo.v);
  }
  exact.light = light_.v;
  exact.mean_albedo = albedo_.v;
  if (has_environment_) exact.environment = environment_.v;
  exact_ = templates(exact, transfer_, kmax_, &exact_spectra_);
  exact_y_.assign(ids, std::vector<std::array<double, 2>>(static_cast<std::size_t>(kmax_) + 1, {0.0, 0.0}));
  for (std::size_t id = 0; id < ids; ++id)
    for (int k = 0; k <= kmax_; ++k)
      for (int lobe = 0; lobe < 2; ++lobe) {
        Vec3d& x = exact_[id][k][lobe];
        exact_y_[id][k][lobe] = x[1];
        if (x[1] > 0) x = {x[0] / x[1], 1.0, x[2] / x[1]};
        else x = {0.0, 0.0, 0.0};
      }

  // The preview render.
  Scene preview = scene;
  preview.render.max_bounces = kmax_;
  const int w = scene.camera.width, h = scene.camera.height;
  const int size = std::max(1, options.preview_size);
  if (w >= h) {
    preview.camera.width = std::min(w, size);
    preview.camera.height = std::max(1, static_cast<int>(std::lround(static_cast<double>(h) * preview.camera.width / w)));
  } else {
    preview.camera.height = std::min(h, size);
    preview.camera.width = std::max(1, static_cast<int>(std::lround(static_cast<double>(w) * preview.camera.height / h)));
  }
  rt::RenderOptions ro;
  ro.samples = options.preview_samples;
  ro.mode = SpectralMode::Bands;
  ro.components = rt::ComponentSelection::parse("all");
  ro.threads = options.threads;
  ro.progress = false;
  const rt::RenderedImage img = rt::render(preview, ro);
  const auto q = sensor::photon_response(img.bands, curves, sensor::ResponseBasis::Energy, 1.0,
                                         PiecewiseLinearSpectrum::constant(1.0));
  const std::size_t nb = img.bands.size(), N = static_cast<std::size_t>(img.width) * img.height;
  auto layer = [&](const std::string& name) -> const std::vector<float>* {
    for (std::size_t i = 0; i < img.components.size(); ++i)
      if (img.components[i] == name) return &img.layers[i + 1];
    return nullptr;
  };
  auto lum = [&](const std::vector<float>* l, std::size_t p) {
    if (!l) return 0.0;
    double s = 0;
    for (std::size_t b = 0; b < nb; ++b) s += q[1][b] * (*l)[p * nb + b];
    return s;
  };
  const auto *dd = layer("diffuse_direct"), *gd = layer("glossy_direct"), *di = layer("diffuse_indirect"),
             *gi = layer("glossy_indirect");
  pixel_count_ = N;
  const auto first_light = static_cast<std::int32_t>(scene.objects.size()) + 1;
  std::size_t hits = 0;
  for (std::size_t p = 0; p < N; ++p) {
    Pixel px;
    px.index = p;
    px.id = img.object_ids[p];
    px.near_light = near_light(img.object_ids, img.width, img.height, p, first_light);
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

  // The exact colours and the white.
  std::vector<Vec3d> xyz(pixels_.size());
  std::vector<double> ys;
  for (std::size_t p = 0; p < pixels_.size(); ++p) {
    const Pixel& px = pixels_[p];
    Vec3d x{};
    for (int k = 0; k <= kmax_; ++k)
      for (int lobe = 0; lobe < 2; ++lobe)
        for (int c = 0; c < 3; ++c) x[c] += px.y[k][lobe] * exact_[px.id][k][lobe][c];
    xyz[p] = x;
    if (!px.near_light) ys.push_back(x[1]);
  }
  // Pixels with no light count as values of zero.
  for (std::size_t p = 0, lit = 0; p < N; ++p) {
    if (lit < pixels_.size() && pixels_[lit].index == p) {
      ++lit;
      continue;
    }
    if (!near_light(img.object_ids, img.width, img.height, p, first_light)) ys.push_back(0.0);
  }
  double yw = percentile(ys, 0.99);
  if (!(yw > 0)) yw = 1;
  white_ = tristimulus(light_.v, obs_);
  const double ws = white_[1] > 0 ? yw / white_[1] : 1.0;
  for (double& v : white_) v = std::max(v * ws, 1e-300);
  lab_exact_.resize(pixels_.size());
  for (std::size_t p = 0; p < pixels_.size(); ++p) lab_exact_[p] = xyz_to_lab(xyz[p], white_);

  // Noise: a second preview with the next seed. The two differ by noise alone, of twice the variance of either;
  // while noise is small against the colour, ΔE00 grows in proportion to its standard deviation, so one render's
  // noise is the mean ΔE00 between the two / √2 and falls as 1/√(paths per pixel).
  rt::RenderOptions ro2 = ro;
  ro2.seed = scene.render.seed + 1;
  ro2.components = rt::ComponentSelection::parse("none");
  const rt::RenderedImage img2 = rt::render(preview, ro2);
  auto colour = [&](const std::vector<float>& l, std::size_t p) {
    Vec3d x{};
    for (int c = 0; c < 3; ++c)
      for (std::size_t b = 0; b < nb; ++b) x[c] += q[c][b] * l[p * nb + b];
    return xyz_to_lab(x, white_);
  };
  double noise = 0;
  for (std::size_t p = 0; p < N; ++p) noise += delta_e_2000(colour(img.layers[0], p), colour(img2.layers[0], p));
  preview_noise_ = N ? noise / static_cast<double>(N) / std::sqrt(2.0) : 0.0;
  preview_samples_ = img.samples;
}

std::pair<double, double> Model::score(const std::vector<std::vector<std::array<Vec3d, 2>>>& templates,
                                       int max_bounces) const {
  std::vector<double> de(pixels_.size());
  for (std::size_t p = 0; p < pixels_.size(); ++p) {
    const Pixel& px = pixels_[p];
    Vec3d x{};
    for (int k = 0; k <= std::min(max_bounces, kmax_); ++k)
      for (int lobe = 0; lobe < 2; ++lobe)
        for (int c = 0; c < 3; ++c) x[c] += px.y[k][lobe] * templates[px.id][k][lobe][c];
    de[p] = delta_e_2000(lab_exact_[p], xyz_to_lab(x, white_));
  }
  const double sum = std::accumulate(de.begin(), de.end(), 0.0);
  de.resize(pixel_count_, 0.0);  // unlit pixels: no error
  return {pixel_count_ ? sum / static_cast<double>(pixel_count_) : 0.0, percentile(de, 0.95)};
}

std::pair<double, double> Model::evaluate_exact(int max_bounces) const { return score(exact_, max_bounces); }

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
  auto t = templates(banded, transfer_, K, reconstruct ? &spectra : nullptr);
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
  for (std::size_t id = 0; id < t.size(); ++id)
    for (int k = 0; k <= K; ++k)
      for (int lobe = 0; lobe < 2; ++lobe) {
        const double y = exact_y_[id][k][lobe];
        Vec3d& x = t[id][k][lobe];
        if (y > 0) x = {x[0] / y, x[1] / y, x[2] / y};
        else x = {0.0, 0.0, 0.0};
      }
  return score(t, K);
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

}  // namespace

PiecewiseLinearSpectrum scene_light_spectrum(const Scene& scene) {
  std::vector<double> nm, v;
  for (int l = 300; l <= 900; ++l) nm.push_back(l);
  v.assign(nm.size(), 0.0);
  const std::vector<TriangleMesh> meshes = scene_meshes(scene);
  bool any = false;
  for (std::size_t i = 0; i < scene.lights.size(); ++i) {
    const Light& light = scene.lights[i];
    if (light.radiance.texture) continue;
    const double area = surface_area(meshes[scene.objects.size() + i]);
    const PiecewiseLinearSpectrum e = light.emitted_radiance();
    for (std::size_t j = 0; j < nm.size(); ++j) v[j] += area * e(nm[j]);
    any = true;
  }
  if (scene.environment && !scene.environment->radiance.texture) {
    Bounds all;
    for (const TriangleMesh& m : meshes)
      for (const Vec3& p : m.positions) all.extend(p);
    const double radius = all.empty() ? 1.0 : std::max(1e-6, 0.5 * (all.hi - all.lo).norm());
    const PiecewiseLinearSpectrum e = scene.environment->radiance.spectrum.scaled(scene.environment->scale);
    for (std::size_t j = 0; j < nm.size(); ++j) v[j] += 4 * M_PI * radius * radius * e(nm[j]);
    any = true;
  }
  if (!any) std::fill(v.begin(), v.end(), 1.0);  // textured light only: equal energy
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
    best_idx = a_idx;
    best_value = a_val;
    BandTrial trial;
    trial.bands = static_cast<int>(a_idx.size() - 1);
    trial.predicted_mean = a_val;
    for (std::size_t i : a_idx) trial.edges_nm.push_back(model.lo() + cand[i]);
    // A count that meets the target is taken unless the warnings before a render (check-scene, render) would
    // name its bands: the mean over the image can hide one surface whose colour the bands cannot hold.
    bool taken = false;
    if (a_val <= options.target_de00) {
      std::vector<int> trial_edges;
      for (std::size_t i : a_idx) trial_edges.push_back(cand[i]);
      BandReconstruction r;
      model.evaluate(trial_edges, plan.max_bounces, model.reconstructs(), &r);
      Bands b = Bands::from_edges(trial.edges_nm, "plan");
      if (r.fine > 0) b = b.with_reconstruction(std::move(r), "plan");
      const auto warnings = check_band_plan(scene, b, SpectralMode::Bands, 2.0, options.renderer == Renderer::Tracer);
      if (warnings.empty()) taken = true;
      else trial.refused = warnings.front().message;
    }
    plan.trials.push_back(trial);
    if (taken) break;
  }
  plan.target_met = !plan.trials.empty() && best_value <= options.target_de00 && plan.trials.back().refused.empty();
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

Json bands_document(const Plan& plan) { return band_plan_document(plan.bands); }

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
  Json trials = Json::array();
  for (const BandTrial& t : plan.trials)
    trials.push_back(Json{{"bands", t.bands}, {"mean_de00", t.predicted_mean}, {"edges_nm", t.edges_nm},
                          {"refused", t.refused.empty() ? Json() : Json(t.refused)}});
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
