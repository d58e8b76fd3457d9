// SPDX-License-Identifier: Apache-2.0
#pragma once
// The display layer of the sensor's EXR output (docs/sensor.md, "Display layer"): the noise-free linear
// camera signal rendered the way a camera renders a picture for people, beside the raw numbers (which it
// leaves alone):
//
//   c  = the camera's noise-free signal of a pixel (e⁻, the `linear` layer)
//   x  = c ⊘ c_w                       white balance: c_w is the camera's signal of a perfect white lit by the
//                                      scene illuminant, so that white becomes (1, 1, 1)
//   X  = M·x                           camera → CIE XYZ (D65-adapted), M fitted to the camera's curves
//   v  = s·S·X                         S: XYZ → linear sRGB; s: the exposure normalisation
//   d  = sRGB-curve(clamp(v, 0, 1))    the display value
//
// M is the white-preserving least-squares fit (M·(1,1,1) = XYZ of sRGB white) of the white-balanced camera
// signals of a set of smooth reflectances lit by the illuminant to the XYZ of the same reflectances lit by
// D65 (a camera's white balance renders objects as they look in daylight). The reflectances are the
// Jakob–Hanika sigmoid spectra (core/rgb_to_spectrum.h) of the 4 × 4 × 4 grid of linear sRGB values
// {0.03, 0.2, 0.5, 0.85}³. For a camera whose curves are a linear mix of the CIE observer's the fit is exact.

#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/spectrum.h"

namespace ct::sensor {

// The training reflectances (64 smooth spectra, 360–830 nm), computed once.
const std::vector<PiecewiseLinearSpectrum>& display_training_reflectances();

// The camera's signal of a perfect white lit by `illuminant` (band values on `bands`), through the per-band
// weights w[c][b] of linear_signal.h.
Eigen::Vector3d white_response(const std::array<std::vector<double>, 3>& weights, const std::vector<double>& illuminant);

// M: white-balanced camera RGB → XYZ (docs above), for the camera weights and an illuminant's band values.
Eigen::Matrix3d camera_to_xyz(const std::array<std::vector<double>, 3>& weights, const Bands& bands,
                              const std::vector<double>& illuminant);

// The same fit against the XYZ of the reflectances lit by the illuminant itself (no adaptation to daylight), white
// preserved as the illuminant's own white (Y = 1): what a DNG ColorMatrix for that calibration illuminant inverts.
Eigen::Matrix3d camera_to_xyz_unadapted(const std::array<std::vector<double>, 3>& weights, const Bands& bands,
                                        const PiecewiseLinearSpectrum& illuminant);

struct DisplayRendering {
  Eigen::Matrix3d matrix = Eigen::Matrix3d::Identity();  // S·M·diag(1/c_w): camera signal → linear sRGB
  double scale = 1.0;                                      // s
};

// S·M·diag(1/c_w) for the camera weights and the illuminant's band values (the weights' scale cancels).
Eigen::Matrix3d display_matrix(const std::array<std::vector<double>, 3>& weights, const Bands& bands,
                               const std::vector<double>& illuminant);

// The linear sRGB value of a camera signal before clamping: s·matrix·c.
inline Eigen::Vector3d display_linear(const DisplayRendering& d, const Eigen::Vector3d& camera) {
  return d.scale * (d.matrix * camera);
}
// The display value of a camera signal: sRGB-encoded, in [0, 1].
Eigen::Vector3d display_value(const DisplayRendering& d, const Eigen::Vector3d& camera);

}  // namespace ct::sensor
