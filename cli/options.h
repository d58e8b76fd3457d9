// SPDX-License-Identifier: Apache-2.0
#pragma once
// Option values several subcommands share, parsed one way.

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <utility>

#include "core/band_plan.h"
#include "core/spectrum.h"

namespace ct::cli {

// "WxH" with positive integers (e.g. "64x48"): {W, H}; InputError naming `option` otherwise.
std::pair<int, int> parse_resolution(const std::string& text, std::string_view option = "--resolution");

// The band plan given by `--bands lo:hi:width` or by a band-plan file (the option `file_option`, e.g. --plan), at
// most one of them; nullopt when neither is given. The file's form also carries what else the file gives (Cycles'
// samples per band group; none for --bands).
std::optional<BandPlanFile> band_plan_file_option(const std::string& bands, const std::string& file,
                                                  std::string_view file_option);
std::optional<Bands> band_plan_option(const std::string& bands, const std::string& file, std::string_view file_option);

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
