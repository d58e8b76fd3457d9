// SPDX-License-Identifier: Apache-2.0
#pragma once
// One atomic OpenEXR output for every writer of the project (the spectral writer, the camera's): scanlines go
// to a temporary file beside the target, finish() completes the file and renames it into place, and an
// output destroyed before finish() removes it. Every failure, OpenEXR's included, is one line naming the file.

#include <filesystem>
#include <memory>

#include <ImfFrameBuffer.h>
#include <ImfHeader.h>

namespace ct {

class AtomicExrOutput {
 public:
  // Creates the temporary file and starts the file with `header` (a runtime_error naming the target if
  // OpenEXR refuses it; an InputError when no file can be created there).
  AtomicExrOutput(const std::filesystem::path& target, const Imf::Header& header);
  ~AtomicExrOutput();
  AtomicExrOutput(const AtomicExrOutput&) = delete;
  AtomicExrOutput& operator=(const AtomicExrOutput&) = delete;

  // Writes `rows` scanlines from `frame`, starting at the next unwritten one, y0.
  void write_rows(const Imf::FrameBuffer& frame, int y0, int rows);
  // Completes the file (OpenEXR writes its line offset table now) and renames it into place.
  void finish();

 private:
  struct File;
  std::filesystem::path target_;
  std::unique_ptr<File> file_;
};

}  // namespace ct
