// SPDX-License-Identifier: Apache-2.0
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
#include <string>
#include <vector>

#include "analyzer/image_input.h"
#include "analyzer/moments.h"

namespace ct::analyzer {

// What the linearised cluster should be: a line (a matte object; (λ2 + λ3) / λ1 is minimised) or a plane (a
// dichromatic object, whose plane through black a per-channel power bends; λ3 / (λ1 + λ2) is minimised).
enum class GammaFlat { Line, Plane };

struct GammaFit {
  double gamma = 1;                  // the encoding exponent: I' = k·I^γ (sRGB-like encodings ≈ 1/2.2)
  GammaFlat flat = GammaFlat::Line;  // what it straightens: a line, or a plane (then the two numbers below are λ3 / (λ1 + λ2))
  double straightness_as_is = 0;     // (λ2 + λ3) / λ1 of the cluster as stored
  double straightness_linearised = 0;  // the same after x ↦ x^(1/γ)
  std::size_t used = 0;              // samples with all three channels > 0
  std::optional<double> gamma_se;    // its standard error (gamma_standard_error), when measured
  double lo = 0, hi = 0;             // the 2nd and 98th percentiles of the used samples' values, as stored
};

// The range fit_gamma searches. A fit within 1 % of either end found no minimum inside it: a cluster no power curve
// bends or straightens (a line through black stays a line under any γ) carries no information on γ.
inline constexpr double kGammaMin = 0.2, kGammaMax = 5.0;
inline bool gamma_at_bound(double gamma) { return gamma <= kGammaMin * 1.01 || gamma >= kGammaMax / 1.01; }

// Searches γ in [kGammaMin, kGammaMax]; nullopt with fewer than 10 positive samples.
std::optional<GammaFit> fit_gamma(const std::vector<Vec3>& points, GammaFlat flat = GammaFlat::Line);

// The standard error of fit_gamma's γ on these points, by the bootstrap: γ refitted on 16 resamples (with
// replacement, a fixed seed, up to 1000 points each, the spread scaled by √(m / n) to the n points the fit used)
// — the spread the pixels' noise and the cluster's own scatter give the fit.
double gamma_standard_error(const std::vector<Vec3>& points, std::uint64_t seed = 1, GammaFlat flat = GammaFlat::Line);

// The fitted γ against the curve the input declared (--input-transfer, or what the file said): they agree when
// they differ by at most 3 standard errors (the bootstrap's coverage, tests/analyzer/test_cluster_shape.cpp).
struct GammaComparison {
  std::string declared;        // the declared curve, described
  double declared_gamma = 1;   // its encoding exponent; the sRGB curve's effective one over the fit's values
  double fitted = 1, se = 0;
  double difference_in_se = 0;  // |fitted − declared_gamma| / se
  // The fit is a measurement: inside the searched range by more than 2 standard errors, with a standard error
  // above 0. Otherwise `not_measured` says why, and `agree` is false: nothing was measured to agree.
  bool measured = false;
  std::string not_measured;
  bool agree = false;
};
inline constexpr double kGammaAgreement = 3;  // standard errors

// nullopt without a standard error. `full_scale`: the stored value of full scale (1 for float files).
std::optional<GammaComparison> compare_gamma(const GammaFit& fit, const ToneCurve& declared, double full_scale);

// The exponent γ of the pure power I' = I^γ nearest the sRGB curve for stored values between lo and hi (fractions
// of full scale, 0 < lo < hi): the slope of ln I' against ln I, least squares over I' spaced evenly in ln I'.
double srgb_effective_gamma(double lo, double hi);

}  // namespace ct::analyzer
