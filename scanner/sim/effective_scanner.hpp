#pragma once

#include <string>

#include "scanner/sim/scene.hpp"

namespace uwscan::scanner::sim {

// The scanner configuration a scene actually simulates: its scanner file with the scene's water
// index in every viewport, index-matched viewports (no bending) when refraction is off and zero
// lens distortion when that stage is off. It is what the dive log stores as the scanner's
// calibration, so that a noise-free dive reconstructs to ground truth.
std::string EffectiveScannerYaml(const Scene& scene);

}  // namespace uwscan::scanner::sim
