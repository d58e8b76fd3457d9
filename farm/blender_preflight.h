// SPDX-License-Identifier: Apache-2.0
#pragma once
// The Blender add-on batch's pre-flight check (batch.py --explain -), run before a farm's Cycles tasks are
// submitted: it refuses bad input here and now, and says how many tasks there are (band groups, and a render per
// bounce limit with the bounces components).

#include <string>
#include <utility>
#include <vector>

#include "core/json_input.h"

namespace ct::farm {

struct BlenderPreflight {
  Json summary;                              // the batch's summary as it printed it (kept as slurm/preflight.json)
  int band_groups = 0;                       // one task per band group …
  std::vector<std::string> render_variants;  // … and per render variant ("all" or each bounce limit)
};

// Runs the batch's command line `argv` (which asks for --explain -) with `env`. InputError with the batch's
// own one-line error when it refuses its options, or with the first reason the summary gives when it refuses
// the scene (`source` names it); std::runtime_error when Blender fails otherwise.
BlenderPreflight run_blender_preflight(const std::vector<std::string>& argv,
                                       const std::vector<std::pair<std::string, std::string>>& env,
                                       const std::string& source);

// The summary in what Blender printed on stdout: Blender prints lines of its own, so it is the JSON object that
// starts a line and ends at a line starting with "}". Empty when there is none.
std::string preflight_summary_text(const std::string& out);

// The last line of a program's stderr that says what went wrong (the batch's one-line error).
std::string last_line(const std::string& text);

}  // namespace ct::farm
