// SPDX-License-Identifier: Apache-2.0
#pragma once
// Spectral CSV tables: a header row whose first column is `wavelength_nm`, then one row per wavelength,
// strictly increasing. Empty cells mean "no data" and read as NaN.

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "core/spectrum.h"

namespace ct {

struct CsvTable {
  std::string source;                        // file name (or embedded name), used in error messages
  std::vector<std::string> columns;          // value columns, without `wavelength_nm`
  std::vector<double> wavelengths;           // strictly increasing
  std::vector<std::vector<double>> values;   // values[column][row]; NaN where the cell was empty

  // Index of a column; throws InputError naming the source and the column if it is absent.
  std::size_t column_index(std::string_view name) const;
  // The column as a piecewise-linear spectrum over the rows that have data (empty cells are skipped).
  PiecewiseLinearSpectrum spectrum(std::string_view column) const;
};

// Parses CSV text. `source` names the origin in errors ("cameras/nikon_d850.csv: line 12: ...").
CsvTable parse_csv(std::string_view text, const std::string& source);
// Reads and parses a file; an unreadable file is an InputError.
CsvTable read_csv(const std::filesystem::path& path);

}  // namespace ct
