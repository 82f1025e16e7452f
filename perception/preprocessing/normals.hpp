#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <vector>

#include "perception/cloud/point_cloud.hpp"

namespace uwscan::perception {

struct NormalOptions {
  int k = 20;           // neighbours (the point itself included) when radius_m == 0; >= 3
  double radius_m = 0;  // metres; > 0 uses every point within this radius instead of k nearest
  // Metres; > 0 searches the k nearest cell by cell on a grid of this cell (KnnGrid), fastest at
  // about the k-th neighbour's distance (a cloud voxelised at v, k = 15: 3 v); 0 on FLANN's
  // kd-tree. The same neighbours either way, but for which of points tied in distance is taken.
  double knn_cell_m = 0;
  // Normals are flipped to face this point, metres, absolute in the cloud's frame (the scanner's
  // position for a single scan).
  Eigen::Vector3d viewpoint = Eigen::Vector3d::Zero();
  int threads = 0;  // OpenMP threads, 0 = OpenMP's default; the result does not depend on it

  // Throws uwscan::Error naming the field when it is out of range.
  void Check() const;
};

// Per-point normals and surface variation, aligned with the input cloud's points.
struct NormalsResult {
  // Unit normals facing the viewpoint (n . (viewpoint - p) >= 0). NaN where the neighbourhood
  // defines no plane: fewer than 3 points, or (nearly) collinear (second eigenvalue below 1e-6
  // of the largest).
  std::vector<Eigen::Vector3f> normals;
  // Surface variation l0 / (l0 + l1 + l2) of the neighbourhood covariance, eigenvalues
  // l0 <= l1 <= l2 (Pauly et al. 2002): 0 on a plane, 1/3 at most (isotropic); NaN where the
  // normal is NaN.
  std::vector<float> curvatures;
  std::size_t num_invalid = 0;  // points with a NaN normal
};

// Normal estimation by principal component analysis of each point's neighbourhood (k nearest
// or fixed radius), in parallel with OpenMP. The covariance is accumulated in double about the
// point, so clouds far from the origin or finely sampled keep their accuracy.
// An empty cloud gives an empty result. Throws uwscan::Error on a non-finite point, or (radius
// mode) when the cloud spans more than 2^21 radii along an axis.
NormalsResult EstimateNormals(const PointCloud& cloud, const NormalOptions& options);

// A cloud carrying its normals, built from the points whose normal is valid.
struct CloudWithNormals {
  PointCloud cloud;                         // the valid points, normals attached
  std::vector<float> curvatures;            // aligned with cloud.points
  std::vector<std::size_t> source_indices;  // index in the input cloud of each kept point
};

// Attaches `normals` (from EstimateNormals on `cloud`) to the points whose normal is valid,
// dropping the others. Throws uwscan::Error when the sizes differ.
CloudWithNormals AttachNormals(const PointCloud& cloud, const NormalsResult& normals);

}  // namespace uwscan::perception
