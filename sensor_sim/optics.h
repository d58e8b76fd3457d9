// SPDX-License-Identifier: Apache-2.0
#pragma once
// Stage 1 of the sensor model (paper eq. 2, docs/sensor.md): the lens turns scene radiance L into irradiance
// on the sensor, E(x, y, λ) = (π/4)·(1/N)²·cos⁴α(x, y)·τ(λ)·L(x, y, λ).

#include <optional>
#include <string>
#include <vector>

#include "core/camera.h"
#include "core/spectral_exr.h"

namespace ct::sensor {

// A pinhole camera's field of view, which fixes α for every pixel.
struct FieldOfView {
  double horizontal_deg = 0;
  double vertical_deg = 0;
  std::string source;  // "chromatrace.camera", "optics.fov_deg", for the record
};

// The field of view from the image header's chromatrace.camera (horizontal_fov_deg, vertical_fov_deg), else
// from a horizontal field of view with square pixels, else none. A malformed attribute is an InputError
// naming the file and the attribute.
std::optional<FieldOfView> field_of_view(const SpectralExrInfo& info, std::optional<double> horizontal_fov_deg);

// (π/4)·(1/N)²: irradiance on the axis per unit radiance, in sr.
double aperture_factor(double f_number);

// The cos⁴ fall-off at the centres of the pixels of a width × height image (pixel (i, j) from the top-left
// corner, centre at (i + 0.5, j + 0.5)), on the camera's image plane (core/camera.h).
class Cos4Falloff {
 public:
  Cos4Falloff(const FieldOfView& fov, int width, int height);
  double at(int i, int j) const { return ImagePlane::cos4(x_[static_cast<std::size_t>(i)], y_[static_cast<std::size_t>(j)]); }
  const ImagePlane& plane() const { return plane_; }

 private:
  ImagePlane plane_;
  std::vector<double> x_, y_;  // the pixel centres on the plane, per column and per row
};

}  // namespace ct::sensor
