#pragma once

#include <CLI/CLI.hpp>

namespace uwscan::app {

// `uwscan inspect --camera ADDRESS [--log DIVE.db] [--view]`: online inspection: a camera's
// frames logged, mapped live (the newest the mapper keeps up with) and shown.
void AddInspectCommand(CLI::App& app);

}  // namespace uwscan::app
