#pragma once
// Gamma diagnosis: which power curve I' = k·I^γ (per channel) bent a straight cluster.
//
// Linear camera signals along one body colour lie on a straight line; a power curve applied per channel
// bends that line whenever it does not pass through black (an ambient or black-level offset, the sRGB
// curve's linear toe). The fit finds the γ whose inverse, x ↦ x^(1/γ), makes the cluster straightest.
// A per-channel gain k does not change straightness, so it need not be known. A line through black stays
// a line under any γ (the paper's remark), so it carries no information on γ.

#include <cstdint>
#include <optional>
#include <vector>

#include "analyzer/moments.h"

namespace ct::analyzer {

struct GammaFit {
  double gamma = 1;                  // the encoding exponent: I' = k·I^γ (sRGB-like encodings ≈ 1/2.2)
  double straightness_as_is = 0;     // (λ2 + λ3) / λ1 of the cluster as stored
  double straightness_linearised = 0;  // the same after x ↦ x^(1/γ)
  std::size_t used = 0;              // samples with all three channels > 0
  std::optional<double> gamma_se;    // its standard error (gamma_standard_error), when measured
};

// Searches γ in [0.2, 5]; nullopt with fewer than 10 positive samples.
std::optional<GammaFit> fit_gamma(const std::vector<Vec3>& points);

// The standard error of fit_gamma's γ on these points, by the bootstrap: γ refitted on 16 resamples (with
// replacement, a fixed seed, up to 1000 points each, the spread scaled by √(m / n) to the n points the fit used)
// — the spread the pixels' noise and the cluster's own scatter give the fit.
double gamma_standard_error(const std::vector<Vec3>& points, std::uint64_t seed = 1);

}  // namespace ct::analyzer
