#include "scanner/sim/effective_scanner.hpp"

namespace uwscan::scanner::sim {
namespace {

void Immerse(const Scene& scene, FlatViewport* viewport) {
  if (scene.effects.refraction) {
    viewport->n_water = scene.water.refractive_index;
  } else {
    viewport->n_glass = viewport->n_air;
    viewport->n_water = viewport->n_air;
  }
}

}  // namespace

Scanner EffectiveScanner(const Scene& scene) {
  Scanner scanner = scene.scanner.model;
  Immerse(scene, &scanner.camera().viewport);
  Immerse(scene, &scanner.laser_viewport());
  if (!scene.effects.lens_distortion) {
    PinholeCamera& c = scanner.camera().camera;
    c.k1 = c.k2 = c.p1 = c.p2 = c.k3 = 0.0;
  }
  RefitSampledFunctions(&scanner);
  return scanner;
}

}  // namespace uwscan::scanner::sim
