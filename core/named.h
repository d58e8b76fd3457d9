// SPDX-License-Identifier: Apache-2.0
#pragma once
// Items found by their `name` (a scene's materials, spectra and objects, a series' variants), and the list of
// names an error message offers.

#include <string>
#include <string_view>
#include <vector>

namespace ct {

template <typename T>
std::string names_of(const std::vector<T>& items) {
  std::string text;
  for (const T& item : items) text += (text.empty() ? "" : ", ") + item.name;
  return text;
}

template <typename T>
const T* find_by_name(const std::vector<T>& items, std::string_view name) {
  for (const T& item : items)
    if (item.name == name) return &item;
  return nullptr;
}

}  // namespace ct
