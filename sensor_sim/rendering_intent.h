// SPDX-License-Identifier: Apache-2.0
#pragma once
// Stage 6 of the sensor model (docs/sensor.md): from the sensor's signal to an encoded image value.
//
//   n  = signal / white                      (signal: DN above black, or e⁻ without an ADC)
//   n' = M · (g ⊙ n)                         (white-balance gains g, then the 3×3 colour matrix M)
//   v  = f(n')                               (f: identity, k·n^γ, or the sRGB curve; odd-symmetric for n' < 0)
//   v  = clamp(v, 0, 1)                      (if clip, or if quantised)
//   v  = round(v·(2^b − 1)) / (2^b − 1)      (b = output_bits, 8 or 16, when given)
// The curves map 0 to 0 and increase, so clipping after them equals clipping before.

#include <array>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "core/spectrum.h"
#include "sensor_sim/config.h"

namespace ct::sensor {

struct RenderingIntent {
  double white = 1.0;
  Eigen::Vector3d gains = Eigen::Vector3d::Ones();
  Eigen::Matrix3d matrix = Eigen::Matrix3d::Identity();
  ResponseCurve curve = ResponseCurve::Linear;
  double gamma = 1.0;
  double k = 1.0;
  bool clip = true;
  std::optional<int> output_bits;
};

// White-balance gains that make an illuminant neutral: with r_c the camera's noise-free signal for a perfect
// white lit by it (band averages of the illuminant through the per-band weights w[c][b] of linear_signal.h),
// g_c = r_g / r_c, so green keeps its scale.
Eigen::Vector3d white_balance_gains(const std::array<std::vector<double>, 3>& weights, const Bands& bands,
                                    const PiecewiseLinearSpectrum& illuminant);

// The intent of a configuration; `gains` are rendering.white_balance, or the illuminant's gains when it names one.
RenderingIntent rendering_intent(const SensorConfig& config, const Eigen::Vector3d& gains);

// One pixel's encoded value from its signal.
Eigen::Vector3d render(const RenderingIntent& intent, const Eigen::Vector3d& signal);

}  // namespace ct::sensor
