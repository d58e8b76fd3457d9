// SPDX-License-Identifier: Apache-2.0
#pragma once
// The command line of the Blender add-on's headless batch (blender_addon/batch.py, docs/blender.md): Blender
// and its own options, then batch.py's options after "--". The one builder for the series runner's Cycles
// renders and the farm's Cycles tasks; ct::run_program (core/process.h) runs it.

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace ct::series {

class BlenderBatchCommand {
 public:
  // blender --background --factory-startup --python BATCH_SCRIPT --
  BlenderBatchCommand(const std::filesystem::path& blender, const std::filesystem::path& batch_script);

  // Adds a batch option and its value; nothing when the value is empty (an option left at the batch's default).
  BlenderBatchCommand& option(std::string_view name, const std::string& value);
  template <typename Number>
  BlenderBatchCommand& option(std::string_view name, const std::optional<Number>& value) {
    return option(name, value ? std::to_string(*value) : std::string());
  }
  // Adds a batch option without a value.
  BlenderBatchCommand& flag(std::string_view name);

  // Blender and its own options; further Blender options (such as --threads) go after these.
  const std::vector<std::string>& blender_words() const { return blender_; }
  // --python BATCH_SCRIPT -- and the batch's options.
  const std::vector<std::string>& batch_words() const { return batch_; }
  // The whole command line.
  std::vector<std::string> argv() const;

  // The environment the batch needs: CHROMATRACE_EXE, the chromatrace it runs for its helpers.
  static std::vector<std::pair<std::string, std::string>> environment(const std::filesystem::path& chromatrace);

 private:
  std::vector<std::string> blender_, batch_;
};

}  // namespace ct::series
