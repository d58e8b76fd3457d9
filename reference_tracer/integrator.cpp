#include "reference_tracer/integrator.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include <fmt/core.h>

#include "core/error.h"
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
    v.diffuse = lambert.eval(wo, wi);
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
  for (const Material& material : scene.scene().materials) (void)material;
  for (std::size_t mesh = 0; mesh < scene.scene().objects.size() + scene.scene().lights.size(); ++mesh) {
    if (const TracerMaterial* m = scene.material_of(static_cast<std::uint32_t>(mesh))) {
      table(m->diffuse);
      table(m->specular);
    }
  }
  for (const TracerLight& light : scene.lights()) table(&light.radiance);
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
  // The pixel position uses its own stream so it does not shift the path's random numbers.
  Random rng(settings_.seed ^ 0x5DEECE66Dull, stream);
  return {x + rng.uniform(), y + rng.uniform()};
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

void PathTracer::trace_lanes(const Vec3& origin, const Vec3& direction, Random& rng, const Chunk* chunk,
                             PixelAccumulator& pixel) const {
  const Bands& bands = settings_.bands;
  const int lanes = chunk ? chunk->count : kHeroLanes;

  // Where each lane's value goes: bands mode, lane i is band first + i; continuous mode, lane j is a hero
  // wavelength, splatted into its band with weight range / (lanes · width) (an unbiased band average).
  Lanes wavelengths(lanes);
  std::array<int, kMaxLanes> band_of{};
  Lanes splat_weight = Lanes::Ones(lanes);
  if (chunk) {
    for (int i = 0; i < lanes; ++i) band_of[i] = chunk->first_band + i;
  } else {
    const double lo = bands.min_wavelength(), range = bands.max_wavelength() - lo;
    const double u = rng.uniform();
    for (int j = 0; j < lanes; ++j) {
      const double t = std::fmod(u + static_cast<double>(j) / lanes, 1.0);
      wavelengths[j] = lo + t * range;
      const auto it = std::upper_bound(bands.edges().begin(), bands.edges().end(), wavelengths[j]);
      band_of[j] = std::clamp(static_cast<int>(it - bands.edges().begin()) - 1, 0, static_cast<int>(bands.size()) - 1);
      splat_weight[j] = range / (lanes * bands.width(static_cast<std::size_t>(band_of[j])));
    }
  }
  auto splat = [&](int layer, const Lanes& value) {
    if (layer < 0) return;
    double* out = pixel.layer(layer);
    for (int i = 0; i < lanes; ++i) out[band_of[i]] += value[i] * splat_weight[i];
  };

  // Adds a contribution that arrived after `scatterings` events from light `light`, split into the parts
  // that left the first scattering event diffusely and glossily (or, before it, all emission).
  auto contribute = [&](int scatterings, const TracerLight& light, const Lanes& diffuse_part, const Lanes& glossy_part) {
    const Lanes total = diffuse_part + glossy_part;
    splat(0, total);
    if (scatterings == 0) {
      splat(layers_.emission, total);
    } else if (scatterings == 1) {
      splat(layers_.diffuse_direct, diffuse_part);
      splat(layers_.glossy_direct, glossy_part);
    } else {
      splat(layers_.diffuse_indirect, diffuse_part);
      splat(layers_.glossy_indirect, glossy_part);
    }
    if (!layers_.light_group.empty()) splat(layers_.light_group[static_cast<std::size_t>(light.group)], total);
    if (!layers_.bounce.empty() && scatterings < static_cast<int>(layers_.bounce.size()))
      splat(layers_.bounce[static_cast<std::size_t>(scatterings)], total);
  };

  const Lanes zero = Lanes::Zero(lanes);
  // Throughput before the first scattering event is 1; after it, the diffuse and glossy parts.
  Lanes t_diffuse = Lanes::Ones(lanes), t_glossy = zero;
  Vec3 o = origin, d = direction;
  double prev_pdf = 0.0;
  bool prev_delta = true;  // the camera ray: emitters it sees are counted without MIS
  Vec3 prev_p = origin;
  const double scale = scene_.accel().scale();

  for (int depth = 0;; ++depth) {
    const auto hit = scene_.accel().intersect(o, d, std::numeric_limits<double>::infinity());
    if (!hit) break;
    SurfaceHit s = scene_.surface(*hit);
    const Vec3 wo_world = -d;

    if (const TracerLight* light = scene_.light_of(s.mesh); light && TracerScene::emits_towards(*light, s.ng, wo_world)) {
      double weight = 1.0;
      if (!prev_delta) {
        const double dist2 = (s.p - prev_p).squaredNorm();
        const double pdf_light = scene_.light_pdf_area(*light) * dist2 / std::abs(s.ng.dot(wo_world));
        weight = power_heuristic(prev_pdf, pdf_light);
      }
      const Lanes le = lane_values(light->radiance, chunk, wavelengths) * weight;
      if (depth == 0) contribute(0, *light, le, zero);
      else contribute(depth, *light, t_diffuse * le, t_glossy * le);
    }
    if (depth >= settings_.max_bounces) break;
    const TracerMaterial* material = scene_.material_of(s.mesh);
    if (!material) break;

    // Surfaces are two-sided: shade the side the ray arrived from.
    if (s.ng.dot(wo_world) < 0.0) {
      s.ng = -s.ng;
      s.ns = -s.ns;
    }
    const Frame frame(s.ns);
    const Vec3 wo = frame.to_local(wo_world);
    if (wo.z() <= 0.0) break;  // shading normal turned away from the viewer
    const Lanes rho_d = material->diffuse ? lane_values(*material->diffuse, chunk, wavelengths) : zero;
    const Lanes k_s = material->specular ? lane_values(*material->specular, chunk, wavelengths)
                                         : Lanes::Constant(lanes, material->specular_weight);
    // Before the first event the path is undivided (t_diffuse holds it); the event splits it.
    const bool first = depth == 0;
    const Lanes throughput = t_diffuse + t_glossy;

    // Next-event estimation.
    const double u_light = rng.uniform();
    const Vec2 u_point(rng.uniform(), rng.uniform());
    if (material->diffuse || !material->is_delta()) {
      if (const auto ls = scene_.sample_light(u_light, u_point)) {
        Vec3 to_light = ls->p - s.p;
        const double dist = to_light.norm();
        to_light /= dist;
        const double cos_light = std::abs(ls->n.dot(to_light));
        const Vec3 wi = frame.to_local(to_light);
        if (dist > 0.0 && cos_light > 0.0 && wi.z() > 0.0 && to_light.dot(s.ng) > 0.0 &&
            TracerScene::emits_towards(*ls->light, ls->n, -to_light)) {
          const LobeValues f = evaluate(*material, wo, wi);
          const double pdf_light = ls->pdf_area * dist * dist / cos_light;
          const double weight = material->is_delta() && !material->diffuse ? 1.0 : power_heuristic(pdf_light, f.pdf);
          if ((f.diffuse > 0.0 || f.glossy > 0.0) &&
              scene_.accel().visible(s.p, s.ng, ls->p, ls->n)) {
            const Lanes le = lane_values(ls->light->radiance, chunk, wavelengths) * (weight / pdf_light);
            const Lanes fd = rho_d * f.diffuse, fg = k_s * f.glossy;
            if (first) contribute(1, *ls->light, fd * le, fg * le);
            else contribute(depth + 1, *ls->light, t_diffuse * (fd + fg) * le, t_glossy * (fd + fg) * le);
          }
        }
      }
    }

    // Continue the path by sampling the material.
    const double u_lobe = rng.uniform();
    const Vec2 u_dir(rng.uniform(), rng.uniform());
    const auto ms = sample_material(*material, wo, u_lobe, u_dir);
    if (!ms) break;
    const Vec3 wi_world = frame.to_world(ms->wi);
    if (wi_world.dot(s.ng) <= 0.0) break;
    const Lanes wd = rho_d * (ms->values.diffuse / ms->values.pdf);
    const Lanes wg = k_s * (ms->values.glossy / ms->values.pdf);
    if (first) {
      t_diffuse = throughput * wd;
      t_glossy = throughput * wg;
    } else {
      const Lanes w = wd + wg;
      t_diffuse *= w;
      t_glossy *= w;
    }
    prev_delta = ms->delta;
    prev_pdf = ms->values.pdf;
    prev_p = s.p;

    // Russian roulette from the third event on: survive with probability q, divide by q.
    if (depth >= 2) {
      const double q = std::min(0.95, (t_diffuse + t_glossy).maxCoeff());
      if (rng.uniform() >= q) break;
      t_diffuse /= q;
      t_glossy /= q;
    }
    o = offset_origin(s.p, s.ng, wi_world, scale);
    d = wi_world;
  }
}

}  // namespace ct::rt
