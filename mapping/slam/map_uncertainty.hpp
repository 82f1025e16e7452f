#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <vector>

#include "mapping/slam/pose_graph.hpp"
#include "perception/cloud/point_cloud.hpp"

namespace uwscan::mapping {

// How far a map's points are expected to lie off the true surfaces from the uncertainty of the
// poses that placed them alone: for each point, the standard deviation along its normal of its
// displacement under its submap pose's covariance ([rotation, position] in the world,
// pose_graph.hpp: the rotation turns about the pose's position), combined as an RMS over the
// points. With a consistent covariance this is what the map's distance to the true surfaces
// should come to, above the sensor's own error: the navigation and the scene's information
// allow no better. Every `stride`-th point of each cloud is used (clouds need normals).
// Throws uwscan::Error when the sizes differ, a cloud has no normals, or stride is 0.
double ExpectedSurfaceErrorRms(const std::vector<const perception::PointCloud*>& clouds_V,
                               const std::vector<Eigen::Isometry3d>& T_W_V,
                               const std::vector<Matrix6d>& covariances, std::size_t stride = 1);

// The same, one submap at a time (a long dive's submaps read back one by one): Add each cloud
// with its pose and covariance, then Rms().
class ExpectedSurfaceError {
 public:
  explicit ExpectedSurfaceError(std::size_t stride);  // stride > 0
  // `submap` names the cloud in errors (it needs normals when it has points).
  void Add(const perception::PointCloud& cloud_V, const Eigen::Isometry3d& T_W_V,
           const Matrix6d& covariance, std::size_t submap);
  double Rms() const;

 private:
  std::size_t stride_;
  double sum_ = 0.0;
  std::size_t count_ = 0;
};

// How far the poses are expected to lie from the true ones from their covariance alone: the
// square root of the mean over the poses of their position variance (the trace of the position
// block of each [rotation, position] covariance). With a consistent covariance this is what the
// ATE (RMS position error, no alignment) should come to: the navigation and the scene's
// information allow no better. Throws uwscan::Error when `covariances` is empty or a position
// variance is negative or not finite.
double ExpectedPositionErrorRms(const std::vector<Matrix6d>& covariances);

}  // namespace uwscan::mapping
