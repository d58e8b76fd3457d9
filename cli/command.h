// SPDX-License-Identifier: Apache-2.0
#pragma once
// The `chromatrace` command: each subcommand lives in its own cmd_<name>.cpp and registers itself here.
//
// A subcommand's add function creates its CLI11 subcommand on `app` and returns the action to run when the
// user chose it. Actions return the exit code (0 success, also for `compare` whether or not the renders agree) and
// throw ct::InputError for bad input (exit 2, one line) or anything else for runtime failures (exit 1).

#include <functional>

#include <CLI/CLI.hpp>

namespace ct::cli {

using Action = std::function<int()>;

Action add_info(CLI::App& app);
Action add_check_scene(CLI::App& app);
Action add_render(CLI::App& app);
Action add_analyze(CLI::App& app);
Action add_sensor(CLI::App& app);
Action add_series(CLI::App& app);
Action add_paper(CLI::App& app);
Action add_plan(CLI::App& app);
Action add_study(CLI::App& app);
// Helpers of the Blender add-on (blender_addon/): spectra, meshes and the final file come from core.
Action add_scene_bands(CLI::App& app);
Action add_export_meshes(CLI::App& app);
Action add_assemble(CLI::App& app);
Action add_combine(CLI::App& app);
// Work split into Slurm jobs on a cluster (docs/farm.md).
Action add_farm(CLI::App& app);
Action add_compare(CLI::App& app);
Action add_calibrate(CLI::App& app);
Action add_prepare_texture(CLI::App& app);

}  // namespace ct::cli
