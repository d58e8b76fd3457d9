#pragma once
// Option values several subcommands share, parsed one way.

#include <string>
#include <string_view>
#include <utility>

namespace ct::cli {

// "WxH" with positive integers (e.g. "64x48"): {W, H}; InputError naming `option` otherwise.
std::pair<int, int> parse_resolution(const std::string& text, std::string_view option = "--resolution");

}  // namespace ct::cli
