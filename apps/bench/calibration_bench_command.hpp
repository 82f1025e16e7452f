#pragma once

#include <CLI/CLI.hpp>

namespace uwscan::app {

// `bench calibration`: every calibration step on simulated datasets, recovered vs true, and the
// gauges with the estimated calibration vs the true one.
void AddCalibrationBenchCommand(CLI::App& bench);

}  // namespace uwscan::app
