// SPDX-License-Identifier: Apache-2.0
#pragma once
// Image libraries that print their own lines to stderr, kept quiet so that every error is one line of chromatrace's.

namespace ct {

// While one exists, what is written to stderr (file descriptor 2) is dropped: held around calls into image
// libraries that print their own lines (libpng's default error handler, which OpenImageIO's PNG reader keeps,
// prints "libpng error: …" before OpenImageIO reports the same error to the caller). Nested and concurrent uses
// share one redirection.
class LibraryStderrSilenced {
 public:
  LibraryStderrSilenced();
  ~LibraryStderrSilenced();
  LibraryStderrSilenced(const LibraryStderrSilenced&) = delete;
  LibraryStderrSilenced& operator=(const LibraryStderrSilenced&) = delete;
};

}  // namespace ct
