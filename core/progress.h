// SPDX-License-Identifier: Apache-2.0
#pragma once
// A progress bar with elapsed time and ETA on stderr, for anything that can take over a second.
//
//   Progress progress("render", total_tiles, !quiet);
//   ... progress.advance();   // from any thread
//
// On a terminal the bar redraws in place at most five times a second; when stderr is not a terminal
// (logs, CI) it prints a line at every 10 %. Disabled, it prints nothing.

#include <atomic>
#include <chrono>
#include <cstddef>
#include <mutex>
#include <string>

namespace ct {

class Progress {
 public:
  Progress(std::string label, std::size_t total, bool enabled);
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  void advance(std::size_t n = 1);
  // Prints the final state (100 % or where it stopped) and a newline; called by the destructor too.
  void finish();
  double elapsed_seconds() const;

 private:
  void draw(std::size_t done, bool final_line);

  std::string label_;
  std::size_t total_;
  bool enabled_;
  bool tty_;
  std::atomic<std::size_t> done_{0};
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point last_draw_;
  int last_decile_ = -1;
  bool finished_ = false;
  std::mutex mutex_;
};

// "1 h 02 min", "3 min 05 s", "12.3 s".
std::string format_duration(double seconds);

}  // namespace ct
