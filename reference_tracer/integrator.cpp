// SPDX-License-Identifier: Apache-2.0
#include "reference_tracer/integrator.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <sstream>

#include <fmt/core.h>

#include "core/error.h"
#include "core/parallel.h"
#include "core/random.h"

namespace ct::rt {
namespace {

double power_heuristic(double pdf_a, double pdf_b) {
  const double a2 = pdf_a * pdf_a, b2 = pdf_b * pdf_b;
  return a2 / (a2 + b2);
}

// The scalar lobe values of a material for one pair of directions: f·cos of the Lambertian term and of the
// glossy lobe (neither scaled by spectra), and the density with which sample_material() picks `wi`.
struct LobeValues {
  double diffuse = 0.0, glossy = 0.0, pdf = 0.0;
};

LobeValues evaluate(const TracerMaterial& m, const Vec3& wo, const Vec3& wi) {
  LobeValues v;
  const double pg = m.glossy_probability;
  if (m.diffuse) {
    const LambertLobe lambert;
    const auto* principled = std::get_if<PrincipledLobe>(&m.glossy);
    v.diffuse = principled ? principled->diffuse(wo, wi) : lambert.eval(wo, wi);
    v.pdf += (1.0 - pg) * lambert.pdf(wo, wi);
  }
  std::visit(
      [&](const auto& lobe) {
        if constexpr (!std::is_same_v<std::decay_t<decltype(lobe)>, std::monostate>) {
          v.glossy = lobe.eval(wo, wi);
          v.pdf += pg * lobe.pdf(wo, wi);
        }
      },
      m.glossy);
  return v;
}

struct MaterialSample {
  Vec3 wi;
  LobeValues values;  // for a delta lobe: glossy = 1 / pg·(weight), pdf = ∞
  bool delta = false;
};

std::optional<MaterialSample> sample_material(const TracerMaterial& m, const Vec3& wo, double u_lobe, const Vec2& u) {
  const double pg = m.glossy_probability;
  const bool pick_glossy = u_lobe < pg;
  if (pick_glossy && m.is_delta()) {
    const auto s = MirrorLobe{}.sample(wo, u);
    if (!s) return std::nullopt;
    MaterialSample out;
    out.wi = s->wi;
    out.delta = true;
    out.values.glossy = 1.0;  // f·cos / pdf of the delta lobe
    out.values.pdf = pg;      // discrete choice only: weight = k_s · glossy / pdf
    return out;
  }
  std::optional<LobeSample> s;
  if (pick_glossy) {
    std::visit(
        [&](const auto& lobe) {
          if constexpr (!std::is_same_v<std::decay_t<decltype(lobe)>, std::monostate>) s = lobe.sample(wo, u);
        },
        m.glossy);
  } else {
    s = LambertLobe{}.sample(wo, u);
  }
  if (!s) return std::nullopt;
  MaterialSample out;
  out.wi = s->wi;
  out.values = evaluate(m, wo, s->wi);
  if (out.values.pdf <= 0.0) return std::nullopt;
  return out;
}

}  // namespace

ComponentSelection ComponentSelection::parse(const std::string& list, const std::string& what) {
  // The grammar and its cases: tests/data/component_grammar.json, shared with the Blender add-on's parser.
  constexpr const char* kKnown = "(known: paths, lights, bounces, all, none)";
  ComponentSelection c{false, false, false};
  bool none = false, family = false;
  std::stringstream in(list);
  std::string item;
  std::size_t items = 0;
  while (std::getline(in, item, ',')) {
    ++items;
    const auto first = item.find_first_not_of(' '), last = item.find_last_not_of(' ');
    item = first == std::string::npos ? "" : item.substr(first, last - first + 1);
    if (item.empty()) throw InputError(fmt::format("{}: an empty item {}", what, kKnown));
    if (item == "none") {
      none = true;
      continue;
    }
    family = true;
    if (item == "paths") c.paths = true;
    else if (item == "lights") c.lights = true;
    else if (item == "bounces") c.bounces = true;
    else if (item == "all") c = {true, true, true};
    else throw InputError(fmt::format("{}: unknown component family \"{}\" {}", what, item, kKnown));
  }
  if (items == 0 || list.back() == ',')  // getline yields no item for "" nor for the empty one after a last comma
    throw InputError(fmt::format("{}: an empty item {}", what, kKnown));
  if (none && family) throw InputError(fmt::format("{}: \"none\" cannot be combined with other families", what));
  return c;
}

LayerPlan plan_layers(const ComponentSelection& selection, const std::vector<std::string>& groups, int max_bounces) {
  LayerPlan plan;
  auto add = [&](std::string name) {
    plan.components.push_back(std::move(name));
    return static_cast<int>(plan.components.size());  // layer 0 is the total
  };
  if (selection.paths) {
    plan.emission = add("emission");
    plan.diffuse_direct = add("diffuse_direct");
    plan.diffuse_indirect = add("diffuse_indirect");
    plan.glossy_direct = add("glossy_direct");
    plan.glossy_indirect = add("glossy_indirect");
  }
  if (selection.lights)
    for (const std::string& g : groups) plan.light_group.push_back(add("light." + g));
  if (selection.bounces)
    for (int k = 0; k <= max_bounces; ++k) plan.bounce.push_back(add(fmt::format("bounce.{}", k)));
  return plan;
}

PathTracer::PathTracer(const TracerScene& scene, TracerSettings settings, LayerPlan layers)
    : scene_(scene), settings_(std::move(settings)), layers_(std::move(layers)) {
  const int n = static_cast<int>(settings_.bands.size());
  for (int first = 0; first < n; first += kMaxLanes) chunks_.push_back({first, std::min(kMaxLanes, n - first)});
  auto table = [&](const PiecewiseLinearSpectrum* s) {
    if (!s) return;
    for (const auto& entry : band_tables_)
      if (entry.first == s) return;
    band_tables_.emplace_back(s, band_averages(*s, settings_.bands));
  };
  for (std::size_t mesh = 0; mesh < scene.scene().objects.size() + scene.scene().lights.size(); ++mesh) {
    if (const TracerMaterial* m = scene.material_of(static_cast<std::uint32_t>(mesh))) {
      table(m->diffuse.spectrum);
      table(m->specular.spectrum);
    }
  }
  for (const TracerLight& light : scene.lights()) table(light.radiance.spectrum);
  if (scene.environment()) table(scene.environment()->radiance.spectrum);
  if (settings_.mode == SpectralMode::Bands) {
    // Each texel colour's spectrum in the form an {"rgb"} spectrum has (1 nm samples), averaged over each band
    // (texel_values, when first met).
    for (const TracerTexture& texture : scene.textures()) {
      const std::size_t entries = texture.spectra.palette.size();
      texture_bands_.push_back({std::unique_ptr<double[]>(new double[entries * settings_.bands.size()]),
                                std::make_unique<std::atomic<std::uint8_t>[]>(entries)});
    }
  }
}

Lanes PathTracer::texel_values(const ColourInput& in, std::size_t texel, const Chunk* chunk,
                               const Lanes& wavelengths) const {
  const TracerTexture& texture = scene_.textures()[static_cast<std::size_t>(in.texture)];
  const std::uint32_t entry = texture.spectra.palette_of[texel];
  if (chunk) {
    const TextureBands& table = texture_bands_[static_cast<std::size_t>(in.texture)];
    const std::size_t nb = settings_.bands.size();
    double* row = table.values.get() + static_cast<std::size_t>(entry) * nb;
    std::atomic<std::uint8_t>& state = table.state[entry];
    if (state.load(std::memory_order_acquire) != 2) {
      std::uint8_t expected = 0;
      if (state.compare_exchange_strong(expected, 1, std::memory_order_acq_rel)) {
        tabulated_band_averages(texture.spectra.palette[entry], settings_.bands, row);
        state.store(2, std::memory_order_release);
      } else if (expected != 2) {  // another thread is computing it: the same values, computed here too
        std::vector<double> own(nb);
        tabulated_band_averages(texture.spectra.palette[entry], settings_.bands, own.data());
        return Eigen::Map<const Eigen::ArrayXd>(own.data() + chunk->first_band, chunk->count) * in.scale;
      }
    }
    return Eigen::Map<const Eigen::ArrayXd>(row + chunk->first_band, chunk->count) * in.scale;
  }
  const ScaledSigmoid& s = texture.spectra.palette[entry];
  Lanes out(wavelengths.size());
  for (Eigen::Index i = 0; i < wavelengths.size(); ++i) out[i] = s.tabulated_at(wavelengths[i]) * in.scale;
  return out;
}

Lanes PathTracer::lane_values(const ColourInput& in, const Vec2& uv, const Chunk* chunk, const Lanes& wavelengths) const {
  if (in.texture < 0) return lane_values(*in.spectrum, chunk, wavelengths);
  const ImageTexture& image = *scene_.textures()[static_cast<std::size_t>(in.texture)].image;
  return texel_values(in, image.texel_at(uv.x(), uv.y()), chunk, wavelengths);
}

Lanes PathTracer::lane_values(const PiecewiseLinearSpectrum& s, const Chunk* chunk, const Lanes& wavelengths) const {
  if (chunk) {
    for (const auto& [spectrum, values] : band_tables_)
      if (spectrum == &s) return Eigen::Map<const Eigen::ArrayXd>(values.data() + chunk->first_band, chunk->count);
    throw std::logic_error("spectrum without a band table");
  }
  Lanes out(wavelengths.size());
  for (Eigen::Index i = 0; i < wavelengths.size(); ++i) out[i] = s(wavelengths[i]);
  return out;
}

std::pair<double, double> PathTracer::film_position(int x, int y, std::uint64_t stream) const {
  if (!settings_.box_filter) return {x + 0.5, y + 0.5};
  // Stratified over the pixel, as Cycles' sample pattern is: sample s is the s-th point of Roberts' R2
  // sequence (a low-discrepancy sequence every prefix of which covers the pixel evenly), shifted by a random
  // offset of the pixel's own (Cranley-Patterson rotation), so the estimate stays unbiased and pixels do not
  // share a pattern. Independent uniform positions would leave a pixel that straddles an edge with the
  // variance of a coin toss per path. The offset has its own stream so it does not shift the path's random
  // numbers.
  constexpr double kR2x = 0.75487766624669276;  // 1/g and 1/g², g the plastic number (1.3247...)
  constexpr double kR2y = 0.56984029099805327;
  const std::uint64_t pixel = stream >> 32, sample = stream & 0xFFFFFFFFull;
  Random rng(settings_.seed ^ 0x5DEECE66Dull, pixel);
  const double ox = rng.uniform(), oy = rng.uniform();
  const auto fraction = [](double v) { return v - std::floor(v); };
  const double s = static_cast<double>(sample);
  return {x + fraction(ox + s * kR2x), y + fraction(oy + s * kR2y)};
}

int PathTracer::object_id_at(int x, int y) const {
  const Camera& camera = scene_.scene().camera;
  const auto hit = scene_.accel().intersect(camera.position, camera.ray_direction(x + 0.5, y + 0.5),
                                            std::numeric_limits<double>::infinity());
  return hit ? static_cast<int>(hit->mesh) + 1 : 0;
}

void PathTracer::trace(double px, double py, std::uint64_t stream, PixelAccumulator& pixel) const {
  const Camera& camera = scene_.scene().camera;
  const Vec3 direction = camera.ray_direction(px, py);
  if (settings_.mode == SpectralMode::Bands) {
    // Every chunk of bands follows the same path (the same random numbers), as multiplexed bands do.
    for (const Chunk& chunk : chunks_) {
      Random rng(settings_.seed, stream);
      trace_lanes(camera.position, direction, rng, &chunk, pixel);
    }
  } else {
    Random rng(settings_.seed, stream);
    trace_lanes(camera.position, direction, rng, nullptr, pixel);
  }
}

// The state a path carries from one scattering event to the next.
struct PathTracer::Path {
  // The lanes. Bands mode: lane i is band chunk->first_band + i. Continuous mode (chunk null): lane j is a
  // hero wavelength, splatted into its band with weight range / (lanes · width) (an unbiased band average).
  const Chunk* chunk = nullptr;
  int lanes = 0;
  Lanes wavelengths;
  std::array<int, kMaxLanes> band_of{};
  Lanes splat_weight;
  // Throughput. Before the first scattering event the path is undivided and t_diffuse holds it (= 1); that
  // event splits it into the parts that left it diffusely and glossily, which are carried on separately.
  Lanes t_diffuse, t_glossy;
  // The ray to follow, and what the MIS weight of an emitter it hits needs: the solid-angle density with
  // which its direction was sampled, whether that was a delta lobe, and the point it left.
  Vec3 o, d;
  double prev_pdf = 0.0;
  bool prev_delta = true;  // the camera ray: emitters it sees are counted without MIS
  Vec3 prev_p;
};

// A scattering event: the hit seen from the side the ray arrived on, its shading frame, and the material's
// two spectral weights in the path's lanes.
struct PathTracer::Shading {
  SurfaceHit s;  // normals flipped towards the viewer
  const TracerMaterial* material;
  Frame frame;   // z = shading normal
  Vec3 wo;       // towards the viewer, in the frame
  Lanes rho_d;   // diffuse reflectance ρ_d (0 without a diffuse term)
  Lanes k_s;     // glossy weight k_s
};

// Camera ray: a path leaving the camera with throughput 1, carrying a chunk of bands or hero wavelengths.
PathTracer::Path PathTracer::start_path(const Vec3& origin, const Vec3& direction, Random& rng,
                                        const Chunk* chunk) const {
  const Bands& bands = settings_.bands;
  Path path;
  path.chunk = chunk;
  path.lanes = chunk ? chunk->count : kHeroLanes;
  const int lanes = path.lanes;
  path.wavelengths.resize(lanes);
  path.splat_weight = Lanes::Ones(lanes);
  if (chunk) {
    for (int i = 0; i < lanes; ++i) path.band_of[i] = chunk->first_band + i;
  } else {
    // Hero wavelengths: evenly spaced over the range from one random offset (the path's first number).
    const double lo = bands.min_wavelength(), range = bands.max_wavelength() - lo;
    const double u = rng.uniform();
    for (int j = 0; j < lanes; ++j) {
      const double t = std::fmod(u + static_cast<double>(j) / lanes, 1.0);
      path.wavelengths[j] = lo + t * range;
      const auto it = std::upper_bound(bands.edges().begin(), bands.edges().end(), path.wavelengths[j]);
      path.band_of[j] = std::clamp(static_cast<int>(it - bands.edges().begin()) - 1, 0, static_cast<int>(bands.size()) - 1);
      path.splat_weight[j] = range / (lanes * bands.width(static_cast<std::size_t>(path.band_of[j])));
    }
  }
  path.t_diffuse = Lanes::Ones(lanes);
  path.t_glossy = Lanes::Zero(lanes);
  path.o = origin;
  path.d = direction;
  path.prev_p = origin;
  return path;
}

// Film: adds a value per lane to one layer of the pixel, each lane into its band.
void PathTracer::splat(const Path& path, PixelAccumulator& pixel, int layer, const Lanes& value) const {
  if (layer < 0) return;
  double* out = pixel.layer(layer);
  for (int i = 0; i < path.lanes; ++i) out[path.band_of[i]] += value[i] * path.splat_weight[i];
}

// Accumulation into components: a contribution that arrived after `scatterings` events from `light`, split
// into the parts that left the first scattering event diffusely and glossily (or, before it, all emission).
void PathTracer::contribute(const Path& path, PixelAccumulator& pixel, int scatterings, int group,
                            const Lanes& diffuse_part, const Lanes& glossy_part) const {
  const Lanes total = diffuse_part + glossy_part;
  splat(path, pixel, 0, total);
  if (scatterings == 0) {
    splat(path, pixel, layers_.emission, total);
  } else if (scatterings == 1) {
    splat(path, pixel, layers_.diffuse_direct, diffuse_part);
    splat(path, pixel, layers_.glossy_direct, glossy_part);
  } else {
    splat(path, pixel, layers_.diffuse_indirect, diffuse_part);
    splat(path, pixel, layers_.glossy_indirect, glossy_part);
  }
  if (!layers_.light_group.empty()) splat(path, pixel, layers_.light_group[static_cast<std::size_t>(group)], total);
  if (!layers_.bounce.empty() && scatterings < static_cast<int>(layers_.bounce.size()))
    splat(path, pixel, layers_.bounce[static_cast<std::size_t>(scatterings)], total);
}

// Emission at a hit: radiance of an emitter the path reached by sampling a direction, MIS-weighted against
// next-event estimation having picked the same point (unweighted after the camera or a delta lobe, which
// next-event estimation cannot reproduce).
void PathTracer::add_emission(const Path& path, const SurfaceHit& s, int depth, PixelAccumulator& pixel) const {
  const Vec3 wo_world = -path.d;
  const TracerLight* light = scene_.light_of(s.mesh);
  if (!light || !TracerScene::emits_towards(*light, s.ng, wo_world)) return;
  double weight = 1.0;
  if (!path.prev_delta) {
    // The light-sampling density of this point, converted from area to solid angle at prev_p.
    const double dist2 = (s.p - path.prev_p).squaredNorm();
    const double pdf_light = scene_.light_pdf_area(*light) * dist2 / std::abs(s.ng.dot(wo_world));
    weight = power_heuristic(path.prev_pdf, pdf_light);
  }
  const Lanes le = lane_values(light->radiance, s.uv, path.chunk, path.wavelengths) * weight;
  if (depth == 0) contribute(path, pixel, 0, light->group, le, Lanes::Zero(path.lanes));
  else contribute(path, pixel, depth, light->group, path.t_diffuse * le, path.t_glossy * le);
}

// The environment seen by a path that leaves the scene: MIS-weighted against next-event estimation having
// sampled the same direction (unweighted after the camera or a delta lobe).
void PathTracer::add_environment(const Path& path, int depth, PixelAccumulator& pixel) const {
  const auto& env = scene_.environment();
  if (!env) return;
  double weight = 1.0;
  if (!path.prev_delta) weight = power_heuristic(path.prev_pdf, env->select_probability * scene_.environment_pdf(path.d.normalized()));
  const Lanes le = (env->radiance.texture >= 0
                        ? texel_values(env->radiance, scene_.environment_texel(path.d.normalized()), path.chunk, path.wavelengths)
                        : lane_values(*env->radiance.spectrum, path.chunk, path.wavelengths)) *
                   weight;
  if (depth == 0) contribute(path, pixel, 0, env->group, le, Lanes::Zero(path.lanes));
  else contribute(path, pixel, depth, env->group, path.t_diffuse * le, path.t_glossy * le);
}

// Shading setup: the material at a hit, seen from the side the ray arrived on. None when the path ends there:
// the surface only emits, or its shading normal is turned away from the viewer.
std::optional<PathTracer::Shading> PathTracer::shade(SurfaceHit s, const Path& path) const {
  const TracerMaterial* material = scene_.material_of(s.mesh);
  if (!material) return std::nullopt;
  const Vec3 wo_world = -path.d;
  // Surfaces are two-sided: shade the side the ray arrived from.
  if (s.ng.dot(wo_world) < 0.0) {
    s.ng = -s.ng;
    s.ns = -s.ns;
  }
  const Frame frame(s.ns);
  const Vec3 wo = frame.to_local(wo_world);
  if (wo.z() <= 0.0) return std::nullopt;
  const Lanes rho_d = material->diffuse ? lane_values(material->diffuse, s.uv, path.chunk, path.wavelengths)
                                        : Lanes::Zero(path.lanes);
  const Lanes k_s = material->specular ? lane_values(material->specular, s.uv, path.chunk, path.wavelengths)
                                       : Lanes::Constant(path.lanes, material->specular_weight);
  return Shading{s, material, frame, wo, rho_d, k_s};
}

// Next-event estimation: one point sampled on the lights (∝ power, then uniform in area), its radiance
// through the BSDF if unoccluded, MIS-weighted against BSDF sampling finding it.
void PathTracer::sample_direct(const Path& path, const Shading& at, int depth, Random& rng,
                               PixelAccumulator& pixel) const {
  // Drawn even where no light can be sampled, so that the path's later numbers do not depend on it.
  const double u_light = rng.uniform();
  const Vec2 u_point(rng.uniform(), rng.uniform());
  const TracerMaterial& material = *at.material;
  if (!material.diffuse && material.is_delta()) return;  // a pure mirror: no sampled light meets its delta lobe
  const auto ls = scene_.sample_light(u_light, u_point);
  if (!ls) return;
  Vec3 to_light;
  double pdf_light = 0.0;  // per solid angle
  if (ls->light) {
    to_light = ls->p - at.s.p;
    const double dist = to_light.norm();
    to_light /= dist;
    const double cos_light = std::abs(ls->n.dot(to_light));
    // The light point must emit towards us.
    if (!(dist > 0.0 && cos_light > 0.0 && TracerScene::emits_towards(*ls->light, ls->n, -to_light))) return;
    pdf_light = ls->pdf_area * dist * dist / cos_light;
  } else {
    to_light = ls->wi;
    pdf_light = ls->pdf_solid_angle;
  }
  // The light must lie above both the shading and the geometric surface.
  const Vec3 wi = at.frame.to_local(to_light);
  if (!(pdf_light > 0.0 && wi.z() > 0.0 && to_light.dot(at.s.ng) > 0.0)) return;
  const LobeValues f = evaluate(material, at.wo, wi);
  const double weight = power_heuristic(pdf_light, f.pdf);
  if (!(f.diffuse > 0.0 || f.glossy > 0.0)) return;  // the BSDF sends nothing that way
  // Shadow ray: occluded.
  if (ls->light ? !scene_.accel().visible(at.s.p, at.s.ng, ls->p, ls->n)
                : scene_.accel().occluded(offset_origin(at.s.p, at.s.ng, to_light, scene_.accel().scale()), to_light,
                                          std::numeric_limits<double>::infinity()))
    return;
  const ColourInput& radiance = ls->light ? ls->light->radiance : scene_.environment()->radiance;
  const Lanes le = (ls->light ? lane_values(radiance, ls->uv, path.chunk, path.wavelengths)
                    : radiance.texture >= 0 ? texel_values(radiance, ls->texel, path.chunk, path.wavelengths)
                                            : lane_values(*radiance.spectrum, path.chunk, path.wavelengths)) *
                   (weight / pdf_light);
  const int group = ls->light ? ls->light->group : scene_.environment()->group;
  const Lanes fd = at.rho_d * f.diffuse, fg = at.k_s * f.glossy;
  if (depth == 0) contribute(path, pixel, 1, group, fd * le, fg * le);
  else contribute(path, pixel, depth + 1, group, path.t_diffuse * (fd + fg) * le, path.t_glossy * (fd + fg) * le);
}

// BSDF sampling: the direction the path continues in, its throughput through this event, and the next ray.
// False when the path ends here (no direction, or one below the geometric surface).
bool PathTracer::sample_continuation(Path& path, const Shading& at, int depth, Random& rng) const {
  const double u_lobe = rng.uniform();
  const Vec2 u_dir(rng.uniform(), rng.uniform());
  const auto ms = sample_material(*at.material, at.wo, u_lobe, u_dir);
  if (!ms) return false;
  const Vec3 wi_world = at.frame.to_world(ms->wi);
  if (wi_world.dot(at.s.ng) <= 0.0) return false;
  const Lanes wd = at.rho_d * (ms->values.diffuse / ms->values.pdf);
  const Lanes wg = at.k_s * (ms->values.glossy / ms->values.pdf);
  if (depth == 0) {
    // The first event splits the undivided throughput into its diffuse and glossy parts.
    const Lanes throughput = path.t_diffuse + path.t_glossy;
    path.t_diffuse = throughput * wd;
    path.t_glossy = throughput * wg;
  } else {
    const Lanes w = wd + wg;
    path.t_diffuse *= w;
    path.t_glossy *= w;
  }
  path.prev_delta = ms->delta;
  path.prev_pdf = ms->values.pdf;
  path.prev_p = at.s.p;
  path.o = offset_origin(at.s.p, at.s.ng, wi_world, scene_.accel().scale());
  path.d = wi_world;
  return true;
}

// Russian roulette from the third event on: survive with probability q, divide by q. False: the path ends.
bool PathTracer::survives_roulette(Path& path, int depth, Random& rng) {
  if (depth < 2) return true;
  const double q = std::min(0.95, (path.t_diffuse + path.t_glossy).maxCoeff());
  if (rng.uniform() >= q) return false;
  path.t_diffuse /= q;
  path.t_glossy /= q;
  return true;
}

// One path from the camera; `depth` counts the scattering events before the current hit.
void PathTracer::trace_lanes(const Vec3& origin, const Vec3& direction, Random& rng, const Chunk* chunk,
                             PixelAccumulator& pixel) const {
  Path path = start_path(origin, direction, rng, chunk);
  for (int depth = 0;; ++depth) {
    // Intersection: the path leaves the scene if the ray hits nothing, and sees the environment if there is one.
    const auto hit = scene_.accel().intersect(path.o, path.d, std::numeric_limits<double>::infinity());
    if (!hit) {
      add_environment(path, depth, pixel);
      break;
    }
    const SurfaceHit s = scene_.surface(*hit);
    add_emission(path, s, depth, pixel);
    if (depth >= settings_.max_bounces) break;
    const std::optional<Shading> at = shade(s, path);
    if (!at) break;
    sample_direct(path, *at, depth, rng, pixel);
    if (!sample_continuation(path, *at, depth, rng)) break;
    if (!survives_roulette(path, depth, rng)) break;
  }
}

}  // namespace ct::rt
