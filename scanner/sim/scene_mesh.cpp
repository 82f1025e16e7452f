#include "scanner/sim/scene_mesh.hpp"

#include "scanner/sim/imr_objects.hpp"

namespace uwscan::scanner::sim {

TriangleMesh SceneMesh(const Scene& scene, double chord_error_m) {
  TriangleMesh out;
  for (const SceneObject& object : scene.objects) {
    const TriangleMesh sphere = object.shape == ObjectShape::kSphere
                                    ? MakeUvSphere(object.sphere_radius_m, chord_error_m)
                                    : TriangleMesh{};
    const TriangleMesh& mesh = object.shape == ObjectShape::kSphere ? sphere : object.mesh;
    const int first = static_cast<int>(out.vertices.size());
    for (const Eigen::Vector3d& v : mesh.vertices) out.vertices.push_back(object.T_W_O * v);
    for (const Eigen::Vector3i& t : mesh.triangles) out.triangles.push_back(t.array() + first);
  }
  return out;
}

}  // namespace uwscan::scanner::sim
