// SPDX-License-Identifier: Apache-2.0
#pragma once
// Runs the real `chromatrace` executable for end-to-end tests and captures what it printed.

#include <string>
#include <vector>

namespace ct::test {

struct CommandResult {
  int exit_code = -1;
  std::string out;  // stdout
  std::string err;  // stderr
};

// Runs CHROMATRACE_EXE with the given arguments (no shell involved).
CommandResult run_chromatrace(const std::vector<std::string>& args);
// Runs any program (a path) the same way; it inherits this process's environment.
CommandResult run_program(const std::string& program, const std::vector<std::string>& args);
// The same in a child whose files may grow to `kib` KiB (RLIMIT_FSIZE, inherited by its children) with SIGXFSZ
// ignored, so that a write beyond it fails with EFBIG as a write to a full disk fails with ENOSPC.
CommandResult run_program_with_file_size_limit(const std::string& program, const std::vector<std::string>& args,
                                               long kib);

}  // namespace ct::test
