// SPDX-License-Identifier: Apache-2.0
#pragma once
// The scene as the reference tracer uses it: triangles in an Embree accelerator, each triangle knowing its
// object or light, materials reduced to their lobes and spectra, and a light-sampling distribution.

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "core/scene.h"
#include "reference_tracer/accel.h"
#include "reference_tracer/bsdf.h"
#include "reference_tracer/lanes.h"
#include "reference_tracer/principled.h"

namespace ct::rt {

// A colour input as the tracer evaluates it: a spectrum, the same everywhere, or a texture looked up at a
// surface's (u, v) or the environment's direction; either times `scale`.
struct ColourInput {
  const PiecewiseLinearSpectrum* spectrum = nullptr;
  int texture = -1;  // index into TracerScene::textures()
  double scale = 1.0;
  explicit operator bool() const { return spectrum || texture >= 0; }
};

// A texture with the spectrum of each of its texels (each distinct colour upsampled once per render).
struct TracerTexture {
  const ImageTexture* image = nullptr;
  TexelSpectra spectra;
  std::vector<double> palette_mean;  // visible mean of each palette entry, for sampling decisions only
  double mean = 0.0;                 // over texels
};

// A material's two scattering terms: f·cos = ρ_d(λ)·(lambert lobe) + k_s(λ)·(glossy lobe).
//  lambert:     ρ_d = reflectance, k_s = 0
//  dichromatic: ρ_d = diffuse,     k_s = specular weight (flat), glossy lobe GGX or Phong
//  mirror:      ρ_d = 0,           k_s = reflectance, glossy lobe a delta
struct TracerMaterial {
  ColourInput diffuse;   // none: no diffuse term
  ColourInput specular;  // none: flat specular_weight
  double specular_weight = 0.0;
  std::variant<std::monostate, GgxLobe, PhongLobe, MirrorLobe, PrincipledLobe> glossy;
  double glossy_probability = 0.0;  // chance of sampling the glossy lobe rather than the diffuse one

  bool is_delta() const { return std::holds_alternative<MirrorLobe>(glossy); }
};

struct TracerLight {
  const Light* light = nullptr;
  std::uint32_t mesh = 0;           // index of its mesh
  std::vector<double> triangle_cdf; // area-proportional triangle choice
  double area = 0.0;
  double select_probability = 0.0;  // ∝ emitted power
  int group = 0;                    // index into TracerScene::groups
  PiecewiseLinearSpectrum spectrum; // radiance · scale, when not a texture
  ColourInput radiance;             // the spectrum, or the texture times the light's scale
};

// The environment (scene format "environment"): radiance from every direction that leaves the scene. A
// texture is sampled ∝ each texel's mean radiance × its solid angle, uniformly in solid angle within the texel;
// a spectrum uniformly over the sphere.
struct TracerEnvironment {
  const Environment* environment = nullptr;
  PiecewiseLinearSpectrum spectrum;  // radiance · scale, when not a texture
  ColourInput radiance;
  int group = 0;
  double select_probability = 0.0;
  double cos_rotation = 1.0, sin_rotation = 0.0;
  std::vector<double> texel_cdf;  // textured: cumulative sampling probability over texels, row-major
};

struct SurfaceHit {
  Vec3 p;          // position
  Vec3 ng;         // unit geometric normal (as wound)
  Vec3 ns;         // unit shading normal, on the side of ng
  Vec2 uv;         // texture coordinates (zero on a mesh without them)
  std::uint32_t mesh;
  int object_id;
};

struct LightSample {
  const TracerLight* light = nullptr;  // null: the environment
  // An area light: point, unit normal of the emitting triangle, its texture coordinates, and the selection ×
  // uniform-area density.
  Vec3 p = Vec3::Zero(), n = Vec3::Zero();
  Vec2 uv = Vec2::Zero();
  double pdf_area = 0.0;
  // The environment: the direction towards it, its texel (textured), and the selection × solid-angle density.
  Vec3 wi = Vec3::Zero();
  std::size_t texel = 0;
  double pdf_solid_angle = 0.0;
};

class TracerScene {
 public:
  // `threads` fit the textures' texels (0: all cores).
  explicit TracerScene(const Scene& scene, int threads = 0);

  const Scene& scene() const { return scene_; }
  const Accelerator& accel() const { return *accel_; }
  const std::vector<std::string>& groups() const { return groups_; }
  const std::vector<TracerLight>& lights() const { return lights_; }
  const std::vector<TracerTexture>& textures() const { return textures_; }
  const std::optional<TracerEnvironment>& environment() const { return environment_; }

  SurfaceHit surface(const Hit& hit) const;
  // Material of a mesh (null: the mesh only emits), and its light (null: not an emitter).
  const TracerMaterial* material_of(std::uint32_t mesh) const;
  const TracerLight* light_of(std::uint32_t mesh) const;
  // Picks a light ∝ power (the environment counts as one, its power that of a disc of the scene's radius lit by
  // it) and a point uniformly on its surface or a direction towards the environment; u1 chooses the light and
  // triangle or texel.
  std::optional<LightSample> sample_light(double u1, const Vec2& u2) const;
  // Density (per area) with which sample_light produces a point on `light`.
  double light_pdf_area(const TracerLight& light) const { return light.select_probability / light.area; }
  // Whether a light emits from its surface with normal ng towards direction `to_viewer`.
  static bool emits_towards(const TracerLight& light, const Vec3& ng, const Vec3& to_viewer);
  // The environment's texel seen in world direction `d` (unit), and the solid-angle density (without the
  // selection probability) with which sample_light picks `d`.
  std::size_t environment_texel(const Vec3& d) const;
  double environment_pdf(const Vec3& d) const;

 private:
  const Scene& scene_;
  std::vector<TriangleMesh> meshes_;
  std::unique_ptr<Accelerator> accel_;
  std::vector<TracerMaterial> materials_;      // parallel to scene.materials
  std::vector<int> mesh_material_;             // -1: none
  std::vector<int> mesh_light_;                // -1: none
  std::vector<TracerLight> lights_;
  std::vector<TracerTexture> textures_;
  std::optional<TracerEnvironment> environment_;
  std::vector<std::vector<std::array<Vec2, 3>>> corner_uvs_;  // per mesh, per triangle (empty: none)
  std::vector<double> light_cdf_;                             // the lights, then the environment
  std::vector<std::string> groups_;
};

}  // namespace ct::rt
