// SPDX-License-Identifier: Apache-2.0
#pragma once
// ΔE00 between two renders of one scene, pixel by pixel: the one definition that `compare`, `plan` (its measured
// error, plan/plan.h measure_delta_e, and its model's predictions) and `study` use.
//
// Both renders' pixels are tristimulus values through one observer (the CIE 1931 curves or a camera's), compared in
// CIELAB under a white that the caller's WhitePolicy sets: the chromaticity of the adapting light (the scene's
// light, or D65 where the scene is not known) at the luminance of the brightest surfaces — the 99th percentile
// (core/statistics.h's rule) of a level image's second channel over the pixels that are not on or next to an
// emitter (with a box pixel filter a pixel beside a lamp holds some of the lamp's own light), falling back to the
// largest value when that percentile is black, and to 1 when every pixel is.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

#include "core/colour.h"

namespace ct {

struct WhitePolicy {
  Vec3d light{};           // the adapting light through the observer; only its chromaticity counts
  double quantile = 0.99;  // of the level image's luminance over the pixels that are not `excluded`
};

// Whether each pixel of a width × height object-id image is on or next to (one of its 8 neighbours) an emitter.
std::vector<bool> near_emitters(const std::vector<std::int32_t>& ids, int width, int height,
                                const std::function<bool(std::int32_t)>& is_emitter);

// The white: policy.light scaled so that its second channel is the policy's quantile of `level`'s second channel
// over the pixels not `excluded` (empty: none), with the fallbacks above. Every channel at least 1e-300.
Vec3d white_point(const std::vector<Vec3d>& level, const std::vector<bool>& excluded, const WhitePolicy& policy);

struct RenderDeltaE {
  Vec3d white{};
  std::vector<double> per_pixel;  // ΔE00 of each pixel, row by row
  double mean = 0, p95 = 0, max = 0;
  double rms = 0;  // root mean square: independent errors add in it as squares (to first order)
};

// ΔE00 of each pixel of `test` against `reference` (same size) under `white`, and their statistics (p95: the 95th
// percentile by core/statistics.h's rule).
RenderDeltaE delta_e_between(const std::vector<Vec3d>& test, const std::vector<Vec3d>& reference, const Vec3d& white);

}  // namespace ct
