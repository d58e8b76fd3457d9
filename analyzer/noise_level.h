// SPDX-License-Identifier: Apache-2.0
#pragma once
// The noise level a cluster's extent is judged against, estimated once for the whole image.
//
// Immerkær's 3×3 mask [1 −2 1; −2 4 −2; 1 −2 1] (Fast noise variance estimation, CVIU 64, 1996) cancels any
// locally planar signal, such as smooth shading, and leaves 6σ of white noise. Applied to R, G, B together it
// gives a residual vector r per pixel whose projection on a unit vector u has 6 × the noise σ along u, whatever
// the correlation of the channels. Texture is not cancelled, so the flat areas of the image decide, per band of
// brightness (shot noise grows with the signal): a start from the 25th percentile of |r·u| (0.3186 × 6σ for
// Gaussian noise), then a clip iterated to its fixed point, the median of the |r·u| within 3 × 6σ (0.6727 × 6σ
// for a Gaussian truncated there), which leaves out the textured pixels whose residuals lie far beyond the
// noise. A region's noise along u is the root of the bands' variances averaged over its samples' brightness:
// the noise of a textured surface is the image's noise at its brightness, not the spread of its texture.
//
// The mask assumes noise independent from pixel to pixel. Demosaicing (and a camera's further processing, JPEG
// compression, resampling) makes neighbouring pixels share their noise, and the mask on adjacent pixels sees
// little of it: on bilinear-demosaiced white noise, red and blue residuals vanish at three pixels of four and the
// estimate falls to 0, green's to a third. With its taps `spacing` pixels apart the mask still cancels a planar
// signal; the spacing is the smallest at which the noise's measured correlation shows it independent
// (choose_noise_spacing), at most 3 (beyond the reach of a 3×3 interpolation).

#include <algorithm>
#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <span>
#include <vector>

#include "analyzer/image_input.h"
#include "analyzer/moments.h"

namespace ct::analyzer {

// Immerkær's mask at pixel p of an image `width` pixels wide, its taps `spacing` pixels apart: Σ mask · value(q)
// over the taps q, 6σ of white noise and nothing of a locally planar signal; none when a tap is not usable(q)
// (clamped and clipped values carry no noise). p must lie `spacing` pixels inside the image's edges.
inline constexpr double kImmerkaerGain = 6;      // the mask's response to white noise of σ 1: √(Σ mask²)
inline constexpr double kQuartileAbs = 0.3186;   // the 25th percentile of |N(0, 1)|
template <class Value, class Usable>
std::optional<double> immerkaer_response(std::size_t p, std::size_t width, std::size_t spacing, Value value, Usable usable) {
  static constexpr int kMask[3][3] = {{1, -2, 1}, {-2, 4, -2}, {1, -2, 1}};
  double r = 0;
  for (int j = -1; j <= 1; ++j)
    for (int k = -1; k <= 1; ++k) {
      const std::size_t q = static_cast<std::size_t>(static_cast<std::ptrdiff_t>(p) +
                                                     static_cast<std::ptrdiff_t>(spacing) * (j * static_cast<std::ptrdiff_t>(width) + k));
      if (!usable(q)) return std::nullopt;
      r += kMask[j + 1][k + 1] * static_cast<double>(value(q));
    }
  return r;
}

// A camera's own noise, from its calibration (chromatrace calibrate: a chromatrace-sensor/1 file), in digital numbers
// above black: a value of mean signal μ varies by K²(σ_read² + DSNU²) + 1/12 + K·μ + (PRNU·μ)² — read noise, fixed
// offsets, quantisation, shot noise and fixed gains, all of which spread one image's cluster (DSNU and PRNU with
// their row and column parts). The dark current's shot noise is left out: the exposure time is not the model's.
struct CameraNoiseModel {
  double gain_dn_per_e = 1, read_e = 0, dsnu_e = 0, prnu = 0;
  std::string source;  // the file it came from
  double variance(double mean_dn) const {
    return gain_dn_per_e * gain_dn_per_e * (read_e * read_e + dsnu_e * dsnu_e) + 1.0 / 12.0 + gain_dn_per_e * std::max(0.0, mean_dn) +
           prnu * prnu * mean_dn * mean_dn;
  }
};

// The mask's spacing chosen by the noise's measured correlation (choose_noise_spacing). At spacing s the residuals
// of noise independent from pixel to pixel at that distance correlate with their neighbours' s pixels on by exactly
// −2/3 (the mask's own autocorrelation: [1 −2 1] against itself shifted by one tap, −4/6); noise shared between
// pixels s apart (demosaicing, compression, resampling) moves that correlation and makes the mask under-read σ by
// about 4.8 times the departure. The correlation is Gnanadesikan and Kettenring's robust one, (S+² − S−²)/(S+² + S−²)
// with S± the clipped-median σ (as the bands') of (z(p) ± z(q))/√2, z the residual over its band's σ, so that
// texture beyond 3σ does not count; its standard error by the jackknife over 4 × 4 tiles of the image.
struct SpacingTest {
  int spacing = 0;
  double departure = 0;        // |ρ + 2/3| of the worst channel, corrected for the rounding's white share (integer files)
  double standard_error = 0;   // of the departure
  bool measurable = false;     // residuals enough, and the noise above the rounding in every channel
};
struct SpacingChoice {
  int spacing = 3;
  bool confirmed = false;          // independence shown at the chosen spacing: departure + 2 SE ≤ kSpacingTolerance
  bool correlated_beyond = false;  // at the largest spacing the noise is still shared: σ is a lower bound
  std::vector<SpacingTest> tests;  // spacings 1, 2, 3
};
// Independent within this departure: about a 10 % bias of σ (4.8 × 0.02), the sampling error of a 50-pixel cluster's
// own σ (1/√(2n)), which moves noise_factor 3 to 2.7–3.3.
inline constexpr double kSpacingTolerance = 0.02;
// Still correlated at the largest spacing when the departure exceeds this by 3 SE: two standard errors of a band's σ
// from 4096 residuals (2 × 1.8 %) over 4.8.
inline constexpr double kCorrelatedBeyond = 0.0076;

// The smallest spacing of 1, 2 and 3 at which the noise is shown independent, else 3. `step`: the file's code step
// (1 for an integer file's stored codes, 0 for a float file): integer values get a deterministic dither of ± step/2
// so that rounding neither fakes independence nor quantises the estimator. Limits as for estimate_image_noise.
SpacingChoice choose_noise_spacing(const RgbImage& image, const std::array<double, 3>& low_levels,
                                   const std::array<double, 3>& high_levels, double step);

struct ImageNoise {
  struct Band {
    double lo = 0, hi = 0;         // the brightness (mean of R, G, B) of its pixels
    std::vector<float> residuals;  // Immerkær residuals / 6, [i][channel]
    std::optional<Vec3> model_variance;  // per channel, from the camera's calibration: used instead of the residuals
  };
  std::optional<CameraNoiseModel> camera;  // the model the bands' variances come from, when one was given
  // By increasing brightness, each holding a sixteenth of the image's finite pixels (a band whose pixels have too
  // few residuals takes the nearest band's); empty when too few pixels were usable.
  std::vector<Band> bands;
  std::size_t pixels = 0;   // pixels with a residual: finite, unclipped 3×3 neighbourhoods (at an even stride)
  double floor = 0;         // never below: the quantisation noise of integer images (step/√12), else 0
  int spacing = 1;          // pixels between the mask's taps
  std::optional<SpacingChoice> spacing_choice;  // how it was chosen, when it was measured

  // The band a brightness falls into (the nearest at the ends).
  std::size_t band_of(double brightness) const;
  // The noise σ along the unit vector u in one band (not floored).
  double band_sigma(std::size_t band, const Vec3& u) const;
};

// Pixels whose 3×3 neighbourhood holds a non-finite value, a value at or below a channel's lower limit
// (`low_levels`: the lowest code, where a converter clamps) or at or above its clipping level (`high_levels`,
// +∞ for none) have no residual: clamped values carry no noise. At most `max_pixels` pixels are used, at an
// even stride; deterministic. `spacing`: 1 when the image says each pixel's noise is its own, else the one
// choose_noise_spacing chose.
inline constexpr int kInterpolatedNoiseSpacing = 3;
ImageNoise estimate_image_noise(const RgbImage& image, const std::array<double, 3>& low_levels, const std::array<double, 3>& high_levels,
                                double floor, int spacing = 1, std::size_t max_pixels = std::size_t{1} << 18);

// The camera's noise instead of the image's: each band of `noise` (one band over the whole image when it has none)
// takes the model's variance at the mean R, G, B of the layer's pixels in it.
void use_camera_noise(ImageNoise& noise, const RgbImage& layer, const CameraNoiseModel& model);

// The share of samples in each band of `noise` (from at most 2²⁰ of them, at an even stride).
std::vector<double> band_weights(const ImageNoise& noise, std::span<const float> rgb);

// The noise standard deviation along the unit vector u for samples with those band weights; never below the floor.
double noise_sigma(const ImageNoise& noise, std::span<const double> weights, const Vec3& u);

}  // namespace ct::analyzer
