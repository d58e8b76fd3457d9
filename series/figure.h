// SPDX-License-Identifier: Apache-2.0
#pragma once
// The figure page of an experiment series run (docs/series.md): DIR/index.html (self-contained, offline)
// and, for a series whose variants name panels of the paper's figures, DIR/figure3.png and DIR/figure4.png
// laid out like the paper's Figures 3 and 4.

#include <filesystem>

#include "core/json_input.h"

namespace ct::series {

// `result` is series.json (runner.h, result_json); every file it names is read relative to `dir`.
void write_figure_page(const std::filesystem::path& dir, const Json& result);

}  // namespace ct::series
