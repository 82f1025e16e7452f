#pragma once

#include <CLI/CLI.hpp>

namespace uwscan::app {

// `uwscan fake-camera SCENE.yaml`: the simulator's frames served as a GigE Vision camera.
void AddFakeCameraCommand(CLI::App& app);
// `uwscan acquire --camera ADDRESS -o DIVE.db`: a camera's frames recorded into a dive log.
void AddAcquireCommand(CLI::App& app);

}  // namespace uwscan::app
