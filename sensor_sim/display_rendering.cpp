// SPDX-License-Identifier: Apache-2.0
#include "sensor_sim/display_rendering.h"

#include <algorithm>

#include <fmt/core.h>

#include "core/cie.h"
#include "core/colour.h"
#include "core/error.h"
#include "core/parallel.h"
#include "core/statistics.h"
#include "sensor_sim/sensor_rows.h"

namespace ct::sensor {

DisplayRendering display_rendering(const Survey& survey, const LinearModel& unit_model, const SensorConfig& config,
                                   const SpectralExrInfo& info, const std::string& lit_by, const std::vector<double>& lighting,
                                   Json& description, std::vector<std::string>& notes, std::vector<double>& scene_light) {
  const Bands& bands = info.bands;
  std::vector<double> light;
  std::string source;
  if (config.display.white_balance) {
    light = band_averages(cie::illuminant(*config.display.white_balance), bands);
    source = fmt::format("illuminant {} (display.white_balance)", *config.display.white_balance);
  } else if (!lighting.empty()) {
    light = lighting;
    source = fmt::format("illuminant {} lighting the reflectance image (--illuminant)", lit_by);
  } else if (const auto white = info.metadata.find("chromatrace.white"); white != info.metadata.end()) {
    // The white the renderer says the scene's colours are relative to (the Blender add-on: D65, Blender's).
    try {
      light = band_averages(cie::illuminant(white->second), bands);
    } catch (const InputError& e) {
      throw InputError(fmt::format("{}: chromatrace.white: {}", info.file, e.what()));
    }
    source = fmt::format("illuminant {}, the white of the scene's colours (chromatrace.white)", white->second);
  } else {
    const std::array<std::vector<double>, 3> xyz = xyz_band_weights(bands);
    double best = 0;
    for (const auto& [id, entry] : survey.emitter_spectra) {
      double y = 0;
      for (std::size_t b = 0; b < bands.size(); ++b) y += entry.first[b] / double(entry.second) * xyz[1][b];
      if (y > best) {
        best = y;
        light = entry.first;
        for (double& v : light) v /= double(entry.second);
        const auto name = info.object_names.find(id);
        source = id < 0 ? fmt::format("the brightest emitter in view ({} pixels)", entry.second)
                        : fmt::format("the brightest emitter in view, object {}{} ({} pixels)", id,
                                      name == info.object_names.end() ? "" : " (" + name->second + ")", entry.second);
      }
    }
  }
  DisplayRendering d;
  const auto matrix_for = [&](const std::vector<double>& l) { return display_matrix(unit_model.weights, bands, l); };
  try {
    if (light.empty()) throw InputError("no emitter in view");
    d.matrix = matrix_for(light);
  } catch (const InputError& e) {
    if (!light.empty()) notes.push_back(fmt::format("display: white balance on D65: {} ({})", source, e.what()));
    light = band_averages(cie::illuminant("D65"), bands);
    source = "illuminant D65 (no emitter in view)";
    d.matrix = matrix_for(light);
  }
  std::vector<float> brightest;
  for (std::size_t i = 0; i + 2 < survey.display_samples.size(); i += 3) {
    const Eigen::Vector3d c(survey.display_samples[i], survey.display_samples[i + 1], survey.display_samples[i + 2]);
    brightest.push_back(static_cast<float>(std::max(0.0, (d.matrix * c).maxCoeff())));
  }
  const double p = brightest.empty() ? 0.0 : quantile_in_place(brightest, config.display.percentile / 100.0);
  if (p > 0) {
    d.scale = config.display.level / p;
  } else {
    d.scale = 1.0;
    notes.push_back("display: the surfaces are black; the display layer's exposure is not normalised");
  }
  Json matrix = Json::array();
  for (int r = 0; r < 3; ++r) matrix.push_back({d.matrix(r, 0), d.matrix(r, 1), d.matrix(r, 2)});
  const Eigen::Vector3d white = white_response(unit_model.weights, light);
  description = {{"channels", {"display.R", "display.G", "display.B"}},
                 {"encoding", "sRGB (IEC 61966-2-1), clamped to [0, 1]"},
                 {"white_balance", source},
                 {"white_response", {white[0], white[1], white[2]}},
                 {"percentile", config.display.percentile},
                 {"level", config.display.level},
                 {"samples", brightest.size()}};
  description["matrix"] = matrix;  // camera e⁻ → linear sRGB, before the scale
  scene_light = light;
  return d;
}

void display_pixels(const DisplayRendering& display, const float* linear, std::size_t count, int threads, float* out) {
  parallel_for(count, threads, [&](std::size_t p) {
    const float* c = linear + 3 * p;
    const Eigen::Vector3d v = display_value(display, Eigen::Vector3d(c[0], c[1], c[2]));
    for (int ch = 0; ch < 3; ++ch) out[3 * p + to_size(ch)] = static_cast<float>(v[ch]);
  });
}

}  // namespace ct::sensor
