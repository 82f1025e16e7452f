#pragma once

#include "perception/cloud/point_cloud.hpp"

namespace uwscan::perception {

struct VoxelFilterOptions {
  double leaf_m = 0.005;  // metres, edge of the cubic voxels; finite and > 0

  // Throws uwscan::Error naming the field when it is out of range.
  void Check() const;
};

// Voxel-grid downsampling: one point per occupied voxel, at the centroid of the voxel's points.
//
// The grid is anchored in the cloud's frame, not at its origin: voxel (i, j, k) holds the points
// whose absolute coordinates x satisfy floor(x / leaf_m) = (i, j, k), computed in double from
// origin + offset, with 64-bit keys. So a cloud and the same cloud stored about another origin
// fall into the same voxels. Centroids are averaged in double from the float offsets; the result
// keeps the input's origin. Output points are ordered by voxel key (i, then j, then k):
// deterministic and independent of the input order's interleaving within a voxel.
// Normals are not carried over (averaged normals are poor estimates): re-estimate them.
// An empty cloud gives an empty cloud. Throws uwscan::Error on a non-finite point or origin, or
// when |x / leaf_m| reaches 2^62 (the key would overflow).
PointCloud VoxelDownsample(const PointCloud& cloud, const VoxelFilterOptions& options);

}  // namespace uwscan::perception
