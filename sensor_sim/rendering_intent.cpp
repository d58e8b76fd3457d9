// SPDX-License-Identifier: Apache-2.0
#include "sensor_sim/rendering_intent.h"

#include <algorithm>
#include <cmath>

#include <fmt/core.h>

#include "core/colour.h"
#include "core/error.h"

namespace ct::sensor {
namespace {

// f(n): the response curve, odd-symmetric so that negative signals (read noise below black) keep their sign.
double response_curve(const RenderingIntent& intent, double n) {
  const double magnitude = std::abs(n);
  double v = magnitude;
  switch (intent.curve) {
    case ResponseCurve::Linear: break;
    case ResponseCurve::Gamma: v = intent.k * std::pow(magnitude, intent.gamma); break;
    case ResponseCurve::Srgb: v = srgb_encode(magnitude); break;
  }
  return std::copysign(v, n);
}

}  // namespace

Eigen::Vector3d white_balance_gains(const std::array<std::vector<double>, 3>& weights, const Bands& bands,
                                    const PiecewiseLinearSpectrum& illuminant) {
  const std::vector<double> light = band_averages(illuminant, bands);
  Eigen::Vector3d response = Eigen::Vector3d::Zero();
  for (std::size_t c = 0; c < 3; ++c)
    for (std::size_t b = 0; b < bands.size(); ++b) response[static_cast<int>(c)] += weights[c][b] * light[b];
  if (!(response.minCoeff() > 0))
    throw InputError(
        fmt::format("rendering.white_balance: the illuminant gives no signal in some channel over "
                    "the image's bands ({:g}-{:g} nm)",
                    bands.min_wavelength(), bands.max_wavelength()));
  return Eigen::Vector3d(response[1] / response[0], 1.0, response[1] / response[2]);
}

RenderingIntent rendering_intent(const SensorConfig& config, const Eigen::Vector3d& gains) {
  const RenderingConfig& r = config.rendering;
  RenderingIntent intent;
  intent.white = white_level(config);
  intent.gains = gains;
  intent.matrix = r.colour_matrix;
  intent.curve = r.curve;
  intent.gamma = r.gamma;
  intent.k = r.k;
  intent.clip = r.clip;
  intent.output_bits = r.output_bits;
  return intent;
}

Eigen::Vector3d render(const RenderingIntent& intent, const Eigen::Vector3d& signal) {
  const Eigen::Vector3d n = intent.matrix * intent.gains.cwiseProduct(signal / intent.white);
  Eigen::Vector3d v;
  for (int c = 0; c < 3; ++c) {
    v[c] = response_curve(intent, n[c]);
    if (intent.clip || intent.output_bits) v[c] = std::clamp(v[c], 0.0, 1.0);
    if (intent.output_bits) {
      const double levels = std::ldexp(1.0, *intent.output_bits) - 1.0;
      v[c] = std::round(v[c] * levels) / levels;
    }
  }
  return v;
}

}  // namespace ct::sensor
