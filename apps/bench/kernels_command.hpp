#pragma once

#include <CLI/CLI.hpp>

namespace uwscan::app {

// `uwscan bench kernels`: a fixed, small amount of work for each hot kernel (the default stripe
// detector on rendered frames; ray-plane, ray-cone and ray-ray on the same stripe pixels), run
// once each, for bench/instructions.sh to count under callgrind: instructions per frame and per
// point do not move with the machine's load, so two versions of the code compare exactly.
void AddKernelsCommand(CLI::App& bench);

}  // namespace uwscan::app
