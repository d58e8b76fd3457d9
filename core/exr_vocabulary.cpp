// SPDX-License-Identifier: Apache-2.0
#include "core/exr_vocabulary.h"

#include <charconv>
#include <cmath>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/json_input.h"

namespace ct::exr {

bool is_object_id(double value) { return value >= 0 && value <= kMaxObjectId && value == std::floor(value); }

void check_object_id(double value, const std::string& file, std::size_t x, std::size_t y) {
  if (!is_object_id(value))
    throw InputError(fmt::format("{}: channel {}: value {} at pixel ({}, {}) is not an object id (a whole number in "
                                 "[0, {}])",
                                 file, kObjectIdChannel, value, x, y, kMaxObjectId));
}

std::string object_names_text(const std::map<std::int32_t, std::string>& names) {
  nlohmann::json json = nlohmann::json::object();
  for (const auto& [id, name] : names) json[std::to_string(id)] = name;
  return json.dump(-1, ' ', false, kReplaceInvalidUtf8);
}

std::map<std::int32_t, std::string> parse_object_names(std::string_view text, const std::string& where) {
  const nlohmann::json json = nlohmann::json::parse(text, nullptr, false);
  if (json.is_discarded() || !json.is_object())
    throw InputError(fmt::format("{}: not a JSON object from object id to name", where));
  std::map<std::int32_t, std::string> names;
  for (const auto& [key, value] : json.items()) {
    std::int32_t id = -1;
    const auto [end, error] = std::from_chars(key.data(), key.data() + key.size(), id);
    if (error != std::errc{} || end != key.data() + key.size() || id < 0 || id > kMaxObjectId)
      throw InputError(
          fmt::format("{}: key \"{}\" is not an object id (a whole number in [0, {}])", where, key, kMaxObjectId));
    if (!value.is_string()) throw InputError(fmt::format("{}: object {}: name must be a string", where, key));
    names[id] = value.get<std::string>();
  }
  return names;
}

std::string component_list_text(const std::vector<std::string>& names) { return fmt::format("{}", fmt::join(names, ",")); }

std::vector<std::string> parse_component_list(std::string_view text) {
  std::vector<std::string> names;
  while (!text.empty()) {
    const std::size_t comma = text.find(',');
    std::string_view item = text.substr(0, comma);
    text = comma == std::string_view::npos ? std::string_view{} : text.substr(comma + 1);
    while (!item.empty() && item.front() == ' ') item.remove_prefix(1);
    while (!item.empty() && item.back() == ' ') item.remove_suffix(1);
    if (!item.empty()) names.emplace_back(item);
  }
  return names;
}

}  // namespace ct::exr
