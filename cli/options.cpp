#include "cli/options.h"

#include <cstdio>

#include <fmt/core.h>

#include "core/error.h"

namespace ct::cli {

std::pair<int, int> parse_resolution(const std::string& text, std::string_view option) {
  int w = 0, h = 0;
  char x = 0, extra = 0;
  if (std::sscanf(text.c_str(), "%d%c%d%c", &w, &x, &h, &extra) != 3 || x != 'x' || w < 1 || h < 1)
    throw InputError(fmt::format("{}: expected WxH with positive integers, got \"{}\"", option, text));
  return {w, h};
}

}  // namespace ct::cli
