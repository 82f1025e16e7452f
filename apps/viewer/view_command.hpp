#pragma once

#include <CLI/CLI.hpp>

namespace uwscan::app {

// `view FILE...`: clouds, meshes, trajectories, dive logs and map reports in one window, or in
// one PNG with --screenshot; `view DIVE.db --follow` shows a log while it is being written.
void AddViewCommand(CLI::App& app);

}  // namespace uwscan::app
