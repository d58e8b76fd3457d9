// SPDX-License-Identifier: Apache-2.0
#pragma once
// The pinhole camera every part shares: the scene format's camera (where it stands, where it looks, its field
// of view), and the image plane that turns a pixel position into a ray, an off-axis angle α and the cos⁴α
// fall-off of paper eq. (2). The tracer traces its rays, the sensor simulator weighs its pixels with its cos⁴,
// and `check-scene --json` hands its focal length to the Blender add-on.

#include "core/geometry.h"

namespace ct {

// The image plane at unit distance in front of the pinhole, spanning [−tan_half_width, tan_half_width] ×
// [−tan_half_height, tan_half_height], with width × height square pixels.
struct ImagePlane {
  double tan_half_width = 1;
  double tan_half_height = 1;
  int width = 1, height = 1;

  // From fields of view in degrees along the image's two axes.
  static ImagePlane from_fov_deg(double horizontal_deg, double vertical_deg, int width, int height);

  // The point of the plane at image position (px, py), in pixels from the image's top-left corner (pixel
  // (i, j) has its centre at (i + 0.5, j + 0.5)): x to the right, y up.
  double x(double px) const { return (2.0 * px / width - 1.0) * tan_half_width; }
  double y(double py) const { return (1.0 - 2.0 * py / height) * tan_half_height; }
  // The angle α (radians) between the ray through (px, py) and the optical axis.
  double off_axis_angle(double px, double py) const;
  // cos⁴α = 1 / (1 + x² + y²)², without trigonometry.
  static double cos4(double x, double y) {
    const double s = 1.0 + x * x + y * y;
    return 1.0 / (s * s);
  }
};

enum class FovAxis { Horizontal, Vertical, Smaller, Larger };

// A pinhole camera. The sensor is `sensor_width_mm` wide along the image's horizontal axis with square
// pixels, which with the field of view fixes the focal length (and so cos⁴ fall-off and f-number).
struct Camera {
  Vec3 position = Vec3::Zero();
  Vec3 look_at = Vec3::UnitY();
  Vec3 up = Vec3::UnitZ();
  double fov_deg = 40.0;  // along fov_axis
  FovAxis fov_axis = FovAxis::Horizontal;
  int width = 256, height = 256;
  double sensor_width_mm = 36.0;

  Vec3 forward() const;            // unit, towards look_at
  Vec3 right() const;              // unit, forward × up
  Vec3 image_up() const;           // unit, right × forward
  double tan_half_width() const;   // tan(horizontal field of view / 2)
  double tan_half_height() const;  // tan(vertical field of view / 2)
  double focal_length_mm() const;
  ImagePlane image_plane() const;
  // Unit world direction of the ray through image point (px, py), in pixels from the top-left corner of
  // the image: px in [0, width], py in [0, height]; pixel (i, j) has its centre at (i + 0.5, j + 0.5).
  Vec3 ray_direction(double px, double py) const;
  // The angle α (radians) between that ray and the optical axis: paper eq. (2), cos⁴α fall-off.
  double off_axis_angle(double px, double py) const { return image_plane().off_axis_angle(px, py); }
};

}  // namespace ct
