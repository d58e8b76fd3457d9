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

// Finds the sigmoid polynomial whose D65-lit colour is the given linear sRGB reflectance (each component
// in [0, 1]; values outside are clamped, with 0 and 1 mapped to the flat spectra 0 and 1).
SigmoidPolynomial fit_rgb_reflectance(const std::array<double, 3>& linear_srgb);
// The fitted spectrum tabulated every 1 nm over 360–830 nm (clamped outside), the grid it was fitted on.
PiecewiseLinearSpectrum rgb_to_spectrum(const std::array<double, 3>& linear_srgb);

}  // namespace ct
