// SPDX-License-Identifier: Apache-2.0
// Spectral CSV tables: parsing, empty cells, and errors that name the file and the line.
#include <gtest/gtest.h>

#include <cmath>

#include "core/csv.h"
#include "core/error.h"

namespace ct {
namespace {

std::string error_of(const std::string& text) {
  try {
    parse_csv(text, "spectra/paint.csv");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(Csv, ParsesColumnsAndSkipsEmptyCells) {
  const CsvTable t = parse_csv("wavelength_nm,a,b\n400,0.1,\n500,0.2,0.5\n600,0.3,0.7\n", "t.csv");
  EXPECT_EQ(t.columns, (std::vector<std::string>{"a", "b"}));
  EXPECT_TRUE(std::isnan(t.values[1][0]));
  const PiecewiseLinearSpectrum b = t.spectrum("b");
  EXPECT_EQ(b.wavelengths(), (std::vector<double>{500, 600}));
  EXPECT_DOUBLE_EQ(t.spectrum("a")(450), 0.15);
}

TEST(Csv, ErrorsNameTheFileAndLine) {
  const std::string decreasing = error_of("wavelength_nm,v\n400,1\n500,1\n450,1\n");
  EXPECT_NE(decreasing.find("spectra/paint.csv: line 4"), std::string::npos) << decreasing;
  EXPECT_NE(decreasing.find("does not increase"), std::string::npos) << decreasing;
  EXPECT_NE(error_of("wavelength_nm,v\n400,1\n400,1\n").find("line 3"), std::string::npos);
  EXPECT_NE(error_of("lambda,v\n400,1\n").find("wavelength_nm"), std::string::npos);
  EXPECT_NE(error_of("wavelength_nm,v\n400,abc\n").find("line 2: v \"abc\""), std::string::npos);
  EXPECT_NE(error_of("wavelength_nm,v\n400,1,2\n").find("expected 2 cells"), std::string::npos);
  EXPECT_NE(error_of("wavelength_nm,v\n400,nan\n").find("not a finite number"), std::string::npos);
  EXPECT_NE(error_of("").find("empty"), std::string::npos);
  EXPECT_THROW(read_csv("/nonexistent/x.csv"), InputError);
  const CsvTable t = parse_csv("wavelength_nm,v\n400,1\n", "t.csv");
  EXPECT_THROW(t.spectrum("w"), InputError);
}

}  // namespace
}  // namespace ct
