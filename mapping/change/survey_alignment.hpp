#pragma once

#include <Eigen/Geometry>
#include <optional>
#include <vector>

#include "mapping/slam/pose_graph.hpp"
#include "perception/cloud/point_cloud.hpp"

namespace uwscan::mapping {

struct SurveyAlignmentOptions {
  // Given: the map is placed by it (T_reference_map) instead of registered as a whole.
  std::optional<Eigen::Isometry3d> T_reference_map;
  // Registration of the whole map onto the reference (point-to-plane ICP from the given
  // transform or the identity: both epochs share the world frame): correspondence distances of
  // its stages, metres, non-increasing, > 0.
  std::vector<double> global_max_correspondence_m = {0.1, 0.04, 0.02, 0.01};
  // Then tile by tile: the map's pose errors change slowly along a dive (the navigation drifts,
  // SLAM pins it where features are seen), so each tile of this size (metres, > 0; 0 = the
  // whole map only) is registered again from the global transform. A change much smaller than
  // a tile barely moves it: its points fall outside the last stage's distance.
  double tile_m = 0.6;
  std::vector<double> tile_max_correspondence_m = {0.04, 0.015, 0.006, 0.003};  // metres, as above
  // The global transform is the tiles' prior: how far a tile may move from it (std, radians
  // and metres, > 0), against the std of one point-to-plane residual (metres, > 0).
  double tile_prior_rotation_rad = 0.01;
  double tile_prior_translation_m = 0.02;
  double tile_point_sigma_m = 0.001;
  int min_tile_points = 200;   // a tile with fewer map points keeps the global transform, >= 3
  double tile_voxel_m = 0.01;  // the tiles are registered voxelised at this size, metres, > 0
  // The whole map is registered voxelised at this size (metres, > 0): coarser than the tiles',
  // since they start from it within their first stage's reach and refine it.
  double global_voxel_m = 0.02;
  void Check() const;
};

// Where the map lies on the reference: one transform for the whole, and one per tile.
struct SurveyAlignment {
  Eigen::Isometry3d T_reference_map = Eigen::Isometry3d::Identity();
  double global_fitness = 0.0;  // share of the map's points paired at the last stage
  double global_rmse_m = 0.0;   // point-to-plane RMS of those pairs, metres
  bool registered = false;      // false: the transform was given
  struct Tile {
    Eigen::Vector3i key = Eigen::Vector3i::Zero();  // floor(p / tile_m) of its points
    Eigen::Isometry3d T_reference_map = Eigen::Isometry3d::Identity();
    // Covariance of the tile's transform, [rotation (rad), translation (m)] about `origin_W`
    // (the rotation turns about that point): the inverse of the registration's information
    // scaled by its residual variance; directions its points do not pin get 0 (they do not move
    // the surface along its normals). Zero for a tile that kept the global transform.
    Matrix6d covariance = Matrix6d::Zero();
    Eigen::Vector3d origin_W = Eigen::Vector3d::Zero();
    bool registered = false;
  };
  double tile_m = 0.0;
  std::vector<Tile> tiles;  // sorted by key
  int tiles_kept_global = 0;

  // The tile map point p_map lies in (nullptr outside every tile).
  const Tile* TileOf(const Eigen::Vector3d& p_map) const;
  // Map point p_map placed on the reference. Each tile's transform holds at its centre; between
  // centres the transforms of the tiles around the point (those that exist) are blended with
  // trilinear weights, so the placement has no step at a tile's border, where two independent
  // registrations meet (a step of a millimetre there would read as a change along the border).
  // The global transform where no tile is near.
  Eigen::Vector3d Place(const Eigen::Vector3d& p_map) const;
  // The standard deviation along normal_W (reference frame) of that placement at q_reference:
  // the blended tiles' registrations are independent, so their variances add with the squared
  // weights.
  double SigmaAlongNormal(const Eigen::Vector3d& p_map, const Eigen::Vector3d& q_reference,
                          const Eigen::Vector3d& normal_W) const;
};

// Registers the map onto the reference (which needs normals). Throws uwscan::Error when the
// options are invalid, the registration pairs less than a tenth of the map's points (the
// clouds do not overlap, or lie farther apart than the first stage's distance: give the
// transform), or a cloud has fewer than 3 points.
SurveyAlignment AlignSurveys(const perception::PointCloud& map,
                             const perception::PointCloud& reference,
                             const SurveyAlignmentOptions& options);

}  // namespace uwscan::mapping
