// SPDX-License-Identifier: Apache-2.0
#pragma once
// A camera's EMVA 1288 "Linear" parameters from a photon-transfer series (EMVA Standard 1288, Release 4.0 Linear,
// sections 6–8): pairs of flat fields at increasing exposure and pairs of dark frames at the same exposure times,
// each colour channel of the mosaic on its own.
//
// Per exposure time t, with A, B the two flats and C, D the two darks (digital numbers, black not subtracted):
//   μ_y = mean(A + B)/2, σ_y² = var(A − B)/2 (the fixed pattern cancels in the difference), and μ_y.dark, σ_y.dark²
//   likewise from C, D. Then
//   - the overall system gain K: the slope of σ_y² − σ_y.dark² against μ_y − μ_y.dark, a line through the origin
//     fitted from the darkest flat up to 70 % of saturation;
//   - saturation: the flat level at which σ_y² is largest; the saturation capacity μ_e.sat = η·μ_p.sat there when the
//     photons are known (as the standard gives it), else (μ_y − μ_y.dark)/K;
//   - the temporal dark noise σ_d = √(σ_y.dark² − σ_q²)/K at the shortest exposure, σ_q² = 1/12 DN²; where
//     σ_y.dark² < 0.24 DN² quantisation hides it, and the upper limit √(0.24 − 1/12)/K = 0.40/K is given instead;
//   - the dark current, both ways the standard gives: the slope of μ_y.dark against t over K, and the slope of
//     σ_y.dark² against t over K² (its shot noise; what a camera that subtracts its dark offset on chip shows) (e⁻/s);
//   - DSNU and PRNU: the spatial variance of the mean of the frames less the temporal variance left in it
//     (σ²/L for L frames), split into row, column and pixel parts as Release 4.0 does (the variance of the row
//     means and of the column means, each less what the pixel part leaves in a mean); DSNU = s_y.dark/K (e⁻),
//     PRNU = √(s_y.50² − s_y.dark²)/(μ_y.50 − μ_y.dark) at the flat level nearest half of saturation;
//   - the linearity error: the half range of the relative deviations of μ_y − μ_y.dark from a line through the
//     flats between 5 % and 95 % of saturation, fitted as the standard fits it (weighted by 1/y: least squares of
//     the relative deviations), against the photons per pixel (or the exposure time when the irradiance is not
//     given: proportional to the photons at constant irradiance);
//   - the quantum efficiency η = R/K, R the slope of μ_y − μ_y.dark against μ_p, when the photons per pixel are known.
// Each estimate comes with its standard error: regression slopes from their residuals, variances from
// var(s²) = 2σ⁴/(n − 1) for n pixels (the Gaussian value), propagated to first order.

#include <optional>
#include <string>
#include <vector>

namespace ct::calibrate {

// One frame of one colour channel: its values in digital numbers (black included), row-major.
struct Plane {
  int width = 0, height = 0;
  std::vector<double> values;
};

// The frames of one step of the series, one plane per frame, for one channel: the flats at one exposure time and
// irradiance, and the darks at that exposure time. A series at one exposure time has a step per irradiance, each
// with the same darks; a step without flats holds darks alone (at a further time, for the dark current).
struct ExposureStep {
  double exposure_s = 0;
  std::optional<double> photons_per_pixel;  // μ_p, when the irradiance is known
  std::vector<Plane> flats, darks;
};

// The spatial non-uniformity as EMVA 1288 Release 4.0 shows it beside its numbers (calibrate/spatial.h).
struct SpatialCurves {
  // σ of the image's deviation from its mean at each spatial frequency k/N, k = 1 … N/2 (cycles per pixel): along the
  // rows (horizontal; the power averaged over the rows) and along the columns (vertical). For white noise of σ every
  // value is about σ.
  std::vector<double> spectrum_horizontal, spectrum_vertical;
  // The temporal noise left in the mean of the frames, √(σ²_temporal / L): the floor a spectrogram cannot go below.
  double temporal_floor = 0;
  std::vector<double> profile_horizontal, profile_vertical;  // column means and row means, less the image's mean
  std::vector<std::pair<double, double>> histogram;          // (deviation from the mean, pixels), nonzero bins
  std::vector<std::pair<double, double>> accumulated;        // (x, % of pixels whose |deviation| ≥ x)
};

struct Estimate {
  double value = 0;
  double standard_error = 0;
};

// Spatial non-uniformity split into row, column and pixel parts (Release 4.0): total² = row² + column² + pixel².
struct Nonuniformity {
  Estimate total, row, column, pixel;
};

// The measured curve, per exposure step (for the photon-transfer and SNR plots).
struct TransferPoint {
  double exposure_s = 0;
  std::optional<double> photons_per_pixel;
  double mean_dn = 0, variance_dn2 = 0;            // μ_y, σ_y²
  double dark_mean_dn = 0, dark_variance_dn2 = 0;  // μ_y.dark, σ_y.dark²
};

struct ChannelCalibration {
  std::string channel;
  std::vector<TransferPoint> points;       // per flat step: by exposure time, then by signal
  std::vector<TransferPoint> dark_points;  // per exposure time of the darks (exposure, dark mean and variance only)
  Estimate gain_dn_per_e;           // K
  Estimate dark_noise_e;            // σ_d
  Estimate saturation_capacity_e;   // μ_e.sat
  double saturation_mean_dn = 0;    // μ_y at saturation
  // Where every pixel is clipped (the flats' temporal variance no more than twice the dark frames'): the full well
  // (or the ADC's top code) the pixels stop at, (μ_y − black) / K. EMVA's saturation capacity lies a little below it,
  // where the brightest pixels of a frame start to clip. Absent when no exposure clips every pixel.
  std::optional<Estimate> clip_level_e;
  // The clipped flats hold one code (their temporal variance under half the read noise's, the dark variance at no
  // exposure): the ADC's top code clips them before the full well, which lies beyond and is not measured; a well's
  // clip leaves the read noise on them.
  bool clips_at_adc = false;
  Estimate dark_current_e_per_s;    // from μ_y.dark against t
  // The dark current from σ²_y.dark against t (slope / K²: the dark electrons' shot noise), which a camera that
  // subtracts its dark offset on chip still shows; absent with one exposure time.
  std::optional<Estimate> dark_current_from_variance_e_per_s;
  // σ²_y.dark below 0.24 DN²: quantisation hides the temporal dark noise, and dark_noise_e is EMVA 1288's upper
  // limit √(0.24 − 1/12)/K, not a measurement.
  bool dark_noise_upper_limit = false;
  Estimate black_level_dn;          // μ_y.dark extrapolated to t = 0
  Nonuniformity dsnu_e;             // DSNU, e⁻
  SpatialCurves dsnu_curves;        // of the dark mean at the shortest exposure, in DN
  SpatialCurves prnu_curves;        // of the flats' mean less the darks' at the PRNU's level, in % of its signal
  Nonuniformity prnu;               // PRNU, a fraction
  double prnu_level_fraction = 0;   // the flat level PRNU was measured at, as a share of saturation
  double linearity_error = 0;       // a fraction (EMVA's LE / 100)
  // The linearity fit, where there is one: signal = intercept + slope·x (x the photons per pixel, or the exposure
  // time), and each fitted point's relative deviation from it; LE_min and LE_max the extremes (signed fractions).
  struct Linearity {
    double intercept = 0, slope = 0, min = 0, max = 0;
    std::vector<std::pair<double, double>> deviations;  // (x, (signal − fitted)/fitted)
  };
  std::optional<Linearity> linearity;
  // σ²_y.dark at no exposure (DN²): the dark variance's line against exposure time at t = 0, or the shortest
  // exposure's with one time; its line's slope (DN²/s) with several.
  double dark_variance_dn2 = 0;
  std::optional<double> dark_variance_slope;
  std::optional<double> saturation_photons;   // μp.sat, when the photons are known
  std::optional<Estimate> responsivity;       // R = ηK, DN per photon
  std::optional<Estimate> quantum_efficiency;
  std::vector<std::string> notes;   // what could not be estimated, and why
};

// The datasheet's derived figures (EMVA 1288 Release 4.0, as its reference implementation computes them).
struct Sensitivity {
  double inverse_gain = 0;           // 1/K, e⁻/DN
  double dark_sigma_dn = 0;          // σ_y.dark, DN (at least √0.24: the quantisation limit)
  double threshold_e = 0;            // μe.min = σ_y.dark/K + 1/2, the absolute sensitivity threshold in electrons
  std::optional<double> threshold_photons;  // μp.min = μe.min/η
  double snr_max = 0;                // √μe.sat
  double dynamic_range = 0;          // μe.sat/μe.min (= μp.sat/μp.min)
  double dsnu_dn = 0;                // DSNU in DN
};
Sensitivity sensitivity(const ChannelCalibration& c);

// Estimates one channel's parameters. InputError (message without a file name; the caller adds it) when the
// steps cannot support the estimates: one flat or fewer than two darks at a step, frames of different sizes,
// fewer than three exposure steps below saturation, or no step that saturates (the saturation capacity and the
// 70 % range of the gain fit need it).
ChannelCalibration calibrate_channel(const std::string& channel, const std::vector<ExposureStep>& steps);

}  // namespace ct::calibrate
