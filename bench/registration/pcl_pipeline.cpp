// PCL's stock registration pipeline, the peer uwscan's pipeline is measured against.
#include <pcl/features/fpfh_omp.h>
#include <pcl/features/normal_3d_omp.h>
#include <pcl/filters/voxel_grid.h>
#include <pcl/registration/icp.h>
#include <pcl/registration/sample_consensus_prerejective.h>

#include <chrono>
#include <cstdlib>

#include "bench/registration/registration_pipelines.hpp"
#include "perception/cloud/pcl_conversion.hpp"

namespace uwscan::bench {
namespace {

using Clock = std::chrono::steady_clock;
using Cloud = pcl::PointCloud<pcl::PointNormal>;
using Features = pcl::PointCloud<pcl::FPFHSignature33>;

double Since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

struct Prepared {
  Cloud::Ptr cloud;
  Features::Ptr features;
};

// Both clouds are expressed about the target's origin so that PCL's float math stays local.
Prepared Prepare(const perception::PointCloud& cloud, const Eigen::Vector3d& frame_origin,
                 const Eigen::Vector3d& viewpoint, const PipelineParameters& p, PipelineRun* run) {
  auto xyz = perception::ToPclXYZ(cloud);
  const Eigen::Vector3d shift = cloud.origin - frame_origin;
  for (pcl::PointXYZ& q : *xyz) {
    q.x += static_cast<float>(shift.x());
    q.y += static_cast<float>(shift.y());
    q.z += static_cast<float>(shift.z());
  }

  Clock::time_point start = Clock::now();
  auto down = pcl::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  pcl::VoxelGrid<pcl::PointXYZ> grid;
  grid.setLeafSize(p.voxel_m, p.voxel_m, p.voxel_m);
  grid.setInputCloud(xyz);
  grid.filter(*down);
  run->stage_seconds["downsample"] += Since(start);

  start = Clock::now();
  Prepared out{pcl::make_shared<Cloud>(), pcl::make_shared<Features>()};
  pcl::copyPointCloud(*down, *out.cloud);
  pcl::NormalEstimationOMP<pcl::PointNormal, pcl::PointNormal> normals(p.threads);
  normals.setRadiusSearch(p.normal_radius_m);
  const Eigen::Vector3d sensor = viewpoint - frame_origin;  // the same viewpoint as uwscan's
  normals.setViewPoint(static_cast<float>(sensor.x()), static_cast<float>(sensor.y()),
                       static_cast<float>(sensor.z()));
  normals.setInputCloud(out.cloud);
  normals.compute(*out.cloud);
  run->stage_seconds["normals"] += Since(start);

  start = Clock::now();
  pcl::FPFHEstimationOMP<pcl::PointNormal, pcl::PointNormal, pcl::FPFHSignature33> fpfh(p.threads);
  fpfh.setRadiusSearch(p.feature_radius_m);
  fpfh.setInputCloud(out.cloud);
  fpfh.setInputNormals(out.cloud);
  fpfh.compute(*out.features);
  run->stage_seconds["features"] += Since(start);
  return out;
}

}  // namespace

PipelineRun RunPclPipeline(const RegistrationPair& pair, const PipelineParameters& p) {
  PipelineRun run;
  const Eigen::Vector3d frame = pair.target.origin;
  const Prepared source = Prepare(pair.source, frame, pair.source_viewpoint, p, &run);
  const Prepared target = Prepare(pair.target, frame, pair.target_viewpoint, p, &run);

  // PCL's RANSAC draws from rand(): seed it so the peer is as repeatable as ours.
  std::srand(static_cast<unsigned>(p.seed));
  Clock::time_point start = Clock::now();
  pcl::SampleConsensusPrerejective<pcl::PointNormal, pcl::PointNormal, pcl::FPFHSignature33> ransac;
  ransac.setInputSource(source.cloud);
  ransac.setSourceFeatures(source.features);
  ransac.setInputTarget(target.cloud);
  ransac.setTargetFeatures(target.features);
  ransac.setMaximumIterations(p.ransac_iterations);
  ransac.setNumberOfSamples(3);
  ransac.setCorrespondenceRandomness(2);
  ransac.setSimilarityThreshold(0.9f);
  ransac.setMaxCorrespondenceDistance(p.inlier_distance_m);
  ransac.setInlierFraction(0.1f);
  Cloud aligned;
  ransac.align(aligned);
  const Eigen::Matrix4f coarse = ransac.getFinalTransformation();
  run.stage_seconds["coarse"] += Since(start);

  start = Clock::now();
  pcl::IterativeClosestPoint<pcl::PointNormal, pcl::PointNormal> icp;
  icp.setInputSource(source.cloud);
  icp.setInputTarget(target.cloud);
  icp.setMaxCorrespondenceDistance(p.icp_distance_m);
  icp.setMaximumIterations(50);
  icp.setTransformationEpsilon(1e-10);
  icp.setEuclideanFitnessEpsilon(1e-12);
  icp.align(aligned, coarse);
  const Eigen::Matrix4d fine = icp.getFinalTransformation().cast<double>();
  run.stage_seconds["icp"] += Since(start);

  // PCL worked in the target's frame shifted to its origin; undo that shift.
  Eigen::Isometry3d shift = Eigen::Isometry3d::Identity();
  shift.translation() = frame;
  run.T_target_source = shift * Eigen::Isometry3d(fine) * shift.inverse();
  run.accepted = ransac.hasConverged() && icp.hasConverged();
  // Stage times only, as for uwscan: conversions into the peer's types are not charged.
  for (const auto& [stage, seconds] : run.stage_seconds) run.seconds += seconds;
  return run;
}

}  // namespace uwscan::bench
