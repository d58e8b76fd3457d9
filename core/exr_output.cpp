// SPDX-License-Identifier: Apache-2.0
#include "core/exr_output.h"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <string>

#include <fmt/format.h>

#include <IexBaseExc.h>
#include <ImfIO.h>
#include <ImfOutputFile.h>
#include <ImfThreading.h>

#include "core/error.h"
#include "core/file_io.h"

namespace ct {
// Not in an anonymous namespace: AtomicExrOutput::File, declared in the header, holds one.
namespace exr_output_detail {

// An OpenEXR output stream on a file descriptor that remembers its first failure: OpenEXR writes the line
// offset table from OutputFile's destructor and swallows errors there, so finish() asks the stream instead.
class DescriptorStream final : public Imf::OStream {
 public:
  DescriptorStream(int fd, const std::string& name) : Imf::OStream(name.c_str()), fd_(fd) {}

  void write(const char c[], int n) override {
    while (n > 0) {
      const ssize_t written = ::write(fd_, c, static_cast<std::size_t>(n));
      if (written < 0 && errno == EINTR) continue;
      if (written == 0) errno = EIO;  // no progress and no reason given
      if (written <= 0) fail("cannot write");
      c += written;
      n -= static_cast<int>(written);
      position_ += static_cast<std::uint64_t>(written);
    }
  }
  uint64_t tellp() override { return position_; }
  void seekp(uint64_t position) override {
    if (::lseek(fd_, static_cast<off_t>(position), SEEK_SET) < 0) fail("cannot seek");
    position_ = position;
  }
  // Empty while every write succeeded.
  const std::string& error() const { return error_; }

 private:
  [[noreturn]] void fail(const char* what) {
    const std::string message = fmt::format("{}: {}", what, std::strerror(errno));
    if (error_.empty()) error_ = message;
    throw Iex::ErrnoExc(message);
  }

  int fd_;
  std::uint64_t position_ = 0;
  std::string error_;
};

}  // namespace exr_output_detail

using exr_output_detail::DescriptorStream;

struct AtomicExrOutput::File {
  explicit File(const std::filesystem::path& target) : output(target) {}
  AtomicFile output;  // declared first: destroyed last, after OpenEXR has let go of the stream
  std::unique_ptr<DescriptorStream> stream;
  std::unique_ptr<Imf::OutputFile> exr;
};

AtomicExrOutput::AtomicExrOutput(const std::filesystem::path& target, const Imf::Header& header) : target_(target) {
  auto file = std::make_unique<File>(target_);
  file->stream = std::make_unique<DescriptorStream>(file->output.descriptor(), file->output.temporary().string());
  try {
    file->exr = std::make_unique<Imf::OutputFile>(*file->stream, header, Imf::globalThreadCount());
  } catch (const std::exception& e) {
    throw std::runtime_error(fmt::format("{}: cannot start writing: {}", target_.string(), one_line(e.what())));
  }
  file_ = std::move(file);
}

AtomicExrOutput::~AtomicExrOutput() = default;

void AtomicExrOutput::write_rows(const Imf::FrameBuffer& frame, int y0, int rows) {
  if (!file_) throw std::logic_error(fmt::format("{}: write_rows after finish", target_.string()));
  try {
    file_->exr->setFrameBuffer(frame);
    file_->exr->writePixels(rows);
  } catch (const std::exception& e) {
    throw std::runtime_error(
        fmt::format("{}: cannot write rows {}-{}: {}", target_.string(), y0, y0 + rows - 1, one_line(e.what())));
  }
}

void AtomicExrOutput::finish() {
  if (!file_) throw std::logic_error(fmt::format("{}: finish called twice", target_.string()));
  file_->exr.reset();  // writes the line offset table
  if (!file_->stream->error().empty())
    throw std::runtime_error(fmt::format("{}: {}", target_.string(), file_->stream->error()));
  file_->output.commit();
  file_.reset();
}

}  // namespace ct
