#pragma once

#include "scanner/lasers/scanner.hpp"
#include "scanner/sim/scene.hpp"

namespace uwscan::scanner::sim {

// The scanner a scene actually simulates: its scanner with the scene's water index in every
// viewport, index-matched viewports (no bending) when refraction is off and zero lens
// distortion when that stage is off; a MEMS scanner's fitted projection functions are fitted
// again to the laser so changed. It is what the dive log stores as the scanner's calibration,
// so that a noise-free dive reconstructs to ground truth.
Scanner EffectiveScanner(const Scene& scene);

}  // namespace uwscan::scanner::sim
