// SPDX-License-Identifier: Apache-2.0
#include "reference_tracer/accel.h"

#include <cmath>
#include <limits>
#include <stdexcept>

#include <fmt/core.h>

namespace ct::rt {

Accelerator::Accelerator(const std::vector<const TriangleMesh*>& meshes) {
  device_ = rtcNewDevice("verbose=0");
  if (!device_) throw std::runtime_error("Embree: cannot create a device");
  scene_ = rtcNewScene(device_);
  rtcSetSceneBuildQuality(scene_, RTC_BUILD_QUALITY_HIGH);
  Bounds all;
  for (std::uint32_t id = 0; id < meshes.size(); ++id) {
    const TriangleMesh& mesh = *meshes[id];
    all.extend(bounds(mesh));
    RTCGeometry geom = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                                 3 * sizeof(float), mesh.positions.size()));
    for (std::size_t i = 0; i < mesh.positions.size(); ++i)
      for (int k = 0; k < 3; ++k) vertices[3 * i + k] = static_cast<float>(mesh.positions[i][k]);
    auto* indices = static_cast<std::uint32_t*>(rtcSetNewGeometryBuffer(
        geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(std::uint32_t), mesh.triangles.size()));
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
      for (int k = 0; k < 3; ++k) indices[3 * t + k] = mesh.triangles[t][k];
    rtcCommitGeometry(geom);
    rtcAttachGeometryByID(scene_, geom, id);
    rtcReleaseGeometry(geom);
  }
  rtcCommitScene(scene_);
  if (rtcGetDeviceError(device_) != RTC_ERROR_NONE) throw std::runtime_error("Embree: scene build failed");
  if (!all.empty()) scale_ = std::max(1e-6, (all.hi - all.lo).maxCoeff());
}

Accelerator::~Accelerator() {
  if (scene_) rtcReleaseScene(scene_);
  if (device_) rtcReleaseDevice(device_);
}

namespace {

void fill_ray(RTCRay& ray, const Vec3& o, const Vec3& d, double t_max) {
  ray.org_x = static_cast<float>(o.x());
  ray.org_y = static_cast<float>(o.y());
  ray.org_z = static_cast<float>(o.z());
  ray.dir_x = static_cast<float>(d.x());
  ray.dir_y = static_cast<float>(d.y());
  ray.dir_z = static_cast<float>(d.z());
  ray.tnear = 0.0f;
  ray.tfar = std::isinf(t_max) ? std::numeric_limits<float>::infinity() : static_cast<float>(t_max);
  ray.time = 0.0f;
  ray.mask = 0xFFFFFFFFu;
  ray.id = 0;
  ray.flags = 0;
}

}  // namespace

std::optional<Hit> Accelerator::intersect(const Vec3& origin, const Vec3& direction, double t_max) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit rh;
  fill_ray(rh.ray, origin, direction, t_max);
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(scene_, &context, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return std::nullopt;
  return Hit{rh.ray.tfar, rh.hit.geomID, rh.hit.primID, rh.hit.u, rh.hit.v};
}

bool Accelerator::occluded(const Vec3& origin, const Vec3& direction, double t_max) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRay ray;
  fill_ray(ray, origin, direction, t_max);
  rtcOccluded1(scene_, &context, &ray);
  return ray.tfar < 0.0f;  // Embree sets tfar to −∞ on a hit
}

bool Accelerator::visible(const Vec3& a, const Vec3& na, const Vec3& b, const Vec3& nb) const {
  const Vec3 from = offset_origin(a, na, b - a, scale_);
  const Vec3 to = offset_origin(b, nb, a - b, scale_);
  const Vec3 d = to - from;
  const double length = d.norm();
  if (!(length > 0.0)) return true;
  // The ends lie off both surfaces, so the full length can be tested, less float rounding of t.
  return !occluded(from, d / length, length * (1.0 - 1e-6));
}

Vec3 offset_origin(const Vec3& p, const Vec3& n, const Vec3& towards, double scene_scale) {
  // Float positions carry a relative error of 2⁻²⁴; 1e-5 of the larger of |p| and the scene size clears it
  // by two orders of magnitude while staying far below any feature a scene should have.
  const double eps = 1e-5 * std::max(scene_scale, p.cwiseAbs().maxCoeff());
  return p + (n.dot(towards) >= 0.0 ? eps : -eps) * n;
}

}  // namespace ct::rt
