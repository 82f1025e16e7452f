#pragma once

#include <string>
#include <string_view>

#include "bench/progress.hpp"

namespace uwscan::app {

// A one-line progress bar on stderr. On a terminal it redraws in place; otherwise it prints a
// line when a stage starts and when it ends, so logs stay readable.
class ProgressBar {
 public:
  ProgressBar();
  ~ProgressBar();
  void Update(std::string_view stage, double fraction);
  bench::Progress Callback() {
    return [this](std::string_view stage, double fraction) { Update(stage, fraction); };
  }

 private:
  void Finish();
  bool terminal_;
  std::string stage_;
  int shown_percent_ = -1;
};

}  // namespace uwscan::app
