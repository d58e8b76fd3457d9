// SPDX-License-Identifier: Apache-2.0
#include "sensor_sim/linear_signal.h"

#include <cmath>
#include <stdexcept>

#include <fmt/core.h>

#include "core/error.h"

#include "sensor_sim/spectral_response.h"

namespace ct::sensor {

LinearModel linear_model(const SensorConfig& config, double exposure_s, const Bands& bands,
                         const std::optional<FieldOfView>& fov, int input_width, int input_height) {
  const OpticsConfig& optics = config.optics;
  const PiecewiseLinearSpectrum transmittance =
      optics.enabled && optics.transmittance ? *optics.transmittance : PiecewiseLinearSpectrum::constant(1.0);
  const double aperture = optics.enabled ? aperture_factor(optics.f_number) : 1.0;
  const double scale = aperture * config.pixel.area_m2() * exposure_s;

  LinearModel model;
  model.weights =
      photon_response(bands, config.response.curves, config.response.basis, config.response.peak_qe, transmittance);
  for (auto& channel : model.weights)
    for (double& w : channel) w *= scale;
  if (optics.enabled && optics.cos4 && fov) model.cos4.emplace(*fov, input_width, input_height);
  model.supersample = config.pixel.supersample;
  model.input_width = input_width;
  model.input_height = input_height;
  return model;
}

void linear_signal(const LinearModel& model, std::span<const float> spectral, int y0, int y1, std::span<float> out) {
  const std::size_t bands = model.weights[0].size();
  const int k = model.supersample;
  const std::size_t in_width = static_cast<std::size_t>(model.input_width);
  const std::size_t width = static_cast<std::size_t>(model.width());
  const std::size_t rows = static_cast<std::size_t>(y1 - y0);
  if (spectral.size() != rows * static_cast<std::size_t>(k) * in_width * bands || out.size() != rows * width * 3)
    throw std::invalid_argument("linear_signal: buffer sizes do not match the rows");

  const double inv_area = 1.0 / (k * k);
  const double* w[3] = {model.weights[0].data(), model.weights[1].data(), model.weights[2].data()};
  for (std::size_t r = 0; r < rows; ++r) {
    for (std::size_t x = 0; x < width; ++x) {
      double sum[3] = {0, 0, 0};
      for (int sy = 0; sy < k; ++sy) {
        const std::size_t in_row = r * static_cast<std::size_t>(k) + static_cast<std::size_t>(sy);
        for (int sx = 0; sx < k; ++sx) {
          const std::size_t in_x = x * static_cast<std::size_t>(k) + static_cast<std::size_t>(sx);
          const float* l = spectral.data() + (in_row * in_width + in_x) * bands;
          double e[3] = {0, 0, 0};
          for (std::size_t b = 0; b < bands; ++b) {
            const double value = l[b];
            e[0] += w[0][b] * value;
            e[1] += w[1][b] * value;
            e[2] += w[2][b] * value;
          }
          const double falloff =
              model.cos4 ? model.cos4->at(static_cast<int>(in_x), (y0 + static_cast<int>(r)) * k + sy) : 1.0;
          for (int c = 0; c < 3; ++c) sum[c] += falloff * e[c];
        }
      }
      for (std::size_t c = 0; c < 3; ++c) {
        const float electrons = static_cast<float>(sum[c] * inv_area);
        // Radiance near a float's largest value times the exposure and pixel area: refused here, at the stage
        // that overflows, rather than carried on as Inf and NaN pixels.
        if (!std::isfinite(electrons))
          throw InputError(fmt::format("the photo-electrons of pixel ({}, {}) are {:g}, beyond a float: the image's "
                                       "radiance times exposure.time_s, exposure.scale, the pixel area and the "
                                       "aperture overflows; lower the exposure or check the image",
                                       x, y0 + static_cast<int>(r), sum[c] * inv_area));
        out[(r * width + x) * 3 + c] = electrons;
      }
    }
  }
}

}  // namespace ct::sensor
