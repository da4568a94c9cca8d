// Progress reporting on stderr for long commands (batch conversion, captures).
//
// On a terminal it redraws one line: a bar, done/total, rate and ETA. When stderr is not a
// terminal (CI logs, pipes) it prints one plain line per completed item instead, so logs stay
// readable. Thread-safe: batch workers call Advance() concurrently.
#pragma once

#include <chrono>
#include <cstddef>
#include <mutex>
#include <string>

namespace brdf::cli {

class Progress {
 public:
  Progress(std::string label, std::size_t total, bool enabled = true);
  ~Progress();

  // Marks one item done; `item` names it in non-terminal output, `failed` counts it as failed.
  void Advance(const std::string& item, bool failed = false);
  // `count` items that will not be done after all (e.g. the other models of an input that
  // failed): the total shrinks, nothing is printed.
  void Drop(std::size_t count);
  // Prints a message above the bar without breaking it.
  void Message(const std::string& text);
  void Finish();

  static std::string FormatDuration(double seconds);

 private:
  void DrawLocked();
  std::mutex mutex_;
  std::string label_;
  std::size_t total_, done_ = 0, failed_ = 0;
  bool enabled_, tty_, finished_ = false;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace brdf::cli
