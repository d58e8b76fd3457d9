// SPDX-License-Identifier: Apache-2.0
// The upsampling every part of chromatrace uses (core/rgb_to_spectrum.h): the coefficient table that
// core/make_rgb_table.cpp computes at build time, compiled in by the assembler's .incbin.
#include <algorithm>
#include <string_view>

#include "core/rgb_to_spectrum.h"

#ifndef CHROMATRACE_RGB_TABLE_FILE
#error "CHROMATRACE_RGB_TABLE_FILE must name the table file that core/make_rgb_table writes"
#endif

asm(".pushsection .rodata\n"
    ".balign 16\n"
    ".global chromatrace_rgb_table_begin\n"
    "chromatrace_rgb_table_begin:\n"
    ".incbin \"" CHROMATRACE_RGB_TABLE_FILE "\"\n"
    ".global chromatrace_rgb_table_end\n"
    "chromatrace_rgb_table_end:\n"
    ".popsection\n");
extern "C" const char chromatrace_rgb_table_begin[];
extern "C" const char chromatrace_rgb_table_end[];

namespace ct {

const RgbCoefficientTable& rgb_table() {
  static const RgbCoefficientTable table = RgbCoefficientTable::from_bytes(
      std::string_view(chromatrace_rgb_table_begin,
                       static_cast<std::size_t>(chromatrace_rgb_table_end - chromatrace_rgb_table_begin)));
  return table;
}

SigmoidPolynomial upsample_rgb_reflectance(const std::array<double, 3>& linear_srgb) {
  return rgb_table().lookup(linear_srgb);
}

ScaledSigmoid upsample_rgb_unbounded(const std::array<double, 3>& linear_srgb) {
  const std::array<double, 3> rgb = {std::max(0.0, linear_srgb[0]), std::max(0.0, linear_srgb[1]),
                                     std::max(0.0, linear_srgb[2])};
  const double m = std::max({rgb[0], rgb[1], rgb[2]});
  if (!(m > 0.0)) return {0.0, upsample_rgb_reflectance({0.0, 0.0, 0.0})};
  const double scale = 2.0 * m;
  return {scale, upsample_rgb_reflectance({rgb[0] / scale, rgb[1] / scale, rgb[2] / scale})};
}

PiecewiseLinearSpectrum rgb_to_spectrum(const std::array<double, 3>& linear_srgb) {
  return ScaledSigmoid{1.0, upsample_rgb_reflectance(linear_srgb)}.tabulated();
}

PiecewiseLinearSpectrum rgb_to_emission_spectrum(const std::array<double, 3>& linear_srgb) {
  return ScaledSigmoid{1.0, upsample_rgb_reflectance(linear_srgb), true}.tabulated();
}

}  // namespace ct
