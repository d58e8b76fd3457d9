// SPDX-License-Identifier: Apache-2.0
#include "plan/render_check.h"

#include <fmt/core.h>

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
  if (p.noise_de00 > target_de00)
    out.push_back(fmt::format(
        "{} {} gives Monte Carlo noise of a predicted mean ΔE00 of {:.3g} (the tracer in bands mode); use {} "
        "samples for {:g} (chromatrace plan)",
        settings.samples_name, settings.samples, p.noise_de00, p.samples_for_target, target_de00));
  return out;
}

}  // namespace ct::plan
