// SPDX-License-Identifier: Apache-2.0
#pragma once
// The paper's test box, which the plan's tests change and plan, and a changed copy of its document as a scene.

#include <filesystem>

#include "core/json_input.h"
#include "core/scene.h"
#include "tests/cli/text_files.h"

namespace ct::test {

inline const std::filesystem::path kBox = kPaperBox;

// A variant of the box's document, its relative paths resolved beside the box.
inline Scene scene_of(const Json& doc) { return parse_scene(doc, "box-variant.json", kBox.parent_path()); }

}  // namespace ct::test
