#include "scanner/triangulation/triangulator.hpp"

namespace uwscan::scanner {

const char* ToString(TriangulationMethod method) {
  switch (method) {
    case TriangulationMethod::kRayPlane:
      return "ray_plane";
    case TriangulationMethod::kRayCone:
      return "ray_cone";
    case TriangulationMethod::kRayRay:
      return "ray_ray";
  }
  return "unknown";
}

std::optional<TriangulationMethod> ParseTriangulationMethod(const std::string& name) {
  if (name == "plane" || name == "ray_plane") return TriangulationMethod::kRayPlane;
  if (name == "cone" || name == "ray_cone") return TriangulationMethod::kRayCone;
  if (name == "ray" || name == "ray_ray") return TriangulationMethod::kRayRay;
  return std::nullopt;
}

}  // namespace uwscan::scanner
