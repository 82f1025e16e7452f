#pragma once

#include <CLI/CLI.hpp>

namespace uwscan::app {

// `uwscan bench soak`: `inspect` on the fake camera in profile mode at the seed camera's
// 339 frames/s for N minutes (logged and mapped live): frames lost and skipped, resident memory
// and the latency to the map, minute by minute.
void AddSoakBenchCommand(CLI::App& bench);

}  // namespace uwscan::app
