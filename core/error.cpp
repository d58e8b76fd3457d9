// SPDX-License-Identifier: Apache-2.0
#include "core/error.h"
#include "core/library_output.h"

#include <fcntl.h>
#include <unistd.h>

#include <cstdio>
#include <mutex>

#include <fmt/core.h>

namespace ct {

std::string one_line(std::string_view text) {
  while (!text.empty() && (text.back() == '\n' || text.back() == '\r' || text.back() == ' ')) text.remove_suffix(1);
  std::string line;
  line.reserve(text.size());
  for (const char c : text) {
    const auto byte = static_cast<unsigned char>(c);
    if (c == '\n') line += "\\n";
    else if (c == '\t') line += "\\t";
    else if (c == '\r') line += "\\r";
    else if (byte < 0x20 || byte == 0x7f) line += fmt::format("\\x{:02x}", byte);
    else line += c;
  }
  return line;
}

namespace {

std::mutex silenced_mutex;
int silenced_depth = 0;
int saved_stderr = -1;

}  // namespace

LibraryStderrSilenced::LibraryStderrSilenced() {
  const std::lock_guard lock(silenced_mutex);
  if (silenced_depth++ > 0) return;
  std::fflush(stderr);
  saved_stderr = ::dup(STDERR_FILENO);
  const int null = ::open("/dev/null", O_WRONLY | O_CLOEXEC);
  if (saved_stderr >= 0 && null >= 0) ::dup2(null, STDERR_FILENO);
  if (null >= 0) ::close(null);
}

LibraryStderrSilenced::~LibraryStderrSilenced() {
  const std::lock_guard lock(silenced_mutex);
  if (--silenced_depth > 0) return;
  std::fflush(stderr);
  if (saved_stderr >= 0) {
    ::dup2(saved_stderr, STDERR_FILENO);
    ::close(saved_stderr);
    saved_stderr = -1;
  }
}

}  // namespace ct
