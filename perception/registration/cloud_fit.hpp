#pragma once

#include <Eigen/Geometry>
#include <cstddef>

#include "perception/cloud/point_cloud.hpp"

namespace uwscan::perception {

// How well a source cloud, moved onto a target, lies on it point by point at full resolution.
// ICP's own fitness and RMSE are over the voxelised clouds it aligned, where even an exact copy
// sits up to about half a voxel from the target's points (voxel centroids of different points).
struct CloudFit {
  double fitness = 0.0;        // share of the source points within the distance of a target point
  double inlier_rmse_m = 0.0;  // RMS distance of those to their nearest target point, metres
  std::size_t inliers = 0;
};

// Every point of `source` moved by T_target_source, against its nearest point of `target`,
// counted when within max_distance_m. Throws uwscan::Error on an empty or non-finite cloud or
// a distance that is not > 0.
CloudFit FitOnTarget(const PointCloud& source, const PointCloud& target,
                     const Eigen::Isometry3d& T_target_source, double max_distance_m);

}  // namespace uwscan::perception
