#pragma once

#include <cstddef>

#include "scanner/sim/ray_caster.hpp"
#include "viewer/scene/scene.hpp"

// Clouds coloured by how far they lie from a simulated scene's true surfaces: a map, or any cloud
// in the scene's world frame, against the objects it was simulated from.
namespace uwscan::viewer {

// Fills `error_m` of every cloud layer of `scene` that has none with each point's distance to
// the nearest surface of `truth`, NaN (no value) where none lies within max_distance_m (> 0).
// Layers that already carry an error (a dive log's own, point by point) keep it. Returns how many
// layers were filled. Throws uwscan::Error when max_distance_m is not > 0 or a point is not finite.
std::size_t SetSurfaceError(const scanner::sim::RayCaster& truth, double max_distance_m,
                            Scene& scene);

}  // namespace uwscan::viewer
