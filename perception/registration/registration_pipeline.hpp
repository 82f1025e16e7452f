#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <map>
#include <optional>
#include <string>

#include "perception/cloud/point_cloud.hpp"
#include "perception/registration/coarse_alignment.hpp"
#include "perception/registration/icp.hpp"
#include "perception/registration/registration_result.hpp"

namespace uwscan::perception {

// Coarse-to-fine registration as in seed 000's structure inspection and object pose:
// voxel downsampling, normals, FPFH at every remaining point, RANSAC over FPFH
// correspondences with SVD and edge pre-rejection, then point-to-plane ICP.
struct RegistrationPipelineOptions {
  double voxel_m = 0.01;           // downsampling leaf, metres
  double normal_radius_m = 0.025;  // normal neighbourhood, metres
  double feature_radius_m = 0.05;  // FPFH support, metres
  // Normals of each cloud face its sensor, given in that cloud's own frame (absolute
  // coordinates); a scan file usually holds points in the sensor frame, hence the default.
  Eigen::Vector3d source_viewpoint = Eigen::Vector3d::Zero();
  Eigen::Vector3d target_viewpoint = Eigen::Vector3d::Zero();
  CoarseAlignmentOptions coarse;
  IcpOptions icp;
  int threads = 0;  // OpenMP threads for every stage (overrides coarse.threads, icp.threads)

  // Parameters scaled to an object of the given bounding-box diagonal: voxel = size / 50 (or
  // `voxel_m` when > 0),
  // normals 2.5 voxels, FPFH 5 voxels, RANSAC inliers and ICP 1.5 voxels, then 0.75; a coarse
  // result is accepted from 1 % of the keypoints in agreement (features are computed at every
  // point, so most have no counterpart in a partial view). ICP has converged once a step moves
  // the object's edge by less than 1 % of a voxel along the directions the pairs pin (a pipe's
  // roll and slide left out: IcpOptions::weak_direction_ratio 0.01) or the RMS changes by less
  // than 1e-4 of it.
  static RegistrationPipelineOptions ForObjectSize(double size_m, std::uint64_t seed = 1,
                                                   int threads = 0, double voxel_m = 0.0);
  // The same for two scans of any size, the voxel chosen from the target's own scale: a
  // hundredth of its robust extent (RobustDiagonal), but at most the object rule's size / 50 and
  // at least twice the sparser cloud's point spacing (MedianPointSpacing), so a voxel holds a few
  // points (the floor wins over the cap for a cloud sparser than a fiftieth of its size). A scene
  // is registered at the scale of its parts, not of its extent: two real scans cut in two, a
  // 1.8 m table scene (1.8 mm spacing) and a 12.6 m site (2.6 cm spacing), fail at size / 50
  // (4 cm and 0.65 m voxels) and register at these (1.8 cm and 13 cm; bench/registration/
  // RESULTS.md). Throws uwscan::Error when the target has no extent.
  static RegistrationPipelineOptions ForClouds(const PointCloud& source, const PointCloud& target,
                                               std::uint64_t seed = 1, int threads = 0);
  void Check() const;
};

struct RegistrationPipelineResult {
  RegistrationResult coarse;  // identity with converged = false when an initial guess was given
  RegistrationResult fine;
  std::map<std::string, double> stage_seconds;  // downsample, normals, features, coarse, icp
};

// Aligns source onto target. With `T_target_source_init` the coarse stage is skipped and ICP
// starts there. When the coarse stage fails (not converged) ICP is not run: `fine` is then the
// coarse result, converged = false. Throws uwscan::Error on invalid clouds (empty, NaN; fewer
// than 3 voxels with a surface normal, such as points along a line) or options.
RegistrationPipelineResult RegisterClouds(
    const PointCloud& source, const PointCloud& target, const RegistrationPipelineOptions& options,
    const std::optional<Eigen::Isometry3d>& T_target_source_init = std::nullopt);

}  // namespace uwscan::perception
