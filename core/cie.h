// SPDX-License-Identifier: Apache-2.0
#pragma once
// CIE data shipped with chromatrace (core/data/, see its README for sources and licences): the CIE 1931
// 2° standard observer, the standard illuminants and the daylight basis.

#include <array>
#include <string>
#include <string_view>
#include <vector>

#include "core/spectrum.h"

namespace ct::cie {

// The CIE 1931 2° colour-matching functions, 360–830 nm at 1 nm (zero outside).
const PiecewiseLinearSpectrum& x_bar();
const PiecewiseLinearSpectrum& y_bar();
const PiecewiseLinearSpectrum& z_bar();

// Names accepted by illuminant(): "A", "D50", "D65", "F1" … "F12" (case-insensitive).
const std::vector<std::string>& illuminant_names();
// A CIE standard illuminant as tabulated (relative; A, D50, D65 = 100 at 560 nm). Zero outside its table.
// Throws InputError for an unknown name, listing the known ones.
const PiecewiseLinearSpectrum& illuminant(std::string_view name);
// CIE daylight at a correlated colour temperature in [4000, 25000] K from the S0, S1, S2 basis
// (CIE 15:2004 §3.1), relative, normalised to 100 at 560 nm. The CCT is used as given (no 1.4388/1.438
// correction), as in CIE 15.
PiecewiseLinearSpectrum daylight(double cct_kelvin);

}  // namespace ct::cie
