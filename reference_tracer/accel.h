// SPDX-License-Identifier: Apache-2.0
#pragma once
// Ray queries against world-space triangle meshes, through Embree.
//
// Embree works in single precision; callers offset secondary-ray origins along the geometric normal
// (offset_origin) so a ray never re-hits the surface it leaves.

#include <cstdint>
#include <optional>
#include <vector>

#include <embree3/rtcore.h>

#include "core/geometry.h"

namespace ct::rt {

struct Hit {
  double t = 0;
  std::uint32_t mesh = 0;      // index into the meshes given to the constructor
  std::uint32_t triangle = 0;  // triangle within that mesh
  double u = 0, v = 0;         // barycentrics: p = (1 − u − v)·a + u·b + v·c
};

class Accelerator {
 public:
  explicit Accelerator(const std::vector<const TriangleMesh*>& meshes);
  ~Accelerator();
  Accelerator(const Accelerator&) = delete;
  Accelerator& operator=(const Accelerator&) = delete;

  std::optional<Hit> intersect(const Vec3& origin, const Vec3& direction, double t_max) const;
  bool occluded(const Vec3& origin, const Vec3& direction, double t_max) const;
  // Whether the segment between two surface points is unobstructed. Both ends are first moved off their
  // surfaces (normals na, nb) towards each other, so neither surface itself can block it.
  bool visible(const Vec3& a, const Vec3& na, const Vec3& b, const Vec3& nb) const;

  // The length scale of the scene, for ray offsets.
  double scale() const { return scale_; }

 private:
  RTCDevice device_ = nullptr;
  RTCScene scene_ = nullptr;
  double scale_ = 1.0;
};

// Moves a surface point off the surface, to the side `towards` points to (relative to normal `n`), by an
// amount proportional to the point's magnitude and the scene scale, well above float rounding.
Vec3 offset_origin(const Vec3& p, const Vec3& n, const Vec3& towards, double scene_scale);

}  // namespace ct::rt
