#pragma once

#include <CLI/CLI.hpp>

namespace uwscan::app {

// `log check DIVE.db [--json FILE]`: verifies every row's checksums and SQLite's structure.
// `log salvage DAMAGED.db -o GOOD.db [--json FILE]`: copies every intact frame into a new log.
void AddLogCommands(CLI::App& app);

}  // namespace uwscan::app
