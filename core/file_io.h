// SPDX-License-Identifier: Apache-2.0
#pragma once
// Reading whole input files, and writing outputs so that a file appears under its name only when complete.

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "core/limits.h"

namespace ct {

// ---- Inputs: one check before any reader opens a file ----------------------------------------------------
//
// What an input may be (docs/errors.md, "Special files and sizes"): a regular file, or — for a reader that reads
// the file once from start to end (JSON, CSV, PLY: read_file) — a named stream such as a pipe (`<(cat s.json)`)
// or a character device; never a directory, a block device or a socket. A regular file's size is bounded
// before it is read, a stream's while it is read, so /dev/zero is refused after kMaxInputBytes, not at 4 GB.

enum class InputAccess {
  Sequential,  // read once from start to end: a regular file or a readable stream
  Seekable,    // opened by a library that seeks (OpenEXR, OpenImageIO, LibRaw): a regular file only
};

// InputError naming `file` when it does not exist or cannot be read, is a directory, a block device or a socket,
// is a FIFO or character device where `access` is Seekable, or is a regular file larger than `max_bytes`.
// Returns the size of a regular file, 0 for a stream.
std::uintmax_t check_input_file(const std::filesystem::path& file, InputAccess access,
                                std::uintmax_t max_bytes = kMaxInputBytes);

// The file's bytes, after check_input_file(file, Sequential, max_bytes): at most `max_bytes` of them, also from
// a stream. A FIFO is opened without blocking; one on which nothing arrives within 2 s is an InputError ("is a
// FIFO that nothing writes to"), not a wait without end.
std::string read_file(const std::filesystem::path& file, std::uintmax_t max_bytes = kMaxInputBytes);

// A name taken from inside an input file (a series variant's name) that becomes a file or directory name under
// an output directory: InputError "<what>: \"<name>\" cannot be a file name: …" unless it is one plain path
// component — not empty, ".", "..", no "/", no control character, at most 255 bytes — so that nothing is
// written outside the output directory.
void check_file_name(std::string_view name, std::string_view what);

// ---- Outputs that never destroy inputs or replace special files ----------------------------------------
//
// Each command checks its outputs with these before any work, so that a mistyped output name is refused
// at once (exit 2) instead of after an hour's render, and never costs an input.

// Whether `a` and `b` name one existing file: the same device and inode, following symbolic links, so that
// hard links, "./x" spellings and links to the file all count. False when either does not exist.
bool same_file(const std::filesystem::path& a, const std::filesystem::path& b);

// InputError "<output>: is the same file as the input <input>; …" when `output` names one of `inputs`.
void check_not_an_input(const std::filesystem::path& output, const std::vector<std::filesystem::path>& inputs);

// What a file output may be: nothing yet, or a regular file (through any symbolic links) this user may write.
// InputError naming `output` when its directory does not exist, when it is (or links to) a directory, a FIFO, a
// device or a socket, when it exists and this user may not write it (as cp refuses; root may), when it is one of
// `inputs`, or when its name is longer than the system takes (4095 bytes a path, 255 a component).
void check_output_file(const std::filesystem::path& output, const std::vector<std::filesystem::path>& inputs = {});

// What an output directory may be: nothing yet (its parent must exist) or a directory. InputError naming
// `directory` otherwise, or when it is one of `inputs`, or when one of `inputs` lies in it under a name in `written`
// (the files the command writes there, which would replace it).
void check_output_directory(const std::filesystem::path& directory,
                            const std::vector<std::filesystem::path>& inputs = {},
                            const std::vector<std::string>& written = {});

// The file a write to `path` lands in: `path` with the symbolic links of its last component followed (a
// link's target relative to the link's directory); `path` itself when it is not a link. InputError on a
// loop of links.
std::filesystem::path follow_links(const std::filesystem::path& path);

// A temporary file beside `target` (so the final rename stays on one file system and is atomic), created
// with O_EXCL and the permissions a plain new file gets (those of the file it replaces, when there is one). commit() flushes it to disk and renames it to
// `target`; destroyed without commit(), it removes the temporary. Nothing half-written is ever left behind.
//
// A `target` that is a symbolic link is followed: the file it points to is replaced (atomically, the
// temporary file beside it) and the link stays. A target that is a directory, FIFO, device or socket is
// never replaced by a regular file: the constructor refuses it, and an existing file this user may not write (see
// check_output_file).
class AtomicFile {
 public:
  // InputError naming the target when it is not a regular file (see above) or no temporary file can be
  // created there.
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
  std::filesystem::path destination_;  // target_ with its links followed: what commit() replaces
  std::filesystem::path temporary_;
  int fd_ = -1;
};

// A directory of outputs that appears complete or not at all. The files are written under path(), a fresh
// directory beside `target` (".<name>.<pid>-<n>.tmp"); commit() moves them into `target`: the whole
// directory is renamed when `target` does not exist yet, else each file is renamed over its namesake there
// (following a symbolic link as AtomicFile does; a special file or directory in the way is an InputError).
// Destroyed without commit() (a full disk, bad input found late), the staging directory and everything in it
// are removed and `target` is left as it was. The files named in `last` (at the top of the directory: the
// summary that points at the rest, e.g. compare.json) are renamed after every other file, so that an
// interrupted commit into an existing directory never shows a new summary without what it points at.
class StagedDirectory {
 public:
  // InputError naming `target` when no directory can be created beside it.
  explicit StagedDirectory(std::filesystem::path target, std::vector<std::string> last = {});
  ~StagedDirectory();
  StagedDirectory(const StagedDirectory&) = delete;
  StagedDirectory& operator=(const StagedDirectory&) = delete;

  const std::filesystem::path& path() const { return staging_; }
  void commit();

 private:
  std::filesystem::path target_;
  std::filesystem::path staging_;
  std::vector<std::string> last_;
};

// InputError when two of a command's outputs are one file (the same path, another spelling of it, or a link to
// it): "<b>: is the same file as the output <a>; …". Outputs not existing yet are compared by absolute path.
void check_distinct_outputs(const std::vector<std::filesystem::path>& outputs);

// Writes `bytes` to `file` through an AtomicFile.
void write_file_atomically(const std::filesystem::path& file, std::string_view bytes);

}  // namespace ct
