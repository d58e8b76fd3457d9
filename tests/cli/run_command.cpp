// SPDX-License-Identifier: Apache-2.0
#include "tests/cli/run_command.h"

#include <fcntl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <stdexcept>
#include <string>

namespace ct::test {
namespace {

std::string drain(int fd) {
  std::string text;
  char buffer[4096];
  ssize_t n;
  while ((n = read(fd, buffer, sizeof buffer)) > 0) text.append(buffer, static_cast<std::size_t>(n));
  close(fd);
  return text;
}

// Runs the program; kib > 0 limits the size of the files it writes.
CommandResult run(const std::string& program, const std::vector<std::string>& args, long kib) {
  // stdout and stderr go to unlinked temporary files, so a chatty command cannot dead-lock on a full pipe.
  char out_name[] = "/tmp/chromatrace-out-XXXXXX";
  char err_name[] = "/tmp/chromatrace-err-XXXXXX";
  const int out_fd = mkstemp(out_name);
  const int err_fd = mkstemp(err_name);
  if (out_fd < 0 || err_fd < 0) throw std::runtime_error("mkstemp failed");
  unlink(out_name);
  unlink(err_name);

  std::vector<char*> argv;
  std::string exe = program;
  argv.push_back(exe.data());
  std::vector<std::string> copies = args;
  for (std::string& a : copies) argv.push_back(a.data());
  argv.push_back(nullptr);

  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error("fork failed");
  if (pid == 0) {
    dup2(out_fd, STDOUT_FILENO);
    dup2(err_fd, STDERR_FILENO);
    if (kib > 0) {
      const rlimit limit{static_cast<rlim_t>(kib) * 1024, static_cast<rlim_t>(kib) * 1024};
      signal(SIGXFSZ, SIG_IGN);  // kept across exec
      if (setrlimit(RLIMIT_FSIZE, &limit) != 0) _exit(126);
    }
    execv(exe.c_str(), argv.data());
    _exit(127);
  }
  int status = 0;
  waitpid(pid, &status, 0);

  CommandResult result;
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  lseek(out_fd, 0, SEEK_SET);
  lseek(err_fd, 0, SEEK_SET);
  result.out = drain(out_fd);
  result.err = drain(err_fd);
  return result;
}

}  // namespace

CommandResult run_chromatrace(const std::vector<std::string>& args) { return run_program(CHROMATRACE_EXE, args); }

CommandResult run_program(const std::string& program, const std::vector<std::string>& args) {
  return run(program, args, 0);
}

CommandResult run_program_with_file_size_limit(const std::string& program, const std::vector<std::string>& args,
                                               long kib) {
  return run(program, args, kib);
}

}  // namespace ct::test
