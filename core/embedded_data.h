// SPDX-License-Identifier: Apache-2.0
#pragma once
// Data files compiled into the library (see cmake/EmbedFiles.cmake and core/data/README.md).

#include <string_view>

namespace ct::embedded {
// The bytes of an embedded file by its path under core/data/, e.g. "illuminants/D65.csv"; empty if unknown.
std::string_view file(std::string_view name);
}  // namespace ct::embedded
