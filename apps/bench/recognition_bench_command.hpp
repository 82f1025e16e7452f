#pragma once

#include <CLI/CLI.hpp>

namespace uwscan::app {

// `uwscan bench recognition [--scans N] [--json FILE]`: uwscan's recogniser beside PCL's
// global ESF pipeline and OpenCV's PPF on the same simulated scans and segments.
void AddRecognitionBenchCommand(CLI::App& bench);

}  // namespace uwscan::app
