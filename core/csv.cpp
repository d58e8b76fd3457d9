// SPDX-License-Identifier: Apache-2.0
#include "core/csv.h"

#include <charconv>
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>

#include <fmt/core.h>

#include "core/error.h"
#include "core/file_io.h"

namespace ct {
namespace {

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

std::vector<std::string_view> split(std::string_view line) {
  std::vector<std::string_view> cells;
  std::size_t start = 0;
  for (std::size_t i = 0; i <= line.size(); ++i) {
    if (i == line.size() || line[i] == ',') {
      cells.push_back(trim(line.substr(start, i - start)));
      start = i + 1;
    }
  }
  return cells;
}

// Parses a whole cell as a finite double; nullopt-like signalling through the return flag.
bool parse_number(std::string_view cell, double& out) {
  if (!cell.empty() && cell.front() == '+') cell.remove_prefix(1);
  const char* end = cell.data() + cell.size();
  auto [ptr, ec] = std::from_chars(cell.data(), end, out);
  return ec == std::errc() && ptr == end && std::isfinite(out);
}

}  // namespace

std::size_t CsvTable::column_index(std::string_view name) const {
  for (std::size_t i = 0; i < columns.size(); ++i)
    if (columns[i] == name) return i;
  std::string known;
  for (const std::string& c : columns) known += (known.empty() ? "" : ", ") + c;
  throw InputError(fmt::format("{}: no column \"{}\" (columns: {})", source, name, known));
}

PiecewiseLinearSpectrum CsvTable::spectrum(std::string_view column) const {
  const std::vector<double>& col = values[column_index(column)];
  std::vector<double> lambda, value;
  for (std::size_t r = 0; r < wavelengths.size(); ++r) {
    if (std::isnan(col[r])) continue;
    lambda.push_back(wavelengths[r]);
    value.push_back(col[r]);
  }
  if (lambda.empty()) throw InputError(fmt::format("{}: column \"{}\" has no values", source, column));
  // As for "samples" in a scene: one value is no spectrum (the line through two is; {"constant": v} is flat).
  if (lambda.size() < 2)
    throw InputError(fmt::format("{}: column \"{}\" has 1 value, at {} nm; a spectrum needs at least 2", source,
                                 column, lambda[0]));
  return PiecewiseLinearSpectrum(std::move(lambda), std::move(value), Extrapolation::Zero,
                                 fmt::format("{}: column \"{}\"", source, column));
}

CsvTable parse_csv(std::string_view text, const std::string& source) {
  CsvTable table;
  table.source = source;
  std::size_t line_no = 0;
  bool header_seen = false;
  while (!text.empty()) {
    const std::size_t eol = text.find('\n');
    std::string_view line = text.substr(0, eol);
    text = eol == std::string_view::npos ? std::string_view() : text.substr(eol + 1);
    ++line_no;
    if (line_no == 1 && line.starts_with("\xEF\xBB\xBF")) line.remove_prefix(3);  // UTF-8 byte-order mark
    if (trim(line).empty() || trim(line).front() == '#') continue;

    const std::vector<std::string_view> cells = split(line);
    if (!header_seen) {
      if (cells.front() != "wavelength_nm")
        throw InputError(fmt::format("{}: line {}: first column must be \"wavelength_nm\", got \"{}\"", source,
                                     line_no, cells.front()));
      if (cells.size() < 2) throw InputError(fmt::format("{}: line {}: no value columns", source, line_no));
      for (std::size_t c = 1; c < cells.size(); ++c) table.columns.emplace_back(cells[c]);
      table.values.resize(table.columns.size());
      header_seen = true;
      continue;
    }
    if (cells.size() != table.columns.size() + 1)
      throw InputError(fmt::format("{}: line {}: expected {} cells, got {}", source, line_no,
                                   table.columns.size() + 1, cells.size()));
    double lambda = 0;
    if (!parse_number(cells[0], lambda))
      throw InputError(fmt::format("{}: line {}: wavelength_nm \"{}\" is not a finite number", source, line_no,
                                   cells[0]));
    if (!table.wavelengths.empty() && lambda <= table.wavelengths.back())
      throw InputError(fmt::format("{}: line {}: wavelength_nm {} does not increase (previous {})", source,
                                   line_no, lambda, table.wavelengths.back()));
    table.wavelengths.push_back(lambda);
    for (std::size_t c = 1; c < cells.size(); ++c) {
      double v = std::numeric_limits<double>::quiet_NaN();
      if (!cells[c].empty() && !parse_number(cells[c], v))
        throw InputError(fmt::format("{}: line {}: {} \"{}\" is not a finite number", source, line_no,
                                     table.columns[c - 1], cells[c]));
      table.values[c - 1].push_back(v);
    }
  }
  if (!header_seen) throw InputError(fmt::format("{}: empty file (no header row)", source));
  if (table.wavelengths.empty()) throw InputError(fmt::format("{}: no data rows", source));
  return table;
}

CsvTable read_csv(const std::filesystem::path& path) { return parse_csv(read_file(path), path.string()); }

}  // namespace ct
