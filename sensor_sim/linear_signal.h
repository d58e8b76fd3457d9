// SPDX-License-Identifier: Apache-2.0
#pragma once
// Stages 1–3 of the sensor model together (docs/sensor.md): the noise-free linear camera signal, the mean
// number of photo-electrons per sensor pixel and channel,
//   μ_e,c(x, y) = (1/k²) Σ_{k×k rendered pixels} cos⁴α · Σ_b w[c][b] · L_b,   w[c][b] = G·A·T·Q[c][b]
// with L_b the band radiances (W·m⁻²·sr⁻¹·nm⁻¹), G the aperture factor (π/4)(1/N)² in sr (1 sr with the
// optics off), A the pixel area (m²), T the exposure time (s) and Q the photon response of
// spectral_response.h. It is linear in L, so each path component goes through it on its own.

#include <array>
#include <optional>
#include <span>
#include <vector>

#include "core/spectrum.h"
#include "sensor_sim/config.h"
#include "sensor_sim/optics.h"

namespace ct::sensor {

struct LinearModel {
  std::array<std::vector<double>, 3> weights;  // e⁻ per band radiance, on the optical axis: w[c][b]
  std::optional<Cos4Falloff> cos4;             // over the rendered pixels; none: no fall-off
  int supersample = 1;                         // k
  int input_width = 0;                         // rendered pixels
  int input_height = 0;

  // Sensor pixels: k×k rendered pixels each; a remainder of fewer than k columns or rows is dropped.
  int width() const { return input_width / supersample; }
  int height() const { return input_height / supersample; }
};

// `fov` switches cos⁴ on (when the configuration asks for it); the exposure time is given separately because
// an automatic one is found from the image.
LinearModel linear_model(const SensorConfig& config, double exposure_s, const Bands& bands,
                         const std::optional<FieldOfView>& fov, int input_width, int input_height);

// Electrons of sensor rows [y0, y1): `spectral` holds rendered rows [k·y0, k·y1) as [row][x][band] (all
// input_width columns); `out` receives (y1 − y0)·width()·3 values as [row][x][channel].
void linear_signal(const LinearModel& model, std::span<const float> spectral, int y0, int y1, std::span<float> out);

}  // namespace ct::sensor
