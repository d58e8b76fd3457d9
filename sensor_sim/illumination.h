// SPDX-License-Identifier: Apache-2.0
#pragma once
// The light a spectral reflectance image is lit by (docs/sensor.md, "Reflectance images"): `sensor
// chart.exr --illuminant D50` turns each band's reflectance ρ_b into the radiance L_b = ρ_b · S̄_b, with S̄_b
// the illuminant's average over the band, the illuminant scaled to 1 W·m⁻²·sr⁻¹·nm⁻¹ at 560 nm (where the
// CIE normalises its tables to 100): a perfect white reflector then has that radiance at 560 nm.

#include <string>
#include <vector>

#include "core/spectrum.h"

namespace ct::sensor {

struct Illumination {
  std::string name;                  // "D50", or the CSV file as given
  PiecewiseLinearSpectrum spectrum;  // 1 at 560 nm
};

// A CIE illuminant's name (A, D50, D65, F1 … F12) or a CSV file (a name containing '/' or ending in .csv):
// `wavelength_nm` and one value column, or the column `power`. InputError naming the option or file for an
// unknown name, an unreadable file, a negative or non-finite value, or no power at 560 nm.
Illumination read_illumination(const std::string& name_or_csv);

}  // namespace ct::sensor
