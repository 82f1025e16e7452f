#pragma once

#include "scanner/common/triangle_mesh.hpp"
#include "scanner/sim/scene.hpp"

namespace uwscan::scanner::sim {

// Every object of a scene as one triangle mesh in the world frame, metres: the structure as
// built, a design model to compare surveys against. Spheres are tessellated (chords at most
// chord_error_m off the true surface, > 0).
TriangleMesh SceneMesh(const Scene& scene, double chord_error_m = 1e-4);

}  // namespace uwscan::scanner::sim
