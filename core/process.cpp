// SPDX-License-Identifier: Apache-2.0
#include "core/process.h"

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <string_view>

#include <fmt/core.h>

extern char** environ;

namespace ct {
namespace {

std::vector<char*> pointers(std::vector<std::string>& strings) {
  std::vector<char*> p;
  for (std::string& s : strings) p.push_back(s.data());
  p.push_back(nullptr);
  return p;
}

std::string slurp(int fd) {
  std::string text;
  char buffer[4096];
  lseek(fd, 0, SEEK_SET);
  ssize_t n;
  while ((n = read(fd, buffer, sizeof buffer)) > 0) text.append(buffer, static_cast<std::size_t>(n));
  close(fd);
  return text;
}

// An unlinked temporary file, open for reading and writing.
int temporary_file() {
  char name[] = "/tmp/chromatrace-run-XXXXXX";
  const int fd = mkstemp(name);
  if (fd < 0) throw std::runtime_error("cannot create a temporary file in /tmp");
  unlink(name);
  return fd;
}

}  // namespace

int spawn_and_wait(const std::vector<std::string>& argv, const std::vector<std::pair<std::string, std::string>>& env,
                   const posix_spawn_file_actions_t* actions) {
  std::vector<std::string> environment;
  for (char** e = environ; *e; ++e) {
    const std::string_view entry(*e);
    if (std::none_of(env.begin(), env.end(), [&](const auto& kv) { return entry.starts_with(kv.first + "="); }))
      environment.emplace_back(entry);
  }
  for (const auto& [name, value] : env) environment.push_back(name + "=" + value);
  std::vector<std::string> args = argv;
  const std::vector<char*> arg_pointers = pointers(args), env_pointers = pointers(environment);
  pid_t pid = 0;
  const int error = posix_spawnp(&pid, arg_pointers[0], actions, nullptr, arg_pointers.data(), env_pointers.data());
  if (error != 0) throw std::runtime_error(fmt::format("cannot start {}: {}", argv[0], std::strerror(error)));
  int status = 0;
  while (waitpid(pid, &status, 0) < 0)
    if (errno != EINTR) throw std::runtime_error("waiting for a process failed");
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

ProgramOutput run_program(const std::vector<std::string>& argv,
                          const std::vector<std::pair<std::string, std::string>>& env,
                          const std::filesystem::path& stdout_log) {
  const bool capture = stdout_log.empty();
  int out_fd = -1, err_fd = -1;
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  ProgramOutput result;
  try {
    if (capture) {
      out_fd = temporary_file();
      err_fd = temporary_file();
      posix_spawn_file_actions_adddup2(&actions, out_fd, STDOUT_FILENO);
      posix_spawn_file_actions_adddup2(&actions, err_fd, STDERR_FILENO);
    } else {
      posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, stdout_log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    }
    result.status = spawn_and_wait(argv, env, &actions);
  } catch (...) {
    posix_spawn_file_actions_destroy(&actions);
    if (out_fd >= 0) close(out_fd);
    if (err_fd >= 0) close(err_fd);
    throw;
  }
  posix_spawn_file_actions_destroy(&actions);
  if (capture) {
    result.out = slurp(out_fd);
    result.err = slurp(err_fd);
  }
  return result;
}

}  // namespace ct
