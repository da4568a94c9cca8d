#include "progress.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>

namespace brdf::cli {

Progress::Progress(std::string label, std::size_t total, bool enabled)
    : label_(std::move(label)),
      total_(total),
      enabled_(enabled),
      tty_(::isatty(STDERR_FILENO) != 0),
      start_(std::chrono::steady_clock::now()) {
  std::lock_guard lock(mutex_);
  if (enabled_ && tty_) DrawLocked();
}

Progress::~Progress() { Finish(); }

std::string Progress::FormatDuration(double seconds) {
  if (!(seconds >= 0)) seconds = 0;
  const long s = static_cast<long>(seconds + 0.5);
  char buf[32];
  if (s >= 3600)
    std::snprintf(buf, sizeof buf, "%ldh%02ldm", s / 3600, (s / 60) % 60);
  else if (s >= 60)
    std::snprintf(buf, sizeof buf, "%ldm%02lds", s / 60, s % 60);
  else
    std::snprintf(buf, sizeof buf, "%.1fs", seconds);
  return buf;
}

void Progress::DrawLocked() {
  const double elapsed =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  const double fraction =
      total_ == 0 ? 1.0 : static_cast<double>(done_) / static_cast<double>(total_);
  constexpr int kWidth = 30;
  const int filled = static_cast<int>(fraction * kWidth);
  std::string bar(static_cast<std::size_t>(filled), '#');
  bar.resize(kWidth, '.');
  const double eta =
      done_ == 0 ? 0.0 : elapsed / static_cast<double>(done_) * static_cast<double>(total_ - done_);
  std::fprintf(stderr, "\r%s [%s] %zu/%zu%s  elapsed %s  ETA %s   ", label_.c_str(), bar.c_str(),
               done_, total_, failed_ ? (" (" + std::to_string(failed_) + " failed)").c_str() : "",
               FormatDuration(elapsed).c_str(), done_ == 0 ? "--" : FormatDuration(eta).c_str());
  std::fflush(stderr);
}

void Progress::Advance(const std::string& item, bool failed) {
  std::lock_guard lock(mutex_);
  ++done_;
  if (failed) ++failed_;
  if (!enabled_) return;
  if (tty_) {
    DrawLocked();
  } else {
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    const double eta = elapsed / static_cast<double>(done_) * static_cast<double>(total_ - done_);
    std::fprintf(stderr, "%s %zu/%zu %s%s (elapsed %s, ETA %s)\n", label_.c_str(), done_, total_,
                 item.c_str(), failed ? " FAILED" : "", FormatDuration(elapsed).c_str(),
                 FormatDuration(eta).c_str());
  }
}

void Progress::Drop(std::size_t count) {
  std::lock_guard lock(mutex_);
  total_ -= std::min(count, total_ - done_);
  if (enabled_ && tty_) DrawLocked();
}

void Progress::Message(const std::string& text) {
  std::lock_guard lock(mutex_);
  if (tty_ && enabled_) std::fprintf(stderr, "\r\033[K");
  std::fprintf(stderr, "%s\n", text.c_str());
  if (tty_ && enabled_ && !finished_) DrawLocked();
}

void Progress::Finish() {
  std::lock_guard lock(mutex_);
  if (finished_) return;
  finished_ = true;
  if (enabled_ && tty_) {
    DrawLocked();
    std::fprintf(stderr, "\n");
  }
}

}  // namespace brdf::cli
