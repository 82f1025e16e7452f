#pragma once

#include <Eigen/Geometry>
#include <vector>

#include "perception/cloud/point_cloud.hpp"
#include "perception/preprocessing/voxel_index.hpp"

namespace uwscan::perception {

// VoxelDownsample one cloud at a time: clouds moved into a common frame are added as they come
// and only each voxel's sum and count are kept, so the memory is the voxels' (the area mapped),
// not the points' (a long dive's revisits). Cloud() gives the same bits as VoxelDownsample of all
// the added points (moved to float about `origin`, in the order added) would.
class VoxelAccumulator {
 public:
  // leaf_m > 0; origin: the merged cloud's, which its float points are relative to.
  VoxelAccumulator(double leaf_m, const Eigen::Vector3d& origin);
  // Adds `cloud`'s points moved by T (into the merged frame). Throws uwscan::Error on a
  // non-finite point or one whose voxel key overflows (as VoxelDownsample).
  void Add(const PointCloud& cloud, const Eigen::Isometry3d& T);
  // Each voxel's centroid, in VoxelDownsample's order (by voxel key), normals dropped.
  PointCloud Cloud() const;
  std::size_t voxel_count() const { return voxels_.size(); }

 private:
  struct Sum {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    std::int64_t count = 0;
  };
  double leaf_m_;
  Eigen::Vector3d origin_;
  VoxelIndex voxels_;
  std::vector<Sum> sums_;  // by voxel id
};

}  // namespace uwscan::perception
