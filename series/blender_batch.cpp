// SPDX-License-Identifier: Apache-2.0
#include "series/blender_batch.h"

namespace ct::series {

BlenderBatchCommand::BlenderBatchCommand(const std::filesystem::path& blender, const std::filesystem::path& batch_script)
    : blender_{blender.string(), "--background", "--factory-startup"}, batch_{"--python", batch_script.string(), "--"} {}

BlenderBatchCommand& BlenderBatchCommand::option(std::string_view name, const std::string& value) {
  if (value.empty()) return *this;
  batch_.emplace_back(name);
  batch_.push_back(value);
  return *this;
}

BlenderBatchCommand& BlenderBatchCommand::flag(std::string_view name) {
  batch_.emplace_back(name);
  return *this;
}

std::vector<std::string> BlenderBatchCommand::argv() const {
  std::vector<std::string> words = blender_;
  words.insert(words.end(), batch_.begin(), batch_.end());
  return words;
}

std::vector<std::pair<std::string, std::string>> BlenderBatchCommand::environment(const std::filesystem::path& chromatrace) {
  return {{"CHROMATRACE_EXE", chromatrace.string()}};
}

}  // namespace ct::series
