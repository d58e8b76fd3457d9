// SPDX-License-Identifier: Apache-2.0
#pragma once
// Spectra and bands.
//
// A spectrum is a function of wavelength in nm. chromatrace uses two representations:
//  - PiecewiseLinearSpectrum: tabulated samples joined by straight lines (the form of every published
//    table), zero outside its range unless it clamps to the end values;
//  - band values: one number per band of a Bands plan, the average of the spectrum over [lo, hi).
// Band averages are exact integrals of the piecewise-linear function, not point samples.

#include <cstddef>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace ct {

// Physical constants (CODATA 2018, exact in SI).
inline constexpr double kPlanck = 6.62607015e-34;      // J s
inline constexpr double kLightSpeed = 299792458.0;     // m / s
inline constexpr double kBoltzmann = 1.380649e-23;     // J / K
// Wien's displacement constant b in m K (CODATA 2018): lambda_max = b / T.
inline constexpr double kWien = 2.897771955e-3;

enum class Extrapolation { Zero, Clamp };

class PiecewiseLinearSpectrum {
 public:
  PiecewiseLinearSpectrum() = default;
  // Wavelengths must be strictly increasing and finite, values finite; sizes equal and >= 1.
  // Throws InputError otherwise, naming `what` (e.g. "spectra.paint.samples").
  PiecewiseLinearSpectrum(std::vector<double> wavelengths, std::vector<double> values,
                          Extrapolation outside = Extrapolation::Zero, const std::string& what = "spectrum");
  static PiecewiseLinearSpectrum constant(double value);  // clamps everywhere

  double operator()(double nm) const;
  // Integral over [lo, hi] in value·nm, exact for the piecewise-linear function (including extrapolation).
  double integral(double lo, double hi) const;
  // Average over [lo, hi); for lo == hi the value at lo.
  double average(double lo, double hi) const;

  const std::vector<double>& wavelengths() const { return lambda_; }
  const std::vector<double>& values() const { return value_; }
  Extrapolation extrapolation() const { return outside_; }
  double min_wavelength() const { return lambda_.front(); }
  double max_wavelength() const { return lambda_.back(); }
  bool empty() const { return lambda_.empty(); }

  PiecewiseLinearSpectrum scaled(double factor) const;

 private:
  std::vector<double> lambda_;
  std::vector<double> value_;
  Extrapolation outside_ = Extrapolation::Zero;
};

// How the band values of a render stand for a spectrum when a step function (each band's value over the band)
// is not good enough: a linear map from the N band values to the values of `fine` uniform bands
// [lo + j·step, lo + (j+1)·step), fine value j = Σ_i matrix[j·N + i]·value_i. `chromatrace plan` fits it to the
// scene's spectra (docs/plan.md); it travels with the bands (band-plan file, EXR header) and every conversion of
// band values to a colour (band_weights) uses it.
struct BandReconstruction {
  double lo_nm = 0, step_nm = 0;
  std::size_t fine = 0;
  std::vector<double> matrix;  // fine × N, row-major
  bool operator==(const BandReconstruction&) const = default;
};

// A band plan: N contiguous or non-contiguous bands [lo_i, hi_i). Stored as N+1 edges when contiguous;
// arbitrary (lo, hi) pairs are allowed for files whose bands were given by centres only.
class Bands {
 public:
  Bands() = default;
  // Contiguous bands from strictly increasing edges (at least two).
  static Bands from_edges(std::vector<double> edges, const std::string& what = "bands");
  // Uniform bands covering [lo, hi) with the given width; hi - lo must be a whole number of widths
  // (within 1e-9 nm).
  static Bands uniform(double lo, double hi, double width, const std::string& what = "bands");
  // Parses "lo:hi:width" (e.g. "380:780:10"); errors name `what`.
  static Bands parse(const std::string& spec, const std::string& what = "--bands");
  // Bands from centre wavelengths only: each reaches halfway to its neighbours; the outer bands are
  // symmetric about their centres (as the spectral EXR layout prescribes).
  static Bands from_centres(const std::vector<double>& centres, const std::string& what = "bands");

  std::size_t size() const { return edges_.empty() ? 0 : edges_.size() - 1; }
  double lo(std::size_t i) const { return edges_[i]; }
  double hi(std::size_t i) const { return edges_[i + 1]; }
  double centre(std::size_t i) const { return 0.5 * (edges_[i] + edges_[i + 1]); }
  double width(std::size_t i) const { return edges_[i + 1] - edges_[i]; }
  const std::vector<double>& edges() const { return edges_; }
  double min_wavelength() const { return edges_.front(); }
  double max_wavelength() const { return edges_.back(); }

  // The reconstruction the band values carry, or null (a step function).
  const BandReconstruction* reconstruction() const { return reconstruction_.get(); }
  // The same bands with a reconstruction: its matrix must have fine × size() finite entries, its fine bands a
  // positive start and step. Its numbers are kept at float precision, as the EXR header stores them. Errors name
  // `what`.
  Bands with_reconstruction(BandReconstruction r, const std::string& what = "reconstruction") const;
  Bands without_reconstruction() const { return from_edges(edges_); }
  bool operator==(const Bands& o) const {
    return edges_ == o.edges_ && (reconstruction_ == o.reconstruction_ ||
                                  (reconstruction_ && o.reconstruction_ && *reconstruction_ == *o.reconstruction_));
  }

 private:
  std::vector<double> edges_;
  std::shared_ptr<const BandReconstruction> reconstruction_;
};

// Weights w_i such that Σ_i value_i·w_i = ∫ f(λ)·s(λ) dλ for the spectrum s that band values stand for, given
// integral(lo, hi) = ∫ f over [lo, hi]: w_i = integral(lo_i, hi_i) for a step function, and
// Σ_j matrix[j·N + i]·integral(fine band j) with a reconstruction. Every observer or camera applied to band
// values goes through this.
std::vector<double> band_weights(const Bands& bands, const std::function<double(double, double)>& integral);

// Band averages of a spectrum over each band.
std::vector<double> band_averages(const PiecewiseLinearSpectrum& s, const Bands& bands);
// Band averages of an arbitrary smooth function, by composite Gauss–Legendre quadrature (for Planck etc.).
std::vector<double> band_averages(const std::function<double(double)>& f, const Bands& bands);

// Resamples a spectrum onto new sample wavelengths: each new sample is the average of `s` over the
// interval halfway to its neighbours (a box filter), which preserves the integral of `s` over the covered
// range for smooth spectra far better than point sampling does for coarse grids.
PiecewiseLinearSpectrum resample(const PiecewiseLinearSpectrum& s, const std::vector<double>& wavelengths);

// ∫ f1·f2 (·f3) dλ over [lo, hi], exact for piecewise-linear factors (3-point Gauss–Legendre between the
// merged breakpoints integrates the piecewise-cubic product exactly).
double integral_of_product(const PiecewiseLinearSpectrum& f1, const PiecewiseLinearSpectrum& f2, double lo, double hi);
double integral_of_product(const PiecewiseLinearSpectrum& f1, const PiecewiseLinearSpectrum& f2,
                           const PiecewiseLinearSpectrum& f3, double lo, double hi);

// Band values seen as a step function (value i on [lo_i, hi_i)): their integral over all bands.
double integrate_band_values(const std::vector<double>& values, const Bands& bands);

// Planck's law: spectral radiance of a blackbody in W m^-2 sr^-1 nm^-1 at wavelength `nm` and
// temperature `kelvin`.
double planck(double nm, double kelvin);
// The blackbody spectrum as a PiecewiseLinearSpectrum sampled every `step_nm` over [lo, hi],
// normalised to 1 at its peak if `normalise` (the convention for "blackbody_k" light colours).
PiecewiseLinearSpectrum blackbody(double kelvin, double lo = 300.0, double hi = 830.0, double step_nm = 1.0,
                                  bool normalise = false);

}  // namespace ct
