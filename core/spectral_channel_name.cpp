// SPDX-License-Identifier: Apache-2.0
#include "core/spectral_channel_name.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <utility>

#include <fmt/format.h>

#include "core/spectrum.h"

namespace ct {
namespace {

bool is_digit(char c) { return c >= '0' && c <= '9'; }

std::size_t skip_digits(std::string_view text, std::size_t i) {
  while (i < text.size() && is_digit(text[i])) ++i;
  return i;
}

// SI prefixes as powers of ten. "da" has two letters, so a prefix is matched as the whole text between
// the number and the unit, never letter by letter.
std::optional<int> prefix_exponent(std::string_view prefix) {
  static constexpr std::array<std::pair<std::string_view, int>, 17> kPrefixes{{
      {"", 0},   {"Y", 24}, {"Z", 21}, {"E", 18},  {"P", 15},  {"T", 12},  {"G", 9},  {"M", 6},  {"k", 3},
      {"h", 2},  {"da", 1}, {"d", -1}, {"c", -2},  {"m", -3},  {"u", -6},  {"n", -9}, {"p", -12},
  }};
  for (const auto& [name, exponent] : kPrefixes)
    if (name == prefix) return exponent;
  return std::nullopt;
}

std::optional<SpectralQuantity> parse_quantity(std::string_view token) {
  static constexpr std::array<std::pair<std::string_view, SpectralQuantity>, 5> kQuantities{{
      {"S0", SpectralQuantity::S0},
      {"S1", SpectralQuantity::S1},
      {"S2", SpectralQuantity::S2},
      {"S3", SpectralQuantity::S3},
      {"T", SpectralQuantity::T},
  }};
  for (const auto& [name, quantity] : kQuantities)
    if (name == token) return quantity;
  return std::nullopt;
}

// Splits at every '.', keeping empty tokens so that "S0..550nm" is rejected rather than repaired.
std::vector<std::string_view> split_dots(std::string_view name) {
  std::vector<std::string_view> tokens;
  std::size_t start = 0;
  for (std::size_t dot = name.find('.'); dot != std::string_view::npos; dot = name.find('.', start)) {
    tokens.push_back(name.substr(start, dot - start));
    start = dot + 1;
  }
  tokens.push_back(name.substr(start));
  return tokens;
}

// The layer is everything before the token at `quantity_index` (the tokens are views into `name`).
std::string layer_before(std::string_view name, const std::vector<std::string_view>& tokens,
                         std::size_t quantity_index) {
  if (quantity_index == 0) return {};
  return std::string(name.substr(0, static_cast<std::size_t>(tokens[quantity_index].data() - name.data()) - 1));
}

}  // namespace

std::string_view quantity_name(SpectralQuantity quantity) {
  switch (quantity) {
    case SpectralQuantity::S0: return "S0";
    case SpectralQuantity::S1: return "S1";
    case SpectralQuantity::S2: return "S2";
    case SpectralQuantity::S3: return "S3";
    case SpectralQuantity::T: return "T";
  }
  return "?";
}

std::optional<double> parse_wavelength_nm(std::string_view text) {
  // The mantissa is rebuilt with a '.' and the unit's power of ten is folded into the exponent, so that
  // the decimal text is converted with a single correct rounding ("550,0nm" is exactly 550).
  std::size_t i = skip_digits(text, 0);
  std::string mantissa(text.substr(0, i));
  std::size_t digit_count = i;
  if (i < text.size() && text[i] == ',') {
    const std::size_t fraction_end = skip_digits(text, i + 1);
    mantissa += '.';
    mantissa += text.substr(i + 1, fraction_end - i - 1);
    digit_count += fraction_end - i - 1;
    i = fraction_end;
  }
  if (digit_count == 0) return std::nullopt;

  long exponent = 0;
  // 'e'/'E' starts an exponent only when digits follow; otherwise "E" is the exa prefix ("1Em").
  if (i < text.size() && (text[i] == 'e' || text[i] == 'E')) {
    std::size_t j = i + 1;
    const bool negative = j < text.size() && text[j] == '-';
    if (j < text.size() && (text[j] == '+' || text[j] == '-')) ++j;
    const std::size_t exponent_end = skip_digits(text, j);
    if (exponent_end > j) {
      const auto [end, error] = std::from_chars(text.data() + j, text.data() + exponent_end, exponent);
      if (error != std::errc{} || end != text.data() + exponent_end) return std::nullopt;
      if (negative) exponent = -exponent;
      i = exponent_end;
    }
  }

  const std::string_view unit = text.substr(i);
  const bool frequency = unit.ends_with("Hz");
  if (!frequency && !unit.ends_with("m")) return std::nullopt;
  const std::optional<int> prefix = prefix_exponent(unit.substr(0, unit.size() - (frequency ? 2 : 1)));
  if (!prefix) return std::nullopt;

  // Wavelengths in nm: metres carry 10^9; frequencies stay in Hz until λ = c / f.
  const long power = exponent + *prefix + (frequency ? 0 : 9);
  const std::string decimal = mantissa + "e" + std::to_string(power);
  double value = 0;
  const auto [end, error] = std::from_chars(decimal.data(), decimal.data() + decimal.size(), value);
  if (error != std::errc{} || end != decimal.data() + decimal.size()) return std::nullopt;
  const double nm = frequency ? kLightSpeed / value * 1e9 : value;
  if (!std::isfinite(nm) || nm <= 0) return std::nullopt;
  return nm;
}

std::optional<SpectralChannelName> parse_spectral_channel_name(std::string_view name) {
  const std::vector<std::string_view> tokens = split_dots(name);
  const std::size_t n = tokens.size();
  if (n < 2 || std::any_of(tokens.begin(), tokens.end(), [](std::string_view t) { return t.empty(); }))
    return std::nullopt;
  const std::optional<double> last = parse_wavelength_nm(tokens[n - 1]);
  if (!last) return std::nullopt;

  if (const std::optional<SpectralQuantity> quantity = parse_quantity(tokens[n - 2]))
    return SpectralChannelName{layer_before(name, tokens, n - 2), *quantity, *last, std::nullopt};

  // Bi-spectral re-radiation T.<in>.<out>.
  if (n >= 3 && tokens[n - 3] == "T") {
    if (const std::optional<double> incident = parse_wavelength_nm(tokens[n - 2]))
      return SpectralChannelName{layer_before(name, tokens, n - 3), SpectralQuantity::T, *incident, *last};
  }
  return std::nullopt;
}

std::string format_spectral_channel_name(std::string_view layer, SpectralQuantity quantity, double wavelength_nm) {
  std::string number = fmt::format("{:.6f}", wavelength_nm);
  std::replace(number.begin(), number.end(), '.', ',');
  if (layer.empty()) return fmt::format("{}.{}nm", quantity_name(quantity), number);
  return fmt::format("{}.{}.{}nm", layer, quantity_name(quantity), number);
}

const std::vector<std::string>& path_type_components() {
  static const std::vector<std::string> kPathTypes{"emission",         "diffuse_direct",      "diffuse_indirect",
                                                   "glossy_direct",    "glossy_indirect",     "transmission_direct",
                                                   "transmission_indirect"};
  return kPathTypes;
}

bool path_types_complete(const std::vector<std::string>& components) {
  auto has = [&](std::string_view name) { return std::find(components.begin(), components.end(), name) != components.end(); };
  for (const char* name : {"emission", "diffuse_direct", "diffuse_indirect", "glossy_direct", "glossy_indirect"})
    if (!has(name)) return false;
  return has("transmission_direct") == has("transmission_indirect");
}

ComponentFamily component_family(std::string_view layer) {
  const auto& path_types = path_type_components();
  if (std::find(path_types.begin(), path_types.end(), layer) != path_types.end()) return ComponentFamily::PathType;
  if (layer.starts_with("light.")) {
    const std::string_view group = layer.substr(6);
    const bool valid = !group.empty() && std::all_of(group.begin(), group.end(), [](char c) {
      return is_digit(c) || (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_' || c == '-';
    });
    if (valid) return ComponentFamily::LightGroup;
  }
  if (layer.starts_with("bounce.")) {
    const std::string_view k = layer.substr(7);
    // A whole number without leading zeros, so each depth has exactly one name.
    const bool valid = !k.empty() && skip_digits(k, 0) == k.size() && (k.size() == 1 || k[0] != '0');
    if (valid) return ComponentFamily::Bounce;
  }
  return ComponentFamily::Unknown;
}

std::string_view family_name(ComponentFamily family) {
  switch (family) {
    case ComponentFamily::PathType: return "path types";
    case ComponentFamily::LightGroup: return "light groups";
    case ComponentFamily::Bounce: return "bounces";
    case ComponentFamily::Unknown: return "other layers";
  }
  return "?";
}

}  // namespace ct
