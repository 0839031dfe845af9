// Progress bar on stderr for long commands (simulate, identify, report):
// drawn only on a terminal or when forced with --progress, and only once the
// work has taken more than a second, so quick runs print nothing.
#pragma once

#include <chrono>
#include <string>

namespace pneumid::cli {

class ProgressBar {
 public:
  /// `label` starts the line ("simulating", "identify").
  ProgressBar(std::string label, bool enabled);
  /// Draws `fraction` in [0, 1] done, with an optional note (the current step).
  void operator()(double fraction, const std::string& note = "");
  /// Ends the line if anything was drawn.
  ~ProgressBar();
  ProgressBar(const ProgressBar&) = delete;
  ProgressBar& operator=(const ProgressBar&) = delete;

 private:
  using Clock = std::chrono::steady_clock;
  std::string label_;
  bool enabled_;
  bool drawn_ = false;
  Clock::time_point start_;
};

}  // namespace pneumid::cli
