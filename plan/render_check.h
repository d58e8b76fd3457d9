// SPDX-License-Identifier: Apache-2.0
#pragma once
// What a render's settings leave out, said before rendering (check-scene, render; docs/stability.md): the band
// plan's colour errors (plan/spectral_check.h), and, by plan's model (plan/plan.h), a bounce limit that drops
// light worth a mean ΔE00 above the target and samples whose Monte Carlo noise is predicted above it. The target is
// plan's default, a mean ΔE00 of 1; plan itself gives the bounce limit a quarter of it, so a scene at the settings
// plan chooses is silent.

#include <optional>
#include <string>
#include <vector>

#include "core/scene.h"

namespace ct::plan {

struct RenderRequest {
  Bands bands;
  SpectralMode mode = SpectralMode::Bands;
  int max_bounces = 0, samples = 0;
  // How the user named each setting in the message: "render.max_bounces" (check-scene) or "--max-bounces".
  std::string bounces_name = "render.max_bounces", samples_name = "render.samples";
  // The renderer has the continuous spectral mode (the tracer; Cycles renders bands only): the band warnings'
  // fixes name it only then.
  bool continuous_available = true;
  // Cycles renders it: its noise is kCyclesNoiseRatio × the tracer's (plan/plan.h), each band group's falling with
  // its own samples where `cycles_samples` gives them (one per group of three bands; else `samples` for every one).
  bool cycles = false;
  std::vector<int> cycles_samples;
  int threads = 0;
};

// The scene's own settings, named as the scene file names them.
RenderRequest scene_settings(const Scene& scene);

// One line each, cause, size and fix: the spectral warnings first (worst first), then bounces, then samples. A
// bounce limit of 0 (emitters only) is taken as meant and not judged.
std::vector<std::string> render_warnings(const Scene& scene, const RenderRequest& settings, double target_de00 = 1.0);

}  // namespace ct::plan
