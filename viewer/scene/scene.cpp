#include "viewer/scene/scene.hpp"

namespace uwscan::viewer {

std::size_t Scene::num_points() const {
  std::size_t n = 0;
  for (const CloudLayer& cloud : clouds) n += cloud.size();
  return n;
}

Eigen::Vector3d Scene::Anchor() const {
  for (const CloudLayer& cloud : clouds) {
    if (!cloud.points.empty()) return cloud.origin;
  }
  for (const MeshLayer& mesh : meshes) {
    if (!mesh.mesh.vertices.empty()) return mesh.T_W_M * mesh.mesh.vertices.front();
  }
  for (const TrajectoryLayer& trajectory : trajectories) {
    if (!trajectory.positions_W.empty()) return trajectory.positions_W.front();
  }
  for (const UncertaintyEllipsoid& e : ellipsoids) return e.centre_W;
  for (const FrameAxes& f : frames) return f.T_W_F.translation();
  for (const Label& l : labels) return l.position_W;
  return Eigen::Vector3d::Zero();
}

}  // namespace uwscan::viewer
