// SPDX-License-Identifier: Apache-2.0
#pragma once
// The colour-constancy literature's statistical baselines: the light's colour from image statistics alone, each
// under its own assumption about the world's surfaces. van de Weijer, Gevers and Gijsenij (2007, "Edge-based
// colour constancy") write them as one family, per channel c:
//
//     e_c ∝ ( Σ_x |∂ⁿ f_c,σ(x)|^p )^(1/p)
//
// f_c,σ the channel smoothed by a Gaussian of σ pixels, ∂ⁿ its derivative of order n (n = 0: the value itself;
// n = 1: the gradient's magnitude √(f_x² + f_y²); n = 2: √(f_xx² + 4 f_xy² + f_yy²), as their code has it):
//  - grey world (Buchsbaum 1980): n = 0, p = 1 — the mean surface is grey;
//  - white patch, max-RGB (Land 1977): n = 0, p = ∞ — the brightest surface is white;
//  - shades of grey (Finlayson and Trezzi 2004): n = 0, p = 6;
//  - grey edge, first and second order: n = 1 or 2, p = 6, σ = 1 — the mean edge is grey.

#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "analyzer/moments.h"

namespace ct::analyzer {

struct MinkowskiSettings {
  std::string name;  // "grey world", "white patch", "shades of grey", "grey edge 1", "grey edge 2"
  int order = 0;     // derivative order n: 0, 1 or 2
  double p = 1.0;    // Minkowski norm; infinity for the maximum
  double sigma = 0.0;  // Gaussian smoothing in pixels before the derivatives (0: none)
  std::string assumption;  // what the world's surfaces must be for it to hold, in words
};

// The five methods above, with the literature's usual parameters.
const std::vector<MinkowskiSettings>& baseline_methods();

// The estimate of one method: a unit RGB direction with a positive sum, or zero when no pixel counts (every
// pixel left out, or no edge). `rgb` holds width × height × 3 linear values, rows from the top; `usable` (empty:
// every finite pixel) is nonzero for a pixel to count. With derivatives, a pixel counts only when every pixel its
// derivative reads (within 3σ + order) is usable, so that a clipped or black pixel's edge is no edge of the scene.
Vec3 minkowski_estimate(std::span<const float> rgb, int width, int height, std::span<const std::uint8_t> usable,
                        const MinkowskiSettings& method);

// The estimate with how much it depends on which surfaces happen to be in view: a block bootstrap. The image is cut
// into about 64 blocks; each of `replicates` resamples draws as many blocks with replacement (a seeded generator:
// the same inputs give the same numbers) and recomputes the estimate from their sums (their maxima for white
// patch); `uncertainty_deg` is the root-mean-square angle of the resamples to the estimate. It measures the
// spread of the statistic over the scene's parts, not whether the method's assumption holds: a scene of grey
// surfaces gives 0 and so does a scene of one uniform colour, on which grey world is wrong. For white patch (a
// maximum) the bootstrap is coarse: a resample either holds the brightest block or not.
struct BaselineEstimate {
  Vec3 rgb = Vec3::Zero();
  double uncertainty_deg = 0.0;
  std::size_t pixels = 0;  // the pixels that counted
};
BaselineEstimate baseline_estimate(std::span<const float> rgb, int width, int height, std::span<const std::uint8_t> usable,
                                   const MinkowskiSettings& method, int replicates = 200, std::uint64_t seed = 1);

}  // namespace ct::analyzer
