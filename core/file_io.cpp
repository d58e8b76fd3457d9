#include "core/file_io.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <utility>

#include <fmt/core.h>

#include "core/error.h"

namespace ct {

namespace fs = std::filesystem;

std::string read_file(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(fmt::format("{}: cannot open file", file.string()));
  std::ostringstream bytes;
  bytes << in.rdbuf();
  return bytes.str();
}

AtomicFile::AtomicFile(fs::path target) : target_(std::move(target)) {
  const fs::path directory = target_.has_parent_path() ? target_.parent_path() : fs::path(".");
  for (int attempt = 0;; ++attempt) {
    temporary_ = directory / fmt::format(".{}.{}-{}.tmp", target_.filename().string(), static_cast<long>(::getpid()), attempt);
    fd_ = ::open(temporary_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd_ >= 0) return;
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
  std::error_code error;
  fs::rename(temporary_, target_, error);
  if (error)
    throw std::runtime_error(
        fmt::format("{}: cannot rename the finished file into place: {}", target_.string(), error.message()));
  temporary_.clear();
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
