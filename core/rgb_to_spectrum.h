#pragma once
// RGB -> smooth reflectance spectrum, after W. Jakob and J. Hanika, "A Low-Dimensional Function Space for
// Efficient Spectral Upsampling", Computer Graphics Forum 38(2), 2019.
//
// The spectrum is s(λ) = sigmoid(c0 λ'² + c1 λ' + c2), with λ' the wavelength mapped to [0, 1] over
// 360–830 nm and sigmoid(x) = ½ + x / (2 sqrt(1 + x²)). It is smooth, bounded in (0, 1), and its three
// coefficients are found by Gauss–Newton so that the spectrum, lit by D65 and seen by the CIE 1931
// observer, has the requested linear sRGB colour (the paper's own fit minimises CIELAB error; we solve the
// same equations for each colour on demand instead of tabulating them).

#include <array>

#include "core/spectrum.h"

namespace ct {

struct SigmoidPolynomial {
  std::array<double, 3> c{};  // coefficients for λ' in [0, 1]
  double operator()(double nm) const;
};

// A fitted spectrum times a scale: scale · sigmoid polynomial. A reflectance has scale 1 (at most); an
// emission colour (unbounded RGB) has scale 2·max(r, g, b), so its shape is the fit of rgb / scale.
struct ScaledSigmoid {
  double scale = 1.0;
  SigmoidPolynomial poly;
  double operator()(double nm) const { return scale * poly(nm); }
  // The value of the tabulated spectrum (samples every 1 nm over 360–830 nm, linear between them, clamped
  // outside): what tabulated() gives, without building it.
  double tabulated_at(double nm) const;
  // scale · poly sampled every 1 nm over 360–830 nm, clamped outside: the form rgb_to_spectrum returns.
  PiecewiseLinearSpectrum tabulated() const;
};

// Finds the sigmoid polynomial whose D65-lit colour is the given linear sRGB reflectance (each component
// in [0, 1]; values outside are clamped, with 0 and 1 mapped to the flat spectra 0 and 1).
SigmoidPolynomial fit_rgb_reflectance(const std::array<double, 3>& linear_srgb);
// The fitted spectrum tabulated every 1 nm over 360–830 nm (clamped outside), the grid it was fitted on.
PiecewiseLinearSpectrum rgb_to_spectrum(const std::array<double, 3>& linear_srgb);
// Unbounded linear sRGB (an emitter's or an environment's colour; components >= 0, negatives clamped to 0), as
// Jakob and Hanika suggest for values outside the unit cube: scale = 2·max(r, g, b) and the reflectance fit of
// rgb / scale, whose largest component is then ½. Black gives scale 0; a grey g gives exactly the flat g.
ScaledSigmoid fit_rgb_unbounded(const std::array<double, 3>& linear_srgb);

}  // namespace ct
