#pragma once
// The scene as the reference tracer uses it: triangles in an Embree accelerator, each triangle knowing its
// object or light, materials reduced to their lobes and spectra, and a light-sampling distribution.

#include <cstdint>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "core/scene.h"
#include "reference_tracer/accel.h"
#include "reference_tracer/bsdf.h"
#include "reference_tracer/lanes.h"

namespace ct::rt {

// A material's two scattering terms: f·cos = ρ_d(λ)·(lambert lobe) + k_s(λ)·(glossy lobe).
//  lambert:     ρ_d = reflectance, k_s = 0
//  dichromatic: ρ_d = diffuse,     k_s = specular weight (flat), glossy lobe GGX or Phong
//  mirror:      ρ_d = 0,           k_s = reflectance, glossy lobe a delta
struct TracerMaterial {
  const PiecewiseLinearSpectrum* diffuse = nullptr;   // null: no diffuse term
  const PiecewiseLinearSpectrum* specular = nullptr;  // null: flat specular_weight
  double specular_weight = 0.0;
  std::variant<std::monostate, GgxLobe, PhongLobe, MirrorLobe> glossy;
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
  PiecewiseLinearSpectrum radiance; // radiance · scale
};

struct SurfaceHit {
  Vec3 p;          // position
  Vec3 ng;         // unit geometric normal (as wound)
  Vec3 ns;         // unit shading normal, on the side of ng
  std::uint32_t mesh;
  int object_id;
};

struct LightSample {
  Vec3 p, n;       // point and unit normal of the emitting triangle
  const TracerLight* light;
  double pdf_area; // selection × uniform-area density
};

class TracerScene {
 public:
  TracerScene(const Scene& scene);

  const Scene& scene() const { return scene_; }
  const Accelerator& accel() const { return *accel_; }
  const std::vector<std::string>& groups() const { return groups_; }
  const std::vector<TracerLight>& lights() const { return lights_; }

  SurfaceHit surface(const Hit& hit) const;
  // Material of a mesh (null: the mesh only emits), and its light (null: not an emitter).
  const TracerMaterial* material_of(std::uint32_t mesh) const;
  const TracerLight* light_of(std::uint32_t mesh) const;
  // Picks a light ∝ power and a point uniformly on its surface; u1 chooses the light and triangle.
  std::optional<LightSample> sample_light(double u1, const Vec2& u2) const;
  // Density (per area) with which sample_light produces a point on `light`.
  double light_pdf_area(const TracerLight& light) const { return light.select_probability / light.area; }
  // Whether a light emits from its surface with normal ng towards direction `to_viewer`.
  static bool emits_towards(const TracerLight& light, const Vec3& ng, const Vec3& to_viewer);

 private:
  const Scene& scene_;
  std::vector<TriangleMesh> meshes_;
  std::unique_ptr<Accelerator> accel_;
  std::vector<TracerMaterial> materials_;      // parallel to scene.materials
  std::vector<int> mesh_material_;             // -1: none
  std::vector<int> mesh_light_;                // -1: none
  std::vector<TracerLight> lights_;
  std::vector<double> light_cdf_;
  std::vector<std::string> groups_;
};

}  // namespace ct::rt
