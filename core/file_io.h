#pragma once
// Reading whole input files, and writing outputs so that a file appears under its name only when complete.

#include <filesystem>
#include <string>
#include <string_view>

namespace ct {

// The file's bytes; an unreadable file is an InputError "<file>: cannot open file".
std::string read_file(const std::filesystem::path& file);

// A temporary file beside `target` (so the final rename stays on one file system and is atomic), created
// with O_EXCL and the permissions a plain new file gets. commit() flushes it to disk and renames it to
// `target`; destroyed without commit(), it removes the temporary. Nothing half-written is ever left behind.
class AtomicFile {
 public:
  // InputError naming the target when no temporary file can be created there.
  explicit AtomicFile(std::filesystem::path target);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  const std::filesystem::path& target() const { return target_; }
  const std::filesystem::path& temporary() const { return temporary_; }
  int descriptor() const { return fd_; }
  // fsync, close and rename into place (a runtime_error naming the target on failure).
  void commit();

 private:
  std::filesystem::path target_;
  std::filesystem::path temporary_;
  int fd_ = -1;
};

// Writes `bytes` to `file` through an AtomicFile.
void write_file_atomically(const std::filesystem::path& file, std::string_view bytes);

}  // namespace ct
