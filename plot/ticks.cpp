// SPDX-License-Identifier: Apache-2.0
#include "plot/ticks.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string_view>

#include <fmt/core.h>

namespace ct::plot {

double nice_step(double span, int intervals) {
  if (!(span > 0) || !std::isfinite(span)) return 1;
  const double raw = span / std::max(1, intervals);
  const double power = std::pow(10.0, std::floor(std::log10(raw)));
  const double mantissa = raw / power;
  return (mantissa < 1.5 ? 1 : mantissa < 3 ? 2 : mantissa < 7 ? 5 : 10) * power;
}

std::vector<double> multiples_in(double lo, double hi, double step) {
  std::vector<double> values;
  if (!(step > 0) || !(hi >= lo) || !std::isfinite(lo) || !std::isfinite(hi)) return values;
  const double slack = 1e-9 * (hi - lo);
  for (double k = std::ceil((lo - slack) / step); k * step <= hi + slack; k += 1) values.push_back(k * step == 0 ? 0.0 : k * step);
  return values;
}

std::string Ticks::label(double value) const { return tick_label(value, step); }

Ticks linear_ticks(double lo, double hi, int intervals) {
  Ticks ticks;
  if (!(hi > lo) || !std::isfinite(lo) || !std::isfinite(hi) || intervals < 1) return ticks;
  ticks.step = nice_step(hi - lo, intervals);
  ticks.values = multiples_in(lo, hi, ticks.step);
  return ticks;
}

NiceRange nice_range(double lo, double hi, int intervals) {
  const double span = hi > lo ? hi - lo : 1.0;
  NiceRange r;
  r.step = nice_step(span, intervals);
  r.lo = std::floor(lo / r.step + 1e-6) * r.step;
  r.hi = std::max(r.lo + r.step, std::ceil((lo + span) / r.step - 1e-6) * r.step);
  return r;
}

std::string tick_label(double value, double step) {
  const int decimals = std::clamp(static_cast<int>(-std::floor(std::log10(step) + 1e-9)), 0, 12);
  if (std::abs(value) < step * 1e-6) value = 0;
  return fmt::format("{:.{}f}", value, decimals);
}

std::vector<double> log_ticks(double lo, double hi) {
  if (!(lo > 0 && lo <= hi && std::isfinite(hi)))
    throw std::invalid_argument(fmt::format("log_ticks: the range [{}, {}] is not a range of positive numbers", lo, hi));
  std::vector<double> ticks;
  const bool fine = std::log10(hi) - std::log10(lo) < 3;
  for (int e = static_cast<int>(std::floor(std::log10(lo))); e <= static_cast<int>(std::ceil(std::log10(hi))); ++e)
    for (double m : fine ? std::vector<double>{1, 2, 5} : std::vector<double>{1}) {
      const double v = m * std::pow(10.0, e);
      if (v >= lo * (1 - 1e-9) && v <= hi * (1 + 1e-9)) ticks.push_back(v);
    }
  if (ticks.size() < 2) {
    ticks.clear();
    ticks.push_back(std::pow(10.0, std::floor(std::log10(lo))));
    ticks.push_back(std::pow(10.0, std::ceil(std::log10(hi))));
    if (ticks[0] == ticks[1]) ticks[1] *= 10;
  }
  return ticks;
}

std::string log_tick_label(double value) {
  const double e = std::floor(std::log10(value) + 1e-9);
  const double m = value / std::pow(10.0, e);
  if (e >= -2 && e <= 3) return fmt::format("{:g}", value);
  if (std::abs(m - 1) < 1e-6) return fmt::format("10^{}", static_cast<int>(e));
  return fmt::format("{:g}x10^{}", std::round(m), static_cast<int>(e));
}

std::string superscript_exponent(const std::string& label) {
  static constexpr std::string_view kDigits[10] = {"\u2070", "\u00b9", "\u00b2", "\u00b3", "\u2074",
                                                   "\u2075", "\u2076", "\u2077", "\u2078", "\u2079"};
  const std::size_t caret = label.find('^');
  if (caret == std::string::npos) return label;
  std::string out = label.substr(0, caret);
  if (const std::size_t times = out.rfind("x10"); times != std::string::npos && times + 3 == out.size()) out.replace(times, 1, "\u00d7");
  for (std::size_t i = caret + 1; i < label.size(); ++i) {
    const char c = label[i];
    if (c == '-') out += "\u207b";
    else if (c >= '0' && c <= '9') out += kDigits[c - '0'];
    else out += c;
  }
  return out;
}

}  // namespace ct::plot
