#pragma once

#include <CLI/CLI.hpp>

namespace uwscan::app {

// `uwscan make-object SHAPE -o FILE.ply [dimensions]`: writes one procedurally generated IMR
// object (scanner/sim/imr_objects.hpp) as a binary PLY mesh in its own frame.
void AddMakeObjectCommand(CLI::App& app);

}  // namespace uwscan::app
