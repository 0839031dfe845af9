#include "progress.hpp"

#include <algorithm>
#include <cstdio>

#include <fmt/format.h>

namespace pneumid::cli {

ProgressBar::ProgressBar(std::string label, bool enabled)
    : label_(std::move(label)), enabled_(enabled), start_(Clock::now()) {}

void ProgressBar::operator()(double fraction, const std::string& note) {
  if (!enabled_) return;
  const double elapsed = std::chrono::duration<double>(Clock::now() - start_).count();
  if (elapsed < 1.0 && !drawn_) return;
  const int width = 40;
  const int filled = static_cast<int>(std::clamp(fraction, 0.0, 1.0) * width);
  const std::string line =
      fmt::format("\r{} [{}{}] {:3.0f}% {:.1f} s {:<16}", label_, std::string(filled, '#'),
                  std::string(width - filled, ' '), 100.0 * fraction, elapsed, note);
  std::fputs(line.c_str(), stderr);
  std::fflush(stderr);
  drawn_ = true;
}

ProgressBar::~ProgressBar() {
  if (drawn_) std::fputs("\n", stderr);
}

}  // namespace pneumid::cli
