#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "perception/cloud/point_cloud.hpp"

namespace uwscan::mapping {

// A few consecutive sweeps, placed with the navigation, in the frame of the vehicle at the
// submap's anchor frame {V_k} (the middle frame): small float offsets from origin 0.
struct Submap {
  int index = 0;
  std::int64_t anchor_frame = 0;  // its time and navigation pose anchor the submap
  double anchor_time_s = 0.0;
  Eigen::Isometry3d T_W_V_nav = Eigen::Isometry3d::Identity();  // navigation at the anchor
  std::int64_t first_frame = 0;
  std::int64_t last_frame = 0;
  double start_s = 0.0;  // first and last frame times
  double end_s = 0.0;
  Eigen::Isometry3d T_W_V_start = Eigen::Isometry3d::Identity();  // navigation at the first frame
  Eigen::Isometry3d T_W_V_end = Eigen::Isometry3d::Identity();    // and at the last
  // Built by BuildSubmapClouds; a Mapper keeps them in its SubmapStore (Mapper::submap_clouds),
  // so the Submaps it hands out have them empty.
  perception::PointCloud cloud;   // voxelised at the map voxel, with normals (ICP target)
  perception::PointCloud sparse;  // voxelised at the registration voxel (ICP source)
  Eigen::Vector3d centroid_V = Eigen::Vector3d::Zero();  // of the cloud, in {V_k}
  double radius_m = 0.0;      // largest distance of a point from the centroid
  double rms_radius_m = 0.0;  // root mean square distance of the points from the centroid
  // Directions the cloud's own surface pins (SurfaceDirections), set by the Mapper: a submap
  // that pins two fewer than a loop must is not tried for loops.
  int surface_directions = 6;
};

struct SubmapCloudOptions {
  double map_voxel_m = 0.005;                             // > 0
  double registration_voxel_m = 0.015;                    // > 0
  int normal_neighbours = 15;                             // >= 3
  Eigen::Vector3d viewpoint_V = Eigen::Vector3d::Zero();  // normals face it (the camera)
  int threads = 0;
  void Check() const;
};

// Fills cloud, sparse, centroid and radius of `submap` from its points in {V_k} (double).
// Points whose normal is undefined (isolated) are left out of the cloud. Leaves the cloud
// empty when fewer than 10 points remain.
void BuildSubmapClouds(const std::vector<Eigen::Vector3d>& points_V,
                       const SubmapCloudOptions& options, Submap* submap);

// The clouds placed in the world by their poses (T_W_cloud, one per cloud) and voxelised at
// voxel_m into one cloud, its origin at the first pose's position (normals dropped).
perception::PointCloud MergeClouds(const std::vector<const perception::PointCloud*>& clouds,
                                   const std::vector<Eigen::Isometry3d>& T_W_cloud, double voxel_m);

}  // namespace uwscan::mapping
