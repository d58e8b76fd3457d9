// SPDX-License-Identifier: Apache-2.0
#include "core/cie.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <map>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "core/csv.h"
#include "core/embedded_data.h"
#include "core/error.h"

namespace ct::cie {
namespace {

CsvTable embedded_table(std::string_view name) {
  const std::string_view bytes = embedded::file(name);
  if (bytes.empty()) throw std::logic_error(fmt::format("embedded data file {} is missing", name));
  return parse_csv(bytes, std::string(name));
}

struct Observer {
  PiecewiseLinearSpectrum x, y, z;
};

const Observer& observer() {
  static const Observer obs = [] {
    const CsvTable t = embedded_table("cie1931_2deg_1nm.csv");
    return Observer{t.spectrum("x_bar"), t.spectrum("y_bar"), t.spectrum("z_bar")};
  }();
  return obs;
}

std::string upper(std::string_view s) {
  std::string u(s);
  for (char& c : u) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return u;
}

}  // namespace

const PiecewiseLinearSpectrum& x_bar() { return observer().x; }
const PiecewiseLinearSpectrum& y_bar() { return observer().y; }
const PiecewiseLinearSpectrum& z_bar() { return observer().z; }

const std::vector<std::string>& illuminant_names() {
  static const std::vector<std::string> names =
      nlohmann::json::parse(embedded::file("defaults.json"))["illuminants"].get<std::vector<std::string>>();
  return names;
}

const PiecewiseLinearSpectrum& illuminant(std::string_view name) {
  static const std::map<std::string, PiecewiseLinearSpectrum> table = [] {
    std::map<std::string, PiecewiseLinearSpectrum> t;
    for (const std::string& n : illuminant_names())
      t.emplace(n, embedded_table("illuminants/" + n + ".csv").spectrum("value"));
    return t;
  }();
  const auto it = table.find(upper(name));
  if (it == table.end()) {
    std::string known;
    for (const std::string& n : illuminant_names()) known += (known.empty() ? "" : ", ") + n;
    throw InputError(fmt::format("unknown CIE illuminant \"{}\" (known: {}, or daylight at a CCT)", name, known));
  }
  return it->second;
}

PiecewiseLinearSpectrum daylight(double cct) {
  if (!(cct >= 4000.0 && cct <= 25000.0))
    throw InputError(fmt::format("daylight CCT must be in [4000, 25000] K, got {}", cct));
  static const CsvTable basis = embedded_table("cie_daylight_basis_S0_S1_S2.csv");
  // Chromaticity of daylight (CIE 15:2004, eq. 3.3 and 3.2).
  const double t = cct, t2 = t * t, t3 = t2 * t;
  const double x = cct <= 7000.0 ? -4.6070e9 / t3 + 2.9678e6 / t2 + 0.09911e3 / t + 0.244063
                                 : -2.0064e9 / t3 + 1.9018e6 / t2 + 0.24748e3 / t + 0.237040;
  const double y = -3.000 * x * x + 2.870 * x - 0.275;
  // Weights of S1 and S2 (eq. 3.5), rounded to three decimals as CIE 15:2004 prescribes so that the
  // standard D illuminants are reproduced.
  const double m = 0.0241 + 0.2562 * x - 0.7341 * y;
  const double m1 = std::round((-1.3515 - 1.7703 * x + 5.9114 * y) / m * 1000.0) / 1000.0;
  const double m2 = std::round((0.0300 - 31.4424 * x + 30.0717 * y) / m * 1000.0) / 1000.0;
  const std::vector<double>& s0 = basis.values[basis.column_index("S0")];
  const std::vector<double>& s1 = basis.values[basis.column_index("S1")];
  const std::vector<double>& s2 = basis.values[basis.column_index("S2")];
  std::vector<double> value(basis.wavelengths.size());
  for (std::size_t i = 0; i < value.size(); ++i) value[i] = s0[i] + m1 * s1[i] + m2 * s2[i];
  const PiecewiseLinearSpectrum raw(basis.wavelengths, value, Extrapolation::Zero, "daylight");
  return raw.scaled(100.0 / raw(560.0));
}

}  // namespace ct::cie
