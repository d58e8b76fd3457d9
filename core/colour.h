// SPDX-License-Identifier: Apache-2.0
#pragma once
// Colorimetry: spectra to XYZ, xyY, CIELAB, ΔE2000, linear sRGB and its transfer curve.
//
// Conventions: XYZ of an emitter is ∫ S(λ) x̄(λ) dλ with λ in nm (no 683 lm/W factor). XYZ of a
// reflectance under an illuminant is normalised so that the perfect white has Y = 1 (or 100 where stated).

#include <array>

#include "core/spectrum.h"

namespace ct {

using Vec3d = std::array<double, 3>;

// Tristimulus values of an emission spectrum: ∫ S x̄ dλ etc. over 360–830 nm, exact for piecewise-linear S.
Vec3d spectrum_to_xyz(const PiecewiseLinearSpectrum& emission);
// Tristimulus values of band values (a step function over `bands`), with the CMFs integrated exactly
// over each band.
Vec3d bands_to_xyz(const std::vector<double>& values, const Bands& bands);
// Per-band weights w_c[i] = ∫_{band i} c̄(λ) dλ, so that XYZ = Σ_i value_i · w[i] (values are averages); with
// the bands' reconstruction, the weights of the spectrum it makes of the values (band_weights).
std::array<std::vector<double>, 3> xyz_band_weights(const Bands& bands);
// Reflectance under an illuminant, normalised so that reflectance 1 gives Y = 1.
Vec3d reflectance_to_xyz(const PiecewiseLinearSpectrum& reflectance, const PiecewiseLinearSpectrum& illuminant);

Vec3d xyz_to_xyY(const Vec3d& xyz);
Vec3d xyY_to_xyz(const Vec3d& xyY);
// Chromaticity (x, y) of a spectrum.
std::array<double, 2> chromaticity(const PiecewiseLinearSpectrum& emission);

// CIELAB relative to a white point (any scale; only the ratios XYZ / white matter).
Vec3d xyz_to_lab(const Vec3d& xyz, const Vec3d& white);
Vec3d lab_to_xyz(const Vec3d& lab, const Vec3d& white);
// CIEDE2000 colour difference (Sharma, Wu, Dalal 2005), with kL = kC = kH = 1 unless given.
double delta_e_2000(const Vec3d& lab1, const Vec3d& lab2, double kL = 1.0, double kC = 1.0, double kH = 1.0);

// White points (XYZ with Y = 1) of the sRGB / D65 and D50 conventions, from their defining chromaticities.
Vec3d d65_white();
// Linear sRGB (IEC 61966-2-1, D65 white, Y = 1 for white) from and to XYZ.
Vec3d xyz_to_linear_srgb(const Vec3d& xyz);
Vec3d linear_srgb_to_xyz(const Vec3d& rgb);
// The sRGB transfer curve (IEC 61966-2-1): linear -> encoded and back, for one channel.
double srgb_encode(double linear);
double srgb_decode(double encoded);

}  // namespace ct
