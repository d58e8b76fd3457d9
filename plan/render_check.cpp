// SPDX-License-Identifier: Apache-2.0
#include "plan/render_check.h"

#include <cmath>

#include <fmt/core.h>
#include <fmt/ranges.h>

#include "plan/plan.h"
#include "plan/spectral_check.h"

namespace ct::plan {

RenderRequest scene_settings(const Scene& scene) {
  RenderRequest s;
  s.bands = scene.render.bands;
  s.mode = scene.render.spectral_mode;
  s.max_bounces = scene.render.max_bounces;
  s.samples = scene.render.samples;
  return s;
}

std::vector<std::string> render_warnings(const Scene& scene, const RenderRequest& settings, double target_de00) {
  std::vector<std::string> out;
  for (const SpectralWarning& w : check_band_plan(scene, settings.bands, settings.mode, 2.0, settings.continuous_available)) out.push_back(w.message);
  // The model needs a band range of at least 2 nm (plan says so; a render of a narrower one is left alone).
  if (settings.max_bounces < 1 || scene.render.bands.max_wavelength() - scene.render.bands.min_wavelength() < 2)
    return out;
  PlanOptions options;
  options.target_de00 = target_de00;
  options.threads = settings.threads;
  const SettingsPrediction p = predict_settings(scene, settings.max_bounces, settings.samples, options);
  if (p.bounce_de00 > target_de00)
    out.push_back(fmt::format(
        "{} {} leaves {:.0f} % of the luminance unrendered (light after more than {} bounce{}), a predicted mean "
        "ΔE00 of {:.3g}; use {} bounces (what chromatrace plan chooses for a mean ΔE00 of {:g})",
        settings.bounces_name, settings.max_bounces, 100 * p.share_beyond, settings.max_bounces,
        settings.max_bounces == 1 ? "" : "s", p.bounce_de00,
        p.bounces_for_target, target_de00));
  if (settings.cycles) {
    // The tracer's noise at one sample, Cycles' share of it, and the groups' samples (each group's noise the same
    // share of the whole, as plan's model has them but for its weights).
    const double at_one = p.noise_de00 * std::sqrt(static_cast<double>(settings.samples));
    double inverse = 1.0 / settings.samples;
    if (!settings.cycles_samples.empty()) {
      inverse = 0;
      for (int n : settings.cycles_samples) inverse += 1.0 / n / static_cast<double>(settings.cycles_samples.size());
    }
    const double noise = kCyclesNoiseRatio * at_one * std::sqrt(inverse);
    if (noise > target_de00)
      out.push_back(fmt::format(
          "{} {} gives Cycles Monte Carlo noise of a predicted mean ΔE00 of {:.3g} ({:g} × the tracer's, the median "
          "over the test scenes); use {} samples for {:g} (chromatrace plan)",
          settings.samples_name, settings.cycles_samples.empty() ? fmt::format("{}", settings.samples)
                                                                 : fmt::format("{}", fmt::join(settings.cycles_samples, ", ")),
          noise, kCyclesNoiseRatio,
          static_cast<int>(std::ceil(std::pow(kCyclesNoiseRatio * at_one / target_de00, 2))), target_de00));
  } else if (p.noise_de00 > target_de00) {
    out.push_back(fmt::format(
        "{} {} gives Monte Carlo noise of a predicted mean ΔE00 of {:.3g} (the tracer in bands mode); use {} "
        "samples for {:g} (chromatrace plan)",
        settings.samples_name, settings.samples, p.noise_de00, p.samples_for_target, target_de00));
  }
  return out;
}

}  // namespace ct::plan
