// SPDX-License-Identifier: Apache-2.0
#pragma once
// The report viewer (analyzer/web/viewer.js with three.js), bundled by esbuild into one IIFE at build time.

#include <string_view>

namespace ct::analyzer {
std::string_view viewer_bundle();
}  // namespace ct::analyzer
