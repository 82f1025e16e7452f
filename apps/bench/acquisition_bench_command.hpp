#pragma once

#include <CLI/CLI.hpp>

namespace uwscan::app {

// `uwscan bench acquisition`: the camera path's throughput on loopback, with Aravis's own
// arv-camera-test-0.8 as the peer on the same fake camera.
void AddAcquisitionBenchCommand(CLI::App& bench);

}  // namespace uwscan::app
