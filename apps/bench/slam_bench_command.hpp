#pragma once

#include <CLI/CLI.hpp>

namespace uwscan::app {

// `uwscan bench slam`: SLAM against dead reckoning and Open3D's multiway registration.
void AddSlamBenchCommand(CLI::App& bench);

}  // namespace uwscan::app
