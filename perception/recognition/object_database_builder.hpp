#pragma once

#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include "perception/recognition/object_catalogue.hpp"
#include "perception/recognition/object_database.hpp"
#include "scanner/sim/virtual_scanner.hpp"

namespace uwscan::perception {

struct DatabaseBuildOptions {
  int views = 48;  // views per object, over the whole sphere of directions, >= 1
  // Stand-offs of the camera from the object's centre, metres, used in turn from view to view
  // (point density changes with range); non-empty, each > 0.
  std::vector<double> standoffs_m = {0.6, 1.0, 1.4};
  ObjectDatabaseParameters parameters;
  std::uint64_t seed = 1;  // scan noise and ESF sampling
  int threads = 0;         // OpenMP threads over views, 0 = OpenMP's default; same result for any
  void Check() const;      // throws uwscan::Error naming the field
};

// The ESF of a cloud as recognition computes it for both views and scan segments: voxelised at
// voxel_m first, so that the descriptor sees the same density whatever the range. `threads` as
// EsfOptions::threads.
EsfResult VoxelisedEsf(const PointCloud& cloud, double voxel_m, std::uint64_t seed, int threads);

// Each object scanned by the virtual scanner from `views` directions (views with fewer than
// 50 points are dropped: the object fell outside the sweep), its model cloud with normals and
// FPFH, diameter, symmetries (declared or detected) and grasp frames. `progress` receives the
// fraction done. Throws uwscan::Error on invalid options, duplicate ids, or an object no view
// sees.
ObjectDatabase BuildObjectDatabase(std::span<const ObjectSource> objects,
                                   const scanner::sim::VirtualScanner& scanner,
                                   const DatabaseBuildOptions& options,
                                   const std::function<void(double)>& progress = {});

// The camera pose of view `index` of `count` around a point (object frame), at `standoff_m`.
Eigen::Isometry3d ViewPose(int index, int count, const Eigen::Vector3d& centre_O,
                           double standoff_m);

}  // namespace uwscan::perception
