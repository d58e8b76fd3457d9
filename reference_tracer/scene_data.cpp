#include "reference_tracer/scene_data.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "core/error.h"

namespace ct::rt {
namespace {

// Mean of a spectrum over the visible range, used only to balance sampling decisions (never a result).
double visible_mean(const PiecewiseLinearSpectrum& s) { return s.average(380.0, 780.0); }

TracerMaterial make_material(const Material& material) {
  TracerMaterial m;
  if (const auto* lambert = std::get_if<LambertMaterial>(&material.model)) {
    m.diffuse = &lambert->reflectance.spectrum;
  } else if (const auto* dichromatic = std::get_if<DichromaticMaterial>(&material.model)) {
    m.diffuse = &dichromatic->diffuse.spectrum;
    m.specular_weight = dichromatic->specular;
    if (const auto* ggx = std::get_if<DichromaticMaterial::Ggx>(&dichromatic->lobe)) {
      // Roughness 0 is a perfect mirror lobe (the scene format's convention, as in Cycles).
      if (ggx->roughness > 0.0)
        m.glossy = rt::GgxLobe{ggx->alpha(), ggx->masking == DichromaticMaterial::Masking::HeightCorrelated};
      else m.glossy = MirrorLobe{};
    } else {
      m.glossy = rt::PhongLobe{std::get<DichromaticMaterial::Phong>(dichromatic->lobe).exponent};
    }
    const double body = visible_mean(*m.diffuse);
    m.glossy_probability = m.specular_weight > 0.0 ? m.specular_weight / (m.specular_weight + body) : 0.0;
    if (body <= 0.0 && m.specular_weight > 0.0) m.glossy_probability = 1.0;
  } else {
    const auto& mirror = std::get<MirrorMaterial>(material.model);
    m.specular = &mirror.reflectance.spectrum;
    m.glossy = MirrorLobe{};
    m.glossy_probability = 1.0;
  }
  return m;
}

}  // namespace

TracerScene::TracerScene(const Scene& scene) : scene_(scene), meshes_(scene_meshes(scene)) {
  std::vector<const TriangleMesh*> pointers;
  for (const TriangleMesh& m : meshes_) pointers.push_back(&m);
  accel_ = std::make_unique<Accelerator>(pointers);

  for (const Material& material : scene.materials) materials_.push_back(make_material(material));
  mesh_material_.assign(meshes_.size(), -1);
  mesh_light_.assign(meshes_.size(), -1);
  for (std::size_t i = 0; i < scene.objects.size(); ++i) mesh_material_[i] = static_cast<int>(scene.objects[i].material);

  double total_power = 0.0;
  for (std::size_t l = 0; l < scene.lights.size(); ++l) {
    const Light& light = scene.lights[l];
    const std::uint32_t mesh = static_cast<std::uint32_t>(scene.objects.size() + l);
    if (light.material) mesh_material_[mesh] = static_cast<int>(*light.material);
    mesh_light_[mesh] = static_cast<int>(lights_.size());

    TracerLight tl;
    tl.light = &light;
    tl.mesh = mesh;
    tl.radiance = light.emitted_radiance();
    const TriangleMesh& m = meshes_[mesh];
    double area = 0.0;
    for (std::size_t t = 0; t < m.triangles.size(); ++t) {
      area += triangle_area(m, t);
      tl.triangle_cdf.push_back(area);
    }
    for (double& c : tl.triangle_cdf) c /= area;
    tl.area = area;
    const std::string group = light.group.empty() ? light.name : light.group;
    auto it = std::find(groups_.begin(), groups_.end(), group);
    tl.group = static_cast<int>(it - groups_.begin());
    if (it == groups_.end()) groups_.push_back(group);
    // Power ∝ mean radiance × area × (sides); only its proportions matter.
    const double power = std::max(0.0, visible_mean(tl.radiance)) * area * (light.two_sided ? 2.0 : 1.0);
    total_power += power;
    light_cdf_.push_back(total_power);
    lights_.push_back(std::move(tl));
  }
  for (std::size_t l = 0; l < lights_.size(); ++l) {
    if (total_power > 0.0) light_cdf_[l] /= total_power;
    else light_cdf_[l] = (l + 1.0) / static_cast<double>(lights_.size());
    lights_[l].select_probability = light_cdf_[l] - (l == 0 ? 0.0 : light_cdf_[l - 1]);
  }
}

const TracerMaterial* TracerScene::material_of(std::uint32_t mesh) const {
  const int m = mesh_material_[mesh];
  return m < 0 ? nullptr : &materials_[static_cast<std::size_t>(m)];
}

const TracerLight* TracerScene::light_of(std::uint32_t mesh) const {
  const int l = mesh_light_[mesh];
  return l < 0 ? nullptr : &lights_[static_cast<std::size_t>(l)];
}

SurfaceHit TracerScene::surface(const Hit& hit) const {
  const TriangleMesh& m = meshes_[hit.mesh];
  const auto& tri = m.triangles[hit.triangle];
  const Vec3& a = m.positions[tri[0]];
  const Vec3& b = m.positions[tri[1]];
  const Vec3& c = m.positions[tri[2]];
  SurfaceHit s;
  // Position from the barycentrics in double precision, rather than origin + t·direction in float.
  s.p = (1.0 - hit.u - hit.v) * a + hit.u * b + hit.v * c;
  s.ng = (b - a).cross(c - a).normalized();
  if (m.normals.empty()) {
    s.ns = s.ng;
  } else {
    const Vec3 n = (1.0 - hit.u - hit.v) * m.normals[tri[0]] + hit.u * m.normals[tri[1]] + hit.v * m.normals[tri[2]];
    s.ns = n.normalized();
    if (s.ns.dot(s.ng) < 0.0) s.ns = -s.ns;
  }
  s.mesh = hit.mesh;
  s.object_id = static_cast<int>(hit.mesh) + 1;
  return s;
}

std::optional<LightSample> TracerScene::sample_light(double u1, const Vec2& u2) const {
  if (lights_.empty()) return std::nullopt;
  std::size_t l = static_cast<std::size_t>(std::lower_bound(light_cdf_.begin(), light_cdf_.end(), u1) - light_cdf_.begin());
  l = std::min(l, lights_.size() - 1);
  const TracerLight& light = lights_[l];
  if (light.select_probability <= 0.0) return std::nullopt;
  // Reuse u1 within the chosen light's interval to pick the triangle (keeps the sample 3-dimensional).
  const double lo = l == 0 ? 0.0 : light_cdf_[l - 1];
  const double v = std::clamp((u1 - lo) / light.select_probability, 0.0, std::nextafter(1.0, 0.0));
  std::size_t t = static_cast<std::size_t>(
      std::lower_bound(light.triangle_cdf.begin(), light.triangle_cdf.end(), v) - light.triangle_cdf.begin());
  t = std::min(t, light.triangle_cdf.size() - 1);
  const TriangleMesh& m = meshes_[light.mesh];
  const auto& tri = m.triangles[t];
  // Uniform point in the triangle (square-root parameterisation).
  const double su = std::sqrt(u2.x());
  const double b0 = 1.0 - su, b1 = u2.y() * su;
  const Vec3 p = b0 * m.positions[tri[0]] + b1 * m.positions[tri[1]] + (1.0 - b0 - b1) * m.positions[tri[2]];
  const Vec3 n = face_normal(m, t);
  return LightSample{p, n, &light, light_pdf_area(light)};
}

bool TracerScene::emits_towards(const TracerLight& light, const Vec3& ng, const Vec3& to_viewer) {
  return light.light->two_sided || ng.dot(to_viewer) > 0.0;
}

}  // namespace ct::rt
