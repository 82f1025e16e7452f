// Open3D's registration pipeline, a second peer; compiled only when Open3D is present.
#include "bench/registration/registration_pipelines.hpp"

#ifdef UWSCAN_HAVE_OPEN3D
#include <open3d/geometry/KDTreeSearchParam.h>
#include <open3d/geometry/PointCloud.h>
#include <open3d/pipelines/registration/CorrespondenceChecker.h>
#include <open3d/pipelines/registration/Feature.h>
#include <open3d/pipelines/registration/Registration.h>
#include <open3d/utility/Random.h>

#include <chrono>
#endif

#include "scanner/common/error.hpp"

namespace uwscan::bench {

#ifdef UWSCAN_HAVE_OPEN3D
namespace {

namespace reg = open3d::pipelines::registration;
using Clock = std::chrono::steady_clock;

double Since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

struct Prepared {
  std::shared_ptr<open3d::geometry::PointCloud> cloud;
  std::shared_ptr<reg::Feature> features;
};

// Both clouds are expressed about the target's origin, as for the other pipelines.
Prepared Prepare(const perception::PointCloud& cloud, const Eigen::Vector3d& frame_origin,
                 const Eigen::Vector3d& viewpoint, const PipelineParameters& p, PipelineRun* run) {
  open3d::geometry::PointCloud full;
  full.points_.reserve(cloud.size());
  for (size_t i = 0; i < cloud.size(); ++i) full.points_.push_back(cloud.Point(i) - frame_origin);

  Clock::time_point start = Clock::now();
  Prepared out;
  out.cloud = full.VoxelDownSample(p.voxel_m);
  run->stage_seconds["downsample"] += Since(start);

  start = Clock::now();
  out.cloud->EstimateNormals(open3d::geometry::KDTreeSearchParamHybrid(p.normal_radius_m, 30));
  out.cloud->OrientNormalsTowardsCameraLocation(viewpoint - frame_origin);  // as uwscan's
  run->stage_seconds["normals"] += Since(start);

  start = Clock::now();
  out.features = reg::ComputeFPFHFeature(
      *out.cloud, open3d::geometry::KDTreeSearchParamHybrid(p.feature_radius_m, 100));
  run->stage_seconds["features"] += Since(start);
  return out;
}

}  // namespace

bool Open3dAvailable() { return true; }

PipelineRun RunOpen3dPipeline(const RegistrationPair& pair, const PipelineParameters& p) {
  PipelineRun run;
  const Eigen::Vector3d frame = pair.target.origin;
  const Prepared source = Prepare(pair.source, frame, pair.source_viewpoint, p, &run);
  const Prepared target = Prepare(pair.target, frame, pair.target_viewpoint, p, &run);

  open3d::utility::random::Seed(static_cast<int>(p.seed));
  Clock::time_point start = Clock::now();
  const reg::CorrespondenceCheckerBasedOnEdgeLength edge_check(0.9);
  const reg::CorrespondenceCheckerBasedOnDistance distance_check(p.inlier_distance_m);
  const reg::RegistrationResult coarse = reg::RegistrationRANSACBasedOnFeatureMatching(
      *source.cloud, *target.cloud, *source.features, *target.features, true, p.inlier_distance_m,
      reg::TransformationEstimationPointToPoint(false), 3, {edge_check, distance_check},
      reg::RANSACConvergenceCriteria(p.ransac_iterations, 0.999));
  run.stage_seconds["coarse"] += Since(start);

  start = Clock::now();
  const reg::RegistrationResult fine =
      reg::RegistrationICP(*source.cloud, *target.cloud, p.icp_distance_m, coarse.transformation_,
                           reg::TransformationEstimationPointToPoint(false),
                           reg::ICPConvergenceCriteria(1e-10, 1e-10, 50));
  run.stage_seconds["icp"] += Since(start);

  Eigen::Isometry3d shift = Eigen::Isometry3d::Identity();
  shift.translation() = frame;
  run.T_target_source = shift * Eigen::Isometry3d(fine.transformation_) * shift.inverse();
  run.accepted = fine.fitness_ >= 0.1;
  // Stage times only, as for uwscan: conversions into the peer's types are not charged.
  for (const auto& [stage, seconds] : run.stage_seconds) run.seconds += seconds;
  return run;
}

#else

bool Open3dAvailable() { return false; }

PipelineRun RunOpen3dPipeline(const RegistrationPair&, const PipelineParameters&) {
  throw Error("this uwscan was built without Open3D (install libopen3d-dev and rebuild)");
}

#endif

}  // namespace uwscan::bench
