// SPDX-License-Identifier: Apache-2.0
#include "cli/options.h"

#include <charconv>
#include <cstdlib>

#include <fmt/core.h>

#include "core/band_plan.h"
#include "core/error.h"
#include "core/limits.h"

namespace ct::cli {

std::pair<int, int> parse_resolution(const std::string& text, std::string_view option) {
  const auto fail = [&] {
    throw InputError(fmt::format("{}: expected WxH with positive integers, got \"{}\"", option, text));
  };
  const std::size_t x = text.find('x');
  if (x == std::string::npos) fail();
  long long size[2] = {0, 0};
  const std::string_view parts[2] = {std::string_view(text).substr(0, x), std::string_view(text).substr(x + 1)};
  for (int i = 0; i < 2; ++i) {
    const auto [end, ec] = std::from_chars(parts[i].data(), parts[i].data() + parts[i].size(), size[i]);
    if (parts[i].empty() || end != parts[i].data() + parts[i].size()) fail();
    if (ec == std::errc::result_out_of_range || (ec == std::errc() && size[i] > kMaxImageSide))
      throw InputError(fmt::format("{}: {} is larger than the limit of {} pixels a side", option, text, kMaxImageSide));
    if (ec != std::errc() || size[i] < 1) fail();
  }
  return {static_cast<int>(size[0]), static_cast<int>(size[1])};
}

std::optional<BandPlanFile> band_plan_file_option(const std::string& bands, const std::string& file,
                                                  std::string_view file_option) {
  if (!bands.empty() && !file.empty())
    throw InputError(fmt::format("{}: give either --bands or {}, not both", file_option, file_option));
  if (!bands.empty()) return BandPlanFile{Bands::parse(bands, "--bands"), {}, {}, 0.0, std::nullopt};
  if (!file.empty()) return read_band_plan_file(file);
  return std::nullopt;
}

std::optional<Bands> band_plan_option(const std::string& bands, const std::string& file, std::string_view file_option) {
  if (auto plan = band_plan_file_option(bands, file, file_option)) return std::move(plan->bands);
  return std::nullopt;
}

namespace fs = std::filesystem;

fs::path own_executable() {
  if (const char* front = std::getenv("CHROMATRACE_FRONT"); front && *front) return front;
  std::error_code error;
  const fs::path exe = fs::read_symlink("/proc/self/exe", error);
  return error ? fs::path("chromatrace") : exe;
}

fs::path shipped_file(const fs::path& relative) {
  const fs::path installed = own_executable().parent_path().parent_path() / "share" / "chromatrace" / relative;
  if (fs::exists(installed)) return installed;
  return fs::path(CHROMATRACE_SOURCE_DIR) / relative;
}

fs::path blender_batch_script() {
  const char* addon = std::getenv("CHROMATRACE_BLENDER_ADDON");
  return (addon && *addon) ? fs::path(addon) / "batch.py" : shipped_file("blender_addon/batch.py");
}

}  // namespace ct::cli
