#include "viewer/scene/surface_error.hpp"

#include <cmath>
#include <exception>
#include <limits>
#include <optional>
#include <string>

#include "scanner/common/error.hpp"

namespace uwscan::viewer {

std::size_t SetSurfaceError(const scanner::sim::RayCaster& truth, double max_distance_m,
                            Scene& scene) {
  if (!(max_distance_m > 0.0 && std::isfinite(max_distance_m))) {
    throw Error("surface error: the search distance must be > 0 m, got " +
                std::to_string(max_distance_m));
  }
  std::size_t filled = 0;
  for (CloudLayer& layer : scene.clouds) {
    if (!layer.error_m.empty()) continue;
    std::vector<float> error(layer.size(), std::numeric_limits<float>::quiet_NaN());
    // Embree's queries are thread-safe; an exception may not leave an OpenMP loop.
    std::exception_ptr failure;
#pragma omp parallel for schedule(dynamic, 4096)
    for (std::ptrdiff_t i = 0; i < static_cast<std::ptrdiff_t>(layer.size()); ++i) {
      try {
        const std::optional<double> d =
            truth.DistanceToSurface(layer.Point(static_cast<std::size_t>(i)), max_distance_m);
        if (d) error[static_cast<std::size_t>(i)] = static_cast<float>(*d);
      } catch (...) {
#pragma omp critical
        if (!failure) failure = std::current_exception();
      }
    }
    if (failure) {
      try {
        std::rethrow_exception(failure);
      } catch (const Error& e) {
        throw Error(layer.name + ": " + e.what());
      }
    }
    layer.error_m = std::move(error);
    ++filled;
  }
  return filled;
}

}  // namespace uwscan::viewer
