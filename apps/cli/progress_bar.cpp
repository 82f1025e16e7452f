#include "apps/cli/progress_bar.hpp"

#include <unistd.h>

#include <algorithm>
#include <cstdio>

namespace uwscan::app {

ProgressBar::ProgressBar()
    : terminal_(isatty(fileno(stderr)) != 0), exceptions_at_start_(std::uncaught_exceptions()) {}

ProgressBar::~ProgressBar() { Finish(std::uncaught_exceptions() > exceptions_at_start_); }

void ProgressBar::Finish(bool stopped) {
  if (stage_.empty()) return;
  if (terminal_) {
    std::fputs(stopped ? " stopped\n" : "\n", stderr);
  } else {
    std::fprintf(stderr, "  %s: %s\n", stage_.c_str(), stopped ? "stopped" : "done");
  }
  stage_.clear();
  shown_percent_ = -1;
}

void ProgressBar::Update(std::string_view stage, double fraction) {
  if (stage != stage_) {
    Finish();
    stage_ = stage;
    if (!terminal_) std::fprintf(stderr, "  %s ...\n", stage_.c_str());
  }
  const int percent = static_cast<int>(std::clamp(fraction, 0.0, 1.0) * 100.0);
  if (percent == shown_percent_) return;
  shown_percent_ = percent;
  if (!terminal_) return;
  constexpr int kWidth = 30;
  const int filled = percent * kWidth / 100;
  std::fprintf(stderr, "\r  [%.*s%*s] %3d%% %s", filled,
               "==============================", kWidth - filled, "", percent, stage_.c_str());
  std::fflush(stderr);
}

}  // namespace uwscan::app
