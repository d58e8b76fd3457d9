// SPDX-License-Identifier: Apache-2.0
#include "sensor_sim/illumination.h"

#include <algorithm>
#include <cctype>
#include <cmath>

#include <fmt/core.h>
#include <fmt/format.h>

#include "core/cie.h"
#include "core/csv.h"
#include "core/error.h"

namespace ct::sensor {
namespace {

constexpr double kNormalisationNm = 560.0;

bool is_csv(const std::string& name) { return name.find('/') != std::string::npos || name.ends_with(".csv"); }

PiecewiseLinearSpectrum csv_illuminant(const std::string& file) {
  const CsvTable table = read_csv(file);
  std::size_t column = 0;
  if (table.columns.size() != 1) {
    const auto it = std::find(table.columns.begin(), table.columns.end(), "power");
    if (it == table.columns.end())
      throw InputError(fmt::format("{}: an illuminant needs one value column (or one named power), has {}", file,
                                   fmt::join(table.columns, ", ")));
    column = static_cast<std::size_t>(it - table.columns.begin());
  }
  for (std::size_t row = 0; row < table.wavelengths.size(); ++row) {
    const double v = table.values[column][row];
    if (std::isnan(v)) continue;  // an empty cell: no data
    if (!std::isfinite(v) || v < 0)
      throw InputError(fmt::format("{}: column {}: value {} at {} nm: an illuminant's power cannot be negative", file,
                                   table.columns[column], v, table.wavelengths[row]));
  }
  return table.spectrum(table.columns[column]);
}

}  // namespace

Illumination read_illumination(const std::string& name_or_csv) {
  Illumination out;
  out.name = name_or_csv;
  if (is_csv(name_or_csv)) {
    out.spectrum = csv_illuminant(name_or_csv);
  } else {
    const auto& names = cie::illuminant_names();
    const bool known = std::any_of(names.begin(), names.end(), [&](const std::string& n) {
      return n.size() == name_or_csv.size() &&
             std::equal(n.begin(), n.end(), name_or_csv.begin(), [](char a, char b) { return std::toupper(a) == std::toupper(b); });
    });
    if (!known)
      throw InputError(fmt::format("--illuminant: unknown illuminant \"{}\" (illuminants: {}; or a CSV file)",
                                   name_or_csv, fmt::join(names, ", ")));
    out.spectrum = cie::illuminant(name_or_csv);
  }
  const double at = out.spectrum(kNormalisationNm);
  if (!(at > 0))
    throw InputError(fmt::format("{}: the illuminant has no power at {} nm, where it is normalised to 1", name_or_csv,
                                 kNormalisationNm));
  std::vector<double> values = out.spectrum.values();
  for (double& v : values) v /= at;
  out.spectrum = PiecewiseLinearSpectrum(out.spectrum.wavelengths(), std::move(values), out.spectrum.extrapolation());
  return out;
}

}  // namespace ct::sensor
