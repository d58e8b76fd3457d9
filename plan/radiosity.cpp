// SPDX-License-Identifier: Apache-2.0
#include "plan/radiosity.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/core.h>

#include "core/random.h"
#include "reference_tracer/accel.h"

namespace ct::plan {

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


SceneSurfaces scene_surfaces(const Scene& scene, const std::vector<TriangleMesh>& meshes, const Grid& grid,
                             const Sampled& light, bool reconstruction, std::vector<std::string>& notes) {
  SceneSurfaces out;
  auto spectrum_of = [&](const SpectrumRef& ref, const std::string& what) -> Sampled {
    if (ref.texture) {
      if (reconstruction && !out.textured)
        notes.push_back(fmt::format("{} is an image texture, whose spectra the model does not hold: no reconstruction "
                                    "is fitted (the bands' values are read as a step function)", what));
      out.textured = true;
      notes.push_back(fmt::format("{} is an image texture: modelled as a flat reflectance of 0.5", what));
      return grid.constant(0.5);
    }
    return grid.sample([&](double nm) { return ref.spectrum(nm); });
  };
  const Sampled zero = grid.constant(0.0);
  const Sampled one = grid.constant(1.0);

  std::vector<double> albedo(grid.n(), 0.0);
  double area_sum = 0;
  std::vector<Surface>& surfaces = out.surfaces;
  surfaces.assign(static_cast<std::size_t>(scene.id_count()) + 1, Surface{zero, zero, zero, zero, false});
  auto add_material = [&](std::size_t id, const Material& m, double area) {
    Surface& s = surfaces[id];
    s.diffuse = spectrum_of(m.reflectance_spectrum(), fmt::format("materials.{}", m.name));
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
    surfaces[id].emitter = true;
    if (light_l.radiance.texture) {
      notes.push_back(fmt::format("lights[{}].radiance is an image texture: modelled as the scene's light", l));
      surfaces[id].emission = light;
    } else {
      const PiecewiseLinearSpectrum e = light_l.emitted_radiance();
      surfaces[id].emission = grid.sample([&](double nm) { return e(nm); });
    }
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
    if (scene.environment->radiance.texture) {
      notes.push_back("environment.radiance is an image texture: modelled as the scene's light spectrum");
      out.environment = light;
    } else {
      const PiecewiseLinearSpectrum e = scene.environment->radiance.spectrum.scaled(scene.environment->scale);
      out.environment = grid.sample([&](double nm) { return e(nm); });
    }
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
