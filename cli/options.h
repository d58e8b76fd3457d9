#pragma once
// Option values several subcommands share, parsed one way.

#include <filesystem>
#include <string>
#include <string_view>
#include <utility>

namespace ct::cli {

// "WxH" with positive integers (e.g. "64x48"): {W, H}; InputError naming `option` otherwise.
std::pair<int, int> parse_resolution(const std::string& text, std::string_view option = "--resolution");

// The `chromatrace` command as the commands it starts must call it: the front executable the full program was
// started by ($CHROMATRACE_FRONT, set by cli/front.cpp), else the running executable (/proc/self/exe), else
// "chromatrace" where that cannot be read.
std::filesystem::path own_executable();

// A file shipped with chromatrace: installed beside the executable (../share/chromatrace/...), else in the
// source tree it was built from.
std::filesystem::path shipped_file(const std::filesystem::path& relative);

// The Blender add-on's headless batch (batch.py): in $CHROMATRACE_BLENDER_ADDON when set, else shipped.
std::filesystem::path blender_batch_script();

}  // namespace ct::cli
