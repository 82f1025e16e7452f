// Open3D's multiway registration as the SLAM benchmark's peer; compiled only with Open3D.
#include "bench/slam/slam_benchmark.hpp"

#ifdef UWSCAN_HAVE_OPEN3D
#include <open3d/geometry/PointCloud.h>
#include <open3d/pipelines/registration/GlobalOptimization.h>
#include <open3d/pipelines/registration/PoseGraph.h>
#include <open3d/pipelines/registration/Registration.h>
#include <open3d/pipelines/registration/TransformationEstimation.h>
#include <open3d/utility/Logging.h>

#include <chrono>
#include <optional>
#include <utility>
#endif

#include "scanner/common/error.hpp"

namespace uwscan::bench {

#ifdef UWSCAN_HAVE_OPEN3D
namespace {

namespace reg = open3d::pipelines::registration;

// The distances of uwscan's own stages, so both pipelines get the same reach.
constexpr double kCoarse_m = 0.04;
constexpr double kFine_m = 0.01;

open3d::geometry::PointCloud ToOpen3d(const perception::PointCloud& cloud) {
  open3d::geometry::PointCloud out;
  out.points_.reserve(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    out.points_.push_back(cloud.Point(i));
    if (cloud.has_normals()) out.normals_.push_back(cloud.normals[i].cast<double>());
  }
  return out;
}

// Point-to-plane ICP of source onto target from T_init (target <- source), coarse then fine.
Eigen::Matrix4d Icp(const open3d::geometry::PointCloud& source,
                    const open3d::geometry::PointCloud& target, const Eigen::Matrix4d& T_init,
                    Eigen::Matrix6d* information) {
  const reg::TransformationEstimationPointToPlane point_to_plane;
  Eigen::Matrix4d T = T_init;
  for (double distance : {kCoarse_m, 0.02, kFine_m}) {
    T = reg::RegistrationICP(source, target, distance, T, point_to_plane,
                             reg::ICPConvergenceCriteria(1e-6, 1e-6, 30))
            .transformation_;
  }
  *information = reg::GetInformationMatrixFromPointClouds(source, target, kFine_m, T);
  return T;
}

// The pairs Open3D registers: each submap with the previous kLocalPairs (consecutive ones are the
// tutorial's certain odometry edges), and with the older submap nearest to it by the navigation
// among those at least kLoopGap back whose clouds overlap: about the pairs uwscan's mapper tries
// with its default options (a local map of 3 merged, one loop candidate per submap, 6 back,
// chosen at its estimated poses within its uncertainty). Every
// overlapping pair, as the tutorial registers, is thousands of ICPs on a dive of
// one-sweep submaps.
constexpr std::size_t kLocalPairs = 3;
constexpr std::size_t kLoopGap = 6;
// uwscan's mapper registers a 15 mm source onto a 5 mm target; Open3D gets the same reach.
constexpr double kSourceVoxel_m = 0.015;

std::vector<std::pair<std::size_t, std::size_t>> Pairs(const std::vector<Eigen::Vector3d>& centres,
                                                       const std::vector<double>& radii) {
  std::vector<std::pair<std::size_t, std::size_t>> pairs;
  for (std::size_t j = 1; j < centres.size(); ++j) {
    for (std::size_t i = j > kLocalPairs ? j - kLocalPairs : 0; i < j; ++i)
      pairs.emplace_back(i, j);
    std::optional<std::size_t> nearest;
    double nearest_m = 0.0;
    for (std::size_t i = 0; i + kLoopGap <= j; ++i) {
      const double d = (centres[i] - centres[j]).norm();
      if (d > 0.6 * (radii[i] + radii[j])) continue;
      if (!nearest || d < nearest_m) nearest = i, nearest_m = d;
    }
    if (nearest) pairs.emplace_back(*nearest, j);
  }
  return pairs;
}

}  // namespace

bool Open3dMultiwayAvailable() { return true; }

std::vector<mapping::TimedPose> Open3dMultiway(const mapping::DiveMapping& m, int threads,
                                               double* seconds) {
  (void)threads;  // Open3D's ICP uses its own OpenMP default
  open3d::utility::SetVerbosityLevel(open3d::utility::VerbosityLevel::Error);
  const auto start = std::chrono::steady_clock::now();
  const std::size_t n = m.submap_clouds.size();
  std::vector<open3d::geometry::PointCloud> targets, sources;
  for (const perception::PointCloud& c : m.submap_clouds) {
    targets.push_back(ToOpen3d(c));
    sources.push_back(*targets.back().VoxelDownSample(kSourceVoxel_m));
  }
  std::vector<Eigen::Vector3d> centres(n);
  std::vector<double> radii(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d c = targets[i].GetCenter();
    centres[i] = m.dead_reckoning[i].T_W_V * c;
    double r = 0.0;
    for (const Eigen::Vector3d& p : targets[i].points_) r = std::max(r, (p - c).norm());
    radii[i] = r;
  }
  reg::PoseGraph graph;
  for (std::size_t i = 0; i < n; ++i) graph.nodes_.emplace_back(m.dead_reckoning[i].T_W_V.matrix());
  // Edges as in Open3D's multiway tutorial: transformation maps the source (i) into the target
  // (j); consecutive pairs are odometry (certain), the others loop candidates (uncertain).
  for (const auto& [i, j] : Pairs(centres, radii)) {
    const Eigen::Matrix4d T_init =
        (m.dead_reckoning[j].T_W_V.inverse() * m.dead_reckoning[i].T_W_V).matrix();
    Eigen::Matrix6d information;
    const Eigen::Matrix4d T = Icp(sources[i], targets[j], T_init, &information);
    graph.edges_.emplace_back(static_cast<int>(i), static_cast<int>(j), T, information, j != i + 1);
  }
  reg::GlobalOptimizationOption option(kFine_m, 0.25, 1.0, 0);
  reg::GlobalOptimization(graph, reg::GlobalOptimizationLevenbergMarquardt(),
                          reg::GlobalOptimizationConvergenceCriteria(), option);
  std::vector<mapping::TimedPose> poses;
  for (std::size_t i = 0; i < n; ++i) {
    Eigen::Isometry3d T(graph.nodes_[i].pose_);
    // Open3D's nodes place their submap in the world, T_W_V as uwscan's.
    poses.push_back({m.slam[i].time_s, T});
  }
  *seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return poses;
}

#else

bool Open3dMultiwayAvailable() { return false; }

std::vector<mapping::TimedPose> Open3dMultiway(const mapping::DiveMapping&, int, double*) {
  throw Error("bench slam: this uwscan was built without Open3D (libopen3d-dev)");
}

#endif

}  // namespace uwscan::bench
