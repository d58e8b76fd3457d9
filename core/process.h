// SPDX-License-Identifier: Apache-2.0
#pragma once
// Running another program and waiting for it (Blender for a series' Cycles renders, Slurm's client commands
// for the farm). posix_spawn: no code of ours runs between fork and exec.

#include <spawn.h>

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace ct {

// Runs argv[0] (found on PATH) with argv, this process's environment with `env` set over it, and the file
// actions (redirections; may be null), and waits. Returns the exit status, or 128 + the signal that ended it.
// std::runtime_error ("cannot start PROGRAM: …") when it cannot be started.
int spawn_and_wait(const std::vector<std::string>& argv, const std::vector<std::pair<std::string, std::string>>& env,
                   const posix_spawn_file_actions_t* actions);

// What a program run by run_program printed, and how it ended.
struct ProgramOutput {
  int status = -1;  // exit status, or 128 + the signal
  std::string out, err;
};

// Runs a program (found on PATH) with `env` set over this process's environment and waits. Without
// `stdout_log`, what it prints on stdout and stderr is captured (through unlinked temporary files, so that no
// pipe can fill up); with it, its stdout goes to that file and its stderr to ours (a long job's progress lines),
// and neither is captured.
ProgramOutput run_program(const std::vector<std::string>& argv,
                          const std::vector<std::pair<std::string, std::string>>& env = {},
                          const std::filesystem::path& stdout_log = {});

}  // namespace ct
