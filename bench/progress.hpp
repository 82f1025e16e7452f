#pragma once

#include <functional>
#include <string_view>

namespace uwscan::bench {

// Reports progress of a long run: the stage and the fraction of it done, in [0, 1].
// Libraries never print; the command-line program turns this into a progress bar.
using Progress = std::function<void(std::string_view stage, double fraction)>;

}  // namespace uwscan::bench
