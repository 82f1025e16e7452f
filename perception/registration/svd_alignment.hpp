#pragma once

#include <Eigen/Geometry>
#include <span>

namespace uwscan::perception {

enum class SvdAlignmentStatus {
  kSuccess,    // the least-squares rigid transform is unique
  kDegenerate  // fewer than 3 pairs of positive weight, or points spanning less than a plane
};

struct SvdAlignment {
  Eigen::Isometry3d T_target_source = Eigen::Isometry3d::Identity();  // identity when degenerate
  SvdAlignmentStatus status = SvdAlignmentStatus::kDegenerate;
  double rmse_m = 0.0;  // weighted root mean square of |T_target_source * s_i - t_i|, metres
};

// The rigid transform T (a proper rotation, det R = +1, and a translation) minimising
// sum_i w_i |T s_i - t_i|^2 over corresponding points, by the closed form of Arun et al. 1987,
// Besl & McKay 1992 and Umeyama 1991 (without scale): with weighted centroids s0, t0 and the
// centred cross-covariance H = sum_i w_i (s_i - s0)(t_i - t0)^T = U S V^T,
//   R = V diag(1, 1, d) U^T, d = sign(det(V U^T)),   t = t0 - R s0.
// The sign d replaces the reflection that the plain V U^T becomes when the data are coplanar
// (the third singular pair is then arbitrary) or themselves mirrored: the result is then the
// best proper rotation, never a reflection. Everything is computed in double about the
// centroids, so points far from the origin (1e6 m) lose only their own rounding.
//
// weights: empty (all 1) or one finite weight >= 0 per pair; zero-weight pairs are ignored.
// Coplanar points are enough (rank 2). Returns status kDegenerate and the identity, not a wrong
// answer, when fewer than 3 pairs have positive weight, or the weighted centred covariance of
// the source or target points, or H, has rank < 2: second singular value <= 1e-12 x the
// largest (collinear or coincident points; a width below ~1e-6 of the length).
// Throws uwscan::Error when the spans differ in size, weights is neither empty nor of that
// size, or a point or weight is not finite or a weight is negative.
SvdAlignment AlignSvd(std::span<const Eigen::Vector3d> source_points,
                      std::span<const Eigen::Vector3d> target_points,
                      std::span<const double> weights = {});

}  // namespace uwscan::perception
