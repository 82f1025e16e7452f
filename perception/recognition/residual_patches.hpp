#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "perception/cloud/point_cloud.hpp"

namespace uwscan::perception {

class NearestGrid;

// How a point-to-plane fit's gradient spreads over patches of the surface: the sum over cubic
// cells of side patch_m of g g^T, g = sum over the cell's pairs of J^T r, J = [(x - c) x n, n]
// and r = n . (x - q) for each source point x (moved by T_target_source) and its nearest target
// point q with normal n within max_distance_m. Ordered [w, v] about centre_target like the ICP's
// information H. At the fit's optimum the g sum to zero; their spread is what the residuals
// push the pose by, patch against patch. H^-1 S H^-1 is the pose covariance when residuals are
// correlated within a patch (a misfit over a bolt head, a facet, a surface the model lacks) and
// independent between patches, where sigma^2 H^-1 assumes every point independent.
// `target` needs normals; `grid` is the NearestGrid of target's points relative to its origin.
Eigen::Matrix<double, 6, 6> ResidualPatchSpread(const PointCloud& source,
                                                const Eigen::Isometry3d& T_target_source,
                                                const PointCloud& target, const NearestGrid& grid,
                                                double max_distance_m,
                                                const Eigen::Vector3d& centre_target,
                                                double patch_m);

}  // namespace uwscan::perception
