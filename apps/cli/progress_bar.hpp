#pragma once

#include <exception>
#include <string>
#include <string_view>

#include "bench/progress.hpp"

namespace uwscan::app {

// A one-line progress bar on stderr. On a terminal it redraws in place; otherwise it prints a
// line when a stage starts and when it ends, so logs stay readable. A stage the bar is destroyed
// in while an exception leaves the command ends "stopped", not "done": the error follows.
class ProgressBar {
 public:
  ProgressBar();
  ~ProgressBar();
  void Update(std::string_view stage, double fraction);
  bench::Progress Callback() {
    return [this](std::string_view stage, double fraction) { Update(stage, fraction); };
  }

 private:
  void Finish(bool stopped = false);
  bool terminal_;
  int exceptions_at_start_;  // std::uncaught_exceptions() when made
  std::string stage_;
  int shown_percent_ = -1;
};

}  // namespace uwscan::app
