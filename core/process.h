#pragma once
// Running another program and waiting for it (Blender for a series' Cycles renders, Slurm's client commands
// for the farm). posix_spawn: no code of ours runs between fork and exec.

#include <spawn.h>

#include <string>
#include <utility>
#include <vector>

namespace ct {

// Runs argv[0] (found on PATH) with argv, this process's environment with `env` set over it, and the file
// actions (redirections; may be null), and waits. Returns the exit status, or 128 + the signal that ended it.
// std::runtime_error ("cannot start PROGRAM: …") when it cannot be started.
int spawn_and_wait(const std::vector<std::string>& argv, const std::vector<std::pair<std::string, std::string>>& env,
                   const posix_spawn_file_actions_t* actions);

}  // namespace ct
