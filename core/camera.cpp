// SPDX-License-Identifier: Apache-2.0
#include "core/camera.h"

#include <cmath>
#include <numbers>

namespace ct {
namespace {

double tan_half(double fov_deg) { return std::tan(fov_deg * std::numbers::pi / 360.0); }

}  // namespace

ImagePlane ImagePlane::from_fov_deg(double horizontal_deg, double vertical_deg, int width, int height) {
  return ImagePlane{tan_half(horizontal_deg), tan_half(vertical_deg), width, height};
}

double ImagePlane::off_axis_angle(double px, double py) const { return std::atan(std::hypot(x(px), y(py))); }

Vec3 Camera::forward() const { return (look_at - position).normalized(); }
Vec3 Camera::right() const { return forward().cross(up).normalized(); }
Vec3 Camera::image_up() const { return right().cross(forward()); }

double Camera::tan_half_width() const {
  const double t = tan_half(fov_deg);
  const bool horizontal = fov_axis == FovAxis::Horizontal || (fov_axis == FovAxis::Smaller && width <= height) ||
                          (fov_axis == FovAxis::Larger && width >= height);
  return horizontal ? t : t * width / height;
}

double Camera::tan_half_height() const { return tan_half_width() * height / width; }

double Camera::focal_length_mm() const { return 0.5 * sensor_width_mm / tan_half_width(); }

ImagePlane Camera::image_plane() const { return ImagePlane{tan_half_width(), tan_half_height(), width, height}; }

Vec3 Camera::ray_direction(double px, double py) const {
  const ImagePlane plane = image_plane();
  return (forward() + plane.x(px) * right() + plane.y(py) * image_up()).normalized();
}

}  // namespace ct
