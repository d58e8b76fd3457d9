// SPDX-License-Identifier: Apache-2.0
#include "plan/radiosity.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>

#include <fmt/core.h>

#include "core/random.h"
#include "reference_tracer/accel.h"
#include "reference_tracer/principled.h"

namespace ct::plan {

// How many colours a textured surface is seen as (texture_colours; each of its pixels in the preview shows one).
constexpr std::size_t kTextureColours = 16;

namespace {

// Points spread uniformly over a mesh's area: a triangle chosen in proportion to its area, then a uniform point of it,
// barycentric (1 − u − v, u, v).
class AreaSampler {
 public:
  explicit AreaSampler(const TriangleMesh& mesh) {
    for (std::size_t tri = 0; tri < mesh.triangles.size(); ++tri) cdf_.push_back(area_ += triangle_area(mesh, tri));
  }
  double area() const { return area_; }
  struct Point {
    std::size_t triangle;
    double u, v;
  };
  Point sample(Random& rng) const {
    const double pick = rng.uniform() * area_;
    const std::size_t tri = std::min<std::size_t>(
        static_cast<std::size_t>(std::upper_bound(cdf_.begin(), cdf_.end(), pick) - cdf_.begin()), cdf_.size() - 1);
    double u = rng.uniform(), v = rng.uniform();
    if (u + v > 1) u = 1 - u, v = 1 - v;
    return {tri, u, v};
  }

 private:
  std::vector<double> cdf_;
  double area_ = 0;
};

}  // namespace

Transfer transfer_factors(const Scene& scene, const std::vector<TriangleMesh>& meshes, int samples) {
  std::vector<const TriangleMesh*> ptrs;
  for (const TriangleMesh& m : meshes) ptrs.push_back(&m);
  const rt::Accelerator accel(ptrs);
  const std::size_t ids = meshes.size() + 1, objects = scene.objects.size();
  Transfer t;
  t.hits.assign(ids, std::vector<double>(ids, 0.0));
  t.lit.assign(ids, std::vector<double>(scene.lights.size(), 0.0));
  for (std::size_t m = 0; m < meshes.size(); ++m) {
    const TriangleMesh& mesh = meshes[m];
    const AreaSampler points(mesh);
    if (!(points.area() > 0)) continue;
    std::array<std::vector<double>, 2> hits{std::vector<double>(ids, 0.0), std::vector<double>(ids, 0.0)};
    std::array<std::vector<double>, 2> lit{std::vector<double>(scene.lights.size(), 0.0),
                                           std::vector<double>(scene.lights.size(), 0.0)};
    Random rng(0x706c616eull, m);
    for (int i = 0; i < samples; ++i) {
      const auto [tri, u, v] = points.sample(rng);
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


namespace {

// A texture's texels pooled by colour (reflectances on a grid of 1/64 per channel; radiances by chromaticity,
// rgb / max, on that grid, their magnitudes summed): within a pool the spectra differ by less than the sigmoid's
// change over 1/64 of a channel.
struct Pool {
  double weight = 0, magnitude = 0;
  std::array<double, 3> colour{};  // the weighted mean (of rgb, or rgb / max for a radiance)
};

std::vector<Pool> texel_pools(const ImageTexture& texture, const std::vector<double>& weight, double& total) {
  constexpr int kLevels = 64;
  const bool radiance = texture.use == TextureUse::Radiance;
  std::map<std::uint32_t, Pool> pools;  // ordered: sums over it do not depend on hashing
  total = 0;
  for (std::size_t t = 0; t < texture.texel_count(); ++t) {
    const double w = t < weight.size() ? weight[t] : 0.0;
    if (!(w > 0)) continue;
    total += w;
    std::array<double, 3> c = texture.texel(t);
    const double m = std::max({c[0], c[1], c[2]});
    if (!(m > 0)) continue;  // black: no light, and a zero reflectance
    if (radiance)
      for (double& x : c) x /= m;
    std::uint32_t key = 0;
    for (double x : c) key = key * (kLevels + 1) + static_cast<std::uint32_t>(std::lround(std::clamp(x, 0.0, 1.0) * kLevels));
    Pool& pool = pools[key];
    pool.weight += w;
    pool.magnitude += w * (radiance ? m : 1.0);
    for (int i = 0; i < 3; ++i) pool.colour[i] += w * c[i];
  }
  std::vector<Pool> out;
  for (auto& [key, pool] : pools) {
    for (double& x : pool.colour) x /= pool.weight;
    out.push_back(pool);
  }
  return out;
}

// Σ magnitude · spectrum of the pools `members`, on the 1 nm grid 360–830 nm.
std::vector<double> pooled_spectrum(const ImageTexture& texture, const std::vector<Pool>& pools,
                                    const std::vector<std::size_t>& members) {
  std::vector<double> v(471, 0.0);
  for (const std::size_t m : members) {
    const ScaledSigmoid s = texel_spectrum(pools[m].colour, texture.use);
    for (std::size_t j = 0; j < v.size(); ++j) v[j] += pools[m].magnitude * s(360.0 + static_cast<double>(j));
  }
  return v;
}

PiecewiseLinearSpectrum on_grid(std::vector<double> v, double factor) {
  std::vector<double> nm(v.size());
  for (std::size_t j = 0; j < v.size(); ++j) nm[j] = 360.0 + static_cast<double>(j), v[j] *= factor;
  return PiecewiseLinearSpectrum(nm, v);
}

}  // namespace

PiecewiseLinearSpectrum mean_texture_spectrum(const ImageTexture& texture, const std::vector<double>& weight) {
  double total = 0;
  const std::vector<Pool> pools = texel_pools(texture, weight, total);
  std::vector<std::size_t> all(pools.size());
  std::iota(all.begin(), all.end(), std::size_t{0});
  return on_grid(pooled_spectrum(texture, pools, all), total > 0 ? texture.scale / total : 0.0);
}

std::vector<TextureColour> texture_colours(const ImageTexture& texture, const std::vector<double>& weight,
                                           std::size_t count) {
  double total = 0;
  const std::vector<Pool> pools = texel_pools(texture, weight, total);
  if (pools.empty() || !(total > 0)) return {};
  // Weighted k-means over the pools' colours, seeded deterministically: the heaviest pool, then each time the pool
  // farthest from every centre so far (weighted by its share), then ten rounds of assignment and update.
  const std::size_t k = std::min(count, pools.size());
  auto distance2 = [](const std::array<double, 3>& a, const std::array<double, 3>& b) {
    return (a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]);
  };
  std::vector<std::array<double, 3>> centre;
  std::size_t first = 0;
  for (std::size_t i = 1; i < pools.size(); ++i)
    if (pools[i].weight > pools[first].weight) first = i;
  centre.push_back(pools[first].colour);
  std::vector<double> nearest(pools.size(), std::numeric_limits<double>::infinity());
  while (centre.size() < k) {
    std::size_t far = 0;
    double best = -1;
    for (std::size_t i = 0; i < pools.size(); ++i) {
      nearest[i] = std::min(nearest[i], distance2(pools[i].colour, centre.back()));
      if (pools[i].weight * nearest[i] > best) best = pools[i].weight * nearest[i], far = i;
    }
    centre.push_back(pools[far].colour);
  }
  std::vector<std::size_t> cluster(pools.size(), 0);
  for (int round = 0; round < 10; ++round) {
    for (std::size_t i = 0; i < pools.size(); ++i)
      for (std::size_t c = 1; c < k; ++c)
        if (distance2(pools[i].colour, centre[c]) < distance2(pools[i].colour, centre[cluster[i]])) cluster[i] = c;
    std::vector<std::array<double, 4>> sum(k, {0.0, 0.0, 0.0, 0.0});
    for (std::size_t i = 0; i < pools.size(); ++i) {
      for (int j = 0; j < 3; ++j) sum[cluster[i]][j] += pools[i].weight * pools[i].colour[j];
      sum[cluster[i]][3] += pools[i].weight;
    }
    for (std::size_t c = 0; c < k; ++c)
      if (sum[c][3] > 0) centre[c] = {sum[c][0] / sum[c][3], sum[c][1] / sum[c][3], sum[c][2] / sum[c][3]};
  }
  std::vector<TextureColour> out;
  for (std::size_t c = 0; c < k; ++c) {
    std::vector<std::size_t> members;
    double w = 0;
    for (std::size_t i = 0; i < pools.size(); ++i)
      if (cluster[i] == c) members.push_back(i), w += pools[i].weight;
    if (members.empty()) continue;
    out.push_back({w / total, on_grid(pooled_spectrum(texture, pools, members), texture.scale / w)});
  }
  double seen = 0;
  for (const Pool& p : pools) seen += p.weight;
  if (seen < total) out.push_back({(total - seen) / total, on_grid(std::vector<double>(471, 0.0), 0.0)});  // black
  return out;
}

std::vector<std::array<Vec2, 3>> light_corner_uvs(const Light& light) {
  return std::visit([](const auto& shape) { return corner_uvs(Shape(shape)); }, light.shape);
}

std::vector<double> surface_texel_weights(const TriangleMesh& mesh, const std::vector<std::array<Vec2, 3>>& uvs,
                                          const ImageTexture& texture) {
  constexpr int kPoints = 16384;  // a texel's share to ±1/(2·√16384) ≈ 0.4 % of the surface at most
  std::vector<double> weight(texture.texel_count(), 0.0);
  const AreaSampler points(mesh);
  if (uvs.size() != mesh.triangles.size() || !(points.area() > 0)) {
    std::fill(weight.begin(), weight.end(), 1.0);
    return weight;
  }
  Random rng(0x74657865ull, 0);
  for (int i = 0; i < kPoints; ++i) {
    const auto [tri, a, b] = points.sample(rng);
    const auto& c = uvs[tri];
    const Vec2 uv = (1 - a - b) * c[0] + a * c[1] + b * c[2];
    weight[texture.texel_at(uv.x(), uv.y())] += 1;
  }
  return weight;
}

std::vector<double> environment_texel_weights(const ImageTexture& texture) {
  std::vector<double> weight(texture.texel_count());
  for (int y = 0; y < texture.height; ++y) {
    const double w = std::sin(M_PI * (y + 0.5) / texture.height);
    std::fill_n(weight.begin() + static_cast<std::ptrdiff_t>(y) * texture.width, texture.width, w);
  }
  return weight;
}

PiecewiseLinearSpectrum emitted_mean_radiance(const Light& light, const TriangleMesh& mesh) {
  if (!light.radiance.texture) return light.emitted_radiance();
  const ImageTexture& t = *light.radiance.texture;
  return mean_texture_spectrum(t, surface_texel_weights(mesh, light_corner_uvs(light), t)).scaled(light.scale);
}

PiecewiseLinearSpectrum mean_environment_radiance(const Environment& environment) {
  if (!environment.radiance.texture) return environment.radiance.spectrum.scaled(environment.scale);
  const ImageTexture& t = *environment.radiance.texture;
  return mean_texture_spectrum(t, environment_texel_weights(t)).scaled(environment.scale);
}

SceneSurfaces scene_surfaces(const Scene& scene, const std::vector<TriangleMesh>& meshes, const Grid& grid,
                             const Sampled& light, bool reconstruction, std::vector<std::string>& notes) {
  SceneSurfaces out;
  auto sampled = [&](const PiecewiseLinearSpectrum& s) { return grid.sample([&](double nm) { return s(nm); }); };
  std::vector<std::pair<double, Sampled>> colours;  // the last texture's (spectrum_of)
  auto spectrum_of = [&](const SpectrumRef& ref, const std::string& what, const TriangleMesh& mesh,
                         const std::vector<std::array<Vec2, 3>>& uvs) -> Sampled {
    colours.clear();
    if (ref.texture) {
      if (reconstruction && !out.textured)
        notes.push_back(fmt::format("{} is an image texture, whose texels' spectra the model does not hold: no "
                                    "reconstruction is fitted (the bands' values are read as a step function)", what));
      out.textured = true;
      notes.push_back(fmt::format("{} is an image texture: modelled as its texels' mean spectrum over the surface, "
                                  "seen as up to {} colours", what, kTextureColours));
      // The mean is the colours' spectra at their shares (texture_colours), so the texels are pooled once.
      Sampled mean = grid.constant(0.0);
      for (const TextureColour& c : texture_colours(*ref.texture, surface_texel_weights(mesh, uvs, *ref.texture),
                                                    kTextureColours)) {
        colours.emplace_back(c.share, sampled(c.spectrum));
        for (std::size_t i = 0; i < mean.v.size(); ++i) mean.v[i] += c.share * colours.back().second.v[i];
      }
      Grid::finish(mean);
      return mean;
    }
    return sampled(ref.spectrum);
  };
  const Sampled zero = grid.constant(0.0);
  const Sampled one = grid.constant(1.0);

  std::vector<double> albedo(grid.n(), 0.0);
  double area_sum = 0;
  std::vector<Surface>& surfaces = out.surfaces;
  surfaces.assign(static_cast<std::size_t>(scene.id_count()) + 1, Surface{zero, zero, zero, zero, false, {}});
  auto add_material = [&](std::size_t id, const Material& m, const TriangleMesh& mesh,
                          const std::vector<std::array<Vec2, 3>>& uvs) {
    const double area = surface_area(mesh);
    Surface& s = surfaces[id];
    s.diffuse = spectrum_of(m.reflectance_spectrum(), fmt::format("materials.{}", m.name), mesh, uvs);
    s.colours = colours;
    double ks = 0;
    bool mirror = false;
    if (auto* d = std::get_if<DichromaticMaterial>(&m.model)) {
      ks = d->specular;
      s.glossy = one;
    } else if (std::holds_alternative<MirrorMaterial>(m.model)) {
      s.glossy = s.diffuse;
      s.diffuse = zero;
      mirror = true;
    } else if (auto* p = std::get_if<PrincipledMaterial>(&m.model)) {
      // The interface reflects its average Fresnel, spectrally flat, beside the base's colour (which Cycles dims
      // by a few per cent under it: the model keeps it whole).
      ks = rt::average_fresnel_dielectric(p->effective_ior());
      s.glossy = one;
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
    add_material(o + 1, scene.materials[scene.objects[o].material], meshes[o], corner_uvs(scene.objects[o].shape));
  for (std::size_t l = 0; l < scene.lights.size(); ++l) {
    const std::size_t id = scene.objects.size() + l + 1;
    const Light& light_l = scene.lights[l];
    if (light_l.material) add_material(id, scene.materials[*light_l.material], meshes[id - 1], light_corner_uvs(light_l));
    surfaces[id].emitter = true;
    if (light_l.radiance.texture)
      notes.push_back(fmt::format("lights[{}].radiance is an image texture: modelled as its texels' mean spectrum "
                                  "over the light", l));
    surfaces[id].emission = sampled(emitted_mean_radiance(light_l, meshes[id - 1]));
  }
  out.mean_albedo.v = albedo;
  for (double& a : out.mean_albedo.v) a /= std::max(area_sum, 1e-300);
  Grid::finish(out.mean_albedo);
  // The background: what the environment (or, in edge pixels, any surface) sends.
  surfaces[0].emission = light;
  surfaces[0].diffuse = out.mean_albedo;
  surfaces[0].glossy = out.mean_albedo;
  if (scene.environment) {
    out.has_environment = true;
    if (scene.environment->radiance.texture)
      notes.push_back("environment.radiance is an image texture: modelled as its texels' mean spectrum over the "
                      "sphere of directions");
    out.environment = sampled(mean_environment_radiance(*scene.environment));
    surfaces[0].emission = out.environment;
  }
  return out;
}

Templates bounce_templates(const Basis& b, const Transfer& t, int kmax, TemplateSpectra* spectra) {
  const std::size_t ids = b.emission.size(), n = b.size(), lights = t.lit.empty() ? 0 : t.lit[0].size();
  const std::size_t first_light = ids - lights;
  Templates out(ids, std::vector<std::array<Vec3d, 2>>(kmax + 1));
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

}  // namespace ct::plan
