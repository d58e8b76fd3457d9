// SPDX-License-Identifier: Apache-2.0
// RGB upsampling (Jakob & Hanika 2019): the fitted spectra reproduce their colour and are smooth, bounded; the
// coefficient table every part of chromatrace upsamples with reproduces the exact fit within the bound measured
// by bench/bench_rgb_table (bench/README.md, "RGB upsampling table").
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "core/cie.h"
#include "core/colour.h"
#include "core/random.h"
#include "core/rgb_to_spectrum.h"

namespace ct {
namespace {

// Linear sRGB of a reflectance lit by D65, with the perfect reflector mapped to (1, 1, 1), computed by
// exact integration of the tabulated spectrum (independent of the fitting code's quadrature).
Vec3d seen_under_d65(const PiecewiseLinearSpectrum& r) {
  const PiecewiseLinearSpectrum& d65 = cie::illuminant("D65");
  const Vec3d rgb = xyz_to_linear_srgb(reflectance_to_xyz(r, d65));
  const Vec3d white = xyz_to_linear_srgb(reflectance_to_xyz(PiecewiseLinearSpectrum::constant(1.0), d65));
  return {rgb[0] / white[0], rgb[1] / white[1], rgb[2] / white[2]};
}

Vec3d lab_of(const Vec3d& linear_srgb) {
  static const Vec3d white = xyY_to_xyz({0.31271, 0.32902, 1.0});
  return xyz_to_lab(linear_srgb_to_xyz(linear_srgb), white);
}

TEST(RgbToSpectrum, GreysAreFlat) {
  for (double g : {0.0, 1e-9, 0.003, 0.18, 0.5, 0.9999999, 1.0}) {
    const PiecewiseLinearSpectrum s = rgb_to_spectrum({g, g, g});
    for (double v : s.values()) EXPECT_NEAR(v, g, 1e-12) << g;
  }
  // Unbounded: a grey g is exactly the flat g, black exactly 0.
  for (double g : {0.0, 1e-6, 0.4, 1.0, 7.5, 3e4}) {
    const ScaledSigmoid s = upsample_rgb_unbounded({g, g, g});
    for (double nm : {360.0, 455.5, 550.0, 700.0, 830.0}) EXPECT_NEAR(s(nm), g, 1e-12 * std::max(g, 1.0)) << g;
  }
  EXPECT_EQ(upsample_rgb_unbounded({0.0, 0.0, 0.0}).scale, 0.0);
  EXPECT_EQ(upsample_rgb_unbounded({-1.0, -2.0, 0.0}).scale, 0.0);
  const PiecewiseLinearSpectrum black = rgb_to_spectrum({0.0, 0.0, 0.0});
  for (double v : black.values()) EXPECT_EQ(v, 0.0);
}

// The table's error against the exact fit, measured by bench_rgb_table over 200 000 colours with the embedded
// resolution 65 (bench/README.md, "RGB upsampling table"): ΔE00 at most 0.104 for reflectances and 0.048 for
// radiances, band averages (10 nm) within 0.065 of the spectrum's peak, linear sRGB within 7.4e-4. The bounds
// below are those maxima raised by about a quarter, and checked here on a smaller set of the same kinds.
constexpr double kTableDeltaE = 0.13;
constexpr double kTableBandError = 0.08;
constexpr double kTableRgbError = 9e-4;

TEST(RgbToSpectrum, TableReproducesTheExactFit) {
  const Bands bands = Bands::parse("360:830:10");
  std::vector<Vec3d> colours;
  for (int r = 0; r <= 255; r += 51)
    for (int g = 0; g <= 255; g += 51)
      for (int b = 0; b <= 255; b += 51)
        colours.push_back({srgb_decode(r / 255.0), srgb_decode(g / 255.0), srgb_decode(b / 255.0)});
  for (int i = 0; i < 600; ++i) {
    Random random(3, static_cast<std::uint64_t>(i));
    colours.push_back({srgb_decode(random.uniform()), srgb_decode(random.uniform()), srgb_decode(random.uniform())});
    colours.push_back({random.uniform(), random.uniform(), random.uniform()});
  }
  double worst_de = 0.0, worst_band = 0.0;
  for (const Vec3d& rgb : colours) {
    const SigmoidPolynomial table = upsample_rgb_reflectance(rgb), exact = fit_rgb_reflectance(rgb);
    const Vec3d got = reflectance_linear_srgb(table), want = reflectance_linear_srgb(exact);
    const double de = delta_e_2000(lab_of(got), lab_of(want));
    worst_de = std::max(worst_de, de);
    EXPECT_LT(de, kTableDeltaE) << rgb[0] << "," << rgb[1] << "," << rgb[2];
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], rgb[c], kTableRgbError) << rgb[0] << "," << rgb[1] << "," << rgb[2];
    const std::vector<double> a = band_averages(ScaledSigmoid{1.0, table}.tabulated(), bands);
    const std::vector<double> e = band_averages(ScaledSigmoid{1.0, exact}.tabulated(), bands);
    const double peak = *std::max_element(e.begin(), e.end());
    for (std::size_t i = 0; i < a.size(); ++i) {
      worst_band = std::max(worst_band, std::abs(a[i] - e[i]) / peak);
      EXPECT_LE(std::abs(a[i] - e[i]), kTableBandError * peak) << rgb[0] << "," << rgb[1] << "," << rgb[2] << " band " << i;
    }
  }
  // The table is an approximation, not the exact fit again: interpolation shows somewhere in this set.
  EXPECT_GT(worst_de, 1e-3);
  EXPECT_GT(worst_band, 1e-4);
}

TEST(RgbToSpectrum, TableRoundTripsSrgb) {
  // Spectrum -> XYZ under D65 (exact integration of the tabulated spectrum) -> linear sRGB against the input: the
  // table's error (kTableRgbError) plus the quadrature difference of the 1 nm grid (5e-4, as for the exact fit).
  for (double r : {0.0, 0.02, 0.25, 0.5, 0.75, 0.98, 1.0})
    for (double g : {0.0, 0.02, 0.25, 0.5, 0.75, 0.98, 1.0})
      for (double b : {0.0, 0.02, 0.25, 0.5, 0.75, 0.98, 1.0}) {
        const Vec3d got = seen_under_d65(rgb_to_spectrum({r, g, b}));
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], (Vec3d{r, g, b})[c], kTableRgbError + 5e-4) << r << "," << g << "," << b;
        EXPECT_LT(delta_e_2000(lab_of(got), lab_of({r, g, b})), kTableDeltaE + 0.1) << r << "," << g << "," << b;
      }
}

TEST(RgbToSpectrum, RadiancesThroughTheTable) {
  // Unbounded colours: the shape is the table's reflectance of rgb / (2·max), on the node plane z = ½.
  for (int i = 0; i < 300; ++i) {
    Random random(5, static_cast<std::uint64_t>(i));
    const double m = std::pow(10.0, -3.0 + 6.0 * random.uniform());
    const Vec3d rgb = {m * random.uniform(), m * random.uniform(), m * random.uniform()};
    const ScaledSigmoid table = upsample_rgb_unbounded(rgb), exact = fit_rgb_unbounded(rgb);
    EXPECT_EQ(table.scale, exact.scale);
    const Vec3d got = reflectance_linear_srgb(table.poly), want = reflectance_linear_srgb(exact.poly);
    EXPECT_LT(delta_e_2000(lab_of(got), lab_of(want)), kTableDeltaE);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c] * table.scale, rgb[c], kTableRgbError * table.scale);
  }
}

TEST(RgbToSpectrum, TableNodesAreExactFits) {
  // At a node, interpolation weighs that node alone: the table gives the exact fit's colour (float storage of the
  // coefficients: ~1e-7 relative).
  const RgbCoefficientTable& table = rgb_table();
  const int n = table.resolution();
  ASSERT_EQ(n % 2, 1);
  for (const int l : {0, 1, 2})
    for (const int k : {1, 5, (n - 1) / 2, n - 3, n - 1})
      for (const int j : {0, 3, n / 2, n - 1})
        for (const int i : {0, 7, n - 2}) {
          Vec3d rgb{};
          rgb[l] = table.z_node(k);
          rgb[(l + 1) % 3] = table.xy_node(i) * rgb[l];
          rgb[(l + 2) % 3] = table.xy_node(j) * rgb[l];
          const Vec3d got = reflectance_linear_srgb(table.lookup(rgb));
          const Vec3d want = reflectance_linear_srgb(fit_rgb_reflectance(rgb));
          for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], want[c], 1e-5) << l << " " << k << " " << j << " " << i;
        }
}

TEST(RgbToSpectrum, TableEdgesOfTheCube) {
  // Below the first node plane z_1 the coefficients follow the sigmoid's asymptote (∝ 1/√z): the colour is still
  // reproduced, relative to its size.
  for (const double scale : {1e-7, 1e-9, 1e-11}) {
    const Vec3d rgb = {0.2 * scale, 0.7 * scale, 0.05 * scale};
    const Vec3d got = reflectance_linear_srgb(upsample_rgb_reflectance(rgb));
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c] / scale, rgb[c] / scale, 2e-3) << scale;
  }
  // Next to white the interpolation would reach white's infinite coefficients: those colours are fitted exactly.
  const Vec3d near_white = {1.0, 0.9996, 0.9999};
  EXPECT_EQ(upsample_rgb_reflectance(near_white).c, fit_rgb_reflectance(near_white).c);
  // Out-of-range components are clamped into [0, 1] as the exact fit does.
  EXPECT_EQ(upsample_rgb_reflectance({1.5, 0.5, -0.2}).c, upsample_rgb_reflectance({1.0, 0.5, 0.0}).c);
}

TEST(RgbToSpectrum, PartialTabulationGivesTheSameBandAverages) {
  // palette_band_averages tabulates only the range of its bands: the averages must be those of the whole table.
  const ScaledSigmoid s = upsample_rgb_unbounded({3.0, 0.7, 0.2});
  for (const Bands& bands : {Bands::parse("400:700:10"), Bands::parse("360:830:47"), Bands::parse("300:900:25"),
                             Bands::from_edges({401.3, 402.9, 555.55, 829.5}), Bands::parse("840:900:20"),
                             Bands::parse("300:350:10")}) {
    const std::vector<double> part = band_averages(s.tabulated(bands.min_wavelength(), bands.max_wavelength()), bands);
    EXPECT_EQ(part, band_averages(s.tabulated(), bands)) << bands.min_wavelength() << "-" << bands.max_wavelength();
  }
}

TEST(RgbToSpectrum, DirectBandAveragesAreThoseOfTheTabulatedSpectrum) {
  // tabulated_band_averages (a texture palette's band averages) repeats PiecewiseLinearSpectrum's arithmetic on
  // the 1 nm samples: the same doubles, for colours of every kind and band plans with fractional edges, edges
  // on the samples, and ranges past the table's ends.
  const std::vector<Bands> plans = {Bands::parse("400:700:10"), Bands::parse("360:830:47"), Bands::parse("300:900:25"),
                                    Bands::from_edges({401.3, 402.9, 555.55, 829.5}), Bands::parse("840:900:20"),
                                    Bands::parse("300:350:10"), Bands::from_edges({359.5, 360.0, 360.25, 830.0, 830.5}),
                                    Bands::parse("380:780:1")};
  std::vector<ScaledSigmoid> spectra = {upsample_rgb_unbounded({0.0, 0.0, 0.0}), upsample_rgb_unbounded({2.0, 2.0, 2.0}),
                                        ScaledSigmoid{1.0, upsample_rgb_reflectance({1.0, 1.0, 1.0})},
                                        ScaledSigmoid{1.0, upsample_rgb_reflectance({1.0, 0.0, 0.0})}};
  for (int i = 0; i < 200; ++i) {
    Random random(9, static_cast<std::uint64_t>(i));
    const Vec3d rgb = {random.uniform(), random.uniform(), random.uniform()};
    spectra.push_back(i % 2 ? ScaledSigmoid{1.0, upsample_rgb_reflectance(rgb)}
                            : upsample_rgb_unbounded({30 * rgb[0], 30 * rgb[1], 30 * rgb[2]}));
    spectra.back().illuminant = i % 4 < 2;  // emitted colours, relative to D65, as well
  }
  for (const Bands& bands : plans)
    for (const ScaledSigmoid& s : spectra) {
      std::vector<double> direct(bands.size());
      tabulated_band_averages(s, bands, direct.data());
      ASSERT_EQ(direct, band_averages(s.tabulated(), bands)) << bands.min_wavelength() << "-" << bands.max_wavelength();
    }
}

// An emitted RGB colour is relative to D65 (pbrt-v4's RGBIlluminantSpectrum): (1, 1, 1) is D65 itself, with the
// luminance of the flat spectrum 1, and a colour is the sigmoid of its reflectance times that white. Bounds: the
// white's samples are D65's times one factor (double rounding, 1e-15 relative); its luminance is set by the
// trapezoid rule on the 1 nm grid, which differs from the exact integral of the linear interpolants by
// O(h²/12 · max|(D65·ȳ)''|) per nm, below 1e-3 relative for h = 1 nm.
TEST(RgbToSpectrum, EmittedRgbIsRelativeToD65) {
  const PiecewiseLinearSpectrum& d65 = cie::illuminant("D65");
  const PiecewiseLinearSpectrum white = rgb_to_emission_spectrum({1.0, 1.0, 1.0});
  const double factor = white(560.0) / d65(560.0);
  for (double nm = 360.0; nm <= 830.0; nm += 1.0) EXPECT_NEAR(white(nm), factor * d65(nm), 1e-13 * d65(nm)) << nm;
  const double y_white = spectrum_to_xyz(white)[1], y_flat = spectrum_to_xyz(PiecewiseLinearSpectrum::constant(1.0))[1];
  EXPECT_NEAR(y_white / y_flat, 1.0, 1e-3);
  // Its chromaticity is D65's (x, y) = (0.31272, 0.32903) to the 5 decimals CIE 15 gives.
  const Vec3d xyy = xyz_to_xyY(spectrum_to_xyz(white));
  EXPECT_NEAR(xyy[0], 0.31272, 1e-5);
  EXPECT_NEAR(xyy[1], 0.32903, 1e-5);
  // A colour: the reflectance's shape times the white, sample for sample; its emitted linear sRGB (XYZ / Y of
  // the flat spectrum 1) is the reflectance's D65-lit colour. The two differ by the quadrature above (5e-4, as in
  // ExactFitReproducesColoursInsideTheCube) and the white's normalisation (1e-3 relative at most).
  for (const Vec3d& rgb : {Vec3d{0.8, 0.3, 0.1}, Vec3d{0.05, 0.2, 0.9}, Vec3d{0.5, 0.5, 0.5}, Vec3d{0.0, 1.0, 0.2}}) {
    const PiecewiseLinearSpectrum emitted = rgb_to_emission_spectrum(rgb), shape = rgb_to_spectrum(rgb);
    for (double nm = 360.0; nm <= 830.0; nm += 1.0) EXPECT_NEAR(emitted(nm), shape(nm) * white(nm), 1e-15 * white(nm));
    const Vec3d xyz = spectrum_to_xyz(emitted);
    const Vec3d seen = xyz_to_linear_srgb({xyz[0] / y_flat, xyz[1] / y_flat, xyz[2] / y_flat});
    const Vec3d lit = seen_under_d65(shape);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(seen[c], lit[c], 5e-4 + 1e-3 * lit[c]) << rgb[0] << "," << rgb[1] << "," << rgb[2];
  }
  // A radiance texel (unbounded form) and the same colour given as {"rgb"}, scaled into [0, 1], have one shape.
  ScaledSigmoid texel = upsample_rgb_unbounded({4.0, 2.0, 1.0});
  texel.illuminant = true;
  const PiecewiseLinearSpectrum tabulated = texel.tabulated();
  for (double nm : {360.0, 400.5, 555.0, 700.25, 830.0}) {
    EXPECT_NEAR(tabulated(nm), texel.tabulated_at(nm), 1e-15 * tabulated(nm)) << nm;
    EXPECT_NEAR(texel(nm), texel.scale * texel.poly(nm) * rgb_white_at(nm), 1e-15 * texel(nm)) << nm;
  }
}

TEST(RgbToSpectrum, TableIsTheSameWhateverTheThreadCount) {
  const RgbCoefficientTable one = RgbCoefficientTable::compute(9, 1), two = RgbCoefficientTable::compute(9, 2);
  EXPECT_EQ(one.bytes(), two.bytes());
  EXPECT_EQ(RgbCoefficientTable::from_bytes(one.bytes()).bytes(), one.bytes());
  EXPECT_THROW(RgbCoefficientTable::from_bytes(one.bytes().substr(1)), std::runtime_error);
  EXPECT_THROW(RgbCoefficientTable::compute(8), std::invalid_argument);
}

TEST(RgbToSpectrum, ExactFitReproducesColoursInsideTheCube) {
  // The exact fit solves the colour equations to ~1e-12 with trapezoid weights on the 1 nm grid; integrating the
  // product of the linear interpolants exactly instead differs by O(h²·max|(D65·c̄·s)''|/12) per nm, which
  // for h = 1 nm stays below 5e-4 in linear RGB (ΔE00 well below 0.1, the bound checked last).
  const Vec3d white = xyY_to_xyz({0.31271, 0.32902, 1.0});
  for (double r : {0.02, 0.25, 0.5, 0.75, 0.98})
    for (double g : {0.02, 0.25, 0.5, 0.75, 0.98})
      for (double b : {0.02, 0.25, 0.5, 0.75, 0.98}) {
        const PiecewiseLinearSpectrum s = ScaledSigmoid{1.0, fit_rgb_reflectance({r, g, b})}.tabulated();
        const Vec3d got = seen_under_d65(s);
        EXPECT_NEAR(got[0], r, 5e-4) << r << "," << g << "," << b;
        EXPECT_NEAR(got[1], g, 5e-4) << r << "," << g << "," << b;
        EXPECT_NEAR(got[2], b, 5e-4) << r << "," << g << "," << b;
        for (double v : s.values()) {
          EXPECT_GT(v, 0.0);
          EXPECT_LT(v, 1.0);
        }
        const double de = delta_e_2000(xyz_to_lab(linear_srgb_to_xyz(got), white),
                                       xyz_to_lab(linear_srgb_to_xyz({r, g, b}), white));
        EXPECT_LT(de, 0.1);
      }
}

TEST(RgbToSpectrum, SaturatedPrimariesStayBoundedAndOrdered) {
  // Pure primaries lie outside what a reflectance can reach; the fit must still give a finite, bounded
  // spectrum peaking where the primary does.
  const PiecewiseLinearSpectrum red = rgb_to_spectrum({1, 0, 0});
  const PiecewiseLinearSpectrum green = rgb_to_spectrum({0, 1, 0});
  const PiecewiseLinearSpectrum blue = rgb_to_spectrum({0, 0, 1});
  for (const auto* s : {&red, &green, &blue})
    for (double v : s->values()) {
      EXPECT_TRUE(std::isfinite(v));
      EXPECT_GE(v, 0.0);
      EXPECT_LE(v, 1.0);
    }
  EXPECT_GT(red(650), red(450));
  EXPECT_GT(blue(450), blue(650));
  EXPECT_GT(green(530), green(420));
  EXPECT_GT(green(530), green(680));
}

}  // namespace
}  // namespace ct
