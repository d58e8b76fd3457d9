// SPDX-License-Identifier: Apache-2.0
#include "reference_tracer/scene_data.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <numeric>

#include "core/error.h"
#include "core/parallel.h"

namespace ct::rt {
namespace {

// Mean of a spectrum over the visible range, used only to balance sampling decisions (never a result).
double visible_mean(const PiecewiseLinearSpectrum& s) { return s.average(380.0, 780.0); }
double visible_mean(const ScaledSigmoid& s) {
  double sum = 0.0;
  for (int nm = 380; nm <= 780; nm += 10) sum += s.tabulated_at(nm);
  return sum / 41.0;
}

// The textures the scene uses, each fitted once, and the colour inputs that refer to them.
class TextureSet {
 public:
  TextureSet(std::vector<TracerTexture>& textures, int threads) : textures_(textures), threads_(threads) {}

  ColourInput input(const SpectrumRef& ref, const PiecewiseLinearSpectrum* spectrum, double scale = 1.0) {
    ColourInput in;
    if (!ref.texture) {
      in.spectrum = spectrum;
      return in;
    }
    in.scale = scale;
    const auto [it, fresh] = index_.emplace(ref.texture.get(), static_cast<int>(textures_.size()));
    if (fresh) {
      TracerTexture t;
      t.image = ref.texture.get();
      t.spectra = upsample_texels(*t.image, threads_);
      t.palette_mean.resize(t.spectra.palette.size());
      parallel_for(t.palette_mean.size(), threads_,
                   [&](std::size_t i) { t.palette_mean[i] = visible_mean(t.spectra.palette[i]); });
      double sum = 0.0;
      for (const std::uint32_t p : t.spectra.palette_of) sum += t.palette_mean[p];
      t.mean = sum / static_cast<double>(t.spectra.palette_of.size());
      textures_.push_back(std::move(t));
    }
    in.texture = it->second;
    return in;
  }

  double mean(const ColourInput& in) const {
    if (in.texture >= 0) return in.scale * textures_[static_cast<std::size_t>(in.texture)].mean;
    return in.spectrum ? in.scale * visible_mean(*in.spectrum) : 0.0;
  }

 private:
  std::vector<TracerTexture>& textures_;
  int threads_;
  std::map<const ImageTexture*, int> index_;
};

TracerMaterial make_material(const Material& material, TextureSet& textures) {
  TracerMaterial m;
  if (const auto* lambert = std::get_if<LambertMaterial>(&material.model)) {
    m.diffuse = textures.input(lambert->reflectance, &lambert->reflectance.spectrum);
  } else if (const auto* dichromatic = std::get_if<DichromaticMaterial>(&material.model)) {
    m.diffuse = textures.input(dichromatic->diffuse, &dichromatic->diffuse.spectrum);
    m.specular_weight = dichromatic->specular;
    if (const auto* ggx = std::get_if<DichromaticMaterial::Ggx>(&dichromatic->lobe)) {
      // Roughness 0 is a perfect mirror lobe (the scene format's convention, as in Cycles).
      if (ggx->roughness > 0.0)
        m.glossy = rt::GgxLobe{ggx->alpha(), ggx->masking == DichromaticMaterial::Masking::HeightCorrelated};
      else m.glossy = MirrorLobe{};
    } else {
      m.glossy = rt::PhongLobe{std::get<DichromaticMaterial::Phong>(dichromatic->lobe).exponent};
    }
    const double body = textures.mean(m.diffuse);
    m.glossy_probability = m.specular_weight > 0.0 ? m.specular_weight / (m.specular_weight + body) : 0.0;
    if (body <= 0.0 && m.specular_weight > 0.0) m.glossy_probability = 1.0;
  } else if (const auto* principled = std::get_if<PrincipledMaterial>(&material.model)) {
    m.diffuse = textures.input(principled->base_color, &principled->base_color.spectrum);
    m.specular_weight = 1.0;  // the lobe carries its Fresnel
    m.glossy = rt::PrincipledLobe(principled->version, principled->roughness, principled->effective_ior(),
                                  principled->multiscatter);
    // The interface's hemispherical average Fresnel beside the base's mean, as the chance of sampling it (at least
    // one in ten, for the highlight's indirect light).
    const double interface = average_fresnel_dielectric(principled->effective_ior());
    const double body = textures.mean(m.diffuse);
    m.glossy_probability = interface > 0.0 ? std::max(0.1, interface / (interface + body)) : 0.0;
  } else {
    const auto& mirror = std::get<MirrorMaterial>(material.model);
    m.specular = textures.input(mirror.reflectance, &mirror.reflectance.spectrum);
    m.glossy = MirrorLobe{};
    m.glossy_probability = 1.0;
  }
  return m;
}

// Polar angle of the top edge of texel row y (of `height`) in the latitude-longitude image.
double row_theta(std::size_t y, int height) { return std::numbers::pi * static_cast<double>(y) / height; }
// Solid angle of one texel of row y.
double texel_solid_angle(std::size_t y, int width, int height) {
  return 2.0 * std::numbers::pi / width * (std::cos(row_theta(y, height)) - std::cos(row_theta(y + 1, height)));
}

}  // namespace

TracerScene::TracerScene(const Scene& scene, int threads) : scene_(scene), meshes_(scene_meshes(scene)) {
  std::vector<const TriangleMesh*> pointers;
  for (const TriangleMesh& m : meshes_) pointers.push_back(&m);
  accel_ = std::make_unique<Accelerator>(pointers);
  for (const Object& object : scene.objects) corner_uvs_.push_back(corner_uvs(object.shape));
  for (const Light& light : scene.lights)
    corner_uvs_.push_back(std::visit([](const auto& shape) { return corner_uvs(Shape(shape)); }, light.shape));

  TextureSet textures(textures_, threads);
  for (const Material& material : scene.materials) materials_.push_back(make_material(material, textures));
  mesh_material_.assign(meshes_.size(), -1);
  mesh_light_.assign(meshes_.size(), -1);
  for (std::size_t i = 0; i < scene.objects.size(); ++i) mesh_material_[i] = static_cast<int>(scene.objects[i].material);

  auto group_index = [&](const std::string& group) {
    auto it = std::find(groups_.begin(), groups_.end(), group);
    if (it == groups_.end()) {
      groups_.push_back(group);
      return static_cast<int>(groups_.size() - 1);
    }
    return static_cast<int>(it - groups_.begin());
  };

  double total_power = 0.0;
  for (std::size_t l = 0; l < scene.lights.size(); ++l) {
    const Light& light = scene.lights[l];
    const std::uint32_t mesh = static_cast<std::uint32_t>(scene.objects.size() + l);
    if (light.material) mesh_material_[mesh] = static_cast<int>(*light.material);
    mesh_light_[mesh] = static_cast<int>(lights_.size());

    TracerLight tl;
    tl.light = &light;
    tl.mesh = mesh;
    if (!light.radiance.texture) tl.spectrum = light.emitted_radiance();
    tl.radiance = textures.input(light.radiance, nullptr, light.scale);  // the spectrum pointer is set below
    const TriangleMesh& m = meshes_[mesh];
    double area = 0.0;
    for (std::size_t t = 0; t < m.triangles.size(); ++t) {
      area += triangle_area(m, t);
      tl.triangle_cdf.push_back(area);
    }
    for (double& c : tl.triangle_cdf) c /= area;
    tl.area = area;
    tl.group = group_index(light.group.empty() ? light.name : light.group);
    // Power ∝ mean radiance × area × (sides); only its proportions matter.
    const double mean = light.radiance.texture ? textures.mean(tl.radiance) : visible_mean(tl.spectrum);
    const double power = std::max(0.0, mean) * area * (light.two_sided ? 2.0 : 1.0);
    total_power += power;
    light_cdf_.push_back(total_power);
    lights_.push_back(std::move(tl));
  }
  for (TracerLight& tl : lights_)
    if (tl.radiance.texture < 0) tl.radiance.spectrum = &tl.spectrum;

  if (scene.environment) {
    const Environment& e = *scene.environment;
    TracerEnvironment env;
    env.environment = &e;
    env.group = group_index(e.group);
    const double rotation = e.rotation_deg * std::numbers::pi / 180.0;
    env.cos_rotation = std::cos(rotation);
    env.sin_rotation = std::sin(rotation);
    double integral = 0.0;  // ∫ mean radiance dω
    if (e.radiance.texture) {
      env.radiance = textures.input(e.radiance, nullptr, e.scale);
      const TracerTexture& t = textures_[static_cast<std::size_t>(env.radiance.texture)];
      const int w = t.image->width, h = t.image->height;
      env.texel_cdf.resize(t.image->texel_count());
      for (std::size_t i = 0; i < env.texel_cdf.size(); ++i) {
        integral += e.scale * t.palette_mean[t.spectra.palette_of[i]] * texel_solid_angle(i / static_cast<std::size_t>(w), w, h);
        env.texel_cdf[i] = integral;
      }
      if (integral > 0.0)
        for (double& c : env.texel_cdf) c /= integral;
    } else {
      env.spectrum = e.radiance.spectrum.scaled(e.scale);
      integral = 4.0 * std::numbers::pi * visible_mean(env.spectrum);
    }
    // As the power of the disc of the scene's bounding radius that the environment lights: R² · ∫ L dω
    // (in the units of the area lights' mean radiance × area).
    Bounds all;
    for (const TriangleMesh& m : meshes_) all.extend(bounds(m));
    const double radius = all.empty() ? 1.0 : std::max(1e-6, 0.5 * (all.hi - all.lo).norm());
    total_power += std::max(0.0, integral) * radius * radius;
    light_cdf_.push_back(total_power);
    environment_ = std::move(env);
    if (environment_->radiance.texture < 0)
      environment_->radiance.spectrum = &environment_->spectrum;
  }

  const std::size_t n = light_cdf_.size();
  for (std::size_t l = 0; l < n; ++l) {
    if (total_power > 0.0) light_cdf_[l] /= total_power;
    else light_cdf_[l] = (l + 1.0) / static_cast<double>(n);
    const double p = light_cdf_[l] - (l == 0 ? 0.0 : light_cdf_[l - 1]);
    if (l < lights_.size()) lights_[l].select_probability = p;
    else environment_->select_probability = p;
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
  const auto& uvs = corner_uvs_[hit.mesh];
  if (uvs.empty()) {
    s.uv = Vec2::Zero();
  } else {
    const auto& t = uvs[hit.triangle];
    s.uv = (1.0 - hit.u - hit.v) * t[0] + hit.u * t[1] + hit.v * t[2];
  }
  s.mesh = hit.mesh;
  s.object_id = static_cast<int>(hit.mesh) + 1;
  return s;
}

std::optional<LightSample> TracerScene::sample_light(double u1, const Vec2& u2) const {
  if (light_cdf_.empty()) return std::nullopt;
  std::size_t l = static_cast<std::size_t>(std::lower_bound(light_cdf_.begin(), light_cdf_.end(), u1) - light_cdf_.begin());
  l = std::min(l, light_cdf_.size() - 1);
  const double lo = l == 0 ? 0.0 : light_cdf_[l - 1];
  const double select = light_cdf_[l] - lo;
  if (select <= 0.0) return std::nullopt;
  // Reuse u1 within the chosen light's interval to pick the triangle or texel (keeps the sample 3-dimensional).
  const double v = std::clamp((u1 - lo) / select, 0.0, std::nextafter(1.0, 0.0));
  LightSample out;
  if (l == lights_.size()) {
    const TracerEnvironment& env = *environment_;
    Vec3 d;  // in the environment's own frame (before its rotation)
    if (env.radiance.texture < 0) {
      // Uniform over the sphere.
      const double z = 1.0 - 2.0 * u2.x(), r = std::sqrt(std::max(0.0, 1.0 - z * z)), phi = 2.0 * std::numbers::pi * u2.y();
      d = Vec3(r * std::cos(phi), r * std::sin(phi), z);
      out.pdf_solid_angle = select / (4.0 * std::numbers::pi);
    } else {
      const ImageTexture& image = *textures_[static_cast<std::size_t>(env.radiance.texture)].image;
      std::size_t t = static_cast<std::size_t>(std::lower_bound(env.texel_cdf.begin(), env.texel_cdf.end(), v) -
                                               env.texel_cdf.begin());
      t = std::min(t, env.texel_cdf.size() - 1);
      const double p_texel = env.texel_cdf[t] - (t == 0 ? 0.0 : env.texel_cdf[t - 1]);
      if (p_texel <= 0.0) return std::nullopt;
      const std::size_t w = static_cast<std::size_t>(image.width), x = t % w, y = t / w;
      // Uniform in solid angle within the texel: φ uniform over its columns, cos θ uniform over its rows.
      const double s = (static_cast<double>(x) + u2.x()) / image.width;
      const double phi = std::numbers::pi * (1.0 - 2.0 * s);  // Blender: u = ½ − φ / 2π
      const double z0 = std::cos(row_theta(y, image.height)), z1 = std::cos(row_theta(y + 1, image.height));
      const double z = z0 + u2.y() * (z1 - z0), r = std::sqrt(std::max(0.0, 1.0 - z * z));
      d = Vec3(r * std::cos(phi), r * std::sin(phi), z);
      out.texel = t;
      out.pdf_solid_angle = select * p_texel / texel_solid_angle(y, image.width, image.height);
    }
    out.wi = Vec3(env.cos_rotation * d.x() - env.sin_rotation * d.y(), env.sin_rotation * d.x() + env.cos_rotation * d.y(), d.z());
    return out;
  }
  const TracerLight& light = lights_[l];
  std::size_t t = static_cast<std::size_t>(
      std::lower_bound(light.triangle_cdf.begin(), light.triangle_cdf.end(), v) - light.triangle_cdf.begin());
  t = std::min(t, light.triangle_cdf.size() - 1);
  const TriangleMesh& m = meshes_[light.mesh];
  const auto& tri = m.triangles[t];
  // Uniform point in the triangle (square-root parameterisation).
  const double su = std::sqrt(u2.x());
  const double b0 = 1.0 - su, b1 = u2.y() * su;
  out.light = &light;
  out.p = b0 * m.positions[tri[0]] + b1 * m.positions[tri[1]] + (1.0 - b0 - b1) * m.positions[tri[2]];
  out.n = face_normal(m, t);
  const auto& uvs = corner_uvs_[light.mesh];
  if (!uvs.empty()) out.uv = b0 * uvs[t][0] + b1 * uvs[t][1] + (1.0 - b0 - b1) * uvs[t][2];
  else out.uv = Vec2::Zero();
  out.pdf_area = light_pdf_area(light);
  return out;
}

std::size_t TracerScene::environment_texel(const Vec3& d) const {
  const TracerEnvironment& env = *environment_;
  if (env.radiance.texture < 0) return 0;
  const ImageTexture& image = *textures_[static_cast<std::size_t>(env.radiance.texture)].image;
  // Into the image's frame (undo the rotation), then Blender's default equirectangular mapping.
  const double x = env.cos_rotation * d.x() + env.sin_rotation * d.y();
  const double y = -env.sin_rotation * d.x() + env.cos_rotation * d.y();
  const double s = 0.5 - std::atan2(y, x) / (2.0 * std::numbers::pi);  // in [0, 1]: 0 and 1 are −X
  const double theta = std::acos(std::clamp(d.z(), -1.0, 1.0));
  const double column = std::clamp(std::floor(s * image.width), 0.0, image.width - 1.0);
  const double row = std::clamp(std::floor(theta / std::numbers::pi * image.height), 0.0, image.height - 1.0);
  return static_cast<std::size_t>(row) * static_cast<std::size_t>(image.width) + static_cast<std::size_t>(column);
}

double TracerScene::environment_pdf(const Vec3& d) const {
  const TracerEnvironment& env = *environment_;
  if (env.radiance.texture < 0) return 1.0 / (4.0 * std::numbers::pi);
  const ImageTexture& image = *textures_[static_cast<std::size_t>(env.radiance.texture)].image;
  const std::size_t t = environment_texel(d);
  const double p_texel = env.texel_cdf[t] - (t == 0 ? 0.0 : env.texel_cdf[t - 1]);
  return p_texel / texel_solid_angle(t / static_cast<std::size_t>(image.width), image.width, image.height);
}

bool TracerScene::emits_towards(const TracerLight& light, const Vec3& ng, const Vec3& to_viewer) {
  return light.light->two_sided || ng.dot(to_viewer) > 0.0;
}

}  // namespace ct::rt
