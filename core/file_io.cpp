// SPDX-License-Identifier: Apache-2.0
#include "core/file_io.h"

#include <fcntl.h>
#include <limits.h>
#include <poll.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <map>
#include <mutex>
#include <stdexcept>
#include <utility>
#include <vector>

#include <fmt/core.h>

#include "core/error.h"

namespace ct {

namespace fs = std::filesystem;

namespace {

// How long read_file waits for a FIFO's first bytes (or its writer's end).
constexpr int kFifoGraceMs = 2000;

// "a FIFO", "a character device", …: what a path is when it is not a regular file.
std::string kind_of(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

// The refusal to replace `resolved` (which `output` is or links to) by a regular file.
std::string not_a_regular_file(const fs::path& output, const fs::path& resolved, mode_t mode) {
  if (S_ISDIR(mode) && output == resolved)
    return fmt::format("{}: is a directory; the output must be a file name", output.string());
  const std::string what = output == resolved ? fmt::format("is {}", kind_of(mode))
                                              : fmt::format("links to {}, which is {}", resolved.string(), kind_of(mode));
  return fmt::format("{}: {}; outputs are written only as regular files, never in place of {}", output.string(), what,
                     S_ISDIR(mode) ? "a directory" : "a special file");
}

// InputError "<output>: cannot write in directory <directory>: <reason>" unless files can be created there: an
// unwritable output location is the user's to change, like a missing one.
void check_writable_directory(const fs::path& output, const fs::path& directory) {
  if (::access(directory.c_str(), W_OK | X_OK) != 0)
    throw InputError(
        fmt::format("{}: cannot write in directory {}: {}", output.string(), directory.string(), std::strerror(errno)));
}

}  // namespace

std::uintmax_t check_input_file(const fs::path& file, InputAccess access, std::uintmax_t max_bytes) {
  const std::string name = file.string();
  struct stat st{};
  if (::stat(file.c_str(), &st) != 0) {
    if (errno == ENOENT || errno == ENOTDIR) throw InputError(fmt::format("{}: cannot open file", name));
    throw InputError(fmt::format("{}: cannot open file: {}", name, std::strerror(errno)));
  }
  if (S_ISDIR(st.st_mode)) throw InputError(fmt::format("{}: is a directory, not a file", name));
  const bool stream = S_ISFIFO(st.st_mode) || S_ISCHR(st.st_mode);
  if (!S_ISREG(st.st_mode) && !(stream && access == InputAccess::Sequential))
    throw InputError(fmt::format("{}: is {}; {}", name, kind_of(st.st_mode),
                                 access == InputAccess::Seekable
                                     ? "this file is read only from a regular file"
                                     : "inputs are read from regular files or streams (pipes, character devices)"));
  if (::access(file.c_str(), R_OK) != 0)
    throw InputError(fmt::format("{}: cannot open file: {}", name, std::strerror(errno)));
  if (S_ISREG(st.st_mode) && static_cast<std::uintmax_t>(st.st_size) > max_bytes)
    throw InputError(fmt::format("{}: {} bytes, more than the limit of {} bytes ({} MiB) for this kind of file", name,
                                 static_cast<std::uintmax_t>(st.st_size), max_bytes, max_bytes >> 20));
  return S_ISREG(st.st_mode) ? static_cast<std::uintmax_t>(st.st_size) : 0;
}

std::string read_file(const fs::path& file, std::uintmax_t max_bytes) {
  check_input_file(file, InputAccess::Sequential, max_bytes);
  const std::string name = file.string();
  // Without blocking: opening a FIFO that nothing writes to would wait for a writer forever.
  const int fd = ::open(file.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) throw InputError(fmt::format("{}: cannot open file: {}", name, std::strerror(errno)));
  struct Closer {
    int fd;
    ~Closer() { ::close(fd); }
  } closer{fd};
  struct stat st{};
  const bool fifo = ::fstat(fd, &st) == 0 && S_ISFIFO(st.st_mode);
  // A pipe can be read once: a command that reads its input twice (check-scene looks at the format, then loads)
  // gets the same bytes the second time.
  static std::mutex read_pipes_mutex;
  static std::map<std::pair<dev_t, ino_t>, std::string> read_pipes;
  const std::lock_guard lock(read_pipes_mutex);
  if (fifo)
    if (const auto known = read_pipes.find({st.st_dev, st.st_ino}); known != read_pipes.end()) return known->second;
  if (fifo) {
    // A pipe's writer (a shell's `<(…)`) is there before the reader; a FIFO made by mkfifo may get one a moment
    // later. Nothing within the grace period is a FIFO that nothing writes to, not a wait without end.
    pollfd ready{fd, POLLIN, 0};
    if (::poll(&ready, 1, kFifoGraceMs) == 0)
      throw InputError(fmt::format("{}: is a FIFO that nothing writes to (nothing arrived within {} s)", name,
                                   kFifoGraceMs / 1000));
  }
  ::fcntl(fd, F_SETFL, ::fcntl(fd, F_GETFL) & ~O_NONBLOCK);  // from here on, a stream is read to its end
  std::string bytes;
  char buffer[65536];
  for (;;) {
    const ssize_t n = ::read(fd, buffer, sizeof buffer);
    if (n == 0) break;
    if (n < 0) {
      if (errno == EINTR) continue;
      throw InputError(fmt::format("{}: cannot read file: {}", name, std::strerror(errno)));
    }
    if (bytes.size() + static_cast<std::size_t>(n) > max_bytes)
      throw InputError(fmt::format("{}: more than the limit of {} bytes ({} MiB) for this kind of file", name,
                                   max_bytes, max_bytes >> 20));
    bytes.append(buffer, static_cast<std::size_t>(n));
  }
  if (fifo) read_pipes[{st.st_dev, st.st_ino}] = bytes;
  return bytes;
}

void check_file_name(std::string_view name, std::string_view what) {
  const auto refuse = [&](std::string_view why) {
    throw InputError(fmt::format("{}{}\"{}\" cannot be a file name: {}", what, what.empty() ? "" : ": ", one_line(name), why));
  };
  if (name.empty()) refuse("it is empty");
  if (name == "." || name == "..") refuse("it names a directory, not a file in the output directory");
  if (name.find('/') != std::string_view::npos) refuse("it holds a \"/\"; names are written inside the output directory");
  for (const char c : name)
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) refuse("it holds a control character");
  if (name.size() > NAME_MAX) refuse(fmt::format("it is longer than {} bytes", NAME_MAX));
}

bool same_file(const fs::path& a, const fs::path& b) {
  struct stat sa{}, sb{};
  if (::stat(a.c_str(), &sa) != 0 || ::stat(b.c_str(), &sb) != 0) return false;
  return sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
}

void check_not_an_input(const fs::path& output, const std::vector<fs::path>& inputs) {
  for (const fs::path& input : inputs)
    if (!input.empty() && same_file(output, input))
      throw InputError(fmt::format("{}: is the same file as the input {}; writing the output would destroy the input",
                                   output.string(), input.string()));
}

fs::path follow_links(const fs::path& path) {
  fs::path current = path;
  for (int hops = 0; hops < 40; ++hops) {
    std::error_code error;
    if (!fs::is_symlink(fs::symlink_status(current, error))) return current;
    const fs::path next = fs::read_symlink(current, error);
    if (error) return current;
    current = next.is_absolute() ? next : (current.parent_path() / next).lexically_normal();
  }
  throw InputError(fmt::format("{}: too many levels of symbolic links", path.string()));
}

namespace {

// InputError when the system could not open `output` for its length: a path of 4096 bytes or more, or a
// component of more than 255.
void check_name_length(const fs::path& output) {
  const std::string text = output.string();
  if (text.size() >= PATH_MAX)
    throw InputError(fmt::format("{}...: the output path is {} bytes long, more than the {} the system takes",
                                 one_line(text.substr(0, 60)), text.size(), PATH_MAX - 1));
  for (const fs::path& part : output)
    if (part.string().size() > NAME_MAX)
      throw InputError(fmt::format("{}...: a name in the output path is {} bytes long, more than the {} the system "
                                   "takes", one_line(text.substr(0, 60)), part.string().size(), NAME_MAX));
}

}  // namespace

void check_distinct_outputs(const std::vector<fs::path>& outputs) {
  for (std::size_t i = 0; i < outputs.size(); ++i)
    for (std::size_t j = i + 1; j < outputs.size(); ++j) {
      if (outputs[i].empty() || outputs[j].empty()) continue;
      const bool same = same_file(outputs[i], outputs[j]) ||
                        fs::absolute(follow_links(outputs[i])).lexically_normal() ==
                            fs::absolute(follow_links(outputs[j])).lexically_normal();
      if (same)
        throw InputError(fmt::format("{}: is the same file as the output {}; each output needs a file of its own",
                                     outputs[j].string(), outputs[i].string()));
    }
}

namespace {

// An existing file this user may not write (its permissions, or a read-only file system) is not replaced behind its
// back through the rename, which needs only the directory's permission: refused as cp refuses it. (Root may write any
// file, and replaces it, as cp does.)
void check_writable_file(const fs::path& output, const fs::path& resolved) {
  if (::access(resolved.c_str(), F_OK) == 0 && ::access(resolved.c_str(), W_OK) != 0 && (errno == EACCES || errno == EROFS))
    throw InputError(fmt::format("{}: exists and is not writable ({}); it is not replaced, as cp would not replace it", output.string(),
                                 std::strerror(errno)));
}

}  // namespace

void check_output_file(const fs::path& output, const std::vector<fs::path>& inputs) {
  check_name_length(output);
  check_not_an_input(output, inputs);
  const fs::path resolved = follow_links(output);
  struct stat st{};
  if (::stat(resolved.c_str(), &st) == 0 && !S_ISREG(st.st_mode))
    throw InputError(not_a_regular_file(output, resolved, st.st_mode));
  check_writable_file(output, resolved);
  if (output.filename().empty()) throw InputError(fmt::format("{}: no file name", output.string()));
  const fs::path parent = fs::absolute(resolved).parent_path();
  if (!fs::is_directory(parent))
    throw InputError(fmt::format("{}: directory {} does not exist", output.string(), parent.string()));
  check_writable_directory(output, parent);
}

void check_output_directory(const fs::path& directory, const std::vector<fs::path>& inputs, const std::vector<std::string>& written) {
  check_name_length(directory);
  check_not_an_input(directory, inputs);
  for (const std::string& name : written)
    for (const fs::path& input : inputs)
      if (!input.empty() && same_file(directory / name, input))
        throw InputError(fmt::format("{}: is the input {}; writing {} there would destroy the input",
                                     (directory / name).string(), input.string(), name));
  std::error_code error;
  if (fs::exists(directory, error) && !fs::is_directory(directory, error))
    throw InputError(fmt::format("{}: exists and is not a directory", directory.string()));
  fs::path absolute = fs::absolute(directory);
  if (!absolute.has_filename()) absolute = absolute.parent_path();  // "out/"
  if (!fs::is_directory(absolute.parent_path()))
    throw InputError(
        fmt::format("{}: directory {} does not exist", directory.string(), absolute.parent_path().string()));
  check_writable_directory(directory, fs::is_directory(absolute) ? absolute : absolute.parent_path());
}

AtomicFile::AtomicFile(fs::path target) : target_(std::move(target)), destination_(follow_links(target_)) {
  struct stat st{};
  if (::stat(destination_.c_str(), &st) == 0 && !S_ISREG(st.st_mode))
    throw InputError(not_a_regular_file(target_, destination_, st.st_mode));
  check_writable_file(target_, destination_);
  const bool replaces = ::stat(destination_.c_str(), &st) == 0;
  const fs::path directory = destination_.has_parent_path() ? destination_.parent_path() : fs::path(".");
  for (int attempt = 0;; ++attempt) {
    temporary_ = directory / fmt::format(".{}.{}-{}.tmp", destination_.filename().string(), static_cast<long>(::getpid()), attempt);
    fd_ = ::open(temporary_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd_ >= 0) {
      // A file replaced keeps its permissions, as one cp writes over does.
      if (replaces) (void)::fchmod(fd_, st.st_mode & 07777);
      return;
    }
    if (errno != EEXIST || attempt >= 1000) {
      const int error = errno;
      temporary_.clear();
      throw InputError(fmt::format("{}: cannot create a temporary file in {}: {}", target_.string(),
                                   directory.string(), std::strerror(error)));
    }
  }
}

AtomicFile::~AtomicFile() {
  if (fd_ >= 0) ::close(fd_);
  std::error_code ignored;
  if (!temporary_.empty()) fs::remove(temporary_, ignored);
}

void AtomicFile::commit() {
  // On disk before it gets the final name, so that a crash cannot leave a renamed but empty file.
  if (::fsync(fd_) != 0 || ::close(std::exchange(fd_, -1)) != 0)
    throw std::runtime_error(fmt::format("{}: cannot write: {}", target_.string(), std::strerror(errno)));
  // What was checked when this file was started may have changed since (a long render): a special file or
  // a directory that has appeared under the name is still not replaced.
  struct stat st{};
  if (::lstat(destination_.c_str(), &st) == 0 && !S_ISREG(st.st_mode))
    throw InputError(not_a_regular_file(target_, destination_, st.st_mode));
  std::error_code error;
  fs::rename(temporary_, destination_, error);
  if (error)
    throw std::runtime_error(
        fmt::format("{}: cannot rename the finished file into place: {}", target_.string(), error.message()));
  temporary_.clear();
}

StagedDirectory::StagedDirectory(fs::path target, std::vector<std::string> last)
    : target_(std::move(target)), last_(std::move(last)) {
  fs::path absolute = fs::absolute(target_);
  if (!absolute.has_filename()) absolute = absolute.parent_path();  // "out/"
  for (int attempt = 0;; ++attempt) {
    staging_ = absolute.parent_path() /
               fmt::format(".{}.{}-{}.tmp", absolute.filename().string(), static_cast<long>(::getpid()), attempt);
    if (::mkdir(staging_.c_str(), 0777) == 0) return;
    if (errno != EEXIST || attempt >= 1000) {
      const int error = errno;
      staging_.clear();
      throw InputError(fmt::format("{}: cannot create a directory in {}: {}", target_.string(),
                                   absolute.parent_path().string(), std::strerror(error)));
    }
  }
}

StagedDirectory::~StagedDirectory() {
  std::error_code ignored;
  if (!staging_.empty()) fs::remove_all(staging_, ignored);
}

void StagedDirectory::commit() {
  std::error_code error;
  if (!fs::exists(fs::symlink_status(target_, error))) {
    fs::rename(staging_, target_, error);
    if (error)
      throw std::runtime_error(
          fmt::format("{}: cannot rename the finished directory into place: {}", target_.string(), error.message()));
    staging_.clear();
    return;
  }
  // Listed first, then moved; directories come before the files in them, the summaries in last_ after all.
  std::vector<fs::directory_entry> entries(fs::recursive_directory_iterator(staging_), {});
  std::stable_partition(entries.begin(), entries.end(), [&](const fs::directory_entry& entry) {
    return entry.path().parent_path() != staging_ ||
           std::find(last_.begin(), last_.end(), entry.path().filename().string()) == last_.end();
  });
  for (const fs::directory_entry& entry : entries) {
    const fs::path relative = entry.path().lexically_relative(staging_);
    const fs::path destination = target_ / relative;
    if (entry.is_directory()) {
      if (!fs::is_directory(destination)) {
        fs::create_directory(destination, error);
        if (error) throw InputError(fmt::format("{}: cannot create the directory: {}", destination.string(), error.message()));
      }
      continue;
    }
    const fs::path resolved = follow_links(destination);
    struct stat st{};
    if (::stat(resolved.c_str(), &st) == 0 && !S_ISREG(st.st_mode))
      throw InputError(not_a_regular_file(destination, resolved, st.st_mode));
    fs::rename(entry.path(), resolved, error);
    if (error)
      throw std::runtime_error(
          fmt::format("{}: cannot rename the finished file into place: {}", destination.string(), error.message()));
  }
}

void write_file_atomically(const fs::path& file, std::string_view bytes) {
  AtomicFile out(file);
  for (std::size_t done = 0; done < bytes.size();) {
    const ssize_t n = ::write(out.descriptor(), bytes.data() + done, bytes.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      throw std::runtime_error(fmt::format("{}: cannot write: {}", file.string(), std::strerror(errno)));
    }
    done += static_cast<std::size_t>(n);
  }
  out.commit();
}

}  // namespace ct
