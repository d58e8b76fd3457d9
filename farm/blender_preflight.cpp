// SPDX-License-Identifier: Apache-2.0
#include "farm/blender_preflight.h"

#include <stdexcept>
#include <string_view>

#include <fmt/core.h>

#include "core/error.h"
#include "core/process.h"

namespace ct::farm {

std::string last_line(const std::string& text) {
  const std::size_t end = text.find_last_not_of("\n");
  if (end == std::string::npos) return "(no message)";
  const std::size_t start = text.rfind('\n', end);
  return text.substr(start == std::string::npos ? 0 : start + 1, end - (start == std::string::npos ? 0 : start + 1) + 1);
}

std::string preflight_summary_text(const std::string& out) {
  const std::size_t at = out.find("\n{");
  const std::size_t first = out.starts_with("{") ? 0 : at == std::string::npos ? at : at + 1;
  const std::size_t last = first == std::string::npos ? first : out.find("\n}", first);
  if (last == std::string::npos) return "";
  return out.substr(first, last + 2 - first);
}

BlenderPreflight run_blender_preflight(const std::vector<std::string>& argv,
                                       const std::vector<std::pair<std::string, std::string>>& env,
                                       const std::string& source) {
  const ProgramOutput checked = run_program(argv, env);
  if (checked.status == 2) {
    std::string message = last_line(checked.err);
    for (const char* prefix : {"batch.py: error: "})
      if (message.starts_with(prefix)) message.erase(0, std::string_view(prefix).size());
    throw InputError(message);
  }
  const std::string text = preflight_summary_text(checked.out);
  if (checked.status != 0 || text.empty())
    throw std::runtime_error(fmt::format("the pre-flight check in Blender failed: {}", last_line(checked.err)));
  BlenderPreflight preflight;
  preflight.summary = parse_json(text, "the Blender batch's pre-flight summary");
  const Json& summary = preflight.summary;
  if (!summary.value("ok", false)) {
    for (const Json& owner : summary.at("owners"))
      if (owner.value("status", "") == "refused" && !owner.at("reasons").empty())
        throw InputError(fmt::format("{}: {}", source, owner.at("reasons")[0].get<std::string>()));
    throw InputError(fmt::format("{}: the pre-flight check refuses it", source));
  }
  preflight.band_groups = summary.at("band_groups").get<int>();
  preflight.render_variants = summary.at("render_variants").get<std::vector<std::string>>();
  return preflight;
}

}  // namespace ct::farm
