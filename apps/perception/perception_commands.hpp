#pragma once

#include <CLI/CLI.hpp>

namespace uwscan::app {

// `uwscan register SOURCE TARGET`.
void AddRegisterCommand(CLI::App& app);
// `bench registration` and `bench features` under `bench`.
void AddPerceptionBenchCommands(CLI::App& bench);

}  // namespace uwscan::app
