// SPDX-License-Identifier: Apache-2.0
#pragma once
// RGB -> smooth spectrum, after W. Jakob and J. Hanika, "A Low-Dimensional Function Space for Efficient
// Spectral Upsampling", Computer Graphics Forum 38(2), 2019.
//
// The spectrum is s(λ) = sigmoid(c0 λ'² + c1 λ' + c2), with λ' the wavelength mapped to [0, 1] over
// 360–830 nm and sigmoid(x) = ½ + x / (2 sqrt(1 + x²)). It is smooth, bounded in (0, 1), and its three
// coefficients are those for which the spectrum, lit by D65 and seen by the CIE 1931 observer, has the
// requested linear sRGB colour (the paper's own fit minimises CIELAB error; we solve the colour equations).
//
// Two levels:
//  - fit_rgb_reflectance: the exact fit, by Gauss–Newton per colour (~0.5 ms). The reference, and what the
//    coefficient table is made of.
//  - upsample_rgb_reflectance / upsample_rgb_unbounded / rgb_to_spectrum: THE upsampling every part of
//    chromatrace uses ({"rgb"} spectra of the scene format, the colours the Blender add-on asks `chromatrace`
//    for, image textures and the environment in the tracer, `chromatrace prepare-texture` for Cycles). They
//    interpolate a table of exact fits (RgbCoefficientTable, as Jakob and Hanika and pbrt-v4 do), made at build
//    time by core/make_rgb_table.cpp and compiled into the library: ~0.3 µs per colour. Greys (black and white
//    included) are exactly flat. Against the exact fit, over 200 000 colours (bench/bench_rgb_table,
//    bench/README.md "RGB upsampling table"): D65-lit colours within 0.104 ΔE00 (rms 0.012), linear sRGB within
//    7.4e-4 of the request, 10 nm band averages within 0.065 of the spectrum's peak (rms 0.002); the bounds
//    tests/core/test_rgb_to_spectrum.cpp asserts are derived from these. A single {"rgb"} colour uses the
//    table too (not the exact fit), so that a texture of one colour is that colour's spectrum and the tracer,
//    the add-on and prepare-texture agree bit for bit.
//  - An RGB colour that is emitted (a light's, the environment's, an HDR image's texel) is relative to the
//    colour space's white: the upsampled shape times D65 of unit luminance (rgb_white_at), as in pbrt-v4 and
//    Mitsuba 3, so that (1, 1, 1) is D65 and not the equal-energy spectrum.

#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "core/spectrum.h"

namespace ct {

struct SigmoidPolynomial {
  std::array<double, 3> c{};  // coefficients for λ' in [0, 1]
  double operator()(double nm) const;
};

// The white of linear sRGB (Blender's scene-linear space) as an emitter's spectrum: CIE D65 scaled to the
// luminance of the flat spectrum 1 (Σ D65·ȳ = Σ ȳ by the trapezoid rule on the 1 nm grid), linear between its
// samples every 1 nm over 360–830 nm, clamped outside. An RGB emitter's spectrum is its upsampled shape times
// this, as pbrt-v4's RGBIlluminantSpectrum and Mitsuba 3's emitters make it: RGB (1, 1, 1) emits D65, the
// white Blender's RGB lights, world colours and HDR images mean, and a light's luminance is that of the flat
// spectrum of its RGB's luminance. Its linear sRGB colour seen by the CIE 1931 observer is the RGB asked for
// (within the upsampling's 7.4e-4 and the 1e-4 by which tabulated D65 misses the sRGB white point).
double rgb_white_at(double nm);

// A fitted spectrum times a scale: scale · sigmoid polynomial, and for an emitter (`illuminant`) times the
// colour space's white, rgb_white_at. A reflectance has scale 1 (at most); an emission colour (unbounded RGB) has
// scale 2·max(r, g, b), so its shape is the fit of rgb / scale.
struct ScaledSigmoid {
  double scale = 1.0;
  SigmoidPolynomial poly;
  bool illuminant = false;  // times rgb_white_at: an RGB emitter's spectrum, relative to D65
  double operator()(double nm) const { return illuminant ? scale * poly(nm) * rgb_white_at(nm) : scale * poly(nm); }
  // The value of the tabulated spectrum (samples every 1 nm over 360–830 nm, linear between them, clamped
  // outside): what tabulated() gives, without building it.
  double tabulated_at(double nm) const;
  // scale · poly sampled every 1 nm over 360–830 nm, clamped outside: the form rgb_to_spectrum returns.
  PiecewiseLinearSpectrum tabulated() const;
  // The samples of tabulated() that an average over [lo_nm, hi_nm] reads, with one more on each side (all of them
  // where the range reaches past 360 or 830 nm): averages over any part of [lo_nm, hi_nm] are those of
  // tabulated(), bit for bit, for fewer evaluations of the sigmoid.
  PiecewiseLinearSpectrum tabulated(double lo_nm, double hi_nm) const;
};

// The band averages of s.tabulated(): bit for bit band_averages(s.tabulated(), bands) (the same samples and the
// same arithmetic as PiecewiseLinearSpectrum::average on the 1 nm grid), written to out[0 … bands.size() - 1]
// without building the tabulated spectrum — what a texture's palette needs millions of times.
void tabulated_band_averages(const ScaledSigmoid& s, const Bands& bands, double* out);

// The exact fit: the sigmoid polynomial whose D65-lit colour is the given linear sRGB reflectance (each
// component in [0, 1]; values outside are clamped, with 0 and 1 mapped to the flat spectra 0 and 1), by
// Gauss–Newton continued from the grey of the same mean.
SigmoidPolynomial fit_rgb_reflectance(const std::array<double, 3>& linear_srgb);
// The linear sRGB colour of a sigmoid reflectance lit by D65, as the fit computes it (trapezoid rule on the 1 nm
// grid; the perfect reflector is (1, 1, 1)): what fit_rgb_reflectance solves for.
std::array<double, 3> reflectance_linear_srgb(const SigmoidPolynomial& poly);
// Unbounded linear sRGB (an emitter's or an environment's colour; components >= 0, negatives clamped to 0), as
// Jakob and Hanika suggest for values outside the unit cube: scale = 2·max(r, g, b) and the reflectance fit of
// rgb / scale, whose largest component is then ½. Black gives scale 0; a grey g gives exactly the flat g.
// Exact fit (fit_rgb_reflectance); upsample_rgb_unbounded is the same through the table.
ScaledSigmoid fit_rgb_unbounded(const std::array<double, 3>& linear_srgb);

// A table of sigmoid coefficients over the RGB cube, laid out as Jakob and Hanika's (and pbrt-v4's): for each
// choice of the largest component l (r, g or b), nodes at z = rgb[l] on a nonlinear scale
// z_k = smoothstep(smoothstep(k / (n - 1))), k = 1 … n - 1 (dense towards 0 and 1, where the coefficients
// diverge; n is odd so that z = ½, every unbounded colour's, is a node plane), and at x = rgb[l+1] / z,
// y = rgb[l+2] / z on the scale smoothstep(i / (n - 1)). Each node holds the exact fit of its colour, found by
// Gauss–Newton warm-started from its neighbour (the middle plane z = ½ is swept outward from white, each column
// then up and down in z), far faster than cold fits; it is stored as c·√z (in float), which the sigmoid's
// asymptote makes constant for dark colours. Lookup is trilinear in (x, y, z) on c·√z, then divided by √z.
class RgbCoefficientTable {
 public:
  RgbCoefficientTable() = default;
  // Computes the table (the only slow part: ~3 n³ warm-started fits) on up to `threads` threads (0: all); the
  // result does not depend on the thread count.
  static RgbCoefficientTable compute(int resolution, int threads = 0);
  // The table from serialised bytes (what bytes() gives); throws std::runtime_error if they are not one.
  static RgbCoefficientTable from_bytes(std::string_view bytes);
  std::string bytes() const;

  int resolution() const { return n_; }
  // The node value z_k (k in [0, n - 1]; z_0 = 0, z_{n-1} = 1).
  double z_node(int k) const;
  // The node value x_i = y_i (i in [0, n - 1]): smoothstep(i / (n - 1)), dense towards 0, where a vanishing
  // component makes the coefficients diverge, and towards 1 (near white).
  double xy_node(int i) const;
  // The coefficients of a reflectance in [0, 1]³ (clamped into it): greys exact (flat; black and white the
  // limits 0 and 1); z below z_1 scaled from the z_1 plane by the sigmoid's asymptote (coefficients ∝ 1/√z,
  // exact to ~1/c2², below 1e-5); colours whose interpolation would involve white's (infinite) coefficients —
  // z above z_{n-2} = 1 - O(n⁻⁴) with both x and y above x_{n-2} = 1 - O(n⁻²), 1 - 7e-4 for n = 65 — fitted
  // exactly (fit_rgb_reflectance).
  SigmoidPolynomial lookup(const std::array<double, 3>& linear_srgb) const;
  // Stored coefficients of node (l, k, j, i): largest component l, z_k (k >= 1), y_j, x_i.
  std::array<double, 3> node(int l, int k, int j, int i) const;

 private:
  std::size_t offset(int l, int k, int j, int i) const;
  int n_ = 0;
  std::vector<float> data_;  // [l][k-1][j][i][3]
};

// The table compiled into the library (core/make_rgb_table.cpp at build time; its resolution is
// kRgbTableResolution in core/CMakeLists.txt).
const RgbCoefficientTable& rgb_table();

// The upsampling every part of chromatrace uses: rgb_table().lookup for a reflectance in [0, 1]³.
SigmoidPolynomial upsample_rgb_reflectance(const std::array<double, 3>& linear_srgb);
// As fit_rgb_unbounded, through the table: scale 2·max(r, g, b) and the table's reflectance of rgb / scale.
ScaledSigmoid upsample_rgb_unbounded(const std::array<double, 3>& linear_srgb);
// upsample_rgb_reflectance tabulated every 1 nm over 360–830 nm (clamped outside): an {"rgb": ...} spectrum.
PiecewiseLinearSpectrum rgb_to_spectrum(const std::array<double, 3>& linear_srgb);
// The same shape times the colour space's white (rgb_white_at), tabulated alike: an {"rgb": ...} spectrum where a
// radiance is expected (a light, an emissive material, the environment), relative to D65.
PiecewiseLinearSpectrum rgb_to_emission_spectrum(const std::array<double, 3>& linear_srgb);

}  // namespace ct
