// RGB upsampling (Jakob & Hanika 2019): the fitted spectra reproduce their colour and are smooth, bounded.
#include <gtest/gtest.h>

#include <cmath>

#include "core/cie.h"
#include "core/colour.h"
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

TEST(RgbToSpectrum, GreysAreFlat) {
  for (double g : {0.0, 0.18, 0.5, 1.0}) {
    const PiecewiseLinearSpectrum s = rgb_to_spectrum({g, g, g});
    for (double v : s.values()) EXPECT_NEAR(v, g, 1e-12);
  }
}

TEST(RgbToSpectrum, ReproducesColoursInsideTheCube) {
  // The fit solves the colour equations to ~1e-12 with trapezoid weights on the 1 nm grid; integrating the
  // product of the linear interpolants exactly instead differs by O(h²·max|(D65·c̄·s)''|/12) per nm, which
  // for h = 1 nm stays below 5e-4 in linear RGB (ΔE00 well below 0.1, the bound checked last).
  const Vec3d white = xyY_to_xyz({0.31271, 0.32902, 1.0});
  for (double r : {0.02, 0.25, 0.5, 0.75, 0.98})
    for (double g : {0.02, 0.25, 0.5, 0.75, 0.98})
      for (double b : {0.02, 0.25, 0.5, 0.75, 0.98}) {
        const PiecewiseLinearSpectrum s = rgb_to_spectrum({r, g, b});
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
