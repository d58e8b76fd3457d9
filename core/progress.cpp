// SPDX-License-Identifier: Apache-2.0
#include "core/progress.h"

#include <unistd.h>

#include <cmath>
#include <cstdio>

#include <fmt/core.h>

namespace ct {

std::string format_duration(double s) {
  if (s < 60.0) return fmt::format("{:.1f} s", s);
  const long total = std::lround(s);
  if (total < 3600) return fmt::format("{} min {:02} s", total / 60, total % 60);
  return fmt::format("{} h {:02} min", total / 3600, (total % 3600) / 60);
}

Progress::Progress(std::string label, std::size_t total, bool enabled)
    : label_(std::move(label)),
      total_(total),
      enabled_(enabled),
      tty_(isatty(STDERR_FILENO) != 0),
      start_(std::chrono::steady_clock::now()),
      last_draw_(start_) {}

Progress::~Progress() { finish(); }

double Progress::elapsed_seconds() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

void Progress::advance(std::size_t n) {
  const std::size_t done = done_.fetch_add(n) + n;
  if (!enabled_) return;
  std::lock_guard<std::mutex> lock(mutex_);
  if (finished_) return;
  const auto now = std::chrono::steady_clock::now();
  if (tty_) {
    if (now - last_draw_ < std::chrono::milliseconds(200)) return;
  } else {
    const int decile = total_ ? static_cast<int>(10 * done / total_) : 10;
    if (decile == last_decile_ || decile >= 10) return;
    last_decile_ = decile;
  }
  last_draw_ = now;
  draw(done, false);
}

void Progress::finish() {
  if (!enabled_) return;
  std::lock_guard<std::mutex> lock(mutex_);
  if (finished_) return;
  finished_ = true;
  draw(done_.load(), true);
}

void Progress::draw(std::size_t done, bool final_line) {
  const double fraction = total_ ? std::min(1.0, static_cast<double>(done) / static_cast<double>(total_)) : 1.0;
  const double elapsed = elapsed_seconds();
  std::string eta;
  // An estimate from the first few per cent (one tile, one step of several) says more of that step than of the rest.
  constexpr double kEtaFrom = 0.05;
  if (!final_line && fraction >= kEtaFrom) eta = ", ETA " + format_duration(elapsed * (1.0 - fraction) / fraction);
  constexpr int kWidth = 30;
  const int filled = static_cast<int>(fraction * kWidth);
  const std::string bar = std::string(filled, '#') + std::string(kWidth - filled, '.');
  fmt::print(stderr, "{}{} [{}] {:3.0f}%  {}{}{}", tty_ ? "\r" : "", label_, bar, 100.0 * fraction,
             format_duration(elapsed), eta, (tty_ && !final_line) ? "   " : "\n");
  std::fflush(stderr);
}

}  // namespace ct
