#pragma once

#include <CLI/CLI.hpp>

namespace uwscan::app {

// `uwscan bench change`: what the inspection found, against the truth, beside CloudCompare's
// distances and the plain nearest-neighbour distance on the same maps.
void AddChangeBenchCommand(CLI::App& bench);

}  // namespace uwscan::app
