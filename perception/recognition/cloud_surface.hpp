#pragma once

#include <cstdint>

#include "perception/cloud/point_cloud.hpp"
#include "scanner/common/triangle_mesh.hpp"

namespace uwscan::perception {

// How an object taught from a scan (a point cloud, not a mesh) gets a surface.
struct CloudSurfaceOptions {
  // One point per voxel of this edge first (at least a 500th of the bounding box's diagonal),
  // metres, > 0.
  double thinning_m = 0.002;
  // Each point becomes a disc of this many median point spacings in radius: enough to close
  // the gaps between neighbours on the surface, little enough not to widen the silhouette much.
  double disc_radius_spacings = 1.2;
  int normal_neighbours = 16;  // points of each normal's PCA, >= 3
  int directions = 48;  // lines of sight tried to tell a disc's outside from its inside, >= 8
  int threads = 0;      // OpenMP threads, 0 = OpenMP's default; same result for any

  // Throws uwscan::Error naming the field when it is out of range.
  void Check() const;
};

// A surface for an object taught from a scan of it: the cloud's points (thinned) as small discs
// on their tangent planes ("splats"), each wound to face out of the object, as a triangle mesh,
// so that the virtual scanner, the model's surface samples and the visibility tests see the
// scanned surface as they see a CAD mesh's; holes the scan left stay holes. Outside is the more
// open side of each disc, where lines of sight run farther before they meet another disc (the
// file's normals, if any, are not trusted for it: tools orient them every way). Deterministic.
// Throws uwscan::Error when the cloud holds fewer than 20 points or is not finite.
scanner::TriangleMesh CloudSurface(const PointCloud& cloud_m,
                                   const CloudSurfaceOptions& options = {});

}  // namespace uwscan::perception
