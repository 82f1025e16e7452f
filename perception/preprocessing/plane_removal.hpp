#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "perception/cloud/point_cloud.hpp"

namespace uwscan::perception {

struct PlaneRemovalOptions {
  double distance_threshold_m = 0.01;  // metres, a point within this of a plane is an inlier; > 0
  // A plane is removed while it holds at least this fraction of the ORIGINAL cloud's points;
  // the search stops at the first plane that holds fewer. In (0, 1].
  double min_fraction = 0.1;
  int max_planes = 10;        // planes removed at most, >= 0
  int max_iterations = 1000;  // RANSAC hypotheses per plane at most, >= 1
  // Stop a plane's search early once a better plane would have been sampled with this
  // probability (Fischler & Bolles 1981, k = log(1 - p) / log(1 - w^3)); in (0, 1).
  double probability = 0.999;
  bool refine = true;      // refit each plane to its inliers by least squares (PCA)
  std::uint64_t seed = 1;  // seeds the std::mt19937_64 that draws the samples
  int threads = 0;         // OpenMP threads, 0 = OpenMP's default; the result does not depend on it

  // Throws uwscan::Error naming the field when it is out of range.
  void Check() const;
};

// A plane n . x + offset_m = 0 in the cloud's frame (absolute coordinates x, metres).
struct DetectedPlane {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // unit
  double offset_m = 0.0;
  std::vector<std::size_t> inliers;  // increasing indices into the input cloud
};

struct PlaneRemovalResult {
  PointCloud remaining;                        // the points of no removed plane
  std::vector<std::size_t> remaining_indices;  // increasing indices into the input cloud
  std::vector<DetectedPlane> planes;           // in the order they were removed
};

// Removes dominant planes one after another with RANSAC (Fischler & Bolles 1981): hypotheses
// from 3 random points of the remaining cloud, the one with most inliers wins (ties: the first
// drawn), optionally refitted, and its inliers are removed while it holds at least
// min_fraction of the original points.
// Deterministic: samples are drawn serially from one std::mt19937_64(seed) and hypotheses are
// scored in fixed batches, so the same input and seed give the same planes for any thread
// count. Terminates on any input: empty, collinear or tiny clouds give no plane.
// Throws uwscan::Error on a non-finite point.
PlaneRemovalResult RemovePlanes(const PointCloud& cloud, const PlaneRemovalOptions& options);

}  // namespace uwscan::perception
